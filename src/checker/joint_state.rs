//! From a joint state given by name to a position for every joint of the model.

use crate::model::{MissingJoint, PositionsError, RobotModel};

/// A state that cannot be checked.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum StateError {
    /// `name` and `position` have different lengths.
    #[error("joint state has {names} names but {positions} positions")]
    Lengths {
        /// Names.
        names: usize,
        /// Positions.
        positions: usize,
    },
    /// A position is NaN or infinite.
    #[error("joint '{joint}' has a non-finite position {value}")]
    NonFinite {
        /// The joint.
        joint: String,
        /// Its value.
        value: f64,
    },
    /// A joint named twice in one state.
    #[error("joint state names joint '{0}' twice")]
    Duplicate(String),
    /// A joint is missing and `missing_joint` is `reject`.
    #[error("joint state lacks joint '{0}' (missing_joint: reject)")]
    Missing(String),
    /// A state that names none of the robot's moving joints (an empty one, another robot's).
    #[error("{0}")]
    NotOurRobot(String),
    /// Under `missing_joint: last`, a joint that moves a checked link has not been received yet.
    #[error("joint '{first}'{} never received: under missing_joint: last a state is checked once every joint that moves a checked link has been received", if *.more > 0 { format!(" (and {} more)", .more) } else { String::new() })]
    Incomplete {
        /// The first such joint, in model order.
        first: String,
        /// How many more.
        more: usize,
    },
    /// A name that is not a joint of the model, where every name must be one (a service request,
    /// `check --joints`).
    #[error("'{0}' is not a joint of the robot model")]
    Unknown(String),
    /// Positions indexed by joint that do not fit the model.
    #[error(transparent)]
    Positions(#[from] PositionsError),
    /// World poses indexed by link that do not fit the model.
    #[error("{got} link poses for a model of {expected} links")]
    Poses {
        /// Links of the model.
        expected: usize,
        /// Poses given.
        got: usize,
    },
    /// A checked link has no pose (its frame does not reach `world_frame`).
    #[error("no pose for link '{0}' (its frame does not reach world_frame)")]
    NoPose(String),
    /// A transform is NaN, infinite or not a rotation.
    #[error("transform for link '{0}' is not a finite rigid transform")]
    BadTransform(String),
}

/// Positions for every joint of `model` from one state alone: every name must be a joint of the
/// model; a joint the state lacks is at 0, or an error under [`MissingJoint::Reject`].
pub(crate) fn resolve_positions(model: &RobotModel, names: &[String], positions: &[f64], missing: MissingJoint) -> Result<Vec<f64>, StateError> {
    if names.len() != positions.len() {
        return Err(StateError::Lengths { names: names.len(), positions: positions.len() });
    }
    let mut q: Vec<Option<f64>> = vec![None; model.joints.len()];
    for (name, &value) in names.iter().zip(positions) {
        let j = model.joint(name).ok_or_else(|| StateError::Unknown(name.clone()))?;
        if !value.is_finite() {
            return Err(StateError::NonFinite { joint: name.clone(), value });
        }
        if q[j].replace(value).is_some() {
            return Err(StateError::Duplicate(name.clone()));
        }
    }
    require_own_joints(model, q.iter().enumerate().filter(|(_, v)| v.is_some()).map(|(j, _)| j), names)?;
    model
        .joints
        .iter()
        .zip(q)
        .map(|(joint, v)| match v {
            Some(v) => Ok(v),
            None if joint.is_actuated() && missing == MissingJoint::Reject => Err(StateError::Missing(joint.name.clone())),
            None => Ok(0.0),
        })
        .collect()
}

/// Refuses a state whose named joints (`given`, model indices) hold none of `model`'s actuated
/// joints: an empty state, or another robot's. A robot with no actuated joint has only the one
/// pose, which any state stands for.
pub(crate) fn require_own_joints(model: &RobotModel, mut given: impl Iterator<Item = usize>, names: &[String]) -> Result<(), StateError> {
    let actuated = model.joints.iter().filter(|j| j.is_actuated()).count();
    if actuated == 0 || given.any(|j| model.joints[j].is_actuated()) {
        return Ok(());
    }
    let what = match names.first() {
        None => "the joint state names no joint".to_owned(),
        Some(first) => format!("the joint state names none of the {actuated} moving joints of robot '{}' (e.g. '{first}')", model.name),
    };
    Err(StateError::NotOurRobot(format!("{what}: another robot's state cannot be checked as this one's")))
}
