//! Messages to checked robot states: the one pipeline the node, replay and `check` share.
//!
//! Each front door turns its input into messages (`sensor_msgs/JointState`, `tf2_msgs/TFMessage`,
//! `robot_description`) and hands them to a [`Pipeline`] in arrival order; the pipeline validates
//! them, merges partial joint states (`missing_joint`), composes `/tf` with `frame_prefix` up to
//! `world_frame`, checks the resulting robot state and gives back a [`CheckedState`] with the
//! input's stamp. A message that gives no state is a [`Skip`] with a counted [`SkipCause`]:
//! nothing that was not checked is ever reported, and a state that cannot be checked where an
//! answer is owed (a service slot, a `check` line) fails closed (`in_collision` and `error`).

mod collision_object;
mod joint_input;
mod link_transforms;
mod planning_world;
mod report_adapter;
mod robot_swap;
mod scene_attached;
mod scene_input;
mod scene_state;
mod skip;
mod state_line;
mod state_pipeline;
mod tf_tree;
mod trajectory;
mod trajectory_file;
mod trajectory_plan;
mod trajectory_stream;
mod validity;

pub use self::report_adapter::{report_message, CheckedState};
pub use self::skip::{Skip, SkipCause};
pub use self::state_line::{parse_state_line, LinkTransform, StateLine, StateLineError};
pub use self::state_pipeline::{Pipeline, RobotState};

// The node's and replay's own steps: `/tf` of a state, and the request jobs the node's workers run
// (the fuzz harness reaches the jobs through `fuzz_access`).
pub(crate) use self::link_transforms::link_transforms;
#[cfg(feature = "ros")]
pub(crate) use self::scene_input::{BuiltScene, ScenePlan};
pub(crate) use self::trajectory::TrajectoryJob;
pub use self::trajectory::{Outcome, APPROACH_SEGMENT};
pub use self::trajectory_file::{read_trajectory_file, TrajectoryFile, MAX_TRAJECTORY_FILE_BYTES};
pub use self::trajectory_plan::Interpolation;
pub use self::trajectory_stream::{outcome_json, StreamedTrajectory, TrajectoryStream};
#[cfg(feature = "ros")]
pub(crate) use self::validity::ValidityJob;

#[cfg(test)]
mod pipeline_tests;
#[cfg(test)]
mod scene_size_tests;
#[cfg(test)]
mod scene_tests;
