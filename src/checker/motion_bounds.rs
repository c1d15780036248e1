//! What the motion checks precompute per checked link: the lever of every joint that moves it,
//! its reach and bounding ball, and its parts grown by each rung of a growth ladder.

use super::link_targets::LinkTargets;
use crate::collision::{ConvexHull, TargetShape};
use crate::math::{pose_from_isometry, Pose, Real, Vector};
use crate::model::{JointKind, PoseKinematics, RobotModel};
use std::sync::{Arc, OnceLock};

/// Rungs of the growth ladder per doubling: growth `base · 2^(level / RUNGS)`. The growth used is
/// the first rung at or above the bound, so it overshoots by up to `2^(1/RUNGS)`; a grown link
/// that overshoots touches more and splits more often. On the motion benchmark (2,000 motions)
/// 1, 2 and 4 rungs took 158, 135 and 125 link tests per motion.
const RUNGS: usize = 4;

/// Levels of the growth ladder: from `base` (half the tolerance) to far past any accepted size.
const LEVELS: usize = 64 * RUNGS;

/// A target's grown parts: per part, per level of the ladder, built on first use.
pub(crate) type Ladder = Vec<Vec<OnceLock<TargetShape>>>;

/// What the motion check precomputes per checked link: the lever of every joint that moves it,
/// and its parts grown by each step of the ladder (built on first use).
#[derive(Clone, Debug)]
pub(crate) struct MotionBounds {
    /// Per target (as `Checker::targets`): (joint index, lever in metres; 1 for prismatic).
    pub(super) levers: Vec<Vec<(usize, Real)>>,
    /// Per target, per entry of `levers`: the lever that bounds how fast the joint moves the
    /// target's points in every configuration. For a revolute joint whose child link is the
    /// target's link or fixed to it, the smaller of `levers`' and the farthest any of the
    /// target's points lies from the joint's axis (the same in every configuration: a link
    /// turning about its own long axis, a forearm or a wrist, moves its points far less than its
    /// reach from the joint's origin); else `levers`'. (`levers` itself bounds the distance from
    /// the joint's origin, which `point_acceleration` needs.)
    pub(super) steady: Vec<Vec<Real>>,
    /// Per target: the farthest any of its points lies from its link's origin.
    pub(super) reach: Vec<Real>,
    /// Per target: a point fixed to its link (link frame) and the farthest any of the target's
    /// points lies from it, for the first-order bound of `JointPath::bound`.
    pub(super) ball: Vec<(Vector, Real)>,
    /// Per target, per part, per level: the part grown by `base · 2^level`. Shared by the
    /// checkers whose targets are the same link with the same parts (see [`MotionBounds::new`]).
    pub(super) grown: Vec<Arc<Ladder>>,
    /// The joints' frames, for the motion loop's forward kinematics.
    pub(super) frames: PoseKinematics,
    /// Where target `t`'s per-joint prefixes (`levers[t].len() + 1` of them, over its first `k`
    /// joints at `[k]`) start in a motion's flat arrays; the last entry is their total.
    pub(super) prefix_start: Vec<usize>,
    /// Per pair of targets `(x, y)`, at `x * targets + y`: see [`MotionBounds::unshared`].
    unshared: Vec<usize>,
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
        TargetShape::Swept { core, sweep } => core.points().iter().map(|p| p.length()).fold(0.0, Real::max) + sweep.length(),
    };
    offset.translation.length() + own
}

/// The farthest any point of a part (posed by `offset` in a frame) lies from the line through
/// that frame's origin along unit `axis`: exact over a hull's points, else through the part's
/// bounding ball.
fn part_axis_reach(shape: &TargetShape, offset: &Pose, axis: Vector) -> Real {
    let off_axis = |p: Vector| (p - axis * p.dot(axis)).length();
    match shape {
        TargetShape::Polytope(h) => h.points().iter().map(|p| off_axis(*offset * *p)).fold(0.0, Real::max),
        _ => off_axis(*offset * shape.centre()) + shape.bounding_radius(),
    }
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

/// `shape ⊕ ball(pad)` or a superset: a hull as [`ConvexHull::grown_by_ball`] makes it (exact
/// supports, the cube-grown polytope for the separating-axis test); primitives grown in closed
/// form.
pub(super) fn grow(shape: &TargetShape, pad: Real) -> TargetShape {
    match shape {
        TargetShape::Sphere { radius } => TargetShape::Sphere { radius: radius + pad },
        TargetShape::Capsule { half_height, radius } => TargetShape::Capsule { half_height: *half_height, radius: radius + pad },
        TargetShape::Cylinder { half_height, radius } => TargetShape::Cylinder { half_height: half_height + pad, radius: radius + pad },
        TargetShape::Polytope(h) => {
            match ConvexHull::grown_by_ball(h, pad) {
                Some(g) => TargetShape::Polytope(Arc::new(g)),
                // A ball around the hull contains it grown as well.
                None => TargetShape::Sphere { radius: h.points().iter().map(|p| p.length()).fold(0.0, Real::max) + pad * 3f64.sqrt() },
            }
        }
        TargetShape::Swept { core, sweep } => match grow(&TargetShape::Polytope(core.clone()), pad) {
            TargetShape::Polytope(grown) => TargetShape::Swept { core: grown, sweep: *sweep },
            other => TargetShape::Sphere { radius: other.bounding_radius() + sweep.length() },
        },
    }
}

impl MotionBounds {
    /// `kept`: the ladders of the first targets, from another checker whose first targets are
    /// these (the robot's links, before objects were attached or detached): what either builds,
    /// both have.
    pub(crate) fn new(robot: &RobotModel, targets: &[LinkTargets], tolerance: Real, kept: &[Arc<Ladder>]) -> MotionBounds {
        let mut levers = Vec::with_capacity(targets.len());
        let mut steady = Vec::with_capacity(targets.len());
        let mut reaches = Vec::with_capacity(targets.len());
        for t in targets {
            let reach = t.parts.iter().map(|(s, o)| part_reach(s, o)).fold(0.0, Real::max);
            reaches.push(reach);
            // Walk up from the link: `chain` is the farthest the link's origin can be from the
            // origin of the joint reached so far, in any configuration.
            let mut chain = 0.0;
            let mut list = Vec::new();
            let mut own_steady = Vec::new();
            // The target's link frame in the frame of `link`, while only fixed joints lie between.
            let mut rigid = Some(Pose::IDENTITY);
            let mut link = t.link;
            let mut steps = 0;
            while let Some(j) = robot.parent_joint(link) {
                let joint = &robot.joints[j];
                match joint.kind {
                    JointKind::Revolute | JointKind::Continuous => {
                        list.push((j, chain + reach));
                        // The axis is fixed in the joint's child frame, which is `link`'s.
                        let axis = Vector::new(joint.axis.x, joint.axis.y, joint.axis.z);
                        let on_axis = rigid.map_or(Real::INFINITY, |r| t.parts.iter().map(|(s, o)| part_axis_reach(s, &(r * *o), axis)).fold(0.0, Real::max));
                        own_steady.push((chain + reach).min(on_axis));
                    }
                    JointKind::Prismatic => {
                        list.push((j, 1.0));
                        own_steady.push(1.0);
                    }
                    JointKind::Fixed | JointKind::Floating | JointKind::Planar => {}
                }
                rigid = match joint.kind {
                    JointKind::Fixed => rigid.map(|r| pose_from_isometry(&joint.origin) * r),
                    _ => None,
                };
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
            steady.push(own_steady);
        }
        let grown = targets
            .iter()
            .enumerate()
            .map(|(t, parts)| match kept.get(t) {
                Some(ladder) => Arc::clone(ladder),
                None => Arc::new(parts.parts.iter().map(|_| (0..LEVELS).map(|_| OnceLock::new()).collect()).collect()),
            })
            .collect();
        let ball = targets.iter().map(|t| target_ball(&t.parts)).collect();
        let prefix_start = std::iter::once(0)
            .chain(levers.iter().scan(0, |at, l| {
                *at += l.len() + 1;
                Some(*at)
            }))
            .collect();
        let n = levers.len();
        let unshared = (0..n * n)
            .map(|xy| {
                let (x, y): (usize, usize) = (xy / n, xy % n);
                levers[x].iter().take_while(|(j, _)| !levers[y].iter().any(|(k, _)| k == j)).count()
            })
            .collect();
        MotionBounds { levers, steady, reach: reaches, ball, grown, frames: robot.pose_kinematics(), prefix_start, unshared, base: tolerance / 2.0 }
    }

    /// Builds every part's grown shapes up to the level that covers `up_to` (see
    /// [`crate::checker::Checker::prepare_motion_checks`]).
    pub(super) fn build_ladder(&self, targets: &[LinkTargets], up_to: Real) {
        let top = self.level(up_to);
        for (t, grown) in targets.iter().zip(&self.grown) {
            for ((shape, _), levels) in t.parts.iter().zip(grown.iter()) {
                for (level, slot) in levels.iter().enumerate().take(top + 1) {
                    let _ = slot.get_or_init(|| grow(shape, self.growth(level)));
                }
            }
        }
    }

    /// Whether every part's grown shapes up to the level that covers `up_to` are built (what
    /// [`MotionBounds::build_ladder`] leaves).
    #[cfg(test)]
    pub(super) fn ladder_built(&self, up_to: Real) -> bool {
        let top = self.level(up_to);
        self.grown.iter().flat_map(|ladder| ladder.iter()).all(|levels| levels.iter().take(top + 1).all(|slot| slot.get().is_some()))
    }

    /// How many of target `x`'s joints (nearest first) come before the first that moves target
    /// `y` too: the joints a pair's two links share are the end of each one's list, and they move
    /// the pair as one body.
    pub(super) fn unshared(&self, x: usize, y: usize) -> usize {
        self.unshared[x * self.levers.len() + y]
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
