//! Entry points for the fuzz harness (`fuzz/harness`) and its regression test
//! (`tests/fuzz_regressions.rs`) into steps that are not part of the API: a fuzzer must reach them
//! on their own, without the checks around them that would hide their failures. Not for any other
//! caller; their signatures may change with the harness.
//!
//! - [`parse_mesh`]: mesh bytes through the parsers `model::read_mesh` uses after reading the
//!   file, the COLLADA and XML guards first;
//! - [`open_bag`]: the bag reader alone, without replay's checks on topics and types;
//! - [`PipelineAccess`]: the node's request services on a [`Pipeline`] (`check_states`,
//!   `check_trajectory` off the loop, MoveIt's `check_state_validity`), with the MoveIt messages
//!   a request is built from;
//! - [`build_self_pairs`]: the self-collision pairs of a parsed SRDF;
//! - [`planning_scene_round_trip`]: the planning-scene messages through their bounded decoders.

use crate::checker::{Checker, SelfPairs};
use crate::model::Srdf;
use crate::msgs::planning_scene::{
    ApplyPlanningSceneRequest, CollisionObject, GetPlanningSceneRequest, GetPlanningSceneResponse, PlanningScene, PlanningSceneWorld,
};
use crate::msgs::{CollisionReport, JointState, JointTrajectory};
use crate::pipeline::{Pipeline, TrajectoryJob};
use crate::replay::{decode_cdr, encode_cdr_le};
use serde::{de::DeserializeOwned, Serialize};

pub use crate::model::mesh_file::parse_mesh;
pub use crate::msgs::moveit::{GetStateValidityRequest, GetStateValidityResponse, JointConstraint};
pub use crate::msgs::planning_scene::{AttachedCollisionObject, RobotStateMsg};
pub use crate::replay::bag_reader::{open_bag, BagMessage, BagReader};

/// Builds the self-collision pairs of `checker`'s robot from a parsed SRDF, as
/// `Checker::apply_semantic` does after parsing, and drops them.
pub fn build_self_pairs(checker: &Checker, srdf: Srdf) {
    let _ = SelfPairs::build(checker, Some(srdf));
}

/// The node's request services as methods of the pipeline (bring the trait into scope).
pub trait PipelineAccess {
    /// A `check_states` request: one report per state, in order.
    fn check_request(&self, states: &[JointState]) -> Vec<CollisionReport>;
    /// A `check_trajectory` request validated and resolved as the node does before its worker
    /// runs it.
    fn trajectory_job(&self, trajectory: &JointTrajectory) -> TrajectoryJob;
    /// A `check_state_validity` request answered on this thread: the response, and why the
    /// request could not be honoured.
    fn check_validity(&self, req: &GetStateValidityRequest) -> (GetStateValidityResponse, Option<String>);
}

impl PipelineAccess for Pipeline {
    fn check_request(&self, states: &[JointState]) -> Vec<CollisionReport> {
        Pipeline::check_request(self, states)
    }

    fn trajectory_job(&self, trajectory: &JointTrajectory) -> TrajectoryJob {
        Pipeline::trajectory_job(self, trajectory)
    }

    fn check_validity(&self, req: &GetStateValidityRequest) -> (GetStateValidityResponse, Option<String>) {
        Pipeline::check_validity(self, req)
    }
}

/// The planning-scene messages a deployment's graph may send: `data`'s first byte picks the type
/// (CollisionObject, AttachedCollisionObject, PlanningScene, PlanningSceneWorld, the
/// ApplyPlanningScene request, the GetPlanningScene request and response), the rest is its CDR
/// payload. What decodes must encode to bytes that decode and encode to the same bytes (panics
/// otherwise): nothing a decoder accepts is lost or changed on the way back out. Returns whether
/// it decoded.
pub fn planning_scene_round_trip(data: &[u8]) -> bool {
    let Some((&kind, payload)) = data.split_first() else {
        return false;
    };
    match kind % 7 {
        0 => round_trip::<CollisionObject>(payload),
        1 => round_trip::<AttachedCollisionObject>(payload),
        2 => round_trip::<PlanningScene>(payload),
        3 => round_trip::<PlanningSceneWorld>(payload),
        4 => round_trip::<ApplyPlanningSceneRequest>(payload),
        5 => round_trip::<GetPlanningSceneRequest>(payload),
        _ => round_trip::<GetPlanningSceneResponse>(payload),
    }
}

fn round_trip<T: Serialize + DeserializeOwned>(payload: &[u8]) -> bool {
    let Ok(message) = decode_cdr::<T>(payload) else {
        return false;
    };
    let bytes = encode_cdr_le(&message);
    let again = decode_cdr::<T>(&bytes).unwrap_or_else(|e| panic!("a decoded message encodes to bytes that do not decode: {e}"));
    assert!(encode_cdr_le(&again) == bytes, "a decoded message does not encode to the same bytes twice");
    true
}
