//! `moveit_msgs/srv/GetStateValidity` and the messages of its closure that the planning scene
//! does not carry, as plain serde structs (field order = wire order, CDR), checked field by
//! field against the `moveit_msgs` ros2 branch and `common_interfaces` (jazzy): Constraints and
//! its four constraint types, BoundingVolume, ContactInformation, CostSource,
//! ConstraintEvalResult and `geometry_msgs/PoseStamped`. The request's RobotState, its attached
//! objects and their shapes are the planning scene's (`super::planning_scene`), with the bounds
//! given there. Constants are given as Rust constants where the node uses them (they do not
//! travel).
//!
//! Every other sequence is bounded while it is decoded ([`MAX_MOVEIT_ENTRIES`]), before its
//! elements are allocated: a request is hostile input like any joint state.

use super::planning_scene::{RobotStateMsg, ShapeMesh, SolidPrimitive};
use super::{Header, Point, PoseMsg, Quaternion, Vector3};
use serde::{Deserialize, Deserializer, Serialize};

/// Entries a sequence of a `GetStateValidity` request outside its robot state may hold when
/// decoded (as many as a joint state's fields may). A longer one is refused as soon as it runs past.
pub const MAX_MOVEIT_ENTRIES: usize = 65_536;

/// A sequence of at most [`MAX_MOVEIT_ENTRIES`], refused as soon as it runs past.
fn bounded<'de, D: Deserializer<'de>, T: Deserialize<'de>>(d: D) -> Result<Vec<T>, D::Error> {
    super::bounded::bounded_vec(d, MAX_MOVEIT_ENTRIES, "GetStateValidity sequence")
}

/// `geometry_msgs/msg/PoseStamped`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PoseStamped {
    /// Header.
    pub header: Header,
    /// Pose.
    pub pose: PoseMsg,
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
/// `moveit_msgs/msg/ContactInformation` `body_type` for an object attached to the robot.
pub const BODY_ROBOT_ATTACHED: u32 = 2;

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
