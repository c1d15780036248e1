//! Clearance (`clearance_threshold`) against an independent computation: the Panda (from
//! example-robot-data) in the peer benchmark's 10,000-triangle world, random joint states (fixed
//! seed) drawn until 2,000 of them have a link within the threshold. For every state and every
//! checked link, parry3d-f64's `query::distance` from the link's hull to every cell whose box
//! comes within the threshold of the link's box (a brute-force scan over all cells, each cell its
//! own `ConvexPolyhedron`: neither this crate's cell tree nor its support functions) gives the
//! oracle distance. Then:
//! - a link the oracle puts within the threshold (by more than 1e-5 m) is reported, and nothing
//!   beyond it (by more than 1e-5 m) is;
//! - a reported distance is within 1e-5 m of the oracle's, its two points are that far apart, the
//!   point on the object lies in the reported triangle's cell and the point on the link on the hull
//!   (1e-6 m);
//! - a colliding link reports minus its contact's depth, both points at the contact point.

#[path = "../benches/peer_compare_core.rs"]
mod peer_compare_core;

use parry3d_f64::bounding_volume::{Aabb, BoundingVolume};
use parry3d_f64::query::PointQuery;
use parry3d_f64::shape::{ConvexPolyhedron, Shape};
use peer_compare_core::*;
use thickness_collision::checker::Checker;
use thickness_collision::collision::TargetShape;
use thickness_collision::math::{Pose, Real, Vector};
use thickness_collision::model::Params;

const THRESHOLD: Real = 0.05;
const TOLERANCE: Real = 1e-5;

#[test]
fn reported_clearances_match_parry_distance_to_every_cell_within_the_threshold() {
    let py = python();
    let (robot, map) = panda(&py);
    let w = world(10_000);
    let params = Params { package_map: map.clone(), clearance_threshold: THRESHOLD, ..Params::default() };
    let checker = Checker::from_robot_and_scene(params, robot.clone(), w.scene, "panda".into()).unwrap();
    // Every cell of every surface once, in the world, as a parry polyhedron with its world box.
    let mut cells: Vec<(usize, u32, ConvexPolyhedron, Aabb)> = Vec::new();
    for (oi, object) in checker.scene().objects().iter().enumerate() {
        for cell in &object.area().expect("the peer world has thin surfaces only").cells {
            let pts: Vec<Vector> = cell.distinct_vertices().iter().map(|v| object.pose * *v).collect();
            let poly = ConvexPolyhedron::from_convex_hull(&pts).expect("a cell is a solid polyhedron");
            let aabb = poly.local_aabb();
            cells.push((oi, cell.triangle, poly, aabb));
        }
    }
    let (mut near_states, mut checked_states) = (0, 0);
    let (mut reported, mut colliding, mut worst): (usize, usize, Real) = (0, 0, 0.0);
    let mut seed = 7;
    while near_states < 2_000 {
        let states = random_states(&robot, 500, seed);
        seed += 1;
        for (names, pos) in &states {
            checked_states += 1;
            let report = checker.check_joints(names, pos).unwrap();
            if !report.clearances.is_empty() {
                near_states += 1;
            }
            let mut q = vec![0.0; robot.joints.len()];
            for (n, p) in names.iter().zip(pos) {
                q[robot.joint(n).unwrap()] = *p;
            }
            let links = robot.forward_kinematics(&q, &nalgebra::Isometry3::identity()).unwrap();
            for t in checker.targets() {
                let link_pose = thickness_collision::math::pose_from_isometry(&links[t.link]);
                let mine = report.clearances.iter().find(|c| c.link_name == t.name);
                // Its environment contact (a self-collision contact names a robot link instead).
                let contact = report.contacts.iter().find(|c| c.link_name == t.name && checker.scene().objects().iter().any(|o| o.name == c.object_name));
                if let Some(contact) = contact {
                    let c = mine.unwrap_or_else(|| panic!("state {pos:?}: colliding link {} has no clearance", t.name));
                    let p = contact.position.unwrap();
                    assert!(c.distance == -contact.depth && c.point_on_link == p && c.point_on_object == p, "{c:?} against {contact:?}");
                    assert_eq!((c.object_name.as_str(), c.triangle), (contact.object_name.as_str(), contact.triangle));
                    colliding += 1;
                    continue;
                }
                // The oracle: parry's distance from each part's hull to each cell near it.
                let mut oracle = Real::INFINITY;
                for (shape, offset) in &t.parts {
                    let TargetShape::Polytope(hull) = shape else { panic!("Panda links are hulls") };
                    let pose = link_pose * *offset;
                    let part_box = hull.as_parry().compute_aabb(&pose).loosened(THRESHOLD);
                    for (_, _, poly, aabb) in &cells {
                        if part_box.intersects(aabb) {
                            let d = parry3d_f64::query::distance(&pose, hull.as_parry(), &Pose::IDENTITY, poly).unwrap().distance;
                            oracle = oracle.min(d);
                        }
                    }
                }
                match mine {
                    None => assert!(oracle > THRESHOLD - TOLERANCE, "state {pos:?}: link {} is {oracle} m from a cell but not reported", t.name),
                    Some(c) => {
                        reported += 1;
                        assert!(c.distance <= THRESHOLD, "{c:?} beyond the threshold");
                        let error = (c.distance - oracle).abs();
                        worst = worst.max(error);
                        assert!(error <= TOLERANCE, "state {pos:?}: link {}: reported {} m, parry {oracle} m", t.name, c.distance);
                        let (a, b) = (Vector::from_array(c.point_on_link), Vector::from_array(c.point_on_object));
                        assert!(((a - b).length() - c.distance).abs() <= TOLERANCE, "{c:?}: the points are {} m apart", (a - b).length());
                        // The point on the object lies in the named cell.
                        let object = checker.scene().objects().iter().find(|o| o.name == c.object_name).unwrap();
                        let cell = object.area().unwrap().cells.iter().find(|cell| cell.triangle == c.triangle).unwrap();
                        assert!(cell.contains_point(object.pose.inverse() * b, 1e-6), "{c:?}: the point on the object is not in its cell");
                        // The point on the link lies on one of its hulls.
                        let on_link = t
                            .parts
                            .iter()
                            .map(|(shape, offset)| {
                                let TargetShape::Polytope(hull) = shape else { unreachable!() };
                                hull.as_parry().distance_to_point(&(link_pose * *offset), a, true)
                            })
                            .fold(Real::INFINITY, Real::min);
                        assert!(on_link <= 1e-6, "{c:?}: the point on the link is {on_link} m from it");
                    }
                }
            }
        }
    }
    eprintln!(
        "{checked_states} states, {near_states} with a link within {THRESHOLD} m: {reported} link clearances within {worst:e} m of parry's, {colliding} colliding links"
    );
    assert!(reported > 2_000 && colliding > 0, "both kinds exercised");
}

/// The field in `check --json` (and replay's JSON lines) and in the `CollisionReport` message:
/// `clearances` is an empty array when the threshold is 0, and with it each entry carries the
/// report's values under the message's field names.
#[test]
fn clearances_reach_the_json_and_the_message() {
    use thickness_collision::msgs::Time;
    use thickness_collision::pipeline::{report_message, CheckedState};
    let py = python();
    let (robot, map) = panda(&py);
    let off =
        Checker::from_robot_and_scene(Params { package_map: map.clone(), ..Params::default() }, robot.clone(), world(2_000).scene, "panda".into()).unwrap();
    let on = Checker::from_robot_and_scene(
        Params { package_map: map, clearance_threshold: THRESHOLD, ..Params::default() },
        robot.clone(),
        world(2_000).scene,
        "panda".into(),
    )
    .unwrap();
    let states = random_states(&robot, 400, 3);
    let mut seen = 0;
    for (names, pos) in &states {
        let report = off.check_joints(names, pos).unwrap();
        let json: serde_json::Value = serde_json::from_str(&CheckedState { stamp: Time::default(), report: report.clone() }.json()).unwrap();
        assert_eq!(json["clearances"], serde_json::json!([]), "off: an empty array");
        assert!(report_message(&report, Time::default(), "world").clearances.is_empty());
        let report = on.check_joints(names, pos).unwrap();
        if report.clearances.is_empty() {
            continue;
        }
        seen += 1;
        let json: serde_json::Value = serde_json::from_str(&CheckedState { stamp: Time::default(), report: report.clone() }.json()).unwrap();
        let message = report_message(&report, Time::default(), "world");
        let listed = json["clearances"].as_array().unwrap();
        assert_eq!((listed.len(), message.clearances.len()), (report.clearances.len(), report.clearances.len()));
        for ((c, j), m) in report.clearances.iter().zip(listed).zip(&message.clearances) {
            let mut keys: Vec<&str> = j.as_object().unwrap().keys().map(String::as_str).collect();
            keys.sort_unstable();
            assert_eq!(keys, ["distance", "link_name", "object_name", "point_on_link", "point_on_object", "triangle"]);
            assert_eq!(j["link_name"], c.link_name.as_str());
            assert_eq!(j["object_name"], c.object_name.as_str());
            assert_eq!(j["triangle"], c.triangle);
            assert_eq!(j["distance"].as_f64().unwrap(), c.distance);
            assert_eq!(j["point_on_link"], serde_json::json!(c.point_on_link));
            assert_eq!(j["point_on_object"], serde_json::json!(c.point_on_object));
            assert_eq!(
                (m.link_name.as_str(), m.object_name.as_str(), m.triangle, m.distance),
                (c.link_name.as_str(), c.object_name.as_str(), c.triangle, c.distance)
            );
            assert_eq!([m.point_on_link.x, m.point_on_link.y, m.point_on_link.z], c.point_on_link);
            assert_eq!([m.point_on_object.x, m.point_on_object.y, m.point_on_object.z], c.point_on_object);
        }
    }
    assert!(seen > 20, "{seen} states with a clearance");
}

/// A free motion's report carries the clearances of its end pose.
#[test]
fn a_free_motion_reports_its_end_pose_clearances() {
    let py = python();
    let (robot, map) = panda(&py);
    let checker = Checker::from_robot_and_scene(
        Params { package_map: map, clearance_threshold: THRESHOLD, ..Params::default() },
        robot.clone(),
        world(2_000).scene,
        "panda".into(),
    )
    .unwrap();
    let full = |pos: &[f64]| {
        let mut q = vec![0.0; robot.joints.len()];
        for (j, p) in robot.joints.iter().filter(|j| j.is_actuated()).zip(pos) {
            q[robot.joint(&j.name).unwrap()] = *p;
        }
        q
    };
    let states = random_states(&robot, 400, 5);
    let (mut free_near, mut free) = (0, 0);
    for pair in states.windows(2) {
        let q0 = full(&pair[0].1);
        // A short motion: a tenth of the way to the next random state.
        let q1: Vec<f64> = q0.iter().zip(full(&pair[1].1)).map(|(a, b)| a + 0.1 * (b - a)).collect();
        let motion = checker.check_motion(&q0, &q1);
        if motion.report.in_collision {
            continue;
        }
        free += 1;
        let end = checker.check_positions(&q1).unwrap();
        assert_eq!(motion.report.clearances, end.clearances);
        free_near += usize::from(!end.clearances.is_empty());
    }
    assert!(free > 50 && free_near > 10, "{free} free motions, {free_near} of them ending near a surface");
}
