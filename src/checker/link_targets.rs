//! What a checked robot link is made of: the convex shapes of its geometry.

use crate::collision::TargetShape;
use crate::math::Pose;

/// The convex parts of one checked robot link.
#[derive(Clone, Debug)]
pub struct LinkTargets {
    /// Index of the link in the robot model.
    pub link: usize,
    /// Its name.
    pub name: String,
    /// Shapes and their poses in the link frame.
    pub parts: Vec<(TargetShape, Pose)>,
}
