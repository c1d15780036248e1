//! Motions: the straight line in joint space between two states, checked so that no crossing is
//! missed (adaptive conservative checking, after Schwarzer, Saha and Latombe, IEEE T-RO 21(3),
//! 2005).
//!
//! Over a sub-interval `[a, b]` of the motion parameter, with `h = (b - a)/2`, every point of
//! link `k` stays within `δ_k = h · Σ_j |Δq_j| · r_jk` of where it is at the middle (`r_jk`
//! bounds the distance from joint `j`'s axis to any point of the link in every configuration; 1
//! for a prismatic joint). Each `r_jk` is tightened with the configuration at the middle: the
//! distance from `j`'s axis to `k`'s origin there plus `k`'s reach, plus what the joints between
//! `j` and `k` can change it by within `h` (see `JointPath::bound`). The link at the middle, grown
//! by `δ_k`, contains every pose of the link on `[a, b]`: if the grown link touches nothing, the
//! sub-interval is free for that link. Otherwise the sub-interval is halved, left half first,
//! until the growth falls under `motion_tolerance`: that sub-interval is reported colliding. So
//! "free" is certain, and a reported fraction is never later than the first contact.
//!
//! The loop itself (`motion_sweep`) is shared with motions between link poses
//! (`world_motion`, for `/tf` input).

use super::checker_build::{Checker, LinkTargets};
use super::motion_sweep::MotionPath;
use super::state_report::StateReport;
use crate::collision::{ConvexHull, TargetShape};
use crate::math::{pose_from_isometry, Pose, Real, Vector};
use crate::model::{JointKind, RobotModel};
use std::sync::{Arc, OnceLock};

/// Sub-intervals examined at most per motion; past that the motion fails closed.
pub const MAX_SUBINTERVALS: u64 = 1 << 20;

/// Rungs of the growth ladder per doubling: growth `base · 2^(level / RUNGS)`. The growth used is
/// the first rung at or above the bound, so it overshoots by up to `2^(1/RUNGS)`; a grown link
/// that overshoots touches more and splits more often. On the motion benchmark (2,000 motions)
/// 1, 2 and 4 rungs took 158, 135 and 125 link tests per motion.
const RUNGS: usize = 4;

/// Levels of the growth ladder: from `base` (half the tolerance) to far past any accepted size.
const LEVELS: usize = 64 * RUNGS;

/// What a motion check gives.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MotionReport {
    /// `in_collision`, `contacts` (of the pose at `fraction`) and `error`, as for a state.
    pub report: StateReport,
    /// The start of the first sub-interval that could not be cleared, in [0, 1]; `None` when free
    /// or not checked.
    pub fraction: Option<f64>,
    /// Sub-intervals examined, counted once for each link tested on one (the count
    /// `MAX_SUBINTERVALS` bounds).
    pub subintervals: u64,
}

/// What the motion check precomputes per checked link: the lever of every joint that moves it,
/// and its parts grown by each step of the ladder (built on first use).
#[derive(Clone, Debug)]
pub(crate) struct MotionBounds {
    /// Per target (as `Checker::targets`): (joint index, lever in metres; 1 for prismatic).
    levers: Vec<Vec<(usize, Real)>>,
    /// Per target: the farthest any of its points lies from its link's origin.
    pub(super) reach: Vec<Real>,
    /// Per target: a point fixed to its link (link frame) and the farthest any of the target's
    /// points lies from it, for the first-order bound of `JointPath::bound`.
    pub(super) ball: Vec<(Vector, Real)>,
    /// Per target, per part, per level: the part grown by `base · 2^level`.
    pub(super) grown: Vec<Vec<Vec<OnceLock<TargetShape>>>>,
    /// Growth of level 0: half the tolerance, so a level under the tolerance exists.
    base: Real,
}

/// Farthest any point of a part lies from its link's origin.
fn part_reach(shape: &TargetShape, offset: &Pose) -> Real {
    let own = match shape {
        TargetShape::Polytope(h) => h.points().iter().map(|p| p.length()).fold(0.0, Real::max),
        TargetShape::Sphere { radius } => *radius,
        TargetShape::Capsule { half_height, radius } => half_height + radius,
        TargetShape::Cylinder { half_height, radius } => half_height.hypot(*radius),
    };
    offset.translation.length() + own
}

/// A ball holding every part: the centre of the box around the parts' own bounding balls, and
/// the radius about it.
fn target_ball(parts: &[(TargetShape, Pose)]) -> (Vector, Real) {
    let balls: Vec<(Vector, Real)> = parts.iter().map(|(shape, offset)| (*offset * shape.centre(), shape.bounding_radius())).collect();
    let (mut lo, mut hi) = (Vector::splat(Real::INFINITY), Vector::splat(Real::NEG_INFINITY));
    for (c, r) in &balls {
        lo = lo.min(*c - Vector::splat(*r));
        hi = hi.max(*c + Vector::splat(*r));
    }
    let centre = if balls.is_empty() { Vector::ZERO } else { (lo + hi) * 0.5 };
    (centre, balls.iter().map(|(c, r)| (*c - centre).length() + r).fold(0.0, Real::max))
}

/// A superset of `shape ⊕ ball(pad)`: for a hull its Minkowski sum with a cube of half-side `pad`
/// (which contains the ball); primitives grown in closed form.
pub(super) fn grow(shape: &TargetShape, pad: Real) -> TargetShape {
    match shape {
        TargetShape::Sphere { radius } => TargetShape::Sphere { radius: radius + pad },
        TargetShape::Capsule { half_height, radius } => TargetShape::Capsule { half_height: *half_height, radius: radius + pad },
        TargetShape::Cylinder { half_height, radius } => TargetShape::Cylinder { half_height: half_height + pad, radius: radius + pad },
        TargetShape::Polytope(h) => {
            match ConvexHull::grown_by_cube(h, pad) {
                Some(g) => TargetShape::Polytope(Arc::new(g)),
                // A ball around the hull contains it grown as well.
                None => TargetShape::Sphere { radius: h.points().iter().map(|p| p.length()).fold(0.0, Real::max) + pad * 3f64.sqrt() },
            }
        }
    }
}

impl MotionBounds {
    pub(crate) fn new(robot: &RobotModel, targets: &[LinkTargets], tolerance: Real) -> MotionBounds {
        let mut levers = Vec::with_capacity(targets.len());
        let mut reaches = Vec::with_capacity(targets.len());
        for t in targets {
            let reach = t.parts.iter().map(|(s, o)| part_reach(s, o)).fold(0.0, Real::max);
            reaches.push(reach);
            // Walk up from the link: `chain` is the farthest the link's origin can be from the
            // origin of the joint reached so far, in any configuration.
            let mut chain = 0.0;
            let mut list = Vec::new();
            let mut link = t.link;
            let mut steps = 0;
            while let Some(j) = robot.parent_joint(link) {
                let joint = &robot.joints[j];
                match joint.kind {
                    JointKind::Revolute | JointKind::Continuous => list.push((j, chain + reach)),
                    JointKind::Prismatic => list.push((j, 1.0)),
                    JointKind::Fixed | JointKind::Floating | JointKind::Planar => {}
                }
                chain += joint.origin.translation.vector.norm();
                if joint.kind == JointKind::Prismatic {
                    chain += joint.limits[0].abs().max(joint.limits[1].abs());
                }
                link = joint.parent;
                steps += 1;
                if steps > robot.joints.len() {
                    break;
                }
            }
            levers.push(list);
        }
        let grown = targets.iter().map(|t| t.parts.iter().map(|_| (0..LEVELS).map(|_| OnceLock::new()).collect()).collect()).collect();
        let ball = targets.iter().map(|t| target_ball(&t.parts)).collect();
        MotionBounds { levers, reach: reaches, ball, grown, base: tolerance / 2.0 }
    }

    /// The ladder level whose growth covers `delta`.
    pub(super) fn level(&self, delta: Real) -> usize {
        if delta <= self.base {
            return 0;
        }
        // Rounding can leave `growth(level)` a hair under `delta`: the caller checks, and
        // splits when it is (as it does past the top of the ladder).
        (((delta / self.base).log2() * RUNGS as Real).ceil() as usize).min(LEVELS - 1)
    }

    /// The growth of ladder `level` (metres).
    pub(super) fn growth(&self, level: usize) -> Real {
        self.base * Real::exp2(level as Real / RUNGS as Real)
    }
}

/// A motion in joint space: `q0 + s·delta`, link poses by forward kinematics.
struct JointPath<'a> {
    checker: &'a Checker,
    q0: &'a [f64],
    delta: Vec<f64>,
    speeds: Vec<Real>,
    /// Per target: a bound on the acceleration of any of its points along `s` (see
    /// `point_acceleration`).
    accelerations: Vec<Real>,
}

/// A bound on `|d²p/ds²|` over every point `p` of a target and every `s`, for the levers of its
/// joints (`levers`, nearest first) and its speed bound `speed`. The joints move at constant
/// rates `Δq`, so `p̈ = Σ_j Δq_j d/ds u_j` with `u_j = a_j × (p − o_j)` (revolute: axis `a_j`
/// through the joint origin `o_j`) or `a_j` (prismatic). The axis turns with the joints above
/// it: `|ȧ_j| ≤ W_j = Σ |Δq_i|` over the revolute joints `i` above `j`. `|p − o_j| ≤ r_j`
/// (the lever, a bound on the distance from the joint's origin in every configuration), and
/// the velocity of `p` relative to `o_j` is at most `W_j r_j` (joints above `j` turning the
/// pair) plus the speed bound (joints from `j` down). So a revolute `j` adds
/// `|Δq_j| (2 W_j r_j + speed)`, a prismatic one `|Δq_j| W_j`.
fn point_acceleration(robot: &RobotModel, levers: &[(usize, Real)], delta: &[f64], speed: Real) -> Real {
    let mut above = 0.0;
    let mut total = 0.0;
    // From the top of the chain down, so that `above` is `W_j` at each joint.
    for &(j, r) in levers.iter().rev() {
        let d = delta[j].abs();
        match robot.joints[j].kind {
            JointKind::Revolute | JointKind::Continuous => {
                total += d * (2.0 * above * r + speed);
                above += d;
            }
            JointKind::Prismatic => total += d * above,
            JointKind::Fixed | JointKind::Floating | JointKind::Planar => {}
        }
    }
    total
}

impl JointPath<'_> {
    fn at(&self, s: f64) -> Vec<f64> {
        self.q0.iter().zip(&self.delta).map(|(a, d)| a + s * d).collect()
    }
}

impl MotionPath for JointPath<'_> {
    fn speeds(&self) -> &[Real] {
        &self.speeds
    }

    fn link_poses(&self, s: f64) -> Result<Vec<Option<Pose>>, String> {
        let poses = self.checker.robot().forward_kinematics(&self.at(s), self.checker.base_pose()).map_err(|e| e.to_string())?;
        Ok(poses.iter().map(|p| Some(pose_from_isometry(p))).collect())
    }

    /// Tighter than `half · speed` where the link is nearer a joint's axis than the lever bound
    /// allows for: the distance from joint `j`'s axis to a point of link `k` at `s` is at most
    /// the distance from the axis to `k`'s origin there plus `k`'s reach, and within `half` of
    /// `s` it grows by at most what the joints between `j` and `k` move the point relative to
    /// `j`, `half · Σ_i |Δq_i| r_ik`. Each joint's lever is the smaller of that and `r_jk`.
    ///
    /// Often tighter still (the joints' motions add as vectors, and partly cancel): the
    /// velocity of the link's points at `s` itself, `|v_c| + |ω| R` for a ball of radius `R`
    /// about a point `c` of the link, plus what it can gain within `half`: every point moves at
    /// most `half · (|v_c| + |ω| R) + half² · A / 2` from where it is at `s`, with `A` the
    /// acceleration bound of `point_acceleration`. The smaller of the two bounds is used.
    fn bound(&self, ti: usize, poses: &[Option<Pose>], half: f64) -> Real {
        let robot = self.checker.robot();
        let bounds = self.checker.motion_bounds();
        let Some(link) = poses[self.checker.targets()[ti].link] else { return half * self.speeds[ti] };
        let reach = bounds.reach[ti];
        let (centre, radius) = bounds.ball[ti];
        let c = link * centre;
        // Σ_i |Δq_i| r_ik over the joints between the current one and the link.
        let mut below = 0.0;
        let mut total = 0.0;
        // The link's angular velocity and the velocity of `c`, at `s`.
        let (mut omega, mut velocity) = (Vector::ZERO, Vector::ZERO);
        let mut first_order = true;
        for &(j, r) in &bounds.levers[ti] {
            let d = self.delta[j].abs();
            let joint = &robot.joints[j];
            let lever = match (joint.kind, poses[joint.child]) {
                (JointKind::Revolute | JointKind::Continuous, Some(child)) => {
                    let axis = child.rotation * Vector::new(joint.axis.x, joint.axis.y, joint.axis.z);
                    let rel = link.translation - child.translation;
                    let off_axis = (rel - axis * rel.dot(axis)).length();
                    omega += axis * self.delta[j];
                    velocity += axis.cross(c - child.translation) * self.delta[j];
                    r.min(off_axis + reach + half * below)
                }
                (JointKind::Prismatic, Some(child)) => {
                    velocity += child.rotation * Vector::new(joint.axis.x, joint.axis.y, joint.axis.z) * self.delta[j];
                    r
                }
                _ => {
                    first_order &= d == 0.0;
                    r
                }
            };
            total += d * lever;
            below += d * r;
        }
        let levers = half * total;
        if !first_order {
            return levers;
        }
        let moving = half * (velocity.length() + omega.length() * radius) + 0.5 * half * half * self.accelerations[ti];
        // NaN (a bad pose) falls back to the lever bound.
        if moving < levers {
            moving
        } else {
            levers
        }
    }

    fn report_at(&self, s: f64) -> StateReport {
        self.checker.check_positions(&self.at(s)).unwrap_or_else(|e| StateReport::failed(e.to_string()))
    }

    /// In the frame of the last link upstream of both: only the joints that move one of the two
    /// and not the other count (a joint above both turns the pair as one body). Each with its
    /// lever bound over all configurations; the world bounds when those are smaller in sum.
    fn pair_bound(&self, a: usize, b: usize, poses: &[Option<Pose>], half: f64) -> (Real, Real) {
        let relative = self.pair_bound_quick(a, b, poses, half);
        let world = (self.bound(a, poses, half), self.bound(b, poses, half));
        if relative.0 + relative.1 <= world.0 + world.1 {
            relative
        } else {
            world
        }
    }

    /// The relative bounds of [`JointPath::pair_bound`] alone.
    fn pair_bound_quick(&self, a: usize, b: usize, _poses: &[Option<Pose>], half: f64) -> (Real, Real) {
        let levers = &self.checker.motion_bounds().levers;
        let own = |x: usize, y: usize| -> Real {
            levers[x].iter().filter(|(j, _)| !levers[y].iter().any(|(k, _)| k == j)).map(|(j, r)| self.delta[*j].abs() * r).sum()
        };
        (half * own(a, b), half * own(b, a))
    }
}

impl Checker {
    /// Checks the motion from `q0` to `q1` (positions of every joint, as for
    /// [`Checker::check_positions`]): continuous joints along the shorter arc, mimic joints
    /// following their master. See the module documentation for what "free" and "colliding" mean.
    pub fn check_motion(&self, q0: &[f64], q1: &[f64]) -> MotionReport {
        match self.joint_path(q0, q1) {
            Ok(path) => self.sweep_motion(&path),
            Err(e) => MotionReport { report: StateReport { motion: true, ..StateReport::failed(e) }, ..Default::default() },
        }
    }

    /// The motion from `q0` to `q1` as the adaptive loop sees it.
    fn joint_path<'a>(&'a self, q0: &'a [f64], q1: &[f64]) -> Result<JointPath<'a>, String> {
        let robot = self.robot();
        for q in [q0, q1] {
            robot.validate_positions(q).map_err(|e| e.to_string())?;
        }
        // Joint-space step of every joint (mimics from their master).
        let mut delta: Vec<f64> = robot
            .joints
            .iter()
            .zip(q0.iter().zip(q1))
            .map(|(j, (a, b))| match j.kind {
                JointKind::Continuous => {
                    let d = (b - a).rem_euclid(std::f64::consts::TAU);
                    if d > std::f64::consts::PI {
                        d - std::f64::consts::TAU
                    } else {
                        d
                    }
                }
                JointKind::Revolute | JointKind::Prismatic => b - a,
                _ => 0.0,
            })
            .collect();
        for (i, j) in robot.joints.iter().enumerate() {
            if let Some(m) = j.mimic {
                delta[i] = m.multiplier * delta[m.joint];
            }
        }
        let bounds = self.motion_bounds();
        // Per target: Σ_j |Δq_j| r_jk, the speed bound of its points per unit of s.
        let speeds: Vec<Real> = bounds.levers.iter().map(|l| l.iter().map(|(j, r)| delta[*j].abs() * r).sum()).collect();
        let accelerations = bounds.levers.iter().zip(&speeds).map(|(l, speed)| point_acceleration(robot, l, &delta, *speed)).collect();
        Ok(JointPath { checker: self, q0, delta, speeds, accelerations })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Params;

    fn arm() -> Checker {
        Checker::from_params(Params::default(), None, None).unwrap()
    }

    fn q(checker: &Checker, values: &[(&str, f64)]) -> Vec<f64> {
        let mut q = vec![0.0; checker.robot().joints.len()];
        for (name, v) in values {
            q[checker.robot().joint(name).unwrap()] = *v;
        }
        q
    }

    /// An end that cannot be posed (non-finite, wrong length) fails the motion closed, with the
    /// error forward kinematics gives, although the motion no longer poses its ends to find it.
    #[test]
    fn a_motion_with_an_end_that_cannot_be_posed_fails_closed() {
        let c = arm();
        let free = q(&c, &[]);
        let base = nalgebra::Isometry3::identity();
        let mut nan = free.clone();
        nan[1] = f64::NAN;
        for (q0, q1) in [(&free, &nan), (&nan, &free), (&free, &free[..free.len() - 1].to_vec())] {
            let r = c.check_motion(q0, q1).report;
            let bad = if q0.iter().all(|v| v.is_finite()) { q1 } else { q0 };
            let expected = c.robot().forward_kinematics(bad, &base).expect_err("an end that cannot be posed").to_string();
            assert!(r.motion && r.in_collision, "fails closed: {r:?}");
            assert_eq!(r.error, expected);
        }
        assert!(c.check_motion(&free, &free).report.error.is_empty());
    }

    /// Points of a part in its link's frame: a hull's vertices, a primitive's extreme points
    /// along 26 directions.
    fn part_points(shape: &TargetShape, offset: &Pose) -> Vec<Vector> {
        let local: Vec<Vector> = match shape {
            TargetShape::Polytope(h) => h.points().to_vec(),
            _ => (0..27)
                .filter(|&i| i != 13)
                .map(|i| shape.support_point(Vector::new((i % 3) as Real - 1.0, ((i / 3) % 3) as Real - 1.0, (i / 9) as Real - 1.0)))
                .collect(),
        };
        local.into_iter().map(|p| *offset * p).collect()
    }

    /// The bound the adaptive loop trusts, checked directly: over random motions of the bundled
    /// arm (revolute, continuous, prismatic and mimic joints), no point of any link, sampled
    /// along a stretch, lies farther from where it is at the stretch's middle than the bound.
    #[test]
    fn no_point_of_a_link_moves_farther_than_its_bound() {
        let c = arm();
        let robot = c.robot();
        let mut rng = oorandom::Rand64::new(12);
        let mut draw = |lo: f64, hi: f64| lo + (hi - lo) * rng.rand_float();
        let (mut checked, mut tightest) = (0usize, 0.0f64);
        for _ in 0..400 {
            let mut qs = [vec![0.0; robot.joints.len()], vec![0.0; robot.joints.len()]];
            for q in &mut qs {
                for (i, j) in robot.joints.iter().enumerate() {
                    let [lo, hi] = j.limits;
                    q[i] = if lo.is_finite() && hi.is_finite() { draw(lo, hi) } else { draw(-std::f64::consts::PI, std::f64::consts::PI) };
                }
            }
            let path = c.joint_path(&qs[0], &qs[1]).unwrap();
            let half = [0.5, 0.2, 0.05, 0.01][checked % 4];
            let s = draw(0.0, 1.0);
            let poses = path.link_poses(s).unwrap();
            for (ti, t) in c.targets().iter().enumerate() {
                let bound = path.bound(ti, &poses, half);
                let points: Vec<Vector> = t.parts.iter().flat_map(|(shape, offset)| part_points(shape, offset)).collect();
                let at = poses[t.link].unwrap();
                let mut farthest = 0.0f64;
                for k in 0..=16 {
                    let other = (s - half + 2.0 * half * k as f64 / 16.0).clamp(0.0, 1.0);
                    let pose = path.link_poses(other).unwrap()[t.link].unwrap();
                    for p in &points {
                        farthest = farthest.max(((pose * *p) - (at * *p)).length());
                    }
                }
                assert!(farthest <= bound + 1e-9, "link '{}' moved {farthest} m within {half} of s = {s}, bound {bound}", t.name);
                if bound > 0.0 {
                    tightest = tightest.max(farthest / bound);
                }
            }
            checked += 1;
        }
        // The bound is not vacuous: somewhere a link comes near it.
        assert!(tightest > 0.3, "largest motion / bound {tightest}");
        eprintln!("{checked} stretches, largest motion / bound {tightest:.3}");
    }

    #[test]
    fn a_crossing_between_free_states_is_found_and_a_free_motion_is_free() {
        let c = arm();
        let free = q(&c, &[]);
        assert!(!c.check_positions(&free).unwrap().in_collision);
        let r = c.check_motion(&free, &free);
        assert_eq!((r.report.in_collision, r.fraction), (false, None), "{r:?}");
        // Into the guard: the motion collides no later than the end state does.
        let into = q(&c, &[("shoulder_lift_joint", 1.2), ("elbow_joint", 0.3)]);
        assert!(c.check_positions(&into).unwrap().in_collision);
        let r = c.check_motion(&free, &into);
        assert!(r.report.in_collision && r.report.error.is_empty(), "{r:?}");
        let f = r.fraction.unwrap();
        assert!((0.0..1.0).contains(&f), "{f}");
        eprintln!("into the guard: fraction {f}, {} sub-intervals, {:?}", r.subintervals, r.report.contacts);
        // Dense sampling finds no contact before the fraction.
        for k in 0..2000 {
            let s = f * k as f64 / 2000.0;
            let qs: Vec<f64> = free.iter().zip(&into).map(|(a, b)| a + s * (b - a)).collect();
            assert!(!c.check_positions(&qs).unwrap().in_collision, "a contact at {s} before the fraction {f}");
        }
    }
}
