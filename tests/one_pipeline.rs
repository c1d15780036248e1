//! One pipeline, two doors: the same message sequences, sent live to the running node over DDS
//! by an independent participant (Cyclone DDS from Python) and written by `rosbags` into a bag
//! with the same stamps for `replay`, give equal reports (flags, links, depths, stamps, errors)
//! and equal skip counts per cause. (a) joint states: partial states from two publishers, a NaN
//! state, a wrong-length state, unknown names; (b) `/tf` with `frame_prefix: robot1/`: prefixed
//! frames, `/tf_static`, another robot's frames, a non-finite transform, a frame that does not
//! reach the world. Also `check_states`: bad states fail closed in their slots, good ones equal
//! `check --json`. Loopback only (see tests/ros_node.rs).

mod common;

use serde_json::{json, Value};
use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use thickness_collision::checker::Checker;
use thickness_collision::math::pose_from_isometry;
use thickness_collision::model::Params;

const ARM: [&str; 6] = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint"];
const FINGER: &str = "finger_left_joint";
const T0: i64 = 1_700_000_000_000_000_000;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_thickness_collision"))
}

fn dir(name: &str) -> PathBuf {
    common::emptied(common::scratch_subdir("one_pipeline", name))
}

/// Arm positions that sweep the bundled arm through the workcell (some colliding, some not).
fn arm(k: usize) -> Vec<f64> {
    let x = k as f64;
    vec![(0.37 * x).sin() * 1.5, 0.3 + (0.23 * x).cos() * 1.1, (0.11 * x).sin() * 1.6, 0.2 * x % 3.0, (0.5 * x).cos() * 1.5, 0.1 * x]
}

fn js(k: usize, names: Vec<&str>, position: Vec<Value>) -> Value {
    let t = T0 + k as i64 * 10_000_000;
    json!({"topic": "/joint_states", "t": t, "stamp": t - 777, "name": names, "position": position})
}

fn nums(v: &[f64]) -> Vec<Value> {
    v.iter().map(|x| json!(x)).collect()
}

/// (a): a full state first (the live peer's warm-up), then partial states from an arm publisher
/// and a gripper publisher, and the bad ones.
fn joint_sequence() -> Vec<Value> {
    let mut m = Vec::new();
    let full = |k: usize| {
        let mut names = ARM.to_vec();
        names.push(FINGER);
        let mut p = arm(k);
        p.push(0.01);
        (names, nums(&p))
    };
    let (n, p) = full(0);
    m.push(js(0, n, p));
    for (k, step) in (1..).zip(0..18) {
        let msg = match step {
            3 => js(k, vec!["elbow_joint", "wrist_1_joint"], vec![json!(0.2), json!("NaN")]),
            6 => js(k, ARM[..3].to_vec(), nums(&arm(k)[..2])),
            9 => {
                let mut names = vec!["robot2/elbow_joint", "robot2/wrist_1_joint"];
                names.extend(ARM);
                let mut p = vec![json!(9.0), json!("NaN")];
                p.extend(nums(&arm(k)));
                js(k, names, p)
            }
            12 => js(k, vec![], vec![]),
            s if s % 2 == 0 => js(k, ARM.to_vec(), nums(&arm(k))),
            _ => js(k, vec![FINGER], vec![json!(0.001 * k as f64)]),
        };
        m.push(msg);
    }
    m
}

fn tf_of(k: usize, prefix: &str, parent: &str, q: &[f64]) -> Value {
    let checker = Checker::from_params(Params::default()).unwrap();
    let mut full = vec![0.0; checker.robot().joints.len()];
    for (n, v) in ARM.iter().zip(q) {
        full[checker.robot().joint(n).unwrap()] = *v;
    }
    let poses = checker.robot().forward_kinematics(&full, &nalgebra::Isometry3::identity()).unwrap();
    let transforms: Vec<Value> = checker
        .targets()
        .iter()
        .map(|t| {
            let p = pose_from_isometry(&poses[t.link]);
            json!({"parent": parent, "child": format!("{prefix}{}", t.name), "translation": p.translation.to_array(), "rotation": [p.rotation.x, p.rotation.y, p.rotation.z, p.rotation.w]})
        })
        .collect();
    let t = T0 + k as i64 * 10_000_000;
    json!({"topic": "/tf", "t": t, "stamp": t - 555, "transforms": transforms})
}

/// (b): prefixed frames of robot1, /tf_static, another robot, a NaN, an unreachable parent.
fn tf_sequence() -> Vec<Value> {
    let mut m = vec![tf_of(0, "robot1/", "world", &arm(0))];
    let t = T0 + 5_000_000;
    m.push(json!({"topic": "/tf_static", "t": t, "stamp": t, "transforms": [{"parent": "world", "child": "robot1/odom", "translation": [0.0, 0.0, 0.0], "rotation": [0.0, 0.0, 0.0, 1.0]}]}));
    for k in 1..14 {
        let msg = match k {
            3 => tf_of(k, "robot2/", "world", &arm(k)),
            5 => {
                let mut bad = tf_of(k, "robot1/", "world", &arm(k));
                bad["transforms"][2]["translation"][1] = json!("NaN");
                bad
            }
            7 => tf_of(k, "robot1/", "robot1/not_connected", &arm(k)),
            k if k % 2 == 0 => tf_of(k, "robot1/", "robot1/odom", &arm(k)),
            _ => tf_of(k, "robot1/", "world", &arm(k)),
        };
        m.push(msg);
    }
    m
}

fn cyclone_config(d: &Path) -> PathBuf {
    let f = d.join("cyclone.xml");
    std::fs::write(&f, common::CYCLONE_LOOPBACK).unwrap();
    f
}

fn peer(request: &Value, cyclone: Option<&Path>) -> Value {
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/peers/sequence_peer.py");
    let mut c = Command::new(common::python());
    let _ = c.arg(&script).stdin(Stdio::piped()).stdout(Stdio::piped()).stderr(Stdio::piped());
    if let Some(f) = cyclone {
        let _ = c.env("CYCLONEDDS_URI", format!("file://{}", f.display()));
    }
    let mut child = c.spawn().unwrap();
    child.stdin.take().unwrap().write_all(request.to_string().as_bytes()).unwrap();
    let o = child.wait_with_output().unwrap();
    assert!(o.status.success(), "sequence_peer.py: {}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}

/// Runs the node with `args` (loopback only) while the peer sends `messages`; returns the reports
/// and the node's skip counts by cause from its last `/diagnostics`.
fn live(messages: &[Value], args: &[&str], domain: u32, d: &Path) -> (Vec<Value>, BTreeMap<String, u64>) {
    let (mut node, _out, _banner) = common::start_node(args, domain);
    let answer = peer(&json!({"op": "live", "domain": domain, "messages": messages, "timeout": 30}), Some(&cyclone_config(d)));
    let _ = Command::new("kill").args(["-TERM", &node.id().to_string()]).status();
    assert!(node.wait().unwrap().success());
    let mut err = String::new();
    let _ = std::io::Read::read_to_string(&mut node.stderr.take().unwrap(), &mut err);
    eprintln!("node stderr:\n{err}");
    let diag = answer["diagnostics"].as_object().unwrap_or_else(|| panic!("no /diagnostics: {answer}"));
    let skips = diag
        .iter()
        .filter_map(|(k, v)| Some((k.strip_prefix("skipped_")?.to_owned(), v.as_str()?.parse::<u64>().ok()?)))
        .filter(|(k, n)| k != "stale" && *n > 0)
        .collect();
    (answer["reports"].as_array().unwrap().clone(), skips)
}

/// Replays `messages` from a bag written by rosbags; returns the JSON lines and the skip counts
/// from the summary.
fn replayed(messages: &[Value], params: &Path, d: &Path, storage: &str) -> (Vec<Value>, BTreeMap<String, u64>) {
    let bag = d.join(format!("bag_{storage}"));
    let _ = peer(&json!({"op": "bag", "path": bag, "storage": storage, "messages": messages}), None);
    let jsonl = d.join(format!("out_{storage}.jsonl"));
    let topic = if messages.iter().any(|m| m["topic"] == "/tf") { "/tf" } else { "/joint_states" };
    let o =
        bin().arg("replay").arg(&bag).args(["--params-file", params.to_str().unwrap(), "--topic", topic, "--jsonl", jsonl.to_str().unwrap()]).output().unwrap();
    let summary = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(o.status.success(), "replay: {}\n{summary}", String::from_utf8_lossy(&o.stderr));
    let mut skips = BTreeMap::new();
    // "skipped messages: N", then "  n x cause" per cause.
    for line in summary.lines().skip_while(|l| !l.starts_with("skipped messages:")).skip(1).filter_map(|l| l.trim().split_once(" x ")) {
        let _ = skips.insert(line.1.to_owned(), line.0.parse::<u64>().unwrap());
    }
    let lines = std::fs::read_to_string(&jsonl).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    (lines, skips)
}

fn same_reports(live: &[Value], replayed: &[Value], what: &str) {
    assert_eq!(live.len(), replayed.len(), "{what}: report count, live {live:?}\nreplayed {replayed:?}");
    for (k, (a, b)) in live.iter().zip(replayed).enumerate() {
        assert_eq!(a["stamp"], b["stamp"], "{what}: report {k} stamp");
        assert_eq!(a["in_collision"], b["in_collision"], "{what}: report {k}");
        assert_eq!(a["error"], b["error"], "{what}: report {k}");
        let (ca, cb) = (a["contacts"].as_array().unwrap(), b["contacts"].as_array().unwrap());
        assert_eq!(ca.len(), cb.len(), "{what}: report {k}: colliding links");
        for (x, y) in ca.iter().zip(cb) {
            for f in ["link_name", "object_name", "triangle"] {
                assert_eq!(x[f], y[f], "{what}: report {k}: {f}");
            }
            assert!((x["depth"].as_f64().unwrap() - y["depth"].as_f64().unwrap()).abs() <= 1e-9, "{what}: report {k}: depth");
        }
    }
}

fn params_file(d: &Path, extra: &str) -> PathBuf {
    let f = d.join("params.yaml");
    std::fs::write(&f, format!("thickness_collision:\n  ros__parameters:\n{extra}")).unwrap();
    f
}

#[test]
fn joint_states_live_and_replayed_give_the_same_reports_and_skips() {
    let d = dir("js");
    let messages = joint_sequence();
    let params = params_file(&d, "    missing_joint: last\n");
    let (live_reports, live_skips) = live(&messages, &["--params-file", params.to_str().unwrap()], 120 + std::process::id() % 40, &d);
    // 19 messages: the NaN one, the wrong-length one and the empty one (it names none of the
    // robot's joints) give no report.
    assert_eq!(live_reports.len(), messages.len() - 3, "{live_reports:?}");
    assert!(live_reports.iter().any(|r| r["in_collision"] == true) && live_reports.iter().any(|r| r["in_collision"] == false));
    assert!(live_reports.iter().all(|r| r["error"] == "" && r["frame_id"] == "world"));
    assert_eq!(live_skips, BTreeMap::from([("lengths".to_owned(), 1), ("non_finite".to_owned(), 1), ("not_our_robot".to_owned(), 1)]));
    for storage in ["mcap", "sqlite3"] {
        let (lines, skips) = replayed(&messages, &params, &d, storage);
        same_reports(&live_reports, &lines, storage);
        assert_eq!(skips, live_skips, "{storage}: skips by cause");
    }
}

#[test]
fn tf_with_a_frame_prefix_live_and_replayed_give_the_same_reports_and_skips() {
    let d = dir("tf");
    let messages = tf_sequence();
    let params = params_file(&d, "    pose_source: tf\n    frame_prefix: robot1/\n");
    let (live_reports, live_skips) = live(&messages, &["--params-file", params.to_str().unwrap()], 160 + std::process::id() % 40, &d);
    // 15 messages: /tf_static, robot2's, the NaN and the unreachable one give no report.
    assert_eq!(live_reports.len(), messages.len() - 4, "{live_reports:?}");
    assert!(live_reports.iter().any(|r| r["in_collision"] == true) && live_reports.iter().any(|r| r["in_collision"] == false));
    let want = BTreeMap::from([("bad_transform".to_owned(), 1), ("not_our_robot".to_owned(), 1), ("unreachable".to_owned(), 1)]);
    assert_eq!(live_skips, want);
    let (lines, skips) = replayed(&messages, &params, &d, "mcap");
    same_reports(&live_reports, &lines, "tf");
    assert_eq!(skips, live_skips);
    // Without the prefix every message is somebody else's: nothing is reported as checked.
    let plain = params_file(&d, "    pose_source: tf\n");
    let (lines, skips) = replayed(&messages, &plain, &d, "sqlite3");
    assert!(lines.is_empty(), "{lines:?}");
    assert_eq!(skips.get("not_our_robot"), Some(&((messages.len() - 2) as u64)), "every /tf but the NaN one");
    assert_eq!(skips.get("bad_transform"), Some(&1));
}

#[test]
fn a_robot_description_in_the_bag_applies_from_its_log_time() {
    let d = dir("desc");
    let urdf = common::fat_arm_urdf();
    let fat = d.join("fat_arm.urdf");
    std::fs::write(&fat, &urdf).unwrap();
    let mut names = ARM.to_vec();
    names.push(FINGER);
    let states: Vec<Value> = (0..40).map(|k| js(k, names.clone(), nums(&[arm(k), vec![0.01]].concat()))).collect();
    let mut messages = states.clone();
    let at = states[20]["t"].as_i64().unwrap() - 1;
    messages.insert(20, json!({"topic": "/robot_description", "t": at, "data": urdf}));
    // States on their own, as `check` without `--motion` gives them.
    let params = params_file(&d, "    missing_joint: last\n    check_motion: false\n");
    let (lines, _) = replayed(&messages, &params, &d, "mcap");
    // check on the same states: the parameters' robot, and the fat one.
    let file = d.join("states.jsonl");
    let text: Vec<String> = states.iter().map(|m| json!({"name": m["name"], "position": m["position"], "stamp": m["stamp"]}).to_string()).collect();
    std::fs::write(&file, text.join("\n") + "\n").unwrap();
    let check = |robot: Option<&Path>| -> Vec<Value> {
        let mut c = bin();
        let _ = c.args(["check", "--params-file", params.to_str().unwrap(), "--states", file.to_str().unwrap(), "--json"]);
        if let Some(r) = robot {
            let _ = c.args(["--robot", r.to_str().unwrap()]);
        }
        let o = c.output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        String::from_utf8(o.stdout).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect()
    };
    let (thin, fat) = (check(None), check(Some(&fat)));
    let differ = |range: std::ops::Range<usize>| range.filter(|&k| thin[k]["contacts"] != fat[k]["contacts"]).count();
    assert!(differ(0..20) > 0 && differ(20..40) > 0, "the fat forearm must change some answers on both sides");
    same_reports(&lines[..20], &thin[..20], "before the description");
    same_reports(&lines[20..], &fat[20..], "after the description");
}

/// The bundled arm at three states (every joint but the finger's mimic): A and C close together
/// in front of the workcell's surfaces, B on the far side. Each state is free and so is the
/// straight motion A → C, but A → B crosses the guard sheet and B → C the shelf: a node that
/// drops B when it falls behind reports a free motion that was not.
const TRIPLE: [[f64; 7]; 3] = [
    [2.3262656677907794, 0.6818684280582978, 2.39428789294752, 2.276771623960049, 1.4581508272089656, 1.2689149002932716, 0.01847976994306216],
    [-2.636566638810667, -0.5700379417947858, 1.5543806482359694, 1.5653099275652815, -0.5548617135963831, -2.789680498270184, 0.03316370801149869],
    [2.3489918091071202, 0.7010671794714393, 2.385904178256132, 2.285909494944286, 1.4359962858749236, 1.257838600196322, 0.01883300333765152],
];
const TOOL0: [f64; 3] = [-1.915057823936282, -1.8962443176668413, -1.9291643109626693];

fn triple_names() -> Vec<&'static str> {
    let mut names = ARM.to_vec();
    names.extend([FINGER, "tool0_joint"]);
    names
}

fn triple_state(i: usize) -> Vec<f64> {
    let mut q = TRIPLE[i].to_vec();
    q.push(TOOL0[i]);
    q
}

/// `check --states` (with `--motion` or not) on the given states of [`TRIPLE`], as JSON reports.
fn check_path(order: &[usize], motion: bool, d: &Path) -> Vec<Value> {
    let f = d.join("triple.jsonl");
    let lines: Vec<String> = order.iter().map(|&i| json!({"name": triple_names(), "position": triple_state(i)}).to_string()).collect();
    std::fs::write(&f, lines.join("\n") + "\n").unwrap();
    let mut cmd = bin();
    let _ = cmd.args(["check", "--json", "--states", f.to_str().unwrap()]);
    if motion {
        let _ = cmd.arg("--motion");
    }
    let o = cmd.output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8(o.stdout).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect()
}

/// Issue 12: states the node falls behind on. The node answers a few states waiting at once with a
/// report each (as replay does); past 64 it is behind, and the oldest share one report, which must
/// cover every state in it. Each round stops the node (SIGSTOP, as a stalled machine would), sends
/// 15 states A, B and 75 states C back to back (within the 100 the reader keeps), and resumes it:
/// B is among the oldest, and the report that covers it must cover the polyline A → B → C, not
/// only its newest state. With
/// `check_motion:=false` the same rounds show what is missed without it. The node must also come
/// back from each stop: unpatched, RustDDS's event loops ended at the first SIGCONT (EINTR,
/// `vendor/rustdds/PATCHES.md` change 11) and nothing was answered after it.
#[test]
fn a_state_the_node_falls_behind_on_is_still_covered_by_the_next_report() {
    let d = dir("skipped");
    // The premises, from `check`: every state free, A → C free, A → B and B → C not.
    let discrete = check_path(&[0, 1, 2], false, &d);
    assert!(discrete.iter().all(|r| r["in_collision"] == false), "{discrete:?}");
    let straight = check_path(&[0, 2, 0], true, &d);
    assert!(straight.iter().all(|r| r["in_collision"] == false), "A -> C -> A: {straight:?}");
    let through = check_path(&[0, 1, 2], true, &d);
    assert!(through[1]["in_collision"] == true && through[2]["in_collision"] == true, "A -> B -> C: {through:?}");

    const ROUNDS: usize = 30;
    // More than the 64 states the node answers one by one.
    const CS: usize = 75;
    const AS: usize = 15;
    let messages = |pid: u32, b_stamps: &mut Vec<i64>| {
        let mut messages = Vec::new();
        let mut k = 0;
        let mut msg = |i: usize, burst: bool| {
            let t = T0 + k as i64 * 10_000_000;
            k += 1;
            json!({"topic": "/joint_states", "t": t, "stamp": t, "name": triple_names(), "position": nums(&triple_state(i)), "burst": burst})
        };
        messages.push(msg(0, false)); // the warm-up
        for _ in 0..ROUNDS {
            messages.push(json!({"signal": "STOP", "pid": pid, "burst": true}));
            // A, held: the node takes the first states as they come in (it is woken by the
            // first), so B comes later, in a turn that finds the rest waiting.
            for _ in 0..AS {
                messages.push(msg(0, true));
            }
            b_stamps.push(messages.last().unwrap()["stamp"].as_i64().unwrap() + 10_000_000);
            messages.push(msg(1, true));
            for _ in 0..CS {
                messages.push(msg(2, true));
            }
            // Resumed, the node finds them all waiting; the peer waits for the report of the
            // last C, so that the next round does not stop the node with states of this one still
            // in its reader, where the next round's 91 could push them out of the 100 it keeps
            // (covered by nothing: the test's count of states received fails). Before, the peer
            // went on 50 ms after the round's first report; a CI host once failed this test.
            let last = messages.last().unwrap()["stamp"].as_i64().unwrap();
            messages.push(json!({"signal": "CONT", "pid": pid, "burst": false, "until": last, "wait": 5}));
        }
        messages
    };
    for motion in [true, false] {
        // Domains of their own (the other tests here use 120-199).
        let domain = if motion { 70 } else { 90 } + std::process::id() % 20;
        let (mut node, _out, _banner) = common::start_node(&["--ros-args", "-p", &format!("check_motion:={motion}")], domain);
        let mut b_stamps = Vec::new();
        let messages = messages(node.id(), &mut b_stamps);
        let answer = peer(&json!({"op": "live", "domain": domain, "messages": messages, "timeout": 30}), Some(&cyclone_config(&d)));
        // A peer that failed half-way must not leave the node stopped.
        let _ = Command::new("kill").args(["-CONT", &node.id().to_string()]).status();
        let _ = Command::new("kill").args(["-TERM", &node.id().to_string()]).status();
        assert!(node.wait().unwrap().success());
        let reports: Vec<Value> = answer["reports"].as_array().unwrap().iter().filter(|r| r["stamp"].as_i64() > Some(T0)).cloned().collect();
        let received: u64 = answer["diagnostics"]["states_received"].as_str().and_then(|s| s.parse().ok()).unwrap_or(0);
        // Every state reached the node (best-effort on loopback, three at a time): a state lost
        // in transport is covered by nothing, and the test could not tell.
        let sent = (AS + 1 + CS) * ROUNDS;
        assert!(received > sent as u64, "check_motion {motion}: the node received {received} states of {}", 1 + sent);
        // Every state received is counted checked or skipped: a report shared by states that
        // waited together counts each of them (all checked with motions; without, all but the
        // newest skipped as stale).
        let count = |key: &str| -> u64 { answer["diagnostics"][key].as_str().and_then(|s| s.parse().ok()).unwrap_or(u64::MAX / 4) };
        let (checked, skipped) = (count("states_checked"), count("states_skipped"));
        assert_eq!(checked + skipped, received, "check_motion {motion}: {}", answer["diagnostics"]);
        if motion {
            assert_eq!(skipped, 0, "check_motion {motion}: {}", answer["diagnostics"]);
        }
        let mut skipped_b = 0;
        for (round, &tb) in b_stamps.iter().enumerate() {
            let first = reports.iter().find(|r| r["stamp"].as_i64().is_some_and(|s| s >= tb));
            let first = first.unwrap_or_else(|| panic!("check_motion {motion}: no report at or after B of round {round}: {reports:?}"));
            let skipped = first["stamp"].as_i64() != Some(tb);
            skipped_b += usize::from(skipped);
            if motion {
                assert!(
                    first["in_collision"] == true && first["motion"] == true && first["error"] == "",
                    "round {round}: the report covering B (skipped: {skipped}) is {first}"
                );
                let f = first["fraction"].as_f64().unwrap();
                assert!((0.0..=1.0).contains(&f), "round {round}: fraction {f}");
            } else if skipped {
                // What a discrete check misses: only C is checked, and it is free.
                assert!(first["in_collision"] == false && first["motion"] == false, "round {round}, discrete: {first}");
            }
        }
        eprintln!(
            "check_motion {motion}: {} reports for {} states; B not reported on its own in {skipped_b} of {ROUNDS} rounds",
            reports.len(),
            (AS + 1 + CS) * ROUNDS
        );
        // Resumed with 91 states waiting, the node answers the newest 63 of a turn on their own
        // and the older ones with one report: at least a quarter of the rounds must show that
        // for B. RustDDS reads the waiting datagrams in batches and the node takes each batch's
        // states together once it is handled (RustDDS change 13): B may come in a batch of its
        // own, or with too few after it (measured, with B after 15 A: 12 to 27 of 30 over 30
        // idle runs of each mode, 22 to 30 with the host busy; answered on the receiving
        // thread, 22 and 24 of 30; woken per sample there instead of per batch, 0).
        assert!(skipped_b >= ROUNDS / 4, "B was reported on its own in {} of {ROUNDS} rounds: {reports:?}", ROUNDS - skipped_b);
        assert!(
            reports.len() >= ROUNDS * (CS - 20),
            "{} reports for {ROUNDS} rounds of {} states: the states waiting were not answered one by one",
            reports.len(),
            2 + CS
        );
    }
}
