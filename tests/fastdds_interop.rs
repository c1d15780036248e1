//! Issue 14, part 1: the node against an independent ROS 2 participant on eProsima Fast DDS, the
//! default RMW of Humble and Jazzy (`tests/peers/fastdds/peer.cpp`, Debian's Fast DDS 2.9, types
//! from the Python peers' field lists through fastddsgen `-typeros2`). The peer speaks as
//! `rmw_fastrtps_cpp` does: topics `rt/...`, services `rq/<service>Request` and
//! `rr/<service>Reply` with the request id carried as the sample identity (the node runs with
//! `service_mapping:=enhanced`), and a client that accepts a reply only when its related sample
//! identity names the client's reply reader (or request writer) and the request's sequence number.
//! What is shown: joint states and `/tf` in, reports out equal to `check --json` on the same states
//! (the node with `check_motion:=false`, one report per state); a latched `robot_description`
//! published before the node starts is taken by it; `check_states`, `check_trajectory` and
//! `check_state_validity` answered equal to `check`, several clients in flight at once, each
//! answer correlated to its own request; the parameter services as `ros2 param` calls them (get,
//! set, list, describe); the latched cell markers (a late joiner, as RViz is) and `/diagnostics`.
//! Loopback only: the node with `ROS_LOCALHOST_ONLY=1`, the peer's UDPv4 transport on 127.0.0.1
//! (no shared memory, no data sharing). Domains 160-162.

mod common;

use common::fastdds::{FastDdsPeer, PeerOptions};
use common::start_node;
use serde_json::{json, Value};
use std::io::Read;
use std::path::PathBuf;
use std::process::{Child, ChildStdout, Command};

const NAMES: [&str; 7] = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint", "finger_left_joint"];

/// A deterministic arm state (the same walk as `tests/ros_node.rs`): some collide, some do not.
fn state(k: usize) -> Vec<f64> {
    let x = k as f64;
    vec![(0.37 * x).sin() * 1.5, 0.3 + (0.23 * x).cos() * 1.1, (0.11 * x).sin() * 1.6, 0.2 * x % 3.0, (0.5 * x).cos() * 1.5, 0.1 * x, 0.02]
}

fn state_json(k: usize, stamp: i64) -> Value {
    json!({"name": NAMES, "position": state(k), "stamp": stamp})
}

fn scratch(name: &str) -> PathBuf {
    common::scratch_subdir("fastdds_interop", name)
}

/// `check --states FILE --json` (plus `extra`) on JSON lines; one report per line.
/// A report (topic or `check_states`) equals check's: collision, and each contact's link, object,
/// triangle, depth, point and normal.
fn assert_same_report(got: &Value, want: &Value, what: &str) {
    assert_eq!(want["error"], "", "{what}: check could not check it: {want}");
    assert_eq!(got["error"], "", "{what}: {got}");
    common::same_report(got, want, what);
    for (a, b) in got["contacts"].as_array().unwrap().iter().zip(want["contacts"].as_array().unwrap()) {
        assert_eq!(a["object_type"], b["object_type"], "{what}: object_type");
    }
}

/// SIGTERM; the node must exit cleanly. Returns its remaining stdout and its stderr.
fn stop(mut node: Child, mut out: std::io::BufReader<ChildStdout>) -> (String, String) {
    let _ = Command::new("kill").args(["-TERM", &node.id().to_string()]).status();
    let status = node.wait().unwrap();
    let (mut rest, mut err) = (String::new(), String::new());
    let _ = out.read_to_string(&mut rest);
    let _ = node.stderr.take().unwrap().read_to_string(&mut err);
    assert!(status.success(), "node exit {status:?}: {err}");
    (rest, err)
}

fn double(x: f64) -> Value {
    json!({"type": 3, "double": x})
}

#[test]
fn fastdds_topics_services_parameters_and_latched_markers() {
    let t0 = std::time::Instant::now();
    let dir = scratch("main");
    let domain = 160;
    let (node, out, banner) = start_node(&["--ros-args", "-r", "__node:=tc_fast", "-p", "check_motion:=false", "-p", "service_mapping:=enhanced"], domain);
    assert!(banner.contains("/tc_fast") && banner.contains("loopback only"), "{banner}");
    let mut peer = FastDdsPeer::start(&PeerOptions::loopback(domain));

    // Joint states in (a reliable keep-last-10 writer, as joint_state_broadcaster offers them,
    // matched by the node's best-effort reader), reports out.
    let states: Vec<Value> = (0..25).map(|k| state_json(k, 1_000_000_000 + k as i64)).collect();
    let reference = common::check_json(&dir, "states", &states, &[]);
    assert!(reference.iter().any(|r| r["in_collision"] == true) && reference.iter().any(|r| r["in_collision"] == false));
    let a = peer.send(&json!({"cmd": "states", "states": states, "warm": common::whole_arm_warm_up(), "timeout": 30}));
    assert_eq!(a["matched"], true, "no match on joint_states/collisions: {a}");
    assert!(a["warm_reports"].as_u64().unwrap() >= 1, "the node never answered the warm-up state: {a}");
    let reports = a["reports"].as_array().unwrap();
    assert_eq!(reports.len(), states.len(), "one report per state sent one at a time");
    for (k, (got, want)) in reports.iter().zip(&reference).enumerate() {
        assert_same_report(got, want, &format!("topic, state {k}"));
        assert_eq!(got["stamp"].as_i64().unwrap(), 1_000_000_000 + k as i64, "stamped with the input's stamp");
        assert_eq!((&got["frame_id"], &got["motion"]), (&json!("world"), &json!(false)));
    }
    eprintln!("topics: {} reports equal check ({:.1} s)", reports.len(), t0.elapsed().as_secs_f64());

    // check_states from two clients at once: each gets the answer to its own request, the reply
    // naming its reply reader's GUID and its request's sequence number, and refuses the other's.
    let nan = json!({"name": ["elbow_joint", "wrist_1_joint"], "position": [0.1, "NaN"], "stamp": 8});
    let q1 = json!({"states": [state_json(0, 7), state_json(1, 7), state_json(2, 7)]});
    let q2 = json!({"states": [nan, state_json(3, 7), state_json(4, 7)]});
    let answers = peer.call("check_states", "check_states", vec![q1, q2], 20.0);
    let mut rejected = 0;
    for (c, ans) in answers.iter().enumerate() {
        assert_eq!(ans["reply_guid"], ans["reader_guid"], "client {c}: the reply names the client's reply reader, as rmw_fastrtps_cpp sets it: {ans}");
        assert!(ans["reply_seq"].as_i64().unwrap() >= 1, "client {c}: {ans}");
        rejected += ans["rejected"].as_u64().unwrap();
    }
    assert!(rejected >= 1, "each client's reader sees the other's reply and must refuse it: {answers:?}");
    let r1 = answers[0]["response"]["reports"].as_array().unwrap_or_else(|| panic!("client 0 got no answer: {}", answers[0]));
    let r2 = answers[1]["response"]["reports"].as_array().unwrap_or_else(|| panic!("client 1 got no answer: {}", answers[1]));
    assert_eq!((r1.len(), r2.len()), (3, 3), "one report per state, in order");
    for k in 0..3 {
        assert_same_report(&r1[k], &reference[k], &format!("check_states client 0, state {k}"));
    }
    assert_eq!(r2[0]["in_collision"], true, "a NaN state fails closed: {}", r2[0]);
    assert!(r2[0]["error"].as_str().unwrap().contains("non-finite"), "{}", r2[0]);
    for k in 1..3 {
        assert_same_report(&r2[k], &reference[k + 2], &format!("check_states client 1, state {}", k + 2));
    }

    // check_trajectory along the chords (`interpolation: linear`): answers equal check --motion on
    // the same waypoints.
    let trajectories: Vec<Vec<usize>> = vec![vec![0, 1, 2, 3, 4, 5], vec![6, 6], vec![10, 11, 12]];
    let requests: Vec<Value> = trajectories
        .iter()
        .map(|t| json!({"joint_names": NAMES, "interpolation": "linear", "points": t.iter().enumerate().map(|(i, &k)| json!({"positions": state(k), "t": 1_000_000_000 * (i as i64 + 1)})).collect::<Vec<_>>()}))
        .collect();
    let answers = peer.call("check_trajectory", "check_trajectory", requests, 30.0);
    let mut invalid = 0;
    for (n, (t, ans)) in trajectories.iter().zip(&answers).enumerate() {
        let got = &ans["response"];
        assert!(got.is_object(), "trajectory {n}: no answer: {ans}");
        let lines: Vec<Value> = t.iter().map(|&k| json!({"name": NAMES, "position": state(k)})).collect();
        let cli = common::check_json(&dir, &format!("trajectory{n}"), &lines, &["--motion"]);
        assert_eq!(got["error"], "", "trajectory {n}: {got}");
        match cli.iter().enumerate().skip(1).find(|(_, l)| l["in_collision"] == true) {
            None => assert_eq!((&got["valid"], &got["segment"]), (&json!(true), &json!(-1)), "trajectory {n}: {got}"),
            Some((line, want)) => {
                invalid += 1;
                assert_eq!((&got["valid"], got["segment"].as_i64()), (&json!(false), Some(line as i64 - 1)), "trajectory {n}: {got} vs {want}");
                assert_eq!(got["fraction"].as_f64(), want["fraction"].as_f64(), "trajectory {n}");
                let (g, w) = (got["contacts"].as_array().unwrap(), want["contacts"].as_array().unwrap());
                assert_eq!(g.len(), w.len(), "trajectory {n}");
                for (a, b) in g.iter().zip(w) {
                    assert_eq!((&a["link_name"], &a["object_name"]), (&b["link_name"], &b["object_name"]), "trajectory {n}");
                    assert!(common::close(&a["depth"], &b["depth"]), "trajectory {n}: depth");
                }
            }
        }
    }
    assert!(invalid >= 1 && invalid < trajectories.len(), "the trajectories cover valid and invalid answers ({invalid} invalid)");

    // check_state_validity (moveit_msgs/srv/GetStateValidity), six clients in flight at once.
    let picks = [0usize, 1, 2, 3, 4, 5];
    let requests: Vec<Value> = picks.iter().map(|&k| json!({"name": NAMES, "position": state(k), "group_name": ""})).collect();
    let answers = peer.call("check_state_validity", "check_state_validity", requests, 20.0);
    for (&k, ans) in picks.iter().zip(&answers) {
        let got = &ans["response"];
        let want = &reference[k];
        assert!(got.is_object(), "state {k}: no answer: {ans}");
        assert_eq!(got["valid"], json!(want["in_collision"] == false), "state {k}: {got} vs {want}");
        let (g, w) = (got["contacts"].as_array().unwrap(), want["contacts"].as_array().unwrap());
        assert_eq!(g.len(), w.len(), "state {k}: {got}");
        for (a, b) in g.iter().zip(w) {
            assert_eq!((&a["body_1"], &a["body_2"], &a["type_1"]), (&b["link_name"], &b["object_name"], &json!(0)), "state {k}");
            assert!(
                common::close(&a["depth"], &b["depth"]) && common::close(&a["position"], &b["position"]) && common::close(&a["normal"], &b["normal"]),
                "state {k}"
            );
        }
    }
    eprintln!("services answered ({:.1} s)", t0.elapsed().as_secs_f64());

    // The parameter services, as `ros2 param get/set/list/describe` call them.
    let get = |peer: &mut FastDdsPeer, names: &[&str]| -> Vec<Value> {
        let a = peer.call("tc_fast/get_parameters", "get_parameters", vec![json!({"names": names})], 20.0);
        a[0]["response"]["values"].as_array().cloned().unwrap_or_else(|| panic!("get_parameters: no answer: {}", a[0]))
    };
    let set = |peer: &mut FastDdsPeer, name: &str, value: Value| -> Value {
        let a = peer.call("tc_fast/set_parameters", "set_parameters", vec![json!({"parameters": [{"name": name, "value": value}]})], 20.0);
        a[0]["response"]["results"][0].clone()
    };
    let before = get(&mut peer, &["default_thickness", "world_frame", "no_such_parameter"]);
    assert_eq!((&before[0]["type"], &before[0]["double"]), (&json!(3), &json!(0.02)), "{before:?}");
    assert_eq!((&before[1]["type"], &before[1]["string"]), (&json!(4), &json!("world")), "{before:?}");
    assert_eq!(before[2]["type"], 0, "an unknown name is NOT_SET: {before:?}");
    let refused = set(&mut peer, "default_thickness", double(-1.0));
    assert_eq!(refused["successful"], false, "a negative thickness is refused: {refused}");
    assert!(!refused["reason"].as_str().unwrap_or_default().is_empty(), "with a reason: {refused}");
    let read_only = set(&mut peer, "service_mapping", json!({"type": 4, "string": "cyclone"}));
    assert_eq!(read_only["successful"], false, "service_mapping is read-only while the node runs: {read_only}");
    let accepted = set(&mut peer, "default_thickness", double(0.03));
    assert_eq!(accepted["successful"], true, "{accepted}");
    let after = get(&mut peer, &["default_thickness", "service_mapping"]);
    assert_eq!((&after[0]["double"], &after[1]["string"]), (&json!(0.03), &json!("enhanced")), "{after:?}");
    let listed = peer.call("tc_fast/list_parameters", "list_parameters", vec![json!({"prefixes": [], "depth": 0})], 20.0);
    let names: Vec<&str> =
        listed[0]["response"]["names"].as_array().unwrap_or_else(|| panic!("list_parameters: {}", listed[0])).iter().filter_map(Value::as_str).collect();
    for n in ["default_thickness", "world_frame", "check_motion", "service_mapping", "padding.values", "use_sim_time"] {
        assert!(names.contains(&n), "list_parameters lacks {n}: {names:?}");
    }
    assert!(listed[0]["response"]["prefixes"].as_array().unwrap().contains(&json!("padding")), "{}", listed[0]);
    let described =
        peer.call("tc_fast/describe_parameters", "describe_parameters", vec![json!({"names": ["default_thickness", "world_frame", "check_motion"]})], 20.0);
    let d = described[0]["response"]["descriptors"].as_array().unwrap_or_else(|| panic!("describe_parameters: {}", described[0]));
    let types: Vec<(&Value, &Value)> = d.iter().map(|x| (&x["name"], &x["type"])).collect();
    assert_eq!(types, vec![(&json!("default_thickness"), &json!(3)), (&json!("world_frame"), &json!(4)), (&json!("check_motion"), &json!(1))]);
    let kinds = peer.call(
        "tc_fast/get_parameter_types",
        "get_parameter_types",
        vec![json!({"names": ["default_thickness", "world_frame", "check_motion", "nope"]})],
        20.0,
    );
    assert_eq!(kinds[0]["response"]["types"], json!([3, 4, 1, 0]), "{}", kinds[0]);
    // set_parameters_atomically: all or nothing (an undeclared name refuses the lot).
    let atomic = |peer: &mut FastDdsPeer, params: Value| -> Value {
        let a = peer.call("tc_fast/set_parameters_atomically", "set_parameters_atomically", vec![json!({"parameters": params})], 20.0);
        a[0]["response"].clone()
    };
    let both = atomic(&mut peer, json!([{"name": "default_thickness", "value": double(0.04)}, {"name": "marker_rate", "value": double(5.0)}]));
    assert_eq!(both["successful"], true, "{both}");
    let refused = atomic(&mut peer, json!([{"name": "default_thickness", "value": double(0.05)}, {"name": "nope", "value": double(1.0)}]));
    assert_eq!(refused["successful"], false, "{refused}");
    let after = get(&mut peer, &["default_thickness", "marker_rate"]);
    assert_eq!((after[0]["double"].as_f64(), after[1]["double"].as_f64()), (Some(0.04), Some(5.0)), "the refused set changed nothing: {after:?}");
    eprintln!("parameter services answered ({:.1} s)", t0.elapsed().as_secs_f64());

    // The latched cells, read by a reader created now (a late joiner, as RViz is), and the status.
    let t_latched = std::time::Instant::now();
    let a = peer.send(&json!({"cmd": "latched", "timeout": 60}));
    let all = a["cells"].as_array().unwrap_or_else(|| panic!("no cell markers within 60 s: {a}"));
    assert_eq!((&all[0]["ns"], &all[0]["points"]), (&json!(""), &json!(0)), "a DELETEALL first: {a}");
    assert!(all.iter().any(|m| m["ns"] == "solids/table"), "the table (a solid) is drawn: {a}");
    let cells: Vec<&serde_json::Value> = all.iter().filter(|m| m["ns"].as_str().unwrap_or_default().starts_with("cells/")).collect();
    assert_eq!(cells.len(), 3, "one triangle list per thin surface: {a}");
    assert!(cells.iter().all(|m| m["type"] == 11 && m["frame"] == "world"), "{a}");
    let triangles: u64 = cells.iter().map(|m| m["points"].as_u64().unwrap() / 3).sum();
    assert_eq!(triangles, 8 * 4112, "8 triangles per cell, every cell of the workcell (under marker_max_cells)");
    eprintln!("latched cells: {} triangles after {:.1} s (2.4 MB; issue 14 part 4 is about this time)", triangles, a["cells_seconds"].as_f64().unwrap_or(-1.0));
    let status = &a["diagnostics"][0];
    assert_eq!(status["name"], "/tc_fast: collision checks", "{a}");
    let received: u64 = status["values"]["states_received"].as_str().and_then(|v| v.parse().ok()).unwrap_or(0);
    assert!(received >= 26, "states_received counts the states sent ({received}): {status}");
    for key in ["input_rate_hz", "states_checked", "states_skipped", "check_seconds_mean"] {
        assert!(status["values"][key].is_string(), "diagnostics lack {key}: {status}");
    }
    eprintln!("latched markers and /diagnostics ({:.1} s)", t_latched.elapsed().as_secs_f64());

    peer.quit();
    let (_rest, err) = stop(node, out);
    assert!(err.contains("non-finite") || err.contains("failed closed"), "the NaN state was warned about: {err}");
    eprintln!("total {:.1} s", t0.elapsed().as_secs_f64());
}

#[test]
fn fastdds_tf_input_equals_check_with_transforms() {
    use thickness_collision::checker::Checker;
    use thickness_collision::math::pose_from_isometry;
    use thickness_collision::model::Params;
    let dir = scratch("tf");
    let domain = 161;
    let (node, out, banner) = start_node(&["--ros-args", "-p", "check_motion:=false", "-p", "pose_source:=tf", "-p", "service_mapping:=enhanced"], domain);
    assert!(banner.contains("/tf"), "{banner}");
    let mut peer = FastDdsPeer::start(&PeerOptions::loopback(domain));

    // Link poses from forward kinematics, sent as world -> <link> transforms on /tf.
    let checker = Checker::from_params(Params::default()).unwrap();
    let (mut tf_states, mut lines) = (Vec::new(), Vec::new());
    for k in 0..12 {
        let mut q = vec![0.0; checker.robot().joints.len()];
        for (n, p) in NAMES.iter().zip(state(k)) {
            q[checker.robot().joint(n).unwrap()] = p;
        }
        let poses = checker.robot().forward_kinematics(&q, &nalgebra::Isometry3::identity()).unwrap();
        let (mut tfs, mut line) = (Vec::new(), Vec::new());
        for t in checker.targets() {
            let p = pose_from_isometry(&poses[t.link]);
            let r = [p.rotation.x, p.rotation.y, p.rotation.z, p.rotation.w];
            tfs.push(json!({"parent": "world", "child": t.name, "translation": p.translation.to_array(), "rotation": r}));
            line.push(json!({"link": t.name, "translation": p.translation.to_array(), "rotation": r}));
        }
        tf_states.push(json!({"stamp": 2_000_000_000 + k, "transforms": tfs}));
        lines.push(json!({"transforms": line}));
    }
    let reference = common::check_json(&dir, "tf", &lines, &[]);
    assert!(reference.iter().any(|r| r["in_collision"] == true) && reference.iter().any(|r| r["in_collision"] == false));
    let mut warm = tf_states[0].clone();
    warm["stamp"] = json!(1);
    let a = peer.send(&json!({"cmd": "states", "input": "tf", "states": tf_states, "warm": warm, "timeout": 30}));
    assert_eq!(a["matched"], true, "no match on /tf or collisions: {a}");
    let reports = a["reports"].as_array().unwrap();
    assert_eq!(reports.len(), reference.len(), "one report per /tf message: {a}");
    for (k, (got, want)) in reports.iter().zip(&reference).enumerate() {
        assert_same_report(got, want, &format!("tf state {k}"));
        assert_eq!(got["stamp"].as_i64().unwrap(), 2_000_000_000 + k as i64);
    }
    peer.quit();
    let _ = stop(node, out);
}

#[test]
fn fastdds_latched_robot_description_is_taken_by_a_node_started_after_it() {
    let dir = scratch("desc");
    let domain = 162;
    let urdf = common::fat_arm_urdf();
    let fat = dir.join("fat_arm.urdf");
    std::fs::write(&fat, &urdf).unwrap();
    let states: Vec<Value> = (0..15).map(|k| state_json(k, k as i64 + 10)).collect();
    let thin = common::check_json(&dir, "thin", &states, &[]);
    let fat_ref = common::check_json(&dir, "fat", &states, &["--robot", fat.to_str().unwrap()]);
    let colliding = |v: &[Value]| v.iter().filter(|r| r["in_collision"] == true).count();
    assert!(colliding(&fat_ref) > colliding(&thin), "the fat forearm must collide more often");

    // The description first, latched (as robot_state_publisher offers it); the node afterwards.
    let mut peer = FastDdsPeer::start(&PeerOptions::loopback(domain));
    assert_eq!(peer.send(&json!({"cmd": "description", "text": urdf}))["ok"], true);
    let (node, out, _banner) = start_node(&["--ros-args", "-p", "check_motion:=false"], domain);
    // The node's lines as they come, to wait for it to take the robot before sending states (a
    // state checked before the description's turn would be the bundled arm's).
    let (lines_tx, lines) = std::sync::mpsc::channel::<String>();
    let reader = std::thread::spawn(move || {
        for line in std::io::BufRead::lines(out).map_while(Result::ok) {
            let _ = lines_tx.send(line);
        }
    });
    let mut seen = String::new();
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(30);
    while !seen.contains("robot from robot_description") {
        match lines.recv_timeout(deadline.saturating_duration_since(std::time::Instant::now())) {
            Ok(line) => seen += &(line + "\n"),
            Err(_) => panic!("the node did not take the latched robot_description within 30 s; its output: {seen}"),
        }
    }
    let a = peer.send(&json!({"cmd": "states", "states": states, "warm": common::whole_arm_warm_up(), "timeout": 30}));
    assert_eq!(a["matched"], true, "{a}");
    let readers = peer.send(&json!({"cmd": "status"}))["description_readers"].as_u64().unwrap();
    assert!(readers >= 1, "the node's robot_description reader matched the latched writer");
    let reports = a["reports"].as_array().unwrap();
    assert_eq!(reports.len(), fat_ref.len(), "{a}");
    for (k, (got, want)) in reports.iter().zip(&fat_ref).enumerate() {
        assert_same_report(got, want, &format!("state {k}: the node must check the fat arm from the latched topic"));
    }
    peer.quit();
    let mut node = node;
    let _ = Command::new("kill").args(["-TERM", &node.id().to_string()]).status();
    let status = node.wait().unwrap();
    reader.join().unwrap();
    let rest: Vec<String> = lines.try_iter().collect();
    assert!(status.success(), "node exit {status:?}");
    assert!(rest.iter().any(|l| l.contains("shutting down")), "{rest:?}");
}

/// The parameter services follow `service_mapping`: with `cyclone` they are reached as `ros2 param`
/// on `rmw_cyclonedds_cpp` reaches them (ros2-client serves them with the enhanced mapping only;
/// the node serves them itself with the others: `src/ros/param_services.rs`). Cyclone DDS from
/// Python (`tests/peers/param_peer.py`), Cyclone's request/reply mapping.
#[test]
fn parameter_services_follow_service_mapping_cyclone() {
    let dir = scratch("params_cyclone");
    let cyclone = common::cyclone_loopback_file(&dir);
    let domain = 163;
    let (node, out, _banner) = start_node(&["--ros-args", "-r", "__node:=tc_cy", "-p", "service_mapping:=cyclone"], domain);
    let calls = json!([
        {"service": "get_parameters", "request": {"names": ["default_thickness", "world_frame", "no_such_parameter"]}},
        {"service": "set_parameters", "request": {"name": "default_thickness", "double": -1.0}},
        {"service": "set_parameters", "request": {"name": "default_thickness", "double": 0.05}},
        {"service": "get_parameters", "request": {"names": ["default_thickness"]}},
        {"service": "list_parameters", "request": {"prefixes": ["padding"], "depth": 0}},
        {"service": "describe_parameters", "request": {"names": ["default_thickness", "service_mapping", "no_such_parameter"]}},
        {"service": "get_parameter_types", "request": {"names": ["default_thickness", "world_frame", "no_such_parameter"]}},
        {"service": "set_parameters_atomically", "request": {"parameters": [{"name": "default_thickness", "double": 0.04}, {"name": "marker_rate", "double": 5.0}]}},
        {"service": "set_parameters_atomically", "request": {"parameters": [{"name": "default_thickness", "double": 0.06}, {"name": "no_such_parameter", "double": 1.0}]}},
        {"service": "set_parameters_atomically", "request": {"parameters": [{"name": "default_thickness", "double": 0.06}, {"name": "world_frame", "double": 1.0}]}},
        {"service": "get_parameters", "request": {"names": ["default_thickness", "marker_rate"]}},
    ]);
    let a = common::run_cyclone_peer("param_peer.py", &cyclone, &json!({"domain": domain, "node": "tc_cy", "calls": calls, "timeout": 20}).to_string());
    let answers = a["answers"].as_array().unwrap();
    assert!(answers.iter().all(Value::is_object), "every call answered over the Cyclone mapping: {a}");
    assert_eq!(answers[0]["values"], json!([[3, 0.02, ""], [4, 0.0, "world"], [0, 0.0, ""]]), "{a}");
    assert_eq!(answers[1]["results"][0][0], false, "a negative thickness is refused: {a}");
    assert_eq!(answers[2]["results"][0], json!([true, ""]), "{a}");
    assert_eq!(answers[3]["values"][0][1], json!(0.05), "{a}");
    assert_eq!(answers[4], json!({"names": ["padding.links", "padding.values"], "prefixes": ["padding"]}), "{a}");
    assert_eq!(answers[5], json!({"types": [3, 4, 0], "read_only": [false, true, true]}), "{a}");
    assert_eq!(answers[6], json!({"types": [3, 4, 0]}), "{a}");
    assert_eq!(answers[7]["result"], json!([true, ""]), "{a}");
    assert_eq!(answers[8]["result"][0], false, "an undeclared name refuses the lot: {a}");
    assert_eq!(answers[9]["result"][0], false, "a wrong type refuses the lot: {a}");
    assert_eq!(answers[10]["values"], json!([[3, 0.04, ""], [3, 5.0, ""]]), "the refused sets changed nothing: {a}");
    let (rest, _err) = stop(node, out);
    assert!(rest.contains("parameters changed"), "the accepted set reached the node's loop: {rest}");
}

/// Jazzy's Fast DDS (2.14) writes a request's related sample identity as PID 0x0083 (Humble's 2.9:
/// 0x800f), and cannot be installed here: the peer sends that form itself (its chaining transport
/// rewrites the PID in each outgoing DATA submessage; `pid_stats` counts the rewrites). The node
/// must read the identity from 0x0083: its reply names the client's reply reader, which only that
/// parameter carries. The control, a PID the node does not know (0x7123), shows the assertion can
/// fail: without the identity the node names the request writer (a reply rmw_fastrtps_cpp still
/// accepts, so the call is answered either way).
#[test]
fn fastdds_jazzy_related_sample_identity_pid_0x0083() {
    let domain = 164;
    let (node, out, _banner) = start_node(&["--ros-args", "-p", "check_motion:=false", "-p", "service_mapping:=enhanced"], domain);
    let request = || vec![json!({"states": [state_json(3, 5)]})];
    for (pid, names_reader) in [("0x0083", true), ("0x7123", false)] {
        let mut opts = PeerOptions::loopback(domain);
        opts.env.push(("TC_FASTDDS_RELATED_SAMPLE_IDENTITY_PID".into(), pid.into()));
        let mut peer = FastDdsPeer::start(&opts);
        let answers = peer.call("check_states", "check_states", request(), 20.0);
        let a = &answers[0];
        assert_eq!(a["response"]["reports"].as_array().map(Vec::len), Some(1), "PID {pid}: check_states answered: {a}");
        let rewritten = peer.send(&json!({"cmd": "pid_stats"}))["rewritten"].as_u64().unwrap();
        assert!(rewritten >= 1, "PID {pid}: the request went out with the rewritten PID ({rewritten} rewrites)");
        assert_eq!(a["reply_guid"] == a["reader_guid"], names_reader, "PID {pid}: the reply names the reply reader only when the node read the identity: {a}");
        peer.quit();
    }
    let _ = stop(node, out);
}
