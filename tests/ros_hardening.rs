//! Doors a deployment can close (issue 33, part 2): `read_only_parameters` refuses remote
//! `set_parameters` on the names it lists (with a reason, the value unchanged) and the parameter
//! services describe them read only in every service mapping (Cyclone's, from Python's
//! `tests/peers/param_peer.py`; the enhanced one, from the Fast DDS peer); with
//! `robot_description_topic` empty a published robot description changes nothing (the control,
//! the same description taking effect on an open door, is `tests/ros_node.rs`'s
//! `robot_description_topic_replaces_the_robot_and_a_bad_one_is_refused`). Loopback only;
//! domains 165-167.

mod common;

use common::fastdds::{FastDdsPeer, PeerOptions};
use common::start_node;
use serde_json::{json, Value};
use std::io::Read;
use std::process::{Child, ChildStdout, Command};

/// SIGTERM; the node must exit cleanly. Returns its remaining stdout.
fn stop(mut node: Child, mut out: std::io::BufReader<ChildStdout>) -> String {
    let _ = Command::new("kill").args(["-TERM", &node.id().to_string()]).status();
    let status = node.wait().unwrap();
    let mut rest = String::new();
    let _ = out.read_to_string(&mut rest);
    assert!(status.success(), "node exit {status:?}");
    rest
}

#[test]
fn read_only_parameters_are_refused_over_the_cyclone_mapping() {
    let dir = common::scratch_subdir("ros_hardening", "cyclone");
    let cyclone = common::cyclone_loopback_file(&dir);
    let domain = 165;
    let (node, out, banner) = start_node(
        &["--ros-args", "-r", "__node:=tc_ro", "-p", "service_mapping:=cyclone", "-p", "read_only_parameters:=[default_thickness, 'thin_surfaces.*']"],
        domain,
    );
    assert!(banner.contains("read-only parameters: default_thickness, thin_surfaces.*"), "{banner}");
    let calls = json!([
        {"service": "set_parameters", "request": {"name": "default_thickness", "double": 0.05}},
        {"service": "get_parameters", "request": {"names": ["default_thickness"]}},
        {"service": "set_parameters", "request": {"name": "marker_rate", "double": 5.0}},
        {"service": "set_parameters", "request": {"name": "robot_description_topic", "string": "elsewhere"}},
        {"service": "describe_parameters", "request": {"names": ["default_thickness", "thin_surfaces.thickness", "marker_rate", "read_only_parameters", "robot_description_topic"]}},
        {"service": "get_parameters", "request": {"names": ["marker_rate", "robot_description_topic"]}},
    ]);
    let a = common::run_cyclone_peer("param_peer.py", &cyclone, &json!({"domain": domain, "node": "tc_ro", "calls": calls, "timeout": 20}).to_string());
    let answers = a["answers"].as_array().unwrap();
    assert!(answers.iter().all(Value::is_object), "every call answered: {a}");
    let refused = &answers[0]["results"][0];
    assert_eq!(refused[0], false, "{a}");
    assert!(refused[1].as_str().is_some_and(|r| r.contains("read_only_parameters") && r.contains("default_thickness")), "the reason names the list: {a}");
    assert_eq!(answers[1]["values"][0][1], json!(0.02), "the value is unchanged: {a}");
    assert_eq!(answers[2]["results"][0], json!([true, ""]), "a name the list leaves out is set: {a}");
    assert_eq!(answers[3]["results"][0][0], false, "a topic parameter is read only: {a}");
    assert_eq!(answers[4]["read_only"], json!([true, true, false, true, true]), "{a}");
    assert_eq!(answers[5]["values"], json!([[3, 5.0, ""], [4, 0.0, "robot_description"]]), "{a}");
    let rest = stop(node, out);
    assert!(rest.contains("parameters changed"), "the accepted set reached the loop: {rest}");
}

#[test]
fn read_only_parameters_are_described_read_only_over_the_enhanced_mapping() {
    let domain = 166;
    let (node, out, _banner) =
        start_node(&["--ros-args", "-r", "__node:=tc_ro_fast", "-p", "service_mapping:=enhanced", "-p", "read_only_parameters:=['*_thickness']"], domain);
    let mut peer = FastDdsPeer::start(&PeerOptions::loopback(domain));
    let described = peer.call("tc_ro_fast/describe_parameters", "describe_parameters", vec![json!({"names": ["default_thickness", "marker_rate"]})], 20.0);
    let d = described[0]["response"]["descriptors"].as_array().unwrap_or_else(|| panic!("describe_parameters: {}", described[0]));
    let read_only: Vec<&Value> = d.iter().map(|x| &x["read_only"]).collect();
    assert_eq!(read_only, vec![&json!(true), &json!(false)], "{}", described[0]);
    let set = peer.call(
        "tc_ro_fast/set_parameters",
        "set_parameters",
        vec![json!({"parameters": [{"name": "default_thickness", "value": {"type": 3, "double": 0.05}}]})],
        20.0,
    );
    let result = &set[0]["response"]["results"][0];
    assert_eq!(result["successful"], false, "{}", set[0]);
    assert!(result["reason"].as_str().is_some_and(|r| r.contains("read_only_parameters")), "{}", set[0]);
    peer.quit();
    let rest = stop(node, out);
    assert!(!rest.contains("parameters changed"), "nothing was changed: {rest}");
}

#[test]
fn a_closed_description_door_ignores_a_published_robot() {
    let dir = common::scratch_subdir("ros_hardening", "desc");
    let cyclone = common::cyclone_loopback_file(&dir);
    let domain = 167;
    let states: Vec<Value> = (0..12)
        .map(|k| {
            let x = k as f64;
            json!({"name": ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint", "finger_left_joint"],
                   "position": [(0.37 * x).sin() * 1.5, 0.3 + (0.23 * x).cos() * 1.1, (0.11 * x).sin() * 1.6, 0.2 * x % 3.0, (0.5 * x).cos() * 1.5, 0.1 * x, 0.02],
                   "stamp": k})
        })
        .collect();
    let fat = dir.join("fat_arm.urdf");
    std::fs::write(&fat, common::fat_arm_urdf()).unwrap();
    let thin = common::check_json(&dir, "thin", &states, &[]);
    let fat_ref = common::check_json(&dir, "fat", &states, &["--robot", fat.to_str().unwrap()]);
    let colliding = |v: &[Value]| v.iter().filter(|r| r["in_collision"] == true).count();
    assert_ne!(colliding(&thin), colliding(&fat_ref), "the two robots must answer differently");

    let (node, out, banner) = start_node(&["--ros-args", "-p", "check_motion:=false", "-p", "robot_description_topic:=''"], domain);
    assert!(banner.contains("robot description: closed (robot_description_topic empty)"), "{banner}");
    let request = json!({"domain": domain, "robot_descriptions": [common::fat_arm_urdf()], "states": states, "timeout": 30});
    let answer = common::run_cyclone_peer("dds_peer.py", &cyclone, &request.to_string());
    let rest = stop(node, out);
    assert!(!rest.contains("robot from robot_description"), "{rest}");
    assert_eq!(answer["description_matched"], false, "the node must not even subscribe: {answer}");
    let reports = answer["reports"].as_array().unwrap();
    assert_eq!(reports.len(), thin.len(), "{answer}");
    for (k, (got, want)) in reports.iter().zip(&thin).enumerate() {
        assert_eq!(got["in_collision"], want["in_collision"], "state {k}: the node must keep its own robot");
        assert_eq!(got["contacts"].as_array().map(Vec::len), want["contacts"].as_array().map(Vec::len), "state {k}");
    }
}
