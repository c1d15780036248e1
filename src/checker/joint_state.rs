//! From a joint state (names and positions) to a position for every joint of the model.

use crate::model::{MissingJoint, RobotModel};

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
    /// A joint is missing and `missing_joint` is `reject`.
    #[error("joint state lacks joint '{0}' (missing_joint: reject)")]
    Missing(String),
    /// A name is not a joint of the model (an error only where asked: `--joints`).
    #[error("'{0}' is not a joint of the robot model")]
    Unknown(String),
    /// A transform names a link that is not in the model.
    #[error("transform for '{0}', which is not a link of the robot model")]
    UnknownLink(String),
    /// A transform is NaN, infinite or not a rotation.
    #[error("transform for link '{0}' is not a finite rigid transform")]
    BadTransform(String),
}

/// The last position seen for every joint (for `missing_joint: last`).
#[derive(Clone, Debug)]
pub struct JointMemory {
    pub(crate) last: Vec<f64>,
    warned: std::collections::HashSet<String>,
}

impl JointMemory {
    /// Zero for every joint of `model`.
    pub fn new(model: &RobotModel) -> JointMemory {
        JointMemory { last: vec![0.0; model.joints.len()], warned: Default::default() }
    }

    /// Returns true the first time `name` is seen as unknown (to warn once per name).
    pub fn first_unknown(&mut self, name: &str) -> bool {
        self.warned.insert(name.to_owned())
    }
}

/// Positions for every joint of `model`, and the names that are not joints of it. With `strict`,
/// an unknown name is an error.
pub(crate) fn resolve_positions(
    model: &RobotModel,
    names: &[String],
    positions: &[f64],
    missing: MissingJoint,
    memory: &mut JointMemory,
    strict: bool,
) -> Result<(Vec<f64>, Vec<String>), StateError> {
    if names.len() != positions.len() {
        return Err(StateError::Lengths { names: names.len(), positions: positions.len() });
    }
    let mut q: Vec<Option<f64>> = vec![None; model.joints.len()];
    let mut unknown = Vec::new();
    for (name, &value) in names.iter().zip(positions) {
        match model.joint(name) {
            Some(j) => {
                if !value.is_finite() {
                    return Err(StateError::NonFinite { joint: name.clone(), value });
                }
                q[j] = Some(value);
            }
            None if strict => return Err(StateError::Unknown(name.clone())),
            None => unknown.push(name.clone()),
        }
    }
    let mut out = Vec::with_capacity(q.len());
    for (j, v) in q.into_iter().enumerate() {
        let joint = &model.joints[j];
        let value = match v {
            Some(v) => v,
            None if !joint.is_actuated() => 0.0,
            None => match missing {
                MissingJoint::Zero => 0.0,
                MissingJoint::Last => memory.last[j],
                MissingJoint::Reject => return Err(StateError::Missing(joint.name.clone())),
            },
        };
        out.push(value);
    }
    memory.last.copy_from_slice(&out);
    Ok((out, unknown))
}
