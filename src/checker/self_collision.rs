//! Self-collision: which pairs of the robot's checked links are checked against each other, and
//! the check itself.
//!
//! The allowed collision matrix is the SRDF's (`disable_collisions`, `disable_default_collisions`,
//! `enable_collisions`) when there is one, else MoveIt's default reasoning: adjacent links (a
//! link without geometry is transparent, so `panda_link7` and `panda_hand`, joined through
//! `panda_link8`, are adjacent) and pairs that touch at the zero state (within `motion_tolerance`). `allowed_collisions`
//! entries naming two robot links allow that pair either way round.

use super::checker::Checker;
use super::link_targets::LinkTargets;
use super::self_pairs::SelfPairs;
use super::state_report::ReportContact;
use crate::collision::{collide_pair, PairContact, Target};
use crate::math::Pose;
use crate::model::{RobotModel, Srdf};
use std::collections::BTreeSet;

/// Target pairs joined through links without a target (transparent), as target indices.
fn adjacent_pairs(robot: &RobotModel, targets: &[LinkTargets]) -> BTreeSet<(usize, usize)> {
    let mut target_of = vec![None; robot.links.len()];
    for (ti, t) in targets.iter().enumerate() {
        target_of[t.link] = Some(ti);
    }
    // Undirected link graph.
    let mut neighbours = vec![Vec::new(); robot.links.len()];
    for j in &robot.joints {
        neighbours[j.parent].push(j.child);
        neighbours[j.child].push(j.parent);
    }
    let mut pairs = BTreeSet::new();
    for (ti, t) in targets.iter().enumerate() {
        // Flood through transparent links; stop at links with a target.
        let mut seen = vec![false; robot.links.len()];
        seen[t.link] = true;
        let mut work = vec![t.link];
        while let Some(l) = work.pop() {
            for &n in &neighbours[l] {
                if std::mem::replace(&mut seen[n], true) {
                    continue;
                }
                match target_of[n] {
                    Some(other) => {
                        let _ = pairs.insert((ti.min(other), ti.max(other)));
                    }
                    None => work.push(n),
                }
            }
        }
    }
    pairs
}

impl SelfPairs {
    /// The pairs `checker` checks, from `srdf` or, without one, the default reasoning.
    pub(crate) fn build(checker: &Checker, srdf: Option<Srdf>) -> SelfPairs {
        let (params, robot, targets) = (checker.params(), checker.robot(), checker.targets());
        if !params.self_collision {
            return SelfPairs { srdf, ..Default::default() };
        }
        let allowed_by_params = |a: &str, b: &str| params.is_allowed(a, b) || params.is_allowed(b, a);
        let mut candidates = Vec::new();
        for a in 0..targets.len() {
            for b in a + 1..targets.len() {
                if !allowed_by_params(&targets[a].name, &targets[b].name) {
                    candidates.push((a, b));
                }
            }
        }
        match srdf {
            Some(s) => {
                let pairs = candidates.into_iter().filter(|&(a, b)| !s.is_disabled(targets[a].link, targets[b].link)).collect();
                SelfPairs { pairs, srdf: Some(s), allowed_at_zero: Vec::new() }
            }
            None => {
                let adjacent = adjacent_pairs(robot, targets);
                let candidates: Vec<(usize, usize)> = candidates.into_iter().filter(|p| !adjacent.contains(p)).collect();
                // At the zero state (mimic joints from their masters, as forward kinematics
                // places them); a robot whose zero state cannot be placed keeps every pair.
                let zero = vec![0.0; robot.joints.len()];
                let touching: BTreeSet<(usize, usize)> = match robot.forward_kinematics(&zero, checker.base_pose()) {
                    Ok(poses) => {
                        let world: Vec<Option<Pose>> = poses.iter().map(|p| Some(crate::math::pose_from_isometry(p))).collect();
                        // Within motion_tolerance counts (each part grown by half of it): a
                        // closed gripper's fingers touch, and a pair that close at the start
                        // would make every motion from there a near miss.
                        candidates
                            .iter()
                            .copied()
                            .filter(|&(a, b)| match (world[targets[a].link], world[targets[b].link]) {
                                (Some(pa), Some(pb)) => checker.grown_pair_contact(a, Some(0), &pa, b, Some(0), &pb).is_some(),
                                _ => false,
                            })
                            .collect()
                    }
                    Err(_) => BTreeSet::new(),
                };
                let allowed_at_zero = touching.iter().map(|&(a, b)| (targets[a].name.clone(), targets[b].name.clone())).collect();
                let pairs = candidates.into_iter().filter(|p| !touching.contains(p)).collect();
                SelfPairs { pairs, srdf: None, allowed_at_zero }
            }
        }
    }
}

/// The deepest contact between the parts of targets `a` and `b` at the given world poses.
fn pair_contact(targets: &[LinkTargets], world: &[Option<Pose>], a: usize, b: usize) -> Option<PairContact> {
    let (ta, tb) = (&targets[a], &targets[b]);
    let (pa, pb) = (world[ta.link]?, world[tb.link]?);
    let mut best: Option<PairContact> = None;
    for (sa, oa) in &ta.parts {
        let part_a = Target::new(sa.clone(), pa * *oa);
        for (sb, ob) in &tb.parts {
            let part_b = Target::new(sb.clone(), pb * *ob);
            if let Some(c) = collide_pair(&part_a, &part_b) {
                if best.is_none_or(|x| c.depth > x.depth) {
                    best = Some(c);
                }
            }
        }
    }
    best
}

impl SelfPairs {
    /// One line for the start-up banner: how many pairs are checked and why the others are not
    /// (without an SRDF, the pairs that touch at the zero state are named: the list MoveIt's
    /// setup assistant would have asked about).
    pub fn summary(&self, checker: &Checker) -> String {
        let targets = checker.targets().len();
        let all = targets * targets.saturating_sub(1) / 2;
        if !checker.params().self_collision {
            return "self-collision off (self_collision: false)".into();
        }
        match &self.srdf {
            Some(s) => format!("self-collision: {} of {all} link pairs checked (SRDF {})", self.pairs.len(), s.source),
            None => {
                let named: Vec<String> = self.allowed_at_zero.iter().map(|(a, b)| format!("{a}:{b}")).collect();
                format!(
                    "self-collision: {} of {all} link pairs checked (no SRDF: adjacent pairs allowed, and {} touching at the zero state{}{})",
                    self.pairs.len(),
                    named.len(),
                    if named.is_empty() { "" } else { ": " },
                    crate::limits::name_list(&named)
                )
            }
        }
    }
}

impl Checker {
    /// One contact per colliding self pair at the given world poses: `link_name` the pair's first
    /// link in model order, `object_name` the other, `normal` pushing `link_name` out, `depth`
    /// the least overlap of its deepest pair of parts.
    pub(crate) fn self_contacts(&self, world: &[Option<Pose>]) -> Vec<ReportContact> {
        self.self_pairs().pairs.iter().filter_map(|&(a, b)| self.self_pair_contact(world, a, b)).collect()
    }

    /// The contact of self pair `(a, b)` at `world`, as a report gives it.
    pub(crate) fn self_pair_contact(&self, world: &[Option<Pose>], a: usize, b: usize) -> Option<ReportContact> {
        let targets = self.targets();
        let c = pair_contact(targets, world, a, b)?;
        Some(ReportContact {
            link_name: targets[a].name.clone(),
            object_name: targets[b].name.clone(),
            triangle: u32::MAX,
            depth: c.depth,
            position: Some(c.position.to_array()),
            normal: c.normal.to_array(),
            object_type: self.target_kind(b),
            link_type: self.target_kind(a),
        })
    }
}
