//! The ROS 2 node: `joint_states` in, `collisions` out, and the `check_states` service, over
//! ros2-client (RustDDS). Nothing here does geometry: states go to [`crate::checker::Checker`].
//!
//! DDS stays where the environment says: `ROS_DOMAIN_ID`, and `ROS_AUTOMATIC_DISCOVERY_RANGE`
//! (`LOCALHOST` or `ROS_LOCALHOST_ONLY=1` bind the participant to 127.0.0.1; `SUBNET`, the default,
//! uses every interface and multicast; `OFF` discovers nobody) with `ROS_STATIC_PEERS`
//! (ros2-client ignores these variables itself, so the participant is built here:
//! `discovery_range.rs`).

mod description_msg;
mod diagnostics;
mod discovery_range;
mod memory_return;
mod msg_impls;
mod node_run;
mod param_services;
mod param_values;
mod ros_args;
mod states_on_receive;
mod validity_worker;

pub use self::node_run::{run, RunOptions};
pub use self::ros_args::{parse_ros_args, RosArgs};
