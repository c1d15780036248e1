//! The one adaptive loop every motion check runs (joint-space motions in `joint_motion`, link-pose
//! motions in `world_motion`): given a bound on how fast every point of each checked link moves
//! along the motion parameter `s`, the link poses at any `s`, and the report of the state at any
//! `s`, find the first stretch of the motion that cannot be cleared, for the links against the
//! environment and for the self pairs alike.

use super::checker::Checker;
use super::motion_bounds::MotionBounds;
use super::state_report::StateReport;
use crate::collision::{BallWitness, CollideSettings};
use crate::math::{Pose, Real, Vector};

/// Sub-intervals examined at most per motion; past that the motion fails closed.
pub(crate) const MAX_SUBINTERVALS: u64 = 1 << 20;

/// Growth above which a sub-interval is split without being tested (metres): it only saves work.
/// On the motion benchmark (Panda, 1M cells, 2,000 motions) links grown by more than 0.36 m were
/// free in 92 of 35,000 tests, and a test that hits cost ~50 µs there; splitting instead of
/// testing above 0.15 m took the mean time per motion from 15.4 to 11.3 state checks (14 % more
/// link tests, each cheaper). With hulls grown by balls (no cube corners) the balance moved:
/// 0.3, 0.15, 0.08, 0.06, 0.04, 0.02 m gave 4.51, 4.22, 4.08, 4.06, 4.03, 4.20 state checks per
/// motion on the peer world and 7.19, 6.57, 6.41, 6.40, 6.47, 7.22 on the wall (10,000 motions).
pub(super) const MAX_TESTED_GROWTH: Real = 0.06;

/// The growth the fastest link's steady lever bound (its speed times the half-width) is brought
/// to, about, by the equal stretches a motion is first split into (metres). On the motion
/// benchmark (planner-like edges, 5,000 wall motions, three runs each), starting every motion from
/// the whole, halves, quarters and eighths gave 3.65, 3.43, 3.36 and 3.62 state checks per motion;
/// this bound gives mostly quarters there (3.35), 0.3 m mostly eighths (3.46), and a short motion
/// one stretch.
const FIRST_GROWTH: Real = 0.6;
/// Stretches a motion is first split into at most.
const MAX_FIRST_PIECES: u32 = 8;

/// A flags-only question of the cells: the motion loop asks only whether a grown link meets
/// anything.
const FLAGS: CollideSettings = CollideSettings { all_contacts: false, flag_only: true, least_overlap: false };

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

/// A motion as the adaptive loop sees it.
pub(super) trait MotionPath {
    /// Per target (as `Checker::targets`): a bound on how far any point of it moves per unit of
    /// `s`, in every part of the motion (0: the target does not move).
    fn speeds(&self) -> &[Real];
    /// The world poses of the robot's links at `s` (indexed like `robot().links`).
    fn link_poses(&self, s: f64) -> Result<Vec<Option<Pose>>, String>;
    /// A bound on how far any point of target `ti` moves from where it is at `s`, for every `s'`
    /// with `|s' - s| <= half`, given the link poses at `s`. At most `half · speeds()[ti]`.
    fn bound(&self, ti: usize, _poses: &[Option<Pose>], _mid: f64, half: f64) -> Real {
        half * self.speeds()[ti]
    }
    /// Target `ti`'s bound within `half` of `mid` split in two, when it can be: a vector `v`
    /// (world frame) and a radius `r` such that every point of the target at every `s` in the
    /// stretch lies within `r` of the segment from `p - v` to `p + v`, `p` where the point is at
    /// `mid`. A link sliding along a surface is then not grown toward it by its whole speed.
    fn sweep(&self, _ti: usize, _poses: &[Option<Pose>], _mid: f64, _half: f64) -> Option<(Vector, Real)> {
        None
    }
    /// The report of the state at `s` (its contacts are those of a motion found colliding there).
    fn report_at(&self, s: f64) -> StateReport;
    /// The joints out of their limits at `s` (none for a motion between link poses).
    fn out_of_limits(&self, _s: f64) -> Vec<String> {
        Vec::new()
    }
    /// The part of target `ti`'s bounds that does not shrink with the stretch (a path tolerance:
    /// every configuration within it of the path is covered). A stretch whose bound is within
    /// the ladder's first rung of it cannot be narrowed further.
    fn floor(&self, _ti: usize) -> Real {
        0.0
    }
    /// Bounds for self pair `(a, b)` within `half` of `s`: how far each target's points move, both
    /// measured in the same frame (the world, or a frame the two share, such as the last link
    /// upstream of both: the joints above it move the pair rigidly and do not change their
    /// distance).
    fn pair_bound(&self, a: usize, b: usize, poses: &[Option<Pose>], mid: f64, half: f64) -> (Real, Real) {
        (self.bound(a, poses, mid, half), self.bound(b, poses, mid, half))
    }
    /// Bounds as [`MotionPath::pair_bound`]'s, possibly looser, cheaper to find.
    fn pair_bound_quick(&self, a: usize, b: usize, poses: &[Option<Pose>], mid: f64, half: f64) -> (Real, Real) {
        self.pair_bound(a, b, poses, mid, half)
    }
}

/// A target grown for one stretch: its ladder level (`None`: as it is), whether that growth is
/// worth testing, and its link's pose at the stretch's middle.
#[derive(Clone, Copy)]
pub(super) struct Grown {
    pub(super) ti: usize,
    pub(super) level: Option<usize>,
    tested: bool,
    /// Splitting the stretch cannot make the growth smaller (the first rung, or within it of
    /// the path's floor).
    settled: bool,
    pub(super) pose: Pose,
}

/// Where a motion could not be cleared: the start of the stretch and the target grown there
/// (for a self pair, both).
struct Blocked {
    fraction: f64,
    grown: Grown,
    other: Option<Grown>,
}

/// What the test of one stretch found.
enum Stretch {
    /// Nothing can be met on it.
    Clear,
    /// Not cleared at this size: try its halves. `met`: the grown test was made and met
    /// something (else the growth was too large to be worth testing).
    Split { met: bool },
    /// Not cleared and not worth splitting: the motion is blocked from the stretch's start.
    Blocked(Blocked),
}

impl Stretch {
    /// The verdict on the stretch from `start` where `grown` (and `other`, for a pair) were
    /// grown: clear when every growth is worth testing and `meets` finds nothing; blocked when
    /// no growth can shrink further (the first rung, or a target that does not move); else split.
    fn judge(start: f64, grown: Grown, other: Option<Grown>, meets: impl FnOnce() -> bool) -> Stretch {
        let all = |f: fn(&Grown) -> bool| f(&grown) && other.as_ref().is_none_or(f);
        if all(|g| g.tested) && !meets() {
            Stretch::Clear
        } else if all(|g| g.settled) {
            Stretch::Blocked(Blocked { fraction: start, grown, other })
        } else {
            Stretch::Split { met: all(|g| g.tested) }
        }
    }
}

/// Target `ti` at `pose` grown to cover a displacement bound `delta`: the ladder level that
/// covers it, worth testing when the growth covers the bound (rounding, NaN or past the ladder's
/// top: split) and is not beyond what is worth testing (the first rung always is). A target
/// that does not move is tested as it is.
fn grown_for(bounds: &MotionBounds, ti: usize, pose: Pose, delta: Real, floor: Real) -> Grown {
    if delta > 0.0 {
        let level = bounds.level(delta);
        let growth = bounds.growth(level);
        let settled = level == 0 || delta - floor <= bounds.growth(0);
        Grown { ti, level: Some(level), tested: growth >= delta && (growth <= MAX_TESTED_GROWTH || settled), settled, pose }
    } else {
        Grown { ti, level: None, tested: true, settled: true, pose }
    }
}

/// A stretch waiting to be examined: its ends, and where the targets and pairs it must still
/// clear are in the sweep's member list (see [`Checker::sweep_motion`]).
struct Pending {
    a: f64,
    b: f64,
    members: std::ops::Range<usize>,
}

/// One stretch as its targets and pairs are judged: the link poses at its middle, its start and
/// its half-width.
#[derive(Clone, Copy)]
struct At<'p> {
    poses: &'p [Option<Pose>],
    start: f64,
    half: f64,
}

/// What one motion's loop learns as it goes, besides its stretches: per target or pair whether
/// it was tried at the start (and the start's link poses), per pair the axis that last
/// separated it, per target the cell box that stopped its last ball walk.
struct Learned {
    probed: Vec<bool>,
    start_poses: Option<Vec<Option<Pose>>>,
    hints: Vec<Vector>,
    witnesses: Vec<Option<BallWitness>>,
}

impl Checker {
    /// The adaptive loop over `path` (see the module documentation of `joint_motion`): every
    /// target against the environment and every self pair, examined together by bisection, left
    /// half first; a stretch is split with only what it did not clear. A stretch is examined
    /// after every stretch that starts before it, so the first one blocked is the earliest of
    /// all, and nothing past it is examined (a motion that collides early costs what its start
    /// costs).
    pub(super) fn sweep_motion(&self, path: &impl MotionPath) -> MotionReport {
        let mut examined = 0u64;
        let blocked = match self.first_blocked(path, &mut examined) {
            Ok(blocked) => blocked,
            Err(error) => {
                let mut report = StateReport::failed(error);
                report.motion = true;
                return MotionReport { report, fraction: None, subintervals: examined };
            }
        };
        match blocked {
            None => {
                // A free motion stands for its end pose: the clearances are that pose's.
                let clearances = if self.params().clearance_threshold > 0.0 { path.report_at(1.0).clearances } else { Vec::new() };
                MotionReport { report: StateReport { motion: true, clearances, ..Default::default() }, fraction: None, subintervals: examined }
            }
            Some(b) => {
                let report = self.report_where_blocked(path, &b);
                let report = match b.other {
                    None => self.motion_contact(report, &b.grown),
                    Some(other) => self.motion_self_contact(report, &b.grown, &other),
                };
                blocked_report(report, b.fraction, examined)
            }
        }
    }

    /// The bisection of [`Checker::sweep_motion`]: the first stretch blocked, or `None` when
    /// every target and pair is cleared over the whole motion; `examined` counts (target or
    /// pair, stretch) pairs.
    fn first_blocked(&self, path: &impl MotionPath, examined: &mut u64) -> Result<Option<Blocked>, String> {
        let count = self.targets().len() + self.self_pairs().pairs.len();
        // One list for every pending stretch: a stretch's survivors are appended after its own
        // members, and both halves share them. The stack is last in, first out, so when a stretch
        // is taken, whatever follows its members belongs to stretches already done.
        let mut members: Vec<u32> = (0..count as u32).collect();
        let mut stack = Vec::with_capacity(64);
        // A motion that moves far is not first examined whole: hardly anything near a surface is
        // cleared over stretches that long, and the ball walks of a long stretch are the dearest
        // (they give up). It starts from as many equal stretches as bring the fastest link's
        // bound to about `FIRST_GROWTH` (a short motion from one).
        let fastest = path.speeds().iter().fold(0.0, |a: Real, b| a.max(*b));
        let mut pieces = 1u32;
        while pieces < MAX_FIRST_PIECES && fastest * 0.5 / f64::from(pieces) > FIRST_GROWTH {
            pieces *= 2;
        }
        for k in (0..pieces).rev() {
            stack.push(Pending { a: f64::from(k) / f64::from(pieces), b: f64::from(k + 1) / f64::from(pieces), members: 0..members.len() });
        }
        let mut learned = Learned {
            probed: vec![false; count],
            start_poses: None,
            hints: vec![Vector::ZERO; self.self_pairs().pairs.len()],
            witnesses: vec![None; self.targets().len()],
        };
        while let Some(Pending { a, b, members: mine }) = stack.pop() {
            members.truncate(mine.end);
            let mid = 0.5 * (a + b);
            let poses = path.link_poses(mid)?;
            let at = At { poses: &poses, start: a, half: 0.5 * (b - a) };
            let survivors = members.len();
            for k in mine {
                *examined += 1;
                if *examined > MAX_SUBINTERVALS {
                    return Err(format!("the motion needs more than {MAX_SUBINTERVALS} sub-intervals to clear; not checked"));
                }
                let i = members[k] as usize;
                match self.judge_member(path, i, at, &mut learned)? {
                    Stretch::Clear => {}
                    Stretch::Split { .. } => members.push(i as u32),
                    Stretch::Blocked(found) => return Ok(Some(found)),
                }
            }
            if members.len() > survivors {
                let split = survivors..members.len();
                stack.push(Pending { a: mid, b, members: split.clone() });
                stack.push(Pending { a, b: mid, members: split });
            }
        }
        Ok(None)
    }

    /// Member `i` of the loop (a target, then the self pairs) on the stretch `at`. Perhaps
    /// meeting something at the motion's start: if it does, the motion is blocked at 0 (the
    /// earliest there is) without descending to the tolerance. Asked once per target or pair: a
    /// target as soon as it is not cleared (its ball at the start first), a pair once its grown
    /// test has met something (a pair's test is cheap, but near pairs are many).
    fn judge_member(&self, path: &impl MotionPath, i: usize, at: At, learned: &mut Learned) -> Result<Stretch, String> {
        let targets = self.targets().len();
        let verdict = match self.member_pair(i) {
            Some((ta, tb)) => self.judge_pair(path, ta, tb, at, &mut learned.hints[i - targets])?,
            None => self.judge_target(path, i, at, &mut learned.witnesses[i])?,
        };
        if let Stretch::Split { met } = verdict {
            if at.start == 0.0 && !learned.probed[i] && (met || i < targets) {
                learned.probed[i] = true;
                if let Some(found) = self.blocked_at_start(path, i, &mut learned.start_poses)? {
                    return Ok(Stretch::Blocked(found));
                }
            }
        }
        Ok(verdict)
    }

    /// Member `i` of the loop as a self pair (the targets come first, then the pairs); `None`
    /// for a target.
    fn member_pair(&self, i: usize) -> Option<(usize, usize)> {
        i.checked_sub(self.targets().len()).and_then(|p| self.self_pairs().pairs.get(p)).copied()
    }

    /// Whether member `i` of the sweep (a target, then the self pairs) meets something, as it
    /// is, at the motion's start: then the motion is blocked there. `poses` keeps the start's
    /// link poses for the next member asked.
    fn blocked_at_start(&self, path: &impl MotionPath, i: usize, poses: &mut Option<Vec<Option<Pose>>>) -> Result<Option<Blocked>, String> {
        let poses = match poses {
            Some(p) => p,
            None => poses.insert(path.link_poses(0.0)?),
        };
        let at = |ti: usize| -> Result<Grown, String> {
            let lt = &self.targets()[ti];
            let pose = poses[lt.link].ok_or_else(|| format!("no pose for link '{}'", lt.name))?;
            Ok(Grown { ti, level: None, tested: true, settled: true, pose })
        };
        let found = match self.member_pair(i) {
            Some((ta, tb)) => {
                let (a, b) = (at(ta)?, at(tb)?);
                let mut hint = Vector::ZERO;
                self.pair_may_meet_within(&a, 0.0, &b, 0.0, &mut hint).then_some(Blocked { fraction: 0.0, grown: a, other: Some(b) })
            }
            None => {
                let g = at(i)?;
                let (centre, radius) = self.motion_bounds().ball[i];
                let near = !self.scene().ball_is_clear(g.pose * centre, radius, |oi| !self.allowed[i][oi]);
                (near && self.grown_link_hit(&g, &FLAGS)).then_some(Blocked { fraction: 0.0, grown: g, other: None })
            }
        };
        Ok(found)
    }

    /// The report of the state where the motion is blocked: only the blocked target or pair is
    /// checked there (every other was cleared over stretches covering that state), unless the
    /// motion is blocked at its start (the targets and pairs after the one found there were not
    /// examined) or clearances are asked for (they need every link).
    fn report_where_blocked(&self, path: &impl MotionPath, b: &Blocked) -> StateReport {
        if self.params().clearance_threshold > 0.0 || b.fraction <= 0.0 {
            return path.report_at(b.fraction);
        }
        match path.link_poses(b.fraction) {
            Ok(poses) => {
                let mut report = self.blocked_state_report(&poses, b.grown.ti, b.other.map(|o| o.ti));
                report.out_of_limits = path.out_of_limits(b.fraction);
                report
            }
            Err(e) => StateReport::failed(e),
        }
    }

    /// A stretch of target `ti` against the environment.
    /// `witness`: a cell's box found within the target's ball at an earlier stretch (see
    /// [`crate::collision::BallWitness`]): a target near a surface is mostly still near it.
    fn judge_target(&self, path: &impl MotionPath, ti: usize, at: At, witness: &mut Option<BallWitness>) -> Result<Stretch, String> {
        let At { poses, start, half } = at;
        let lt = &self.targets()[ti];
        let pose = poses[lt.link].ok_or_else(|| format!("no pose for link '{}'", lt.name))?;
        // A link that does not move is where it is at every s: checked as it is, ungrown (a
        // base resting on a table is not a near miss).
        let delta = if path.speeds()[ti] > 0.0 { path.bound(ti, poses, start + half, half) } else { 0.0 };
        // A ball around the link, grown by the bound, apart from every box near it: clear at any
        // growth, without a walk of the cells.
        let (centre, radius) = self.motion_bounds().ball[ti];
        if self.scene().ball_is_clear_near(pose * centre, radius + delta, |oi| !self.allowed[ti][oi], witness) {
            return Ok(Stretch::Clear);
        }
        let grown = grown_for(self.motion_bounds(), ti, pose, delta, path.floor(ti));
        // Swept along its velocity where the stretch can still be split: a link that meets
        // nothing so is clear; one that may (the swept test proves only "apart") is split. A
        // stretch that cannot be split asks the grown link, whose contact its report gives.
        let sweep = if grown.tested && !grown.settled { path.sweep(ti, poses, start + half, half) } else { None };
        Ok(Stretch::judge(start, grown, None, || match sweep {
            Some((along, rest)) => self.swept_link_hit(&grown, along, rest, &FLAGS),
            None => self.grown_link_hit(&grown, &FLAGS),
        }))
    }

    /// A stretch of self pair `(ta, tb)`: cleared when its two links at the middle, each grown by
    /// its own displacement bound, do not meet (then they stay apart all along the stretch).
    /// `hint`: the axis that last separated the pair, in the first link's frame (see
    /// [`crate::collision::pair_may_meet_grown`]).
    fn judge_pair(&self, path: &impl MotionPath, ta: usize, tb: usize, at: At, hint: &mut Vector) -> Result<Stretch, String> {
        let At { poses, start, half } = at;
        let (la, lb) = (&self.targets()[ta], &self.targets()[tb]);
        let (Some(pa), Some(pb)) = (poses[la.link], poses[lb.link]) else {
            return Err(format!("no pose for link '{}' or '{}'", la.name, lb.name));
        };
        // Balls that hold the two links, each grown by its bound, apart: the pair stays apart
        // all along the stretch, at any growth (no hull test needed). Most pairs are cleared so,
        // on the quick bounds.
        let bounds = self.motion_bounds();
        let ((ca, ra), (cb, rb)) = (bounds.ball[ta], bounds.ball[tb]);
        let gap = (pa * ca - pb * cb).length() - ra - rb;
        let (quick_a, quick_b) = path.pair_bound_quick(ta, tb, poses, start + half, half);
        if gap > quick_a + quick_b {
            return Ok(Stretch::Clear);
        }
        let (delta_a, delta_b) = path.pair_bound(ta, tb, poses, start + half, half);
        if gap > delta_a + delta_b {
            return Ok(Stretch::Clear);
        }
        let (a, b) = (grown_for(bounds, ta, pa, delta_a, path.floor(ta)), grown_for(bounds, tb, pb, delta_b, path.floor(tb)));
        Ok(Stretch::judge(start, a, Some(b), || self.pair_may_meet_within(&a, delta_a.max(0.0), &b, delta_b.max(0.0), hint)))
    }
}

/// The report of a motion found colliding on the stretch starting at `fraction`.
fn blocked_report(mut report: StateReport, fraction: f64, examined: u64) -> MotionReport {
    report.in_collision = true;
    report.motion = true;
    report.fraction = Some(fraction);
    MotionReport { report, fraction: Some(fraction), subintervals: examined }
}
