//! Test support for the motion bounds: points of a checked link's parts to sample.

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
