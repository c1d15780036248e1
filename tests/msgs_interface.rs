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
        "thickness_collision_msgs/msg/Clearance",
        "thickness_collision_msgs/srv/CheckStates_Request",
        "thickness_collision_msgs/srv/CheckStates_Response",
        "thickness_collision_msgs/srv/CheckTrajectory_Request",
        "thickness_collision_msgs/srv/CheckTrajectory_Response",
    ] {
        let parsed: Vec<&str> = types[name].as_array().unwrap_or_else(|| panic!("{name} missing: {types}")).iter().map(|v| v.as_str().unwrap()).collect();
        // rosbags files service parts under `pkg/srv/msg/Type`.
        let short = name.rsplit('/').next().unwrap();
        assert!(parsed.iter().any(|p| p.starts_with("thickness_collision_msgs/") && p.ends_with(&format!("/{short}"))), "{name}: {parsed:?}");
    }
    // Field order is wire order: compare with the serde structs' order.
    let contact = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/interfaces/thickness_collision_msgs/msg/Contact.msg")).unwrap();
    // Constants (`uint8 ROBOT_LINK=1`) are not fields.
    let fields: Vec<&str> =
        contact.lines().filter_map(|l| l.split('#').next()).filter_map(|l| l.split_whitespace().nth(1)).filter(|f| !f.contains('=')).collect();
    assert_eq!(fields, ["link_name", "object_name", "triangle", "depth", "position", "normal", "object_type", "link_type"]);
    let report = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/interfaces/thickness_collision_msgs/msg/CollisionReport.msg")).unwrap();
    let fields: Vec<&str> = report.lines().filter_map(|l| l.split('#').next()).filter_map(|l| l.split_whitespace().nth(1)).collect();
    assert_eq!(fields, ["header", "in_collision", "contacts", "check_seconds", "error", "motion", "fraction", "clearances"]);
    let r = serde_json::to_value(thickness_collision::msgs::CollisionReport::default()).unwrap();
    assert_eq!(r.as_object().unwrap().len(), fields.len());
    assert!(r["clearances"].is_array());
    let clearance = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/interfaces/thickness_collision_msgs/msg/Clearance.msg")).unwrap();
    let lines: Vec<(&str, &str)> =
        clearance.lines().filter_map(|l| l.split('#').next()).filter_map(|l| Some((l.split_whitespace().next()?, l.split_whitespace().nth(1)?))).collect();
    assert_eq!(
        lines,
        [
            ("string", "link_name"),
            ("string", "object_name"),
            ("uint32", "triangle"),
            ("float64", "distance"),
            ("geometry_msgs/Point", "point_on_link"),
            ("geometry_msgs/Point", "point_on_object")
        ]
    );
    // serde_json sorts keys: compare the names as sets (the wire order is the struct's, checked
    // by the round trip through the peer's types in the bag tests).
    let c = serde_json::to_value(thickness_collision::msgs::ClearanceMsg::default()).unwrap();
    let mut keys: Vec<&str> = c.as_object().unwrap().keys().map(String::as_str).collect();
    let mut names: Vec<&str> = lines.iter().map(|(_, n)| *n).collect();
    keys.sort_unstable();
    names.sort_unstable();
    assert_eq!(keys, names);
    let c = thickness_collision::msgs::ContactMsg::default();
    let v = serde_json::to_value(&c).unwrap();
    let keys: Vec<&String> = v.as_object().unwrap().keys().collect();
    assert_eq!(keys.len(), 8);
}

/// `CheckTrajectory.srv`'s two parts against the serde structs the node sends and receives (field
/// order is wire order), and its types against the ROS packages the interface package depends on.
#[test]
fn check_trajectory_srv_matches_the_rust_types() {
    let root = env!("CARGO_MANIFEST_DIR");
    let text = std::fs::read_to_string(format!("{root}/interfaces/thickness_collision_msgs/srv/CheckTrajectory.srv")).unwrap();
    let (request, response) = text.split_once("---").unwrap();
    let fields = |part: &str| -> Vec<(String, String)> {
        part.lines()
            .filter_map(|l| l.split('#').next())
            .filter_map(|l| {
                let mut w = l.split_whitespace();
                Some((w.next()?.to_owned(), w.next()?.to_owned()))
            })
            .collect()
    };
    // The struct's fields in serialisation order (a `Value` would sort them): where each name
    // first appears in the JSON text, the nested ones left out by taking only top-level names.
    let keys = |text: String| -> Vec<String> {
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        let mut names: Vec<(usize, String)> = v.as_object().unwrap().keys().map(|k| (text.find(&format!("\"{k}\":")).unwrap(), k.clone())).collect();
        names.sort();
        names.into_iter().map(|n| n.1).collect()
    };
    let (req, resp) = (fields(request), fields(response));
    let want_req = [("trajectory_msgs/JointTrajectory", "trajectory"), ("string", "interpolation"), ("float64[]", "path_tolerance")];
    assert_eq!(req, want_req.map(|(t, n)| (t.to_owned(), n.to_owned())));
    let req_keys = keys(serde_json::to_string(&thickness_collision::msgs::CheckTrajectoryRequest::default()).unwrap());
    assert_eq!(req.iter().map(|f| f.1.clone()).collect::<Vec<_>>(), req_keys);
    let resp_keys = keys(serde_json::to_string(&thickness_collision::msgs::CheckTrajectoryResponse::default()).unwrap());
    assert_eq!(resp.iter().map(|f| f.1.clone()).collect::<Vec<_>>(), resp_keys);
    let types: Vec<&str> = resp.iter().map(|f| f.0.as_str()).collect();
    assert_eq!(types, ["bool", "int32", "float64", "builtin_interfaces/Duration", "Contact[]", "string", "Clearance[]"]);
    // trajectory_msgs/JointTrajectory and JointTrajectoryPoint as ROS defines them.
    let traj = keys(serde_json::to_string(&thickness_collision::msgs::JointTrajectory::default()).unwrap());
    assert_eq!(traj, ["header", "joint_names", "points"]);
    let point = keys(serde_json::to_string(&thickness_collision::msgs::JointTrajectoryPoint::default()).unwrap());
    assert_eq!(point, ["positions", "velocities", "accelerations", "effort", "time_from_start"]);
    // The interface package declares the packages the service uses.
    let cmake = std::fs::read_to_string(format!("{root}/interfaces/thickness_collision_msgs/CMakeLists.txt")).unwrap();
    let package = std::fs::read_to_string(format!("{root}/interfaces/thickness_collision_msgs/package.xml")).unwrap();
    for dep in ["trajectory_msgs", "builtin_interfaces"] {
        assert!(cmake.contains(&format!("find_package({dep} REQUIRED)")) && cmake.contains(&format!(" {dep}")), "CMakeLists.txt: {dep}");
        assert!(package.contains(&format!("<depend>{dep}</depend>")), "package.xml: {dep}");
    }
    assert!(cmake.contains("\"srv/CheckTrajectory.srv\""));
}

/// A Cyclone DDS peer's `moveit_msgs/CollisionObject` and `PlanningScene` (IDL types built from
/// `moveit_msgs`' definitions, `tests/peers/moveit_types.py`) serialise to the bytes kept in
/// `tests/fixtures/planning_scene/`, which the crate's unit tests decode to the same messages
/// and encode back byte for byte (`src/msgs/planning_scene_tests.rs`).
#[test]
fn a_cyclone_peers_planning_scene_bytes_are_the_fixtures() {
    let answer = common::run_peer("scene_cdr.py", &json!({}));
    let fixtures = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/planning_scene");
    for name in ["collision_object", "planning_scene"] {
        let hex = answer[name].as_str().unwrap_or_else(|| panic!("{name} missing: {answer}"));
        let peer: Vec<u8> = (0..hex.len()).step_by(2).map(|i| u8::from_str_radix(&hex[i..i + 2], 16).unwrap()).collect();
        let kept = std::fs::read(format!("{fixtures}/{name}.cdr")).unwrap();
        assert_eq!(peer, kept, "{name}: the peer's bytes differ from the fixture");
    }
}
