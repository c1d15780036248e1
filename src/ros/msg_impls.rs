//! The shared message types are ROS messages for ros2-client.

use crate::msgs::{CollisionReport, DiagnosticArray, JointState, MarkerArray, StringMsg, TfMessage};
use serde::{Deserialize, Serialize};

impl ros2_client::Message for JointState {}
impl ros2_client::Message for CollisionReport {}
impl ros2_client::Message for TfMessage {}
impl ros2_client::Message for StringMsg {}
impl ros2_client::Message for MarkerArray {}
impl ros2_client::Message for DiagnosticArray {}

/// `thickness_collision_msgs/srv/CheckStates` request.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct CheckStatesRequest {
    /// The states to check.
    pub states: Vec<JointState>,
}
impl ros2_client::Message for CheckStatesRequest {}

/// `thickness_collision_msgs/srv/CheckStates` response.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct CheckStatesResponse {
    /// One report per state, in order.
    pub reports: Vec<CollisionReport>,
}
impl ros2_client::Message for CheckStatesResponse {}

/// `rosgraph_msgs/msg/Clock`.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize)]
pub struct ClockMsg {
    /// Simulated time.
    pub clock: crate::msgs::Time,
}
impl ros2_client::Message for ClockMsg {}
