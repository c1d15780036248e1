//! `moveit_msgs/srv/GetStateValidity` and the closure of messages it carries, as plain serde
//! structs (field order = wire order, CDR), checked field by field against the `moveit_msgs`
//! ros2 branch and `common_interfaces` (jazzy): RobotState, AttachedCollisionObject,
//! CollisionObject, Constraints and its four constraint types, BoundingVolume,
//! ContactInformation, CostSource, ConstraintEvalResult, shape_msgs, object_recognition_msgs,
//! sensor_msgs/MultiDOFJointState and the geometry_msgs they use. Constants are given as Rust
//! constants where the node uses them (they do not travel).
//!
//! Every sequence is bounded while it is decoded ([`MAX_MOVEIT_ENTRIES`]), before its elements
//! are allocated: a request is hostile input like any joint state.

use super::{Header, JointState, JointTrajectory, Point, PoseMsg, Quaternion, Transform, Vector3};
use serde::{Deserialize, Deserializer, Serialize};

/// Entries any sequence of a `GetStateValidity` request may hold when decoded (as many as a
/// joint state's fields may). A longer one is refused as soon as it runs past.
pub const MAX_MOVEIT_ENTRIES: usize = 65_536;

/// A sequence of at most [`MAX_MOVEIT_ENTRIES`], refused as soon as it runs past.
fn bounded<'de, D: Deserializer<'de>, T: Deserialize<'de>>(d: D) -> Result<Vec<T>, D::Error> {
    super::bounded::bounded_vec(d, MAX_MOVEIT_ENTRIES, "GetStateValidity sequence")
}

/// `float64[<=3]`: a bounded sequence of at most 3 on the wire, refused past that.
fn at_most_3<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<f64>, D::Error> {
    let v: Vec<f64> = bounded(d)?;
    if v.len() > 3 {
        return Err(serde::de::Error::custom(format!("SolidPrimitive.dimensions has {} entries; at most 3 allowed", v.len())));
    }
    Ok(v)
}

/// `geometry_msgs/msg/Twist`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Twist {
    /// Linear velocity.
    pub linear: Vector3,
    /// Angular velocity.
    pub angular: Vector3,
}

/// `geometry_msgs/msg/Wrench`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Wrench {
    /// Force.
    pub force: Vector3,
    /// Torque.
    pub torque: Vector3,
}

/// `geometry_msgs/msg/PoseStamped`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PoseStamped {
    /// Header.
    pub header: Header,
    /// Pose.
    pub pose: PoseMsg,
}

/// `geometry_msgs/msg/Point32`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Point32 {
    /// x.
    pub x: f32,
    /// y.
    pub y: f32,
    /// z.
    pub z: f32,
}

/// `geometry_msgs/msg/Polygon`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Polygon {
    /// Vertices.
    #[serde(deserialize_with = "bounded")]
    pub points: Vec<Point32>,
}

/// `sensor_msgs/msg/MultiDOFJointState`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MultiDofJointState {
    /// Header.
    pub header: Header,
    /// Joint names.
    #[serde(deserialize_with = "bounded")]
    pub joint_names: Vec<String>,
    /// One transform per joint.
    #[serde(deserialize_with = "bounded")]
    pub transforms: Vec<Transform>,
    /// Velocities.
    #[serde(deserialize_with = "bounded")]
    pub twist: Vec<Twist>,
    /// Wrenches.
    #[serde(deserialize_with = "bounded")]
    pub wrench: Vec<Wrench>,
}

/// `shape_msgs/msg/SolidPrimitive` (with the `polygon` field of humble and later).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct SolidPrimitive {
    /// BOX=1, SPHERE=2, CYLINDER=3, CONE=4, PRISM=5.
    #[serde(rename = "type")]
    pub kind: u8,
    /// `float64[<=3]`.
    #[serde(deserialize_with = "at_most_3")]
    pub dimensions: Vec<f64>,
    /// The base of a PRISM.
    pub polygon: Polygon,
}

/// `shape_msgs/msg/MeshTriangle`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct MeshTriangle {
    /// `uint32[3]` (a fixed array: no length on the wire).
    pub vertex_indices: [u32; 3],
}

/// `shape_msgs/msg/Mesh`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ShapeMesh {
    /// Triangles.
    #[serde(deserialize_with = "bounded")]
    pub triangles: Vec<MeshTriangle>,
    /// Vertices.
    #[serde(deserialize_with = "bounded")]
    pub vertices: Vec<Point>,
}

/// `shape_msgs/msg/Plane`: `float64[4] coef` (a fixed array).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Plane {
    /// ax + by + cz + d = 0.
    pub coef: [f64; 4],
}

/// `object_recognition_msgs/msg/ObjectType`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ObjectType {
    /// Key.
    pub key: String,
    /// Database.
    pub db: String,
}

/// `moveit_msgs/msg/CollisionObject`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CollisionObject {
    /// Header.
    pub header: Header,
    /// Pose of the object.
    pub pose: PoseMsg,
    /// Id.
    pub id: String,
    /// Type.
    #[serde(rename = "type")]
    pub kind: ObjectType,
    /// Primitives.
    #[serde(deserialize_with = "bounded")]
    pub primitives: Vec<SolidPrimitive>,
    /// Their poses.
    #[serde(deserialize_with = "bounded")]
    pub primitive_poses: Vec<PoseMsg>,
    /// Meshes.
    #[serde(deserialize_with = "bounded")]
    pub meshes: Vec<ShapeMesh>,
    /// Their poses.
    #[serde(deserialize_with = "bounded")]
    pub mesh_poses: Vec<PoseMsg>,
    /// Planes.
    #[serde(deserialize_with = "bounded")]
    pub planes: Vec<Plane>,
    /// Their poses.
    #[serde(deserialize_with = "bounded")]
    pub plane_poses: Vec<PoseMsg>,
    /// Subframe names.
    #[serde(deserialize_with = "bounded")]
    pub subframe_names: Vec<String>,
    /// Subframe poses.
    #[serde(deserialize_with = "bounded")]
    pub subframe_poses: Vec<PoseMsg>,
    /// `byte`: ADD=0, REMOVE=1, APPEND=2, MOVE=3.
    pub operation: u8,
}

/// `moveit_msgs/msg/AttachedCollisionObject`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct AttachedCollisionObject {
    /// The link it is attached to.
    pub link_name: String,
    /// The object.
    pub object: CollisionObject,
    /// Links it may touch.
    #[serde(deserialize_with = "bounded")]
    pub touch_links: Vec<String>,
    /// Posture on detaching.
    pub detach_posture: JointTrajectory,
    /// Weight (kg).
    pub weight: f64,
}

/// `moveit_msgs/msg/RobotState`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RobotStateMsg {
    /// Single-DOF joints.
    pub joint_state: JointState,
    /// Multi-DOF joints.
    pub multi_dof_joint_state: MultiDofJointState,
    /// Attached collision objects.
    #[serde(deserialize_with = "bounded")]
    pub attached_collision_objects: Vec<AttachedCollisionObject>,
    /// Whether the state is a difference to the current one (the node applies it on top of the
    /// current state either way, as `move_group` does).
    pub is_diff: bool,
}

/// `moveit_msgs/msg/JointConstraint`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct JointConstraint {
    /// Joint.
    pub joint_name: String,
    /// Position.
    pub position: f64,
    /// Tolerance above.
    pub tolerance_above: f64,
    /// Tolerance below.
    pub tolerance_below: f64,
    /// Weight.
    pub weight: f64,
}

/// `moveit_msgs/msg/BoundingVolume`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct BoundingVolume {
    /// Primitives.
    #[serde(deserialize_with = "bounded")]
    pub primitives: Vec<SolidPrimitive>,
    /// Their poses.
    #[serde(deserialize_with = "bounded")]
    pub primitive_poses: Vec<PoseMsg>,
    /// Meshes.
    #[serde(deserialize_with = "bounded")]
    pub meshes: Vec<ShapeMesh>,
    /// Their poses.
    #[serde(deserialize_with = "bounded")]
    pub mesh_poses: Vec<PoseMsg>,
}

/// `moveit_msgs/msg/PositionConstraint`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PositionConstraint {
    /// Header.
    pub header: Header,
    /// Link.
    pub link_name: String,
    /// Offset of the target point in the link.
    pub target_point_offset: Vector3,
    /// Region.
    pub constraint_region: BoundingVolume,
    /// Weight.
    pub weight: f64,
}

/// `moveit_msgs/msg/OrientationConstraint`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct OrientationConstraint {
    /// Header.
    pub header: Header,
    /// Orientation.
    pub orientation: Quaternion,
    /// Link.
    pub link_name: String,
    /// Tolerance about x.
    pub absolute_x_axis_tolerance: f64,
    /// Tolerance about y.
    pub absolute_y_axis_tolerance: f64,
    /// Tolerance about z.
    pub absolute_z_axis_tolerance: f64,
    /// XYZ_EULER_ANGLES=0, ROTATION_VECTOR=1.
    pub parameterization: u8,
    /// Weight.
    pub weight: f64,
}

/// `moveit_msgs/msg/VisibilityConstraint`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct VisibilityConstraint {
    /// Target radius.
    pub target_radius: f64,
    /// Target pose.
    pub target_pose: PoseStamped,
    /// Cone sides.
    pub cone_sides: i32,
    /// Sensor pose.
    pub sensor_pose: PoseStamped,
    /// Maximum view angle.
    pub max_view_angle: f64,
    /// Maximum range angle.
    pub max_range_angle: f64,
    /// SENSOR_Z=0, SENSOR_Y=1, SENSOR_X=2.
    pub sensor_view_direction: u8,
    /// Weight.
    pub weight: f64,
}

/// `moveit_msgs/msg/Constraints`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Constraints {
    /// Name.
    pub name: String,
    /// Joint constraints.
    #[serde(deserialize_with = "bounded")]
    pub joint_constraints: Vec<JointConstraint>,
    /// Position constraints.
    #[serde(deserialize_with = "bounded")]
    pub position_constraints: Vec<PositionConstraint>,
    /// Orientation constraints.
    #[serde(deserialize_with = "bounded")]
    pub orientation_constraints: Vec<OrientationConstraint>,
    /// Visibility constraints.
    #[serde(deserialize_with = "bounded")]
    pub visibility_constraints: Vec<VisibilityConstraint>,
}

impl Constraints {
    /// Whether any constraint is given (a name alone constrains nothing).
    pub fn is_empty(&self) -> bool {
        self.joint_constraints.is_empty()
            && self.position_constraints.is_empty()
            && self.orientation_constraints.is_empty()
            && self.visibility_constraints.is_empty()
    }
}

/// `moveit_msgs/msg/ContactInformation` `body_type` for a robot link.
pub const BODY_ROBOT_LINK: u32 = 0;
/// `moveit_msgs/msg/ContactInformation` `body_type` for a world object.
pub const BODY_WORLD_OBJECT: u32 = 1;

/// `moveit_msgs/msg/ContactInformation`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ContactInformation {
    /// Frame of `position` and `normal`.
    pub header: Header,
    /// Contact point.
    pub position: Point,
    /// Contact normal.
    pub normal: Vector3,
    /// Penetration depth (metres).
    pub depth: f64,
    /// First body.
    pub contact_body_1: String,
    /// Its type ([`BODY_ROBOT_LINK`], ...).
    pub body_type_1: u32,
    /// Second body.
    pub contact_body_2: String,
    /// Its type.
    pub body_type_2: u32,
}

/// `moveit_msgs/msg/CostSource`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct CostSource {
    /// Cost density.
    pub cost_density: f64,
    /// Box minimum.
    pub aabb_min: Vector3,
    /// Box maximum.
    pub aabb_max: Vector3,
}

/// `moveit_msgs/msg/ConstraintEvalResult`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ConstraintEvalResult {
    /// Satisfied.
    pub result: bool,
    /// Distance.
    pub distance: f64,
}

/// `moveit_msgs/srv/GetStateValidity` request.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct GetStateValidityRequest {
    /// The state, applied on top of the node's current merged joint state.
    pub robot_state: RobotStateMsg,
    /// The planning group (links its joints move, and their descendants); empty or unknown: the
    /// whole robot.
    pub group_name: String,
    /// Constraints (the node refuses any).
    pub constraints: Constraints,
}

/// `moveit_msgs/srv/GetStateValidity` response.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct GetStateValidityResponse {
    /// No checked pair collides, and the request could be honoured.
    pub valid: bool,
    /// The contacts (in `world_frame`).
    pub contacts: Vec<ContactInformation>,
    /// Always empty.
    pub cost_sources: Vec<CostSource>,
    /// Always empty.
    pub constraint_result: Vec<ConstraintEvalResult>,
}
