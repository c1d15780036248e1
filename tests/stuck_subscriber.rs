//! One stuck reliable subscriber of `collisions` must not stop the node's reports for everyone
//! else. A Cyclone DDS subscriber (reliable, keep last 5; `tests/peers/stuck_peer.py`) matches
//! the node's `collisions` writer, takes one report, and is frozen with SIGSTOP, as a planner that
//! hangs or is stopped in a debugger would be: it acknowledges nothing more. Another participant
//! then sends 16,000 joint states at 2.5 kHz (the node runs with `check_motion:=false`, one report
//! per state it checks; states that wait together get one report, for the newest) and reads the
//! reports reliably: it must get more than 8,400 of them (the stalled writer let through 8,191),
//! including reports for the last states. RustDDS 0.15.1 as published stops a
//! reliable writer once 8,192 samples are unacknowledged by one matched reader, even a KEEP_LAST
//! one (the node's writer is reliable, keep last 100), so its reports stopped there for every
//! subscriber; patch 10 in `vendor/rustdds/PATCHES.md` keeps KEEP_LAST writers from waiting on
//! acknowledgements, as DDS has it. Then the frozen subscriber is resumed: it must get reports
//! again (the samples it missed are answered by GAP, so it moves on), the node must answer a new
//! state, and it must stop cleanly on SIGTERM.
//!
//! The frozen peer announces a 60 s lease, so the node keeps it matched for the whole test (with
//! Cyclone's default of 10 s it could drop it mid-flood and hide the stall). Loopback only, as
//! every DDS test here: the node gets `ROS_LOCALHOST_ONLY=1` and
//! `ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST`, the peers the loopback Cyclone configuration.

mod common;

use serde_json::{json, Value};
use std::io::{BufRead, BufReader, Write};
use std::path::PathBuf;
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{self, Receiver};
use std::time::Duration;

use common::{start_node, CYCLONE_LOOPBACK};

/// States sent while the subscriber is frozen: well over the 8,192 that stalled the writer.
const FLOOD: u64 = 16_000;
/// Their rate: the node checks most of them one by one at this rate on a busy 2-core machine
/// (measured: 9,600-12,500 reports for 14,000 states at load 1.5-3).
const RATE_HZ: u64 = 2_500;
const BASE_STAMP: u64 = 1_000_000_000;
const PHASE2_STAMP: u64 = 50_000_000_000;

/// The frozen subscriber: killed (even while stopped) if the test ends early, so no peer is left
/// holding a match on the domain.
struct Stuck {
    child: Child,
    stdin: Option<ChildStdin>,
    lines: Receiver<Value>,
}

impl Stuck {
    fn signal(&self, sig: libc::c_int) {
        // SAFETY: kill(2) on our own child's pid; it is reaped only in Drop or finish.
        assert_eq!(unsafe { libc::kill(self.child.id() as libc::pid_t, sig) }, 0, "signal {sig} to the subscriber");
    }

    /// The next line the subscriber prints, or None after `wait`.
    fn next(&self, wait: Duration) -> Option<Value> {
        self.lines.recv_timeout(wait).ok()
    }
}

impl Drop for Stuck {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn spawn_stuck(cyclone: &std::path::Path, domain: u32) -> Stuck {
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/peers/stuck_peer.py");
    let mut child = Command::new(common::python())
        .arg(script)
        .env("CYCLONEDDS_URI", format!("file://{}", cyclone.display()))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("start the stuck subscriber");
    let mut stdin = child.stdin.take().unwrap();
    let request = json!({"role": "stuck", "domain": domain, "depth": 5, "phase2_from": PHASE2_STAMP});
    writeln!(stdin, "{request}").unwrap();
    let stdout = child.stdout.take().unwrap();
    let (tx, lines) = mpsc::channel();
    let _ = std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines().map_while(Result::ok) {
            if tx.send(serde_json::from_str::<Value>(&line).unwrap_or(Value::Null)).is_err() {
                break;
            }
        }
    });
    Stuck { child, stdin: Some(stdin), lines }
}

#[test]
fn a_stopped_reliable_subscriber_does_not_stall_collisions() {
    let dir = common::scratch_dir("stuck_subscriber");
    let cyclone = common::cyclone_loopback_file(&dir);
    let long_lease = dir.join("cyclone_long_lease.xml");
    std::fs::write(&long_lease, CYCLONE_LOOPBACK.replace("<Discovery>", "<Discovery><LeaseDuration>60 s</LeaseDuration>")).unwrap();
    let domain = 173 + std::process::id() % 50;

    let (node, mut out, banner) = start_node(&["--ros-args", "-p", "check_motion:=false"], domain);
    assert!(banner.contains("loopback only"), "{banner}");
    // The node's standard output is drained so that it never blocks on a full pipe.
    let _ = std::thread::spawn(move || {
        let mut sink = String::new();
        while out.read_line(&mut sink).is_ok_and(|n| n > 0) {
            sink.clear();
        }
    });

    // The subscriber to freeze: once a report has reached it, the node's writer has matched it.
    let mut stuck = spawn_stuck(&long_lease, domain);
    let mut first = None;
    for k in 0..5 {
        let warm = common::run_cyclone_peer("stuck_peer.py", &cyclone, &json!({"role": "warm", "domain": domain, "stamp": 1000 + k}).to_string());
        assert_eq!(warm["ok"], true, "the node answered no state: {warm}");
        first = stuck.next(Duration::from_secs(3));
        if first.is_some() {
            break;
        }
    }
    assert!(first.is_some_and(|v| v["first"].is_u64()), "the subscriber to freeze got no report");
    stuck.signal(libc::SIGSTOP);

    let flood = common::run_cyclone_peer(
        "stuck_peer.py",
        &cyclone,
        &json!({"role": "flood", "domain": domain, "count": FLOOD, "rate": RATE_HZ, "base": BASE_STAMP, "tail": 3.0}).to_string(),
    );
    eprintln!("with one subscriber stopped: {flood}");
    assert_eq!(flood["warm"], true, "{flood}");
    let reports = flood["reports"].as_u64().unwrap();
    let late = flood["after"]["12000"].as_u64().unwrap();
    assert!(reports > 8_400, "{reports} reports for {FLOOD} states while one subscriber was stopped: the collisions writer stalled (8,192 unacknowledged)");
    assert!(late >= 500, "only {late} reports for states after the 12,000th: {flood}");
    assert!(flood["max_k"].as_u64().unwrap() >= FLOOD - 100, "the reports stopped before the last states: {flood}");

    // Resumed, the subscriber gets reports again: what it missed is gone from the writer's
    // history and answered by GAP instead of stalling it.
    stuck.signal(libc::SIGCONT);
    let mut resumed = false;
    for k in 0..10 {
        let warm = common::run_cyclone_peer("stuck_peer.py", &cyclone, &json!({"role": "warm", "domain": domain, "stamp": PHASE2_STAMP + k}).to_string());
        assert_eq!(warm["ok"], true, "the node stopped answering after the subscriber was resumed: {warm}");
        std::thread::sleep(Duration::from_millis(500));
        writeln!(stuck.stdin.as_mut().unwrap(), "poll").unwrap();
        let status = stuck.next(Duration::from_secs(1));
        eprintln!("resumed subscriber after {} new state(s): {status:?}", k + 1);
        if status.is_some_and(|v| v["phase2"].as_u64().is_some_and(|n| n > 0)) {
            resumed = true;
            break;
        }
    }
    assert!(resumed, "the resumed subscriber got no new report");
    drop(stuck.stdin.take());
    let _ = stuck.child.wait();

    let err = common::stop_node(node);
    assert!(!err.contains("panicked"), "{err}");
}
