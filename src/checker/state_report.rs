//! What one robot state gives: the fields of the node's `CollisionReport` and `Contact` messages.

use serde::{Deserialize, Serialize};

/// One contact, as in `thickness_collision_msgs/Contact`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReportContact {
    /// Robot link.
    pub link_name: String,
    /// Environment object (link of the environment URDF).
    pub object_name: String,
    /// Triangle index in the object's mesh file (`u32::MAX` for solids).
    pub triangle: u32,
    /// How far the link reaches past the surface along `normal` (metres).
    pub depth: f64,
    /// A point within 1e-6 m of both shapes (world frame); `None` only from a flags-only check.
    pub position: Option<[f64; 3]>,
    /// Push-out direction (world frame).
    pub normal: [f64; 3],
    /// What `object_name` is: an environment object, or (self-collision) another robot link or
    /// an attached object.
    #[serde(default)]
    pub object_type: ObjectType,
    /// What `link_name` is: a robot link, or an attached object (only then in JSON).
    #[serde(default = "robot_link", skip_serializing_if = "is_robot_link")]
    pub link_type: ObjectType,
}

fn robot_link() -> ObjectType {
    ObjectType::RobotLink
}

fn is_robot_link(t: &ObjectType) -> bool {
    *t == ObjectType::RobotLink
}

/// What a contact's object is, as `Contact.object_type`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ObjectType {
    /// A link of the environment URDF (a thin surface or a solid).
    #[default]
    Environment,
    /// Another link of the robot: `link_name` is the pair's first link in model order.
    RobotLink,
    /// An object attached to a robot link (a planning scene's attached collision object).
    AttachedObject,
}

impl ObjectType {
    /// `Contact.ENVIRONMENT`, `Contact.ROBOT_LINK` or `Contact.ATTACHED_OBJECT`.
    pub fn code(self) -> u8 {
        match self {
            ObjectType::Environment => 0,
            ObjectType::RobotLink => 1,
            ObjectType::AttachedObject => 2,
        }
    }
}

/// How near one link is to the environment, as in `thickness_collision_msgs/Clearance`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReportClearance {
    /// Robot link.
    pub link_name: String,
    /// The nearest environment object (link of the environment URDF).
    pub object_name: String,
    /// Triangle index of the nearest cell in the object's mesh file (`u32::MAX` for solids).
    pub triangle: u32,
    /// Signed distance (metres): the gap to the nearest cell or solid, or minus the depth of the
    /// link's contact when it collides.
    pub distance: f64,
    /// The nearest point on the link (world frame); the contact point when colliding.
    pub point_on_link: [f64; 3],
    /// The nearest point on the object (world frame); the contact point when colliding.
    pub point_on_object: [f64; 3],
}

/// The result for one state, as in `thickness_collision_msgs/CollisionReport` (without header).
///
/// Fail closed: a state that could not be checked is reported with `in_collision` set and the
/// cause in `error` ([`StateReport::failed`]), never as free.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct StateReport {
    /// Whether any checked link collides.
    pub in_collision: bool,
    /// The deepest contact of every colliding link, in link order (all contacts when asked).
    pub contacts: Vec<ReportContact>,
    /// Joints whose position lies outside their limits.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub out_of_limits: Vec<String>,
    /// Why the state could not be checked; empty when it was.
    #[serde(default)]
    pub error: String,
    /// The report covers a motion (from the previous state to this one), not one state.
    #[serde(default)]
    pub motion: bool,
    /// For a motion in collision: the first contact along it, in [0, 1] (the start of the first
    /// stretch that could not be cleared, never later than the true first contact).
    #[serde(default)]
    pub fraction: Option<f64>,
    /// Each checked link within `clearance_threshold` of the environment, in link order; empty
    /// when clearance is off.
    #[serde(default)]
    pub clearances: Vec<ReportClearance>,
    /// Seconds spent checking (not part of `check --json`, which must be deterministic).
    #[serde(skip)]
    pub check_seconds: f64,
}

impl StateReport {
    /// The report of a state that could not be checked: in collision, with the cause.
    pub fn failed(error: impl Into<String>) -> StateReport {
        StateReport { in_collision: true, error: error.into(), ..Default::default() }
    }
}
