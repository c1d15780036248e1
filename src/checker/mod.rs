//! The pipeline both front doors share (the CLI's `check`, the ROS node, bag replay): a robot
//! and an environment loaded from the parameters, turned into convex targets and a scene of
//! thickness cells and solids, and robot states (joint positions or link poses) turned into
//! collision reports.

#[allow(clippy::module_inception)]
mod checker;
mod checker_build;
mod checker_error;
mod clearance;
mod collision_matrix;
mod geometry_shapes;
mod joint_motion;
mod joint_spline;
mod joint_state;
mod link_sizes;
mod link_targets;
mod motion_bounds;
mod motion_contact;
mod motion_sweep;
mod self_collision;
mod self_pairs;
mod spline_clearance;
mod spline_poly;
mod state_check;
mod state_report;
#[cfg(test)]
mod test_points;
mod world_motion;
mod world_objects;
mod world_shapes;

pub use self::checker::{BuildSummary, Checker};
pub(crate) use self::checker_build::read_semantic_file;
pub use self::checker_error::CheckerError;
pub(crate) use self::collision_matrix::CollisionMatrix;
pub use self::joint_spline::SplineSegment;
pub(crate) use self::joint_state::require_own_joints;
pub use self::joint_state::StateError;
pub(crate) use self::link_sizes::LinkSizes;
pub use self::link_targets::LinkTargets;
pub use self::motion_sweep::MotionReport;
pub use self::self_pairs::SelfPairs;
pub use self::spline_clearance::CLEARANCE_SLACK;
pub use self::spline_poly::SegmentPoly;
pub use self::state_report::{ObjectType, ReportClearance, ReportContact, StateReport};
pub(crate) use self::world_objects::Attached;
#[cfg(test)]
pub(crate) use self::world_shapes::{plane_mesh, PLANE_HALF_SIDE};
pub(crate) use self::world_shapes::{BodyCache, WorldShape};
