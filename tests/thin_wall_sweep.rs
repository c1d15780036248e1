//! End to end, the reason the product exists: a real arm link (the Panda hand, its STL collision
//! mesh as a convex hull) moved in 5 mm steps on a straight path through a one-layer wall with
//! t = 2 cm. `check` (the CLI) reports a collision at exactly the steps where some part of the
//! link lies within t behind the wall (or crosses it); coal on the plain wall mesh misses the
//! steps where the link lies wholly behind the surface.

mod common;

use serde_json::json;
use std::process::Command;
use thickness_collision::math::{Pose, Rotation, Vector};
use thickness_collision::mesh::generate;
use thickness_collision::model::{read_mesh, write_obj};

const WALL_X: f64 = 0.5;
const T: f64 = 0.02;

#[test]
fn a_link_behind_the_wall_is_caught_where_coal_misses_it() {
    let erd = common::example_robot_data();
    let panda = erd.join("robots/panda_description/urdf/panda.urdf");
    let hand_stl = erd.join("robots/panda_description/meshes/collision/hand.stl");
    let dir = common::scratch_dir("thin_wall_sweep");

    // The wall: a flat 1 x 1 m sheet of 800 triangles standing at x = 0.5, front towards -x.
    let (wv, wt) = generate::flat_grid(20, 20, 1.0, 1.0);
    write_obj(&dir.join("wall.obj"), &wv, &wt, "test wall").unwrap();
    std::fs::write(
        dir.join("wall.urdf"),
        format!(r#"<robot name="cell"><link name="world"/><link name="wall"><collision><geometry><mesh filename="wall.obj"/></geometry></collision></link>
<joint name="w" type="fixed"><parent link="world"/><child link="wall"/><origin xyz="{WALL_X} 1 0" rpy="1.5707963267948966 0 -1.5707963267948966"/></joint></robot>"#),
    )
    .unwrap();
    let wall_pose = Pose::from_parts(
        Vector::new(WALL_X, 1.0, 0.0),
        Rotation::from_euler(glam::EulerRot::ZYX, -std::f64::consts::FRAC_PI_2, 0.0, std::f64::consts::FRAC_PI_2),
    );

    // The hand, tilted, its centre moving along +x through the wall's middle in 5 mm steps.
    let hand = read_mesh(&hand_stl, Vector::ONE).unwrap();
    let rot = Rotation::from_axis_angle(Vector::new(1.0, 2.0, 0.5).normalize(), 0.7);
    let steps: Vec<Pose> = (0..=100).map(|k| Pose::from_parts(Vector::new(0.25 + 0.005 * k as f64, 0.5, 0.5), rot)).collect();
    let mut lines = String::new();
    for p in &steps {
        let q = p.rotation;
        lines += &json!({"transforms": [{"link": "panda_hand", "translation": p.translation.to_array(), "rotation": [q.x, q.y, q.z, q.w]}]}).to_string();
        lines.push('\n');
    }
    std::fs::write(dir.join("states.jsonl"), lines).unwrap();
    // Only the hand is placed, so only the hand is checked (a transforms line must place every
    // checked link).
    std::fs::write(dir.join("hand_only.yaml"), "thickness_collision:\n  ros__parameters:\n    checked_links: [panda_hand]\n").unwrap();

    let out = Command::new(env!("CARGO_BIN_EXE_thickness_collision"))
        .args(["check", "--robot", panda.to_str().unwrap(), "--environment", dir.join("wall.urdf").to_str().unwrap()])
        .args(["--params-file", dir.join("hand_only.yaml").to_str().unwrap()])
        .args(["--thickness", &T.to_string(), "--states", dir.join("states.jsonl").to_str().unwrap(), "--json"])
        .env("AMENT_PREFIX_PATH", erd.parent().unwrap().parent().unwrap())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let ours: Vec<bool> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap()["in_collision"].as_bool().unwrap())
        .collect();
    assert_eq!(ours.len(), steps.len());

    // coal on the plain wall mesh (no thickness), hand mesh against wall mesh.
    let poses: Vec<Vec<f64>> = steps
        .iter()
        .map(|p| {
            let rel = wall_pose.inv_mul(p);
            thickness_collision::math::pose_rows(&rel).to_vec()
        })
        .collect();
    let mesh_json = |v: &[Vector], t: &[[u32; 3]]| json!({"vertices": v.iter().map(|p| p.to_array()).collect::<Vec<_>>(), "triangles": t});
    let coal = common::run_peer("coal_sweep.py", &json!({"wall": mesh_json(&wv, &wt), "link": mesh_json(&hand.vertices, &hand.triangles), "poses": poses}));
    let coal: Vec<bool> = coal.as_array().unwrap().iter().map(|b| b.as_bool().unwrap()).collect();

    // Expected from the hand's own vertices: its extent along x against the wall and the slab.
    let (mut behind_only, mut ambiguous, mut missed) = (0, 0, 0);
    for (k, p) in steps.iter().enumerate() {
        let xs: Vec<f64> = hand.vertices.iter().map(|v| (*p * *v).x).collect();
        let (lo, hi) = xs.iter().fold((f64::MAX, f64::MIN), |(a, b), x| (a.min(*x), b.max(*x)));
        if [lo - WALL_X, hi - WALL_X, lo - WALL_X - T].iter().any(|d| d.abs() < 1e-6) {
            ambiguous += 1;
            continue;
        }
        let expected = hi > WALL_X && lo < WALL_X + T;
        assert_eq!(ours[k], expected, "step {k}: x from {lo:.4} to {hi:.4}");
        let wholly_behind = lo > WALL_X && lo < WALL_X + T;
        behind_only += wholly_behind as usize;
        if ours[k] && !coal[k] {
            missed += 1;
            assert!(wholly_behind, "step {k}: coal misses a link that is not wholly behind the surface");
        }
        if wholly_behind {
            assert!(!coal[k], "step {k}: coal sees a link wholly behind a surface it has no inside for?");
        }
        if hi < WALL_X {
            assert!(!coal[k] && !ours[k]);
        }
    }
    eprintln!(
        "{} steps of 5 mm: thickness_collision reports {} colliding, coal {}; coal misses {missed} steps where the hand lies wholly within t = {T} m behind the wall",
        steps.len(),
        ours.iter().filter(|b| **b).count(),
        coal.iter().filter(|b| **b).count()
    );
    assert_eq!(ambiguous, 0);
    assert!(missed >= 3, "the path must have steps wholly behind the surface");
    assert_eq!(missed, behind_only);
}
