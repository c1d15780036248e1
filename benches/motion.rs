//! Motions against states (issue 12): the Panda among the peer benchmark's 1M-triangle world,
//! planner-like motions (each arm joint moves 0.1–1 rad), one core, load time excluded.
//!
//!   cargo bench --bench motion            # MOTIONS=10000 DENSE=100 by default
//!
//! Prints a markdown table: the mean time per motion of `check_motion` beside the mean time per
//! state of the discrete check on the motions' end states, and, on the first `DENSE` motions,
//! beside dense discrete sampling at the resolution that gives the same guarantee (steps of
//! `motion_tolerance` at the fastest-moving point, with the 1.2 m lever bound of the Panda). The
//! dense samples are checked ungrown (growing every link by half the tolerance, as the same
//! guarantee needs, would cost more): the ratio is a lower bound.

#[path = "peer_compare_core.rs"]
mod peer_compare_core;

use oorandom::Rand64;
use std::time::Instant;
use thickness_collision::checker::Checker;
use thickness_collision::model::Params;

fn main() {
    let motions: usize = std::env::var("MOTIONS").ok().and_then(|v| v.parse().ok()).unwrap_or(10_000);
    let dense: usize = std::env::var("DENSE").ok().and_then(|v| v.parse().ok()).unwrap_or(100);
    let py = peer_compare_core::python();
    let (robot, map) = peer_compare_core::panda(&py);
    let world = peer_compare_core::world(1_000_000);
    let cells = world.scene.cell_count();
    let checker = Checker::from_robot_and_scene(Params { package_map: map, ..Params::default() }, robot, world.scene, "panda".into()).unwrap();
    let robot = checker.robot();
    let arm: Vec<usize> = (1..=7).map(|i| robot.joint(&format!("panda_joint{i}")).unwrap()).collect();
    let mut rng = Rand64::new(2026);
    let pairs: Vec<(Vec<f64>, Vec<f64>)> = (0..motions)
        .map(|_| {
            let mut q0 = vec![0.0; robot.joints.len()];
            let mut q1 = q0.clone();
            for &j in &arm {
                let [lo, hi] = robot.joints[j].limits;
                q0[j] = lo + (hi - lo) * rng.rand_float();
                let d = (0.1 + 0.9 * rng.rand_float()) * if rng.rand_u64() % 2 == 0 { 1.0 } else { -1.0 };
                q1[j] = (q0[j] + d).clamp(lo, hi);
            }
            (q0, q1)
        })
        .collect();

    // Warm: the growth ladder of every link is built on first use.
    for (q0, q1) in pairs.iter().take(50) {
        let _ = checker.check_motion(q0, q1);
    }
    let started = Instant::now();
    let (mut colliding, mut subintervals) = (0usize, 0u64);
    for (q0, q1) in &pairs {
        let r = checker.check_motion(q0, q1);
        colliding += r.report.in_collision as usize;
        subintervals += r.subintervals;
    }
    let motion_mean = started.elapsed().as_secs_f64() / motions as f64;
    let started = Instant::now();
    let mut end_colliding = 0usize;
    for (_, q1) in &pairs {
        end_colliding += checker.check_positions(q1).unwrap().in_collision as usize;
    }
    let state_mean = started.elapsed().as_secs_f64() / motions as f64;

    // Dense sampling at equal resolution on the first motions, and the motion check on the same.
    let tol = checker.params().motion_tolerance;
    let (mut dense_seconds, mut ours_seconds, mut samples, mut sampled_colliding, mut disagree) = (0.0, 0.0, 0usize, 0usize, 0usize);
    for (q0, q1) in pairs.iter().take(dense) {
        let total: f64 = arm.iter().map(|&j| (q1[j] - q0[j]).abs()).sum();
        let n = ((1.2 * total / tol).ceil() as usize).max(1);
        let started = Instant::now();
        let mut hit = false;
        for k in 0..=n {
            let s = k as f64 / n as f64;
            let q: Vec<f64> = q0.iter().zip(q1).map(|(a, b)| a + s * (b - a)).collect();
            samples += 1;
            if checker.check_positions(&q).unwrap().in_collision {
                hit = true;
                break;
            }
        }
        dense_seconds += started.elapsed().as_secs_f64();
        sampled_colliding += hit as usize;
        let started = Instant::now();
        let r = checker.check_motion(q0, q1);
        ours_seconds += started.elapsed().as_secs_f64();
        // A sampled contact the motion check reports free would be a defect.
        disagree += (hit && !r.report.in_collision) as usize;
    }
    assert_eq!(disagree, 0, "a densely sampled contact reported free");

    println!("Panda, {cells} cells (1M triangles), one core, motion_tolerance {tol} m; {motions} motions, each arm joint 0.1-1 rad:\n");
    println!("| measure | value |");
    println!("|---|---|");
    println!(
        "| `check_motion`, mean per motion | {:.1} µs ({:.1} sub-intervals, {colliding} of {motions} in collision) |",
        motion_mean * 1e6,
        subintervals as f64 / motions as f64
    );
    println!("| discrete check of the end states, mean per state | {:.1} µs ({end_colliding} in collision) |", state_mean * 1e6);
    println!("| motion / state | {:.2} |", motion_mean / state_mean);
    println!(
        "| dense sampling at steps of {tol} m, first {dense} motions, stopping at the first contact | {:.1} ms per motion ({:.0} samples per motion, {sampled_colliding} in collision) |",
        dense_seconds / dense as f64 * 1e3,
        samples as f64 / dense as f64
    );
    println!("| `check_motion` on the same {dense} motions | {:.1} µs per motion |", ours_seconds / dense as f64 * 1e6);
    println!("| dense sampling / `check_motion` | {:.0} |", dense_seconds / ours_seconds);
}
