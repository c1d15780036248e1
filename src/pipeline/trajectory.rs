//! A `check_trajectory` request: a `trajectory_msgs/JointTrajectory` checked segment by segment
//! with the guaranteed motion check, the first contact given as a segment, a fraction along it
//! and a time from the trajectory's start.
//!
//! Input policy, the same for every door: every name must be a joint of the robot and appear
//! once; every point gives one finite position per name; `time_from_start` increases strictly.
//! Joints the trajectory does not name keep the pipeline's current merged state (what the joint
//! state stream gave last); one never received follows `missing_joint` (`reject` refuses the
//! request, otherwise 0). A refused request is never reported free: `valid` is false, `segment`
//! -1 and `error` one line saying why.
//!
//! Segment `i` is the straight line in joint space from point `i` to point `i + 1`
//! ([`Checker::check_motion`]): "free" is certain along that line. A controller that splines
//! between the points (through their velocities and accelerations) can leave it; the guarantee
//! covers linear interpolation only. Segments are checked in order and the first that is not
//! free ends the walk, so the answer for segment `i` equals `check --states FILE --motion` on the
//! same waypoints, whose line `i + 2` is the motion from point `i` to point `i + 1`.
//!
//! The work is split in two so that the node can check off its event loop: [`Pipeline::trajectory_job`]
//! validates and resolves the positions against the current state (linear in the request's size),
//! and [`TrajectoryJob::run`], which holds the checker it started with, can run on any thread.

use super::Pipeline;
use crate::checker::{Checker, StateReport};
use crate::limits::MAX_NAMES_IN_ERROR;
use crate::msgs::{CheckTrajectoryResponse, DurationMsg, JointTrajectory, Time, MAX_TRAJECTORY_ENTRIES};
use std::sync::Arc;

/// Points a trajectory may have (the decoder refuses longer sequences already).
pub(crate) const MAX_TRAJECTORY_POINTS: usize = MAX_TRAJECTORY_ENTRIES;

use crate::limits::MAX_TRAJECTORY_SUBINTERVALS;

/// Names a trajectory may give (more than any robot has joints; the decoder refuses longer lists
/// already).
pub(crate) const MAX_TRAJECTORY_NAMES: usize = MAX_TRAJECTORY_ENTRIES;

/// A validated trajectory with the positions of every joint at every point, and the checker to
/// walk it with: ready to run on any thread.
#[derive(Clone)]
pub struct TrajectoryJob {
    checker: Arc<Checker>,
    /// The waypoints (every joint), or why the request is refused.
    plan: Result<Plan, String>,
}

impl std::fmt::Debug for TrajectoryJob {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("TrajectoryJob").field("points", &self.points()).field("refused", &self.refused()).finish_non_exhaustive()
    }
}

#[derive(Clone, Debug)]
struct Plan {
    /// Positions of every joint at every point.
    q: Vec<Vec<f64>>,
    /// `time_from_start` of every point, nanoseconds.
    t: Vec<i64>,
}

impl Pipeline {
    /// Validates `trajectory` and resolves every point to positions of every joint, joints it does
    /// not name from the current merged state. Cheap (no geometry); see [`TrajectoryJob::run`].
    pub(crate) fn trajectory_job(&self, trajectory: &JointTrajectory) -> TrajectoryJob {
        let plan = resolve(self, trajectory);
        TrajectoryJob { checker: self.checker().clone(), plan }
    }

    /// A `check_trajectory` request answered on this thread: validated and resolved against the
    /// current merged state, then walked segment by segment with the motion check, as the node's
    /// worker walks it.
    pub fn check_trajectory(&self, trajectory: &JointTrajectory) -> CheckTrajectoryResponse {
        self.trajectory_job(trajectory).run()
    }
}

/// The nanoseconds of a `builtin_interfaces/Duration` (`nanosec` past 1e9 adds up, as rclcpp's
/// conversion does).
fn duration_nanos(d: &DurationMsg) -> i64 {
    d.sec as i64 * 1_000_000_000 + d.nanosec as i64
}

fn resolve(pipeline: &Pipeline, trajectory: &JointTrajectory) -> Result<Plan, String> {
    let robot = pipeline.checker().robot();
    let (names, points) = (&trajectory.joint_names, &trajectory.points);
    if points.is_empty() {
        return Err("the trajectory has no points".into());
    }
    if points.len() > MAX_TRAJECTORY_POINTS {
        return Err(format!("the trajectory has {} points; at most {MAX_TRAJECTORY_POINTS} allowed", points.len()));
    }
    if names.len() > MAX_TRAJECTORY_NAMES {
        return Err(format!("the trajectory names {} joints; at most {MAX_TRAJECTORY_NAMES} allowed", names.len()));
    }
    let index = joint_indices(robot, names)?;
    let mut seen = vec![false; robot.joints.len()];
    index.iter().for_each(|&j| seen[j] = true);
    let base = left_out_joints(pipeline, &seen)?;
    let mut q = Vec::with_capacity(points.len());
    let mut t = Vec::with_capacity(points.len());
    for (k, point) in points.iter().enumerate() {
        if point.positions.len() != names.len() {
            return Err(format!("point {k} has {} positions for {} joint_names", point.positions.len(), names.len()));
        }
        let mut qk = base.clone();
        for ((&j, &v), name) in index.iter().zip(&point.positions).zip(names) {
            if !v.is_finite() {
                return Err(format!("point {k}: joint '{name}' has a non-finite position {v}"));
            }
            qk[j] = v;
        }
        let tk = duration_nanos(&point.time_from_start);
        if let Some(&before) = t.last() {
            if tk <= before {
                return Err(format!(
                    "point {k}: time_from_start {} s is not after point {}'s {} s (it must increase strictly)",
                    tk as f64 * 1e-9,
                    k - 1,
                    before as f64 * 1e-9
                ));
            }
        }
        q.push(qk);
        t.push(tk);
    }
    Ok(Plan { q, t })
}

/// The joint index of every name; unknown and repeated names refused (a few unknown ones quoted,
/// the rest counted).
fn joint_indices(robot: &crate::model::RobotModel, names: &[String]) -> Result<Vec<usize>, String> {
    let mut index = Vec::with_capacity(names.len());
    let mut seen = vec![false; robot.joints.len()];
    let (mut unknown, mut unknown_count): (Vec<String>, usize) = (Vec::new(), 0);
    for name in names {
        match robot.joint(name) {
            Some(j) if seen[j] => return Err(format!("joint_names gives joint '{name}' twice")),
            Some(j) => {
                seen[j] = true;
                index.push(j);
            }
            None => {
                unknown_count += 1;
                if unknown.len() < MAX_NAMES_IN_ERROR {
                    unknown.push(format!("'{name}'"));
                }
            }
        }
    }
    if unknown_count > 0 {
        let more = if unknown_count > unknown.len() { format!(" and {} more", unknown_count - unknown.len()) } else { String::new() };
        let what = if unknown_count == 1 { "is not a joint" } else { "are not joints" };
        return Err(format!("joint_names: {}{more} {what} of the robot model", unknown.join(", ")));
    }
    Ok(index)
}

/// The positions of the joints a trajectory leaves out (`named[j]` false): the current merged
/// state, else the missing_joint rule.
fn left_out_joints(pipeline: &Pipeline, named: &[bool]) -> Result<Vec<f64>, String> {
    named.iter().enumerate().map(|(j, named)| if *named { Ok(0.0) } else { pipeline.left_out_position(j, "joint_names") }).collect()
}

/// `t0 + fraction (t1 - t0)` rounded down to the nanosecond (never later than the contact), as a
/// `Duration` with `nanosec` in [0, 1e9).
fn time_at(t0: i64, t1: i64, fraction: f64) -> DurationMsg {
    let ns = t0 + ((t1 - t0) as f64 * fraction.clamp(0.0, 1.0)).floor() as i64;
    let t = Time::from_nanos(ns);
    DurationMsg { sec: t.sec, nanosec: t.nanosec }
}

impl TrajectoryJob {
    /// Whether the request was refused before any check (then [`TrajectoryJob::run`] is
    /// immediate).
    pub fn refused(&self) -> Option<&str> {
        self.plan.as_ref().err().map(String::as_str)
    }

    /// Points in the trajectory (0 for a refused request).
    pub fn points(&self) -> usize {
        self.plan.as_ref().map_or(0, |p| p.q.len())
    }

    /// Walks the segments in order with the motion check; the first that is not free ends the
    /// walk, and so does a spent [`MAX_TRAJECTORY_SUBINTERVALS`] budget (failing closed at the
    /// first segment not checked). A single point is checked as one state.
    pub fn run(&self) -> CheckTrajectoryResponse {
        self.run_with_budget(MAX_TRAJECTORY_SUBINTERVALS)
    }

    fn run_with_budget(&self, budget: u64) -> CheckTrajectoryResponse {
        let plan = match &self.plan {
            Ok(plan) => plan,
            Err(e) => return refused(e.clone()),
        };
        let frame = &self.checker.params().world_frame;
        let answer = |segment: usize, report: StateReport, fraction: f64, t: DurationMsg| {
            let message = super::report_message(&report, Time::default(), frame);
            CheckTrajectoryResponse {
                valid: false,
                segment: segment as i32,
                fraction,
                time_from_start: t,
                contacts: message.contacts,
                error: if report.error.is_empty() { String::new() } else { format!("segment {segment}: {}", report.error) },
            }
        };
        if let [q] = plan.q.as_slice() {
            let report = self.checker.check_positions(q).unwrap_or_else(|e| StateReport::failed(e.to_string()));
            if report.in_collision {
                let (fraction, t) = if report.error.is_empty() { (0.0, time_at(plan.t[0], plan.t[0], 0.0)) } else { (-1.0, DurationMsg::default()) };
                return answer(0, report, fraction, t);
            }
            return free();
        }
        let mut spent = 0u64;
        for (i, pair) in plan.q.windows(2).enumerate() {
            if spent >= budget {
                let error = format!("the motion checks spent the {budget} sub-intervals one request may use; segments {i} to {} not checked", plan.q.len() - 2);
                return answer(i, StateReport::failed(error), -1.0, DurationMsg::default());
            }
            let r = self.checker.check_motion(&pair[0], &pair[1]);
            spent += r.subintervals;
            if !r.report.in_collision {
                continue;
            }
            return match r.fraction.filter(|_| r.report.error.is_empty()) {
                Some(f) => answer(i, r.report, f, time_at(plan.t[i], plan.t[i + 1], f)),
                None => answer(i, r.report, -1.0, DurationMsg::default()),
            };
        }
        free()
    }
}

fn free() -> CheckTrajectoryResponse {
    CheckTrajectoryResponse { valid: true, segment: -1, fraction: -1.0, ..Default::default() }
}

fn refused(error: String) -> CheckTrajectoryResponse {
    CheckTrajectoryResponse { valid: false, segment: -1, fraction: -1.0, error, ..Default::default() }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{MissingJoint, Params};
    use crate::msgs::{JointState, JointTrajectoryPoint};

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

    fn point(positions: &[f64], sec: i32, nanosec: u32) -> JointTrajectoryPoint {
        JointTrajectoryPoint { positions: positions.to_vec(), time_from_start: DurationMsg { sec, nanosec }, ..Default::default() }
    }

    fn trajectory(names: &[&str], points: Vec<JointTrajectoryPoint>) -> JointTrajectory {
        JointTrajectory { joint_names: names.iter().map(|s| s.to_string()).collect(), points, ..Default::default() }
    }

    #[test]
    fn bad_requests_are_refused_with_one_line() {
        let p = arm(MissingJoint::Last);
        let cases = [
            (trajectory(&["elbow_joint"], vec![]), "no points"),
            (trajectory(&["elbow_joint", "wrist_1_joint"], vec![point(&[0.1, 0.2], 0, 0), point(&[0.1], 1, 0)]), "point 1 has 1 positions for 2"),
            (trajectory(&["elbow_joint"], vec![point(&[0.1], 1, 0), point(&[0.2], 1, 0)]), "must increase strictly"),
            (trajectory(&["elbow_joint"], vec![point(&[0.1], 1, 0), point(&[0.2], 0, 999_999_999)]), "must increase strictly"),
            (trajectory(&["elbow_joint"], vec![point(&[0.1], 0, 0), point(&[f64::NAN], 1, 0)]), "non-finite position NaN"),
            (trajectory(&["elbow_joint"], vec![point(&[f64::INFINITY], 0, 0)]), "non-finite position inf"),
            (trajectory(&["elbow_joint", "no_such_joint"], vec![point(&[0.1, 0.0], 0, 0)]), "'no_such_joint' is not a joint"),
            (trajectory(&["elbow_joint", "elbow_joint"], vec![point(&[0.1, 0.0], 0, 0)]), "'elbow_joint' twice"),
        ];
        for (t, cause) in cases {
            let r = p.check_trajectory(&t);
            assert!(!r.valid && r.segment == -1 && r.contacts.is_empty(), "{cause}: {r:?}");
            assert!(r.error.contains(cause) && !r.error.contains('\n'), "{cause}: {}", r.error);
        }
    }

    #[test]
    fn joints_left_out_keep_the_merged_state_or_follow_missing_joint() {
        let names: Vec<String> = arm(MissingJoint::Last).checker().robot().joints.iter().filter(|j| j.is_actuated()).map(|j| j.name.clone()).collect();
        let t = trajectory(&["elbow_joint"], vec![point(&[0.3], 0, 0), point(&[0.4], 1, 0)]);
        // reject: nothing received yet, the request is refused naming a joint it lacks.
        let mut p = fresh(MissingJoint::Reject);
        let r = p.check_trajectory(&t);
        assert!(!r.valid && r.error.contains("missing_joint: reject"), "{r:?}");
        // Once a full state arrived, the same request is checked, from that state.
        let lift = p.checker().robot().joint("shoulder_lift_joint").unwrap();
        let values: Vec<f64> = names.iter().map(|n| if n == "shoulder_lift_joint" { 0.7 } else { 0.0 }).collect();
        let _ = p.joint_state(&JointState { name: names.clone(), position: values, ..Default::default() }).unwrap();
        let job = p.trajectory_job(&t);
        assert_eq!(job.refused(), None);
        let plan = job.plan.as_ref().unwrap();
        let elbow = p.checker().robot().joint("elbow_joint").unwrap();
        assert_eq!((plan.q[0][lift], plan.q[1][lift], plan.q[0][elbow], plan.q[1][elbow]), (0.7, 0.7, 0.3, 0.4));
        // last: a joint that moves a checked link, never received, leaves the pose unknown.
        let r = fresh(MissingJoint::Last).check_trajectory(&t);
        assert!(!r.valid && r.segment == -1 && r.error.contains("'shoulder_pan_joint' is neither") && r.error.contains("missing_joint: last"), "{r:?}");
        // zero: it is 0.
        let job = fresh(MissingJoint::Zero).trajectory_job(&t);
        assert_eq!(job.plan.as_ref().unwrap().q[1][lift], 0.0);
    }

    const PAN_LIFT_ELBOW: [&str; 3] = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint"];

    /// Two nearby poses (pan, lift, elbow; the other joints at 0) whose motion is free both ways,
    /// found on a small grid so that the tests do not hang on one pose staying free.
    fn free_pair(p: &Pipeline) -> ([f64; 3], [f64; 3]) {
        let grid = [0.0, 0.5, -0.5, 1.0, -1.0, 1.5, 2.0, 3.0];
        for pan in grid {
            for lift in [-0.3, 0.0, -0.6, 0.3] {
                for elbow in [0.6, 0.3, 1.0, -0.5] {
                    let (a, b) = ([pan, lift, elbow], [pan + 0.1, lift + 0.1, elbow + 0.1]);
                    let t = trajectory(&PAN_LIFT_ELBOW, vec![point(&a, 0, 0), point(&b, 1, 0), point(&a, 2, 0)]);
                    if p.check_trajectory(&t).valid {
                        return (a, b);
                    }
                }
            }
        }
        panic!("no free pair of poses on the grid");
    }

    #[test]
    fn the_answer_is_the_first_motion_check_that_fails() {
        let p = arm(MissingJoint::Last);
        let c = p.checker();
        let names = PAN_LIFT_ELBOW;
        // Free, then free, then into the guard (as in the motion check's own test).
        let (a, b) = free_pair(&p);
        let t = trajectory(&names, vec![point(&a, 1, 0), point(&b, 2, 0), point(&a, 3, 0), point(&[0.0, 1.2, 0.3], 5, 0)]);
        let r = p.check_trajectory(&t);
        let job = p.trajectory_job(&t);
        let q = &job.plan.as_ref().unwrap().q;
        for (i, pair) in q.windows(2).enumerate().take(2) {
            assert!(!c.check_motion(&pair[0], &pair[1]).report.in_collision, "segment {i} must be free for this test");
        }
        let m = c.check_motion(&q[2], &q[3]);
        assert!(m.report.in_collision, "segment 2 must collide for this test");
        assert!(!r.valid && r.error.is_empty(), "{r:?}");
        assert_eq!((r.segment, r.fraction), (2, m.fraction.unwrap()));
        let want_ns = 3_000_000_000 + (2e9 * m.fraction.unwrap()).floor() as i64;
        assert_eq!(r.time_from_start.sec as i64 * 1_000_000_000 + r.time_from_start.nanosec as i64, want_ns);
        assert_eq!(r.contacts.len(), m.report.contacts.len());
        assert!(!r.contacts.is_empty());
        // The first two segments alone are free.
        let mut free_part = t.clone();
        free_part.points.truncate(3);
        let r = p.check_trajectory(&free_part);
        assert_eq!((r.valid, r.segment, r.fraction, r.error.as_str()), (true, -1, -1.0, ""));
        // One point: a state; in collision at segment 0, fraction 0, its own time.
        let one = trajectory(&names, vec![point(&[0.0, 1.2, 0.3], 4, 5)]);
        let r = p.check_trajectory(&one);
        assert_eq!((r.valid, r.segment, r.fraction, r.time_from_start), (false, 0, 0.0, DurationMsg { sec: 4, nanosec: 5 }));
    }

    #[test]
    fn a_spent_budget_fails_closed_at_the_first_segment_not_checked() {
        let p = arm(MissingJoint::Last);
        let (a, b) = free_pair(&p);
        let t = trajectory(&PAN_LIFT_ELBOW, (0..6).map(|k| point(if k % 2 == 0 { &a } else { &b }, k, 0)).collect());
        let job = p.trajectory_job(&t);
        let free = job.run();
        assert!(free.valid, "{free:?}");
        // What each segment costs, and a budget spent after the second.
        let q = &job.plan.as_ref().unwrap().q;
        let cost: Vec<u64> = q.windows(2).map(|w| p.checker().check_motion(&w[0], &w[1]).subintervals).collect();
        let r = job.run_with_budget(cost[0] + cost[1]);
        assert_eq!((r.valid, r.segment, r.fraction), (false, 2, -1.0), "{r:?}");
        assert!(r.error.starts_with("segment 2: ") && r.error.contains("segments 2 to 4 not checked"), "{}", r.error);
        assert_eq!(job.run_with_budget(cost.iter().sum::<u64>()), free, "the whole budget checks everything");
    }

    #[test]
    fn time_at_rounds_down_and_normalises() {
        assert_eq!(time_at(1_000_000_000, 3_000_000_000, 0.25), DurationMsg { sec: 1, nanosec: 500_000_000 });
        assert_eq!(time_at(-1_000_000_000, 0, 0.5), DurationMsg { sec: -1, nanosec: 500_000_000 });
        assert_eq!(time_at(0, 3, 0.5), DurationMsg { sec: 0, nanosec: 1 });
    }
}
