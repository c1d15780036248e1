//! Grown links for the motion loop: whether a link (or a self pair), grown to cover its motion
//! over a stretch, meets anything, and the contact a blocked motion reports.

use super::checker::Checker;
use super::motion_bounds::grow;
use super::motion_sweep::Grown;
use super::state_report::{ObjectType, ReportContact, StateReport};
use crate::collision::{collide_pair, pair_may_meet_grown, CollideSettings, PairContact, Target, TargetShape};
use crate::math::{Pose, Real, Vector};

impl Checker {
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

    /// Whether the grown target, every part grown by its level, touches anything it may not.
    pub(super) fn grown_link_hit(&self, g: &Grown, settings: &CollideSettings) -> bool {
        self.targets()[g.ti].parts.iter().enumerate().any(|(pi, (_, offset))| {
            let target = Target::new(self.grown_part(g.ti, pi, g.level).clone(), g.pose * *offset);
            !self.collide_target(g.ti, &target, settings).contacts.is_empty()
        })
    }

    /// Whether the target at `g`'s pose, swept along the segment `±along` (world frame) and
    /// grown by `rest` (its ladder level covering it), may touch anything it may not: "no" is
    /// proved, "yes" may be a part the GJK could not prove apart. A part that is not a hull is
    /// grown by `g`'s level instead (the whole bound).
    pub(super) fn swept_link_hit(&self, g: &Grown, along: Vector, rest: Real, settings: &CollideSettings) -> bool {
        let bounds = self.motion_bounds();
        let level = bounds.level(rest);
        if !(bounds.growth(level) >= rest) {
            return self.grown_link_hit(g, settings);
        }
        self.targets()[g.ti].parts.iter().enumerate().any(|(pi, (_, offset))| {
            let pose = g.pose * *offset;
            let shape = match self.grown_part(g.ti, pi, Some(level)) {
                TargetShape::Polytope(core) => TargetShape::Swept { core: core.clone(), sweep: pose.rotation.inverse() * along },
                _ => self.grown_part(g.ti, pi, g.level).clone(),
            };
            !self.collide_target(g.ti, &Target::new(shape, pose), settings).contacts.is_empty()
        })
    }

    /// Whether any part of target `a` grown by a ball of radius `delta_a` may meet any part of
    /// `b` grown by `delta_b`, both as they are at their grown poses (see
    /// [`pair_may_meet_grown`]).
    /// `hint`: where the search starts and the separating axis found (see
    /// [`pair_may_meet_grown`]), shared by the pair's parts.
    pub(super) fn pair_may_meet_within(&self, a: &Grown, delta_a: Real, b: &Grown, delta_b: Real, hint: &mut Vector) -> bool {
        let (ta, tb) = (&self.targets()[a.ti], &self.targets()[b.ti]);
        ta.parts.iter().any(|(sa, oa)| {
            let part_a = Target::new(sa.clone(), a.pose * *oa);
            tb.parts.iter().any(|(sb, ob)| pair_may_meet_grown(&part_a, delta_a, &Target::new(sb.clone(), b.pose * *ob), delta_b, hint))
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

    /// `report` (that of the pose where the motion was blocked) with, for a near miss (the link
    /// does not collide there), the object the grown link touched, depth 0.
    pub(super) fn motion_contact(&self, mut report: StateReport, g: &Grown) -> StateReport {
        let lt = &self.targets()[g.ti];
        if !report.contacts.iter().any(|c| c.link_name == lt.name) {
            let settings = CollideSettings { flag_only: false, least_overlap: false, ..Default::default() };
            let near = lt.parts.iter().enumerate().find_map(|(pi, (_, offset))| {
                self.collide_target(g.ti, &Target::new(self.grown_part(g.ti, pi, g.level).clone(), g.pose * *offset), &settings).deepest().copied()
            });
            if let Some(c) = near {
                report.contacts.push(ReportContact {
                    link_name: lt.name.clone(),
                    object_name: self.scene().objects()[c.object].name.clone(),
                    triangle: self.scene().reported_triangle(c.object, c.triangle),
                    depth: 0.0,
                    position: c.position.map(|p| p.to_array()),
                    normal: c.normal.to_array(),
                    object_type: ObjectType::Environment,
                    link_type: self.target_kind(g.ti),
                });
            }
        }
        report
    }

    /// As [`Checker::motion_contact`] for a self pair: for a near miss, the pair the grown links
    /// met as, depth 0.
    pub(super) fn motion_self_contact(&self, mut report: StateReport, a: &Grown, b: &Grown) -> StateReport {
        let (name_a, name_b) = (&self.targets()[a.ti].name, &self.targets()[b.ti].name);
        if !report.contacts.iter().any(|c| &c.link_name == name_a && &c.object_name == name_b) {
            if let Some(c) = self.grown_pair_contact(a.ti, a.level, &a.pose, b.ti, b.level, &b.pose) {
                report.contacts.push(ReportContact {
                    link_name: name_a.clone(),
                    object_name: name_b.clone(),
                    triangle: u32::MAX,
                    depth: 0.0,
                    position: Some(c.position.to_array()),
                    normal: c.normal.to_array(),
                    object_type: self.target_kind(b.ti),
                    link_type: self.target_kind(a.ti),
                });
            }
        }
        report
    }
}
