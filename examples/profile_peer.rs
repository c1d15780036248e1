//! Where the time of the peer benchmark goes (not part of the benchmark): per world, colliding
//! vs free states, candidates, survivors.
#[path = "../benches/peer_compare_core.rs"]
mod peer_compare_core;
use peer_compare_core::*;
use std::time::Instant;
use thickness_collision::checker::{Checker, JointMemory};
use thickness_collision::collision::{CollideSettings, Target};
use thickness_collision::math::pose_from_isometry;
use thickness_collision::model::Params;

fn main() {
    let n: usize = std::env::var("N").ok().and_then(|s| s.parse().ok()).unwrap_or(2000);
    let size: usize = std::env::var("SIZE").ok().and_then(|s| s.parse().ok()).unwrap_or(1_000_000);
    let py = python();
    let (robot, map) = panda(&py);
    let states = random_states(&robot, n, 1);
    let w = world(size);
    let params = Params { package_map: map.to_vec(), ..Params::default() };
    let checker = Checker::from_robot_and_scene(params, robot.clone(), w.scene, "panda".into()).unwrap();
    let mut t_col = 0.0; let mut t_free = 0.0; let mut n_col = 0;
    for (names, pos) in &states {
        let mut memory = JointMemory::new(&checker.robot);
        let s = Instant::now();
        let r = checker.check_joints(names, pos, &mut memory, true).unwrap().0;
        let e = s.elapsed().as_secs_f64();
        if r.in_collision { t_col += e; n_col += 1 } else { t_free += e }
    }
    println!("size {size}: colliding {n_col} states {:.1} us/state (total share {:.1} us/state), free {:.1} us/state (share {:.1})",
        t_col / n_col as f64 * 1e6, t_col / n as f64 * 1e6, t_free / (n - n_col) as f64 * 1e6, t_free / n as f64 * 1e6);
    // candidates per link
    let mut cand_col = 0usize; let mut cand_free = 0usize; let mut links_col = 0; let mut links_free = 0;
    let mut t_lcol = 0.0; let mut t_lfree = 0.0;
    let mut per: Vec<(f64, usize, Vec<usize>, String)> = Vec::new();
    let mut heavy: Vec<Target> = Vec::new();
    for (names, pos) in &states {
        let mut q = vec![0.0; checker.robot.joints.len()];
        for (nm, p) in names.iter().zip(pos) { q[checker.robot.joint(nm).unwrap()] = *p; }
        let poses = checker.robot.forward_kinematics(&q, &nalgebra::Isometry3::identity());
        for lt in &checker.targets {
            let lp = pose_from_isometry(&poses[lt.link]);
            for (shape, off) in &lt.parts {
                let t = Target::new(shape.clone(), lp * *off);
                let s = Instant::now();
                let r = checker.scene.collide(&t, &CollideSettings::default());
                let e = s.elapsed().as_secs_f64();
                if r.in_collision() { cand_col += r.candidates; links_col += 1; t_lcol += e; per.push((e, r.candidates, r.objects.clone(), lt.name.clone())); heavy.push(t.clone()); } else { cand_free += r.candidates; links_free += 1; t_lfree += e }
            }
        }
    }
    per.sort_by(|a, b| b.0.total_cmp(&a.0));
    let tot: f64 = per.iter().map(|p| p.0).sum();
    for q in [0.01, 0.05, 0.1, 0.25, 0.5] { let k = (per.len() as f64 * q) as usize; let share: f64 = per[..k].iter().map(|p| p.0).sum::<f64>() / tot; println!("top {q}: share {share:.2}, at {:.1} us {} cands", per[k].0*1e6, per[k].1); }
    let mut byobj = std::collections::BTreeMap::new();
    for p in &per { let e = byobj.entry(format!("{:?}", p.2)).or_insert((0.0, 0usize)); e.0 += p.0; e.1 += 1; }
    for (k, v) in byobj { println!("objects {k}: {} parts, {:.1} ms, {:.1} us each", v.1, v.0*1e3, v.0/v.1 as f64*1e6); }
    let mut bylink = std::collections::BTreeMap::new();
    for p in &per { let e = bylink.entry(p.3.clone()).or_insert((0.0, 0usize)); e.0 += p.0; e.1 += 1; }
    for (k, v) in bylink { println!("link {k}: {} parts, {:.1} ms, {:.1} us each", v.1, v.0*1e3, v.0/v.1 as f64*1e6); }
    if std::env::var_os("MICRO").is_some() {
        // support lookups in a tight loop
        let hull = checker.targets.iter().find(|t| t.name == "panda_link5").map(|t| t.parts[0].0.clone()).unwrap();
        let mut rng = oorandom::Rand64::new(7);
        let dirs: Vec<thickness_collision::math::Vector> = (0..4096).map(|_| thickness_collision::math::Vector::new(rng.rand_float()-0.5, rng.rand_float()-0.5, rng.rand_float()-0.5).normalize()).collect();
        let t = Target::new(hull, thickness_collision::math::Pose::IDENTITY);
        println!("exact bins: {:.2}", thickness_collision::collision::exact_fraction(&t));
        let s = Instant::now();
        let mut acc = 0.0;
        for _ in 0..1000 { for d in &dirs { acc += thickness_collision::collision::bench_support(&t, *d); } }
        println!("support: {:.1} ns each ({acc})", s.elapsed().as_secs_f64() / 4096e3 * 1e9);
        let s = Instant::now();
        let mut acc = 0.0;
        for _ in 0..1000 { for d in &dirs { acc += thickness_collision::math::project_points(t.shape_points(), *d)[1]; } }
        // one colliding pair from the heavy list, its SAT repeated
        for lt in &checker.targets { if let thickness_collision::collision::TargetShape::Polytope(h) = &lt.parts[0].0 { println!("{}: {} points {} faces", lt.name, h.points().len(), h.face_count()); } }
        if let Some(t0) = heavy.first() {
            let r = checker.scene.collide(t0, &CollideSettings::default());
            let c = r.contacts[0];
            let obj = &checker.scene.objects()[c.object];
            let area = obj.area().unwrap();
            let cell = area.cells.iter().find(|x| x.triangle == c.triangle).unwrap();
            let s = Instant::now();
            let mut n = 0;
            for _ in 0..20000 { if thickness_collision::collision::collide_target_cell(t0, cell, area.side, &obj.pose, false).is_some() { n += 1; } }
            println!("collide_target_cell (no point): {:.0} ns each ({n})", s.elapsed().as_secs_f64() / 20000.0 * 1e9);
            let s = Instant::now();
            for _ in 0..2000 { let _ = thickness_collision::collision::collide_target_cell(t0, cell, area.side, &obj.pose, true); }
            println!("collide_target_cell (point): {:.0} ns each", s.elapsed().as_secs_f64() / 2000.0 * 1e9);
            let s = Instant::now();
            for _ in 0..200 { let _ = checker.scene.collide(t0, &CollideSettings::default()); }
            println!("scene.collide of that part: {:.0} ns each", s.elapsed().as_secs_f64() / 200.0 * 1e9);
        }
        println!("linear scan: {:.1} ns each ({acc})", s.elapsed().as_secs_f64() / 4096e3 * 1e9);
    }
    if let Some(reps) = std::env::var("REPEAT").ok().and_then(|s| s.parse::<usize>().ok()) {
        let s = Instant::now();
        for _ in 0..reps { for t in &heavy { let _ = std::hint::black_box(checker.scene.collide(t, &CollideSettings { least_overlap: false, ..Default::default() })); } }
        println!("repeat: {:.1} us per colliding part", s.elapsed().as_secs_f64() / (reps * heavy.len()) as f64 * 1e6);
    }
    println!("  colliding parts {links_col}: {:.0} candidates each, {:.1} us each; free parts {links_free}: {:.1} candidates each, {:.2} us each",
        cand_col as f64 / links_col as f64, t_lcol / links_col as f64 * 1e6, cand_free as f64 / links_free as f64, t_lfree / links_free as f64 * 1e6);
}

#[allow(dead_code)]
fn micro() {}
