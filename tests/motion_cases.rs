//! Issue 12, the cases a motion check exists for: a link jumping through a thin sheet between two
//! free states; a rotating link whose swept volume leaves the convex hull of its two end poses
//! (what swept-hull checkers miss); and the bundled arm's continuous, prismatic and mimic joints,
//! against dense sampling that interpolates them the same way (shorter arc, mimic from master).

mod common;

use oorandom::Rand64;
use parry3d_f64::query;
use parry3d_f64::shape::ConvexPolyhedron;
use std::path::Path;
use std::process::Command;
use thickness_collision::checker::Checker;
use thickness_collision::collision::Scene;
use thickness_collision::math::{Pose, Rotation, Vector};
use thickness_collision::mesh::generate;
use thickness_collision::model::{JointKind, PackageResolver, Params, RobotModel};

/// Positions along a motion as `check_motion` defines it: continuous joints by the shorter arc,
/// mimic joints from their master.
fn along(robot: &RobotModel, q0: &[f64], q1: &[f64], s: f64) -> Vec<f64> {
    let mut q: Vec<f64> = robot
        .joints
        .iter()
        .zip(q0.iter().zip(q1))
        .map(|(j, (a, b))| {
            let d =
                if j.kind == JointKind::Continuous { (b - a + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI } else { b - a };
            a + s * d
        })
        .collect();
    for (i, j) in robot.joints.iter().enumerate() {
        if let Some(m) = j.mimic {
            q[i] = m.multiplier * q[m.joint] + m.offset;
        }
    }
    q
}

/// The bundled arm's motions, every joint moving (the continuous wrist often across ±π, the
/// prismatic finger with its mimic), against samples 0.5 mm apart at the fastest point.
#[test]
fn the_bundled_arm_with_continuous_prismatic_and_mimic_joints_agrees_with_dense_sampling() {
    let c = Checker::from_params(Params::default()).unwrap();
    let robot = c.robot();
    let mut rng = Rand64::new(7);
    let (mut caught, mut free, mut through_sheet) = (0, 0, 0);
    for m in 0..240 {
        let mut q0 = vec![0.0; robot.joints.len()];
        let mut q1 = q0.clone();
        for (j, joint) in robot.joints.iter().enumerate() {
            let (lo, hi) = match joint.kind {
                JointKind::Continuous => (-3.1, 3.1),
                JointKind::Revolute | JointKind::Prismatic => (joint.limits[0], joint.limits[1]),
                _ => continue,
            };
            if joint.mimic.is_some() {
                continue;
            }
            q0[j] = lo + (hi - lo) * rng.rand_float();
            // Half the motions small, half across the whole range (those cross the surfaces).
            q1[j] = if joint.kind == JointKind::Revolute && m % 2 == 0 {
                (q0[j] + 0.8 * (rng.rand_float() - 0.5)).clamp(lo, hi)
            } else {
                lo + (hi - lo) * rng.rand_float()
            };
        }
        let r = c.check_motion(&q0, &q1);
        assert!(r.report.error.is_empty(), "{}", r.report.error);
        // 1.2 m bounds every point's distance from any axis of this arm; prismatic travel 4 cm.
        let total: f64 = (0..robot.joints.len()).map(|j| (along(robot, &q0, &q1, 1.0)[j] - q0[j]).abs()).sum();
        let n = ((1.2 * total / 1e-3).ceil() as usize).max(1);
        let first = (0..=n).map(|k| k as f64 / n as f64).find(|&s| c.check_positions(&along(robot, &q0, &q1, s)).unwrap().in_collision);
        let ends_free = !c.check_positions(&q0).unwrap().in_collision && !c.check_positions(&q1).unwrap().in_collision;
        match first {
            Some(s) => {
                assert!(r.report.in_collision, "motion {m}: free, but the sample at {s} collides");
                assert!(s >= r.fraction.unwrap() - 1.0 / n as f64, "motion {m}: a contact at {s} before the fraction {:?}", r.fraction);
                caught += 1;
                // Between two free states, through one of the thin surfaces (not the table).
                let hit = c.check_positions(&along(robot, &q0, &q1, s)).unwrap();
                through_sheet += (ends_free && hit.contacts.iter().any(|c| c.object_name != "table")) as usize;
            }
            None => free += !r.report.in_collision as usize,
        }
    }
    eprintln!("240 arm motions: {caught} colliding caught ({through_sheet} through a thin surface between two free states), {free} free");
    assert!(through_sheet >= 5, "the sample must cross thin surfaces between free states");
    assert!(free >= 30);
}

/// A 1 m bar turning about z from -100° to +100°: both ends point away from a sheet at x = 0.8,
/// and so does the convex hull of the two end poses; the bar sweeps through it at 0°.
#[test]
fn a_rotating_link_leaving_the_hull_of_its_end_poses_is_caught() {
    let urdf = r#"<robot name="bar"><link name="base"/><link name="bar"><collision><origin xyz="0.5 0 0"/><geometry><box size="1 0.04 0.04"/></geometry></collision></link>
<joint name="turn" type="revolute"><parent link="base"/><child link="bar"/><axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint></robot>"#;
    let robot = RobotModel::from_str(urdf, "bar.urdf", Path::new("."), &PackageResolver::default(), false).unwrap();
    let (v, t) = generate::flat_grid(4, 4, 0.6, 0.6);
    let area = common::thin_area(&v, &t, 0.01);
    // The grid lies in z = 0 around the origin; stood up at x = 0.8, facing -x.
    let sheet_pose = Pose::from_parts(Vector::new(0.8, 0.0, 0.0), Rotation::from_rotation_y(std::f64::consts::FRAC_PI_2));
    let mut scene = Scene::new();
    let _ = scene.add_surface("sheet", sheet_pose, area.clone());
    let c = Checker::from_robot_and_scene(Params::default(), robot, scene, "bar.urdf".into()).unwrap();
    let (q0, q1) = ([-1.745], [1.745]);
    assert!(!c.check_positions(&q0).unwrap().in_collision && !c.check_positions(&q1).unwrap().in_collision);
    // The swept-hull test: the hull of the bar at both ends against every cell, by parry.
    let corners = |angle: f64| -> Vec<Vector> {
        let rot = Rotation::from_rotation_z(angle);
        (0..8)
            .map(|i| rot * Vector::new(if i & 1 == 0 { 0.0 } else { 1.0 }, if i & 2 == 0 { -0.02 } else { 0.02 }, if i & 4 == 0 { -0.02 } else { 0.02 }))
            .collect()
    };
    let ends: Vec<Vector> = [corners(q0[0]), corners(q1[0])].concat();
    let swept_hull = ConvexPolyhedron::from_convex_hull(&ends).unwrap();
    for cell in &area.cells {
        let cell_shape = ConvexPolyhedron::from_convex_hull(&cell.distinct_vertices()).unwrap();
        assert!(
            !query::intersection_test(&Pose::IDENTITY, &swept_hull, &sheet_pose, &cell_shape).unwrap().intersecting,
            "the hull of the end poses must miss the sheet"
        );
    }
    let r = c.check_motion(&q0, &q1);
    assert!(r.report.in_collision, "{r:?}");
    assert_eq!(r.report.contacts[0].object_name, "sheet");
    // The first contact by dense sampling (the bar's tip moves 0.35 mm per sample).
    let n = 10_000;
    let first = (0..=n).map(|k| k as f64 / n as f64).find(|s| c.check_positions(&[q0[0] + s * (q1[0] - q0[0])]).unwrap().in_collision).unwrap();
    let f = r.fraction.unwrap();
    assert!(f <= first && f > first - 0.01, "fraction {f}, first contact at {first}");
}

/// `check --states --motion`: the first line is a state, each further line the motion to it.
#[test]
fn check_motion_on_the_command_line() {
    let dir = common::scratch_dir("motion_cases");
    let states = dir.join("path.jsonl");
    let line = |lift: f64, elbow: f64| format!("{{\"name\": [\"shoulder_lift_joint\", \"elbow_joint\"], \"position\": [{lift}, {elbow}]}}\n");
    // The first waypoint is the whole arm (missing_joint: last waits for every joint); the others
    // move two joints.
    let first = "{\"name\": [\"shoulder_pan_joint\", \"shoulder_lift_joint\", \"elbow_joint\", \"wrist_1_joint\", \"wrist_2_joint\", \"wrist_3_joint\", \"finger_left_joint\"], \"position\": [0, 0, 0, 0, 0, 0, 0]}\n";
    std::fs::write(&states, first.to_owned() + &line(0.3, 0.0) + &line(1.2, 0.3)).unwrap();
    let out =
        Command::new(env!("CARGO_BIN_EXE_thickness_collision")).args(["check", "--motion", "--json", "--states", states.to_str().unwrap()]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let reports: Vec<serde_json::Value> = String::from_utf8(out.stdout).unwrap().lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(reports.len(), 3);
    assert_eq!((reports[0]["motion"].as_bool(), reports[0]["fraction"].is_null()), (Some(false), true));
    assert_eq!((reports[1]["motion"].as_bool(), reports[1]["in_collision"].as_bool()), (Some(true), Some(false)));
    assert_eq!((reports[2]["motion"].as_bool(), reports[2]["in_collision"].as_bool()), (Some(true), Some(true)));
    let f = reports[2]["fraction"].as_f64().unwrap();
    assert!(f > 0.0 && f < 1.0, "{f}");
    // --motion needs --states.
    let out = Command::new(env!("CARGO_BIN_EXE_thickness_collision")).args(["check", "--motion", "--joints", "elbow_joint=0"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
}
