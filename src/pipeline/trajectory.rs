//! A `check_trajectory` request: a `trajectory_msgs/JointTrajectory` checked as the robot would
//! execute it (`trajectory_plan`: the controller's splines, the approach from the current state,
//! the path tolerance's tube), segment by segment with the guaranteed motion check, the first
//! contact given as a segment, a fraction along it and a time from the trajectory's start.
//!
//! Input policy, the same for every door: every name must be a joint of the robot and appear
//! once; every point gives one finite position per name (and velocities and accelerations
//! either not at all or one finite value per name); `time_from_start` increases strictly.
//! Joints the trajectory does not name keep the pipeline's current merged state (what the joint
//! state stream gave last); one never received follows `missing_joint` (`reject` refuses the
//! request, otherwise 0). A refused request is never reported free: `valid` is false, `segment`
//! -1 and `error` one line saying why.
//!
//! With `interpolation: linear`, segment `i` is the straight line in joint space from point `i`
//! to point `i + 1` ([`Checker::check_motion`]) and there is no approach: the answer for segment
//! `i` then equals `check --states FILE --motion` on the same waypoints, whose line `i + 2` is the
//! motion from point `i` to point `i + 1`. Segments are checked in order and the first that is
//! not free ends the walk.
//!
//! The work is split in two so that the node can check off its event loop: [`Pipeline::trajectory_job`]
//! validates and resolves the positions against the current state (linear in the request's size),
//! and [`TrajectoryJob::run`], which holds the checker it started with, can run on any thread.

use super::trajectory_plan::{resolve, Interpolation, Plan};
use super::Pipeline;
use crate::checker::{Checker, MotionReport, StateReport};
use crate::msgs::{CheckTrajectoryRequest, CheckTrajectoryResponse, DurationMsg, Time};
use std::sync::Arc;

use crate::limits::MAX_TRAJECTORY_SUBINTERVALS;

/// The `segment` of the approach from the current state to the first point.
pub const APPROACH_SEGMENT: i32 = -2;

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

impl Pipeline {
    /// Validates `request` and resolves every point to positions of every joint, joints it does
    /// not name from the current merged state (and the approach from the current state). Cheap
    /// (no geometry); see [`TrajectoryJob::run`].
    pub(crate) fn trajectory_job(&self, request: &CheckTrajectoryRequest) -> TrajectoryJob {
        let plan = resolve(self, request);
        TrajectoryJob { checker: self.checker().clone(), plan }
    }

    /// A `check_trajectory` request answered on this thread: validated and resolved against the
    /// current merged state, then walked segment by segment with the motion check, as the node's
    /// worker walks it.
    pub fn check_trajectory(&self, request: &CheckTrajectoryRequest) -> CheckTrajectoryResponse {
        self.trajectory_job(request).run()
    }

    /// [`Pipeline::check_trajectory`] with the report of the state at the first contact.
    pub fn check_trajectory_with_report(&self, request: &CheckTrajectoryRequest) -> Outcome {
        self.trajectory_job(request).run_with_report()
    }
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
    /// first segment not checked). A single point is checked as one state (after its approach).
    pub fn run(&self) -> CheckTrajectoryResponse {
        self.run_with_budget(MAX_TRAJECTORY_SUBINTERVALS, None).0
    }

    /// [`TrajectoryJob::run`], with the report of the state at the first contact (its contacts
    /// as `check --json` gives them); `None` when free or refused.
    pub fn run_with_report(&self) -> Outcome {
        self.run_with_budget(MAX_TRAJECTORY_SUBINTERVALS, None)
    }

    /// [`TrajectoryJob::run_with_report`] for a trajectory executed only until `until`
    /// nanoseconds on its `time_from_start` scale (a newer one preempted it then): segments that
    /// start later are not checked, and a first contact at or after `until` is no contact.
    pub fn run_until(&self, until: i64) -> Outcome {
        let outcome = self.run_with_budget(MAX_TRAJECTORY_SUBINTERVALS, Some(until));
        let t = &outcome.0.time_from_start;
        let at = t.sec as i64 * 1_000_000_000 + t.nanosec as i64;
        if !outcome.0.valid && outcome.0.fraction >= 0.0 && at >= until {
            return free();
        }
        outcome
    }

    fn run_with_budget(&self, budget: u64, until: Option<i64>) -> Outcome {
        let plan = match &self.plan {
            Ok(plan) => plan,
            Err(e) => return refused(e.clone()),
        };
        let mut spent = 0u64;
        let mut walk = |segment: i32, t0: i64, t1: i64, check: &dyn Fn() -> MotionReport| -> Option<Outcome> {
            if until.is_some_and(|u| t0 >= u) {
                return Some(free());
            }
            if spent >= budget {
                let error = format!(
                    "the motion checks spent the {budget} sub-intervals one request may use; {} and the segments after it not checked",
                    segment_name(segment)
                );
                return Some(self.answer(segment, StateReport::failed(error), -1.0, DurationMsg::default()));
            }
            let r = check();
            spent += r.subintervals;
            if !r.report.in_collision {
                return None;
            }
            Some(match r.fraction.filter(|_| r.report.error.is_empty()) {
                Some(f) => self.answer(segment, r.report, f, time_at(t0, t1, f)),
                None => self.answer(segment, r.report, -1.0, DurationMsg::default()),
            })
        };
        match plan.interpolation {
            Interpolation::Executed => {
                let mut nearest = PathClearance::default();
                for (index, segment, t0, t1) in plan.executed_segments() {
                    let number = index.map_or(APPROACH_SEGMENT, |i| i as i32);
                    if until.is_none_or(|u| t0 < u) {
                        if let Err(e) = nearest.add(&self.checker, &segment) {
                            return self.answer(number, StateReport::failed(e), -1.0, DurationMsg::default());
                        }
                    }
                    if let Some(mut answer) = walk(number, t0, t1, &|| self.checker.check_spline(&segment)) {
                        nearest.into_response(&mut answer.0);
                        return answer;
                    }
                }
                if plan.q.len() > 1 {
                    let mut answer = free();
                    nearest.into_response(&mut answer.0);
                    return answer;
                }
            }
            Interpolation::Linear => {
                for (i, pair) in plan.q.windows(2).enumerate() {
                    let check = || if plan.has_tolerance() { self.checker.check_spline(&plan.chord(i)) } else { self.checker.check_motion(&pair[0], &pair[1]) };
                    if let Some(answer) = walk(i as i32, plan.t[i], plan.t[i + 1], &check) {
                        return answer;
                    }
                }
            }
        }
        if plan.q.len() == 1 {
            return self.single_point(plan);
        }
        free()
    }

    /// A one-point trajectory: its state (once its approach, if any, was found free).
    fn single_point(&self, plan: &Plan) -> Outcome {
        let report = if plan.has_tolerance() {
            let r = self.checker.check_spline(&plan.at_rest(0));
            if r.report.in_collision {
                let fraction = if r.report.error.is_empty() { 0.0 } else { -1.0 };
                let t = if r.report.error.is_empty() { time_at(plan.t[0], plan.t[0], 0.0) } else { DurationMsg::default() };
                return self.answer(0, r.report, fraction, t);
            }
            return free();
        } else {
            self.checker.check_positions(&plan.q[0]).unwrap_or_else(|e| StateReport::failed(e.to_string()))
        };
        if report.in_collision {
            let (fraction, t) = if report.error.is_empty() { (0.0, time_at(plan.t[0], plan.t[0], 0.0)) } else { (-1.0, DurationMsg::default()) };
            return self.answer(0, report, fraction, t);
        }
        free()
    }

    fn answer(&self, segment: i32, mut report: StateReport, fraction: f64, t: DurationMsg) -> Outcome {
        let frame = &self.checker.params().world_frame;
        if !report.error.is_empty() {
            report.error = format!("{}: {}", segment_name(segment), report.error);
        }
        let message = super::report_message(&report, Time::default(), frame);
        let response = CheckTrajectoryResponse {
            valid: false,
            segment,
            fraction,
            time_from_start: t,
            contacts: message.contacts,
            error: report.error.clone(),
            clearances: Vec::new(),
        };
        (response, Some(report))
    }
}

/// The smallest clearance of each link over the segments walked so far, and the stretches that
/// cost (one request's clearances share [`MAX_TRAJECTORY_SUBINTERVALS`], as its motion checks do).
#[derive(Default)]
struct PathClearance {
    nearest: Vec<crate::checker::ReportClearance>,
    spent: u64,
}

impl PathClearance {
    /// Folds in one segment's (nothing when `clearance_threshold` is 0).
    fn add(&mut self, checker: &Checker, segment: &crate::checker::SplineSegment) -> Result<(), String> {
        let budget = MAX_TRAJECTORY_SUBINTERVALS.saturating_sub(self.spent) as usize;
        let (found, examined) = checker.spline_clearances(segment, budget)?;
        self.spent += examined as u64;
        for c in found {
            match self.nearest.iter_mut().find(|n| n.link_name == c.link_name) {
                Some(n) if c.distance < n.distance => *n = c,
                Some(_) => {}
                None => self.nearest.push(c),
            }
        }
        Ok(())
    }

    fn into_response(self, response: &mut CheckTrajectoryResponse) {
        response.clearances = self.nearest.iter().map(super::report_adapter::clearance_message).collect();
    }
}

/// "segment i", or "the approach" for [`APPROACH_SEGMENT`].
fn segment_name(segment: i32) -> String {
    if segment == APPROACH_SEGMENT {
        "the approach from the current state".to_owned()
    } else {
        format!("segment {segment}")
    }
}

/// A trajectory's answer, and the report of the state at its first contact (`None` when free or
/// refused).
pub type Outcome = (CheckTrajectoryResponse, Option<StateReport>);

fn free() -> Outcome {
    (CheckTrajectoryResponse { valid: true, segment: -1, fraction: -1.0, ..Default::default() }, None)
}

fn refused(error: String) -> Outcome {
    (CheckTrajectoryResponse { valid: false, segment: -1, fraction: -1.0, error, ..Default::default() }, None)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{MissingJoint, Params};
    use crate::msgs::{JointState, JointTrajectory, JointTrajectoryPoint};

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

    /// A request along the straight chords (the tests of this module are about the walk).
    fn trajectory(names: &[&str], points: Vec<JointTrajectoryPoint>) -> CheckTrajectoryRequest {
        let trajectory = JointTrajectory { joint_names: names.iter().map(|s| s.to_string()).collect(), points, ..Default::default() };
        CheckTrajectoryRequest { trajectory, interpolation: "linear".into(), path_tolerance: Vec::new() }
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
        free_part.trajectory.points.truncate(3);
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
        let r = job.run_with_budget(cost[0] + cost[1], None).0;
        assert_eq!((r.valid, r.segment, r.fraction), (false, 2, -1.0), "{r:?}");
        assert!(r.error.starts_with("segment 2: ") && r.error.contains("segment 2 and the segments after it not checked"), "{}", r.error);
        assert_eq!(job.run_with_budget(cost.iter().sum::<u64>(), None).0, free, "the whole budget checks everything");
    }

    #[test]
    fn time_at_rounds_down_and_normalises() {
        assert_eq!(time_at(1_000_000_000, 3_000_000_000, 0.25), DurationMsg { sec: 1, nanosec: 500_000_000 });
        assert_eq!(time_at(-1_000_000_000, 0, 0.5), DurationMsg { sec: -1, nanosec: 500_000_000 });
        assert_eq!(time_at(0, 3, 0.5), DurationMsg { sec: 0, nanosec: 1 });
    }
}
