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
//! - [`planning_scene_round_trip`]: the planning-scene messages through their bounded decoders;
//! - [`planning_scene_apply`]: the planning-scene messages applied to a pipeline as the node
//!   applies them, with what must hold after each;
//! - [`collision_object_cdr`] and [`apply_collision_object_cdr`]: a mesh object's message as
//!   bytes, and those bytes decoded and applied as the node does on arrival (the scene benchmark,
//!   `benches/scene_update.rs`, times the latter).

use crate::checker::{Checker, SelfPairs};
use crate::model::Srdf;
use crate::msgs::planning_scene::{
    ApplyPlanningSceneRequest, CollisionObject, GetPlanningSceneRequest, GetPlanningSceneResponse, PlanningScene, PlanningSceneWorld,
};
use crate::msgs::{CheckTrajectoryRequest, CollisionReport, JointState};
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
    fn trajectory_job(&self, request: &CheckTrajectoryRequest) -> TrajectoryJob;
    /// A `check_state_validity` request answered on this thread: the response, and why the
    /// request could not be honoured.
    fn check_validity(&self, req: &GetStateValidityRequest) -> (GetStateValidityResponse, Option<String>);
}

impl PipelineAccess for Pipeline {
    fn check_request(&self, states: &[JointState]) -> Vec<CollisionReport> {
        Pipeline::check_request(self, states)
    }

    fn trajectory_job(&self, request: &CheckTrajectoryRequest) -> TrajectoryJob {
        Pipeline::trajectory_job(self, request)
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

/// A planning-scene message applied to `pipeline` as the node applies it: `data`'s first byte
/// picks the type (CollisionObject, AttachedCollisionObject, PlanningScene, PlanningSceneWorld,
/// the ApplyPlanningScene request), the rest is its CDR payload. Panics when what must hold does
/// not: a refused message leaves the checker and the scene as they were; after an applied one,
/// the scene `get_planning_scene` gives (with padding and scale) is taken back whole (as a full scene) and gives the same
/// objects; a state is checked without a panic. Returns whether it decoded.
pub fn planning_scene_apply(pipeline: &mut Pipeline, data: &[u8]) -> bool {
    let Some((&kind, payload)) = data.split_first() else {
        return false;
    };
    let before = (std::sync::Arc::clone(pipeline.checker()), pipeline.scene_object_count());
    let result = match kind % 5 {
        0 => decode_cdr::<CollisionObject>(payload).map(|m| pipeline.collision_object(&m)),
        1 => decode_cdr::<AttachedCollisionObject>(payload).map(|m| pipeline.attached_collision_object(&m)),
        2 => decode_cdr::<PlanningScene>(payload).map(|m| pipeline.planning_scene(&m)),
        3 => decode_cdr::<PlanningSceneWorld>(payload).map(|m| pipeline.planning_scene_world(&m)),
        _ => decode_cdr::<ApplyPlanningSceneRequest>(payload).map(|m| pipeline.planning_scene(&m.scene)),
    };
    let Ok(result) = result else {
        return false;
    };
    let _ = pipeline.take_warnings();
    if result.is_err() {
        assert!(std::sync::Arc::ptr_eq(&before.0, pipeline.checker()), "a refused message changed the checker");
        assert_eq!(before.1, pipeline.scene_object_count(), "a refused message changed the scene");
        return true;
    }
    use crate::msgs::planning_scene::PlanningSceneComponents as C;
    let all = C::WORLD_OBJECT_GEOMETRY | C::ROBOT_STATE_ATTACHED_OBJECTS | C::TRANSFORMS | C::ALLOWED_COLLISION_MATRIX | C::LINK_PADDING_AND_SCALING;
    let counts = pipeline.scene_object_count();
    let scene = pipeline.planning_scene_message(all, crate::msgs::Time::default());
    if let Err(e) = pipeline.planning_scene(&scene) {
        panic!("the scene get_planning_scene gives is refused: {}", e.message);
    }
    assert_eq!(counts, pipeline.scene_object_count(), "the scene given back holds other objects");
    let names: Vec<String> = pipeline.checker().robot().joints.iter().filter(|j| j.is_actuated()).map(|j| j.name.clone()).collect();
    let _ = pipeline.checker().check_joints(&names, &vec![0.3; names.len()]);
    true
}

/// The CDR bytes of a `moveit_msgs/CollisionObject` in `world` with `operation` (0 ADD, 1 REMOVE,
/// 2 APPEND, 3 MOVE), its pose (x, y, z, qx, qy, qz, qw) and, if given, one mesh.
pub fn collision_object_cdr(id: &str, operation: u8, pose: [f64; 7], mesh: Option<(&[crate::math::Vector], &[[u32; 3]])>) -> Vec<u8> {
    encode_cdr_le(&collision_object(id, operation, pose, mesh))
}

/// The CDR bytes of a `moveit_msgs/srv/ApplyPlanningScene` request as a client on the enhanced
/// mapping (Fast DDS) sends it: a difference whose world holds the object of
/// [`collision_object_cdr`].
pub fn apply_planning_scene_cdr(id: &str, operation: u8, pose: [f64; 7], mesh: Option<(&[crate::math::Vector], &[[u32; 3]])>) -> Vec<u8> {
    use crate::msgs::planning_scene::{ApplyPlanningSceneRequest, PlanningSceneWorld};
    let world = PlanningSceneWorld { collision_objects: vec![collision_object(id, operation, pose, mesh)], ..Default::default() };
    encode_cdr_le(&ApplyPlanningSceneRequest { scene: PlanningScene { is_diff: true, world, ..Default::default() } })
}

fn collision_object(id: &str, operation: u8, pose: [f64; 7], mesh: Option<(&[crate::math::Vector], &[[u32; 3]])>) -> CollisionObject {
    use crate::msgs::planning_scene::{MeshTriangle, ShapeMesh};
    use crate::msgs::{Header, Point, PoseMsg, Quaternion};
    let [x, y, z, qx, qy, qz, qw] = pose;
    let meshes = mesh.map_or_else(Vec::new, |(v, t)| {
        vec![ShapeMesh {
            vertices: v.iter().map(|p| Point { x: p.x, y: p.y, z: p.z }).collect(),
            triangles: t.iter().map(|t| MeshTriangle { vertex_indices: *t }).collect(),
        }]
    });
    CollisionObject {
        header: Header { frame_id: "world".into(), ..Default::default() },
        pose: PoseMsg { position: Point { x, y, z }, orientation: Quaternion { x: qx, y: qy, z: qz, w: qw } },
        id: id.to_owned(),
        meshes,
        operation,
        ..Default::default()
    }
}

/// `bytes` decoded as a `moveit_msgs/CollisionObject` and applied to `pipeline`, as the node does
/// when one arrives on `collision_object`: the error says why it was not.
pub fn apply_collision_object_cdr(pipeline: &mut Pipeline, bytes: &[u8]) -> Result<(), String> {
    let msg = decode_cdr::<CollisionObject>(bytes).map_err(|e| e.to_string())?;
    pipeline.collision_object(&msg).map_err(|s| s.message)
}

/// Empties the planning scene (a full scene with nothing in it).
pub fn planning_scene_clear(pipeline: &mut Pipeline) {
    if let Err(e) = pipeline.planning_scene(&PlanningScene::default()) {
        panic!("an empty full scene is refused: {}", e.message);
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
