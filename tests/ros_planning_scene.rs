//! MoveIt's planning scene through the node's doors and through `replay`: a MoveIt application as
//! an independent ROS 2 participant (Cyclone DDS from Python, `tests/peers/scene_peer.py`, its
//! types parsed from moveit_msgs' own definition files in `tests/fixtures/msg_definitions/`) adds
//! a thin scanned sheet by topic and a crate by `apply_planning_scene`, moves the sheet, appends a
//! sphere to the crate, removes the sheet, places an object in an environment link's frame and in
//! a fixed frame; after each step the node's reports for a set of random states equal `check
//! --json` on an environment URDF describing the same world (its "twin"). Bad inputs are refused
//! (the reply false, the warning, the count in `/diagnostics`) with the scene unchanged, and
//! `get_planning_scene` gives back the scene in force. The same messages in a bag give the same
//! reports through `replay`. Loopback only, as in `tests/ros_node.rs`.

mod common;

use common::start_node;
use serde_json::{json, Value};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use thickness_collision::model::Params;

/// A quaternion (x, y, z, w) as a ROS message, and the same rotation as URDF rpy.
const TILT: ([f64; 4], [f64; 3]) = ([0.0, std::f64::consts::FRAC_1_SQRT_2, 0.0, std::f64::consts::FRAC_1_SQRT_2], [0.0, std::f64::consts::FRAC_PI_2, 0.0]);
const LEVEL: ([f64; 4], [f64; 3]) = ([0.0, 0.0, 0.0, 1.0], [0.0, 0.0, 0.0]);

fn pose(p: [f64; 3], (q, _): ([f64; 4], [f64; 3])) -> Value {
    json!({"position": {"x": p[0], "y": p[1], "z": p[2]}, "orientation": {"x": q[0], "y": q[1], "z": q[2], "w": q[3]}})
}

/// An open sheet of 8 x 8 squares, 0.5 m a side, in its frame's x-y plane (coordinates exact in
/// single precision, so the twin's OBJ file holds the same triangles).
fn sheet() -> (Vec<[f64; 3]>, Vec<[u32; 3]>) {
    let n = 8;
    let mut v = Vec::new();
    let mut t = Vec::new();
    for i in 0..=n {
        for j in 0..=n {
            v.push([i as f64 * 0.0625, j as f64 * 0.0625 - 0.25, 0.0]);
        }
    }
    for i in 0..n {
        for j in 0..n {
            let a = (i * (n + 1) + j) as u32;
            let (b, c, d) = (a + (n + 1) as u32, a + 1, a + (n + 1) as u32 + 1);
            t.push([a, b, d]);
            t.push([a, d, c]);
        }
    }
    (v, t)
}

fn sheet_msg() -> Value {
    let (v, t) = sheet();
    json!({
        "vertices": v.iter().map(|p| json!({"x": p[0], "y": p[1], "z": p[2]})).collect::<Vec<_>>(),
        "triangles": t.iter().map(|t| json!({"vertex_indices": t})).collect::<Vec<_>>(),
    })
}

fn box_msg(size: [f64; 3]) -> Value {
    json!({"type": 1, "dimensions": size})
}

fn sphere_msg(r: f64) -> Value {
    json!({"type": 2, "dimensions": [r]})
}

/// A CollisionObject as JSON (header frame, id, operation, and the fields given in `rest`).
fn object(frame: &str, id: &str, operation: u8, rest: Value) -> Value {
    let mut o = json!({"header": {"frame_id": frame}, "id": id, "operation": operation});
    for (k, v) in rest.as_object().unwrap() {
        o[k] = v.clone();
    }
    o
}

/// A PlanningScene difference holding these world objects.
fn diff(objects: Vec<Value>) -> Value {
    json!({"is_diff": true, "world": {"collision_objects": objects}})
}

/// One link of the twin: its geometry (URDF) and its pose in a parent link.
struct TwinLink {
    name: &'static str,
    parent: &'static str,
    xyz: [f64; 3],
    rpy: [f64; 3],
    collisions: String,
}

fn origin(xyz: [f64; 3], rpy: [f64; 3]) -> String {
    format!("<origin xyz=\"{} {} {}\" rpy=\"{} {} {}\"/>", xyz[0], xyz[1], xyz[2], rpy[0], rpy[1], rpy[2])
}

/// The bundled environment with these links added, written to `dir/name.urdf`.
fn twin(dir: &Path, name: &str, links: &[&TwinLink]) -> PathBuf {
    let env_path = Params::default().environment_path();
    // Its mesh files by absolute path: the twin is written elsewhere.
    let env = std::fs::read_to_string(&env_path).unwrap().replace("filename=\"", &format!("filename=\"{}/", env_path.parent().unwrap().display()));
    let mut added = String::new();
    for l in links {
        let _ = write!(
            added,
            "<link name=\"{n}\">{c}</link><joint name=\"{n}_joint\" type=\"fixed\"><parent link=\"{p}\"/><child link=\"{n}\"/>{o}</joint>",
            n = l.name,
            c = l.collisions,
            p = l.parent,
            o = origin(l.xyz, l.rpy)
        );
    }
    let path = dir.join(format!("{name}.urdf"));
    std::fs::write(&path, env.replacen("</robot>", &(added + "</robot>"), 1)).unwrap();
    path
}

fn sheet_obj(dir: &Path) -> PathBuf {
    let (v, t) = sheet();
    let mut obj = String::new();
    for p in &v {
        let _ = writeln!(obj, "v {} {} {}", p[0], p[1], p[2]);
    }
    for f in &t {
        let _ = writeln!(obj, "f {} {} {}", f[0] + 1, f[1] + 1, f[2] + 1);
    }
    let path = dir.join("scan_sheet.obj");
    std::fs::write(&path, obj).unwrap();
    path
}

/// Random states of the bundled arm within its limits, as `{name, position}`.
fn random_states(n: usize, seed: u128) -> Vec<Value> {
    let (names, states) = common::random_arm_states(n, seed);
    states.iter().map(|q| json!({"name": names, "position": q})).collect()
}

/// The world after each step, as twins.
struct Story {
    /// (step label, the twin environment file, the object some of the step's states must touch).
    checkpoints: Vec<(&'static str, PathBuf, &'static str)>,
}

/// `check`'s report for a world with a plane, as the node gives it: the plane's twin is a
/// two-triangle sheet, so its contacts get the plane's triangle (`u32::MAX`); and its point is
/// taken from the node's report (where a link passes through the whole slab any point of the
/// overlap is a contact point, and the cells decide which one): bodies, depths and normals are
/// compared.
fn as_plane(want: &Value, got: &Value, plane: &str) -> Value {
    let mut want = want.clone();
    for (w, g) in want["contacts"].as_array_mut().unwrap().iter_mut().zip(got["contacts"].as_array().unwrap()) {
        if w["object_name"] == plane {
            w["triangle"] = json!(u32::MAX);
            w["position"] = g["position"].clone();
        }
    }
    want
}

#[test]
fn the_planning_scene_as_moveit_keeps_it_live_and_replayed() {
    let dir = common::scratch_dir("ros_planning_scene");
    let cyclone = common::cyclone_loopback_file(&dir);
    let obj = sheet_obj(&dir);
    let states = random_states(30, 32);

    // The world, step by step, and its twins.
    let sheet_at = ([0.3, 0.15, 0.6], TILT);
    let sheet_moved = ([0.25, -0.1, 0.3], LEVEL);
    let crate_at = [0.35, -0.1, 0.3];
    let sheet_link = |p: ([f64; 3], ([f64; 4], [f64; 3]))| TwinLink {
        name: "scan_sheet",
        parent: "world",
        xyz: p.0,
        rpy: p.1 .1,
        collisions: format!("<collision><geometry><mesh filename=\"{}\"/></geometry></collision>", obj.display()),
    };
    let box_urdf = "<collision><geometry><box size=\"0.3 0.3 0.3\"/></geometry></collision>";
    let crate_box = TwinLink { name: "crate", parent: "world", xyz: crate_at, rpy: [0.0; 3], collisions: box_urdf.into() };
    let crate_full = TwinLink {
        name: "crate",
        parent: "world",
        xyz: crate_at,
        rpy: [0.0; 3],
        collisions: format!("{box_urdf}<collision><origin xyz=\"0 0.2 0.1\"/><geometry><sphere radius=\"0.08\"/></geometry></collision>"),
    };
    // A plane x = 0.6875 facing the arm (exact in the single precision the twin's mesh file is
    // read in), and its twin: the 10 x 10 m square of it with the diagonal
    // the node's square has (its corners foot +- 5 u +- 5 v, u = (0, 1, 0), v = n x u = (0, 0, -1)).
    let square = dir.join("wall_plane.obj");
    std::fs::write(&square, "v 0.6875 -5 5\nv 0.6875 5 5\nv 0.6875 5 -5\nv 0.6875 -5 -5\nf 1 2 3\nf 1 3 4\n").unwrap();
    let wall_link = TwinLink {
        name: "wall_plane",
        parent: "world",
        xyz: [0.0; 3],
        rpy: [0.0; 3],
        collisions: format!("<collision><geometry><mesh filename=\"{}\"/></geometry></collision>", square.display()),
    };
    // A box 0.15 m above the table's frame, given in the environment link `table`.
    let on_table = TwinLink {
        name: "on_table",
        parent: "table",
        xyz: [0.25, 0.3, 0.15],
        rpy: [0.0; 3],
        collisions: "<collision><geometry><box size=\"0.3 0.3 0.3\"/></geometry></collision>".into(),
    };
    let story = Story {
        checkpoints: vec![
            ("sheet added by topic", twin(&dir, "a", &[&sheet_link(sheet_at)]), "scan_sheet"),
            ("crate added by apply_planning_scene", twin(&dir, "b", &[&sheet_link(sheet_at), &crate_box]), "crate"),
            ("sheet moved", twin(&dir, "c", &[&sheet_link(sheet_moved), &crate_box]), "scan_sheet"),
            ("sphere appended to the crate, sheet removed", twin(&dir, "d", &[&crate_full]), "crate"),
            ("an object in the table's frame", twin(&dir, "e", &[&crate_full, &on_table]), "on_table"),
            ("a plane", twin(&dir, "f", &[&crate_full, &on_table, &wall_link]), "wall_plane"),
            ("a tray attached to the hand", twin(&dir, "g", &[&crate_full, &on_table, &wall_link]), "tray"),
            ("the crate allowed by the collision matrix", twin(&dir, "h", &[&on_table, &wall_link]), "tray"),
        ],
    };
    // The tray's twins are the arm holding it, with the SRDF that disables its touch links.
    let touch = ["gripper_link", "finger_left_link", "finger_right_link"];
    let (srdf, tray_srdf) = common::arm_srdfs(&touch);
    let (srdf_file, tray_srdf_file, tray_urdf) = (dir.join("arm.srdf"), dir.join("tray.srdf"), dir.join("tray.urdf"));
    std::fs::write(&srdf_file, srdf).unwrap();
    std::fs::write(&tray_srdf_file, tray_srdf).unwrap();
    std::fs::write(&tray_urdf, common::arm_with_tray()).unwrap();
    let holding = ["--robot", tray_urdf.to_str().unwrap(), "--srdf", tray_srdf_file.to_str().unwrap()];
    let cli: Vec<Vec<Value>> = story
        .checkpoints
        .iter()
        .enumerate()
        .map(|(k, (_, env, _))| {
            let mut args = vec!["--environment", env.to_str().unwrap()];
            if k >= 6 {
                args.extend(holding);
            }
            common::check_json(&dir, &format!("checkpoint{k}"), &states, &args)
        })
        .collect();
    for ((label, _, object), reports) in story.checkpoints.iter().zip(&cli) {
        let touching =
            reports.iter().filter(|r| r["contacts"].as_array().unwrap().iter().any(|c| c["object_name"] == *object || c["link_name"] == *object)).count();
        let colliding = reports.iter().filter(|r| r["in_collision"] == true).count();
        assert!(
            touching >= 2 && colliding < reports.len(),
            "{label}: {touching} states touch {object}, {colliding} collide: the states must tell the worlds apart"
        );
    }

    let sheet_add = object("world", "scan_sheet", 0, json!({"pose": pose(sheet_at.0, sheet_at.1), "meshes": [sheet_msg()]}));
    // One shape and MoveIt's empty object pose: the shape's pose becomes the object's.
    let crate_add = object("world", "crate", 0, json!({"primitives": [box_msg([0.3, 0.3, 0.3])], "primitive_poses": [pose(crate_at, LEVEL)]}));
    let sheet_move = object("world", "scan_sheet", 3, json!({"pose": pose(sheet_moved.0, sheet_moved.1)}));
    // APPEND places shapes relative to the object's pose, which stays (the message's pose only
    // places a new object); it is given here because with a lone shape and an empty pose MoveIt
    // would move the shape's pose onto the (unused) object pose and put the sphere at the origin.
    let sphere_append = object(
        "world",
        "crate",
        2,
        json!({"pose": pose([9.0, 9.0, 9.0], LEVEL), "primitives": [sphere_msg(0.08)], "primitive_poses": [pose([0.0, 0.2, 0.1], LEVEL)]}),
    );
    let sheet_remove = object("world", "scan_sheet", 1, json!({}));
    let table_add = object("table", "on_table", 0, json!({"pose": pose([0.25, 0.3, 0.15], LEVEL), "primitives": [box_msg([0.3, 0.3, 0.3])]}));
    let bad = [
        (object("world", "ghost", 1, json!({})), "scene_unknown_id", "no such object"),
        (object("nowhere", "x", 0, json!({"primitives": [sphere_msg(0.1)]})), "scene_frame", "'nowhere' is not a known frame"),
        (object("world", "base_link", 0, json!({"primitives": [sphere_msg(0.1)]})), "scene_id", "names a link of the robot"),
        (object("world", "x", 7, json!({"primitives": [sphere_msg(0.1)]})), "scene_operation", "operation 7"),
        (
            object("world", "x", 0, json!({"meshes": [{"vertices": [{"x": "NaN"}, {}, {"x": 1.0}], "triangles": [{"vertex_indices": [0, 1, 2]}]}]})),
            "scene_geometry",
            "meshes[0].vertices[0]: not finite",
        ),
        (
            object("world", "x", 0, json!({"primitives": [box_msg([0.1, 0.1, 0.1])], "primitive_poses": [pose([0.0; 3], LEVEL), pose([0.0; 3], LEVEL)]})),
            "scene_geometry",
            "2 poses for 1 shapes",
        ),
    ];

    let states_step = || json!({"states": states});
    let mut steps = vec![
        json!({"publish": "collision_object", "msg": sheet_add}),
        json!({"wait_objects": ["scan_sheet"]}),
        states_step(),
        json!({"apply": diff(vec![crate_add.clone()])}),
        states_step(),
        json!({"apply": diff(vec![sheet_move.clone()])}),
        states_step(),
        json!({"apply": diff(vec![sphere_append.clone()])}),
        json!({"publish": "collision_object", "msg": sheet_remove}),
        json!({"wait_objects": ["crate"]}),
        states_step(),
    ];
    let bad_from = steps.len();
    // The node warns at most once a second per cause: each bad request waits that out.
    steps.extend(bad.iter().flat_map(|(o, _, _)| [json!({"apply": diff(vec![o.clone()])}), json!({"sleep": 1.1})]));
    steps.push(json!({"apply": diff(vec![table_add.clone()])}));
    steps.push(states_step());
    steps.push(json!({"get": 8 | 16 | 64}));

    // Then a plane and a tray in the hand (topics), and the collision matrix read back.
    let plane_add = object("world", "wall_plane", 0, json!({"planes": [{"coef": [-1.0, 0.0, 0.0, 0.6875]}]}));
    let tray = object("tool0", "tray", 0, json!({"pose": pose([0.0, 0.0, 0.12], LEVEL), "primitives": [box_msg([0.3, 0.2, 0.04])]}));
    let attach = json!({"link_name": "tool0", "object": tray, "touch_links": touch});
    let steps2 = vec![
        json!({"publish": "collision_object", "msg": plane_add}),
        json!({"wait_objects": ["crate", "on_table", "wall_plane"]}),
        states_step(),
        json!({"publish": "attached_collision_object", "msg": attach}),
        json!({"wait_objects": ["crate", "on_table", "wall_plane"], "attached": ["tray"]}),
        states_step(),
        // The cell markers show the scene in force, after the bursts of changes above (sent at
        // most twice a second, the newest scene always): the sheet removed, attached objects
        // not drawn.
        json!({"markers": {"present": ["solids/crate", "solids/on_table", "cells/wall_plane"], "absent": ["cells/scan_sheet", "solids/tray"]}}),
        json!({"get": 128}),
    ];

    let domain = 66 + std::process::id() % 4;
    let semantic = format!("robot_semantic_file:={}", srdf_file.display());
    let (node, _out, banner) = start_node(&["--ros-args", "-p", "check_motion:=false", "-p", &semantic], domain);
    assert!(banner.contains("planning scene: subscribes collision_object"), "{banner}");
    let session = |steps: &[Value]| {
        common::run_cyclone_peer("scene_peer.py", &cyclone, &json!({"op": "live", "domain": domain, "timeout": 60, "steps": steps}).to_string())
    };
    let answer = session(&steps);
    let answer2 = session(&steps2);
    // The matrix as get_planning_scene gave it, with the crate allowed against every body,
    // written back: the crate is as good as gone.
    let mut acm = answer2["results"][steps2.len() - 1]["allowed_collision_matrix"].clone();
    let names: Vec<String> = acm["entry_names"].as_array().unwrap().iter().map(|n| n.as_str().unwrap().to_owned()).collect();
    assert!(names.iter().any(|n| n == "tray") && names.iter().any(|n| n == "shoulder_link"), "the matrix names links and the attached tray: {names:?}");
    let c = names.iter().position(|n| n == "crate").unwrap();
    for (i, row) in acm["entry_values"].as_array_mut().unwrap().iter_mut().enumerate() {
        for (j, v) in row["enabled"].as_array_mut().unwrap().iter_mut().enumerate() {
            if i == c || j == c {
                *v = json!(true);
            }
        }
    }
    let steps3 = vec![json!({"apply": {"is_diff": true, "allowed_collision_matrix": acm}}), states_step()];
    let answer3 = session(&steps3);
    let err = common::stop_node(node);
    let results = answer["results"].as_array().unwrap();
    assert_eq!(results.len(), steps.len(), "{answer}");
    assert_eq!(answer3["results"][0], json!({"success": true}), "{answer3}");
    assert_eq!((&answer2["results"][1]["ok"], &answer2["results"][4]["ok"]), (&json!(true), &json!(true)), "{answer2}");
    assert_eq!(answer2["results"][6]["ok"], true, "the cell markers show the scene in force: {}", answer2["results"][6]);

    // Each states step against its twin.
    let mut reported = Vec::new();
    for (a, st) in [(&answer, &steps), (&answer2, &steps2), (&answer3, &steps3)] {
        for (r, step) in a["results"].as_array().unwrap().iter().zip(st.iter()) {
            if step.get("states").is_some() {
                reported.push(r.as_array().unwrap().clone());
            }
        }
    }
    assert_eq!(reported.len(), story.checkpoints.len());
    for (k, ((label, _, _), (got, want))) in story.checkpoints.iter().zip(reported.iter().zip(&cli)).enumerate() {
        for (i, (g, w)) in got.iter().zip(want).enumerate() {
            assert!(g.is_object(), "{label}: state {i} got no report");
            let w = if k >= 5 { as_plane(w, g, "wall_plane") } else { w.clone() };
            common::same_report(g, &w, &format!("{label}, state {i}"));
        }
    }
    for i in [3, 5, 7] {
        assert_eq!(results[i], json!({"success": true}), "step {i}: {}", steps[i]);
    }
    assert_eq!(results[1]["ok"], true, "{}", results[1]);
    assert_eq!(results[9]["ok"], true, "{}", results[9]);
    for (k, (_, key, needle)) in bad.iter().enumerate() {
        assert_eq!(results[bad_from + 2 * k], json!({"success": false}), "a bad object is refused: {}", steps[bad_from + 2 * k]);
        assert!(err.contains(needle), "the log says why ({needle}): {err}");
        let count: u64 = answer["diagnostics"][format!("skipped_{key}")].as_str().and_then(|v| v.parse().ok()).unwrap_or(0);
        assert!(count >= 1, "/diagnostics counts {key}: {}", answer["diagnostics"]);
    }
    assert_eq!(results[bad_from + 2 * bad.len()], json!({"success": true}));

    // get_planning_scene: the scene in force, objects in world_frame with shapes relative to them.
    let scene = &results[steps.len() - 1];
    let objects = scene["world"]["collision_objects"].as_array().unwrap();
    let ids: Vec<&str> = objects.iter().map(|o| o["id"].as_str().unwrap()).collect();
    assert_eq!(ids, ["crate", "on_table"], "{scene}");
    let crate_msg = &objects[0];
    assert_eq!(crate_msg["header"]["frame_id"], "world");
    assert!(common::close(
        &json!([crate_msg["pose"]["position"]["x"], crate_msg["pose"]["position"]["y"], crate_msg["pose"]["position"]["z"]]),
        &json!(crate_at)
    ));
    let dims: Vec<&Value> = crate_msg["primitives"].as_array().unwrap().iter().map(|p| &p["dimensions"]).collect();
    assert_eq!(dims, [&json!([0.3, 0.3, 0.3]), &json!([0.08])]);
    assert_eq!(crate_msg["primitive_poses"][1]["position"], json!({"x": 0.0, "y": 0.2, "z": 0.1}));
    let table = &objects[1]["pose"]["position"];
    assert!(common::close(&json!([table["x"], table["y"], table["z"]]), &json!([0.25, 0.3, 0.15])), "the table link is at the world's origin: {table}");
    assert!(!err.contains("panicked"), "{err}");

    // The same messages in a bag (the service calls as planning_scene messages, as
    // move_group would publish them), replayed: the same reports.
    let mut messages = Vec::new();
    let mut t: i64 = 1_000_000_000;
    let mut next = || {
        t += 1_000_000;
        t
    };
    for step in steps.iter().chain(&steps2).chain(&steps3) {
        if let Some(s) = step.get("states") {
            for st in s.as_array().unwrap() {
                let at = next();
                messages.push(json!({"topic": "/joint_states", "t": at, "stamp": at, "name": st["name"], "position": st["position"]}));
            }
        } else if let Some(msg) = step.get("apply") {
            messages.push(json!({"topic": "/planning_scene", "t": next(), "msg": msg}));
        } else if let Some(topic) = step.get("publish") {
            messages.push(json!({"topic": format!("/{}", topic.as_str().unwrap()), "t": next(), "msg": step["msg"]}));
        }
    }
    let bag = dir.join("scene_bag");
    let written = common::run_peer("scene_peer.py", &json!({"op": "bag", "path": bag, "storage": "mcap", "messages": messages}));
    assert_eq!(written["ok"], true);
    let jsonl = dir.join("replayed.jsonl");
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_thickness_collision"))
        .args(["replay", bag.to_str().unwrap(), "--no-motion", "--jsonl", jsonl.to_str().unwrap(), "--srdf", srdf_file.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(o.status.success(), "replay: {}", String::from_utf8_lossy(&o.stderr));
    let replayed: Vec<Value> = std::fs::read_to_string(&jsonl).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(replayed.len(), states.len() * story.checkpoints.len());
    for (k, (got, want)) in replayed.iter().zip(cli.iter().flatten()).enumerate() {
        let want = if k >= 5 * states.len() { as_plane(want, got, "wall_plane") } else { want.clone() };
        common::same_report(got, &want, &format!("replayed state {k}"));
    }
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(stderr.contains("no such object"), "replay warns about the refused messages: {stderr}");
}
