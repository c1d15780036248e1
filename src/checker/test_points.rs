//! Test support for the motion bounds: points of a checked link's parts to sample, states to
//! move between, two checkers' answers compared.

use crate::collision::TargetShape;
use crate::math::{Pose, Real, Vector};

/// Points of a part in its link's frame: a hull's vertices, a primitive's extreme points along
/// 26 directions.
pub(crate) fn part_points(shape: &TargetShape, offset: &Pose) -> Vec<Vector> {
    let local: Vec<Vector> = match shape {
        TargetShape::Polytope(h) => h.points().to_vec(),
        _ => (0..27)
            .filter(|&i| i != 13)
            .map(|i| shape.support_point(Vector::new((i % 3) as Real - 1.0, ((i / 3) % 3) as Real - 1.0, (i / 9) as Real - 1.0)))
            .collect(),
    };
    local.into_iter().map(|p| *offset * p).collect()
}

/// The largest change, from the poses `at` to any of `others`, of the distance between a point
/// of `points_a` on link `la` and one of `points_b` on link `lb` (every third point of each).
pub(crate) fn largest_pair_change(points_a: &[Vector], la: usize, points_b: &[Vector], lb: usize, at: &[Option<Pose>], others: &[Vec<Option<Pose>>]) -> Real {
    let posed = |poses: &[Option<Pose>], link: usize| poses[link].expect("every link posed");
    let mut largest: Real = 0.0;
    for other in others {
        for p in points_a.iter().step_by(3) {
            for q in points_b.iter().step_by(3) {
                let now = (posed(at, la) * *p - posed(at, lb) * *q).length();
                let then = (posed(other, la) * *p - posed(other, lb) * *q).length();
                largest = largest.max((then - now).abs());
            }
        }
    }
    largest
}

/// A state with every joint within its limits (continuous ones within one turn), each drawn by
/// `draw(lo, hi)`.
pub(crate) fn random_state(robot: &crate::model::RobotModel, draw: &mut impl FnMut(f64, f64) -> f64) -> Vec<f64> {
    let pi = std::f64::consts::PI;
    robot.joints.iter().map(|j| if j.limits.iter().all(|l| l.is_finite()) { draw(j.limits[0], j.limits[1]) } else { draw(-pi, pi) }).collect()
}

/// Asserts that `a` and `b` answer `motions` random motions of `a`'s robot (seeded by `seed`)
/// the same, but for the report's own clock; returns how many collide, so a caller can require
/// that some do.
pub(crate) fn assert_same_motions(a: &crate::checker::Checker, b: &crate::checker::Checker, seed: u64, motions: usize) -> usize {
    let robot = a.robot();
    let mut rng = oorandom::Rand64::new(seed.into());
    let mut draw = |lo: f64, hi: f64| lo + (hi - lo) * rng.rand_float();
    let mut colliding = 0;
    for _ in 0..motions {
        let (q0, q1) = (random_state(robot, &mut draw), random_state(robot, &mut draw));
        let (mut x, mut y) = (a.check_motion(&q0, &q1), b.check_motion(&q0, &q1));
        // The report's own clock is the one field that may differ.
        (x.report.check_seconds, y.report.check_seconds) = (0.0, 0.0);
        assert_eq!(x, y, "from {q0:?} to {q1:?}");
        colliding += usize::from(x.report.in_collision);
    }
    colliding
}
