//! The node against an independent ROS 2 participant: Cyclone DDS from Python publishes
//! `sensor_msgs/JointState` on `rt/joint_states`, reads `rt/collisions` with types built from the
//! project's own `.msg` files, and calls `check_states` (Cyclone's request/reply mapping). The
//! reports equal `check --json` on the same states (the node runs with `check_motion:=false`, one
//! report per state; motions on the node: `tests/one_pipeline.rs`). Loopback only: the node gets
//! `ROS_LOCALHOST_ONLY=1` and `ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST`, Cyclone a config with
//! `NetworkInterface 127.0.0.1`, no multicast and the peer 127.0.0.1.

mod common;

use serde_json::{json, Value};
use std::process::Command;

use common::start_node;

fn state(k: usize) -> (Vec<&'static str>, Vec<f64>) {
    let names = vec!["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint", "finger_left_joint"];
    let x = k as f64;
    let pos = vec![(0.37 * x).sin() * 1.5, 0.3 + (0.23 * x).cos() * 1.1, (0.11 * x).sin() * 1.6, 0.2 * x % 3.0, (0.5 * x).cos() * 1.5, 0.1 * x, 0.02];
    (names, pos)
}

#[test]
fn reports_over_dds_equal_check_and_bad_input_is_skipped() {
    let dir = common::scratch_subdir("ros_node", "states");
    let cyclone = common::cyclone_loopback_file(&dir);
    let domain = 100 + std::process::id() % 50;
    let params = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("config/params.yaml");
    // The node is renamed, and a parameters file applies by the node's full name (as rclcpp's).
    let renamed = dir.join("params_tc_test.yaml");
    let text = std::fs::read_to_string(&params).unwrap();
    assert!(text.contains("/**/thickness_collision:"), "config/params.yaml changed its key");
    std::fs::write(&renamed, text.replace("/**/thickness_collision:", "/**/tc_test:")).unwrap();

    let (mut node, mut out, banner) =
        start_node(&["--ros-args", "-r", "__node:=tc_test", "--params-file", renamed.to_str().unwrap(), "-p", "check_motion:=false"], domain);
    assert!(banner.contains("/tc_test") && banner.contains("loopback only"), "{banner}");

    // The states, and check's answer for them.
    let states: Vec<(Vec<&str>, Vec<f64>)> = (0..25).map(state).collect();
    let lines: Vec<String> = states.iter().map(|(n, p)| json!({"name": n, "position": p}).to_string()).collect();
    let file = dir.join("states.jsonl");
    std::fs::write(&file, lines.join("\n") + "\n").unwrap();
    // The node's parameters after the set below: default_thickness 0.2, the rest as in the file.
    let after = dir.join("params_after.yaml");
    std::fs::write(&after, std::fs::read_to_string(&params).unwrap().replace("default_thickness: 0.02", "default_thickness: 0.2")).unwrap();
    let reference = Command::new(env!("CARGO_BIN_EXE_thickness_collision"))
        .args(["check", "--params-file", after.to_str().unwrap(), "--states", file.to_str().unwrap(), "--json"])
        .output()
        .unwrap();
    assert!(reference.status.success());
    let reference: Vec<Value> = String::from_utf8(reference.stdout).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert!(reference.iter().any(|r| r["in_collision"] == true) && reference.iter().any(|r| r["in_collision"] == false));

    let big: Vec<String> = (0..100_000).map(|i| format!("j{i}")).collect();
    let bad = json!([
        {"name": ["elbow_joint"], "position": [f64::NAN.to_string()]},
        {"name": ["elbow_joint", "wrist_1_joint"], "position": [0.1]},
        {"name": big, "position": vec![0.0; 100_000]},
        {"name": ["another_robots_joint"], "position": [1.0]},
    ]);
    // check_states: good states, a NaN state and a state naming a joint the robot lacks.
    let mut service_states: Vec<Value> = states[..5].iter().map(|(n, p)| json!({"name": n, "position": p, "stamp": 7})).collect();
    service_states.insert(1, json!({"name": ["elbow_joint", "wrist_1_joint"], "position": [0.1, "NaN"], "stamp": 8}));
    service_states.insert(3, json!({"name": ["elbow_joint", "no_such_joint"], "position": [0.1, 0.2], "stamp": 9}));
    // An empty state (no joint named) must not be checked at the zero pose.
    service_states.insert(5, json!({"name": [], "position": [], "stamp": 10}));
    let request = json!({
        "domain": domain,
        "bad": bad,
        "states": states.iter().enumerate().map(|(k, (n, p))| json!({"name": n, "position": p, "stamp": 1_000_000_000 + k})).collect::<Vec<_>>(),
        "service_states": service_states,
        "timeout": 30,
        "node": "tc_test",
        "markers": true,
        "set_thickness": 0.2,
        "burst": 10_000,
    });
    let rss = |pid: u32| -> u64 {
        let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap_or_default();
        status.lines().find(|l| l.starts_with("VmRSS:")).and_then(|l| l.split_whitespace().nth(1)).and_then(|v| v.parse().ok()).unwrap_or(0)
    };
    let rss_before = rss(node.id());
    let answer = common::run_cyclone_peer("dds_peer.py", &cyclone, &request.to_string().replace("\"NaN\"", "NaN"));
    assert_eq!(answer["matched"], true, "no DDS match on loopback");
    let rss_after = rss(node.id());
    eprintln!("node RSS: {} KiB before, {} KiB after a 10,000-state burst and the bad messages", rss_before, rss_after);
    assert!(rss_before > 0 && rss_after < rss_before + 50 * 1024, "resident memory grew by more than 50 MiB");
    // The cells as RViz markers (latched: a late subscriber gets them), and the status.
    let all = answer["cells_markers"].as_array().unwrap_or_else(|| panic!("no cell markers: {answer}"));
    assert_eq!((&all[0]["ns"], &all[0]["points"]), (&json!(""), &json!(0)), "a DELETEALL first: {:?}", all[0]);
    assert!(all.iter().any(|m| m["ns"] == "solids/table"), "the table (a solid) is drawn: {all:?}");
    let cells: Vec<&serde_json::Value> = all.iter().filter(|m| m["ns"].as_str().unwrap_or_default().starts_with("cells/")).collect();
    assert_eq!(cells.len(), 3, "one triangle list per thin surface");
    let triangles: u64 = cells.iter().map(|m| m["points"].as_u64().unwrap() / 3).sum();
    assert_eq!(triangles, 8 * 4112, "8 triangles per cell, every cell of the workcell (under marker_max_cells)");
    assert!(cells.iter().all(|m| m["type"] == 11 && m["frame"] == "world"));
    let diag = &answer["diagnostics"].as_array().unwrap_or_else(|| panic!("no /diagnostics: {answer}"))[0];
    for key in ["input_rate_hz", "states_received", "states_checked", "states_skipped", "check_seconds_mean", "check_seconds_max"] {
        assert!(diag["values"][key].is_string(), "diagnostics lack {key}: {diag}");
    }
    // States are answered on RustDDS's receiving thread when the node's loop is idle (issue 14):
    // some were, here, and no more than were received.
    let count = |key: &str| diag["values"][key].as_str().and_then(|s| s.parse::<u64>().ok());
    let (taken, received) = (count("states_taken_on_receive"), count("states_received"));
    assert!(matches!((taken, received), (Some(t), Some(r)) if t > 0 && t <= r), "states taken on receive {taken:?} of {received:?}: {diag}");
    // Contact markers: a DELETEALL, then a sphere list of the contact points (when there are
    // any), at most marker_rate (10 Hz).
    let cm = answer["contact_markers"].as_array().unwrap_or_else(|| panic!("no contact markers: {answer}"));
    let seconds = answer["states_seconds"].as_f64().unwrap();
    assert!(!cm.is_empty() && cm.iter().all(|m| m["deleteall_first"] == true && (m["type"] == 7 || m["type"].is_null())), "{cm:?}");
    assert!(cm.iter().any(|m| m["points"].as_u64().unwrap() > 0), "{cm:?}");
    assert!((cm.len() as f64) <= seconds * 10.0 + 2.0, "{} contact marker messages in {seconds:.2} s exceed 10 Hz", cm.len());
    // Parameter services: get, a refused set, a set that rebuilds the cells, get again.
    assert_eq!(answer["get_before"], json!([0.02, "world"]));
    assert_eq!(answer["set_results"][0][0], false, "a negative thickness is refused: {}", answer["set_results"]);
    assert_eq!(answer["set_results"][1][0], true, "{}", answer["set_results"]);
    assert_eq!(answer["get_after"], json!(0.2));

    let reports = answer["reports"].as_array().unwrap();
    assert_eq!(reports.len(), states.len(), "one report per state sent one at a time");
    for (k, (got, want)) in reports.iter().zip(&reference).enumerate() {
        common::same_report(got, want, &format!("topic, state {k}"));
        assert_eq!(got["stamp"].as_i64().unwrap(), 1_000_000_000 + k as i64, "stamped with the input's stamp");
        assert_eq!(got["error"], "", "a checked state has no error");
        assert_eq!(got["frame_id"], "world");
    }
    let service = answer["service"].as_array().unwrap();
    assert_eq!(service.len(), 8, "check_states answers every state, bad ones in their slots");
    // Fail closed: the bad slots say in collision, with the cause.
    for (slot, cause) in [(1, "non-finite"), (3, "no_such_joint"), (5, "names no joint")] {
        assert_eq!(service[slot]["in_collision"], true, "slot {slot}: {}", service[slot]);
        assert!(service[slot]["error"].as_str().unwrap().contains(cause), "slot {slot}: {}", service[slot]);
        assert!(service[slot]["contacts"].as_array().unwrap().is_empty());
    }
    let good: Vec<&Value> = service.iter().enumerate().filter(|(k, _)| ![1, 3, 5].contains(k)).map(|(_, v)| v).collect();
    for (k, (got, want)) in good.iter().zip(&reference).enumerate() {
        common::same_report(got, want, &format!("service, state {k}"));
        assert_eq!(got["error"], "", "service, state {k}");
    }

    // SIGTERM: a clean shutdown.
    let _ = Command::new("kill").args(["-TERM", &node.id().to_string()]).status();
    let status = node.wait().unwrap();
    let mut rest = String::new();
    let _ = std::io::Read::read_to_string(&mut out, &mut rest);
    let mut err = String::new();
    let _ = std::io::Read::read_to_string(&mut node.stderr.take().unwrap(), &mut err);
    assert!(status.success(), "exit {status:?}; stderr: {err}");
    assert!(rest.contains("shutting down"), "{rest}");
    // The bad messages were warned about and skipped, the node kept running.
    assert!(err.contains("2 positions") || err.contains("1 positions"), "lengths: {err}");
    assert!(err.contains("another_robots_joint") || err.contains("not a joint"), "unknown joint: {err}");
    // A message of another robot's joints alone is skipped and counted, not checked at a pose.
    assert!(rest.contains("not_our_robot"), "{rest}");
    eprintln!("node stderr:\n{err}\nnode stdout tail: {rest}");
}

#[test]
fn tf_input_with_a_frame_prefix_equals_check_with_transforms() {
    use thickness_collision::checker::Checker;
    use thickness_collision::math::pose_from_isometry;
    use thickness_collision::model::Params;
    let dir = common::scratch_subdir("ros_node", "tf");
    let cyclone = common::cyclone_loopback_file(&dir);
    let domain = 150 + std::process::id() % 50;
    let (mut node, _out, banner) = start_node(
        &[
            "--ros-args",
            "-p",
            "check_motion:=false",
            "-r",
            "__ns:=/robot1",
            "-p",
            "pose_source:=tf",
            "-p",
            "frame_prefix:=robot1/",
            "-p",
            "use_sim_time:=true",
            "-p",
            "service_mapping:=enhanced",
        ],
        domain,
    );
    assert!(banner.contains("/robot1/thickness_collision") && banner.contains("/tf"), "{banner}");

    // Link poses from forward kinematics, sent as world -> robot1/<link> transforms.
    let checker = Checker::from_params(Params::default()).unwrap();
    let mut tf_states = Vec::new();
    let mut lines = Vec::new();
    for k in 0..12 {
        let (names, pos) = state(k);
        let mut q = vec![0.0; checker.robot().joints.len()];
        for (n, p) in names.iter().zip(&pos) {
            q[checker.robot().joint(n).unwrap()] = *p;
        }
        let poses = checker.robot().forward_kinematics(&q, &nalgebra::Isometry3::identity()).unwrap();
        let (mut tfs, mut line) = (Vec::new(), Vec::new());
        for t in checker.targets() {
            let p = pose_from_isometry(&poses[t.link]);
            let r = [p.rotation.x, p.rotation.y, p.rotation.z, p.rotation.w];
            tfs.push(json!({"parent": "world", "child": format!("robot1/{}", t.name), "translation": p.translation.to_array(), "rotation": r}));
            line.push(json!({"link": t.name, "translation": p.translation.to_array(), "rotation": r}));
        }
        tf_states.push(json!({"stamp": 2_000_000_000 + k, "transforms": tfs}));
        lines.push(json!({"transforms": line}).to_string());
    }
    let file = dir.join("tf.jsonl");
    std::fs::write(&file, lines.join("\n") + "\n").unwrap();
    let reference = Command::new(env!("CARGO_BIN_EXE_thickness_collision")).args(["check", "--states", file.to_str().unwrap(), "--json"]).output().unwrap();
    assert!(reference.status.success());
    let reference: Vec<Value> = String::from_utf8(reference.stdout).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect();

    let request = json!({"domain": domain, "ns": "/robot1", "states": [], "tf_states": tf_states, "timeout": 30,
        "clock": 42_000_000_000i64, "markers": true, "service_mapping": "enhanced",
        "service_states": [{"name": ["elbow_joint"], "position": [0.1]}]});
    let answer = common::run_cyclone_peer("dds_peer.py", &cyclone, &request.to_string().replace("\"NaN\"", "NaN"));
    let _ = Command::new("kill").args(["-TERM", &node.id().to_string()]).status();
    assert!(node.wait().unwrap().success());
    let mut err = String::new();
    let _ = std::io::Read::read_to_string(&mut node.stderr.take().unwrap(), &mut err);
    assert!(err.contains("unknown to the robot") && err.contains("camera_link"), "{err}");
    assert_eq!(answer["tf_unknown_reports"], 0, "a TF for another frame is not a robot state");
    assert_eq!(answer["tf_matched"], true);
    // use_sim_time: the node's own messages carry /clock time.
    assert_eq!(answer["diagnostics"][0]["stamp"], json!(42_000_000_000i64), "{}", answer["diagnostics"]);
    // service_mapping: enhanced, as Fast DDS and Connext speak it.
    assert_eq!(answer["service"].as_array().map(|v| v.len()), Some(1), "check_states over the enhanced mapping: {answer}");
    let reports = answer["tf_reports"].as_array().unwrap();
    assert_eq!(reports.len(), reference.len(), "one report per /tf message");
    for (k, (got, want)) in reports.iter().zip(&reference).enumerate() {
        assert_eq!(got["in_collision"], want["in_collision"], "tf state {k}");
        let (g, w) = (got["contacts"].as_array().unwrap(), want["contacts"].as_array().unwrap());
        assert_eq!(g.len(), w.len(), "tf state {k}");
        for (a, b) in g.iter().zip(w) {
            assert_eq!(a["link_name"], b["link_name"]);
            assert!((a["depth"].as_f64().unwrap() - b["depth"].as_f64().unwrap()).abs() <= 1e-9);
        }
        assert_eq!(got["stamp"].as_i64().unwrap(), 2_000_000_000 + k as i64);
    }
}

#[test]
fn robot_description_topic_replaces_the_robot_and_a_bad_one_is_refused() {
    let dir = common::scratch_subdir("ros_node", "desc");
    let cyclone = common::cyclone_loopback_file(&dir);
    let domain = 200 + std::process::id() % 30;
    let urdf = common::fat_arm_urdf();
    let fat = dir.join("fat_arm.urdf");
    std::fs::write(&fat, &urdf).unwrap();

    let (mut node, mut out, _banner) = start_node(&["--ros-args", "-p", "check_motion:=false"], domain);
    let states: Vec<(Vec<&str>, Vec<f64>)> = (0..15).map(state).collect();
    let lines: Vec<String> = states.iter().map(|(n, p)| json!({"name": n, "position": p}).to_string()).collect();
    let file = dir.join("states.jsonl");
    std::fs::write(&file, lines.join("\n") + "\n").unwrap();
    let check = |robot: Option<&std::path::Path>| -> Vec<Value> {
        let mut c = Command::new(env!("CARGO_BIN_EXE_thickness_collision"));
        let _ = c.args(["check", "--states", file.to_str().unwrap(), "--json"]);
        if let Some(r) = robot {
            let _ = c.args(["--robot", r.to_str().unwrap()]);
        }
        let o = c.output().unwrap();
        assert!(o.status.success());
        String::from_utf8(o.stdout).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect()
    };
    let (thin, fat_ref) = (check(None), check(Some(&fat)));
    let colliding = |v: &[Value]| v.iter().filter(|r| r["in_collision"] == true).count();
    assert!(colliding(&fat_ref) > colliding(&thin), "the fat forearm must collide more often");

    // Refused in turn: malformed, nothing to check (visual geometry only), unexpanded xacro.
    let visual_only = "<robot name='shown_only'><link name='a'><visual><geometry><box size='1 1 1'/></geometry></visual></link></robot>";
    let xacro = "<robot name='x' xmlns:xacro='http://www.ros.org/wiki/xacro'><xacro:include filename='arm.xacro'/></robot>";
    let request = json!({"domain": domain, "robot_descriptions": ["<robot name='broken'><link name='a'></robot>", visual_only, xacro, urdf],
        "states": states.iter().enumerate().map(|(k, (n, p))| json!({"name": n, "position": p, "stamp": k})).collect::<Vec<_>>(), "timeout": 30});
    let answer = common::run_cyclone_peer("dds_peer.py", &cyclone, &request.to_string().replace("\"NaN\"", "NaN"));
    let _ = Command::new("kill").args(["-TERM", &node.id().to_string()]).status();
    assert!(node.wait().unwrap().success());
    let mut rest = String::new();
    let _ = std::io::Read::read_to_string(&mut out, &mut rest);
    let mut err = String::new();
    let _ = std::io::Read::read_to_string(&mut node.stderr.take().unwrap(), &mut err);
    assert!(err.contains("robot_description rejected") && err.contains("malformed"), "{err}");
    assert!(err.contains("has no link to check") && err.contains("unexpanded xacro"), "{err}");
    assert!(rest.contains("robot from robot_description"), "{rest}");
    let reports = answer["reports"].as_array().unwrap();
    assert_eq!(reports.len(), fat_ref.len());
    for (k, (got, want)) in reports.iter().zip(&fat_ref).enumerate() {
        assert_eq!(got["in_collision"], want["in_collision"], "state {k}: the node must check the fat arm from the topic");
        assert_eq!(got["contacts"].as_array().unwrap().len(), want["contacts"].as_array().unwrap().len(), "state {k}");
    }
}
