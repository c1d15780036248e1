//! Issue 13, part 2, `check_state_validity`: MoveIt's `moveit_msgs/srv/GetStateValidity` called
//! over DDS by an independent ROS 2 participant (Cyclone DDS from Python,
//! `tests/peers/validity_peer.py`, types from this project's field lists in
//! `tests/peers/moveit_types.py`, Cyclone's request/reply mapping), with the service name unchanged.
//! `valid` and the contacts agree with `check --states FILE --json` on the same states; requests
//! with an object attached to no link, with constraints, with a multi-DOF joint, with a NaN joint and with an
//! unknown joint are answered `valid = false` without contacts, the reason in the node's log and
//! counted in `/diagnostics`, and the node keeps answering after them. Loopback only, as in
//! `tests/ros_node.rs`.

mod common;

use common::start_node;
use serde_json::{json, Value};

/// `check --states FILE --json` on states given by name: one report per state.
/// The service's answer against `check --json` on the same state: `valid` is "not in
/// collision", and each contact is the report's (link as body 1, a robot link; the object as body
/// 2, a world object, or a robot link for a self contact; depth, point and normal; in
/// `world_frame`).
fn assert_same(k: usize, got: &Value, cli: &Value) {
    assert_eq!(cli["error"], "", "state {k}: check could not check it: {cli}");
    assert_eq!(got["valid"], json!(cli["in_collision"] == false), "state {k}: {got} vs {cli}");
    assert_eq!((&got["cost_sources"], &got["constraint_result"]), (&json!(0), &json!(0)), "state {k}");
    let (gc, cc) = (got["contacts"].as_array().unwrap(), cli["contacts"].as_array().unwrap());
    assert_eq!(gc.len(), cc.len(), "state {k}: {got} vs {cli}");
    for (g, c) in gc.iter().zip(cc) {
        // ROBOT_LINK 0, WORLD_OBJECT 1, ROBOT_ATTACHED 2: a self contact's object is another link
        // or an attached object.
        let code = |t: &Value| match t.as_str() {
            Some("robot_link") => json!(0),
            Some("attached_object") => json!(2),
            _ => json!(1),
        };
        let type_1 = if c["link_type"] == "attached_object" { json!(2) } else { json!(0) };
        assert_eq!(
            (&g["body_1"], &g["type_1"], &g["body_2"], &g["type_2"]),
            (&c["link_name"], &type_1, &c["object_name"], &code(&c["object_type"])),
            "state {k}"
        );
        assert!(
            common::close(&g["depth"], &c["depth"]) && common::close(&g["position"], &c["position"]) && common::close(&g["normal"], &c["normal"]),
            "state {k}: {g} vs {c}"
        );
        assert_eq!(g["frame"], "world", "state {k}");
    }
}

#[test]
fn check_state_validity_agrees_with_check_and_refuses_what_it_cannot_honour() {
    let dir = common::scratch_dir("ros_validity");
    let cyclone = common::cyclone_loopback_file(&dir);

    // Random states of the bundled arm within its limits, some free and some not.
    let (names, states) = common::random_arm_states(40, 13);
    let lines: Vec<Value> = states.iter().map(|p| json!({"name": names, "position": p})).collect();
    let cli = common::check_json(&dir, "states", &lines, &[]);
    assert_eq!(cli.len(), states.len());
    let colliding = cli.iter().filter(|l| l["in_collision"] == true).count();
    assert!(colliding >= 5 && colliding + 5 <= states.len(), "{colliding} of {} states collide: the test needs both kinds", states.len());

    // Requests: the states (the second half with is_diff set and an unknown group: the same
    // answer), then what the node cannot honour, then a state again.
    let mut requests: Vec<Value> = states
        .iter()
        .enumerate()
        .map(
            |(k, q)| {
                if k < 20 {
                    json!({"name": names, "position": q})
                } else {
                    json!({"name": names, "position": q, "is_diff": true, "group": "no_such_group"})
                }
            },
        )
        .collect();
    let bad = [
        // The bare `true` attaches to the first joint's name, which is no link.
        (json!({"name": names, "position": states[0], "attached": true}), "link_name: 'shoulder_pan_joint' is not a link of the robot"),
        (json!({"name": names, "position": states[0], "constraints": true}), "constraints given"),
        (json!({"name": names, "position": states[0], "multi_dof": ["virtual_joint"]}), "multi_dof_joint_state"),
        (json!({"name": ["elbow_joint"], "position": ["NaN"]}), "non-finite position NaN"),
        (json!({"name": ["elbow_joint", "no_such_joint"], "position": [0.1, 0.2]}), "'no_such_joint' is not a joint"),
    ];
    // The node warns at most once a second per cause: each bad request waits that out, so every
    // reason reaches the log.
    requests.extend(bad.iter().map(|(r, _)| {
        let mut r = r.clone();
        r["pause"] = json!(1.1);
        r
    }));
    let last = states.len() - 1;
    requests.push(json!({"name": names, "position": states[last]}));

    let domain = 230 + std::process::id() % 3;
    let (node, _out, banner) = start_node(&["--ros-args", "-p", "check_motion:=false"], domain);
    assert!(banner.contains("check_state_validity (moveit_msgs/srv/GetStateValidity)"), "{banner}");
    let answer = common::run_cyclone_peer(
        "validity_peer.py",
        &cyclone,
        &json!({"domain": domain, "requests": requests, "timeout": 90, "refused_at_least": bad.len()}).to_string(),
    );
    let err = common::stop_node(node);

    let answers = answer["answers"].as_array().unwrap();
    assert_eq!(answers.len(), requests.len());
    assert!(answers.iter().all(Value::is_object), "every request answered: {answers:?}");
    for (k, (got, want)) in answers.iter().zip(&cli).enumerate() {
        assert_same(k, got, want);
    }
    for ((_, cause), got) in bad.iter().zip(&answers[states.len()..]) {
        assert_eq!(got, &json!({"valid": false, "contacts": [], "cost_sources": 0, "constraint_result": 0}), "{cause}");
        assert!(err.contains(cause), "the reason '{cause}' is in the node's log: {err}");
    }
    // The node kept answering after them.
    assert_same(last, &answers[states.len() + bad.len()], &cli[last]);
    assert!(err.contains("check_state_validity: request not honoured (valid = false)"), "{err}");
    assert!(err.contains("group 'no_such_group' is not a group"), "an unknown group is warned about: {err}");
    assert!(answer["refused_count"].as_u64().is_some_and(|n| n >= bad.len() as u64), "/diagnostics counts the requests not honoured: {answer}");
    assert!(!err.contains("panicked"), "{err}");
}

/// An object attached to `tool0` in the request (`is_diff` false: the request's attached objects
/// are all there are), with the gripper's links as touch links: the answers equal `check --json`
/// on the twin robot, the same arm with a fixed child link `tray` of `tool0` and an SRDF that
/// disables the tray's pairs with the touch links; the tray's contacts have `ROBOT_ATTACHED` body
/// types.
#[test]
fn check_state_validity_with_an_attached_object_agrees_with_its_twin() {
    let dir = common::scratch_dir("ros_validity_attached");
    let cyclone = common::cyclone_loopback_file(&dir);
    // One matrix for both sides: an SRDF disabling what the default reasoning allows.
    let touch = ["gripper_link", "finger_left_link", "finger_right_link"];
    let (srdf, twin_srdf) = common::arm_srdfs(&touch);
    let (srdf_file, twin_srdf_file, twin_urdf) = (dir.join("arm.srdf"), dir.join("twin.srdf"), dir.join("twin.urdf"));
    std::fs::write(&srdf_file, srdf).unwrap();
    std::fs::write(&twin_srdf_file, twin_srdf).unwrap();
    std::fs::write(&twin_urdf, common::arm_with_tray()).unwrap();
    let (names, states) = common::random_arm_states(40, 34);
    let lines: Vec<Value> = states.iter().map(|p| json!({"name": names, "position": p})).collect();
    let cli = common::check_json(&dir, "twin", &lines, &["--robot", twin_urdf.to_str().unwrap(), "--srdf", twin_srdf_file.to_str().unwrap()]);
    let with_tray = cli.iter().filter(|r| r["contacts"].as_array().unwrap().iter().any(|c| c["link_name"] == "tray" || c["object_name"] == "tray")).count();
    assert!(with_tray >= 5, "{with_tray} of {} states touch the tray: the test needs them", states.len());

    let spec = json!({"link": "tool0", "id": "tray", "size": [0.3, 0.2, 0.04], "z": 0.12, "touch_links": touch});
    let requests: Vec<Value> = states.iter().map(|q| json!({"name": names, "position": q, "attached": spec})).collect();
    let domain = 220 + std::process::id() % 8;
    let semantic = format!("robot_semantic_file:={}", srdf_file.display());
    let (node, _out, _banner) = start_node(&["--ros-args", "-p", "check_motion:=false", "-p", &semantic], domain);
    let answer = common::run_cyclone_peer("validity_peer.py", &cyclone, &json!({"domain": domain, "requests": requests, "timeout": 90}).to_string());
    let err = common::stop_node(node);
    let answers = answer["answers"].as_array().unwrap();
    assert_eq!(answers.len(), requests.len());
    let mut tray_types = 0;
    for (k, (got, want)) in answers.iter().zip(&cli).enumerate() {
        assert!(got.is_object(), "state {k} answered: {err}");
        // The twin's tray is a robot link; the node's is an attached object.
        let mut want = want.clone();
        for c in want["contacts"].as_array_mut().unwrap() {
            if c["link_name"] == "tray" {
                c["link_type"] = json!("attached_object");
            }
            if c["object_name"] == "tray" {
                c["object_type"] = json!("attached_object");
            }
        }
        assert_same(k, got, &want);
        tray_types += got["contacts"].as_array().unwrap().iter().filter(|c| c["type_1"] == 2 || c["type_2"] == 2).count();
    }
    assert!(tray_types >= 5, "ROBOT_ATTACHED contacts: {tray_types}");
    // (The peer's warm-up, an empty request, is not honoured before a joint state came: that
    // is the only refusal.)
    assert_eq!(
        err.matches("not honoured").count(),
        err.matches("request not honoured (valid = false): joint 'shoulder_pan_joint' is neither").count(),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
}
