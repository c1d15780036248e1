//! A trajectory segment as the controller executes it: every joint on its own polynomial in the
//! segment's parameter `s` (`spline_poly`), checked with the adaptive loop of the motion check
//! (`motion_sweep`) and the same guarantee: "free" is certain for every instant of the segment,
//! and a reported fraction is never later than the first contact.
//!
//! Over a stretch `[a, b]` with middle `m`, joint `j` strays from `q_j(m)` by at most its
//! excursion `e_j = max |q_j(s') − q_j(m)|` over `s'` in `[a, b]`, found exactly from the
//! polynomial (its extremes lie at the ends or at roots of its derivative). Any configuration
//! of the stretch is then reachable from the one at `m` by a straight joint-space move of at
//! most `e_j` per joint, so every point of link `k` lies within `Σ_j e_j · r_jk` of where it is at
//! `m` (the lever bounds of `joint_motion`, tightened the same way with the configuration at
//! `m`). With a path tolerance `τ_j` (a controller may stray that far from the path) the
//! excursion is `e_j + τ_j`: the link at `m` grown by the bound holds the whole tube, and a
//! stretch whose bound is within the ladder's first rung of the tolerance's own share cannot be
//! narrowed (`MotionPath::floor`).

use super::checker::Checker;
use super::joint_motion::axis_and_offset;
use super::motion_sweep::{MotionPath, MotionReport};
use super::spline_poly::SegmentPoly;
use super::state_report::StateReport;
use crate::math::{pose_from_isometry, Pose, Real, Vector};
use crate::model::JointKind;
use std::cell::RefCell;

/// One segment of an executed trajectory, in joint space.
#[derive(Clone, Debug, PartialEq)]
pub struct SplineSegment {
    /// Per joint of the robot (indexed like its `joints`): the position over the segment. Only
    /// actuated joints' are read; mimic joints follow their master.
    pub joints: Vec<SegmentPoly>,
    /// Per joint: how far the executed path may stray from these polynomials (radians or
    /// metres); empty for none.
    pub tolerance: Vec<f64>,
}

impl SplineSegment {
    /// Positions of every joint at `s` (mimics from their master, as forward kinematics has them).
    pub fn at(&self, s: f64) -> Vec<f64> {
        self.joints.iter().map(|p| p.at(s)).collect()
    }
}

/// A segment as the adaptive loop sees it.
pub(super) struct SplinePath<'a> {
    checker: &'a Checker,
    segment: &'a SplineSegment,
    /// Per joint (mimics resolved): the polynomial, its turning points, its tolerance.
    polys: Vec<SegmentPoly>,
    turning: Vec<Vec<f64>>,
    tolerance: Vec<f64>,
    /// Per joint: the first and second derivatives, each with its turning points.
    rates: Vec<[(SegmentPoly, Vec<f64>); 2]>,
    /// Per target: `Σ_j (top speed_j + τ_j) r_jk`, positive whenever the target can move.
    speeds: Vec<Real>,
    /// Per target: `Σ_j τ_j r_jk`.
    floors: Vec<Real>,
    /// Per target: the levers of `MotionBounds`, each revolute joint's grown by how far a
    /// prismatic joint below it strays past its limits on this segment (the levers assume the
    /// limits; a spline can overshoot them).
    levers: Vec<Vec<(usize, Real)>>,
    /// What the stretch last asked about holds for every target and pair asked there (the loop
    /// examines a stretch's targets and pairs together).
    stretch: RefCell<StretchBounds>,
}

/// Per joint, over one stretch: its excursion (see [`SplinePath::excursions`]), its rate at
/// the middle, and the largest magnitude of its first and second derivatives; per target, its
/// bound once found.
#[derive(Default)]
struct StretchBounds {
    /// The bits of the stretch's middle and half-width (`None`: none yet).
    key: Option<(u64, u64)>,
    excursions: Vec<f64>,
    rate: Vec<f64>,
    top: Vec<f64>,
    acceleration: Vec<f64>,
    bound: Vec<Option<Real>>,
}

impl SplinePath<'_> {
    /// The stretch of half-width `half` about `mid`'s [`StretchBounds`], found once.
    fn stretch(&self, mid: f64, half: f64) -> std::cell::RefMut<'_, StretchBounds> {
        let mut kept = self.stretch.borrow_mut();
        let key = Some((mid.to_bits(), half.to_bits()));
        if kept.key != key {
            let k = &mut *kept;
            k.key = key;
            let (a, b) = ((mid - half).max(0.0), (mid + half).min(1.0));
            k.excursions.clear();
            k.excursions.extend(self.excursions(mid, half));
            k.rate.clear();
            k.top.clear();
            k.acceleration.clear();
            for [(d1, t1), (d2, t2)] in &self.rates {
                k.rate.push(d1.at(mid));
                k.top.push(d1.max_abs(t1, a, b));
                k.acceleration.push(d2.max_abs(t2, a, b));
            }
            k.bound.clear();
            k.bound.resize(self.speeds.len(), None);
        }
        kept
    }

    /// Per joint: the excursion over `[mid - half, mid + half]` (within `[0, 1]`), grown by its
    /// tolerance, with a margin for the rounding of the polynomial's evaluation.
    fn excursions(&self, mid: f64, half: f64) -> impl Iterator<Item = f64> + '_ {
        let (a, b) = ((mid - half).max(0.0), (mid + half).min(1.0));
        self.polys.iter().zip(&self.turning).zip(&self.tolerance).map(move |((p, t), tol)| {
            let e = p.excursion(t, mid, a, b);
            e + tol + 1e-12 * (1.0 + p.at(mid).abs())
        })
    }

    /// Per joint that moves target `ti` and not target `other`, the sum of excursion times lever.
    fn own(&self, x: usize, y: usize, e: &[f64]) -> Real {
        self.levers[x].iter().take(self.checker.motion_bounds().unshared(x, y)).map(|(j, r)| e[*j] * r).sum()
    }

    fn bound_with(&self, ti: usize, poses: &[Option<Pose>], e: &[f64]) -> Real {
        let robot = self.checker.robot();
        let bounds = self.checker.motion_bounds();
        let plain: Real = self.levers[ti].iter().map(|(j, r)| e[*j] * r).sum();
        let Some(link) = poses[self.checker.targets()[ti].link] else { return plain };
        let reach = bounds.reach[ti];
        // As in `JointPath::bound`: a joint's lever is at most the distance from its axis to the
        // link's origin at the middle plus the link's reach, plus what the joints between it and
        // the link can change that distance by on the stretch.
        let (mut below, mut total) = (0.0, 0.0);
        for &(j, r) in &self.levers[ti] {
            let joint = &robot.joints[j];
            let lever = match (joint.kind, poses[joint.child]) {
                (JointKind::Revolute | JointKind::Continuous, Some(child)) => {
                    let (_, off_axis) = axis_and_offset(joint, &child, &link);
                    r.min(off_axis + reach + below)
                }
                _ => r,
            };
            total += e[j] * lever;
            below += e[j] * r;
        }
        // NaN (a bad pose) falls back to the plain lever bound.
        if total < plain {
            total
        } else {
            plain
        }
    }

    /// The first-order bound of [`MotionPath::bound`], without the tolerance's share, from the
    /// stretch's rates.
    fn first_order(&self, ti: usize, poses: &[Option<Pose>], half: f64, at: &StretchBounds) -> Real {
        let robot = self.checker.robot();
        let bounds = self.checker.motion_bounds();
        let Some(link) = poses[self.checker.targets()[ti].link] else { return Real::INFINITY };
        let (centre, radius) = bounds.ball[ti];
        let c = link * centre;
        let (mut omega, mut velocity, mut rates) = (Vector::ZERO, Vector::ZERO, 0.0);
        for &(j, r) in &self.levers[ti] {
            let joint = &robot.joints[j];
            let rate = at.rate[j];
            rates += at.acceleration[j] * r;
            let Some(child) = poses[joint.child] else { return Real::INFINITY };
            let axis = child.rotation * Vector::new(joint.axis.x, joint.axis.y, joint.axis.z);
            match joint.kind {
                JointKind::Revolute | JointKind::Continuous => {
                    omega += axis * rate;
                    velocity += axis.cross(c - child.translation) * rate;
                }
                JointKind::Prismatic => velocity += axis * rate,
                _ => {}
            }
        }
        let speed: Real = self.levers[ti].iter().map(|(j, r)| at.top[*j] * r).sum();
        let acceleration = rates + super::joint_motion::point_acceleration(robot, &self.levers[ti], &at.top, speed);
        half * (velocity.length() + omega.length() * radius) + 0.5 * half * half * acceleration
    }

    /// [`MotionPath::bound`] at the stretch `at`, found once per target.
    fn bound_at(&self, ti: usize, poses: &[Option<Pose>], half: f64, at: &mut StretchBounds) -> Real {
        if let Some(b) = at.bound[ti] {
            return b;
        }
        let levers = self.bound_with(ti, poses, &at.excursions);
        let first_order = self.first_order(ti, poses, half, at) + self.floors[ti];
        // NaN (a bad pose) falls back to the lever bound.
        let b = if first_order < levers { first_order } else { levers };
        at.bound[ti] = Some(b);
        b
    }
}

impl MotionPath for SplinePath<'_> {
    fn speeds(&self) -> &[Real] {
        &self.speeds
    }

    fn link_poses(&self, s: f64) -> Result<Vec<Option<Pose>>, String> {
        let poses = self.checker.robot().forward_kinematics(&self.segment.at(s), self.checker.base_pose()).map_err(|e| e.to_string())?;
        Ok(poses.iter().map(|p| Some(pose_from_isometry(p))).collect())
    }

    /// The smaller of the lever bound over the joints' excursions and a first-order one: the
    /// link's points move at most `h·(|v_c| + |ω| R) + h²/2 · A` from where they are at the
    /// middle, with the velocity of a point `c` of the link and its angular velocity at the
    /// middle, `R` the radius of a ball about `c` holding the link, and `A` a bound on the
    /// acceleration of its points over the stretch: `p̈ = Σ_j q̈_j u_j + Σ_j q̇_j u̇_j`, so the
    /// largest `|q̈_j|` times the lever plus `point_acceleration` at the largest `|q̇_j|` (both
    /// over the stretch, from the polynomials). Plus the tolerance's share, which no stretch
    /// narrows.
    fn bound(&self, ti: usize, poses: &[Option<Pose>], mid: f64, half: f64) -> Real {
        self.bound_at(ti, poses, half, &mut self.stretch(mid, half))
    }

    fn out_of_limits(&self, s: f64) -> Vec<String> {
        self.checker.out_of_limits(&self.segment.at(s))
    }

    fn report_at(&self, s: f64) -> StateReport {
        self.checker.check_positions(&self.segment.at(s)).unwrap_or_else(|e| StateReport::failed(e.to_string()))
    }

    fn floor(&self, ti: usize) -> Real {
        self.floors[ti]
    }

    /// The relative bounds of `JointPath::pair_bound` when there is no tolerance (the joints
    /// above both links move the pair as one body); with one, the world bounds, whose floor
    /// [`MotionPath::floor`] gives.
    fn pair_bound(&self, a: usize, b: usize, poses: &[Option<Pose>], mid: f64, half: f64) -> (Real, Real) {
        let mut at = self.stretch(mid, half);
        let world = (self.bound_at(a, poses, half, &mut at), self.bound_at(b, poses, half, &mut at));
        if self.floors[a] > 0.0 || self.floors[b] > 0.0 {
            return world;
        }
        let relative = (self.own(a, b, &at.excursions), self.own(b, a, &at.excursions));
        if relative.0 + relative.1 <= world.0 + world.1 {
            relative
        } else {
            world
        }
    }

    /// Without a tolerance, the relative lever sums of [`SplinePath::pair_bound`] alone (no
    /// pose is read); with one, its world bounds.
    fn pair_bound_quick(&self, a: usize, b: usize, poses: &[Option<Pose>], mid: f64, half: f64) -> (Real, Real) {
        if self.floors[a] > 0.0 || self.floors[b] > 0.0 {
            return self.pair_bound(a, b, poses, mid, half);
        }
        let at = self.stretch(mid, half);
        (self.own(a, b, &at.excursions), self.own(b, a, &at.excursions))
    }
}

impl Checker {
    /// Checks one executed trajectory segment (see the module documentation): the first
    /// fraction of `s` not cleared, the contacts there, or free.
    pub fn check_spline(&self, segment: &SplineSegment) -> MotionReport {
        match self.spline_path(segment) {
            Ok(path) => self.sweep_motion(&path),
            Err(e) => MotionReport { report: StateReport { motion: true, ..StateReport::failed(e) }, ..Default::default() },
        }
    }

    pub(super) fn spline_path<'a>(&'a self, segment: &'a SplineSegment) -> Result<SplinePath<'a>, String> {
        let robot = self.robot();
        let n = robot.joints.len();
        if segment.joints.len() != n {
            return Err(format!("the segment gives {} joints; the robot has {n}", segment.joints.len()));
        }
        if !segment.tolerance.is_empty() && segment.tolerance.len() != n {
            return Err(format!("the segment gives {} tolerances; the robot has {n} joints", segment.tolerance.len()));
        }
        if let Some((j, _)) = segment.joints.iter().enumerate().find(|(_, p)| p.c.iter().any(|c| !c.is_finite())) {
            return Err(format!("joint '{}': the segment's polynomial is not finite", robot.joints[j].name));
        }
        let moves = |j: usize| matches!(robot.joints[j].kind, JointKind::Revolute | JointKind::Continuous | JointKind::Prismatic);
        let mut polys: Vec<SegmentPoly> = (0..n).map(|j| if moves(j) { segment.joints[j] } else { SegmentPoly::constant(0.0) }).collect();
        let mut tolerance: Vec<f64> = (0..n).map(|j| if moves(j) { segment.tolerance.get(j).copied().unwrap_or(0.0) } else { 0.0 }).collect();
        if let Some(t) = tolerance.iter().find(|t| !(t.is_finite() && **t >= 0.0)) {
            return Err(format!("a path tolerance of {t} (allowed: finite, at least 0)"));
        }
        for (i, j) in robot.joints.iter().enumerate() {
            if let Some(m) = j.mimic {
                polys[i] = polys[m.joint].scaled(m.multiplier, m.offset);
                tolerance[i] = m.multiplier.abs() * tolerance[m.joint];
            }
        }
        let turning: Vec<Vec<f64>> = polys.iter().map(SegmentPoly::turning_points).collect();
        let rates = polys
            .iter()
            .map(|p| {
                let (d1, d2) = (p.derivative(), p.derivative().derivative());
                [(d1, d1.turning_points()), (d2, d2.turning_points())]
            })
            .collect();
        let top: Vec<f64> = polys.iter().map(SegmentPoly::top_speed).collect();
        // How far each prismatic joint strays past the larger magnitude of its limits.
        let overshoot: Vec<f64> = (0..n)
            .map(|j| {
                let joint = &robot.joints[j];
                if joint.kind != JointKind::Prismatic {
                    return 0.0;
                }
                let (lo, hi) = polys[j].range(&turning[j]);
                let reach = lo.abs().max(hi.abs()) + tolerance[j];
                (reach - joint.limits[0].abs().max(joint.limits[1].abs())).max(0.0)
            })
            .collect();
        let levers: Vec<Vec<(usize, Real)>> = self
            .motion_bounds()
            .levers
            .iter()
            .map(|list| {
                // Nearest first: a prismatic joint lengthens the levers of the joints above it.
                let mut extra = 0.0;
                list.iter()
                    .map(|&(j, r)| {
                        let r = if robot.joints[j].kind == JointKind::Prismatic { r } else { r + extra };
                        extra += overshoot[j];
                        (j, r)
                    })
                    .collect()
            })
            .collect();
        let speeds = levers.iter().map(|l| l.iter().map(|(j, r)| (top[*j] + tolerance[*j]) * r).sum()).collect();
        let floors = levers.iter().map(|l| l.iter().map(|(j, r)| tolerance[*j] * r).sum()).collect();
        Ok(SplinePath { checker: self, segment, polys, turning, tolerance, rates, speeds, floors, levers, stretch: RefCell::default() })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::checker::test_points::{largest_pair_change, part_points};
    use crate::model::Params;

    /// A random segment of `robot`: quintic, cubic or linear by `case`, every fifth out and
    /// back (its extreme inside), every other with a random path tolerance per joint.
    fn random_segment(robot: &crate::model::RobotModel, case: usize, draw: &mut impl FnMut(f64, f64) -> f64) -> SplineSegment {
        let duration = draw(0.2, 2.0);
        let joints: Vec<SegmentPoly> = robot
            .joints
            .iter()
            .map(|j| {
                let [lo, hi] = j.limits;
                let (lo, hi) = if lo.is_finite() && hi.is_finite() { (lo, hi) } else { (-3.0, 3.0) };
                let (p0, mut p1) = (draw(lo, hi), draw(lo, hi));
                let (mut v0, mut v1, a0, a1) = (draw(-2.0, 2.0), draw(-2.0, 2.0), draw(-8.0, 8.0), draw(-8.0, 8.0));
                if case.is_multiple_of(5) {
                    (p1, v0, v1) = (p0, 2.0 * duration, -2.0 * duration);
                }
                match case % 3 {
                    0 => SegmentPoly::quintic(p0, v0, a0, p1, v1, a1, duration),
                    1 => SegmentPoly::cubic(p0, v0, p1, v1, duration),
                    _ => SegmentPoly::linear(p0, p1),
                }
            })
            .collect();
        let tolerance = if case.is_multiple_of(2) { Vec::new() } else { robot.joints.iter().map(|_| draw(0.0, 0.05)).collect() };
        SplineSegment { joints, tolerance }
    }

    /// The self pairs' bounds on a spline, checked directly: within a stretch, no distance
    /// between a point of one link of a pair and a point of the other changes by more than the
    /// sum of the pair's bounds, the quick ones (the relative lever sums) or the full ones, over
    /// random segments of the bundled arm, with and without a tolerance (then at configurations
    /// of the tube too).
    #[test]
    fn no_distance_within_a_self_pair_leaves_its_bounds_on_a_spline() {
        let c = Checker::from_params(Params::default()).unwrap();
        let robot = c.robot();
        let mut rng = oorandom::Rand64::new(45);
        let mut draw = |lo: f64, hi: f64| lo + (hi - lo) * rng.rand_float();
        let points: Vec<Vec<Vector>> = c.targets().iter().map(|t| t.parts.iter().flat_map(|(shape, offset)| part_points(shape, offset)).collect()).collect();
        let (mut checked, mut tightest) = (0usize, 0.0f64);
        for case in 0..120 {
            let segment = random_segment(robot, case, &mut draw);
            let path = c.spline_path(&segment).unwrap();
            let half = [0.5, 0.2, 0.05, 0.01][case % 4];
            let s = draw(0.0, 1.0);
            let poses = path.link_poses(s).unwrap();
            let others: Vec<Vec<Option<Pose>>> = (0..=8)
                .map(|k| {
                    let mut q = segment.at((s - half + 2.0 * half * k as f64 / 8.0).clamp(0.0, 1.0));
                    q.iter_mut().zip(&segment.tolerance).for_each(|(x, t)| *x += t * [-1.0, 1.0, 0.3][k % 3]);
                    robot.forward_kinematics(&q, c.base_pose()).unwrap().iter().map(|p| Some(pose_from_isometry(p))).collect()
                })
                .collect();
            for &(a, b) in &c.self_pairs().pairs {
                let (qa, qb) = path.pair_bound_quick(a, b, &poses, s, half);
                let (da, db) = path.pair_bound(a, b, &poses, s, half);
                let (la, lb) = (c.targets()[a].link, c.targets()[b].link);
                let largest = largest_pair_change(&points[a], la, &points[b], lb, &poses, &others);
                assert!(largest <= qa + qb + 1e-9, "case {case}, pair ({a}, {b}): a distance changed by {largest}, quick bounds {qa} + {qb}");
                assert!(largest <= da + db + 1e-9, "case {case}, pair ({a}, {b}): a distance changed by {largest}, bounds {da} + {db}");
                if da + db > 0.0 {
                    tightest = tightest.max(largest / (da + db));
                }
                checked += 1;
            }
        }
        assert!(checked > 200 && tightest > 0.3, "{checked} pair stretches, largest change / bound {tightest}");
        eprintln!("{checked} pair stretches, largest change / bound {tightest:.3}");
    }

    /// The bound the adaptive loop trusts, checked directly: over random quintic, cubic and linear
    /// segments of the bundled arm (revolute, continuous, prismatic and mimic joints), with and
    /// without a tolerance, no point of any link, sampled along a stretch (and, with a tolerance,
    /// at random configurations of the tube around it), lies farther from where it is at the
    /// stretch's middle than the bound.
    #[test]
    fn no_point_of_a_link_leaves_its_bound_on_a_spline() {
        let c = Checker::from_params(Params::default()).unwrap();
        let robot = c.robot();
        let mut rng = oorandom::Rand64::new(34);
        let mut draw = |lo: f64, hi: f64| lo + (hi - lo) * rng.rand_float();
        let (mut checked, mut tightest) = (0usize, 0.0f64);
        for case in 0..300 {
            let segment = random_segment(robot, case, &mut draw);
            let tolerance = segment.tolerance.clone();
            let path = c.spline_path(&segment).unwrap();
            let half = [0.5, 0.2, 0.05, 0.01][checked % 4];
            let s = draw(0.0, 1.0);
            let poses = path.link_poses(s).unwrap();
            for (ti, t) in c.targets().iter().enumerate() {
                let bound = path.bound(ti, &poses, s, half);
                let points: Vec<Vector> = t.parts.iter().flat_map(|(shape, offset)| part_points(shape, offset)).collect();
                let at = poses[t.link].unwrap();
                let mut farthest = 0.0f64;
                for k in 0..=24 {
                    let other = (s - half + 2.0 * half * k as f64 / 24.0).clamp(0.0, 1.0);
                    let mut q = segment.at(other);
                    if !tolerance.is_empty() {
                        q.iter_mut().zip(&tolerance).for_each(|(x, t)| *x += t * [-1.0, 1.0, 0.3, -0.7][k % 4]);
                    }
                    let pose = pose_from_isometry(&robot.forward_kinematics(&q, c.base_pose()).unwrap()[t.link]);
                    for p in &points {
                        farthest = farthest.max(((pose * *p) - (at * *p)).length());
                    }
                }
                assert!(farthest <= bound + 1e-9, "case {case}: link '{}' moved {farthest} m within {half} of s = {s}, bound {bound}", t.name);
                if bound > 0.0 {
                    tightest = tightest.max(farthest / bound);
                }
            }
            checked += 1;
        }
        assert!(tightest > 0.3, "largest motion / bound {tightest}");
        eprintln!("{checked} stretches, largest motion / bound {tightest:.3}");
    }
}
