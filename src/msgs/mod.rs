//! ROS 2 message types as plain serde structs, shared by the node (ros2-client serialises them)
//! and the bag replay (CDR in `replay`), and their `.msg` definitions (the MCAP `ros2msg`
//! schemas). Nothing here depends on the rest of the crate.
//!
//! Field order is wire order: CDR has no field names. The project's own messages mirror
//! `interfaces/thickness_collision_msgs/msg/*.msg`; `tests/msgs_interface.rs` checks the field
//! order, and the replay tests read what `replay` writes back with rosbags.

mod bounded;
mod check_states;
mod definitions;
pub(crate) mod moveit;
// Public for the objects a library user applies to a pipeline (`CollisionObject`,
// `AttachedCollisionObject`); the rest of the scene's messages are the node's and replay's.
#[cfg_attr(not(test), expect(dead_code, reason = "some scene messages are read by the node alone"))]
pub mod planning_scene;
#[cfg(test)]
mod planning_scene_tests;

pub use self::check_states::{CheckStatesRequest, CheckStatesResponse};
pub(crate) use self::definitions::{full_definition, COLLISION_REPORT_TYPE, MARKER_ARRAY_TYPE, STRING_TYPE, TF_MESSAGE_TYPE};

use serde::{Deserialize, Deserializer, Serialize};

/// Entries a `JointState` field may hold when decoded (a robot has hundreds of joints at most).
/// A longer sequence is refused while it is read, before its elements are allocated: a
/// million made-up names would otherwise cost some 60 MB of strings per message.
pub(crate) const MAX_JOINT_STATE_ENTRIES: usize = 65_536;

/// A sequence of at most [`MAX_JOINT_STATE_ENTRIES`], refused as soon as it runs past.
fn bounded_seq<'de, D: Deserializer<'de>, T: Deserialize<'de>>(d: D) -> Result<Vec<T>, D::Error> {
    bounded::bounded_vec(d, MAX_JOINT_STATE_ENTRIES, "joint state field")
}

/// `builtin_interfaces/msg/Time`. A field a file leaves out is 0, as when ROS 2 reads a message
/// from YAML (`stamp: {sec: 5}`); CDR always carries both.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(default)]
pub struct Time {
    /// Seconds.
    pub sec: i32,
    /// Nanoseconds.
    pub nanosec: u32,
}

impl Time {
    /// From nanoseconds since the epoch.
    pub fn from_nanos(ns: i64) -> Time {
        Time { sec: ns.div_euclid(1_000_000_000) as i32, nanosec: ns.rem_euclid(1_000_000_000) as u32 }
    }

    /// Nanoseconds since the epoch.
    pub fn as_nanos(&self) -> i64 {
        self.sec as i64 * 1_000_000_000 + self.nanosec as i64
    }
}

/// `rosgraph_msgs/msg/Clock` (`/clock`, read under `use_sim_time`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ClockMsg {
    /// Simulated time.
    pub clock: Time,
}

/// `std_msgs/msg/Header`. A field a file leaves out is empty, as when ROS 2 reads a message from
/// YAML (`header: {stamp: {sec: 0}}`); CDR always carries both.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Header {
    /// Stamp.
    pub stamp: Time,
    /// Frame.
    pub frame_id: String,
}

/// `std_msgs/msg/String`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StringMsg {
    /// Text.
    pub data: String,
}

/// `sensor_msgs/msg/JointState`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct JointState {
    /// Header.
    pub header: Header,
    /// Joint names.
    #[serde(deserialize_with = "bounded_seq")]
    pub name: Vec<String>,
    /// Positions (radians or metres).
    #[serde(deserialize_with = "bounded_seq")]
    pub position: Vec<f64>,
    /// Velocities.
    #[serde(deserialize_with = "bounded_seq")]
    pub velocity: Vec<f64>,
    /// Efforts.
    #[serde(deserialize_with = "bounded_seq")]
    pub effort: Vec<f64>,
}

/// `geometry_msgs/msg/Vector3`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Vector3 {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
}

/// `geometry_msgs/msg/Point`.
pub type Point = Vector3;

/// `geometry_msgs/msg/Quaternion`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Quaternion {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
    /// w.
    pub w: f64,
}

impl Default for Quaternion {
    fn default() -> Self {
        Quaternion { x: 0.0, y: 0.0, z: 0.0, w: 1.0 }
    }
}

/// `geometry_msgs/msg/Transform`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Transform {
    /// Translation.
    pub translation: Vector3,
    /// Rotation.
    pub rotation: Quaternion,
}

/// `geometry_msgs/msg/TransformStamped`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TransformStamped {
    /// Header (`frame_id` is the parent frame).
    pub header: Header,
    /// The child frame.
    pub child_frame_id: String,
    /// Pose of the child in the parent.
    pub transform: Transform,
}

/// `tf2_msgs/msg/TFMessage`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TfMessage {
    /// Transforms.
    pub transforms: Vec<TransformStamped>,
}

/// `thickness_collision_msgs/msg/Contact`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ContactMsg {
    /// Robot link.
    pub link_name: String,
    /// Environment object.
    pub object_name: String,
    /// Triangle in the object's mesh file (4294967295 for solids).
    pub triangle: u32,
    /// How far the link reaches past the surface along `normal` (metres).
    pub depth: f64,
    /// A point within 1e-6 m of both shapes.
    pub position: Point,
    /// Push-out direction.
    pub normal: Vector3,
    /// [`ContactMsg::ENVIRONMENT`], [`ContactMsg::ROBOT_LINK`] or [`ContactMsg::ATTACHED_OBJECT`].
    pub object_type: u8,
    /// What `link_name` is: [`ContactMsg::ROBOT_LINK`] or [`ContactMsg::ATTACHED_OBJECT`].
    pub link_type: u8,
}

impl ContactMsg {
    /// `object_name` is an environment object.
    pub const ENVIRONMENT: u8 = 0;
    /// `object_name` is another robot link (self-collision).
    pub const ROBOT_LINK: u8 = 1;
    /// The body is an object attached to the robot (a planning scene's attached object).
    pub const ATTACHED_OBJECT: u8 = 2;
}

/// `thickness_collision_msgs/msg/CollisionReport`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CollisionReport {
    /// The input's stamp and `world_frame`.
    pub header: Header,
    /// Whether any checked link collides.
    pub in_collision: bool,
    /// At least one contact (the deepest) for every colliding link.
    pub contacts: Vec<ContactMsg>,
    /// Time spent checking (seconds).
    pub check_seconds: f64,
    /// Why the state could not be checked (then `in_collision` is true); empty when it was.
    pub error: String,
    /// The report covers a motion from the previous state to this one.
    pub motion: bool,
    /// The first contact along the motion in [0, 1] when `motion` and `in_collision`; else -1.
    pub fraction: f64,
    /// Each checked link within `clearance_threshold` of the environment (empty when off).
    pub clearances: Vec<ClearanceMsg>,
}

/// `thickness_collision_msgs/msg/Clearance`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ClearanceMsg {
    /// Robot link.
    pub link_name: String,
    /// The nearest environment object.
    pub object_name: String,
    /// Triangle of the nearest cell in the object's mesh file (4294967295 for solids).
    pub triangle: u32,
    /// Signed distance (metres); minus the depth of the link's contact when colliding.
    pub distance: f64,
    /// Nearest point on the link; the contact point when colliding.
    pub point_on_link: Point,
    /// Nearest point on the object; the contact point when colliding.
    pub point_on_object: Point,
}

/// `std_msgs/msg/ColorRGBA`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct ColorRgba {
    /// Red.
    pub r: f32,
    /// Green.
    pub g: f32,
    /// Blue.
    pub b: f32,
    /// Alpha.
    pub a: f32,
}

/// `geometry_msgs/msg/Pose`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PoseMsg {
    /// Position.
    pub position: Point,
    /// Orientation.
    pub orientation: Quaternion,
}

/// `builtin_interfaces/msg/Duration`. A field a file leaves out is 0, as when ROS 2 reads a
/// message from YAML (`time_from_start: {sec: 3}`, the form `ros2 topic pub` examples use); CDR
/// always carries both.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct DurationMsg {
    /// Seconds.
    pub sec: i32,
    /// Nanoseconds.
    pub nanosec: u32,
}

/// `sensor_msgs/msg/CompressedImage` (empty in markers).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct CompressedImage {
    /// Header.
    pub header: Header,
    /// Format.
    pub format: String,
    /// Data.
    pub data: Vec<u8>,
}

/// `visualization_msgs/msg/UVCoordinate`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct UvCoordinate {
    /// u.
    pub u: f32,
    /// v.
    pub v: f32,
}

/// `visualization_msgs/msg/MeshFile`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct MeshFile {
    /// File name.
    pub filename: String,
    /// Data.
    pub data: Vec<u8>,
}

/// `visualization_msgs/msg/Marker` (the Iron/Jazzy layout, with texture and mesh file fields).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct Marker {
    /// Header.
    pub header: Header,
    /// Namespace.
    pub ns: String,
    /// Id within the namespace.
    pub id: i32,
    /// Marker type (7 sphere list, 11 triangle list).
    #[serde(rename = "type")]
    pub kind: i32,
    /// 0 add/modify, 2 delete, 3 delete all.
    pub action: i32,
    /// Pose.
    pub pose: PoseMsg,
    /// Scale.
    pub scale: Vector3,
    /// Colour.
    pub color: ColorRgba,
    /// How long the marker lives (0: forever).
    pub lifetime: DurationMsg,
    /// Frame locked.
    pub frame_locked: bool,
    /// Points.
    pub points: Vec<Point>,
    /// Per-point colours.
    pub colors: Vec<ColorRgba>,
    /// Texture resource.
    pub texture_resource: String,
    /// Texture.
    pub texture: CompressedImage,
    /// UV coordinates.
    pub uv_coordinates: Vec<UvCoordinate>,
    /// Text.
    pub text: String,
    /// Mesh resource.
    pub mesh_resource: String,
    /// Mesh file.
    pub mesh_file: MeshFile,
    /// Mesh materials.
    pub mesh_use_embedded_materials: bool,
}

/// `visualization_msgs/msg/MarkerArray`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct MarkerArray {
    /// Markers.
    pub markers: Vec<Marker>,
}

/// `diagnostic_msgs/msg/KeyValue`.
#[cfg(feature = "ros")]
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct KeyValue {
    /// Key.
    pub key: String,
    /// Value.
    pub value: String,
}

/// `diagnostic_msgs/msg/DiagnosticStatus`.
#[cfg(feature = "ros")]
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct DiagnosticStatus {
    /// 0 OK, 1 WARN, 2 ERROR, 3 STALE.
    pub level: u8,
    /// Name.
    pub name: String,
    /// Message.
    pub message: String,
    /// Hardware id.
    pub hardware_id: String,
    /// Values.
    pub values: Vec<KeyValue>,
}

/// `diagnostic_msgs/msg/DiagnosticArray`.
#[cfg(feature = "ros")]
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub(crate) struct DiagnosticArray {
    /// Header.
    pub header: Header,
    /// Statuses.
    pub status: Vec<DiagnosticStatus>,
}

/// Points, joint names, and entries of one point's fields a `trajectory_msgs/JointTrajectory`
/// may hold when decoded. A longer sequence is refused while it is read, before its elements are
/// allocated (an empty point costs 24 bytes on the wire and some 100 in memory).
pub(crate) const MAX_TRAJECTORY_ENTRIES: usize = 65_536;

/// A trajectory sequence of at most [`MAX_TRAJECTORY_ENTRIES`], refused as soon as it runs past.
pub(crate) fn bounded_trajectory_seq<'de, D: Deserializer<'de>, T: Deserialize<'de>>(d: D) -> Result<Vec<T>, D::Error> {
    bounded::bounded_vec(d, MAX_TRAJECTORY_ENTRIES, "trajectory field")
}

/// `trajectory_msgs/msg/JointTrajectoryPoint`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct JointTrajectoryPoint {
    /// Positions, one per joint name (radians or metres).
    #[serde(deserialize_with = "bounded_trajectory_seq")]
    pub positions: Vec<f64>,
    /// Velocities (per second), one per joint name, or none (a file may leave them out).
    #[serde(default, deserialize_with = "bounded_trajectory_seq")]
    pub velocities: Vec<f64>,
    /// Accelerations, one per joint name, or none (a file may leave them out).
    #[serde(default, deserialize_with = "bounded_trajectory_seq")]
    pub accelerations: Vec<f64>,
    /// Efforts (not used by the check; a file may leave them out).
    #[serde(default, deserialize_with = "bounded_trajectory_seq")]
    pub effort: Vec<f64>,
    /// When the point is reached, from the trajectory's start.
    pub time_from_start: DurationMsg,
}

/// `trajectory_msgs/msg/JointTrajectory`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct JointTrajectory {
    /// Header (a file may leave it out).
    #[serde(default)]
    pub header: Header,
    /// The joints every point gives a position for, in order.
    #[serde(deserialize_with = "bounded_trajectory_seq")]
    pub joint_names: Vec<String>,
    /// Waypoints.
    #[serde(deserialize_with = "bounded_trajectory_seq")]
    pub points: Vec<JointTrajectoryPoint>,
}

/// `thickness_collision_msgs/srv/CheckTrajectory` request.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct CheckTrajectoryRequest {
    /// The trajectory; joints it does not name keep the node's current merged state.
    pub trajectory: JointTrajectory,
    /// How the segments are interpolated: empty, as `joint_trajectory_controller` executes them
    /// (linear, cubic or quintic by what the points give, from the current state); `linear`, the
    /// straight chords between the waypoints.
    pub interpolation: String,
    /// Per joint of `joint_names`, how far the executed path may stray (radians or metres);
    /// empty: none.
    pub path_tolerance: Vec<f64>,
}

/// `path_tolerance` as decoded: bounded like the trajectory's own fields.
#[derive(Deserialize)]
struct Tolerances(#[serde(deserialize_with = "bounded_trajectory_seq")] Vec<f64>);

/// Decoded field by field so that an older client's request, which ends after `trajectory`,
/// decodes with the two appended fields empty. A request that gives `interpolation` must give
/// `path_tolerance` whole (else it does not decode).
impl<'de> Deserialize<'de> for CheckTrajectoryRequest {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::{Error, MapAccess, SeqAccess, Visitor};
        struct Fields;
        impl<'de> Visitor<'de> for Fields {
            type Value = CheckTrajectoryRequest;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a CheckTrajectory request")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
                let trajectory = seq.next_element()?.ok_or_else(|| A::Error::invalid_length(0, &self))?;
                let Ok(Some(interpolation)) = seq.next_element::<String>() else {
                    return Ok(CheckTrajectoryRequest { trajectory, ..Default::default() });
                };
                let path_tolerance = seq.next_element::<Tolerances>()?.map(|t| t.0).unwrap_or_default();
                Ok(CheckTrajectoryRequest { trajectory, interpolation, path_tolerance })
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
                let mut r = CheckTrajectoryRequest::default();
                while let Some(key) = map.next_key::<String>()? {
                    match key.as_str() {
                        "trajectory" => r.trajectory = map.next_value()?,
                        "interpolation" => r.interpolation = map.next_value()?,
                        "path_tolerance" => r.path_tolerance = map.next_value::<Tolerances>()?.0,
                        other => return Err(A::Error::unknown_field(other, &["trajectory", "interpolation", "path_tolerance"])),
                    }
                }
                Ok(r)
            }
        }
        d.deserialize_struct("CheckTrajectoryRequest", &["trajectory", "interpolation", "path_tolerance"], Fields)
    }
}

/// `thickness_collision_msgs/srv/CheckTrajectory` response.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CheckTrajectoryResponse {
    /// Every segment (linear interpolation between waypoints) is free.
    pub valid: bool,
    /// The first segment (from point `segment` to point `segment + 1`) found colliding or not
    /// checkable; -1 when valid or when the request itself is refused.
    pub segment: i32,
    /// The first contact along `segment`, in [0, 1]; -1 when there is none.
    pub fraction: f64,
    /// `t_i + fraction · (t_{i+1} - t_i)` for `segment` i; zero when there is no contact.
    pub time_from_start: DurationMsg,
    /// The contacts of the pose at `fraction`.
    pub contacts: Vec<ContactMsg>,
    /// Why the trajectory was refused or could not be checked; empty otherwise.
    pub error: String,
    /// With `clearance_threshold` set: per link within it somewhere on the path (up to the first
    /// contact), its smallest clearance over the path, never above the true minimum and at most
    /// 1 mm below it; empty otherwise.
    pub clearances: Vec<ClearanceMsg>,
}
