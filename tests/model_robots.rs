//! Real robots from example-robot-data (installed by `.ci/run`): they load, every link with
//! geometry becomes targets, and forward kinematics matches yourdfpy to 1e-9 over 1,000 random
//! joint vectors per robot.

mod common;

use nalgebra::Isometry3;
use oorandom::Rand64;
use serde_json::json;
use thickness_collision::checker::Checker;
use thickness_collision::model::{bundled_config_dir, JointKind, PackageResolver, Params, RobotModel};

fn load(rel: &str) -> (Checker, std::path::PathBuf, Vec<String>) {
    let (urdf, map) = common::erd_robot(rel);
    let params = Params { package_map: map.clone(), robot_description_file: urdf.display().to_string(), ..Params::default() };
    let checker = Checker::from_params(params).unwrap_or_else(|e| panic!("{rel}: {e}"));
    (checker, urdf, map)
}

#[test]
fn real_robots_load_and_every_link_gets_targets() {
    for rel in [
        "panda_description/urdf/panda.urdf",
        "ur_description/urdf/ur5_robot.urdf",
        "solo_description/robots/solo12.urdf",  // STL with a `solid` header
        "talos_data/robots/talos_full_v2.urdf", // negative mesh scales
    ] {
        let (checker, _, _) = load(rel);
        let with_geometry: Vec<&str> = checker.robot().links.iter().filter(|l| !l.geometry.is_empty()).map(|l| l.name.as_str()).collect();
        assert!(!with_geometry.is_empty(), "{rel}");
        assert_eq!(checker.targets().len(), with_geometry.len(), "{rel}: every link with geometry is checked");
        for t in checker.targets() {
            assert_eq!(t.parts.len(), checker.robot().links[t.link].geometry.len(), "{rel}: {}", t.name);
        }
        eprintln!("{rel}: {} links, {} with targets, {} meshes read", checker.robot().links.len(), checker.targets().len(), checker.summary().meshes_read);
    }
}

#[test]
fn solo12_binary_stl_with_solid_header_is_read() {
    let (checker, _, _) = load("solo_description/robots/solo12.urdf");
    let header_is_solid = checker.robot().links.iter().flat_map(|l| &l.geometry).any(|g| match &g.spec {
        thickness_collision::model::GeometrySpec::Mesh { path, .. } => std::fs::read(path)
            .map(|b| b.starts_with(b"solid") && b.len() == 84 + 50 * u32::from_le_bytes([b[80], b[81], b[82], b[83]]) as usize)
            .unwrap_or(false),
        _ => false,
    });
    assert!(header_is_solid, "the fixture no longer has a binary STL starting with `solid`");
}

#[test]
fn talos_negative_scales_are_mirrored() {
    let (checker, _, _) = load("talos_data/robots/talos_full_v2.urdf");
    let mirrored = checker
        .robot()
        .links
        .iter()
        .flat_map(|l| &l.geometry)
        .filter(|g| matches!(&g.spec, thickness_collision::model::GeometrySpec::Mesh { scale, .. } if scale.iter().product::<f64>() < 0.0))
        .count();
    assert!(mirrored > 0);
}

fn fk_matches_yourdfpy(urdf: &std::path::Path, map: &[String], seed: u64) {
    let model = RobotModel::from_file(urdf, &PackageResolver::new(map), false).unwrap();
    let mut rng = Rand64::new(seed as u128);
    let links: Vec<String> = model.links.iter().map(|l| l.name.clone()).collect();
    let mut configs = Vec::new();
    let mut ours = Vec::new();
    for _ in 0..1000 {
        let mut q = vec![0.0; model.joints.len()];
        let mut cfg = serde_json::Map::new();
        for (i, j) in model.joints.iter().enumerate() {
            if !j.is_actuated() {
                continue;
            }
            let (lo, hi) = match j.kind {
                JointKind::Continuous => (-std::f64::consts::PI, std::f64::consts::PI),
                _ => (j.limits[0].max(-10.0), j.limits[1].min(10.0)),
            };
            q[i] = lo + (hi - lo) * rng.rand_float();
            let _ = cfg.insert(j.name.clone(), json!(q[i]));
        }
        configs.push(serde_json::Value::Object(cfg));
        ours.push(model.forward_kinematics(&q, &Isometry3::identity()).unwrap());
    }
    let theirs = common::run_peer("fk_yourdfpy.py", &json!({"urdf": urdf, "links": links, "configs": configs}));
    let theirs = theirs.as_array().unwrap();
    assert_eq!(theirs.len(), ours.len());
    let mut worst: f64 = 0.0;
    for (k, (a, b)) in ours.iter().zip(theirs).enumerate() {
        for (li, pose) in a.iter().enumerate() {
            let m = pose.to_homogeneous();
            let t: Vec<f64> = b[li].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect();
            for r in 0..3 {
                for c in 0..4 {
                    let d = (m[(r, c)] - t[r * 4 + c]).abs();
                    worst = worst.max(d);
                    assert!(d < 1e-9, "{}: config {k}, link {}: entry ({r},{c}) differs by {d}", urdf.display(), links[li]);
                }
            }
        }
    }
    eprintln!("{}: 1000 configurations x {} links, largest difference {worst:e}", urdf.display(), links.len());
}

#[test]
fn panda_forward_kinematics_matches_yourdfpy() {
    let (urdf, map) = common::erd_robot("panda_description/urdf/panda.urdf");
    fk_matches_yourdfpy(&urdf, &map, 1);
}

#[test]
fn ur5_forward_kinematics_matches_yourdfpy() {
    let (urdf, map) = common::erd_robot("ur_description/urdf/ur5_robot.urdf");
    fk_matches_yourdfpy(&urdf, &map, 2);
}

#[test]
fn bundled_arm_with_mimic_matches_yourdfpy() {
    let urdf = bundled_config_dir().join("example_workcell/robot.urdf");
    fk_matches_yourdfpy(&urdf, &[], 3);
}
