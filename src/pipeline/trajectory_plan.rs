//! A `JointTrajectory` turned into the motions the robot makes: validated, resolved to every
//! joint against the pipeline's current state, and cut into segments, each the polynomial
//! `joint_trajectory_controller` commands (ros2_controllers' `trajectory.cpp`, jazzy):
//!
//! - a segment is quintic when both its points give velocities and accelerations, cubic when
//!   both give velocities, linear otherwise (`interpolate_between_points`);
//! - when the first point's `time_from_start` is above 0 the robot first moves to it from the
//!   current state (`Trajectory::sample` before the first point): from the velocities the joint
//!   states last gave (0 when they gave none, as the controller zero-fills a state without them
//!   when the first point has them), accelerations 0, and each continuous joint moved the
//!   shorter way round to the first point (`wraparound_joint`, its tie at π included);
//! - points that give accelerations without velocities are refused: the controller's
//!   interpolation has no branch for them (it would command position 0).
//!
//! Joints the trajectory does not name stay where the current state has them.

use super::Pipeline;
use crate::checker::{SegmentPoly, SplineSegment};
use crate::limits::MAX_NAMES_IN_ERROR;
use crate::model::JointKind;
use crate::msgs::{CheckTrajectoryRequest, DurationMsg, MAX_TRAJECTORY_ENTRIES};

/// Points a trajectory may have (the decoder refuses longer sequences already).
pub(crate) const MAX_TRAJECTORY_POINTS: usize = MAX_TRAJECTORY_ENTRIES;

/// Names a trajectory may give (more than any robot has joints; the decoder refuses longer lists
/// already).
pub(crate) const MAX_TRAJECTORY_NAMES: usize = MAX_TRAJECTORY_ENTRIES;

/// How the segments between waypoints are interpolated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interpolation {
    /// As the controller executes them (the default).
    Executed,
    /// Straight chords in joint space between the waypoints, no approach.
    Linear,
}

impl Interpolation {
    /// The request's `interpolation` field: empty or `spline`: executed; `linear`.
    pub fn parse(text: &str) -> Result<Interpolation, String> {
        match text {
            "" | "spline" => Ok(Interpolation::Executed),
            "linear" => Ok(Interpolation::Linear),
            other => Err(format!("interpolation '{other}' is not known (allowed: '' or 'spline' as the controller executes it, 'linear')")),
        }
    }
}

/// A validated trajectory, every joint at every point.
#[derive(Clone, Debug)]
pub(crate) struct Plan {
    /// Positions of every joint at every point.
    pub(crate) q: Vec<Vec<f64>>,
    /// Velocities (per second) of every joint at every point that gives them.
    v: Vec<Option<Vec<f64>>>,
    /// Accelerations of every joint at every point that gives them.
    a: Vec<Option<Vec<f64>>>,
    /// `time_from_start` of every point, nanoseconds.
    pub(crate) t: Vec<i64>,
    /// Per joint: the path tolerance (0 for joints not named).
    pub(crate) tolerance: Vec<f64>,
    pub(crate) interpolation: Interpolation,
    /// The current state's positions and velocities, for the approach (executed, `t[0] > 0`).
    start: Option<(Vec<f64>, Vec<f64>)>,
    /// Per joint: continuous (a chord takes it the shorter way, as the motion check does).
    continuous: Vec<bool>,
}

/// The nanoseconds of a `builtin_interfaces/Duration` (`nanosec` past 1e9 adds up, as rclcpp's
/// conversion does).
fn duration_nanos(d: &DurationMsg) -> i64 {
    d.sec as i64 * 1_000_000_000 + d.nanosec as i64
}

/// One point's optional field (velocities or accelerations) over every joint: `None` when
/// empty; refused unless one finite value per name.
fn point_field(base: &[f64], index: &[usize], names: &[String], values: &[f64], k: usize, what: &str) -> Result<Option<Vec<f64>>, String> {
    if values.is_empty() {
        return Ok(None);
    }
    if values.len() != names.len() {
        return Err(format!("point {k} has {} {what} for {} joint_names (allowed: none, or one per name)", values.len(), names.len()));
    }
    let mut out = base.to_vec();
    for ((&j, &x), name) in index.iter().zip(values).zip(names) {
        if !x.is_finite() {
            return Err(format!("point {k}: joint '{name}' has a non-finite {what} value {x}"));
        }
        out[j] = x;
    }
    Ok(Some(out))
}

/// Validates a request and resolves every point to every joint (see the module documentation).
pub(crate) fn resolve(pipeline: &Pipeline, request: &CheckTrajectoryRequest) -> Result<Plan, String> {
    let trajectory = &request.trajectory;
    let interpolation = Interpolation::parse(&request.interpolation)?;
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
    let tolerance = tolerances(robot.joints.len(), &index, names, &request.path_tolerance)?;
    let mut seen = vec![false; robot.joints.len()];
    index.iter().for_each(|&j| seen[j] = true);
    let base = left_out_joints(pipeline, &seen)?;
    let zeros = vec![0.0; base.len()];
    let (mut q, mut v, mut a, mut t) =
        (Vec::with_capacity(points.len()), Vec::with_capacity(points.len()), Vec::with_capacity(points.len()), Vec::with_capacity(points.len()));
    for (k, point) in points.iter().enumerate() {
        if point.positions.len() != names.len() {
            return Err(format!("point {k} has {} positions for {} joint_names", point.positions.len(), names.len()));
        }
        let mut qk = base.clone();
        for ((&j, &x), name) in index.iter().zip(&point.positions).zip(names) {
            if !x.is_finite() {
                return Err(format!("point {k}: joint '{name}' has a non-finite position {x}"));
            }
            qk[j] = x;
        }
        let vk = point_field(&zeros, &index, names, &point.velocities, k, "velocities")?;
        let ak = point_field(&zeros, &index, names, &point.accelerations, k, "accelerations")?;
        if ak.is_some() && vk.is_none() {
            return Err(format!("point {k} gives accelerations without velocities (joint_trajectory_controller cannot interpolate that)"));
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
        v.push(vk);
        a.push(ak);
        t.push(tk);
    }
    let start = if interpolation == Interpolation::Executed && t[0] > 0 { Some(current_state(pipeline, &q[0])?) } else { None };
    let continuous = robot.joints.iter().map(|j| j.kind == JointKind::Continuous).collect();
    Ok(Plan { q, v, a, t, tolerance, interpolation, start, continuous })
}

/// Per joint, the request's `path_tolerance` (in `joint_names` order) or 0.
fn tolerances(joints: usize, index: &[usize], names: &[String], given: &[f64]) -> Result<Vec<f64>, String> {
    let mut out = vec![0.0; joints];
    if given.is_empty() {
        return Ok(out);
    }
    if given.len() != names.len() {
        return Err(format!("path_tolerance has {} values for {} joint_names (allowed: none, or one per name)", given.len(), names.len()));
    }
    for ((&j, &x), name) in index.iter().zip(given).zip(names) {
        if !(x.is_finite() && x >= 0.0) {
            return Err(format!("path_tolerance of joint '{name}' is {x} (allowed: finite, at least 0)"));
        }
        out[j] = x;
    }
    Ok(out)
}

/// Where the robot is when the trajectory arrives: every joint's current position (a joint never
/// received follows `missing_joint`, as for joints a request leaves out) and velocity, each
/// continuous joint moved the shorter way round to the first point.
fn current_state(pipeline: &Pipeline, first: &[f64]) -> Result<(Vec<f64>, Vec<f64>), String> {
    let robot = pipeline.checker().robot();
    let mut q = Vec::with_capacity(first.len());
    let mut v = Vec::with_capacity(first.len());
    for (j, joint) in robot.joints.iter().enumerate() {
        let here = pipeline.left_out_position(j, "the trajectory's approach (the current joint state)")?;
        q.push(if joint.kind == JointKind::Continuous { wrapped_start(here, first[j]) } else { here });
        v.push(pipeline.current_velocity(j));
    }
    Ok((q, v))
}

/// `wraparound_joint`: the start of a continuous joint moved by whole turns so that it reaches
/// `next` the shorter way (at exactly half a turn, towards `next`).
pub(crate) fn wrapped_start(current: f64, next: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let mut dist = (next - current).rem_euclid(TAU);
    if dist > PI {
        dist -= TAU;
    }
    if ((dist.abs()) - PI).abs() < 1e-9 {
        dist = if next > current { dist.abs() } else { -dist.abs() };
    }
    next - dist
}

impl Plan {
    /// The segments as the controller executes them, in order: the approach first (index
    /// `None`) when there is one, then point `i` to point `i + 1` (index `Some(i)`).
    pub(crate) fn executed_segments(&self) -> impl Iterator<Item = (Option<usize>, SplineSegment, i64, i64)> + '_ {
        let approach = self.start.as_ref().map(|(q, v)| {
            let zeros = vec![0.0; q.len()];
            let a0 = self.a[0].as_ref().map(|_| zeros.as_slice());
            let v0 = self.v[0].as_ref().map(|_| v.as_slice());
            (None, self.segment((q, v0, a0), (&self.q[0], self.v[0].as_deref(), self.a[0].as_deref()), self.t[0]), 0, self.t[0])
        });
        let segments = (0..self.q.len().saturating_sub(1)).map(move |i| {
            let ends = |k: usize| (self.q[k].as_slice(), self.v[k].as_deref(), self.a[k].as_deref());
            (Some(i), self.segment(ends(i), ends(i + 1), self.t[i + 1] - self.t[i]), self.t[i], self.t[i + 1])
        });
        approach.into_iter().chain(segments)
    }

    /// The controller's polynomial for every joint between two ends (positions, velocities,
    /// accelerations) `ns` nanoseconds apart.
    fn segment(&self, from: End<'_>, to: End<'_>, ns: i64) -> SplineSegment {
        let duration = ns as f64 * 1e-9;
        let joints = (0..from.0.len())
            .map(|j| match (from, to) {
                ((p0, Some(v0), Some(a0)), (p1, Some(v1), Some(a1))) => SegmentPoly::quintic(p0[j], v0[j], a0[j], p1[j], v1[j], a1[j], duration),
                ((p0, Some(v0), _), (p1, Some(v1), _)) => SegmentPoly::cubic(p0[j], v0[j], p1[j], v1[j], duration),
                ((p0, _, _), (p1, _, _)) => SegmentPoly::linear(p0[j], p1[j]),
            })
            .collect();
        SplineSegment { joints, tolerance: self.tolerance.clone() }
    }

    /// The straight chord from point `i` to point `i + 1` (linear interpolation) with the tube.
    pub(crate) fn chord(&self, i: usize) -> SplineSegment {
        let joints = (0..self.q[i].len())
            .map(|j| {
                let (a, b) = (self.q[i][j], self.q[i + 1][j]);
                SegmentPoly::linear(a, if self.continuous[j] { a + (b - wrapped_start(a, b)) } else { b })
            })
            .collect();
        SplineSegment { joints, tolerance: self.tolerance.clone() }
    }

    /// Point `k` held still, with the tube.
    pub(crate) fn at_rest(&self, k: usize) -> SplineSegment {
        SplineSegment { joints: self.q[k].iter().map(|p| SegmentPoly::constant(*p)).collect(), tolerance: self.tolerance.clone() }
    }

    /// Whether any joint has a path tolerance.
    pub(crate) fn has_tolerance(&self) -> bool {
        self.tolerance.iter().any(|t| *t > 0.0)
    }
}

/// Positions, velocities and accelerations of every joint at a segment's end.
type End<'a> = (&'a [f64], Option<&'a [f64]>, Option<&'a [f64]>);

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
