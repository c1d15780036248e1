//! Issue 13, part 2, `check_state_validity`: MoveIt's `moveit_msgs/srv/GetStateValidity` called
//! over DDS by an independent ROS 2 participant (Cyclone DDS from Python,
//! `tests/peers/validity_peer.py`, types from this project's field lists in
//! `tests/peers/moveit_types.py`, Cyclone's request/reply mapping), with the service name unchanged.
//! `valid` and the contacts agree with `check --states FILE --json` on the same states; requests
//! with an attached object, with constraints, with a multi-DOF joint, with a NaN joint and with an
//! unknown joint are answered `valid = false` without contacts, the reason in the node's log and
//! counted in `/diagnostics`, and the node keeps answering after them. Loopback only, as in
//! `tests/ros_node.rs`.

mod common;

use common::start_node;
use oorandom::Rand64;
use serde_json::{json, Value};
use thickness_collision::checker::Checker;
use thickness_collision::model::{JointKind, Params};

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
        // ROBOT_LINK 0, WORLD_OBJECT 1: a self contact's object is another link.
        let type_2 = if c["object_type"] == "robot_link" { json!(0) } else { json!(1) };
        assert_eq!((&g["body_1"], &g["type_1"], &g["body_2"], &g["type_2"]), (&c["link_name"], &json!(0), &c["object_name"], &type_2), "state {k}");
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
    let checker = Checker::from_params(Params::default()).unwrap();
    let joints: Vec<_> = checker.robot().joints.iter().filter(|j| j.is_actuated()).collect();
    let names: Vec<String> = joints.iter().map(|j| j.name.clone()).collect();
    let mut rng = Rand64::new(13);
    let states: Vec<Vec<f64>> = (0..40)
        .map(|_| {
            joints
                .iter()
                .map(|j| {
                    let (lo, hi) = if j.kind == JointKind::Continuous { (-3.1, 3.1) } else { (j.limits[0], j.limits[1]) };
                    lo + (hi - lo) * rng.rand_float()
                })
                .collect()
        })
        .collect();
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
        (json!({"name": names, "position": states[0], "attached": true}), "attached collision object"),
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
