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

use super::checker::Checker;
use super::motion_sweep::{MotionPath, MotionReport};
use super::state_report::StateReport;
use crate::math::{pose_from_isometry, Pose, Real, Vector};
use crate::model::{JointKind, RobotModel};
use std::cell::RefCell;

/// A motion in joint space: `q0 + s·delta`, link poses by forward kinematics.
struct JointPath<'a> {
    checker: &'a Checker,
    /// The robot's base in the world.
    base: Pose,
    q0: &'a [f64],
    delta: Vec<f64>,
    speeds: Vec<Real>,
    /// Per target: a bound on the acceleration of any of its points along `s` (see
    /// `point_acceleration`).
    accelerations: Vec<Real>,
    /// Per target: `Σ_j |Δq_j| r_j` over its first `k` joints (nearest first, the steady
    /// levers) at `[k]`; the last is its speed. A self pair's quick relative bound is such a
    /// prefix times the half-width.
    /// (Every per-target prefix array of a motion is one flat array: see
    /// `MotionBounds::prefix_start`.)
    steady_sums: Vec<Real>,
    /// Per target, at `[k]`: the acceleration bound of `point_acceleration` over its first `k`
    /// joints alone, what its points do in the frame above them (a self pair's relative
    /// first-order bound; see [`JointPath::pair_bound`]).
    relative_accelerations: Vec<Real>,
    /// Per target, the bounds last found for it (see [`Levered`]): the sweep examines a
    /// stretch's targets and pairs together, so a pair asks at the stretch its targets just
    /// answered.
    levered: RefCell<Levered>,
    /// Every joint's axis in the world at the stretch the targets were last asked at: each
    /// target's pass over its joints would turn the same axes again.
    axes: RefCell<StretchAxes>,
}

/// See [`JointPath::axes`].
#[derive(Default)]
struct StretchAxes {
    /// The bits of the stretch's middle and half-width (`None`: none yet).
    stretch: Option<(u64, u64)>,
    /// Per joint (zero when its child link has no pose).
    axes: Vec<Vector>,
}

/// What one pass over a target's joints gives at a stretch's middle, per target: the world
/// bound (the smaller of the lever sum and the first-order bound), and the lever sums of its
/// nearest joints, `prefix[k]` over the first `k` (times the half-width). A self pair's
/// relative bound is such a prefix: the joints a pair's two links share are the end of each
/// one's list. The prefixes of every target are one flat array (`MotionBounds::prefix_start`).
struct Levered {
    bounds: Vec<TargetBound>,
    prefix: Vec<Real>,
    /// At `[k]`: the angular velocity of the link and the velocity of its ball's centre that its
    /// first `k` joints give it (world frame, per unit of `s`); `None` from the first moving
    /// joint whose child has no pose on.
    moving: Vec<Option<(Vector, Vector)>>,
}

/// A target's world bound at a stretch (see [`Levered`]).
#[derive(Clone, Copy, Default)]
struct TargetBound {
    /// The stretch it is for: the bits of its middle and half-width (`None`: none yet).
    stretch: Option<(u64, u64)>,
    world: Real,
    /// When the first-order bound is the world bound: its translation part as a vector (the
    /// velocity of the ball's centre times the half-width, world frame) and the rest of it (see
    /// [`MotionPath::sweep`]).
    sweep: Option<(Vector, Real)>,
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
pub(super) fn point_acceleration(robot: &RobotModel, levers: &[(usize, Real)], delta: &[f64], speed: Real) -> Real {
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

/// A revolute joint's axis in the world (its child link at `child`), and how far the origin of a
/// link at `link` lies from that axis: what a lever is tightened to at the middle of a stretch.
pub(super) fn axis_and_offset(joint: &crate::model::JointModel, child: &Pose, link: &Pose) -> (Vector, Real) {
    let axis = child.rotation * Vector::new(joint.axis.x, joint.axis.y, joint.axis.z);
    (axis, distance_from_axis(axis, child.translation, link.translation))
}

/// How far `point` lies from the line through `through` along unit `axis`.
fn distance_from_axis(axis: Vector, through: Vector, point: Vector) -> Real {
    let rel = point - through;
    (rel - axis * rel.dot(axis)).length()
}

/// What the joints below a target do to it at the middle of a stretch (see `JointPath::bound`).
struct Moved {
    /// The link's angular velocity, and the velocity of the centre of its ball.
    omega: Vector,
    velocity: Vector,
    /// Every joint that moves was posed (else only the lever sum holds).
    first_order: bool,
}

impl JointPath<'_> {
    fn at(&self, s: f64) -> Vec<f64> {
        self.q0.iter().zip(&self.delta).map(|(a, d)| a + s * d).collect()
    }

    /// Target `ti`'s joints, nearest first: the lever sums over the first `k` of them, each lever
    /// the smaller of its steady bound and the distance from the axis to the link's origin (or
    /// its ball's centre) at the middle, plus the link's reach (or the ball's radius), plus what
    /// the joints between can change that within `half`; and the velocities at the middle, of the
    /// link's rotation and of its ball's centre.
    /// `prefix` gets `Σ_j |Δq_j| · lever_j` over the first `k` joints at `[k]`; the last is the
    /// whole sum.
    fn levers_at(
        &self,
        ti: usize,
        link: Pose,
        poses: &[Option<Pose>],
        (mid, half): (f64, f64),
        prefix: &mut [Real],
        moving: &mut [Option<(Vector, Vector)>],
    ) -> Moved {
        let robot = self.checker.robot();
        let bounds = self.checker.motion_bounds();
        let mut axes = self.axes.borrow_mut();
        let stretch = Some((mid.to_bits(), half.to_bits()));
        if axes.stretch != stretch {
            axes.stretch = stretch;
            axes.axes.clear();
            axes.axes.extend(robot.joints.iter().enumerate().map(|(j, joint)| match poses[joint.child] {
                Some(child) => child.rotation * bounds.frames.axis(j),
                None => Vector::ZERO,
            }));
        }
        let reach = bounds.reach[ti];
        let (centre, radius) = bounds.ball[ti];
        let centre = link * centre;
        // Σ_i |Δq_i| r_ik over the joints between the current one and the link.
        let mut below = 0.0;
        let mut moved = Moved { omega: Vector::ZERO, velocity: Vector::ZERO, first_order: true };
        prefix[0] = 0.0;
        moving[0] = Some((Vector::ZERO, Vector::ZERO));
        let mut sum = 0.0;
        for (k, (&(j, _), &r)) in bounds.levers[ti].iter().zip(&bounds.steady[ti]).enumerate() {
            let d = self.delta[j].abs();
            let joint = &robot.joints[j];
            let lever = match (joint.kind, poses[joint.child]) {
                (JointKind::Revolute | JointKind::Continuous, Some(child)) => {
                    let axis = axes.axes[j];
                    moved.omega += axis * self.delta[j];
                    moved.velocity += axis.cross(centre - child.translation) * self.delta[j];
                    // From the axis to the link's origin plus its reach, or to its ball's centre
                    // plus the ball's radius: both hold every point of the link at the middle.
                    let off_axis = distance_from_axis(axis, child.translation, link.translation);
                    let off_centre = distance_from_axis(axis, child.translation, centre);
                    r.min((off_axis + reach).min(off_centre + radius) + half * below)
                }
                (JointKind::Prismatic, Some(_)) => {
                    moved.velocity += axes.axes[j] * self.delta[j];
                    r
                }
                _ => {
                    moved.first_order &= d == 0.0;
                    r
                }
            };
            sum += d * lever;
            prefix[k + 1] = sum;
            moving[k + 1] = moved.first_order.then_some((moved.omega, moved.velocity));
            below += d * r;
        }
        moved
    }

    /// The bounds of target `ti` on the stretch of half-width `half` about `mid` (`poses` there),
    /// found once and kept for the pairs that ask again; its world bound.
    fn ensure_levered(&self, ti: usize, poses: &[Option<Pose>], mid: f64, half: f64) -> Real {
        let stretch = Some((mid.to_bits(), half.to_bits()));
        let mut kept = self.levered.borrow_mut();
        let Levered { bounds, prefix, moving } = &mut *kept;
        let slot = &mut bounds[ti];
        if slot.stretch != stretch {
            let start = &self.checker.motion_bounds().prefix_start;
            let range = start[ti]..start[ti + 1];
            let (world, sweep) = self.find_levered(ti, poses, (mid, half), &mut prefix[range.clone()], &mut moving[range]);
            *slot = TargetBound { stretch, world, sweep };
        }
        slot.world
    }

    /// [`Levered`]'s prefixes for target `ti` into `prefix` and `moving` (its own), returning
    /// the world bound (see [`JointPath::bound`]) and, when the first-order bound is the one it
    /// is, its sweep.
    fn find_levered(
        &self,
        ti: usize,
        poses: &[Option<Pose>],
        (mid, half): (f64, f64),
        prefix: &mut [Real],
        moving: &mut [Option<(Vector, Vector)>],
    ) -> (Real, Option<(Vector, Real)>) {
        let Some(link) = poses[self.checker.targets()[ti].link] else {
            let whole = half * self.speeds[ti];
            prefix.fill(whole);
            moving.fill(None);
            return (whole, None);
        };
        let radius = self.checker.motion_bounds().ball[ti].1;
        let moved = self.levers_at(ti, link, poses, (mid, half), prefix, moving);
        prefix.iter_mut().for_each(|p| *p *= half);
        let levers = prefix.last().copied().unwrap_or(0.0);
        if !moved.first_order {
            return (levers, None);
        }
        let turning = half * moved.omega.length() * radius + 0.5 * half * half * self.accelerations[ti];
        let moving = half * moved.velocity.length() + turning;
        // NaN (a bad pose) falls back to the lever bound.
        if moving < levers {
            (moving, Some((moved.velocity * half, turning)))
        } else {
            (levers, None)
        }
    }
}

impl JointPath<'_> {
    /// Target `t`'s bound within `half` over its first `k` joints alone (`kept`: the
    /// [`Levered`] of the stretch, found for `t`), in the frame of the link above them: the
    /// smaller of their lever sum and their first-order bound. In that frame the chain from it
    /// down to the link is fixed at its base, so the first-order bound of `bound` holds with
    /// their velocities and their own acceleration bound.
    fn relative_bound(&self, kept: &Levered, t: usize, k: usize, half: f64) -> Real {
        let bounds = self.checker.motion_bounds();
        let at = bounds.prefix_start[t] + k;
        let levers = kept.prefix[at];
        let Some((omega, velocity)) = kept.moving[at] else {
            return levers;
        };
        let radius = bounds.ball[t].1;
        let first_order = half * (velocity.length() + omega.length() * radius) + 0.5 * half * half * self.relative_accelerations[at];
        // NaN (a bad pose) keeps the lever sum.
        if first_order < levers {
            first_order
        } else {
            levers
        }
    }
}

impl MotionPath for JointPath<'_> {
    fn speeds(&self) -> &[Real] {
        &self.speeds
    }

    /// Both ends were validated (`Checker::joint_path`): every position between is finite.
    fn link_poses(&self, s: f64) -> Result<Vec<Option<Pose>>, String> {
        let frames = &self.checker.motion_bounds().frames;
        Ok(self.checker.robot().forward_poses(frames, |j| self.q0[j] + s * self.delta[j], self.base))
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
    fn bound(&self, ti: usize, poses: &[Option<Pose>], mid: f64, half: f64) -> Real {
        self.ensure_levered(ti, poses, mid, half)
    }

    /// The first-order bound's parts, when it is the bound: a point `p` of the link at `mid + t`
    /// is `p + t·v + e` with `v` the velocity of the ball's centre `c` at `mid` and
    /// `|e| <= |t|·|ω|·R + t²·A/2` (`ω × (p - c)` is the rest of `p`'s velocity; `A` the
    /// acceleration bound): within `half`, the segment `±half·v` and a ball of the rest.
    fn sweep(&self, ti: usize, poses: &[Option<Pose>], mid: f64, half: f64) -> Option<(Vector, Real)> {
        let _ = self.ensure_levered(ti, poses, mid, half);
        self.levered.borrow().bounds[ti].sweep
    }

    fn out_of_limits(&self, s: f64) -> Vec<String> {
        self.checker.out_of_limits(&self.at(s))
    }

    fn report_at(&self, s: f64) -> StateReport {
        self.checker.check_positions(&self.at(s)).unwrap_or_else(|e| StateReport::failed(e.to_string()))
    }

    /// In the frame of the last link upstream of both: only the joints that move one of the two
    /// and not the other count (a joint above both turns the pair as one body), each link's the
    /// smaller of their levers tightened at the middle and their first-order bound, as for
    /// `bound`; the world bounds when those are smaller in sum.
    fn pair_bound(&self, a: usize, b: usize, poses: &[Option<Pose>], mid: f64, half: f64) -> (Real, Real) {
        let targets = self.checker.targets();
        if poses[targets[a].link].is_none() || poses[targets[b].link].is_none() {
            return self.pair_bound_quick(a, b, poses, mid, half);
        }
        let _ = (self.ensure_levered(a, poses, mid, half), self.ensure_levered(b, poses, mid, half));
        let kept = self.levered.borrow();
        let bounds = self.checker.motion_bounds();
        let (ka, kb) = (bounds.unshared(a, b), bounds.unshared(b, a));
        let relative = (self.relative_bound(&kept, a, ka, half), self.relative_bound(&kept, b, kb, half));
        let world = (kept.bounds[a].world, kept.bounds[b].world);
        if relative.0 + relative.1 <= world.0 + world.1 {
            relative
        } else {
            world
        }
    }

    /// The relative bounds of [`JointPath::pair_bound`] alone.
    fn pair_bound_quick(&self, a: usize, b: usize, _poses: &[Option<Pose>], _mid: f64, half: f64) -> (Real, Real) {
        let bounds = self.checker.motion_bounds();
        let start = &bounds.prefix_start;
        (half * self.steady_sums[start[a] + bounds.unshared(a, b)], half * self.steady_sums[start[b] + bounds.unshared(b, a)])
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
        // Per target: Σ_j |Δq_j| r_jk (the steady levers), the speed bound of its points per
        // unit of s.
        // One allocation per array, not one per target: a motion's setup was 3-5 % of its time.
        let prefixes = bounds.prefix_start.last().copied().unwrap_or(0);
        let (mut steady_sums, mut relative_accelerations) = (Vec::with_capacity(prefixes), Vec::with_capacity(prefixes));
        for (l, steady) in bounds.levers.iter().zip(&bounds.steady) {
            let first = steady_sums.len();
            steady_sums.push(0.0);
            let mut sum = 0.0;
            for ((j, _), r) in l.iter().zip(steady) {
                sum += delta[*j].abs() * r;
                steady_sums.push(sum);
            }
            relative_accelerations.extend((0..=l.len()).map(|k| point_acceleration(robot, &l[..k], &delta, steady_sums[first + k])));
        }
        let speeds: Vec<Real> = bounds.prefix_start.windows(2).map(|w| steady_sums[w[1] - 1]).collect();
        let accelerations = bounds.levers.iter().zip(&speeds).map(|(l, speed)| point_acceleration(robot, l, &delta, *speed)).collect();
        let levered = RefCell::new(Levered { bounds: vec![TargetBound::default(); speeds.len()], prefix: vec![0.0; prefixes], moving: vec![None; prefixes] });
        Ok(JointPath {
            checker: self,
            base: pose_from_isometry(self.base_pose()),
            q0,
            delta,
            speeds,
            accelerations,
            relative_accelerations,
            steady_sums,
            levered,
            axes: RefCell::default(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::checker::test_points::{assert_same_motions, largest_pair_change, part_points, random_state};
    use crate::model::Params;

    fn arm() -> Checker {
        Checker::from_params(Params::default()).unwrap()
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

    /// The motion loop's forward kinematics (glam, unvalidated) poses every link where the
    /// state check's (nalgebra) does, over random states of the bundled arm (revolute,
    /// continuous, prismatic and mimic joints) on a base that is not the identity.
    #[test]
    fn the_loops_forward_kinematics_is_the_state_checks() {
        let c = arm();
        let robot = c.robot();
        let mut rng = oorandom::Rand64::new(41);
        let mut draw = |lo: f64, hi: f64| lo + (hi - lo) * rng.rand_float();
        let frames = robot.pose_kinematics();
        let mut largest = 0.0f64;
        for _ in 0..200 {
            let q = random_state(robot, &mut draw);
            let base = nalgebra::Isometry3::new(
                nalgebra::Vector3::new(draw(-1.0, 1.0), draw(-1.0, 1.0), draw(0.0, 1.0)),
                nalgebra::Vector3::new(draw(-1.0, 1.0), draw(-1.0, 1.0), draw(-3.0, 3.0)),
            );
            let expected = robot.forward_kinematics(&q, &base).unwrap();
            let got = robot.forward_poses(&frames, |j| q[j], pose_from_isometry(&base));
            assert_eq!(got.len(), expected.len());
            for (g, e) in got.iter().zip(&expected) {
                let (g, e) = (g.expect("every link posed"), pose_from_isometry(e));
                for p in [Vector::X, Vector::Y, Vector::Z, Vector::new(0.3, -0.2, 0.5)] {
                    largest = largest.max((g * p - e * p).length());
                }
            }
        }
        assert!(largest < 1e-12, "largest difference {largest} m");
    }

    /// `prepare_motion_checks` builds every rung up to the largest tested growth, for every
    /// part, and nothing above it; motions then answer as they do on a checker that builds its
    /// rungs on first use.
    #[test]
    fn a_prepared_checker_has_its_ladder_and_answers_as_an_unprepared_one() {
        let (prepared, lazy) = (arm(), arm());
        assert!(!prepared.motion_checks_prepared());
        prepared.prepare_motion_checks();
        assert!(prepared.motion_checks_prepared());
        let bounds = prepared.motion_bounds();
        let top = bounds.level(crate::checker::motion_sweep::MAX_TESTED_GROWTH);
        assert!(top > 0 && bounds.growth(top) >= crate::checker::motion_sweep::MAX_TESTED_GROWTH);
        // Every rung up to `top` is built (asserted above), none above it.
        for levels in bounds.grown.iter().flat_map(|ladder| ladder.iter()) {
            assert!(levels.iter().skip(top + 1).all(|l| l.get().is_none()));
        }
        assert!(assert_same_motions(&prepared, &lazy, 47, 60) > 0, "some motions collide");
    }

    /// The self pairs' bound, checked directly: within a stretch, no distance between a point of
    /// one link of a pair and a point of the other changes by more than the two bounds' sum (so
    /// two links grown by them at the middle, apart, stay apart), over random motions of the
    /// bundled arm and every pair it checks.
    #[test]
    fn no_distance_within_a_self_pair_changes_more_than_its_bounds() {
        let c = arm();
        let robot = c.robot();
        let mut rng = oorandom::Rand64::new(34);
        let mut draw = |lo: f64, hi: f64| lo + (hi - lo) * rng.rand_float();
        let (mut checked, mut tightest) = (0usize, 0.0f64);
        let points: Vec<Vec<Vector>> = c.targets().iter().map(|t| t.parts.iter().flat_map(|(shape, offset)| part_points(shape, offset)).collect()).collect();
        for k in 0..200 {
            let qs = [random_state(robot, &mut draw), random_state(robot, &mut draw)];
            let path = c.joint_path(&qs[0], &qs[1]).unwrap();
            let half = [0.5, 0.2, 0.05, 0.01][k % 4];
            let s = draw(0.0, 1.0);
            let poses = path.link_poses(s).unwrap();
            let others: Vec<Vec<Option<Pose>>> = (0..=8).map(|i| path.link_poses((s - half + 2.0 * half * i as f64 / 8.0).clamp(0.0, 1.0)).unwrap()).collect();
            for &(a, b) in &c.self_pairs().pairs {
                let (da, db) = path.pair_bound(a, b, &poses, s, half);
                let (la, lb) = (c.targets()[a].link, c.targets()[b].link);
                let largest = largest_pair_change(&points[a], la, &points[b], lb, &poses, &others);
                assert!(largest <= da + db + 1e-9, "pair ({a}, {b}): a distance changed by {largest} within {half} of s = {s}, bounds {da} + {db}");
                if da + db > 0.0 {
                    tightest = tightest.max(largest / (da + db));
                }
                checked += 1;
            }
        }
        assert!(checked > 200 && tightest > 0.3, "{checked} pair stretches, largest change / bound {tightest}");
        eprintln!("{checked} pair stretches, largest change / bound {tightest:.3}");
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
            let qs = [random_state(robot, &mut draw), random_state(robot, &mut draw)];
            let path = c.joint_path(&qs[0], &qs[1]).unwrap();
            let half = [0.5, 0.2, 0.05, 0.01][checked % 4];
            let s = draw(0.0, 1.0);
            let poses = path.link_poses(s).unwrap();
            for (ti, t) in c.targets().iter().enumerate() {
                let bound = path.bound(ti, &poses, s, half);
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

    /// A motion that starts in collision is blocked at 0 with the start state's own report, found
    /// at the first stretch (every target and pair examined once at most), not by descending to
    /// the tolerance; the same motion from a free start is not.
    #[test]
    fn a_motion_from_a_colliding_start_is_blocked_there_at_once() {
        let c = arm();
        let into = q(&c, &[("shoulder_lift_joint", 1.2), ("elbow_joint", 0.3)]);
        let free = q(&c, &[]);
        let start = c.check_positions(&into).unwrap();
        assert!(start.in_collision);
        let r = c.check_motion(&into, &free);
        assert_eq!(r.fraction, Some(0.0), "{r:?}");
        assert_eq!(r.report.contacts, start.contacts);
        let members = (c.targets().len() + c.self_pairs().pairs.len()) as u64;
        assert!(r.subintervals <= members, "{} stretches examined, {members} targets and pairs", r.subintervals);
        let back = c.check_motion(&free, &into);
        assert!(back.fraction.unwrap() > 0.0 && back.subintervals > members, "{back:?}");
    }

    /// A short motion away from everything is cleared on one stretch, every target and pair
    /// examined once; a long one starts from several (its links' bounds over the whole motion
    /// are far past what could be cleared), each examined on each.
    #[test]
    fn a_short_motion_is_examined_whole_and_a_long_one_in_pieces() {
        let c = arm();
        let members = (c.targets().len() + c.self_pairs().pairs.len()) as u64;
        let free = q(&c, &[]);
        let near = q(&c, &[("shoulder_pan_joint", 1e-3), ("elbow_joint", -1e-3)]);
        let r = c.check_motion(&free, &near);
        assert!(!r.report.in_collision && r.subintervals == members, "{r:?}");
        let far = q(&c, &[("shoulder_pan_joint", 3.0), ("wrist_1_joint", 2.0)]);
        let r = c.check_motion(&free, &far);
        assert!(r.subintervals >= 2 * members, "{} stretches examined, {members} targets and pairs", r.subintervals);
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
