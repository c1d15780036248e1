//! Self-collision against coal (issue 13): the Panda with its SRDF (example-robot-data), 10,000
//! random states, one core; the same link pairs (the SRDF's enabled ones) as the same convex
//! hulls. Ours: the full state check with an empty environment (forward kinematics, every
//! enabled pair, contacts with depth); coal 3: `collide` on every enabled pair of parts, with the
//! Python loop's own cost measured and taken off (benches/self_collision_coal.py).
//!
//!   TC_PYTHON=<venv python> RAYON_NUM_THREADS=1 cargo bench --bench self_collision   # STATES=10000

#[path = "peer_compare_core.rs"]
mod peer_compare_core;

use oorandom::Rand64;
use std::path::Path;
use std::process::Command;
use std::time::Instant;
use thickness_collision::checker::Checker;
use thickness_collision::collision::{Scene, TargetShape};
use thickness_collision::model::Params;

fn main() {
    let n: usize = std::env::var("STATES").ok().and_then(|v| v.parse().ok()).unwrap_or(10_000);
    let py = peer_compare_core::python();
    let (robot, map) = peer_compare_core::panda(&py);
    let erd = map[0].split_once('=').unwrap().1.to_owned();
    let srdf = Path::new(&erd).join("robots/panda_description/srdf/panda.srdf");
    let params = Params { package_map: map, robot_semantic_file: srdf.display().to_string(), ..Params::default() };
    let checker = Checker::from_robot_and_scene(params, robot, Scene::new(), "panda".into()).unwrap();
    let targets = checker.targets();
    let robot = checker.robot();
    let pairs = &checker.self_pairs().pairs;

    let mut rng = Rand64::new(2026);
    let states: Vec<Vec<f64>> = (0..n)
        .map(|_| {
            robot
                .joints
                .iter()
                .map(|j| if j.is_actuated() && j.mimic.is_none() { j.limits[0] + (j.limits[1] - j.limits[0]) * rng.rand_float() } else { 0.0 })
                .collect()
        })
        .collect();
    let started = Instant::now();
    let mut colliding = 0usize;
    for q in &states {
        colliding += usize::from(checker.check_positions(q).unwrap().in_collision);
    }
    let ours = started.elapsed().as_secs_f64();

    // The same hulls and part poses for coal.
    let dir = peer_compare_core::scaffold::emptied(peer_compare_core::scaffold::scratch_dir("bench_self"));
    let mut parts = Vec::new();
    for (ti, t) in targets.iter().enumerate() {
        for (pi, (shape, _)) in t.parts.iter().enumerate() {
            let TargetShape::Polytope(hull) = shape else { panic!("Panda links are meshes") };
            let (pts, tri) = hull.vertices_and_triangles();
            peer_compare_core::scaffold::write_le(&dir.join(format!("part{}_vertices.f64", parts.len())), &pts);
            peer_compare_core::scaffold::write_le(&dir.join(format!("part{}_triangles.u32", parts.len())), &tri);
            parts.push((ti, pi));
        }
    }
    let mut part_pairs: Vec<[u32; 2]> = Vec::new();
    for (i, &(ta, _)) in parts.iter().enumerate() {
        for (j, &(tb, _)) in parts.iter().enumerate().skip(i + 1) {
            if pairs.contains(&(ta.min(tb), ta.max(tb))) {
                part_pairs.push([i as u32, j as u32]);
            }
        }
    }
    let mut poses: Vec<f64> = Vec::with_capacity(n * parts.len() * 12);
    for q in &states {
        let world = robot.forward_kinematics(q, checker.base_pose()).unwrap();
        for &(ti, pi) in &parts {
            let p = thickness_collision::math::pose_from_isometry(&world[targets[ti].link]) * targets[ti].parts[pi].1;
            poses.extend_from_slice(&thickness_collision::math::pose_rows(&p));
        }
    }
    peer_compare_core::scaffold::write_le(&dir.join("poses.f64"), &poses);
    peer_compare_core::scaffold::write_le(&dir.join("pairs.u32"), &part_pairs);
    std::fs::write(dir.join("meta.json"), serde_json::json!({"states": n, "parts": parts.len()}).to_string()).unwrap();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/self_collision_coal.py");
    let out = Command::new(&py).arg(&script).arg(&dir).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let coal: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    let coal_seconds = coal["seconds"].as_f64().unwrap();
    let coal_colliding = coal["colliding_states"].as_u64().unwrap();
    println!(
        "Panda with its SRDF, {n} random states, {} of {} link pairs enabled ({} part pairs), one core",
        pairs.len(),
        targets.len() * (targets.len() - 1) / 2,
        part_pairs.len()
    );
    println!("| measure | value |");
    println!("|---|---|");
    println!(
        "| ours: state check, empty environment (FK, every enabled pair, depth) | {:.2} µs per state ({colliding} states in collision) |",
        ours / n as f64 * 1e6
    );
    println!(
        "| coal 3 `collide` on the same part pairs (loop overhead {:.2} µs per state taken off) | {:.2} µs per state ({coal_colliding} states in collision) |",
        coal["overhead_seconds"].as_f64().unwrap() / n as f64 * 1e6,
        coal_seconds / n as f64 * 1e6
    );
    println!("| ours / coal | **{:.3}** (goal ≤ 0.3) |", ours / coal_seconds);
}
