//! Every type the node sends or receives is a ROS message for ros2-client: the shared message
//! types of `msgs` (the node's own services among them) and the node's bounded decoding of
//! `robot_description`.

use super::description_msg::DescriptionMsg;
use crate::msgs::moveit::{GetStateValidityRequest, GetStateValidityResponse};
use crate::msgs::planning_scene::{
    ApplyPlanningSceneRequest, ApplyPlanningSceneResponse, AttachedCollisionObject, CollisionObject, GetPlanningSceneRequest, GetPlanningSceneResponse,
    PlanningScene, PlanningSceneWorld,
};
use crate::msgs::{
    CheckStatesRequest, CheckStatesResponse, CheckTrajectoryRequest, CheckTrajectoryResponse, ClockMsg, CollisionReport, DiagnosticArray, JointState,
    MarkerArray, StringMsg, TfMessage,
};

impl ros2_client::Message for JointState {}
impl ros2_client::Message for CollisionReport {}
impl ros2_client::Message for TfMessage {}
impl ros2_client::Message for StringMsg {}
impl ros2_client::Message for MarkerArray {}
impl ros2_client::Message for DiagnosticArray {}
impl ros2_client::Message for CheckTrajectoryRequest {}
impl ros2_client::Message for CheckTrajectoryResponse {}
impl ros2_client::Message for CheckStatesRequest {}
impl ros2_client::Message for CheckStatesResponse {}
impl ros2_client::Message for ClockMsg {}
impl ros2_client::Message for GetStateValidityRequest {}
impl ros2_client::Message for GetStateValidityResponse {}
impl ros2_client::Message for DescriptionMsg {}
impl ros2_client::Message for CollisionObject {}
impl ros2_client::Message for AttachedCollisionObject {}
impl ros2_client::Message for PlanningScene {}
impl ros2_client::Message for PlanningSceneWorld {}
impl ros2_client::Message for ApplyPlanningSceneRequest {}
impl ros2_client::Message for ApplyPlanningSceneResponse {}
impl ros2_client::Message for GetPlanningSceneRequest {}
impl ros2_client::Message for GetPlanningSceneResponse {}
