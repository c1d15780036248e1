//! Trajectories as the controller executes them (issue 34): the Panda among the peer benchmark's
//! 1M-triangle world, one core, load time excluded.
//!
//!   cargo bench --bench trajectory       # SEGMENTS=2000 TRAJECTORIES=20 DENSE=5 by default
//!
//! Prints a markdown table:
//! - per segment, on the motion benchmark's planner-like edges (each arm joint 0.1-1 rad, 1 s):
//!   the linear check (`check_motion`), the spline check of the same path timed as a cubic from
//!   rest to rest (every joint `p0 + (p1 - p0)(3s² - 2s³)`: the chord again, at another pace),
//!   and of a cubic with end velocities of up to 0.8 rad/s per joint (it bulges off the chord),
//!   interleaved, with the ratios to the linear check;
//! - `TRAJECTORIES` 100-point trajectories from ruckig (`benches/ruckig_trajectories.py`, jerk
//!   limited through 5 random waypoints, sampled with positions, velocities and accelerations as
//!   MoveIt passes them on), checked segment by segment as quintics, beside dense sampling of the
//!   same quintics at the same guarantee on the first `DENSE` (steps of `motion_tolerance` at the
//!   fastest point by the 1.2 m lever bound, links grown by half the tolerance, flags-only checks,
//!   stopping at the first contact).

#[path = "peer_compare_core.rs"]
mod peer_compare_core;

use oorandom::Rand64;
use std::process::Command;
use std::time::Instant;
use thickness_collision::checker::{Checker, SegmentPoly, SplineSegment};
use thickness_collision::model::{Padding, Params};

fn env_usize(name: &str, default: usize) -> usize {
    std::env::var(name).ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

/// One ruckig trajectory: times and per-instant positions, velocities, accelerations (7 joints).
#[derive(serde::Deserialize)]
struct Sampled {
    t: Vec<f64>,
    p: Vec<Vec<f64>>,
    v: Vec<Vec<f64>>,
    a: Vec<Vec<f64>>,
}

/// A planner-like edge: start and end positions, start and end velocities (every joint).
type Edge = (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>);

fn main() {
    let segments = env_usize("SEGMENTS", 2_000);
    let trajectories = env_usize("TRAJECTORIES", 20);
    let dense = env_usize("DENSE", 5).min(trajectories);
    let py = peer_compare_core::python();
    let (robot, map) = peer_compare_core::panda(&py);
    let world = peer_compare_core::world(1_000_000);
    let cells = world.scene.cell_count();
    let (world_vertices, world_triangles) = (world.vertices.clone(), world.triangles.clone());
    let params = Params { package_map: map.clone(), ..Params::default() };
    let tol = params.motion_tolerance;
    let checker = Checker::from_robot_and_scene(params, robot.clone(), world.scene, "panda".into()).unwrap();
    let n = checker.robot().joints.len();
    let names: Vec<String> = checker.robot().joints.iter().map(|j| j.name.clone()).collect();
    let arm: Vec<usize> = (1..=7).map(|i| checker.robot().joint(&format!("panda_joint{i}")).unwrap()).collect();
    let mut rng = Rand64::new(2026);
    let mut draw = |lo: f64, hi: f64| lo + (hi - lo) * rng.rand_float();
    let edges: Vec<Edge> = (0..segments)
        .map(|_| {
            let (mut q0, mut q1, mut v0, mut v1) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
            for &j in &arm {
                let [lo, hi] = checker.robot().joints[j].limits;
                q0[j] = draw(lo, hi);
                let d = draw(0.1, 1.0) * if draw(0.0, 1.0) < 0.5 { 1.0 } else { -1.0 };
                q1[j] = (q0[j] + d).clamp(lo, hi);
                (v0[j], v1[j]) = (draw(-0.8, 0.8), draw(-0.8, 0.8));
            }
            (q0, q1, v0, v1)
        })
        .collect();
    let spline = |q0: &[f64], q1: &[f64], v0: &[f64], v1: &[f64]| SplineSegment {
        joints: (0..n).map(|j| SegmentPoly::cubic(q0[j], v0[j], q1[j], v1[j], 1.0)).collect(),
        tolerance: Vec::new(),
    };
    let rest = vec![0.0; n];
    // As the node does at start (see benches/motion.rs).
    checker.prepare_motion_checks();
    for (q0, q1, v0, v1) in edges.iter().take(100) {
        let _ = (checker.check_motion(q0, q1), checker.check_spline(&spline(q0, q1, v0, v1)));
    }
    let (mut linear, mut same_path, mut bulging) = (0.0, 0.0, 0.0);
    let (mut hits, mut disagree) = ([0usize; 3], 0usize);
    for (q0, q1, v0, v1) in &edges {
        let started = Instant::now();
        let a = checker.check_motion(q0, q1);
        linear += started.elapsed().as_secs_f64();
        let chord = spline(q0, q1, &rest, &rest);
        let started = Instant::now();
        let b = checker.check_spline(&chord);
        same_path += started.elapsed().as_secs_f64();
        let bulge = spline(q0, q1, v0, v1);
        let started = Instant::now();
        let c = checker.check_spline(&bulge);
        bulging += started.elapsed().as_secs_f64();
        for (h, r) in hits.iter_mut().zip([&a, &b, &c]) {
            *h += r.report.in_collision as usize;
        }
        disagree += (a.report.in_collision != b.report.in_collision) as usize;
    }
    let per = |s: f64| s / segments as f64 * 1e6;
    println!("Panda, {cells} cells (1M triangles), one core, motion_tolerance {tol} m; {segments} segments, each arm joint 0.1-1 rad in 1 s:\n");
    println!("| measure | value |");
    println!("|---|---|");
    println!("| linear (`check_motion`), mean per segment | {:.1} µs ({} in collision) |", per(linear), hits[0]);
    println!(
        "| spline, the same chord as a cubic from rest to rest | {:.1} µs ({} in collision; {disagree} answers differ from the linear check's) |",
        per(same_path),
        hits[1]
    );
    println!("| spline / linear, same path | **{:.2}** |", same_path / linear);
    println!("| spline, cubic with end velocities up to 0.8 rad/s | {:.1} µs ({} in collision) |", per(bulging), hits[2]);
    println!("| spline with velocities / linear | **{:.2}** |", bulging / linear);

    if trajectories == 0 {
        return;
    }
    let file = std::env::temp_dir().join(format!("tc_ruckig_{}.json", std::process::id()));
    let script = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/ruckig_trajectories.py");
    let ok = Command::new(&py).arg(&script).args([&trajectories.to_string(), "100", "34", file.to_str().unwrap()]).status().unwrap();
    assert!(ok.success(), "ruckig_trajectories.py failed (pip install ruckig: scripts/setup_venv.sh has it)");
    let sampled: Vec<Sampled> = serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
    let _ = std::fs::remove_file(&file);
    let full = |x: &[f64]| -> Vec<f64> {
        let mut q = vec![0.0; n];
        arm.iter().zip(x).for_each(|(&j, &v)| q[j] = v);
        q
    };
    let segments_of = |s: &Sampled| -> Vec<SplineSegment> {
        (0..s.t.len() - 1)
            .map(|i| {
                let (a, b) = (full(&s.p[i]), full(&s.p[i + 1]));
                let (va, vb, aa, ab) = (full(&s.v[i]), full(&s.v[i + 1]), full(&s.a[i]), full(&s.a[i + 1]));
                let d = s.t[i + 1] - s.t[i];
                SplineSegment { joints: (0..n).map(|j| SegmentPoly::quintic(a[j], va[j], aa[j], b[j], vb[j], ab[j], d)).collect(), tolerance: Vec::new() }
            })
            .collect()
    };
    // Ours: every segment until the first that is not free.
    let check = |segs: &[SplineSegment]| -> (bool, u64) {
        let mut spent = 0;
        for seg in segs {
            let r = checker.check_spline(seg);
            spent += r.subintervals;
            if r.report.in_collision {
                return (true, spent);
            }
        }
        (false, spent)
    };
    let all: Vec<Vec<SplineSegment>> = sampled.iter().map(segments_of).collect();
    let (mut ours, mut colliding, mut verdicts) = (0.0, 0usize, Vec::new());
    for segs in &all {
        let started = Instant::now();
        let hit = check(segs).0;
        ours += started.elapsed().as_secs_f64();
        colliding += hit as usize;
        verdicts.push(hit);
    }
    println!(
        "| {trajectories} ruckig trajectories, 100 points, 7 joints ({:.1} s long on average): ours, mean per trajectory | {:.2} ms ({colliding} in collision) |",
        sampled.iter().map(|s| s.t[s.t.len() - 1]).sum::<f64>() / trajectories as f64,
        ours / trajectories as f64 * 1e3
    );
    coal_moveit(&py, &checker, &sampled, &full, &world_vertices, &world_triangles, ours, &verdicts);
    if dense == 0 {
        return;
    }
    let grown_params = Params { package_map: map, padding: Padding { links: vec!["*".into()], values: vec![tol / 2.0] }, ..Params::default() };
    let grown = Checker::from_robot_and_scene(grown_params, robot, peer_compare_core::world(1_000_000).scene, "panda, grown".into()).unwrap();
    let (mut dense_seconds, mut ours_seconds, mut samples) = (0.0, 0.0, 0usize);
    for segs in all.iter().take(dense) {
        let started = Instant::now();
        'walk: for seg in segs {
            let speed: f64 = seg.joints.iter().map(SegmentPoly::top_speed).sum();
            let steps = ((1.2 * speed / tol).ceil() as usize).max(1);
            for k in 0..=steps {
                samples += 1;
                if grown.check_joints_flags(&names, &seg.at(k as f64 / steps as f64)).unwrap().in_collision {
                    break 'walk;
                }
            }
        }
        dense_seconds += started.elapsed().as_secs_f64();
        let started = Instant::now();
        let _ = check(segs);
        ours_seconds += started.elapsed().as_secs_f64();
    }
    println!(
        "| dense sampling at the same guarantee, first {dense} trajectories | {:.1} ms per trajectory ({:.0} samples each) |",
        dense_seconds / dense as f64 * 1e3,
        samples as f64 / dense as f64
    );
    println!("| ours on the same {dense} | {:.2} ms per trajectory |", ours_seconds / dense as f64 * 1e3);
    println!("| dense sampling / ours | **{:.1}** |", dense_seconds / ours_seconds);
}

/// coal with MoveIt-style validation of the same trajectories (`benches/coal_motion.py`, the
/// environment only): every waypoint and, between two, the straight chord sampled every
/// `longest_valid_segment_fraction` 0.005 of the joint-space extent (MoveIt's distance: the sum of
/// the joints' distances; the extent: the sum of their ranges), stopping at the first colliding
/// state. No guarantee between samples, and the chords are not the executed splines.
#[allow(clippy::too_many_arguments)]
fn coal_moveit(
    py: &std::path::Path,
    checker: &Checker,
    sampled: &[Sampled],
    full: &dyn Fn(&[f64]) -> Vec<f64>,
    world_vertices: &[[f64; 3]],
    world_triangles: &[[u32; 3]],
    ours: f64,
    verdicts: &[bool],
) {
    let dir = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("trajectory_coal");
    let parts = peer_compare_core::write_coal_inputs(&dir, checker, world_vertices, world_triangles);
    let robot = checker.robot();
    let arm: Vec<usize> = (1..=7).map(|i| robot.joint(&format!("panda_joint{i}")).unwrap()).collect();
    let extent: f64 = arm.iter().map(|&j| robot.joints[j].limits[1] - robot.joints[j].limits[0]).sum();
    let step = 0.005 * extent;
    let states: Vec<Vec<Vec<f64>>> = sampled
        .iter()
        .map(|s| {
            let mut out = Vec::new();
            for w in s.p.windows(2) {
                let d: f64 = w[0].iter().zip(&w[1]).map(|(a, b)| (b - a).abs()).sum();
                let n = ((d / step).ceil() as usize).max(1);
                out.extend((0..n).map(|k| full(&w[0].iter().zip(&w[1]).map(|(a, b)| a + (b - a) * k as f64 / n as f64).collect::<Vec<_>>())));
            }
            out.push(full(&s.p[s.p.len() - 1]));
            out
        })
        .collect();
    let longest = states.iter().map(Vec::len).max().unwrap_or(0);
    let mut poses: Vec<f64> = Vec::with_capacity(states.len() * longest * parts.len() * 12);
    for trajectory in &states {
        for k in 0..longest {
            let q = &trajectory[k.min(trajectory.len() - 1)];
            let links = robot.forward_kinematics(q, checker.base_pose()).unwrap();
            for (ti, offset) in &parts {
                let p = thickness_collision::math::pose_from_isometry(&links[checker.targets()[*ti].link]) * *offset;
                poses.extend_from_slice(&thickness_collision::math::pose_rows(&p));
            }
        }
    }
    peer_compare_core::scaffold::write_le(&dir.join("motion_poses.f64"), &poses);
    let counts: Vec<usize> = states.iter().map(Vec::len).collect();
    let meta = serde_json::json!({"motions": states.len(), "samples": longest, "parts": parts.len(), "counts": counts});
    std::fs::write(dir.join("meta.json"), meta.to_string()).unwrap();
    let script = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("benches/coal_motion.py");
    let out = Command::new(py).arg(&script).arg(&dir).output().unwrap();
    assert!(out.status.success(), "coal_motion.py: {}", String::from_utf8_lossy(&out.stderr));
    let coal: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("coal_motion.json")).unwrap()).unwrap();
    let hits: Vec<bool> = coal["hits"].as_array().unwrap().iter().map(|h| h.as_u64() == Some(1)).collect();
    let coal_seconds = coal["seconds"].as_f64().unwrap();
    let m = states.len();
    let missed = hits.iter().zip(verdicts).filter(|(coal_hit, ours_hit)| !**coal_hit && **ours_hit).count();
    println!(
        "| coal, MoveIt-style validation ({:.0} states per trajectory on average, stopping at the first colliding one) | {:.2} ms per trajectory ({} calls to collide; {} of {m} in collision) |",
        counts.iter().sum::<usize>() as f64 / m as f64,
        coal_seconds / m as f64 * 1e3,
        coal["calls"],
        hits.iter().filter(|h| **h).count()
    );
    println!("| **coal MoveIt-style / ours** | **{:.2}** |", coal_seconds / ours);
    println!("| trajectories MoveIt-style validation passes that ours finds colliding when executed | {missed} of {m} |");
}
