//! The ROS 2 node: `joint_states` in, `collisions` out, and the `check_states` service, over
//! ros2-client (RustDDS). Nothing here does geometry: states go to [`crate::checker::Checker`].
//!
//! DDS stays where the environment says: `ROS_DOMAIN_ID`, and `ROS_AUTOMATIC_DISCOVERY_RANGE`
//! (`LOCALHOST` or `ROS_LOCALHOST_ONLY=1` bind the participant to 127.0.0.1; `SUBNET`, the default,
//! uses every interface and multicast; `OFF` discovers nobody) with `ROS_STATIC_PEERS`
//! (ros2-client ignores these variables itself, so the participant is built here:
//! `discovery_range.rs`).
//!
//! Where things are: `interfaces.rs` names, QoS and creates every topic and service and turns
//! their inputs into events; `node_state.rs` is the behaviour, one handler per input;
//! `workers.rs` runs the requests checked off the loop; `node_run.rs` is the loop and shutdown;
//! `states_on_receive.rs` answers joint states on the thread that receives them. A new input or
//! service touches `interfaces.rs` and `node_state.rs` (and `workers.rs` when it runs off the loop).

mod background;
mod description_msg;
mod diagnostics;
mod discovery_range;
mod interfaces;
mod memory_return;
mod motion_ladder;
mod msg_impls;
mod node_run;
mod node_state;
mod param_services;
mod param_values;
mod participant;
mod rate_limited_log;
mod ros_args;
mod states_on_receive;
mod workers;

pub use self::node_run::{run, RunOptions};
pub use self::ros_args::{parse_ros_args, RosArgs};
