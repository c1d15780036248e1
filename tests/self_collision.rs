//! Issue 13, self-collision: the Panda (10,000 random states) and Talos (2,000) from
//! example-robot-data with their own SRDFs. Our colliding link pairs equal coal's on the same
//! convex hulls, link pair by link pair, outside a 1e-6 m band (coal 3: `collide` with GJK/EPA,
//! `distance` with `gjk_tolerance` 1e-9 for the band; `tests/peers/self_pairs_coal.py`); the
//! SRDF's disabled pairs are never reported. The part poses both sides use come from this crate's
//! forward kinematics (checked against yourdfpy in `tests/model_robots.rs`): the verdicts are what
//! is compared.

mod common;

use oorandom::Rand64;
use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::Path;
use std::process::Command;
use thickness_collision::checker::{Checker, ObjectType};
use thickness_collision::collision::{Scene, TargetShape};
use thickness_collision::model::{PackageResolver, Params, RobotModel};

struct Outcome {
    states: usize,
    colliding_pairs: usize,
    band: usize,
    disagreements: Vec<String>,
}

fn compare(name: &str, urdf: &str, srdf: &str, n: usize, seed: u64) -> Outcome {
    let root = common::example_robot_data();
    let map = vec![format!("example-robot-data={}", root.display())];
    let (urdf, srdf) = (root.join("robots").join(urdf), root.join("robots").join(srdf));
    let robot = RobotModel::from_file(&urdf, &PackageResolver::new(&map), false).unwrap();
    let params = Params { package_map: map, robot_semantic_file: srdf.display().to_string(), ..Params::default() };
    let checker = Checker::from_robot_and_scene(params, robot, Scene::new(), urdf.display().to_string()).unwrap();
    let srdf_model = checker.self_pairs().srdf.clone().expect("the SRDF was applied");
    let targets = checker.targets();
    let robot = checker.robot();
    eprintln!("{name}: {}", checker.self_pairs().summary(&checker));

    // Every part of every checked link, with its hull for coal.
    let mut parts = Vec::new(); // (target, part)
    for (ti, t) in targets.iter().enumerate() {
        for pi in 0..t.parts.len() {
            parts.push((ti, pi));
        }
    }
    let enabled: BTreeSet<(usize, usize)> = checker.self_pairs().pairs.iter().copied().collect();
    let mut part_pairs = Vec::new();
    for (i, &(ta, _)) in parts.iter().enumerate() {
        for (j, &(tb, _)) in parts.iter().enumerate().skip(i + 1) {
            if ta != tb && enabled.contains(&(ta.min(tb), ta.max(tb))) {
                part_pairs.push([i as u32, j as u32]);
            }
        }
    }
    let dir = common::emptied(common::scratch_subdir("self_collision", name));
    let mut kinds = Vec::new();
    for (k, &(ti, pi)) in parts.iter().enumerate() {
        let hull = match &targets[ti].parts[pi].0 {
            TargetShape::Polytope(hull) => hull,
            TargetShape::Sphere { radius } => {
                kinds.push(serde_json::json!({"sphere": radius}));
                continue;
            }
            TargetShape::Capsule { half_height, radius } => {
                kinds.push(serde_json::json!({"capsule": [radius, half_height]}));
                continue;
            }
            TargetShape::Cylinder { half_height, radius } => {
                kinds.push(serde_json::json!({"cylinder": [radius, half_height]}));
                continue;
            }
            other => panic!("a link's shape is never {other:?}"),
        };
        kinds.push(serde_json::json!("hull"));
        let (pts, tri) = hull.vertices_and_triangles();
        common::write_le(&dir.join(format!("part{k}_vertices.f64")), &pts);
        common::write_le(&dir.join(format!("part{k}_triangles.u32")), &tri);
    }
    common::write_le(&dir.join("pairs.u32"), &part_pairs);

    // Random states within the limits, fixed seed; ours, and the part poses for coal.
    let mut rng = Rand64::new(seed as u128);
    let mut poses: Vec<f64> = Vec::with_capacity(n * parts.len() * 12);
    let mut ours: Vec<BTreeSet<(usize, usize)>> = Vec::with_capacity(n);
    let index: HashMap<&str, usize> = targets.iter().enumerate().map(|(i, t)| (t.name.as_str(), i)).collect();
    let disabled_reported = std::cell::Cell::new(0usize);
    for _ in 0..n {
        let q: Vec<f64> = robot
            .joints
            .iter()
            .map(|j| {
                if j.is_actuated() && j.mimic.is_none() {
                    j.limits[0].max(-3.2) + (j.limits[1].min(3.2) - j.limits[0].max(-3.2)) * rng.rand_float()
                } else {
                    0.0
                }
            })
            .collect();
        let report = checker.check_positions(&q).unwrap();
        let pairs: BTreeSet<(usize, usize)> = report
            .contacts
            .iter()
            .filter(|c| c.object_type == ObjectType::RobotLink)
            .map(|c| {
                let (a, b) = (index[c.link_name.as_str()], index[c.object_name.as_str()]);
                assert!(a < b, "{name}: link_name must be the pair's first link in model order: {c:?}");
                if srdf_model.is_disabled(targets[a].link, targets[b].link) {
                    disabled_reported.set(disabled_reported.get() + 1);
                }
                (a, b)
            })
            .collect();
        ours.push(pairs);
        // The state as the checker placed it (mimic joints included).
        let world = robot.forward_kinematics(&q, checker.base_pose()).unwrap();
        for &(ti, pi) in &parts {
            let p = thickness_collision::math::pose_from_isometry(&world[targets[ti].link]) * targets[ti].parts[pi].1;
            poses.extend_from_slice(&thickness_collision::math::pose_rows(&p));
        }
    }
    assert_eq!(disabled_reported.get(), 0, "{name}: a pair the SRDF disables was reported");
    common::write_le(&dir.join("poses.f64"), &poses);
    std::fs::write(dir.join("meta.json"), serde_json::json!({"states": n, "parts": parts.len(), "kinds": kinds}).to_string()).unwrap();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/peers/self_pairs_coal.py");
    let out = Command::new(common::python()).arg(&script).arg(&dir).output().unwrap();
    assert!(out.status.success(), "self_pairs_coal.py: {}", String::from_utf8_lossy(&out.stderr));
    let coal: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(dir.join("coal.json")).unwrap()).unwrap();
    let _ = std::fs::remove_dir_all(&dir);

    let link_pair = |k: u64| {
        let [i, j] = part_pairs[k as usize];
        let (a, b) = (parts[i as usize].0, parts[j as usize].0);
        (a.min(b), a.max(b))
    };
    let mut outcome = Outcome { states: n, colliding_pairs: 0, band: 0, disagreements: Vec::new() };
    for (s, row) in coal["states"].as_array().unwrap().iter().enumerate() {
        let hits: BTreeSet<(usize, usize)> = row["hits"].as_array().unwrap().iter().map(|k| link_pair(k.as_u64().unwrap())).collect();
        let band: BTreeSet<(usize, usize)> = row["band"].as_array().unwrap().iter().map(|k| link_pair(k.as_u64().unwrap())).collect();
        outcome.colliding_pairs += hits.len();
        outcome.band += band.len();
        let mut seen: BTreeMap<(usize, usize), (bool, bool)> = BTreeMap::new();
        for p in &ours[s] {
            seen.entry(*p).or_default().0 = true;
        }
        for p in &hits {
            seen.entry(*p).or_default().1 = true;
        }
        for (p, (us, them)) in seen {
            if us != them && !band.contains(&p) {
                outcome.disagreements.push(format!("state {s}: {} x {}: ours {us}, coal {them}", targets[p.0].name, targets[p.1].name));
            }
        }
    }
    outcome
}

#[test]
fn self_collision_pairs_equal_coal_on_panda_and_talos_with_their_srdfs() {
    for (name, urdf, srdf, n, seed) in [
        ("panda", "panda_description/urdf/panda.urdf", "panda_description/srdf/panda.srdf", 10_000, 13),
        ("talos", "talos_data/robots/talos_reduced.urdf", "talos_data/srdf/talos.srdf", 2_000, 17),
    ] {
        let o = compare(name, urdf, srdf, n, seed);
        eprintln!(
            "{name}: {} states, {} colliding link pairs by coal, {} within the 1e-6 m band, {} disagreements",
            o.states,
            o.colliding_pairs,
            o.band,
            o.disagreements.len()
        );
        for d in o.disagreements.iter().take(10) {
            eprintln!("  {d}");
        }
        assert!(o.colliding_pairs > 100, "{name}: too few self contacts to show anything ({})", o.colliding_pairs);
        assert!(o.disagreements.is_empty(), "{name}: {} disagreements with coal", o.disagreements.len());
    }
}
