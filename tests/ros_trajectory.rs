//! Issue 12, `check_trajectory`: the service called from an independent ROS 2 participant (Cyclone
//! DDS from Python, `tests/peers/trajectory_peer.py`, Cyclone's request/reply mapping, types
//! built from the project's `CheckTrajectory.srv`). Its answer equals `check --states FILE
//! --motion --json` on the same waypoints (segment `i` is the file's line `i + 2`); joints the
//! trajectory leaves out come from the node's merged joint state; bad requests are refused with
//! a cause; and a long trajectory is checked while the live stream goes on being reported.
//! Loopback only, as in `tests/ros_node.rs`.

mod common;

use common::start_node;
use oorandom::Rand64;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::Command;
use thickness_collision::checker::Checker;
use thickness_collision::model::{JointKind, Params};

fn scratch(name: &str) -> (PathBuf, PathBuf) {
    let dir = common::scratch_subdir("ros_trajectory", name);
    let cyclone = common::cyclone_loopback_file(&dir);
    (dir, cyclone)
}

/// The bundled arm, the names of its actuated joints, and random states within its limits.
struct Arm {
    checker: Checker,
    names: Vec<String>,
    /// Joint index of every name.
    index: Vec<usize>,
}

impl Arm {
    fn new() -> Arm {
        let checker = Checker::from_params(Params::default()).unwrap();
        let actuated: Vec<(usize, String)> =
            checker.robot().joints.iter().enumerate().filter(|(_, j)| j.is_actuated()).map(|(i, j)| (i, j.name.clone())).collect();
        Arm { names: actuated.iter().map(|a| a.1.clone()).collect(), index: actuated.iter().map(|a| a.0).collect(), checker }
    }

    /// Positions of every joint from positions of the actuated ones.
    fn full(&self, named: &[f64]) -> Vec<f64> {
        let mut q = vec![0.0; self.checker.robot().joints.len()];
        for (&j, &v) in self.index.iter().zip(named) {
            q[j] = v;
        }
        q
    }

    fn free(&self, named: &[f64]) -> bool {
        !self.checker.check_positions(&self.full(named)).unwrap().in_collision
    }

    fn motion_free(&self, a: &[f64], b: &[f64]) -> bool {
        !self.checker.check_motion(&self.full(a), &self.full(b)).report.in_collision
    }

    /// A random state of the actuated joints: near `from` (within ±`step` rad) or anywhere.
    fn random(&self, rng: &mut Rand64, from: Option<&[f64]>, step: f64) -> Vec<f64> {
        self.index
            .iter()
            .enumerate()
            .map(|(k, &j)| {
                let joint = &self.checker.robot().joints[j];
                let (lo, hi) = if joint.kind == JointKind::Continuous { (-3.1, 3.1) } else { (joint.limits[0], joint.limits[1]) };
                match from {
                    Some(f) if joint.kind != JointKind::Prismatic => (f[k] + step * (2.0 * rng.rand_float() - 1.0)).clamp(lo, hi),
                    _ => lo + (hi - lo) * rng.rand_float(),
                }
            })
            .collect()
    }

    /// A free state near `from` (or anywhere) whose motion from `from` is free.
    fn free_step(&self, rng: &mut Rand64, from: Option<&[f64]>, step: f64) -> Vec<f64> {
        for _ in 0..10_000 {
            let q = self.random(rng, from, step);
            if self.free(&q) && from.is_none_or(|f| self.motion_free(f, &q)) {
                return q;
            }
        }
        panic!("no free step found");
    }
}

/// Waypoint times: 1 s, then every 0.5 s.
fn t_ns(k: usize) -> i64 {
    1_000_000_000 + 500_000_000 * k as i64
}

/// Waypoints along the straight chords (`interpolation: linear`), as `check --motion` checks them.
fn request_of(names: &[String], waypoints: &[Vec<f64>]) -> Value {
    json!({"joint_names": names, "interpolation": "linear", "points": waypoints.iter().enumerate().map(|(k, p)| json!({"positions": p, "t": t_ns(k)})).collect::<Vec<_>>()})
}

/// `check --states FILE --motion --json` on waypoints given by name.
fn check_motion_cli(dir: &Path, name: &str, names: &[String], waypoints: &[Vec<f64>]) -> Vec<Value> {
    let lines: Vec<String> = waypoints.iter().map(|p| json!({"name": names, "position": p}).to_string()).collect();
    let file = dir.join(format!("{name}.jsonl"));
    std::fs::write(&file, lines.join("\n") + "\n").unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_thickness_collision")).args(["check", "--states", file.to_str().unwrap(), "--motion", "--json"]).output().unwrap();
    assert!(o.status.success(), "check --motion: {}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8(o.stdout).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect()
}

/// The node's answer against `check --motion` on the same waypoints: the first motion line in
/// collision (line `i + 2`, 1-based) is segment `i`, with its fraction and contacts; none, valid.
/// Returns the segment.
fn assert_same(what: &str, got: &Value, cli: &[Value]) -> i64 {
    assert_eq!(got["error"], "", "{what}: {got}");
    assert!(cli.iter().all(|l| l["error"] == ""), "{what}: check could not check a waypoint: {cli:?}");
    assert!(cli.iter().skip(1).all(|l| l["motion"] == true), "{what}: every line after the first is a motion");
    let first = cli.iter().enumerate().skip(1).find(|(_, l)| l["in_collision"] == true).map(|(n, _)| n - 1);
    let Some(i) = first else {
        assert_eq!((&got["valid"], &got["segment"], &got["fraction"]), (&json!(true), &json!(-1), &json!(-1.0)), "{what}: {got}");
        assert!(got["contacts"].as_array().unwrap().is_empty(), "{what}");
        return -1;
    };
    let line = &cli[i + 1];
    assert_eq!((&got["valid"], got["segment"].as_i64()), (&json!(false), Some(i as i64)), "{what}: {got} vs line {}: {line}", i + 2);
    let f = line["fraction"].as_f64().unwrap();
    assert_eq!(got["fraction"].as_f64().unwrap(), f, "{what}: fraction");
    let t = t_ns(i) + ((t_ns(i + 1) - t_ns(i)) as f64 * f).floor() as i64;
    assert_eq!(got["time_from_start"].as_i64().unwrap(), t, "{what}: t_i + fraction (t_i+1 - t_i)");
    let (g, w) = (got["contacts"].as_array().unwrap(), line["contacts"].as_array().unwrap());
    assert!(!w.is_empty(), "{what}: a colliding motion names what it hits");
    assert_eq!(g.len(), w.len(), "{what}: contacts {g:?} vs {w:?}");
    for (a, b) in g.iter().zip(w) {
        for k in ["link_name", "object_name", "triangle"] {
            assert_eq!(a[k], b[k], "{what}: {k}");
        }
        assert!((a["depth"].as_f64().unwrap() - b["depth"].as_f64().unwrap()).abs() <= 1e-9, "{what}: depth");
        for k in ["position", "normal"] {
            for c in 0..3 {
                assert!((a[k][c].as_f64().unwrap() - b[k][c].as_f64().unwrap()).abs() <= 1e-9, "{what}: {k}");
            }
        }
    }
    i as i64
}

#[test]
fn check_trajectory_over_dds_equals_check_motion_and_refuses_bad_requests() {
    let (dir, cyclone) = scratch("equal");
    let arm = Arm::new();
    let mut rng = Rand64::new(2026);

    // 1. Every joint named: three free waypoints (two free segments), then a jump to a free state
    //    that crosses something or comes within motion_tolerance of it, then two more waypoints.
    let mut crossing = vec![arm.free_step(&mut rng, None, 0.0)];
    while crossing.len() < 3 {
        let next = arm.free_step(&mut rng, crossing.last().map(Vec::as_slice), 0.4);
        crossing.push(next);
    }
    loop {
        let q = arm.random(&mut rng, None, 0.0);
        if arm.free(&q) && !arm.motion_free(crossing.last().unwrap(), &q) {
            crossing.push(q);
            break;
        }
    }
    for _ in 0..2 {
        let next = arm.free_step(&mut rng, crossing.last().map(Vec::as_slice), 0.4);
        crossing.push(next);
    }
    // 2. Every joint named, every segment free.
    let mut free = vec![arm.free_step(&mut rng, None, 0.0)];
    while free.len() < 6 {
        let next = arm.free_step(&mut rng, free.last().map(Vec::as_slice), 0.3);
        free.push(next);
    }
    // 3. Two joints named, the others from a state the node received: a pose and lift/elbow
    //    waypoints whose answer differs from the one with the others at 0 (so the merge shows).
    let partial_names = vec!["shoulder_lift_joint".to_string(), "elbow_joint".to_string()];
    let slot = |n: &str| arm.names.iter().position(|x| x == n).unwrap();
    let (lift, elbow) = (slot("shoulder_lift_joint"), slot("elbow_joint"));
    let (base, partial) = loop {
        let base = arm.free_step(&mut rng, None, 0.0);
        let waypoints: Vec<Vec<f64>> = (0..4).map(|_| vec![1.6 * rng.rand_float() - 0.3, 2.4 * rng.rand_float() - 1.2]).collect();
        let merged = |b: &[f64]| -> Vec<Vec<f64>> {
            waypoints
                .iter()
                .map(|w| {
                    let mut q = b.to_vec();
                    (q[lift], q[elbow]) = (w[0], w[1]);
                    q
                })
                .collect()
        };
        let first_hit = |qs: &[Vec<f64>]| {
            qs.windows(2).enumerate().find_map(|(i, p)| arm.checker.check_motion(&arm.full(&p[0]), &arm.full(&p[1])).fraction.map(|f| (i, f)))
        };
        let (with_base, with_zero) = (merged(&base), merged(&vec![0.0; arm.names.len()]));
        if first_hit(&with_base).is_some() && first_hit(&with_base) != first_hit(&with_zero) {
            break (base, waypoints);
        }
    };
    let partial_full: Vec<Vec<f64>> = partial
        .iter()
        .map(|w| {
            let mut q = base.clone();
            (q[lift], q[elbow]) = (w[0], w[1]);
            q
        })
        .collect();

    let cli_crossing = check_motion_cli(&dir, "crossing", &arm.names, &crossing);
    let cli_free = check_motion_cli(&dir, "free", &arm.names, &free);
    let cli_partial = check_motion_cli(&dir, "partial", &arm.names, &partial_full);
    // The answers these waypoints were chosen for, by check itself.
    assert!(cli_crossing[..3].iter().all(|l| l["in_collision"] == false), "{cli_crossing:?}");
    assert_eq!(cli_crossing[3]["in_collision"], true, "the jump between free states collides (or comes within motion_tolerance)");
    assert!(cli_free.iter().all(|l| l["in_collision"] == false), "{cli_free:?}");

    let elbow_only = vec!["elbow_joint".to_string()];
    let bad = [
        (json!({"joint_names": partial_names, "points": [{"positions": [0.1, 0.2], "t": 0}, {"positions": [0.1], "t": 1_000_000_000}]}), "1 positions for 2"),
        (
            json!({"joint_names": elbow_only, "points": [{"positions": [0.1], "t": 1_000_000_000}, {"positions": [0.2], "t": 1_000_000_000}]}),
            "increase strictly",
        ),
        (json!({"joint_names": elbow_only, "points": [{"positions": [0.1], "t": 0}, {"positions": ["NaN"], "t": 1_000_000_000}]}), "non-finite"),
        (json!({"joint_names": ["elbow_joint", "no_such_joint"], "points": [{"positions": [0.1, 0.2], "t": 0}]}), "'no_such_joint' is not a joint"),
        (json!({"joint_names": elbow_only, "points": []}), "no points"),
        (json!({"joint_names": elbow_only, "interpolation": "cubic", "points": [{"positions": [0.1], "t": 0}]}), "interpolation 'cubic' is not known"),
        (json!({"joint_names": elbow_only, "path_tolerance": [0.1, 0.2], "points": [{"positions": [0.1], "t": 0}]}), "path_tolerance has 2 values for 1"),
        (json!({"joint_names": elbow_only, "points": [{"positions": [0.1], "accelerations": [1.0], "t": 0}]}), "accelerations without velocities"),
    ];

    let domain = 1 + std::process::id() % 14;
    let (node, _out, banner) = start_node(&[], domain);
    assert!(banner.contains("check_trajectory"), "{banner}");
    let mut trajectories = vec![request_of(&arm.names, &crossing), request_of(&arm.names, &free), request_of(&partial_names, &partial)];
    trajectories.extend(bad.iter().map(|(t, _)| t.clone()));
    let state = json!({"name": arm.names, "position": base, "stamp": 5_000_000_000i64});
    let answer = common::run_cyclone_peer(
        "trajectory_peer.py",
        &cyclone,
        &json!({"domain": domain, "state": state, "trajectories": trajectories, "timeout": 60}).to_string(),
    );
    let err = common::stop_node(node);

    assert!(answer["state_report"].is_object(), "the node reported on the state the trajectory is merged with: {answer}");
    let answers = answer["answers"].as_array().unwrap();
    assert_eq!(answers.len(), trajectories.len());
    assert!(answers.iter().all(Value::is_object), "every request answered: {answers:?}");
    assert_eq!(assert_same("crossing", &answers[0], &cli_crossing), 2, "the jump is segment 2");
    assert_eq!(assert_same("free", &answers[1], &cli_free), -1);
    assert!(assert_same("partial", &answers[2], &cli_partial) >= 0);
    for ((_, cause), got) in bad.iter().zip(&answers[3..]) {
        assert_eq!((&got["valid"], &got["segment"], &got["fraction"]), (&json!(false), &json!(-1), &json!(-1.0)), "{cause}: {got}");
        assert!(got["error"].as_str().unwrap().contains(cause), "{cause}: {got}");
        assert!(got["contacts"].as_array().unwrap().is_empty(), "{cause}");
    }
    assert!(err.contains("check_trajectory: not valid"), "refused requests are warned about: {err}");
}

#[test]
fn a_long_trajectory_is_checked_while_the_live_stream_goes_on() {
    let (_dir, cyclone) = scratch("long");
    let arm = Arm::new();
    let mut rng = Rand64::new(99);
    // Back and forth between two free states whose motion is free (both ways), repeated until the
    // check takes some 6 s on this machine as measured here (the node took 2-3 s in practice; at
    // most 65,536 points).
    let a = arm.free_step(&mut rng, None, 0.0);
    let b = arm.free_step(&mut rng, Some(&a), 0.6);
    assert!(arm.motion_free(&b, &a));
    let started = std::time::Instant::now();
    let mut runs = 0;
    while started.elapsed().as_secs_f64() < 0.3 {
        let _ = arm.checker.check_motion(&arm.full(&a), &arm.full(&b));
        runs += 1;
    }
    let per_segment = started.elapsed().as_secs_f64() / runs as f64;
    // Within the request's sub-interval budget, with room to spare (both directions cost alike).
    let per_segment_subintervals = arm.checker.check_motion(&arm.full(&a), &arm.full(&b)).subintervals.max(1);
    let within_budget = (thickness_collision::limits::MAX_TRAJECTORY_SUBINTERVALS / (2 * per_segment_subintervals)) as usize;
    let points = ((6.0 / per_segment) as usize).min(within_budget).clamp(100, 65_536);
    let waypoints: Vec<Vec<f64>> = (0..points).map(|k| if k % 2 == 0 { a.clone() } else { b.clone() }).collect();
    eprintln!("{points} points, {:.3} ms per segment here", per_segment * 1e3);
    // The live stream meanwhile: the two states in turn, one every 10 ms until the answer (the
    // budget-bound request takes 0.3-1.3 s to check on these machines: 30 states or more).
    let stream: Vec<Value> = [&a, &b].iter().map(|q| json!({"name": arm.names, "position": q, "stamp": 10_000_000_000i64})).collect();

    let domain = 15 + std::process::id() % 14;
    let (node, _out, _banner) = start_node(&[], domain);
    let answer = common::run_cyclone_peer(
        "trajectory_peer.py",
        &cyclone,
        &json!({"domain": domain, "long": request_of(&arm.names, &waypoints), "stream": stream, "period": 0.01, "timeout": 120}).to_string(),
    );
    let _ = common::stop_node(node);
    let long = &answer["long"];
    eprintln!("long trajectory: {long}");
    assert_eq!((&long["answer"]["valid"], &long["answer"]["segment"]), (&json!(true), &json!(-1)), "{long}");
    let seconds = long["seconds"].as_f64().unwrap();
    // The request is sized by the sub-interval budget (it must be answered valid), which bounds
    // its length to 0.3-1.3 s of checking here: at least 0.1 s (ten states of the stream) keeps the test meaningful.
    assert!(seconds >= 0.1, "the check must take a while for this test to mean anything ({seconds} s)");
    // Reports kept coming while the trajectory was checked.
    let before = long["reports_before_answer"].as_u64().unwrap();
    let sent = long["states_sent"].as_u64().unwrap();
    assert!(before >= 10 && before * 3 >= sent, "{before} reports for {sent} states in {seconds} s while the trajectory was checked: {long}");
    // Each report came soon after the state it is stamped with was sent (the node's check of a
    // state takes milliseconds; a stalled loop would hold them for the whole trajectory).
    assert!(long["latencies"].as_u64().unwrap() >= 10, "{long}");
    assert!(long["max_latency"].as_f64().unwrap() < 1.0, "the live stream stalled: {long}");
}

/// A trajectory point: positions, velocities, accelerations, time from start (ns).
type Point = (Vec<f64>, Vec<f64>, Vec<f64>, i64);

/// A trajectory of the bundled arm for `check --trajectory` (its JSON file) and for the peer.
fn executed_request(names: &[String], points: &[Point]) -> (Value, Value) {
    let file = json!({
        "joint_names": names,
        "points": points.iter().map(|(p, v, a, t)| json!({"positions": p, "velocities": v, "accelerations": a,
            "time_from_start": {"sec": t / 1_000_000_000, "nanosec": t % 1_000_000_000}})).collect::<Vec<_>>(),
    });
    let peer = json!({
        "joint_names": names,
        "points": points.iter().map(|(p, v, a, t)| json!({"positions": p, "velocities": v, "accelerations": a, "t": t})).collect::<Vec<_>>(),
    });
    (file, peer)
}

/// Issue 34: trajectories with velocities and accelerations, executed as the controller would
/// from the state the node last received (published by the peer, at rest), over DDS: each answer
/// equals `check --trajectory FILE --json --joints <that state>` (segment, fraction, time to the
/// nanosecond, contacts), and the set has both answers and an approach.
#[test]
fn executed_trajectories_over_dds_equal_check_trajectory() {
    let (dir, cyclone) = scratch("executed");
    let arm = Arm::new();
    let mut rng = Rand64::new(34);
    let start = arm.free_step(&mut rng, None, 0.0);
    let mut cases = Vec::new();
    for k in 0..10 {
        let mut p = start.clone();
        let mut t = if k % 3 == 0 { 0 } else { 400_000_000 + 100_000_000 * k as i64 };
        let points: Vec<Point> = (0..3)
            .map(|_| {
                p = arm.random(&mut rng, Some(&p), 0.5);
                let v: Vec<f64> = p.iter().map(|_| 1.6 * rng.rand_float() - 0.8).collect();
                let a: Vec<f64> = if k % 2 == 0 { p.iter().map(|_| 6.0 * rng.rand_float() - 3.0).collect() } else { Vec::new() };
                let point = (p.clone(), v, a, t);
                t += 600_000_000;
                point
            })
            .collect();
        cases.push(executed_request(&arm.names, &points));
    }
    let joints: String = arm.names.iter().zip(&start).map(|(n, x)| format!("{n}={x}")).collect::<Vec<_>>().join(",");
    let cli: Vec<Value> = cases
        .iter()
        .enumerate()
        .map(|(k, (file, _))| {
            let path = dir.join(format!("trajectory_{k}.json"));
            std::fs::write(&path, file.to_string()).unwrap();
            let o = Command::new(env!("CARGO_BIN_EXE_thickness_collision"))
                .args(["check", "--trajectory", path.to_str().unwrap(), "--json", "--joints", &joints])
                .output()
                .unwrap();
            assert!(o.status.success(), "check --trajectory {k}: {}", String::from_utf8_lossy(&o.stderr));
            serde_json::from_slice(&o.stdout).unwrap()
        })
        .collect();
    assert!(cli.iter().any(|c| c["in_collision"] == true) && cli.iter().any(|c| c["in_collision"] == false), "both answers: {cli:?}");

    let domain = 168;
    let (node, _out, _banner) = start_node(&[], domain);
    let state = json!({"name": arm.names, "position": start, "stamp": 5_000_000_000i64});
    let trajectories: Vec<Value> = cases.iter().map(|(_, peer)| peer.clone()).collect();
    let answer = common::run_cyclone_peer(
        "trajectory_peer.py",
        &cyclone,
        &json!({"domain": domain, "state": state, "trajectories": trajectories, "timeout": 60}).to_string(),
    );
    common::stop_node(node);
    let answers = answer["answers"].as_array().unwrap();
    assert_eq!(answers.len(), cli.len(), "{answer}");
    for (k, (got, want)) in answers.iter().zip(&cli).enumerate() {
        assert_eq!(got["error"], "", "case {k}: {got}");
        assert_eq!(got["valid"].as_bool(), want["in_collision"].as_bool().map(|c| !c), "case {k}: {got} vs {want}");
        if got["valid"] == true {
            continue;
        }
        assert_eq!(got["segment"], want["segment"], "case {k}");
        assert_eq!(got["fraction"], want["fraction"], "case {k}");
        let ns = got["time_from_start"].as_i64().unwrap();
        assert!((ns as f64 * 1e-9 - want["time"].as_f64().unwrap()).abs() < 1e-9, "case {k}: {ns} ns vs {}", want["time"]);
        let (g, w) = (got["contacts"].as_array().unwrap(), want["contacts"].as_array().unwrap());
        assert_eq!(g.len(), w.len(), "case {k}");
        for (a, b) in g.iter().zip(w) {
            for key in ["link_name", "object_name", "triangle"] {
                assert_eq!(a[key], b[key], "case {k}: {key}");
            }
        }
    }
}
