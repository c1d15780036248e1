//! The pipeline both front doors share (the CLI's `check`, the ROS node, bag replay): a robot
//! and an environment loaded from the parameters, turned into convex targets and a scene of
//! thickness cells and solids, and robot states (joint positions or link poses) turned into
//! collision reports.

mod checker_build;
mod joint_state;
mod state_report;
mod tf_tree;

pub use self::checker_build::{BuildSummary, Checker, CheckerError, LinkTargets};
pub use self::joint_state::{JointMemory, StateError};
pub use self::state_report::{ReportContact, StateReport};
pub use self::tf_tree::TfTree;
