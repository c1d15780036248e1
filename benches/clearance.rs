//! Clearance against coal's `distance`: the Panda (example-robot-data), random joint states (fixed
//! seed), the peer benchmark's world of 1M thin-surface triangles (`benches/peer_compare_core.rs`).
//! Ours: the full state check (deepest contacts) with `clearance_threshold` 5 cm, against the same
//! check without clearance. coal 3.0.3: `distance` from each link part's convex hull to the
//! plain mesh (one OBBRSS BVH), per state, Python overhead taken off. One core, load excluded.
//!
//! `cargo bench --bench clearance`   (TC_CLEARANCE_STATES, TC_CLEARANCE_SIZE to change the run)

#[path = "peer_compare_core.rs"]
mod peer_compare_core;

use peer_compare_core::*;
use std::process::Command;
use std::time::Instant;
use thickness_collision::checker::Checker;
use thickness_collision::collision::TargetShape;
use thickness_collision::math::Pose;
use thickness_collision::model::Params;

const THRESHOLD: f64 = 0.05;

fn main() {
    if std::env::args().any(|a| a == "--test" || a == "--list") {
        return;
    }
    let n_states: usize = std::env::var("TC_CLEARANCE_STATES").ok().and_then(|s| s.parse().ok()).unwrap_or(2_000);
    let size: usize = std::env::var("TC_CLEARANCE_SIZE").ok().and_then(|s| s.parse().ok()).unwrap_or(1_000_000);
    let py = python();
    let (robot, map) = panda(&py);
    let states = random_states(&robot, n_states, 1);
    let dir = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/clearance_bench");
    std::fs::create_dir_all(&dir).unwrap();

    let w = world(size);
    let triangles = w.triangles.len();
    scaffold::write_le(&dir.join("env_vertices.f64"), &w.vertices);
    scaffold::write_le(&dir.join("env_triangles.u32"), &w.triangles);
    let params = Params { package_map: map.clone(), clearance_threshold: THRESHOLD, ..Params::default() };
    let checker = Checker::from_robot_and_scene(params.clone(), robot.clone(), w.scene, "panda".into()).unwrap();
    // The same world built again for the check without clearance (the scene is not shared).
    let plain_params = Params { clearance_threshold: 0.0, ..params };
    let plain = Checker::from_robot_and_scene(plain_params, robot.clone(), world(size).scene, "panda".into()).unwrap();

    // Both checks interleaved in blocks of 100 states (the machine is shared).
    let (mut with_s, mut plain_s) = (0.0, 0.0);
    let (mut near_links, mut near_states) = (0usize, 0usize);
    for block in states.chunks(100) {
        let started = Instant::now();
        for (names, pos) in block {
            let r = checker.check_joints(names, pos).unwrap();
            near_links += r.clearances.len();
            near_states += usize::from(!r.clearances.is_empty());
        }
        with_s += started.elapsed().as_secs_f64();
        let started = Instant::now();
        for (names, pos) in block {
            let _ = plain.check_joints(names, pos).unwrap();
        }
        plain_s += started.elapsed().as_secs_f64();
    }

    // coal: each link part's hull, posed per state.
    let mut parts: Vec<(usize, std::sync::Arc<thickness_collision::collision::ConvexHull>, Pose)> = Vec::new();
    for (ti, t) in checker.targets().iter().enumerate() {
        for (shape, offset) in &t.parts {
            match shape {
                TargetShape::Polytope(h) => parts.push((ti, h.clone(), *offset)),
                other => panic!("link {}: coal gets convex hulls only, not {other:?}", t.name),
            }
        }
    }
    for (i, (_, hull, _)) in parts.iter().enumerate() {
        let (pts, tri) = hull.vertices_and_triangles();
        scaffold::write_le(&dir.join(format!("part{i}_vertices.f64")), &pts);
        scaffold::write_le(&dir.join(format!("part{i}_triangles.u32")), &tri);
    }
    let mut poses: Vec<f64> = Vec::with_capacity(states.len() * parts.len() * 12);
    for (names, pos) in &states {
        let mut q = vec![0.0; robot.joints.len()];
        for (n, p) in names.iter().zip(pos) {
            q[robot.joint(n).unwrap()] = *p;
        }
        let links = robot.forward_kinematics(&q, &nalgebra::Isometry3::identity()).unwrap();
        for (ti, _, offset) in &parts {
            let p = thickness_collision::math::pose_from_isometry(&links[checker.targets()[*ti].link]) * *offset;
            poses.extend_from_slice(&thickness_collision::math::pose_rows(&p));
        }
    }
    scaffold::write_le(&dir.join("poses.f64"), &poses);
    std::fs::write(dir.join("meta.json"), serde_json::json!({"states": states.len(), "parts": parts.len()}).to_string()).unwrap();
    let script = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("benches/clearance_coal.py");
    let out = Command::new(&py).arg(&script).arg(&dir).output().unwrap();
    assert!(out.status.success(), "clearance_coal.py: {}", String::from_utf8_lossy(&out.stderr));
    let coal: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("coal_distance.json")).unwrap()).unwrap();
    let coal_s = coal["seconds"].as_f64().unwrap();
    let coal_near = coal["distances"].as_array().unwrap().iter().filter(|row| row.as_array().unwrap().iter().any(|d| d.as_f64().unwrap() <= THRESHOLD)).count();

    let per = |s: f64| s / states.len() as f64 * 1e6;
    let (ours, plain, theirs) = (per(with_s), per(plain_s), per(coal_s));
    println!(
        "{} random Panda states, {triangles} triangles, {} cells, clearance_threshold {THRESHOLD} m, {} link parts, one core\n",
        states.len(),
        checker.scene().cell_count(),
        parts.len()
    );
    println!("| check | µs/state | ratio |");
    println!("|---|---:|---:|");
    println!("| ours: full check with clearance | {ours:.1} | {:.2} of coal's distance |", ours / theirs);
    println!("| ours: full check without clearance | {plain:.1} | with / without: {:.2} |", ours / plain);
    println!("| coal 3.0.3 `distance`, every part to the plain mesh | {theirs:.1} | |");
    println!(
        "\nstates with a link within {THRESHOLD} m: ours {near_states} (to the cells; {near_links} link clearances), coal {coal_near} (to the plain mesh)"
    );
}
