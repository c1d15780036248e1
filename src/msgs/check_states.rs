//! `thickness_collision_msgs/srv/CheckStates`: a batch of joint states checked in one call, one
//! report back per state.

use super::{CollisionReport, JointState};
use serde::{Deserialize, Serialize};

/// `thickness_collision_msgs/srv/CheckStates` request.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CheckStatesRequest {
    /// The states to check.
    pub states: Vec<JointState>,
}

/// `thickness_collision_msgs/srv/CheckStates` response.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CheckStatesResponse {
    /// One report per state, in order.
    pub reports: Vec<CollisionReport>,
}
