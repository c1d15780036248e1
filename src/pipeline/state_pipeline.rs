//! The one path from input messages to checked states. The node, replay and `check` hand it
//! messages in arrival order and publish what it returns; it owns everything that decides an
//! answer (the checker, merged joint states, the TF tree, the robot's source, skip counts), so the
//! same messages give the same reports, stamps and skips through every door.

use super::joint_input::JointInput;
use super::report_adapter::CheckedState;
use super::scene_state::SceneState;
use super::skip::{Skip, SkipCause};
use super::tf_tree::{TfRejection, TfTree};
use crate::checker::{read_semantic_file, BodyCache, Checker, CheckerError, StateError, StateReport};
use crate::math::Pose;
use crate::model::{MissingJoint, Params};
use crate::msgs::{CollisionReport, JointState, TfMessage, Time};
use std::collections::{BTreeMap, HashSet};
use std::sync::Arc;

/// Unknown joint names remembered (to warn once each); past this, new ones are not warned
/// about, so a flood of made-up names cannot grow memory.
const MAX_UNKNOWN_NAMES: usize = 1024;

/// Where the robot came from: it keeps its source when parameters change.
#[derive(Clone, Debug)]
pub(super) enum RobotSource {
    /// The file the parameters name (see [`Params::robot_path`]).
    Files,
    /// A `robot_description` message (URDF text) and what to call it in errors.
    Description { urdf: Arc<str>, source: String },
}

/// A robot state ready to check: positions of every joint, or world poses of the links. Two
/// states are equal when their stamps and poses are, however they were reached.
#[derive(Clone, Debug)]
pub struct RobotState {
    /// The input's stamp.
    pub stamp: Time,
    pose: StatePose,
    /// Whether the robot got here from the state accepted just before (same robot and
    /// parameters, no rejected message between, stamps forward by at most `motion_max_gap`): only
    /// then is the motion between them checked.
    follows: bool,
}

impl RobotState {
    /// The joint positions of a state made from a joint state (None for one made of link poses:
    /// its `/tf` came with the input). With [`link_transforms`] they give the state's `/tf`.
    pub(crate) fn joint_positions(&self) -> Option<&[f64]> {
        match &self.pose {
            StatePose::Joints(q) => Some(q),
            StatePose::Links(_) => None,
        }
    }
}

impl PartialEq for RobotState {
    fn eq(&self, other: &RobotState) -> bool {
        self.stamp == other.stamp && self.pose == other.pose
    }
}

#[derive(Clone, Debug, PartialEq)]
enum StatePose {
    Joints(Vec<f64>),
    Links(Vec<Option<Pose>>),
}

/// Messages in, checked states out. See the module documentation.
pub struct Pipeline {
    pub(super) checker: Arc<Checker>,
    pub(super) source: RobotSource,
    joints: JointInput,
    pub(super) tf: TfTree,
    skipped: BTreeMap<SkipCause, u64>,
    unknown_names: HashSet<String>,
    pub(super) warnings: Vec<String>,
    /// The planning scene's objects and frames in force (in the checker's scene too).
    pub(super) scene: SceneState,
    /// The cells built for the planning scene's meshes, kept while the scene holds them.
    pub(super) bodies: BodyCache,
    /// An octomap was refused (it is warned about once).
    pub(super) octomap_warned: bool,
    /// Stamp of the last state accepted, while the next one may follow it.
    last_stamp: Option<Time>,
    /// The last state checked or covered by a report: where the next motion starts.
    trail: Option<RobotState>,
    /// The latest `robot_description_semantic` (SRDF text, and what to call it): applied to
    /// every robot built after it that it fits.
    pub(super) semantic: Option<(Arc<str>, String)>,
    /// `semantic` is the parameters' `robot_semantic_file`, held for the robot that comes as a
    /// `robot_description` because it does not fit the one the files give: a description it
    /// does not fit is refused, and robots built from files do without it.
    pub(super) semantic_deferred: bool,
}

impl Pipeline {
    /// The robot and environment the parameters name (see [`Params::robot_path`] and
    /// [`Params::environment_path`]).
    pub fn new(params: Params) -> Result<Pipeline, CheckerError> {
        let checker = Checker::from_params(params)?;
        Ok(Self::with_checker(checker, RobotSource::Files))
    }

    fn with_checker(checker: Checker, source: RobotSource) -> Pipeline {
        let joints = JointInput::new(&checker);
        Pipeline {
            checker: Arc::new(checker),
            source,
            joints,
            tf: TfTree::default(),
            skipped: BTreeMap::new(),
            unknown_names: HashSet::new(),
            warnings: Vec::new(),
            scene: SceneState::default(),
            bodies: BodyCache::default(),
            octomap_warned: false,
            last_stamp: None,
            trail: None,
            semantic: None,
            semantic_deferred: false,
        }
    }

    /// As [`Pipeline::new`], for a front door whose robot may still come as a `robot_description`
    /// (the node; a bag that recorded one). With no robot file named (the bundled arm stands in),
    /// an SRDF file that does not fit the bundled arm is not refused here: it is meant for the
    /// robot to come, and is checked against each description as it arrives (one it does not fit
    /// is refused). [`Pipeline::semantic_deferred`] says whether that is waiting.
    pub(crate) fn new_expecting_description(params: Params) -> Result<Pipeline, CheckerError> {
        let placeholder = params.robot_is_bundled();
        match Pipeline::new(params.clone()) {
            Err(CheckerError::Srdf(_)) if placeholder && !params.robot_semantic_file.is_empty() => {
                let file = params.robot_semantic_file.clone();
                let text = read_semantic_file(&file)?;
                let mut bare = params;
                bare.robot_semantic_file.clear();
                let mut checker = Checker::from_params(bare)?;
                checker.set_semantic_file_name(file.clone());
                let mut pipeline = Self::with_checker(checker, RobotSource::Files);
                pipeline.semantic = Some((text.into(), file));
                pipeline.semantic_deferred = true;
                Ok(pipeline)
            }
            other => other,
        }
    }

    /// Whether the parameters' SRDF waits for a `robot_description` it fits (see
    /// [`Pipeline::new_expecting_description`]): true until one has been applied with it.
    pub(crate) fn semantic_deferred(&self) -> bool {
        self.semantic_deferred && !matches!(self.source, RobotSource::Description { .. })
    }

    /// The checker in force (shared: a batch on other threads keeps the one it started with).
    pub fn checker(&self) -> &Arc<Checker> {
        &self.checker
    }

    /// The parameters in force.
    pub fn params(&self) -> &Params {
        self.checker.params()
    }

    /// Messages skipped so far, by cause.
    pub fn skipped(&self) -> &BTreeMap<SkipCause, u64> {
        &self.skipped
    }

    /// Counts skipped messages the front door decided on (undecodable payloads, stale states).
    pub(crate) fn count_skip(&mut self, cause: SkipCause, n: u64) {
        if n > 0 {
            *self.skipped.entry(cause).or_insert(0) += n;
        }
    }

    /// Warnings that are not skips (an unknown joint name, once per name), oldest first.
    pub fn take_warnings(&mut self) -> Vec<String> {
        std::mem::take(&mut self.warnings)
    }

    fn skip(&mut self, cause: SkipCause, message: String) -> Skip {
        self.count_skip(cause, 1);
        // A rejected state message breaks the trail: what the robot did in between is unknown,
        // so the next state is checked on its own. Another robot's `/tf` says nothing of ours.
        if cause != SkipCause::NotOurRobot {
            self.last_stamp = None;
        }
        Skip { cause, message }
    }

    /// A state made from an accepted message, marked as following the one before when a motion
    /// between them may be checked.
    fn accept(&mut self, stamp: Time, pose: StatePose) -> RobotState {
        let max_gap = (self.params().motion_max_gap * 1e9) as i64;
        let follows = self.last_stamp.is_some_and(|last| {
            let gap = stamp.as_nanos() - last.as_nanos();
            (0..=max_gap).contains(&gap)
        });
        self.last_stamp = Some(stamp);
        RobotState { stamp, pose, follows }
    }

    /// A `sensor_msgs/JointState` from the stream: the state to check, or why there is none.
    pub fn joint_state(&mut self, msg: &JointState) -> Result<RobotState, Skip> {
        let mut unknown = Vec::new();
        let missing = self.params().missing_joint;
        let result = self.joints.ingest(&self.checker, missing, &msg.name, &msg.position, &msg.velocity, &mut unknown);
        for name in unknown {
            if self.unknown_names.len() < MAX_UNKNOWN_NAMES && self.unknown_names.insert(name.clone()) {
                self.warnings.push(format!("'{name}' is not a joint of the robot model; ignored (warned once)"));
            }
        }
        match result {
            Ok(q) => Ok(self.accept(msg.header.stamp, StatePose::Joints(q))),
            Err(e) => {
                let cause = match e {
                    StateError::Lengths { .. } => SkipCause::Lengths,
                    StateError::NonFinite { .. } => SkipCause::NonFinite,
                    StateError::Duplicate(_) => SkipCause::DuplicateName,
                    StateError::NotOurRobot(_) => SkipCause::NotOurRobot,
                    StateError::Incomplete { .. } => SkipCause::Incomplete,
                    _ => SkipCause::MissingJoint,
                };
                Err(self.skip(cause, e.to_string()))
            }
        }
    }

    /// A `/tf_static` message: it only updates the TF tree.
    pub fn tf_static(&mut self, msg: &TfMessage) -> Result<(), Skip> {
        self.tf.update(msg).map_err(|r| self.tf_skip(r, "/tf_static"))
    }

    fn tf_skip(&mut self, r: TfRejection, topic: &str) -> Skip {
        let message = match r {
            TfRejection::NotRigid(f) => format!("{topic}: the transform of frame '{f}' is not a finite rigid transform"),
            TfRejection::TooManyFrames(f) => format!("{topic}: new frame '{f}' would pass {} frames", TfTree::MAX_FRAMES),
            TfRejection::Duplicate(f) => return self.skip(SkipCause::DuplicateName, format!("{topic}: frame '{f}' is given twice in one message")),
        };
        self.skip(SkipCause::BadTransform, message)
    }

    /// A `/tf` message: the robot's link poses in `world_frame` after it, or why there is no
    /// state. A message that names none of the robot's frames (with `frame_prefix`) updates the
    /// tree but is not a state of this robot.
    pub fn tf(&mut self, msg: &TfMessage) -> Result<RobotState, Skip> {
        self.tf.update(msg).map_err(|r| self.tf_skip(r, "/tf"))?;
        let checker = self.checker.clone();
        let (prefix, world) = (&checker.params().frame_prefix, &checker.params().world_frame);
        let robot = checker.robot();
        let ours =
            msg.transforms.iter().any(|t| t.child_frame_id.trim_start_matches('/').strip_prefix(prefix.as_str()).is_some_and(|l| robot.link(l).is_some()));
        if !ours {
            let first = msg.transforms.first().map_or("", |t| t.child_frame_id.as_str());
            return Err(self.skip(SkipCause::NotOurRobot, format!("/tf: frames unknown to the robot (e.g. '{first}', frame_prefix '{prefix}')")));
        }
        let mut world_poses = vec![None; robot.links.len()];
        for t in checker.targets() {
            let frame = format!("{prefix}{}", t.name);
            match self.tf.world_pose(&frame, world) {
                Some(p) => world_poses[t.link] = Some(p),
                None => return Err(self.skip(SkipCause::Unreachable, format!("/tf: frame '{frame}' does not reach world_frame '{world}' yet"))),
            }
        }
        let stamp = msg.transforms.iter().map(|t| t.header.stamp).max().unwrap_or_default();
        Ok(self.accept(stamp, StatePose::Links(world_poses)))
    }

    /// Checks a state. A state the checker cannot take (it cannot happen for states this
    /// pipeline made from the current robot) fails closed.
    pub fn check(&self, state: &RobotState) -> CheckedState {
        let result = match &state.pose {
            StatePose::Joints(q) => self.checker.check_positions(q),
            StatePose::Links(world) => self.checker.check_world_poses(world),
        };
        CheckedState { stamp: state.stamp, report: result.unwrap_or_else(|e| StateReport::failed(e.to_string())) }
    }

    /// Checks the motion from `from` to `to`, with nothing crossed unseen: the straight line in
    /// joint space between joint states; between link poses (`/tf`), each link along the straight
    /// line and the shortest rotation between its two poses.
    pub fn check_motion(&self, from: &RobotState, to: &RobotState) -> CheckedState {
        let report = match (&from.pose, &to.pose) {
            (StatePose::Joints(a), StatePose::Joints(b)) => self.checker.check_motion(a, b).report,
            (StatePose::Links(a), StatePose::Links(b)) => self.checker.check_world_motion(a, b).report,
            // Both ends come from one pose source; a mix cannot be interpolated.
            _ => StateReport { motion: true, ..StateReport::failed("a motion between a joint state and link poses cannot be checked") },
        };
        CheckedState { stamp: to.stamp, report }
    }

    /// The URDF text of the robot in force, for viewers that draw it: the `robot_description`
    /// received, else the file `--robot` or the parameters name (else the bundled arm's), read now.
    pub(crate) fn robot_urdf(&self) -> Result<String, crate::limits::InputFileError> {
        match &self.source {
            RobotSource::Description { urdf, .. } => Ok(urdf.to_string()),
            RobotSource::Files => crate::limits::read_regular_text(&self.params().robot_path(), "robot URDF", crate::limits::MAX_DESCRIPTION_BYTES),
        }
    }

    /// The states accepted since the last report, oldest first, as one report stamped with the
    /// newest. With `check_motion`, the polyline through them from the last state reported: a
    /// motion into every state that follows its predecessor, a discrete check of one that does
    /// not (the first state, the first after a rejected message or a swap of robot or
    /// parameters, a stamp that goes back or jumps past `motion_max_gap`); the first contact
    /// along the polyline is reported, its `fraction` counting each state as an equal step
    /// ((i + f) / n for step i of n). Without `check_motion`, the newest state alone, older
    /// ones counted `stale`. `None` for no states.
    pub(crate) fn check_path(&mut self, states: &[RobotState]) -> Option<CheckedState> {
        let newest = states.last()?;
        if !self.params().check_motion {
            self.count_skip(SkipCause::Stale, states.len() as u64 - 1);
            self.trail = Some(newest.clone());
            return Some(self.check(newest));
        }
        let started = std::time::Instant::now();
        let trail = self.trail.replace(newest.clone());
        let steps = states.len() as f64;
        let mut from = trail.as_ref();
        let mut any_motion = false;
        let mut last_report = None;
        for (i, state) in states.iter().enumerate() {
            let checked = match from.filter(|_| state.follows) {
                Some(f) => {
                    any_motion = true;
                    self.check_motion(f, state)
                }
                None => self.check(state),
            };
            from = Some(state);
            if checked.report.in_collision {
                let mut report = checked.report;
                if any_motion {
                    // A discrete hit is where step i ends.
                    let f = if report.motion { report.fraction.unwrap_or(0.0) } else { 1.0 };
                    report.fraction = Some((i as f64 + f) / steps);
                    report.motion = true;
                }
                report.check_seconds = started.elapsed().as_secs_f64();
                return Some(CheckedState { stamp: newest.stamp, report });
            }
            last_report = Some(checked.report);
        }
        let mut report = last_report.unwrap_or_default();
        report.motion = any_motion;
        report.fraction = None;
        report.check_seconds = started.elapsed().as_secs_f64();
        Some(CheckedState { stamp: newest.stamp, report })
    }

    /// A `check_states` request: every state on its own, every name a joint of the robot; one
    /// report per state, in order, a state that cannot be checked failing closed in its slot.
    /// Checked on all cores with the `parallel` feature.
    pub(crate) fn check_request(&self, states: &[JointState]) -> Vec<CollisionReport> {
        let pairs: Vec<(&[String], &[f64])> = states.iter().map(|s| (s.name.as_slice(), s.position.as_slice())).collect();
        let frame = &self.params().world_frame;
        self.checker
            .check_joints_batch(&pairs)
            .into_iter()
            .zip(states)
            .map(|(r, s)| {
                let report = r.unwrap_or_else(|e| StateReport::failed(e.to_string()));
                CheckedState { stamp: s.header.stamp, report }.message(frame)
            })
            .collect()
    }

    /// A new robot, environment or parameters: the planning scene's objects are put beside the
    /// environment again (an object that cannot be, say with an id that is now a robot link's,
    /// drops the scene's objects, warned).
    pub(super) fn replace(&mut self, checker: Checker) {
        let checker = if self.scene.is_empty() {
            checker
        } else {
            match self.scene.checker_on(&checker, &mut self.bodies) {
                Ok(with) => with,
                Err(e) => {
                    let (world, attached) = (self.scene.world.len(), self.scene.attached.len());
                    self.warnings.push(format!("the planning scene's {world} world and {attached} attached objects are dropped: {e}"));
                    self.scene = SceneState::default();
                    checker
                }
            }
        };
        self.swap(checker);
    }

    /// Puts `checker` in force.
    pub(super) fn swap(&mut self, checker: Checker) {
        let same_joints = checker.robot().joints.iter().map(|j| &j.name).eq(self.checker.robot().joints.iter().map(|j| &j.name));
        if !same_joints {
            self.joints = JointInput::new(&checker);
        }
        self.checker = Arc::new(checker);
        // The next state is checked on its own: the last one belongs to the old robot or
        // parameters.
        self.last_stamp = None;
        self.trail = None;
    }

    /// The position of joint `j` for a request that leaves it out (`check_trajectory`,
    /// `check_state_validity`): the merged state, else the `missing_joint` rule. `request` says
    /// where the joint was looked for, for the error. Under `last` a joint that moves a checked
    /// link and was never received leaves the pose unknown: checking it at 0 could call a
    /// colliding request free.
    /// The velocity joint `j` was last received with; 0 (at rest) when its last joint state gave
    /// none or it was never received.
    pub(crate) fn current_velocity(&self, j: usize) -> f64 {
        self.joints.velocities()[j].unwrap_or(0.0)
    }

    pub(crate) fn left_out_position(&self, j: usize, request: &str) -> Result<f64, String> {
        let joint = &self.checker.robot().joints[j];
        let missing = self.params().missing_joint;
        match self.joints.current()[j] {
            Some(v) => Ok(v),
            None if joint.is_actuated() && missing == MissingJoint::Reject => {
                Err(format!("joint '{}' is neither in {request} nor in a joint state received so far (missing_joint: reject)", joint.name))
            }
            None if missing == MissingJoint::Last && self.checker.moves_checked_link(j) => Err(format!(
                "joint '{}' is neither in {request} nor in a joint state received so far (missing_joint: last takes it from the joint states)",
                joint.name
            )),
            None => Ok(0.0),
        }
    }
}

impl std::fmt::Debug for Pipeline {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Pipeline").field("source", &self.source).field("skipped", &self.skipped).finish_non_exhaustive()
    }
}
