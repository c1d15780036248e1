//! Joint states to positions of every joint: validation, merging of partial messages and the
//! `missing_joint` rule, the same for the node, replay and `check --states`.

use crate::checker::{Checker, StateError};
use crate::model::MissingJoint;

/// Unknown names passed back from one message at most.
const MAX_UNKNOWN_REPORTED: usize = 64;

/// The positions received so far (merged across messages under `last` and `reject`).
#[derive(Clone, Debug)]
pub(crate) struct JointInput {
    received: Vec<Option<f64>>,
    /// The velocity each joint was last received with (`None`: its last message gave none).
    velocity: Vec<Option<f64>>,
}

impl JointInput {
    /// Nothing received yet for any joint of `robot`.
    pub(crate) fn new(checker: &Checker) -> JointInput {
        JointInput { received: vec![None; checker.robot().joints.len()], velocity: vec![None; checker.robot().joints.len()] }
    }

    /// One message: the position of every joint, or why the message gives no state. A bad message
    /// changes nothing (it is not merged), nor does one that names none of the robot's actuated
    /// joints (another robot's). Names that are not joints of the robot are ignored (other robots
    /// share the topic) and pushed to `unknown`. Under `last`, a merged state still lacking a joint
    /// that moves a checked link is not a state yet (MoveIt's current state monitor waits for a
    /// complete state likewise).
    pub(crate) fn ingest(
        &mut self,
        checker: &Checker,
        missing: MissingJoint,
        names: &[String],
        positions: &[f64],
        velocities: &[f64],
        unknown: &mut Vec<String>,
    ) -> Result<Vec<f64>, StateError> {
        let robot = checker.robot();
        if names.len() != positions.len() {
            return Err(StateError::Lengths { names: names.len(), positions: positions.len() });
        }
        let mut given: Vec<(usize, f64)> = Vec::with_capacity(names.len().min(robot.joints.len()));
        let mut speeds: Vec<Option<f64>> = Vec::with_capacity(given.capacity());
        for (k, (name, &value)) in names.iter().zip(positions).enumerate() {
            match robot.joint(name) {
                Some(_) if !value.is_finite() => return Err(StateError::NonFinite { joint: name.clone(), value }),
                Some(j) if given.iter().any(|(k, _)| *k == j) => return Err(StateError::Duplicate(name.clone())),
                Some(j) => {
                    given.push((j, value));
                    // A message whose velocities do not match its names gives none.
                    speeds.push(if velocities.len() == names.len() { velocities.get(k).copied().filter(|v| v.is_finite()) } else { None });
                }
                // The pipeline warns about a bounded number of names; a message of made-up
                // names must not cost a copy of each.
                None if unknown.len() < MAX_UNKNOWN_REPORTED => unknown.push(name.clone()),
                None => {}
            }
        }
        crate::checker::require_own_joints(robot, given.iter().map(|&(j, _)| j), names)?;
        if missing == MissingJoint::Zero {
            self.received.iter_mut().for_each(|v| *v = None);
            self.velocity.iter_mut().for_each(|v| *v = None);
        }
        for ((j, value), speed) in given.into_iter().zip(speeds) {
            self.received[j] = Some(value);
            self.velocity[j] = speed;
        }
        if missing == MissingJoint::Last {
            let mut lacking = (0..robot.joints.len()).filter(|&j| self.received[j].is_none() && checker.moves_checked_link(j));
            if let Some(first) = lacking.next() {
                return Err(StateError::Incomplete { first: robot.joints[first].name.clone(), more: lacking.count() });
            }
        }
        robot
            .joints
            .iter()
            .zip(&self.received)
            .map(|(joint, v)| match v {
                Some(v) => Ok(*v),
                None if joint.is_actuated() && missing == MissingJoint::Reject => Err(StateError::Missing(joint.name.clone())),
                None => Ok(0.0),
            })
            .collect()
    }

    /// The positions received so far, by joint index (`None`: never received, or cleared under
    /// `missing_joint: zero`).
    pub(crate) fn current(&self) -> &[Option<f64>] {
        &self.received
    }

    /// The velocities received with [`JointInput::current`]'s positions (`None`: not given).
    pub(crate) fn velocities(&self) -> &[Option<f64>] {
        &self.velocity
    }
}
