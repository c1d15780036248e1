//! The smallest clearance of each link over a whole trajectory segment, as the controller executes
//! it: never above the true minimum over every instant, and at most [`CLEARANCE_SLACK`] below it.
//!
//! Branch and bound over the segment's parameter: on a stretch, a link's clearance at the middle
//! minus how far its points can move on the stretch (the bound of `joint_spline`) is a lower bound
//! for the whole stretch; the least clearance seen at any middle is an upper bound for the
//! minimum. A stretch is split while some link's lower bound there is more than the slack below
//! that link's upper bound (and below `clearance_threshold`: a link that stays beyond it is not
//! reported, as for a state). The answer per link is the least lower bound over the final
//! stretches, with the points of the nearest configuration seen.

use super::checker::Checker;
use super::clearance::link_clearance;
use super::joint_spline::SplineSegment;
use super::motion_sweep::MotionPath;
use super::state_report::ReportClearance;

/// How far below the true minimum a reported path clearance may be (metres).
pub const CLEARANCE_SLACK: f64 = 1e-3;

/// Stretches examined at most per segment; past that the clearance is not given.
const MAX_CLEARANCE_STRETCHES: usize = 1 << 16;

impl Checker {
    /// Per checked link within `clearance_threshold` of the environment somewhere on the segment:
    /// its smallest clearance over the segment (see the module documentation), in link order;
    /// empty when the threshold is 0; and the stretches examined. An error when the segment
    /// cannot be posed or needs more than `budget` (at most [`MAX_CLEARANCE_STRETCHES`])
    /// stretches.
    pub fn spline_clearances(&self, segment: &SplineSegment, budget: usize) -> Result<(Vec<ReportClearance>, usize), String> {
        let threshold = self.params().clearance_threshold;
        if !(threshold > 0.0) {
            return Ok((Vec::new(), 0));
        }
        let budget = budget.min(MAX_CLEARANCE_STRETCHES);
        let path = self.spline_path(segment)?;
        let targets = self.targets().len();
        // Per target: the nearest clearance seen (its report), and the least lower bound over
        // the stretches not split further.
        let mut seen: Vec<Option<ReportClearance>> = vec![None; targets];
        let mut lower = vec![f64::INFINITY; targets];
        let mut stack = vec![(0.0f64, 1.0f64)];
        let mut examined = 0usize;
        while let Some((a, b)) = stack.pop() {
            examined += 1;
            if examined > budget {
                return Err(format!("the path clearance needs more than the {budget} stretches left to it; not given"));
            }
            let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
            let poses = path.link_poses(mid)?;
            let mut split = false;
            let mut bounds = Vec::with_capacity(targets);
            for (ti, target) in self.targets().iter().enumerate() {
                let Some(link_pose) = poses[target.link] else { return Err(format!("no pose for link '{}'", target.name)) };
                let moved = if path.speeds()[ti] > 0.0 { path.bound(ti, &poses, mid, half) } else { 0.0 };
                // Nothing within the threshold plus what the link can move: beyond the threshold
                // all along the stretch.
                let here = link_clearance(&self.scene, &self.allowed[ti], target, link_pose, None, threshold + moved);
                let Some(c) = here else {
                    bounds.push(threshold);
                    continue;
                };
                let lb = c.distance - moved;
                if c.distance < threshold && seen[ti].as_ref().is_none_or(|s| c.distance < s.distance) {
                    seen[ti] = Some(c);
                }
                let upper = seen[ti].as_ref().map_or(threshold, |s| s.distance);
                // A path tolerance's share of the bound does not shrink: stop once the rest does.
                split |= lb < upper - CLEARANCE_SLACK && moved - path.floor(ti) > 0.5 * CLEARANCE_SLACK;
                bounds.push(lb);
            }
            if split {
                stack.push((mid, b));
                stack.push((a, mid));
            } else {
                lower.iter_mut().zip(&bounds).for_each(|(l, lb)| *l = l.min(*lb));
            }
        }
        let found = seen
            .into_iter()
            .zip(lower)
            .enumerate()
            .filter(|(_, (_, l))| *l < threshold)
            .map(|(ti, (c, l))| {
                let mut c = c.unwrap_or_else(|| ReportClearance {
                    link_name: self.targets()[ti].name.clone(),
                    object_name: String::new(),
                    triangle: u32::MAX,
                    distance: threshold,
                    point_on_link: [f64::NAN; 3],
                    point_on_object: [f64::NAN; 3],
                });
                c.distance = l;
                c
            })
            .collect();
        Ok((found, examined))
    }
}
