//! A `check_state_validity` request (`moveit_msgs/srv/GetStateValidity`), answered as
//! `move_group` answers it, for the collisions this node checks.
//!
//! Input policy:
//! - `robot_state.joint_state` is applied on top of the pipeline's current merged joint state
//!   whatever `is_diff` says (as `move_group` does): joints it names take its positions, the
//!   others keep what the joint state stream gave last; a joint never received follows
//!   `missing_joint` (`reject` refuses the request, otherwise 0). Every name must be a joint of
//!   the robot, once, with a finite position; `position` as long as `name`. Velocities and
//!   efforts are not used.
//! - `group_name`: the links the group's joints move, with their descendants; a contact is kept
//!   when at least one of its two bodies is in that set (for the environment, the robot link must
//!   be). Empty: the whole robot. A group the robot's SRDF does not define: the whole robot, with
//!   a warning.
//! - Joint limits do not affect `valid` (as in `move_group`'s service, which checks collisions
//!   and constraints only).
//!
//! The response has no text field, so a request the node cannot honour is answered `valid =
//! false` with no contacts, and the reason is handed back beside the response for the front door
//! to log and count: multi-DOF joints (the node cannot place them from a request), non-empty
//! constraints, a non-finite position, an unknown or repeated joint, lengths that differ, an
//! attached object that cannot be placed. Nothing in a request is silently ignored.
//! - `robot_state.attached_collision_objects` are attached at the request's state for this
//!   request only, on top of the node's attached objects, or in their place when
//!   `robot_state.is_diff` is false (as MoveIt's `robotStateMsgToRobotState` does); contacts of an
//!   attached object have `ROBOT_ATTACHED` body types.
//!
//! As for `check_trajectory`, the work is split so the node can check off its event loop:
//! [`Pipeline::validity_job`] validates and resolves (linear in the request; the hulls of the
//! objects a request attaches are built here, no cells) and
//! [`ValidityJob::run`], holding the checker it started with, runs on any thread.

use super::Pipeline;
use crate::checker::{Checker, ObjectType, ReportContact};
use crate::limits::name_list;
use crate::model::RobotModel;
use crate::msgs::moveit::{ContactInformation, GetStateValidityRequest, GetStateValidityResponse, BODY_ROBOT_ATTACHED, BODY_ROBOT_LINK, BODY_WORLD_OBJECT};
use crate::msgs::{Header, Time, Vector3};
use std::sync::Arc;

/// A validated request with a position for every joint and the links it covers: ready to run on
/// any thread.
#[derive(Clone)]
pub(crate) struct ValidityJob {
    checker: Arc<Checker>,
    /// The resolved state, or why the request is refused.
    plan: Result<Plan, String>,
    /// The stamp of the request's joint state (the contacts' header stamp).
    stamp: Time,
    /// A warning to log (an unknown group checked as the whole robot).
    warning: Option<String>,
}

impl std::fmt::Debug for ValidityJob {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ValidityJob").field("refused", &self.refused()).field("warning", &self.warning).finish_non_exhaustive()
    }
}

#[derive(Clone, Debug)]
struct Plan {
    /// Positions of every joint.
    q: Vec<f64>,
    /// Links covered, by link index; `None`: the whole robot.
    links: Option<Vec<bool>>,
}

impl Pipeline {
    /// Validates `req` and resolves it to a position for every joint and the links its group
    /// covers. Cheap (no cells; the hulls of attached objects); see [`ValidityJob::run`].
    pub(crate) fn validity_job(&self, req: &GetStateValidityRequest) -> ValidityJob {
        let (links, warning) = group_links(self.checker(), &req.group_name);
        let plan = refusal(self.checker().robot(), req).map_or_else(|| resolve(self, req).map(|q| Plan { q, links }), Err);
        let checker = match &plan {
            Ok(p) => self.request_checker(&req.robot_state, &p.q),
            Err(_) => Ok(self.checker().clone()),
        };
        match checker {
            Ok(checker) => ValidityJob { checker, plan, stamp: req.robot_state.joint_state.header.stamp, warning },
            Err(e) => ValidityJob { checker: self.checker().clone(), plan: Err(e), stamp: req.robot_state.joint_state.header.stamp, warning },
        }
    }

    /// A `check_state_validity` request answered on this thread: the response, and why the
    /// request could not be honoured (then `valid` is false and there are no contacts).
    pub(crate) fn check_validity(&self, req: &GetStateValidityRequest) -> (GetStateValidityResponse, Option<String>) {
        self.validity_job(req).run()
    }
}

/// What the node cannot honour in a request, before the joint state is looked at: multi-DOF
/// joints, constraints.
fn refusal(robot: &RobotModel, req: &GetStateValidityRequest) -> Option<String> {
    let state = &req.robot_state;
    let multi = &state.multi_dof_joint_state;
    if !multi.joint_names.is_empty() || !multi.transforms.is_empty() {
        let (known, unknown): (Vec<&String>, Vec<&String>) = multi.joint_names.iter().partition(|n| robot.joint(n).is_some());
        if !unknown.is_empty() {
            let quoted: Vec<String> = unknown.iter().map(|n| format!("'{n}'")).collect();
            let what = if unknown.len() == 1 { "is not a joint" } else { "are not joints" };
            return Some(format!("multi_dof_joint_state: {} {what} of the robot model", name_list(&quoted)));
        }
        let quoted: Vec<String> = known.iter().map(|n| format!("'{n}'")).collect();
        return Some(format!(
            "multi_dof_joint_state gives {} joint(s) ({}) and {} transform(s); the node cannot place multi-DOF joints from a request",
            multi.joint_names.len(),
            name_list(&quoted),
            multi.transforms.len()
        ));
    }
    let c = &req.constraints;
    if !c.is_empty() {
        return Some(format!(
            "constraints given ({} joint, {} position, {} orientation, {} visibility); the node checks collisions only",
            c.joint_constraints.len(),
            c.position_constraints.len(),
            c.orientation_constraints.len(),
            c.visibility_constraints.len()
        ));
    }
    None
}

/// The request's joint state on top of the current merged state.
fn resolve(pipeline: &Pipeline, req: &GetStateValidityRequest) -> Result<Vec<f64>, String> {
    let robot = pipeline.checker().robot();
    let js = &req.robot_state.joint_state;
    if js.name.len() != js.position.len() {
        return Err(format!("robot_state.joint_state has {} names but {} positions", js.name.len(), js.position.len()));
    }
    let mut given: Vec<Option<f64>> = vec![None; robot.joints.len()];
    let mut unknown = Vec::new();
    let mut unknown_count = 0usize;
    for (name, &value) in js.name.iter().zip(&js.position) {
        match robot.joint(name) {
            None => {
                unknown_count += 1;
                if unknown.len() < crate::limits::MAX_NAMES_IN_ERROR {
                    unknown.push(format!("'{name}'"));
                }
            }
            Some(_) if !value.is_finite() => return Err(format!("robot_state.joint_state: joint '{name}' has a non-finite position {value}")),
            Some(j) if given[j].is_some() => return Err(format!("robot_state.joint_state names joint '{name}' twice")),
            Some(j) => given[j] = Some(value),
        }
    }
    if unknown_count > 0 {
        let more = if unknown_count > unknown.len() { format!(" and {} more", unknown_count - unknown.len()) } else { String::new() };
        let what = if unknown_count == 1 { "is not a joint" } else { "are not joints" };
        return Err(format!("robot_state.joint_state: {}{more} {what} of the robot model", unknown.join(", ")));
    }
    given.iter().enumerate().map(|(j, given)| given.map_or_else(|| pipeline.left_out_position(j, "the request"), Ok)).collect()
}

/// The links a group covers (by link index), and a warning for a group the robot does not define.
/// Empty name: the whole robot, no warning.
fn group_links(checker: &Checker, name: &str) -> (Option<Vec<bool>>, Option<String>) {
    if name.is_empty() {
        return (None, None);
    }
    match group_joints(checker, name) {
        Some(joints) => (Some(moved_links(checker.robot(), &joints)), None),
        None => (None, Some(format!("group '{name}' is not a group of the robot's SRDF; checked as the whole robot"))),
    }
}

/// The joints of SRDF group `name` (by joint index), `None` for a group the robot lacks or
/// without an SRDF.
fn group_joints(checker: &Checker, name: &str) -> Option<Vec<usize>> {
    checker.self_pairs().srdf.as_ref()?.group_joints(name, checker.robot())
}

/// The links `joints` move: each joint's child link and all its descendants.
fn moved_links(robot: &RobotModel, joints: &[usize]) -> Vec<bool> {
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); robot.links.len()];
    for j in &robot.joints {
        children[j.parent].push(j.child);
    }
    let mut moved = vec![false; robot.links.len()];
    let mut stack: Vec<usize> = joints.iter().filter_map(|&j| robot.joints.get(j)).map(|j| j.child).collect();
    while let Some(l) = stack.pop() {
        if !std::mem::replace(&mut moved[l], true) {
            stack.extend(&children[l]);
        }
    }
    moved
}

/// The refused answer: not valid, no contacts.
fn refused() -> GetStateValidityResponse {
    GetStateValidityResponse::default()
}

impl ValidityJob {
    /// Why the request is refused before any check, if it is.
    pub(crate) fn refused(&self) -> Option<&str> {
        self.plan.as_ref().err().map(String::as_str)
    }

    /// A warning for the node's log (an unknown group checked as the whole robot).
    #[cfg(feature = "ros")]
    pub(crate) fn warning(&self) -> Option<&str> {
        self.warning.as_deref()
    }

    /// Checks the state (discrete): the response, and why the request could not be honoured
    /// (refused, or the check failed).
    pub(crate) fn run(&self) -> (GetStateValidityResponse, Option<String>) {
        let plan = match &self.plan {
            Ok(plan) => plan,
            Err(e) => return (refused(), Some(e.clone())),
        };
        let report = match self.checker.check_positions(&plan.q) {
            Ok(r) if r.error.is_empty() => r,
            Ok(r) => return (refused(), Some(format!("the state could not be checked: {}", r.error))),
            Err(e) => return (refused(), Some(format!("the state could not be checked: {e}"))),
        };
        let robot = self.checker.robot();
        // A body of the robot is covered when its link is (an attached object's: the link it is on).
        let covered = |name: &str, kind: ObjectType| {
            let link = match kind {
                ObjectType::RobotLink => robot.link(name),
                ObjectType::AttachedObject => self.checker.targets().iter().rev().find(|t| t.name == name).map(|t| t.link),
                ObjectType::Environment => None,
            };
            match (&plan.links, link) {
                (None, _) => true,
                (Some(set), Some(l)) => set[l],
                (Some(_), None) => false,
            }
        };
        let frame = &self.checker.params().world_frame;
        let contacts: Vec<ContactInformation> = report
            .contacts
            .iter()
            .filter(|c| covered(&c.link_name, c.link_type) || covered(&c.object_name, c.object_type))
            .map(|c| contact(c, frame, self.stamp))
            .collect();
        (GetStateValidityResponse { valid: contacts.is_empty(), contacts, ..Default::default() }, None)
    }
}

/// A body type of a report as `ContactInformation`'s.
fn body_type(kind: ObjectType) -> u32 {
    match kind {
        ObjectType::RobotLink => BODY_ROBOT_LINK,
        ObjectType::AttachedObject => BODY_ROBOT_ATTACHED,
        ObjectType::Environment => BODY_WORLD_OBJECT,
    }
}

/// A report contact as `moveit_msgs/ContactInformation`: body 1 the robot link, body 2 the
/// environment object (or the other link), `normal` the direction that pushes body 1 out,
/// `depth` how far it reaches in, all in `world_frame`.
fn contact(c: &ReportContact, frame: &str, stamp: Time) -> ContactInformation {
    let v = |a: [f64; 3]| Vector3 { x: a[0], y: a[1], z: a[2] };
    ContactInformation {
        header: Header { stamp, frame_id: frame.to_owned() },
        // Every check here computes the point; NaN would mark one that was not.
        position: v(c.position.unwrap_or([f64::NAN; 3])),
        normal: v(c.normal),
        depth: c.depth,
        contact_body_1: c.link_name.clone(),
        body_type_1: body_type(c.link_type),
        contact_body_2: c.object_name.clone(),
        body_type_2: body_type(c.object_type),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{MissingJoint, Params};
    use crate::msgs::moveit::JointConstraint;
    use crate::msgs::planning_scene::{AttachedCollisionObject, RobotStateMsg};
    use crate::msgs::{JointState, Transform};

    /// The arm with nothing received yet.
    fn fresh(missing: MissingJoint) -> Pipeline {
        Pipeline::new(Params { missing_joint: missing, ..Params::default() }).unwrap()
    }

    /// The arm once its whole state at 0 was received, as a running node has it.
    fn arm(missing: MissingJoint) -> Pipeline {
        let mut p = fresh(missing);
        let name: Vec<String> = p.checker().robot().joints.iter().filter(|j| j.is_actuated()).map(|j| j.name.clone()).collect();
        let position = vec![0.0; name.len()];
        let _ = p.joint_state(&JointState { name, position, ..Default::default() }).unwrap();
        p
    }

    fn request(names: &[&str], positions: &[f64]) -> GetStateValidityRequest {
        GetStateValidityRequest {
            robot_state: RobotStateMsg {
                joint_state: JointState { name: names.iter().map(|s| s.to_string()).collect(), position: positions.to_vec(), ..Default::default() },
                ..Default::default()
            },
            ..Default::default()
        }
    }

    #[test]
    fn requests_the_node_cannot_honour_are_not_valid_with_a_reason() {
        let p = arm(MissingJoint::Last);
        let mut attached = request(&["elbow_joint"], &[0.1]);
        attached.robot_state.attached_collision_objects.push(AttachedCollisionObject { link_name: "tool0".into(), ..Default::default() });
        let mut constrained = request(&["elbow_joint"], &[0.1]);
        constrained.constraints.joint_constraints.push(JointConstraint { joint_name: "elbow_joint".into(), ..Default::default() });
        let mut multi = request(&[], &[]);
        multi.robot_state.multi_dof_joint_state.joint_names.push("elbow_joint".into());
        multi.robot_state.multi_dof_joint_state.transforms.push(Transform::default());
        let mut multi_unknown = multi.clone();
        multi_unknown.robot_state.multi_dof_joint_state.joint_names[0] = "virtual_joint".into();
        let cases = [
            (attached, "attached collision object '' on link 'tool0': id: an object to attach needs an id"),
            (constrained, "1 joint, 0 position"),
            (multi, "cannot place multi-DOF joints"),
            (multi_unknown, "'virtual_joint' is not a joint"),
            (request(&["elbow_joint"], &[f64::NAN]), "non-finite position NaN"),
            (request(&["elbow_joint", "no_such_joint"], &[0.1, 0.0]), "'no_such_joint' is not a joint"),
            (request(&["elbow_joint", "elbow_joint"], &[0.1, 0.2]), "'elbow_joint' twice"),
            (request(&["elbow_joint"], &[]), "1 names but 0 positions"),
        ];
        for (req, cause) in cases {
            let (r, why) = p.check_validity(&req);
            assert!(!r.valid && r.contacts.is_empty() && r.cost_sources.is_empty() && r.constraint_result.is_empty(), "{cause}: {r:?}");
            let why = why.unwrap_or_default();
            assert!(why.contains(cause) && !why.contains('\n'), "{cause}: {why}");
        }
        // A name alone constrains nothing.
        let mut named = request(&["elbow_joint"], &[0.1]);
        named.constraints.name = "none".into();
        assert_eq!(p.check_validity(&named).1, None);
    }

    #[test]
    fn the_answer_agrees_with_the_discrete_check_and_ignores_limits() {
        let p = arm(MissingJoint::Last);
        let c = p.checker();
        let names = ["shoulder_lift_joint", "elbow_joint"];
        for (q, limits) in [([0.0, 0.0], false), ([1.2, 0.3], false), ([0.0, 40.0], true)] {
            let (r, why) = p.check_validity(&request(&names, &q));
            assert_eq!(why, None);
            let names: Vec<String> = names.iter().map(|s| s.to_string()).collect();
            let want = c.check_joints(&names, &q).unwrap();
            assert_eq!(!want.out_of_limits.is_empty(), limits, "the case's limits");
            assert_eq!(r.valid, !want.in_collision, "{q:?}");
            assert_eq!(r.contacts.len(), want.contacts.len());
            for (got, want) in r.contacts.iter().zip(&want.contacts) {
                assert_eq!(
                    (got.contact_body_1.as_str(), got.contact_body_2.as_str(), got.depth),
                    (want.link_name.as_str(), want.object_name.as_str(), want.depth)
                );
                assert_eq!((got.body_type_1, got.body_type_2), (BODY_ROBOT_LINK, BODY_WORLD_OBJECT));
                assert_eq!(got.header.frame_id, c.params().world_frame);
                assert_eq!([got.normal.x, got.normal.y, got.normal.z], want.normal);
            }
        }
        assert!(!p.check_validity(&request(&names, &[1.2, 0.3])).0.valid, "the colliding case must collide for this test");
    }

    #[test]
    fn the_request_applies_on_top_of_the_merged_state_whatever_is_diff_says() {
        // Nothing received under last: a joint that moves a checked link, left out, is refused.
        let (r, why) = fresh(MissingJoint::Last).check_validity(&request(&["elbow_joint"], &[0.3]));
        assert!(!r.valid && why.as_deref().unwrap_or_default().contains("missing_joint: last"), "{why:?}");
        let mut p = fresh(MissingJoint::Reject);
        // Nothing received: a joint the request leaves out is refused under reject.
        let (r, why) = p.check_validity(&request(&["elbow_joint"], &[0.3]));
        assert!(!r.valid && why.unwrap_or_default().contains("missing_joint: reject"));
        let names: Vec<String> = p.checker().robot().joints.iter().filter(|j| j.is_actuated()).map(|j| j.name.clone()).collect();
        let values: Vec<f64> = names.iter().map(|n| if n == "shoulder_lift_joint" { 0.7 } else { 0.0 }).collect();
        let _ = p.joint_state(&JointState { name: names, position: values, ..Default::default() }).unwrap();
        let (lift, elbow) = (p.checker().robot().joint("shoulder_lift_joint").unwrap(), p.checker().robot().joint("elbow_joint").unwrap());
        for is_diff in [false, true] {
            let mut req = request(&["elbow_joint"], &[0.3]);
            req.robot_state.is_diff = is_diff;
            let job = p.validity_job(&req);
            let q = &job.plan.as_ref().unwrap().q;
            assert_eq!((q[lift], q[elbow]), (0.7, 0.3), "is_diff {is_diff}");
        }
    }

    #[test]
    fn groups_cover_the_links_their_joints_move_and_unknown_ones_warn() {
        let p = arm(MissingJoint::Last);
        let robot = p.checker().robot();
        let elbow = robot.joint("elbow_joint").unwrap();
        let moved = moved_links(robot, &[elbow]);
        // The elbow moves its child and everything below it, nothing above.
        let child = robot.joints[elbow].child;
        assert!(moved[child] && !moved[robot.root] && !moved[robot.joints[elbow].parent]);
        for j in &robot.joints {
            if moved[j.parent] {
                assert!(moved[j.child], "{} is below the elbow", robot.links[j.child].name);
            }
        }
        // A group of the SRDF: the contacts of the links it moves, no warning.
        let mut with_srdf = arm(MissingJoint::Last);
        let srdf = r#"<robot name="tc_arm"><group name="forearm"><joint name="elbow_joint"/></group></robot>"#;
        with_srdf.set_robot_semantic(srdf, "test SRDF").unwrap();
        let robot = with_srdf.checker().robot();
        let (mut kept, mut dropped) = (0, 0);
        for q in [[1.2, 0.3], [0.0, 0.0], [0.6, 1.5], [-0.4, 2.2], [1.6, 0.0], [0.9, 1.0]] {
            let mut req = request(&["shoulder_lift_joint", "elbow_joint"], &q);
            let (whole, _) = with_srdf.check_validity(&req);
            req.group_name = "forearm".into();
            let job = with_srdf.validity_job(&req);
            assert_eq!(job.warning(), None);
            let (group, why) = job.run();
            assert_eq!(why, None);
            let want: Vec<&ContactInformation> = whole
                .contacts
                .iter()
                .filter(|c| {
                    moved[robot.link(&c.contact_body_1).unwrap()]
                        || (c.body_type_2 == BODY_ROBOT_LINK && robot.link(&c.contact_body_2).is_some_and(|l| moved[l]))
                })
                .collect();
            assert_eq!(group.contacts.iter().collect::<Vec<_>>(), want, "{q:?}");
            assert_eq!(group.valid, want.is_empty());
            kept += want.len();
            dropped += whole.contacts.len() - want.len();
        }
        assert!(kept > 0 && dropped > 0, "the cases must show contacts kept ({kept}) and dropped ({dropped}) by the group");
        let job = p.validity_job(&GetStateValidityRequest { group_name: "no_such_group".into(), ..Default::default() });
        assert!(job.warning().unwrap_or_default().contains("'no_such_group'"));
        assert!(job.plan.as_ref().unwrap().links.is_none(), "an unknown group is the whole robot");
        assert_eq!(p.validity_job(&GetStateValidityRequest::default()).warning(), None);
    }
}
