//! Issue 15: hostile input over DDS must not take the node down. An independent participant
//! (Cyclone DDS from Python, `tests/peers/hostile_peer.py`) sends the running node joint states
//! that are NaN, a million elements long, a 10,000-state burst, or bytes that are not a
//! JointState; then latched `robot_description`s nested 20,000 deep, with a cylinder of radius
//! 1e300, with a mesh that is a named pipe or a link to `/dev/zero`, of 50 MB, or not UTF-8; then
//! a DATA_FRAG made by hand (UDP to the node's ports) announcing a 3 GB sample. The node must keep
//! running and answer valid states as `check` does (with the robot it kept, then
//! with a good description's robot), show a refused description as ERROR in `/diagnostics` with
//! the reason, count the undecodable samples there and in its shutdown line, keep its resident
//! memory within 50 MiB plus the largest message of where it started, and stop on SIGTERM within
//! 2 s with exit status 0. The memory bound is asserted as the issue states it, throughout: with
//! RustDDS as published (0.15.1) the 50 MB description cost up to two more copies of itself, which
//! the test allowed; the patched RustDDS in `vendor/rustdds` (`vendor/rustdds/PATCHES.md`: no
//! second buffer for a repeated fragment of a completed sample, no copy of a reassembled sample,
//! announced sizes over 64 MiB refused before any allocation) keeps the node within the issue's
//! bound, so the allowance is gone. What was left of the joint-state phase used to stack under
//! the 50 MB description (peaks of 89-120 MiB against about 117 allowed: one CI run in four
//! failed): ~10 MB joint states whose fragments were lost in the burst kept their assembly
//! buffers (patch 9 drops them at once), and glibc kept freed blocks after its thresholds rose
//! (the node fixes them: `src/ros/memory_return.rs`). Now 67-71 MiB in 4 runs.
//!
//! Network: node and peer run in a private network namespace with only `lo` (`unshare -n`, the
//! peer joining it with `nsenter`) where that is allowed, else on loopback with the loopback
//! settings; the test prints which.

mod common;

use serde_json::{json, Value};
use std::io::{Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use common::{start_node_wrapped, CYCLONE_LOOPBACK};

const MIB: u64 = 1 << 20;
/// Past this the node is killed (the issue's "memory past 1 GB" failure), before it can take the
/// machine's memory from the other jobs.
const KILL_RSS: u64 = 1 << 30;
/// The DATA_FRAG made by hand announces a sample of this many bytes: allocated as announced
/// (RustDDS 0.15.1 as published) it would take the node past [`KILL_RSS`].
const HUGE_DATAFRAG: u64 = 3_000_000_000;

/// Whether a private network namespace can be made here (root, or user namespaces allowed) and
/// joined by a second process.
fn netns_allowed() -> bool {
    let ok = |c: &mut Command| c.stdout(Stdio::null()).stderr(Stdio::null()).status().is_ok_and(|s| s.success());
    ok(Command::new("unshare").args(["-n", "sh", "-c", "ip link set lo up"])) && ok(Command::new("nsenter").arg("--version"))
}

/// Resident memory of `pid` in bytes (0 once it is gone).
fn rss(pid: u32) -> u64 {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap_or_default();
    status.lines().find(|l| l.starts_with("VmRSS:")).and_then(|l| l.split_whitespace().nth(1)).and_then(|v| v.parse::<u64>().ok()).unwrap_or(0) * 1024
}

/// The bundled arm's joints, and positions that sweep it through the workcell.
fn state(k: usize) -> (Vec<&'static str>, Vec<f64>) {
    let names = vec!["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint", "wrist_3_joint", "finger_left_joint"];
    let x = k as f64;
    let pos = vec![(0.37 * x).sin() * 1.5, 0.3 + (0.23 * x).cos() * 1.1, (0.11 * x).sin() * 1.6, 0.2 * x % 3.0, (0.5 * x).cos() * 1.5, 0.1 * x, 0.02];
    (names, pos)
}

/// `check --json` on `states`, with the robot at `robot` (the bundled arm when `None`).
fn check(dir: &Path, name: &str, states: &[(Vec<&str>, Vec<f64>)], robot: Option<&Path>) -> Vec<Value> {
    let file = dir.join(name);
    let lines: Vec<String> = states.iter().map(|(n, p)| json!({"name": n, "position": p}).to_string()).collect();
    std::fs::write(&file, lines.join("\n") + "\n").unwrap();
    let mut c = Command::new(env!("CARGO_BIN_EXE_thickness_collision"));
    let _ = c.args(["check", "--states", file.to_str().unwrap(), "--json"]);
    if let Some(r) = robot {
        let _ = c.args(["--robot", r.to_str().unwrap()]);
    }
    let o = c.output().unwrap();
    assert!(o.status.success(), "check: {}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8(o.stdout).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect()
}

/// A one-link robot whose collision geometry is `geometry`.
fn one_link(geometry: &str) -> String {
    format!("<robot name='hostile'><link name='base_link'><collision><geometry>{geometry}</geometry></collision></link></robot>")
}

fn same_reports(got: &[Value], want: &[Value], what: &str) {
    assert_eq!(got.len(), want.len(), "{what}: one report per state");
    for (k, (g, w)) in got.iter().zip(want).enumerate() {
        assert!(g.is_object(), "{what}, state {k}: no report from the node");
        assert_eq!(g["in_collision"], w["in_collision"], "{what}, state {k}: {g} vs check's {w}");
        assert_eq!(g["error"], "", "{what}, state {k}");
        let (gc, wc) = (g["contacts"].as_array().unwrap(), w["contacts"].as_array().unwrap());
        assert_eq!(gc.len(), wc.len(), "{what}, state {k}: colliding links");
        for (a, b) in gc.iter().zip(wc) {
            assert_eq!(a["link_name"], b["link_name"], "{what}, state {k}");
            assert!((a["depth"].as_f64().unwrap() - b["depth"].as_f64().unwrap()).abs() <= 1e-9, "{what}, state {k}: depth");
        }
    }
}

fn count(status: &Value, key: &str) -> u64 {
    status["values"][key].as_str().and_then(|v| v.parse().ok()).unwrap_or_else(|| panic!("/diagnostics lacks {key}: {status}"))
}

#[test]
fn hostile_input_does_not_take_the_node_down() {
    let started = Instant::now();
    let dir = common::emptied(common::scratch_dir("node_robustness"));
    let cyclone = dir.join("cyclone.xml");
    std::fs::write(&cyclone, CYCLONE_LOOPBACK).unwrap();
    // Domains 30-69: the other DDS tests use 100-229.
    let domain = 30 + std::process::id() % 40;

    // Special files as meshes: a named pipe (opening it for reading would wait for a writer) and
    // a link to /dev/zero (reading it never ends).
    let fifo = dir.join("pipe.stl");
    assert!(Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    let zero = dir.join("zero.stl");
    std::os::unix::fs::symlink("/dev/zero", &zero).unwrap();
    let mesh = |p: &Path| one_link(&format!("<mesh filename='file://{}'/>", p.display()));
    const TOO_BIG: &str = "more than the 16777216 allowed";
    let descriptions = json!([
        {"label": "20,000 nested elements", "deep": 20_000},
        {"label": "cylinder radius 1e300", "text": one_link("<cylinder radius='1e300' length='1'/>")},
        {"label": "mesh that is a named pipe", "text": mesh(&fifo)},
        {"label": "mesh that is a link to /dev/zero", "text": mesh(&zero)},
        {"label": "50 MB", "bytes": 50_000_000, "expect": TOO_BIG},
    ]);
    let raw_descriptions = 2;

    // Valid states: for the bundled arm the node keeps through the hostile descriptions, then for
    // the fat-armed robot of a good description.
    let kept: Vec<_> = (0..6).map(state).collect();
    let good: Vec<_> = (6..12).map(state).collect();
    let fat = dir.join("fat_arm.urdf");
    let fat_urdf = common::fat_arm_urdf();
    std::fs::write(&fat, &fat_urdf).unwrap();
    let kept_ref = check(&dir, "kept.jsonl", &kept, None);
    let good_ref = check(&dir, "good.jsonl", &good, Some(&fat));
    let stamped = |states: &[(Vec<&str>, Vec<f64>)], base: u64| -> Vec<Value> {
        states.iter().enumerate().map(|(k, (n, p))| json!({"name": n, "position": p, "stamp": base + k as u64})).collect()
    };

    let netns = netns_allowed();
    let wrapper: &[&str] = if netns { &["unshare", "-n", "sh", "-c", "ip link set lo up && exec \"$0\" \"$@\""] } else { &[] };
    eprintln!(
        "network: {}",
        if netns {
            "a private network namespace with only lo (unshare -n), the peer joined to it with nsenter; loopback settings as well"
        } else {
            "unshare -n is not allowed here: the host's loopback, with ROS_LOCALHOST_ONLY and the loopback Cyclone config"
        }
    );
    // One report per state, as `check` gives them (motions on the node: tests/one_pipeline.rs).
    let (mut node, mut out, banner) = start_node_wrapped(wrapper, &["--ros-args", "-p", "check_motion:=false"], domain);
    assert!(banner.contains("loopback only"), "{banner}");
    let pid = node.id();

    // Resident memory through the run.
    let rss_start = rss(pid);
    let sampling = Arc::new(AtomicBool::new(true));
    let sampler = {
        let sampling = sampling.clone();
        std::thread::spawn(move || {
            // Samples as (seconds since the Unix epoch, bytes), to split by the peer's phases.
            let mut samples = Vec::new();
            let mut killed = false;
            while sampling.load(Ordering::SeqCst) {
                let now = rss(pid);
                samples.push((SystemTime::now().duration_since(UNIX_EPOCH).unwrap().as_secs_f64(), now));
                if now > KILL_RSS && !killed {
                    killed = true;
                    let _ = Command::new("kill").args(["-KILL", &pid.to_string()]).status();
                }
                std::thread::sleep(Duration::from_millis(20));
            }
            (samples, killed)
        })
    };

    let request = json!({
        "domain": domain,
        "timeout": 30,
        "nan_states": 100,
        "raw_states": 6,
        "huge_state": 1_000_000,
        "burst": 10_000,
        "descriptions": descriptions,
        "raw_descriptions": raw_descriptions,
        "states_kept": stamped(&kept, 5_000_000_000),
        "good_description": fat_urdf,
        "states_good": stamped(&good, 6_000_000_000),
        "huge_datafrag": HUGE_DATAFRAG,
        "node_pid": pid,
    });
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/peers/hostile_peer.py");
    let mut peer = if netns {
        let mut c = Command::new("nsenter");
        let _ = c.arg(format!("--net=/proc/{pid}/ns/net")).arg(common::python());
        c
    } else {
        Command::new(common::python())
    };
    let mut peer = peer
        .arg(&script)
        .env("CYCLONEDDS_URI", format!("file://{}", cyclone.display()))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start the hostile peer");
    peer.stdin.take().unwrap().write_all(request.to_string().as_bytes()).unwrap();
    // A peer that outlives the node by 2 s is waiting for answers that cannot come.
    let mut died = None;
    while peer.try_wait().unwrap().is_none() {
        if node.try_wait().unwrap().is_some() && died.get_or_insert_with(Instant::now).elapsed() > Duration::from_secs(2) {
            let _ = peer.kill();
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let peer_out = peer.wait_with_output().unwrap();
    let alive = node.try_wait().unwrap().is_none();

    // SIGTERM: the time to exit, the exit status, the shutdown line.
    let term = Instant::now();
    let _ = Command::new("kill").args(["-TERM", &pid.to_string()]).stderr(Stdio::null()).status();
    let status = loop {
        if let Some(s) = node.try_wait().unwrap() {
            break Some(s);
        }
        if term.elapsed() > Duration::from_secs(5) {
            let _ = node.kill();
            let _ = node.wait();
            break None;
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let stop_seconds = term.elapsed().as_secs_f64();
    sampling.store(false, Ordering::SeqCst);
    let (samples, killed_for_memory) = sampler.join().unwrap();
    let rss_peak = samples.iter().map(|s| s.1).max().unwrap_or(0);
    let mut rest = String::new();
    let _ = out.read_to_string(&mut rest);
    let mut err = String::new();
    let _ = node.stderr.take().unwrap().read_to_string(&mut err);
    let refusals: Vec<&str> = err.lines().filter(|l| l.contains("robot_description rejected")).collect();
    let undecodable_warnings = err.lines().filter(|l| l.contains("undecodable")).count();

    let answer: Value = serde_json::from_slice(&peer_out.stdout).unwrap_or(Value::Null);
    let largest = answer["largest_message"].as_u64().unwrap_or(50_000_000);
    eprintln!(
        "node: RSS {:.1} MiB at start, peak {:.1} MiB (allowed {:.1} MiB: start + 50 MiB + the largest message, {:.1} MiB)",
        rss_start as f64 / MIB as f64,
        rss_peak as f64 / MIB as f64,
        (rss_start + 50 * MIB + largest) as f64 / MIB as f64,
        largest as f64 / MIB as f64
    );
    let peak_in = |from: f64, to: f64| samples.iter().filter(|s| s.0 >= from && s.0 <= to).map(|s| s.1).max().unwrap_or(0) as f64 / MIB as f64;
    let mut phases = Vec::new();
    for phase in ["states", "descriptions", "valid"] {
        if let Some([from, to]) = answer["phases"][phase].as_array().and_then(|a| a.iter().map(Value::as_f64).collect::<Option<Vec<_>>>()).as_deref() {
            phases.push(format!("{phase} {:.1}", peak_in(*from, *to)));
        }
    }
    eprintln!("node: peak RSS (MiB) by the peer's phases: {}", phases.join(", "));
    let t0 = samples.first().map_or(0.0, |s| s.0);
    let timeline: Vec<String> =
        samples.chunks(25).map(|c| c.iter().map(|s| s.1).max().unwrap_or(0)).filter(|&b| b > 0).map(|b| format!("{:.0}", b as f64 / MIB as f64)).collect();
    eprintln!("node: RSS (MiB), peak of each 0.5 s from {t0:.1}: {}", timeline.join(" "));
    for robot in rest.lines().filter(|l| l.contains("robot from")) {
        eprintln!("node: accepted a description: {robot}");
    }
    eprintln!("node: stopped {:.3} s after SIGTERM, {status:?}; alive after the peer: {alive}", stop_seconds);
    eprintln!("node: {} description refusals:", refusals.len());
    for r in &refusals {
        eprintln!("  {}", r.chars().take(300).collect::<String>());
    }
    eprintln!(
        "node: {undecodable_warnings} undecodable warnings; shutdown: {}",
        rest.lines().filter(|l| l.contains("shutting down")).collect::<Vec<_>>().join(" | ")
    );
    eprintln!("peer: sent {}, seconds {}", answer["sent"], answer["seconds"]);
    for k in ["diag_after_states", "diag_after_descriptions_any", "diag_after_descriptions", "diag_after_descriptions_next", "diag_after_good", "diag_final"] {
        eprintln!("peer: {k}: level {} '{}'", answer[k]["level"], answer[k]["message"].as_str().unwrap_or("").chars().take(200).collect::<String>());
    }
    eprintln!("test: {:.1} s", started.elapsed().as_secs_f64());

    // The node survived everything and answered the peer.
    assert!(!killed_for_memory, "the node went past 1 GiB of resident memory and was killed; stderr {err}");
    assert!(peer_out.status.success(), "hostile_peer.py: {}\nnode stderr: {err}", String::from_utf8_lossy(&peer_out.stderr));
    assert_eq!(answer["matched"], true, "no DDS match: {answer}");
    assert!(alive, "the node died under hostile input ({status:?}): stderr {err}\nstdout {rest}");
    assert_eq!(answer["warm_report"], true);
    assert!(answer["diag_after_states"].is_object(), "no /diagnostics after the hostile joint states: the node's loop is stuck");
    assert!(
        answer["unresponsive_after_descriptions"].is_null(),
        "the node stopped answering during the hostile descriptions (acknowledged: {}, not: {}); stderr {err}",
        answer["sent"]["descriptions"],
        answer["sent"]["not_acknowledged"]
    );
    // SIGTERM honoured within 2 s, exit 0, the counts in the shutdown line.
    assert!(status.is_some_and(|s| s.success()) && stop_seconds < 2.0, "SIGTERM: {status:?} after {stop_seconds:.3} s; stderr {err}");
    let shutdown = rest.lines().find(|l| l.contains("shutting down")).unwrap_or_else(|| panic!("no shutdown line: {rest}"));
    assert!(shutdown.contains("undecodable") && shutdown.contains("non_finite"), "{shutdown}");

    // Every hostile description refused (one line each, the reason in it), ERROR in /diagnostics
    // with the last one's reason, back to no ERROR once a good one arrived.
    let sent = answer["sent"]["descriptions"].as_array().unwrap();
    assert_eq!(sent.len(), descriptions.as_array().unwrap().len(), "{answer}");
    assert_eq!(refusals.len(), sent.len(), "one refusal per hostile description: {refusals:#?}");
    assert!(refusals.iter().any(|r| r.contains("256")), "nesting: {refusals:#?}");
    assert!(refusals.iter().any(|r| r.contains("named pipe")), "named pipe: {refusals:#?}");
    assert!(refusals.iter().any(|r| r.contains("/dev/zero") || r.contains("device")), "/dev/zero: {refusals:#?}");
    assert!(refusals.iter().any(|r| r.contains(TOO_BIG)), "50 MB: {refusals:#?}");
    let after = &answer["diag_after_descriptions"];
    assert_eq!(after["level"], 2, "a refused description is an ERROR: {after}");
    assert!(after["message"].as_str().unwrap().contains(TOO_BIG) && after["values"]["robot_description_error"].as_str().unwrap().contains(TOO_BIG), "{after}");
    assert_eq!(answer["diag_after_good"]["level"], 1, "a good description clears the ERROR (WARN stays: bad messages came): {}", answer["diag_after_good"]);

    // Valid states answered as check answers them: the kept robot, then the good description's.
    same_reports(answer["reports_kept"].as_array().unwrap(), &kept_ref, "the robot kept through the hostile descriptions");
    same_reports(answer["reports_good"].as_array().unwrap(), &good_ref, "the robot of the good description");

    // Counted by cause: the undecodable states and descriptions, the NaN states.
    let last = &answer["diag_final"];
    eprintln!("peer: diag_final values {}", last["values"]);
    // The raw descriptions (reliable) and at least one raw state (best effort).
    assert!(count(last, "skipped_undecodable") > raw_descriptions, "undecodable: {last}");
    assert!(count(last, "skipped_non_finite") >= 1, "NaN: {last}");
    assert!(count(last, "states_received") >= 1000, "the burst: {last}");
    assert!(undecodable_warnings >= 1, "undecodable samples are warned about with the reason: {err}");

    // The hand-made DATA_FRAG went out (to the node's ports; the node dropping it is what keeps
    // the memory below, and the valid states and the good description after it are answered).
    let huge = &answer["sent"]["huge_datafrag"];
    assert!(huge["datagrams"].as_u64().unwrap_or(0) > 0 && huge["sample_size"] == HUGE_DATAFRAG, "the 3 GB DATA_FRAG was not sent: {answer}");

    // Memory: within start + 50 MiB + the largest message sent, as the issue says, throughout,
    // the descriptions (the 50 MB one, refused from its length by the node, but reassembled by
    // RustDDS first) and the 3 GB DATA_FRAG included. With RustDDS 0.15.1 as published the 50 MB
    // phase needed two more copies of the largest message; the patched copy in vendor/rustdds
    // does not (vendor/rustdds/PATCHES.md, docs/upstream/rustdds.md).
    let issue_bound = rss_start + 50 * MIB + largest;
    let descriptions_from = answer["phases"]["descriptions"][0].as_f64().expect("the peer's descriptions phase");
    let peak_before = samples.iter().filter(|s| s.0 < descriptions_from).map(|s| s.1).max().unwrap_or(0);
    let peak_from = samples.iter().filter(|s| s.0 >= descriptions_from).map(|s| s.1).max().unwrap_or(0);
    let mib = |b: u64| b as f64 / MIB as f64;
    eprintln!(
        "node: memory before the descriptions: peak {:.1} MiB, allowed {:.1} MiB (start + 50 MiB + the largest message); \
         from the descriptions on (50 MB description, 3 GB DATA_FRAG): peak {:.1} MiB, allowed the same {:.1} MiB; \
         the issue's bound {} for the 50 MB phase",
        mib(peak_before),
        mib(issue_bound),
        mib(peak_from),
        mib(issue_bound),
        if peak_from <= issue_bound { "holds" } else { "does not hold" }
    );
    assert!(rss_start > 0 && peak_before > 0 && peak_from > 0, "no memory samples: start {rss_start}, before {peak_before}, from {peak_from}");
    assert!(
        peak_before <= issue_bound,
        "resident memory before the descriptions went from {:.1} MiB to a peak of {:.1} MiB, past start + 50 MiB + the largest message ({:.1} MiB) (by phase: {})",
        mib(rss_start),
        mib(peak_before),
        mib(issue_bound),
        phases.join(", ")
    );
    // RustDDS's topic cache kept every sample until 64 newer ones pushed it out, so the 50 MB
    // description stayed resident beside whatever came next (one run of seven peaked at 129 MiB
    // that way); the vendored copy now releases a reassembled sample once every local reader has
    // taken it (vendor/rustdds/PATCHES.md, change 5), and the issue's bound is asserted as it is.
    assert!(
        peak_from <= issue_bound,
        "resident memory from the descriptions on went from {:.1} MiB to a peak of {:.1} MiB, past start + 50 MiB + the largest message ({:.1} MiB) (by phase: {})",
        mib(rss_start),
        mib(peak_from),
        mib(issue_bound),
        phases.join(", ")
    );
}
