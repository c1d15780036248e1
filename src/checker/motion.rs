//! Motions: the straight line in joint space between two states, checked so that no crossing is
//! missed (adaptive conservative checking, after Schwarzer, Saha and Latombe, IEEE T-RO 21(3),
//! 2005).
//!
//! Over a sub-interval `[a, b]` of the motion parameter, every point of link `k` stays within
//! `δ_k = (b - a)/2 · Σ_j |Δq_j| · r_jk` of where it is at the middle (`r_jk` bounds the distance
//! from joint `j`'s axis to any point of the link in every configuration; 1 for a prismatic
//! joint). The link at the middle, grown by `δ_k`, contains every pose of the link on `[a, b]`:
//! if the grown link touches nothing, the sub-interval is free for that link. Otherwise the
//! sub-interval is halved, left half first, until the growth falls under `motion_tolerance`:
//! that sub-interval is reported colliding. So "free" is certain, and a reported fraction is
//! never later than the first contact.

use super::checker_build::{Checker, LinkTargets};
use super::state_report::{ReportContact, StateReport};
use crate::collision::{CollideSettings, ConvexHull, Target, TargetShape};
use crate::math::{pose_from_isometry, Pose, Real, Vector};
use crate::model::{JointKind, RobotModel};
use std::sync::{Arc, OnceLock};

/// Sub-intervals examined at most per motion; past that the motion fails closed.
pub const MAX_SUBINTERVALS: u64 = 1 << 20;

/// Levels of the growth ladder: `base · 2^level` for level 0..LEVELS covers 1e-6 m to far past
/// any accepted size.
const LEVELS: usize = 64;

/// What a motion check gives.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MotionReport {
    /// `in_collision`, `contacts` (of the pose at `fraction`) and `error`, as for a state.
    pub report: StateReport,
    /// The start of the first sub-interval that could not be cleared, in [0, 1]; `None` when free
    /// or not checked.
    pub fraction: Option<f64>,
    /// Sub-intervals examined.
    pub subintervals: u64,
}

/// What the motion check precomputes per checked link: the lever of every joint that moves it,
/// and its parts grown by each step of the ladder (built on first use).
#[derive(Clone, Debug)]
pub(crate) struct MotionBounds {
    /// Per target (as `Checker::targets`): (joint index, lever in metres; 1 for prismatic).
    levers: Vec<Vec<(usize, Real)>>,
    /// Per target, per part, per level: the part grown by `base · 2^level`.
    grown: Vec<Vec<Vec<OnceLock<TargetShape>>>>,
    /// Growth of level 0: half the tolerance, so a level under the tolerance exists.
    base: Real,
    tolerance: Real,
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
fn grow(shape: &TargetShape, pad: Real) -> TargetShape {
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
        // The joint whose child each link is.
        let mut parent_joint = vec![None; robot.links.len()];
        for (j, joint) in robot.joints.iter().enumerate() {
            parent_joint[joint.child] = Some(j);
        }
        let mut levers = Vec::with_capacity(targets.len());
        for t in targets {
            let reach = t.parts.iter().map(|(s, o)| part_reach(s, o)).fold(0.0, Real::max);
            // Walk up from the link: `chain` is the farthest the link's origin can be from the
            // origin of the joint reached so far, in any configuration.
            let mut chain = 0.0;
            let mut list = Vec::new();
            let mut link = t.link;
            let mut steps = 0;
            while let Some(j) = parent_joint[link] {
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
        MotionBounds { levers, grown, base: tolerance / 2.0, tolerance }
    }

    /// The ladder level whose growth covers `delta`.
    fn level(&self, delta: Real) -> usize {
        if delta <= self.base {
            return 0;
        }
        ((delta / self.base).log2().ceil() as usize).min(LEVELS - 1)
    }

    fn growth(&self, level: usize) -> Real {
        self.base * Real::powi(2.0, level as i32)
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
        let at = |s: f64| -> Vec<f64> { q0.iter().zip(&delta).map(|(a, d)| a + s * d).collect() };
        let bounds = self.motion_bounds();
        // Per target: Σ_j |Δq_j| r_jk, the speed bound of its points per unit of s.
        let speed: Vec<Real> = bounds.levers.iter().map(|l| l.iter().map(|(j, r)| delta[*j].abs() * r).sum()).collect();
        let flags = CollideSettings { flag_only: true, least_overlap: false, ..Default::default() };

        let mut stack: Vec<(f64, f64, Vec<usize>)> = vec![(0.0, 1.0, (0..self.targets().len()).collect())];
        let mut examined = 0u64;
        while let Some((a, b, links)) = stack.pop() {
            examined += 1;
            if examined > MAX_SUBINTERVALS {
                let mut report = StateReport::failed(format!("the motion needs more than {MAX_SUBINTERVALS} sub-intervals to clear; not checked"));
                report.motion = true;
                return MotionReport { report, fraction: None, subintervals: examined };
            }
            let m = 0.5 * (a + b);
            let poses = match robot.forward_kinematics(&at(m), self.base_pose()) {
                Ok(p) => p,
                Err(e) => return MotionReport { report: StateReport::failed(e.to_string()), fraction: None, subintervals: examined },
            };
            let mut split = Vec::new();
            for &ti in &links {
                let lt = &self.targets()[ti];
                // A link no joint moves is where it is at every s: checked as it is, ungrown (a
                // base resting on a table is not a near miss).
                let level = (speed[ti] > 0.0).then(|| bounds.level(0.5 * (b - a) * speed[ti]));
                let link_pose = pose_from_isometry(&poses[lt.link]);
                let hit = self.grown_link_hit(ti, level, &link_pose, &flags);
                if !hit {
                    continue;
                }
                if level.is_none_or(|l| bounds.growth(l) < bounds.tolerance) {
                    return self.motion_contact(&at(a), ti, level, &link_pose, a, examined);
                }
                split.push(ti);
            }
            if !split.is_empty() {
                stack.push((m, b, split.clone()));
                stack.push((a, m, split));
            }
        }
        MotionReport { report: StateReport { motion: true, ..Default::default() }, fraction: None, subintervals: examined }
    }

    /// Target `ti`'s part `pi` grown by ladder `level` (as it is for `None`).
    fn grown_part(&self, ti: usize, pi: usize, level: Option<usize>) -> &TargetShape {
        let (shape, _) = &self.targets()[ti].parts[pi];
        match level {
            None => shape,
            Some(level) => {
                let bounds = self.motion_bounds();
                bounds.grown[ti][pi][level].get_or_init(|| grow(shape, bounds.growth(level)))
            }
        }
    }

    /// Whether target `ti`, every part grown by ladder `level`, touches anything it may not.
    fn grown_link_hit(&self, ti: usize, level: Option<usize>, link_pose: &Pose, settings: &CollideSettings) -> bool {
        self.targets()[ti].parts.iter().enumerate().any(|(pi, (_, offset))| {
            let target = Target::new(self.grown_part(ti, pi, level).clone(), *link_pose * *offset);
            !self.collide_target(ti, &target, settings).contacts.is_empty()
        })
    }

    /// The report of a motion found colliding on the sub-interval starting at `fraction`: the
    /// contacts of the pose there, or for a near miss the object the grown link touched, depth 0.
    fn motion_contact(&self, q: &[f64], ti: usize, level: Option<usize>, mid_pose: &Pose, fraction: f64, examined: u64) -> MotionReport {
        let mut report = match self.check_positions(q) {
            Ok(r) => r,
            Err(e) => StateReport::failed(e.to_string()),
        };
        if !report.contacts.iter().any(|c| c.link_name == self.targets()[ti].name) {
            let settings = CollideSettings { flag_only: false, least_overlap: false, ..Default::default() };
            let lt = &self.targets()[ti];
            let near = lt.parts.iter().enumerate().find_map(|(pi, (_, offset))| {
                self.collide_target(ti, &Target::new(self.grown_part(ti, pi, level).clone(), *mid_pose * *offset), &settings).deepest().copied()
            });
            if let Some(c) = near {
                report.contacts.push(ReportContact {
                    link_name: lt.name.clone(),
                    object_name: self.scene().objects()[c.object].name.clone(),
                    triangle: c.triangle,
                    depth: 0.0,
                    position: c.position.map(|p| p.to_array()),
                    normal: c.normal.to_array(),
                });
            }
        }
        report.in_collision = true;
        report.motion = true;
        report.fraction = Some(fraction);
        MotionReport { report, fraction: Some(fraction), subintervals: examined }
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
