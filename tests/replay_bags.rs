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
