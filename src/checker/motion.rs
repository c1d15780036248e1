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

/// A superset of `shape ⊕ ball(pad)`: for a hull its Minkowski sum with a cube of half-side `pad`
/// (which contains the ball); primitives grown in closed form.
pub(super) fn grow(shape: &TargetShape, pad: Real) -> TargetShape {
    match shape {
        TargetShape::Sphere { radius } => TargetShape::Sphere { radius: radius + pad },
        TargetShape::Capsule { half_height, radius } => TargetShape::Capsule { half_height: *half_height, radius: radius + pad },
        TargetShape::Cylinder { half_height, radius } => TargetShape::Cylinder { half_height: half_height + pad, radius: radius + pad },
        TargetShape::Polytope(h) => {
            let corners =
                (0..8).map(|i| Vector::new(if i & 1 == 0 { -pad } else { pad }, if i & 2 == 0 { -pad } else { pad }, if i & 4 == 0 { -pad } else { pad }));
            let corners: Vec<Vector> = corners.collect();
            let points: Vec<Vector> = h.points().iter().flat_map(|p| corners.iter().map(move |c| *p + *c)).collect();
            match ConvexHull::from_points(&points) {
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
        MotionBounds { levers, reach: reaches, grown, base: tolerance / 2.0 }
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
    fn bound(&self, ti: usize, poses: &[Option<Pose>], half: f64) -> Real {
        let robot = self.checker.robot();
        let bounds = self.checker.motion_bounds();
        let Some(link) = poses[self.checker.targets()[ti].link] else { return half * self.speeds[ti] };
        let reach = bounds.reach[ti];
        // Σ_i |Δq_i| r_ik over the joints between the current one and the link.
        let mut below = 0.0;
        let mut total = 0.0;
        for &(j, r) in &bounds.levers[ti] {
            let d = self.delta[j].abs();
            let joint = &robot.joints[j];
            let lever = match (joint.kind, poses[joint.child]) {
                (JointKind::Revolute | JointKind::Continuous, Some(child)) => {
                    let axis = child.rotation * Vector::new(joint.axis.x, joint.axis.y, joint.axis.z);
                    let rel = link.translation - child.translation;
                    let off_axis = (rel - axis * rel.dot(axis)).length();
                    r.min(off_axis + reach + half * below)
                }
                _ => r,
            };
            total += d * lever;
            below += d * r;
        }
        half * total
    }

    fn report_at(&self, s: f64) -> StateReport {
        self.checker.check_positions(&self.at(s)).unwrap_or_else(|e| StateReport::failed(e.to_string()))
    }

    /// In the frame of the last link upstream of both: only the joints that move one of the two
    /// and not the other count (a joint above both turns the pair as one body). Each with its
    /// lever bound over all configurations; the world bounds when those are smaller in sum.
    fn pair_bound(&self, a: usize, b: usize, poses: &[Option<Pose>], half: f64) -> (Real, Real) {
        let levers = &self.checker.motion_bounds().levers;
        let own = |x: usize, y: usize| -> Real {
            levers[x].iter().filter(|(j, _)| !levers[y].iter().any(|(k, _)| k == j)).map(|(j, r)| self.delta[*j].abs() * r).sum()
        };
        let relative = (half * own(a, b), half * own(b, a));
        let world = (self.bound(a, poses, half), self.bound(b, poses, half));
        if relative.0 + relative.1 <= world.0 + world.1 {
            relative
        } else {
            world
        }
    }
}

impl Checker {
    /// Checks the motion from `q0` to `q1` (positions of every joint, as for
    /// [`Checker::check_positions`]): continuous joints along the shorter arc, mimic joints
    /// following their master. See the module documentation for what "free" and "colliding" mean.
    pub fn check_motion(&self, q0: &[f64], q1: &[f64]) -> MotionReport {
        let robot = self.robot();
        for q in [q0, q1] {
            if let Err(e) = robot.forward_kinematics(q, &nalgebra::Isometry3::identity()) {
                return MotionReport { report: StateReport { motion: true, ..StateReport::failed(e.to_string()) }, ..Default::default() };
            }
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
        let speeds = bounds.levers.iter().map(|l| l.iter().map(|(j, r)| delta[*j].abs() * r).sum()).collect();
        self.sweep_motion(&JointPath { checker: self, q0, delta, speeds })
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
