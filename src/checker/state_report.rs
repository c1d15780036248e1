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
