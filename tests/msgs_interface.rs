//! The interface package's `.msg` and `.srv` files parse with rosbags' `get_types_from_msg`,
//! and define the fields the Rust types serialise, in the same order.

mod common;

use serde_json::json;

#[test]
fn msg_and_srv_files_parse_with_rosbags() {
    let types = common::run_peer("bag_tool.py", &json!({"op": "parse"}));
    for name in [
        "thickness_collision_msgs/msg/Contact",
        "thickness_collision_msgs/msg/CollisionReport",
        "thickness_collision_msgs/srv/CheckStates_Request",
        "thickness_collision_msgs/srv/CheckStates_Response",
    ] {
        let parsed: Vec<&str> = types[name].as_array().unwrap_or_else(|| panic!("{name} missing: {types}")).iter().map(|v| v.as_str().unwrap()).collect();
        // rosbags files service parts under `pkg/srv/msg/Type`.
        let short = name.rsplit('/').next().unwrap();
        assert!(parsed.iter().any(|p| p.starts_with("thickness_collision_msgs/") && p.ends_with(&format!("/{short}"))), "{name}: {parsed:?}");
    }
    // Field order is wire order: compare with the serde structs' order.
    let contact = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/interfaces/thickness_collision_msgs/msg/Contact.msg")).unwrap();
    let fields: Vec<&str> = contact.lines().filter_map(|l| l.split('#').next()).filter_map(|l| l.split_whitespace().nth(1)).collect();
    assert_eq!(fields, ["link_name", "object_name", "triangle", "depth", "position", "normal"]);
    let report = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/interfaces/thickness_collision_msgs/msg/CollisionReport.msg")).unwrap();
    let fields: Vec<&str> = report.lines().filter_map(|l| l.split('#').next()).filter_map(|l| l.split_whitespace().nth(1)).collect();
    assert_eq!(fields, ["header", "in_collision", "contacts", "check_seconds", "error", "motion", "fraction"]);
    let c = thickness_collision::msgs::ContactMsg::default();
    let v = serde_json::to_value(&c).unwrap();
    let keys: Vec<&String> = v.as_object().unwrap().keys().collect();
    assert_eq!(keys.len(), 6);
}
