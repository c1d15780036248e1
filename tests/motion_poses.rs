//! Issue 12 with `/tf` input: motions between link poses (`Checker::check_world_motion`), each
//! link along the straight line between its positions and the shortest rotation between its
//! orientations. A bar jumping through a sheet between two free poses is caught; a free motion is
//! free; the shortest rotation is the one taken; and a few hundred random pose motions agree with
//! an oracle that samples each motion densely (every point of the bar moves less than 1 mm
//! between samples), interpolating with glam's own slerp.

mod common;

use oorandom::Rand64;
use std::path::Path;
use thickness_collision::checker::Checker;
use thickness_collision::collision::Scene;
use thickness_collision::math::{Pose, Rotation, Vector};
use thickness_collision::mesh::generate;
use thickness_collision::model::{PackageResolver, Params, RobotModel};

/// A 1 m bar (4 cm square) from its link's origin along +x, and a 0.6 m sheet standing at
/// x = 0.8 (1 cm thick), as in tests/motion_cases.rs.
fn bar_and_sheet() -> Checker {
    let urdf = r#"<robot name="bar"><link name="base"/><link name="bar"><collision><origin xyz="0.5 0 0"/><geometry><box size="1 0.04 0.04"/></geometry></collision></link>
<joint name="turn" type="revolute"><parent link="base"/><child link="bar"/><axis xyz="0 0 1"/><limit lower="-2" upper="2" effort="1" velocity="1"/></joint></robot>"#;
    let robot = RobotModel::from_str(urdf, "bar.urdf", Path::new("."), &PackageResolver::default(), false).unwrap();
    let (v, t) = generate::flat_grid(6, 6, 0.6, 0.6);
    let area = common::thin_area(&v, &t, 0.01);
    let sheet_pose = Pose::from_parts(Vector::new(0.8, 0.0, 0.0), Rotation::from_rotation_y(std::f64::consts::FRAC_PI_2));
    let mut scene = Scene::new();
    let _ = scene.add_surface("sheet", sheet_pose, area);
    Checker::from_robot_and_scene(Params::default(), robot, scene, "bar.urdf".into()).unwrap()
}

/// The world poses of the two links (`base`, `bar`) with the bar at `bar`.
fn world(c: &Checker, bar: Pose) -> Vec<Option<Pose>> {
    let mut w = vec![None; c.robot().links.len()];
    w[c.robot().links.iter().position(|l| l.name == "bar").unwrap()] = Some(bar);
    w
}

fn free(c: &Checker, bar: Pose) -> bool {
    !c.check_world_poses(&world(c, bar)).unwrap().in_collision
}

#[test]
fn a_bar_jumping_through_a_sheet_between_two_free_poses_is_caught() {
    let c = bar_and_sheet();
    let (a, b) = (Pose::from_translation(Vector::new(-0.5, 0.0, 0.0)), Pose::from_translation(Vector::new(0.9, 0.05, 0.0)));
    assert!(free(&c, a) && free(&c, b));
    let r = c.check_world_motion(&world(&c, a), &world(&c, b));
    assert!(r.report.in_collision && r.report.motion && r.report.error.is_empty(), "{r:?}");
    assert_eq!(r.report.contacts[0].object_name, "sheet");
    // The bar's tip reaches the sheet's back (x = 0.79) at s = 0.29/1.4.
    let f = r.fraction.unwrap();
    assert!(f <= 0.29 / 1.4 + 1e-9 && f > 0.29 / 1.4 - 0.01, "{f}");
}

#[test]
fn a_free_pose_motion_is_free_and_the_rotation_taken_is_the_shortest() {
    let c = bar_and_sheet();
    let a = Pose::from_translation(Vector::new(-0.5, 0.0, 0.0));
    let b = Pose::from_parts(Vector::new(-0.5, 0.6, 0.3), Rotation::from_rotation_z(0.5));
    let r = c.check_world_motion(&world(&c, a), &world(&c, b));
    assert!(!r.report.in_collision && r.report.motion && r.fraction.is_none(), "{r:?}");
    // About the origin from -100° to +100°: the shortest rotation (160°) passes behind, free;
    // from -80° to +80° it passes through 0°, through the sheet.
    let turn = |deg: f64| Pose::from_rotation(Rotation::from_rotation_z(deg.to_radians()));
    assert!(free(&c, turn(-100.0)) && free(&c, turn(100.0)) && free(&c, turn(-80.0)) && free(&c, turn(80.0)));
    let r = c.check_world_motion(&world(&c, turn(-100.0)), &world(&c, turn(100.0)));
    assert!(!r.report.in_collision, "{r:?}");
    let r = c.check_world_motion(&world(&c, turn(-80.0)), &world(&c, turn(80.0)));
    assert!(r.report.in_collision && r.report.contacts[0].object_name == "sheet", "{r:?}");
}

#[test]
fn a_checked_link_without_a_pose_fails_closed() {
    let c = bar_and_sheet();
    let a = world(&c, Pose::IDENTITY);
    let none = vec![None; c.robot().links.len()];
    for (from, to) in [(&a, &none), (&none, &a)] {
        let r = c.check_world_motion(from, to);
        assert!(r.report.in_collision && r.report.motion && !r.report.error.is_empty(), "{r:?}");
    }
    let r = c.check_world_motion(&a, &a[..1]);
    assert!(r.report.in_collision && !r.report.error.is_empty(), "{r:?}");
    let nan = world(&c, Pose::from_translation(Vector::new(f64::NAN, 0.0, 0.0)));
    assert!(!c.check_world_motion(&a, &nan).report.error.is_empty());
}

/// Random motions of the bar around the sheet against dense sampling.
#[test]
fn pose_motions_agree_with_dense_sampling() {
    let c = bar_and_sheet();
    let mut rng = Rand64::new(12);
    let random_pose = |rng: &mut Rand64| {
        let t = Vector::new(-0.4 + 1.4 * rng.rand_float(), -0.5 + rng.rand_float(), -0.5 + rng.rand_float());
        let axis = Vector::new(rng.rand_float() - 0.5, rng.rand_float() - 0.5, rng.rand_float() - 0.5).normalize();
        Pose::from_parts(t, Rotation::from_axis_angle(axis, std::f64::consts::PI * (2.0 * rng.rand_float() - 1.0)))
    };
    // Farthest point of the bar from its origin.
    let reach = Vector::new(1.0, 0.02, 0.02).length();
    let (mut colliding, mut free_motions, mut between_free) = (0, 0, 0);
    for m in 0..300 {
        let a = random_pose(&mut rng);
        // Half the motions short (near misses and grazes), half long.
        let b = if m % 2 == 0 {
            let small = random_pose(&mut rng);
            Pose::from_parts(a.translation + (small.translation - Vector::new(0.3, 0.0, 0.0)) * 0.2, a.rotation.slerp(small.rotation, 0.2))
        } else {
            random_pose(&mut rng)
        };
        let r = c.check_world_motion(&world(&c, a), &world(&c, b));
        assert!(r.report.error.is_empty() && r.report.motion, "motion {m}: {r:?}");
        let angle = a.rotation.angle_between(b.rotation);
        let n = (((b.translation - a.translation).length() + angle * reach) / 1e-3).ceil().max(1.0) as usize;
        let at = |s: f64| Pose::from_parts(a.translation.lerp(b.translation, s), a.rotation.slerp(b.rotation, s));
        let first = (0..=n).map(|k| k as f64 / n as f64).find(|&s| !free(&c, at(s)));
        match first {
            Some(s) => {
                assert!(r.report.in_collision, "motion {m}: reported free, but the sample at s = {s} collides");
                let f = r.fraction.unwrap();
                assert!(s >= f - 1.0 / n as f64, "motion {m}: a colliding sample at {s}, before the reported fraction {f}");
                colliding += 1;
                between_free += (free(&c, a) && free(&c, b)) as usize;
            }
            None => free_motions += !r.report.in_collision as usize,
        }
        if r.report.in_collision {
            assert!(!r.report.contacts.is_empty(), "motion {m}: colliding without a contact");
        }
    }
    eprintln!("300 bar pose motions: {colliding} colliding by dense sampling ({between_free} between two free poses), {free_motions} free");
    assert!(colliding >= 30 && between_free >= 10 && free_motions >= 30, "the sample must have every outcome");
}
