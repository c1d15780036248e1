//! The adaptive loop that joint-space motions and link-pose motions share: given a bound on how
//! fast every point of each checked link moves along the motion parameter `s`, the link poses at
//! any `s`, and the report of the state at any `s`, find the first stretch of the motion that
//! cannot be cleared.

use super::checker_build::Checker;
use super::motion::{grow, MotionBounds, MotionReport, MAX_SUBINTERVALS};
use super::state_report::{ObjectType, ReportContact, StateReport};
use crate::collision::{collide_pair, pair_may_meet, CollideSettings, PairContact, Target, TargetShape};
use crate::math::{Pose, Real};
use std::collections::hash_map::{Entry, HashMap};

/// Growth above which a sub-interval is split without being tested (metres): it only saves work.
/// On the motion benchmark (Panda, 1M cells, 2,000 motions) links grown by more than 0.36 m were
/// free in 92 of 35,000 tests, and a test that hits cost ~50 µs there; splitting instead of
/// testing above 0.15 m took the mean time per motion from 15.4 to 11.3 state checks (14 % more
/// link tests, each cheaper).
const MAX_TESTED_GROWTH: Real = 0.15;

/// A motion as the adaptive loop sees it.
pub(super) trait MotionPath {
    /// Per target (as `Checker::targets`): a bound on how far any point of it moves per unit of
    /// `s`, in every part of the motion (0: the target does not move).
    fn speeds(&self) -> &[Real];
    /// The world poses of the robot's links at `s` (indexed like `robot().links`).
    fn link_poses(&self, s: f64) -> Result<Vec<Option<Pose>>, String>;
    /// A bound on how far any point of target `ti` moves from where it is at `s`, for every `s'`
    /// with `|s' - s| <= half`, given the link poses at `s`. At most `half · speeds()[ti]`.
    fn bound(&self, ti: usize, _poses: &[Option<Pose>], half: f64) -> Real {
        half * self.speeds()[ti]
    }
    /// The report of the state at `s` (its contacts are those of a motion found colliding there).
    fn report_at(&self, s: f64) -> StateReport;
    /// Bounds for self pair `(a, b)` within `half` of `s`: how far each target's points move, both
    /// measured in the same frame (the world, or a frame the two share, such as the last link
    /// upstream of both: the joints above it move the pair rigidly and do not change their
    /// distance).
    fn pair_bound(&self, a: usize, b: usize, poses: &[Option<Pose>], half: f64) -> (Real, Real) {
        (self.bound(a, poses, half), self.bound(b, poses, half))
    }
    /// Bounds as [`MotionPath::pair_bound`]'s, possibly looser, cheaper to find.
    fn pair_bound_quick(&self, a: usize, b: usize, poses: &[Option<Pose>], half: f64) -> (Real, Real) {
        self.pair_bound(a, b, poses, half)
    }
}

/// Link poses kept for reuse at most (cleared past this): a motion that needs millions of
/// midpoints must not keep a pose set for each.
const MAX_CACHED_POSES: usize = 4096;

/// Where a motion could not be cleared: the start of the stretch, the target, the ladder level it
/// was grown by and its pose at the stretch's middle.
struct Blocked {
    fraction: f64,
    ti: usize,
    level: Option<usize>,
    pose: Pose,
    /// For a self pair: the other target, its level and its pose.
    other: Option<(usize, Option<usize>, Pose)>,
}

/// What the test of one stretch found.
enum Stretch {
    /// Nothing can be met on it.
    Clear,
    /// Not cleared at this size: try its halves.
    Split,
    /// Not cleared and not worth splitting: the motion is blocked from the stretch's start.
    Blocked(Blocked),
}

/// The ladder level that covers a displacement bound, and whether it is worth testing with: the
/// growth covers the bound (rounding, NaN or past the ladder's top: split) and is not beyond what
/// is worth testing (the first rung always is). A target that does not move is tested as it is.
fn rung(bounds: &MotionBounds, delta: Real) -> (Option<usize>, bool) {
    if delta > 0.0 {
        let level = bounds.level(delta);
        let growth = bounds.growth(level);
        (Some(level), growth >= delta && (growth <= MAX_TESTED_GROWTH || level == 0))
    } else {
        (None, true)
    }
}

/// The state of one sweep: the link poses by `s` (the targets of one link chain meet at the same
/// midpoints), the earliest stretch blocked so far, and the stretches examined.
struct Sweep {
    poses_at: HashMap<u64, Vec<Option<Pose>>>,
    blocked: Option<Blocked>,
    examined: u64,
    stack: Vec<(f64, f64)>,
}

impl Sweep {
    /// Clears `[0, limit)` by bisection, left half first, where `limit` is the earliest stretch
    /// blocked so far; `test` judges a stretch from the link poses at its middle, its start and
    /// its half-width.
    fn clear(&mut self, path: &impl MotionPath, mut test: impl FnMut(&[Option<Pose>], f64, f64) -> Result<Stretch, String>) -> Result<(), String> {
        self.stack.clear();
        self.stack.push((0.0, 1.0));
        while let Some((a, b)) = self.stack.pop() {
            let limit = self.blocked.as_ref().map_or(f64::INFINITY, |b| b.fraction);
            if a >= limit {
                continue;
            }
            self.examined += 1;
            if self.examined > MAX_SUBINTERVALS {
                return Err(format!("the motion needs more than {MAX_SUBINTERVALS} sub-intervals to clear; not checked"));
            }
            let m = 0.5 * (a + b);
            if self.poses_at.len() >= MAX_CACHED_POSES {
                self.poses_at.clear();
            }
            let poses = match self.poses_at.entry(m.to_bits()) {
                Entry::Occupied(e) => e.into_mut(),
                Entry::Vacant(e) => e.insert(path.link_poses(m)?),
            };
            match test(poses, a, 0.5 * (b - a))? {
                Stretch::Clear => {}
                Stretch::Split => {
                    self.stack.push((m, b));
                    self.stack.push((a, m));
                }
                Stretch::Blocked(blocked) => {
                    self.blocked = Some(blocked);
                    return Ok(());
                }
            }
        }
        Ok(())
    }
}

impl Checker {
    /// The adaptive loop over `path` (see the module documentation of `motion`). Targets, then
    /// self pairs, are cleared one after the other, each over `[0, limit)`, where `limit` is the
    /// earliest stretch that an earlier one could not clear: the answer is the earliest over all,
    /// as if they were examined together, left half first.
    pub(super) fn sweep_motion(&self, path: &impl MotionPath) -> MotionReport {
        let bounds = self.motion_bounds();
        let speed = path.speeds();
        let flags = CollideSettings { flag_only: true, least_overlap: false, ..Default::default() };
        let mut sweep = Sweep { poses_at: HashMap::new(), blocked: None, examined: 0, stack: Vec::with_capacity(64) };
        let mut run = || -> Result<(), String> {
            for (ti, lt) in self.targets().iter().enumerate() {
                sweep.clear(path, |poses, a, half| {
                    let pose = poses[lt.link].ok_or_else(|| format!("no pose for link '{}'", lt.name))?;
                    // A link that does not move is where it is at every s: checked as it is,
                    // ungrown (a base resting on a table is not a near miss).
                    let (level, tested) = if speed[ti] > 0.0 { rung(bounds, path.bound(ti, poses, half)) } else { (None, true) };
                    Ok(if tested && !self.grown_link_hit(ti, level, &pose, &flags) {
                        Stretch::Clear
                    } else if level.is_none_or(|l| l == 0) {
                        Stretch::Blocked(Blocked { fraction: a, ti, level, pose, other: None })
                    } else {
                        Stretch::Split
                    })
                })?;
            }
            // A pair is cleared on a stretch when its two links at the middle, each grown by its
            // own displacement bound, do not meet (then they stay apart all along the stretch).
            for &(ta, tb) in &self.self_pairs().pairs {
                let (la, lb) = (&self.targets()[ta], &self.targets()[tb]);
                sweep.clear(path, |poses, a, half| {
                    let (Some(pa), Some(pb)) = (poses[la.link], poses[lb.link]) else {
                        return Err(format!("no pose for link '{}' or '{}'", la.name, lb.name));
                    };
                    // Balls that hold the two links, each grown by its bound, apart: the pair
                    // stays apart all along the stretch, at any growth (no hull test needed).
                    // Most pairs are cleared so, on the quick bounds.
                    let ((ca, ra), (cb, rb)) = (bounds.ball[ta], bounds.ball[tb]);
                    let gap = (pa * ca - pb * cb).length() - ra - rb;
                    let (quick_a, quick_b) = path.pair_bound_quick(ta, tb, poses, half);
                    if gap > quick_a + quick_b {
                        return Ok(Stretch::Clear);
                    }
                    let (delta_a, delta_b) = path.pair_bound(ta, tb, poses, half);
                    if gap > delta_a + delta_b {
                        return Ok(Stretch::Clear);
                    }
                    let ((level_a, tested_a), (level_b, tested_b)) = (rung(bounds, delta_a), rung(bounds, delta_b));
                    Ok(if tested_a && tested_b && !self.grown_pair_may_meet(ta, level_a, &pa, tb, level_b, &pb) {
                        Stretch::Clear
                    } else if level_a.is_none_or(|l| l == 0) && level_b.is_none_or(|l| l == 0) {
                        Stretch::Blocked(Blocked { fraction: a, ti: ta, level: level_a, pose: pa, other: Some((tb, level_b, pb)) })
                    } else {
                        Stretch::Split
                    })
                })?;
            }
            Ok(())
        };
        if let Err(error) = run() {
            let mut report = StateReport::failed(error);
            report.motion = true;
            return MotionReport { report, fraction: None, subintervals: sweep.examined };
        }
        let examined = sweep.examined;
        match sweep.blocked {
            None => {
                // A free motion stands for its end pose: the clearances are that pose's.
                let clearances = if self.params().clearance_threshold > 0.0 { path.report_at(1.0).clearances } else { Vec::new() };
                MotionReport { report: StateReport { motion: true, clearances, ..Default::default() }, fraction: None, subintervals: examined }
            }
            Some(b) => match b.other {
                None => self.motion_contact(path.report_at(b.fraction), b.ti, b.level, &b.pose, b.fraction, examined),
                Some(other) => self.motion_self_contact(path.report_at(b.fraction), (b.ti, b.level, b.pose), other, b.fraction, examined),
            },
        }
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

    /// Whether any part of target `ta` may meet any of `tb`, each grown by its ladder level, at
    /// the given link poses (see [`pair_may_meet`]).
    fn grown_pair_may_meet(&self, ta: usize, level_a: Option<usize>, pa: &Pose, tb: usize, level_b: Option<usize>, pb: &Pose) -> bool {
        self.targets()[ta].parts.iter().enumerate().any(|(ia, (_, oa))| {
            let part_a = Target::new(self.grown_part(ta, ia, level_a).clone(), *pa * *oa);
            self.targets()[tb]
                .parts
                .iter()
                .enumerate()
                .any(|(ib, (_, ob))| pair_may_meet(&part_a, &Target::new(self.grown_part(tb, ib, level_b).clone(), *pb * *ob)))
        })
    }

    /// The deepest contact between the parts of targets `ta` and `tb`, each grown by its ladder
    /// level, at the given link poses.
    pub(super) fn grown_pair_contact(&self, ta: usize, level_a: Option<usize>, pa: &Pose, tb: usize, level_b: Option<usize>, pb: &Pose) -> Option<PairContact> {
        let mut best: Option<PairContact> = None;
        for (ia, (_, oa)) in self.targets()[ta].parts.iter().enumerate() {
            let part_a = Target::new(self.grown_part(ta, ia, level_a).clone(), *pa * *oa);
            for (ib, (_, ob)) in self.targets()[tb].parts.iter().enumerate() {
                let part_b = Target::new(self.grown_part(tb, ib, level_b).clone(), *pb * *ob);
                if let Some(c) = collide_pair(&part_a, &part_b) {
                    if best.is_none_or(|x| c.depth > x.depth) {
                        best = Some(c);
                    }
                }
            }
        }
        best
    }

    /// As [`Checker::motion_contact`] for a self pair: for a near miss, the pair the grown links
    /// met as, depth 0.
    fn motion_self_contact(
        &self,
        mut report: StateReport,
        a: (usize, Option<usize>, Pose),
        b: (usize, Option<usize>, Pose),
        fraction: f64,
        examined: u64,
    ) -> MotionReport {
        let (name_a, name_b) = (&self.targets()[a.0].name, &self.targets()[b.0].name);
        if !report.contacts.iter().any(|c| &c.link_name == name_a && &c.object_name == name_b) {
            if let Some(c) = self.grown_pair_contact(a.0, a.1, &a.2, b.0, b.1, &b.2) {
                report.contacts.push(ReportContact {
                    link_name: name_a.clone(),
                    object_name: name_b.clone(),
                    triangle: u32::MAX,
                    depth: 0.0,
                    position: Some(c.position.to_array()),
                    normal: c.normal.to_array(),
                    object_type: ObjectType::RobotLink,
                });
            }
        }
        report.in_collision = true;
        report.motion = true;
        report.fraction = Some(fraction);
        MotionReport { report, fraction: Some(fraction), subintervals: examined }
    }

    /// The report of a motion found colliding on the stretch starting at `fraction`: `report` is
    /// that of the pose there; for a near miss (the link does not collide there) the object the
    /// grown link at `link_pose` touched is added, with depth 0.
    fn motion_contact(&self, mut report: StateReport, ti: usize, level: Option<usize>, link_pose: &Pose, fraction: f64, examined: u64) -> MotionReport {
        if !report.contacts.iter().any(|c| c.link_name == self.targets()[ti].name) {
            let settings = CollideSettings { flag_only: false, least_overlap: false, ..Default::default() };
            let lt = &self.targets()[ti];
            let near = lt.parts.iter().enumerate().find_map(|(pi, (_, offset))| {
                self.collide_target(ti, &Target::new(self.grown_part(ti, pi, level).clone(), *link_pose * *offset), &settings).deepest().copied()
            });
            if let Some(c) = near {
                report.contacts.push(ReportContact {
                    link_name: lt.name.clone(),
                    object_name: self.scene().objects()[c.object].name.clone(),
                    triangle: c.triangle,
                    depth: 0.0,
                    position: c.position.map(|p| p.to_array()),
                    normal: c.normal.to_array(),
                    object_type: ObjectType::Environment,
                });
            }
        }
        report.in_collision = true;
        report.motion = true;
        report.fraction = Some(fraction);
        MotionReport { report, fraction: Some(fraction), subintervals: examined }
    }
}
