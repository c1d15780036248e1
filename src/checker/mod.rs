//! The pipeline both front doors share (the CLI's `check`, the ROS node, bag replay): a robot
//! and an environment loaded from the parameters, turned into convex targets and a scene of
//! thickness cells and solids, and robot states (joint positions or link poses) turned into
//! collision reports.

mod checker_build;
mod clearance;
mod joint_state;
mod motion;
mod motion_sweep;
mod self_collision;
pub use self::self_collision::SelfPairs;
mod state_report;
mod world_motion;

pub use self::checker_build::{BuildSummary, Checker, CheckerError, LinkTargets};
pub(crate) use self::joint_state::not_our_robot;
pub use self::joint_state::StateError;
pub use self::motion::{MotionReport, MAX_SUBINTERVALS};
pub use self::state_report::{ObjectType, ReportClearance, ReportContact, StateReport};
