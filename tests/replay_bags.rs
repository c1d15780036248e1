//! Replay of bags written by rosbags (MCAP and sqlite3): the same reports as `check` on the same
//! states, an output bag that rosbags and mcap-ros2-support read back, determinism, and bad bags.

mod common;

use oorandom::Rand64;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use thickness_collision::checker::Checker;
use thickness_collision::math::pose_from_isometry;
use thickness_collision::model::{bundled_config_dir, Params};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_thickness_collision"))
}

fn dir(name: &str) -> PathBuf {
    common::emptied(common::scratch_subdir("replay_bags", name))
}

fn ok(out: Output) -> String {
    assert!(out.status.success(), "failed: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).unwrap()
}

/// Random states of the bundled arm, a good share of them colliding with the workcell.
fn states(n: usize, seed: u64) -> Vec<(Vec<String>, Vec<f64>)> {
    let checker = Checker::from_params(Params::default()).unwrap();
    let mut rng = Rand64::new(seed as u128);
    (0..n)
        .map(|_| {
            let mut names = Vec::new();
            let mut pos = Vec::new();
            for j in checker.robot().joints.iter().filter(|j| j.is_actuated()) {
                let (lo, hi) = (j.limits[0].max(-3.0), j.limits[1].min(3.0));
                names.push(j.name.clone());
                pos.push(lo + (hi - lo) * rng.rand_float());
            }
            (names, pos)
        })
        .collect()
}

const T0: i64 = 1_700_000_000_000_000_000;

fn joint_messages(states: &[(Vec<String>, Vec<f64>)]) -> Vec<Value> {
    states
        .iter()
        .enumerate()
        .map(|(k, (n, p))| json!({"t": T0 + k as i64 * 10_000_000, "stamp": T0 + k as i64 * 10_000_000 - 1234, "name": n, "position": p}))
        .collect()
}

/// `check --states` lines for the states of [`joint_messages`], with the same stamps.
fn state_lines(states: &[(Vec<String>, Vec<f64>)]) -> Vec<String> {
    joint_messages(states).iter().map(|m| json!({"name": m["name"], "position": m["position"], "stamp": m["stamp"]}).to_string()).collect()
}

fn check_reference(d: &Path, lines: &[String]) -> Vec<String> {
    check_reference_with(d, lines, &[])
}

fn check_reference_with(d: &Path, lines: &[String], extra: &[&str]) -> Vec<String> {
    let f = d.join("states.jsonl");
    std::fs::write(&f, lines.join("\n") + "\n").unwrap();
    ok(bin().args(["check", "--states", f.to_str().unwrap(), "--json"]).args(extra).output().unwrap()).lines().map(str::to_owned).collect()
}

fn write_bag(path: &Path, storage: &str, messages: &[Value], description: Option<String>) {
    let _ = common::run_peer("bag_tool.py", &json!({"op": "write", "path": path, "storage": storage, "messages": messages, "robot_description": description}));
}

/// Asserts equal line lists, reporting only the first difference.
fn same_lines(got: &[String], want: &[String], what: &str) {
    if let Some(i) = (0..got.len().min(want.len())).find(|&i| got[i] != want[i]) {
        panic!("{what}: line {i} differs:\n got  {}\n want {}", got[i], want[i]);
    }
    assert_eq!(got.len(), want.len(), "{what}: line count");
}

/// `replay BAG extra...`: states on their own (`--no-motion`, as `check` without `--motion`
/// gives them) unless `extra` asks for `--motion`.
fn replay(bag: &Path, extra: &[&str]) -> Output {
    let mut c = bin();
    let _ = c.arg("replay").arg(bag).args(extra);
    if !extra.contains(&"--motion") {
        let _ = c.arg("--no-motion");
    }
    c.output().unwrap()
}

#[test]
fn joint_state_bags_replay_like_check_and_read_back() {
    let st = states(400, 7);
    let d = dir("js");
    let reference = check_reference(&d, &state_lines(&st));
    let colliding = reference.iter().filter(|l| l.contains("\"in_collision\":true")).count();
    assert!(colliding > 40 && colliding < 360, "{colliding} of 400 colliding: pick another seed");
    let motion_reference = check_reference_with(&d, &state_lines(&st), &["--motion"]);
    let motions = motion_reference.iter().skip(1).filter(|l| l.contains("\"motion\":true")).count();
    let moving_hits = motion_reference.iter().filter(|l| l.contains("\"in_collision\":true")).count();
    assert_eq!(motions, 399, "every state after the first is a motion");
    assert!(moving_hits >= colliding, "a motion into a colliding state collides: {moving_hits} < {colliding}");
    let msgs = joint_messages(&st);
    for storage in ["mcap", "sqlite3"] {
        let bag = d.join(format!("in_{storage}"));
        write_bag(&bag, storage, &msgs, None);
        let out_bag = d.join(format!("out_{storage}"));
        let jsonl = d.join(format!("out_{storage}.jsonl"));
        let summary = ok(replay(&bag, &["--jsonl", jsonl.to_str().unwrap(), "--out", out_bag.to_str().unwrap()]));
        assert!(summary.contains(&format!("states: 400, in collision: {colliding}")), "{summary}");
        let got: Vec<String> = std::fs::read_to_string(&jsonl).unwrap().lines().map(str::to_owned).collect();
        same_lines(&got, &reference, &format!("{storage}: replay vs check"));
        // With motions (the parameters' default): replay's report of each state covers the
        // motion from the one before, as `check --motion` gives it for the same path.
        let moving = d.join(format!("motion_{storage}.jsonl"));
        let _ = ok(replay(&bag, &["--motion", "--jsonl", moving.to_str().unwrap()]));
        let got: Vec<String> = std::fs::read_to_string(&moving).unwrap().lines().map(str::to_owned).collect();
        same_lines(&got, &motion_reference, &format!("{storage}: replay --motion vs check --motion"));
        // Deterministic: byte-identical JSON lines.
        let again = d.join(format!("again_{storage}.jsonl"));
        let _ = ok(replay(&bag, &["--jsonl", again.to_str().unwrap()]));
        assert_eq!(std::fs::read(&again).unwrap(), std::fs::read(&jsonl).unwrap());

        // The output bag, read back by rosbags and by mcap-ros2-support.
        let back = common::run_peer("bag_tool.py", &json!({"op": "read", "path": out_bag}));
        for reader in ["rosbags", "mcap_ros2"] {
            let msgs_back = back[reader].as_array().unwrap();
            assert_eq!(msgs_back.len(), 400, "{reader}");
            for (k, (m, r)) in msgs_back.iter().zip(&reference).enumerate() {
                let r: Value = serde_json::from_str(r).unwrap();
                assert_eq!(m["in_collision"], r["in_collision"], "{reader} state {k}");
                assert_eq!(m["contacts"].as_array().unwrap().len(), r["contacts"].as_array().unwrap().len());
                for (a, b) in m["contacts"].as_array().unwrap().iter().zip(r["contacts"].as_array().unwrap()) {
                    assert_eq!(a["link_name"], b["link_name"]);
                    assert_eq!(a["object_name"], b["object_name"]);
                    assert_eq!(a["triangle"], b["triangle"]);
                    assert_eq!(a["depth"].as_f64(), b["depth"].as_f64());
                    assert_eq!(a["position"], b["position"]);
                    assert_eq!(a["normal"], b["normal"]);
                }
                assert_eq!(m["log_time"].as_i64().unwrap(), T0 + k as i64 * 10_000_000, "stamped like the inputs");
                if reader == "rosbags" {
                    assert_eq!(m["stamp"].as_i64().unwrap(), T0 + k as i64 * 10_000_000 - 1234);
                    assert_eq!(m["frame_id"], "world");
                    assert_eq!(m["type"], "thickness_collision_msgs/msg/CollisionReport");
                } else {
                    assert_eq!(m["schema"], "thickness_collision_msgs/msg/CollisionReport");
                }
            }
        }
    }
}

#[test]
fn tf_bags_replay_like_check_with_transforms() {
    let st = states(120, 11);
    let checker = Checker::from_params(Params::default()).unwrap();
    let d = dir("tf");
    let mut msgs = Vec::new();
    let mut lines = Vec::new();
    for (k, (names, pos)) in st.iter().enumerate() {
        let mut q = vec![0.0; checker.robot().joints.len()];
        for (n, p) in names.iter().zip(pos) {
            q[checker.robot().joint(n).unwrap()] = *p;
        }
        let poses = checker.robot().forward_kinematics(&q, &nalgebra::Isometry3::identity()).unwrap();
        let mut tfs = Vec::new();
        let mut line = Vec::new();
        for t in checker.targets() {
            let p = pose_from_isometry(&poses[t.link]);
            let r = [p.rotation.x, p.rotation.y, p.rotation.z, p.rotation.w];
            tfs.push(json!({"parent": "world", "child": t.name, "translation": p.translation.to_array(), "rotation": r}));
            line.push(json!({"link": t.name, "translation": p.translation.to_array(), "rotation": r}));
        }
        msgs.push(json!({"t": T0 + k as i64 * 10_000_000, "stamp": T0 + k as i64 * 10_000_000, "transforms": tfs}));
        lines.push(json!({"transforms": line, "stamp": T0 + k as i64 * 10_000_000}).to_string());
    }
    let reference = check_reference(&d, &lines);
    // Motions between link poses: each link along the straight line and the shortest rotation.
    let motion_reference = check_reference_with(&d, &lines, &["--motion"]);
    assert_eq!(motion_reference.iter().filter(|l| l.contains("\"motion\":true")).count(), 119, "every message after the first is a motion");
    for storage in ["mcap", "sqlite3"] {
        let bag = d.join(format!("tf_{storage}"));
        write_bag(&bag, storage, &msgs, None);
        let jsonl = d.join(format!("tf_{storage}.jsonl"));
        let _ = ok(replay(&bag, &["--pose-source", "tf", "--jsonl", jsonl.to_str().unwrap()]));
        let got: Vec<String> = std::fs::read_to_string(&jsonl).unwrap().lines().map(str::to_owned).collect();
        same_lines(&got, &reference, storage);
        let moving = d.join(format!("tf_motion_{storage}.jsonl"));
        let _ = ok(replay(&bag, &["--pose-source", "tf", "--motion", "--jsonl", moving.to_str().unwrap()]));
        let got: Vec<String> = std::fs::read_to_string(&moving).unwrap().lines().map(str::to_owned).collect();
        same_lines(&got, &motion_reference, &format!("{storage}: replay --motion vs check --motion, /tf"));
    }
}

#[test]
fn robot_description_from_the_bag() {
    let st = states(50, 3);
    let d = dir("desc");
    let urdf = std::fs::read_to_string(bundled_config_dir().join("example_workcell/robot.urdf")).unwrap();
    let abs = bundled_config_dir().join("example_workcell/gripper.obj");
    let urdf = urdf.replace("filename=\"gripper.obj\"", &format!("filename=\"file://{}\"", abs.display()));
    let bag = d.join("bag");
    write_bag(&bag, "mcap", &joint_messages(&st), Some(urdf));
    let reference = check_reference(&d, &state_lines(&st));
    let jsonl = d.join("out.jsonl");
    let _ = ok(replay(&bag, &["--jsonl", jsonl.to_str().unwrap()]));
    same_lines(&std::fs::read_to_string(&jsonl).unwrap().lines().map(str::to_owned).collect::<Vec<_>>(), &reference, "description");
}

/// A bag's robot description is applied from the topic `robot_description_topic` names, and not at
/// all when it is empty, as the node's door (the fat arm in the bag: the open door follows it, the
/// closed one keeps the bundled arm).
#[test]
fn a_closed_description_door_keeps_the_robot_in_replay() {
    let st = states(60, 9);
    let d = dir("desc_closed");
    let bag = d.join("bag");
    write_bag(&bag, "mcap", &joint_messages(&st), Some(common::fat_arm_urdf()));
    let thin = check_reference(&d, &state_lines(&st));
    let fat_file = d.join("fat.urdf");
    std::fs::write(&fat_file, common::fat_arm_urdf()).unwrap();
    let fat = check_reference_with(&d, &state_lines(&st), &["--robot", fat_file.to_str().unwrap()]);
    assert_ne!(thin, fat, "the two robots must answer differently");
    let jsonl = d.join("open.jsonl");
    let _ = ok(replay(&bag, &["--jsonl", jsonl.to_str().unwrap()]));
    same_lines(&std::fs::read_to_string(&jsonl).unwrap().lines().map(str::to_owned).collect::<Vec<_>>(), &fat, "open door");
    let params = d.join("closed.yaml");
    std::fs::write(&params, "thickness_collision:\n  ros__parameters:\n    robot_description_topic: \"\"\n").unwrap();
    let jsonl = d.join("closed.jsonl");
    let _ = ok(replay(&bag, &["--params-file", params.to_str().unwrap(), "--jsonl", jsonl.to_str().unwrap()]));
    same_lines(&std::fs::read_to_string(&jsonl).unwrap().lines().map(str::to_owned).collect::<Vec<_>>(), &thin, "closed door");
}

#[test]
fn corrupt_tail_and_undecodable_message_keep_the_reports_before() {
    let st = states(3000, 5);
    let d = dir("bad");
    let reference = check_reference(&d, &state_lines(&st));

    // One undecodable message in the middle: skipped, counted, every other report kept.
    let mut msgs = joint_messages(&st);
    msgs[1500] = json!({"t": msgs[1500]["t"], "raw": [0, 1, 0, 0, 255, 255, 255]});
    for storage in ["mcap", "sqlite3"] {
        let bag = d.join(format!("undecodable_{storage}"));
        write_bag(&bag, storage, &msgs, None);
        let jsonl = d.join(format!("undecodable_{storage}.jsonl"));
        let summary = ok(replay(&bag, &["--jsonl", jsonl.to_str().unwrap()]));
        assert!(summary.contains("1 x undecodable"), "{summary}");
        let mut expected = reference.clone();
        let _ = expected.remove(1500);
        same_lines(&std::fs::read_to_string(&jsonl).unwrap().lines().map(str::to_owned).collect::<Vec<_>>(), &expected, storage);
    }

    // A truncated MCAP file: an error naming it, exit 2, and the reports before the cut kept.
    let bag = d.join("cut");
    write_bag(&bag, "mcap", &joint_messages(&st), None);
    let file = std::fs::read_dir(&bag).unwrap().map(|e| e.unwrap().path()).find(|p| p.extension().is_some_and(|e| e == "mcap")).unwrap();
    let bytes = std::fs::read(&file).unwrap();
    std::fs::write(&file, &bytes[..bytes.len() * 6 / 10]).unwrap();
    let jsonl = d.join("cut.jsonl");
    let out = replay(&bag, &["--jsonl", jsonl.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains(file.file_name().unwrap().to_str().unwrap()) && err.contains("truncated"), "{err}");
    let kept: Vec<String> = std::fs::read_to_string(&jsonl).unwrap().lines().map(str::to_owned).collect();
    assert!(kept.len() > 100 && kept.len() < 3000, "kept {}", kept.len());
    same_lines(&kept, &reference[..kept.len()], "truncated");
    eprintln!("truncated at 60%: {} of 3000 reports kept", kept.len());

    // A corrupt sqlite3 file.
    let bag = d.join("corrupt_db");
    write_bag(&bag, "sqlite3", &joint_messages(&st[..10]), None);
    let db = std::fs::read_dir(&bag).unwrap().map(|e| e.unwrap().path()).find(|p| p.extension().is_some_and(|e| e == "db3")).unwrap();
    std::fs::write(&db, b"this is not a database, it only has the name of one").unwrap();
    let out = replay(&bag, &[]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains(db.file_name().unwrap().to_str().unwrap()));
}

#[test]
fn bad_bags_are_clear_errors() {
    let d = dir("errors");
    let txt = d.join("notes.txt");
    std::fs::write(&txt, "x").unwrap();
    let out = replay(&txt, &[]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("unknown storage format"));
    let out = replay(&d.join("nothing_here.mcap"), &[]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("nothing_here.mcap"));
    let bag = d.join("bag");
    write_bag(&bag, "mcap", &joint_messages(&states(5, 1)), None);
    let out = replay(&bag, &["--topic", "/arm/joint_states"]);
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("/arm/joint_states") && err.contains("/joint_states"), "{err}");
}

/// A trajectory of the bundled arm from `start`: three points 0.5 s apart (the first after
/// 0.3 s, so the approach counts too), each joint moving up to 0.4 rad, with velocities.
fn arm_trajectory(names: &[String], start: &[f64], rng: &mut Rand64) -> Value {
    let mut p = start.to_vec();
    let points: Vec<Value> = (0..3)
        .map(|k| {
            p = p.iter().map(|x| x + 0.8 * rng.rand_float() - 0.4).collect();
            let v: Vec<f64> = p.iter().map(|_| 1.2 * rng.rand_float() - 0.6).collect();
            json!({"positions": p, "velocities": v, "t": 300_000_000 + 500_000_000 * k})
        })
        .collect();
    json!({"joint_names": names, "points": points})
}

/// `check --trajectory --json` on `trajectory` from `start` (at rest).
fn check_trajectory_cli(d: &Path, name: &str, names: &[String], start: &[f64], trajectory: &Value) -> Value {
    let file = d.join(format!("{name}.json"));
    let points: Vec<Value> = trajectory["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| {
            let t = p["t"].as_i64().unwrap();
            json!({"positions": p["positions"], "velocities": p["velocities"], "time_from_start": {"sec": t / 1_000_000_000, "nanosec": t % 1_000_000_000}})
        })
        .collect();
    std::fs::write(&file, json!({"joint_names": names, "points": points}).to_string()).unwrap();
    let joints: Vec<String> = names.iter().zip(start).map(|(n, x)| format!("{n}={x}")).collect();
    let out = ok(bin().args(["check", "--trajectory", file.to_str().unwrap(), "--json", "--joints", &joints.join(",")]).output().unwrap());
    serde_json::from_str(out.trim()).unwrap()
}

/// Issue 34, `replay --trajectory-topic`: trajectories recorded on a controller's topic between
/// joint states. Each is checked from the state recorded before it; one that runs to its first
/// contact before the next arrives answers as `check --trajectory` from that state does; one
/// preempted before its contact is free for what was executed; the last runs to its end.
#[test]
fn recorded_trajectories_replay_as_check_trajectory_answers() {
    let d = dir("trajectories");
    let (names, pool) = common::random_arm_states(400, 34);
    let params = Params::default();
    let mut pipeline = thickness_collision::pipeline::Pipeline::new(params).unwrap();
    let mut rng = Rand64::new(34);
    // Search: free starts, and trajectories from them that collide (with the contact's time).
    let mut colliding = Vec::new();
    for s in &pool {
        if colliding.len() == 3 {
            break;
        }
        let state = thickness_collision::msgs::JointState { name: names.clone(), position: s.clone(), ..Default::default() };
        if pipeline.joint_state(&state).is_err() || pipeline.checker().check_joints(&names, s).unwrap().in_collision {
            continue;
        }
        let t = arm_trajectory(&names, s, &mut rng);
        let cli = check_trajectory_cli(&d, &format!("search_{}", colliding.len()), &names, s, &t);
        if cli["in_collision"] == true && cli["error"] == "" && cli["time"].as_f64().unwrap() > 0.2 {
            colliding.push((s.clone(), t, cli));
        }
    }
    assert_eq!(colliding.len(), 3, "three colliding trajectories from free starts");
    let [(s0, c, c_cli), (s1, a, a_cli), (s2, b, b_cli)] = <[_; 3]>::try_from(colliding).unwrap();
    let (tc, ta) = (c_cli["time"].as_f64().unwrap(), a_cli["time"].as_f64().unwrap());
    let ns = |s: f64| (s * 1e9) as i64;
    // C runs past its contact; A is preempted halfway to its contact by B, which runs to its end.
    let t_c = T0 + 100_000_000;
    let t_a = t_c + ns(tc) + 300_000_000;
    let t_b = t_a + ns(ta / 2.0);
    let js = |t: i64, p: &[f64]| json!({"t": t, "stamp": t, "name": names, "position": p});
    let messages = vec![
        js(T0, &s0),
        json!({"t": t_c, "trajectory": c}),
        js(t_a - 50_000_000, &s1),
        json!({"t": t_a, "trajectory": a}),
        js(t_b - 10_000_000, &s2),
        json!({"t": t_b, "trajectory": b}),
    ];
    let bag = d.join("in");
    write_bag(&bag, "mcap", &messages, None);
    let jsonl = d.join("out.jsonl");
    let summary = ok(bin()
        .args(["replay", bag.to_str().unwrap(), "--trajectory-topic", "/joint_trajectory_controller/joint_trajectory", "--jsonl", jsonl.to_str().unwrap()])
        .output()
        .unwrap());
    assert!(summary.contains("trajectories: 3, in collision or not checked: 2"), "{summary}");
    let lines: Vec<Value> =
        std::fs::read_to_string(&jsonl).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).filter(|v: &Value| v.get("trajectory").is_some()).collect();
    assert_eq!(lines.len(), 3, "one line per trajectory: {lines:?}");
    let same = |got: &Value, want: &Value, what: &str| {
        for key in ["in_collision", "time", "segment", "fraction", "error"] {
            assert_eq!(got[key], want[key], "{what}: {key}: {got} vs {want}");
        }
        let (g, w) = (got["contacts"].as_array().unwrap(), want["contacts"].as_array().unwrap());
        assert_eq!(g.len(), w.len(), "{what}");
        for (x, y) in g.iter().zip(w) {
            for key in ["link_name", "object_name", "triangle"] {
                assert_eq!(x[key], y[key], "{what}: {key}");
            }
        }
    };
    same(&lines[0], &c_cli, "C, run past its contact");
    assert!(lines[0]["preempted_after"].as_f64().unwrap() > tc, "{}", lines[0]);
    assert_eq!((&lines[1]["in_collision"], &lines[1]["time"]), (&json!(false), &Value::Null), "A, preempted before its contact: {}", lines[1]);
    assert!((lines[1]["preempted_after"].as_f64().unwrap() - ta / 2.0).abs() < 1e-6, "{}", lines[1]);
    same(&lines[2], &b_cli, "B, run to its end");
    assert_eq!(lines[2]["preempted_after"], Value::Null);
}
