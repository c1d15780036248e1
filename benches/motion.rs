//! Motions against states (issue 12): the Panda among the peer benchmark's 1M-triangle world,
//! planner-like motions (each arm joint moves 0.1–1 rad), one core, load time excluded.
//!
//!   cargo bench --bench motion            # MOTIONS=10000 DENSE=100 COAL=1000 by default
//!   WORLD=wall cargo bench --bench motion # one wavy 1M-triangle wall facing the arm instead
//!
//! Prints a markdown table: the mean time per motion of `check_motion` beside the mean time per
//! state of the discrete check on the motions' end states (timed in turn, motion then state, so
//! that a load on the machine weighs on both alike); on the first `DENSE` motions, beside
//! dense discrete sampling at the resolution that gives the same guarantee (steps of
//! `motion_tolerance` at the fastest-moving point, with the 1.2 m lever bound of the Panda, every
//! link grown by half the tolerance, each sample a flags-only check); and on the first `COAL`
//! motions (default 1,000; 0 skips), beside coal with MoveIt-style sampling (201 states per
//! motion, `benches/coal_motion.py`, the environment only), with the count of motions that
//! sampling passes but that collide with the environment: reported colliding by `check_motion`
//! and confirmed by dense sampling from the reported fraction on (those where the arm meets
//! itself first are counted apart).

#[path = "peer_compare_core.rs"]
mod peer_compare_core;
#[path = "wall_1m.rs"]
mod wall_1m;

use oorandom::Rand64;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;
use thickness_collision::checker::{Checker, ObjectType};
use thickness_collision::collision::TargetShape;
use thickness_collision::math::{pose_from_isometry, Pose, Vector};
use thickness_collision::model::{Padding, Params};

fn env_usize(name: &str, default: usize) -> usize {
    std::env::var(name).ok().and_then(|v| v.parse().ok()).unwrap_or(default)
}

/// Joint positions at `s` along a motion.
type Along<'a> = &'a dyn Fn(&[f64], &[f64], f64) -> Vec<f64>;
/// Dense samples for a motion.
type DenseSteps<'a> = &'a dyn Fn(&[f64], &[f64]) -> usize;

/// MoveIt-style sampling: `longest_valid_segment_fraction` 0.005, 201 states per motion.
const MOVEIT_STATES: usize = 201;

fn main() {
    let motions = env_usize("MOTIONS", 10_000);
    let dense = env_usize("DENSE", 100).min(motions);
    let coal_motions = env_usize("COAL", 1_000).min(motions);
    let py = peer_compare_core::python();
    let (robot, map) = peer_compare_core::panda(&py);
    let world = bench_world();
    let cells = world.scene.cell_count();
    let (world_vertices, world_triangles) = (world.vertices, world.triangles);
    let params = Params { package_map: map.clone(), ..Params::default() };
    let tol = params.motion_tolerance;
    let checker = Checker::from_robot_and_scene(params, robot.clone(), world.scene, "panda".into()).unwrap();
    let robot = checker.robot();
    let names: Vec<String> = robot.joints.iter().map(|j| j.name.clone()).collect();
    let arm: Vec<usize> = (1..=7).map(|i| robot.joint(&format!("panda_joint{i}")).unwrap()).collect();
    let mut rng = Rand64::new(2026);
    let pairs: Vec<(Vec<f64>, Vec<f64>)> = (0..motions)
        .map(|_| {
            let mut q0 = vec![0.0; robot.joints.len()];
            let mut q1 = q0.clone();
            for &j in &arm {
                let [lo, hi] = robot.joints[j].limits;
                q0[j] = lo + (hi - lo) * rng.rand_float();
                let d = (0.1 + 0.9 * rng.rand_float()) * if rng.rand_u64().is_multiple_of(2) { 1.0 } else { -1.0 };
                q1[j] = (q0[j] + d).clamp(lo, hi);
            }
            (q0, q1)
        })
        .collect();
    let along = |q0: &[f64], q1: &[f64], s: f64| -> Vec<f64> { q0.iter().zip(q1).map(|(a, b)| a + s * (b - a)).collect() };
    // Steps of `tol` at the fastest point: 1.2 m bounds any Panda point's distance from an axis.
    let dense_steps = |q0: &[f64], q1: &[f64]| -> usize {
        let total: f64 = arm.iter().map(|&j| (q1[j] - q0[j]).abs()).sum();
        ((1.2 * total / tol).ceil() as usize).max(1)
    };

    // Built before timing, as the node builds it at start: the growth ladder of every link (a
    // first use builds what it needs; 200 motions left a third of it to the timed loop, 3 % of
    // its time on the wall). The warm motions warm the caches.
    checker.prepare_motion_checks();
    for (q0, q1) in pairs.iter().take(200) {
        let _ = checker.check_motion(q0, q1);
    }
    // Interleaved, motion then state, so that a load on the machine weighs on both alike.
    let (mut motion_seconds, mut state_seconds) = (0.0, 0.0);
    let (mut colliding, mut subintervals, mut end_colliding) = (0usize, 0u64, 0usize);
    let mut reports = Vec::with_capacity(motions);
    for (q0, q1) in &pairs {
        let started = Instant::now();
        let r = checker.check_motion(q0, q1);
        motion_seconds += started.elapsed().as_secs_f64();
        let started = Instant::now();
        end_colliding += checker.check_positions(q1).unwrap().in_collision as usize;
        state_seconds += started.elapsed().as_secs_f64();
        colliding += r.report.in_collision as usize;
        subintervals += r.subintervals;
        reports.push(r);
    }
    let motion_mean = motion_seconds / motions as f64;
    let state_mean = state_seconds / motions as f64;

    println!("Panda, {cells} cells (1M triangles, {}), one core, motion_tolerance {tol} m; {motions} motions, each arm joint 0.1-1 rad:\n", world_name());
    println!("| measure | value |");
    println!("|---|---|");
    println!(
        "| `check_motion`, mean per motion | {:.1} µs ({:.1} link tests, {colliding} of {motions} in collision) |",
        motion_mean * 1e6,
        subintervals as f64 / motions as f64
    );
    println!("| discrete check of the end states, mean per state | {:.1} µs ({end_colliding} in collision) |", state_mean * 1e6);
    println!("| motion / state | {:.2} |", motion_mean / state_mean);

    // Dense sampling at equal guarantee: samples `tol` apart at the fastest point, every link grown
    // by `tol / 2` (padding: faces out by exactly that), each sample a flags-only check.
    if dense > 0 {
        let grown_params = Params { package_map: map.clone(), padding: Padding { links: vec!["*".into()], values: vec![tol / 2.0] }, ..Params::default() };
        let grown = Checker::from_robot_and_scene(grown_params, robot.clone(), bench_world().scene, "panda, grown".into()).unwrap();
        let (mut dense_seconds, mut ours_seconds, mut samples, mut sampled_colliding, mut disagree) = (0.0, 0.0, 0usize, 0usize, 0usize);
        for (q0, q1) in pairs.iter().take(dense) {
            let n = dense_steps(q0, q1);
            let started = Instant::now();
            let mut hit = false;
            for k in 0..=n {
                samples += 1;
                if grown.check_joints_flags(&names, &along(q0, q1, k as f64 / n as f64)).unwrap().in_collision {
                    hit = true;
                    break;
                }
            }
            dense_seconds += started.elapsed().as_secs_f64();
            sampled_colliding += hit as usize;
            let started = Instant::now();
            let r = checker.check_motion(q0, q1);
            ours_seconds += started.elapsed().as_secs_f64();
            // A motion both say is free where the other does not is allowed (near misses within
            // the tolerance); a contact of the ungrown links reported free is checked below.
            disagree += (hit && !r.report.in_collision && {
                let n = dense_steps(q0, q1);
                (0..=n).any(|k| checker.check_joints_flags(&names, &along(q0, q1, k as f64 / n as f64)).unwrap().in_collision)
            }) as usize;
        }
        assert_eq!(disagree, 0, "a densely sampled contact reported free");
        println!(
            "| dense sampling, steps of {tol} m at the fastest point, links grown by {} m, first {dense} motions, stopping at the first contact | {:.1} ms per motion ({:.0} samples per motion, {sampled_colliding} in collision) |",
            tol / 2.0,
            dense_seconds / dense as f64 * 1e3,
            samples as f64 / dense as f64
        );
        println!("| `check_motion` on the same {dense} motions | {:.1} µs per motion |", ours_seconds / dense as f64 * 1e6);
        println!("| dense sampling / `check_motion` | {:.1} |", dense_seconds / ours_seconds);
    }

    if coal_motions > 0 {
        coal_moveit(&py, &checker, &pairs[..coal_motions], &reports[..coal_motions], &world_vertices, &world_triangles, &names, &along, &dense_steps);
    }
}

/// `WORLD`: `peer` (default) or `wall`.
fn world_name() -> String {
    std::env::var("WORLD").unwrap_or_else(|_| "peer".into())
}

/// The peer benchmark's world (a guard, a scanned wall and a shelf), or one wavy 7 x 7 m wall of
/// 1M triangles standing 0.5 m in front of the arm's base, its front towards the arm (local x
/// along world -y, local y up, local z towards -x), from 1 m below the base.
fn bench_world() -> peer_compare_core::World {
    match world_name().as_str() {
        "wall" => {
            use thickness_collision::math::Rotation;
            let pose = Pose::from_parts(
                Vector::new(0.5, 3.5, -1.0),
                Rotation::from_rotation_z(-std::f64::consts::FRAC_PI_2) * Rotation::from_rotation_x(std::f64::consts::FRAC_PI_2),
            );
            peer_compare_core::world_from(vec![("wavy_wall".into(), wall_1m::wall(708, 708), pose)])
        }
        "peer" => peer_compare_core::world(1_000_000),
        other => panic!("WORLD={other}: `peer` or `wall`"),
    }
}

/// coal with MoveIt-style sampling on `pairs`, beside `check_motion`, and the motions it passes
/// that collide.
#[allow(clippy::too_many_arguments)]
fn coal_moveit(
    py: &Path,
    checker: &Checker,
    pairs: &[(Vec<f64>, Vec<f64>)],
    reports: &[thickness_collision::checker::MotionReport],
    world_vertices: &[[f64; 3]],
    world_triangles: &[[u32; 3]],
    names: &[String],
    along: Along,
    dense_steps: DenseSteps,
) {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("motion_coal");
    let parts = peer_compare_core::write_coal_inputs(&dir, checker, world_vertices, world_triangles);
    let robot = checker.robot();
    let mut poses: Vec<f64> = Vec::with_capacity(pairs.len() * MOVEIT_STATES * parts.len() * 12);
    for (q0, q1) in pairs {
        for k in 0..MOVEIT_STATES {
            let links = robot.forward_kinematics(&along(q0, q1, k as f64 / (MOVEIT_STATES - 1) as f64), checker.base_pose()).unwrap();
            for (ti, offset) in &parts {
                let p = pose_from_isometry(&links[checker.targets()[*ti].link]) * *offset;
                poses.extend_from_slice(&thickness_collision::math::pose_rows(&p));
            }
        }
    }
    peer_compare_core::scaffold::write_le(&dir.join("motion_poses.f64"), &poses);
    let meta = serde_json::json!({"motions": pairs.len(), "samples": MOVEIT_STATES, "parts": parts.len()});
    std::fs::write(dir.join("meta.json"), meta.to_string()).unwrap();
    let script = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("benches/coal_motion.py");
    let out = Command::new(py).arg(&script).arg(&dir).output().unwrap();
    assert!(out.status.success(), "coal_motion.py: {}", String::from_utf8_lossy(&out.stderr));
    let coal: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("coal_motion.json")).unwrap()).unwrap();
    let hits: Vec<bool> = coal["hits"].as_array().unwrap().iter().map(|h| h.as_u64() == Some(1)).collect();
    let coal_seconds = coal["seconds"].as_f64().unwrap();

    let started = Instant::now();
    for (q0, q1) in pairs {
        let _ = checker.check_motion(q0, q1);
    }
    let ours_seconds = started.elapsed().as_secs_f64();

    // Motions coal passes that we report colliding: confirmed when a dense sample (steps of the
    // tolerance at the fastest point, links as they are) from the reported fraction on collides
    // with the environment (coal was given the environment only: a motion where the arm meets
    // itself first is counted apart); of those, the ones where a colliding link's hull meets the
    // bare triangles themselves at one of the dense samples (parry), not only the cells' 2 cm
    // behind them.
    let trimesh = parry3d_f64::shape::TriMesh::new(world_vertices.iter().map(|p| Vector::from_array(*p)).collect(), world_triangles.to_vec()).unwrap();
    let (mut passed, mut reported, mut confirmed, mut through_surface, mut own) = (0usize, 0usize, 0usize, 0usize, 0usize);
    for (((q0, q1), r), coal_hit) in pairs.iter().zip(reports).zip(&hits) {
        if *coal_hit {
            continue;
        }
        passed += 1;
        if !r.report.in_collision {
            continue;
        }
        if r.report.contacts.iter().all(|c| c.object_type == ObjectType::RobotLink) {
            own += 1;
            continue;
        }
        reported += 1;
        let n = dense_steps(q0, q1);
        let k0 = (r.fraction.unwrap() * n as f64).floor() as usize;
        let mut first = None;
        let mut meets = false;
        for k in k0..=n {
            let q = along(q0, q1, k as f64 / n as f64);
            let mut flags = checker.check_joints_flags(names, &q).unwrap();
            flags.contacts.retain(|c| c.object_type == ObjectType::Environment);
            if flags.contacts.is_empty() {
                continue;
            }
            first.get_or_insert(k);
            let links = robot.forward_kinematics(&q, checker.base_pose()).unwrap();
            meets = flags.contacts.iter().any(|c| {
                let t = checker.targets().iter().find(|t| t.name == c.link_name).unwrap();
                t.parts.iter().any(|(shape, offset)| {
                    let TargetShape::Polytope(h) = shape else { return false };
                    let pose: Pose = pose_from_isometry(&links[t.link]) * *offset;
                    parry3d_f64::query::intersection_test(&pose, h.as_parry(), &Pose::IDENTITY, &trimesh).unwrap().intersecting
                })
            });
            if meets || k > first.unwrap() + 2 * n / 10 {
                break;
            }
        }
        confirmed += first.is_some() as usize;
        through_surface += meets as usize;
    }
    let m = pairs.len();
    println!(
        "| coal, MoveIt-style sampling ({MOVEIT_STATES} states per motion, stopping at the first colliding state), first {m} motions | {:.1} µs per motion ({} calls to collide; {} of {m} in collision) |",
        coal_seconds / m as f64 * 1e6,
        coal["calls"],
        hits.iter().filter(|h| **h).count()
    );
    println!("| `check_motion` on the same {m} motions | {:.1} µs per motion |", ours_seconds / m as f64 * 1e6);
    println!("| coal MoveIt-style / `check_motion` | {:.2} |", coal_seconds / ours_seconds);
    println!(
        "| **motions MoveIt-style sampling passes that collide** with the environment | **{confirmed}** of the {passed} it passes ({reported} reported colliding with it by `check_motion`, {confirmed} confirmed by dense sampling; in {through_surface} of them a link meets the bare triangles, not only the 2 cm cells behind them) |"
    );
    println!("| motions coal passed where the arm meets itself first (coal was not asked) | {own} |");
}
