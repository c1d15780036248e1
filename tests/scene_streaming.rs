//! States keep being answered while a large planning-scene object's cells are built: the node
//! builds a scene's cells without holding its state. A test binary of its own, so that no other
//! test's node and peer share the two cores with it while it times the answers. Loopback only.

mod common;

use common::start_node;
use serde_json::{json, Value};

/// A CollisionObject as JSON (header frame, id, operation, and the fields given in `rest`).
fn object(frame: &str, id: &str, operation: u8, rest: Value) -> Value {
    let mut o = json!({"header": {"frame_id": frame}, "id": id, "operation": operation});
    for (k, v) in rest.as_object().unwrap() {
        o[k] = v.clone();
    }
    o
}

/// States keep being answered while a large object's cells are built: `apply_planning_scene`
/// adds an 80,000-triangle sheet while the peer sends the arm's state every 5 ms; the states
/// answered meanwhile were checked against the scene in force (the sheet not in it), and from the
/// change on against the new one; the same state after the reply touches the sheet.
#[test]
fn states_are_answered_while_an_object_is_built() {
    let dir = common::scratch_dir("ros_planning_scene_streaming");
    let cyclone = common::cyclone_loopback_file(&dir);
    let (v, t) = thickness_collision::mesh::generate::wavy_sheet(200, 200, 7.0, 7.0, 0.05, 0.5);
    let mesh = json!({
        "vertices": v.iter().map(|p| json!({"x": p.x, "y": p.y, "z": p.z})).collect::<Vec<_>>(),
        "triangles": t.iter().map(|t| json!({"vertex_indices": t})).collect::<Vec<_>>(),
    });
    // A sheet 0.3 m above the table across the whole cell: the upright arm passes through it.
    let level = json!({"position": {"x": -3.5, "y": -3.5, "z": 0.3}, "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}});
    let sheet = object("world", "big_sheet", 0, json!({"pose": level, "meshes": [mesh]}));
    let (arm, _) = common::random_arm_states(1, 1);
    let upright = json!({"name": arm, "position": vec![0.0; arm.len()]});
    let steps = vec![
        json!({"states": [upright]}),
        json!({"apply_streaming": {"is_diff": true, "world": {"collision_objects": [sheet]}}, "state": upright, "period": 0.005}),
        json!({"states": [upright]}),
    ];
    let domain = 70 + std::process::id() % 4;
    let (node, _out, _banner) = start_node(&["--ros-args", "-p", "check_motion:=false"], domain);
    let answer = common::run_cyclone_peer("scene_peer.py", &cyclone, &json!({"op": "live", "domain": domain, "timeout": 60, "steps": steps}).to_string());
    let err = common::stop_node(node);
    let results = answer["results"].as_array().unwrap();
    let streamed = &results[1];
    assert_eq!(streamed["success"], true, "{streamed}: {err}");
    let reply = streamed["reply"].as_f64().unwrap();
    let during: Vec<&Value> = streamed["reports"].as_array().unwrap().iter().filter(|r| r["reported"].as_f64().unwrap() < reply).collect();
    eprintln!("reply after {:.0} ms; {} of {} states answered before it", reply * 1e3, during.len(), streamed["sent"]);
    // In stamp order, the states first meet the scene in force (no sheet), then the new one; a
    // state checked between the change and the reply's arrival may see it already.
    let touches: Vec<bool> = streamed["reports"].as_array().unwrap().iter().map(|r| r["objects"].as_array().unwrap().contains(&json!("big_sheet"))).collect();
    assert!(touches.windows(2).all(|w| w[0] <= w[1]), "never the old scene after the new: {touches:?}");
    let before = during.iter().filter(|r| !r["objects"].as_array().unwrap().contains(&json!("big_sheet"))).count();
    assert!(before >= 3, "states answered against the scene in force while the sheet was built: {streamed}");
    let after = &results[2][0];
    assert!(after["contacts"].as_array().unwrap().iter().any(|c| c["object_name"] == "big_sheet"), "in force after the reply: {after}");
    assert!(!err.contains("panicked"), "{err}");
}
