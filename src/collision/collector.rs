//! What a scene query keeps: the collectors of [`Scene::query`](super::scene::Scene). One walk
//! over the objects and their cell trees serves every question; a collector decides what a hit
//! means (the answer to a yes/no question, one of every contact, a candidate for the deepest)
//! and when the question is answered.

use super::cell_contact::LocalPair;
use super::cell_search::{deepest_cell, CellFound, EachHit};
use super::cell_tree::CellTree;
use super::cell_walk::{walk, CellVisitor};
use super::report::{Contact, LeastOverlap, TargetReport};
use super::target::{Target, TargetShape};
use super::target_view::TargetView;
use crate::math::{Aabb, Pose, Real};
use crate::thickness::ThicknessArea;
use parry3d_f64::bounding_volume::BoundingVolume;
use std::ops::ControlFlow;

/// A query's side of the walk over a scene's objects.
pub(crate) trait Collector {
    /// How far from the target an object's box may be and still matter (0: it must touch).
    fn reach(&self) -> Real {
        0.0
    }

    /// A convex solid whose box meets the target's (within [`Collector::reach`]). `Break`: the
    /// question is answered.
    fn solid(&mut self, object: usize, target: &Target, pose: &Pose, shape: &TargetShape) -> ControlFlow<()>;

    /// A thin surface whose box meets the target's, seen from its frame.
    fn surface(&mut self, object: usize, area: &ThicknessArea, tree: &CellTree, view: &TargetView) -> ControlFlow<()>;
}

/// The contact of a cell found in a surface, in the world frame; without its point.
fn cell_contact(object: usize, area: &ThicknessArea, view: &TargetView, found: &CellFound) -> Contact {
    let rot = view.target.pose.rotation;
    let least = found.sat.map(|s| LeastOverlap { overlap: s.overlap, axis: rot * s.axis });
    Contact { object, triangle: area.cells[found.index as usize].triangle, depth: found.depth, normal: rot * found.push, position: None, least }
}

/// [`cell_contact`] with its contact point.
fn cell_contact_with_point(object: usize, area: &ThicknessArea, view: &TargetView, found: &CellFound) -> Contact {
    let cell = &area.cells[found.index as usize];
    let position = LocalPair::new(view.target, cell, &view.object_in_target).point(found.push).map(|p| view.target.pose * p);
    Contact { position, ..cell_contact(object, area, view, found) }
}

/// A target against a convex solid, with parry's GJK/EPA: the depth is the penetration depth, the
/// normal the direction that pushes the target out, the point midway between the two witnesses.
fn collide_solid(target: &Target, object: usize, object_pose: &Pose, shape: &TargetShape) -> Option<Contact> {
    let c = target
        .shape
        .with_parry(|s1, o1| shape.with_parry(|s2, o2| parry3d_f64::query::contact(&(target.pose * *o1), s1, &(*object_pose * *o2), s2, 0.0).ok().flatten()))?;
    if !(c.dist < 0.0) {
        return None;
    }
    let normal = -c.normal1;
    Some(Contact {
        object,
        triangle: u32::MAX,
        depth: -c.dist,
        normal,
        position: Some((c.point1 + c.point2) * 0.5),
        least: Some(LeastOverlap { overlap: -c.dist, axis: normal }),
    })
}

/// A yes/no question: the first colliding cell or solid answers it, with no contact point.
pub(crate) struct AnyHit {
    pub report: TargetReport,
    /// Whether the hit's least overlap is wanted (the SAT confirms it).
    pub least_overlap: bool,
}

impl Collector for AnyHit {
    fn solid(&mut self, object: usize, target: &Target, pose: &Pose, shape: &TargetShape) -> ControlFlow<()> {
        self.report.candidates += 1;
        let Some(contact) = collide_solid(target, object, pose, shape) else {
            return ControlFlow::Continue(());
        };
        self.report.objects.push(object);
        self.report.contacts.push(contact);
        ControlFlow::Break(())
    }

    fn surface(&mut self, object: usize, area: &ThicknessArea, tree: &CellTree, view: &TargetView) -> ControlFlow<()> {
        let mut first = None;
        let mut stop_at_first = |hit| {
            first = Some(hit);
            ControlFlow::Break(())
        };
        let mut search = EachHit::new(area, self.least_overlap, &mut stop_at_first);
        let _ = walk(tree, view, &mut search);
        self.report.candidates += search.candidates;
        let Some(hit) = first else {
            return ControlFlow::Continue(());
        };
        self.report.objects.push(object);
        self.report.contacts.push(cell_contact(object, area, view, &hit));
        ControlFlow::Break(())
    }
}

/// The leaves of one surface's tree under a region around a target's box (the surface's frame),
/// for one part of a target asked again and again near the same place (a link along a motion).
#[derive(Clone, Debug)]
pub(crate) struct KeptLeaves {
    part: usize,
    object: usize,
    region: Aabb,
    leaves: Vec<u32>,
    /// Where in `leaves` the last hit was found: the next search starts there (a link near a
    /// surface mostly meets it where it met it a moment before).
    last_hit: usize,
}

/// Leaves kept per region at most: a region past this is walked each time.
const MAX_KEPT_LEAVES: usize = 4096;

/// [`AnyHit`] that keeps, per surface, the leaves under a region around the target's box grown
/// by `margin`, and checks a target whose box lies within a kept region against its leaves
/// without walking the tree down to them. A region is made anew when the box leaves it, or when
/// it has become much larger than the box needs (the leaves beyond would only be read in vain).
pub(crate) struct AnyHitKept<'k> {
    pub report: TargetReport,
    part: usize,
    margin: Real,
    kept: &'k mut Vec<KeptLeaves>,
}

impl<'k> AnyHitKept<'k> {
    /// The first hit of part `part` of a target; `margin` (metres, at least 0) around its box.
    pub fn new(part: usize, margin: Real, kept: &'k mut Vec<KeptLeaves>) -> Self {
        AnyHitKept { report: TargetReport::default(), part, margin: margin.max(0.0), kept }
    }
}

/// Whether `inner` lies within `outer` and `outer` is at most `slack` wider on every side.
fn fits(outer: &Aabb, inner: &Aabb, slack: Real) -> bool {
    let (lo, hi) = (inner.mins - outer.mins, outer.maxs - inner.maxs);
    lo.min_element() >= 0.0 && hi.min_element() >= 0.0 && lo.max_element() <= slack && hi.max_element() <= slack
}

impl Collector for AnyHitKept<'_> {
    fn solid(&mut self, object: usize, target: &Target, pose: &Pose, shape: &TargetShape) -> ControlFlow<()> {
        let mut any = AnyHit { report: std::mem::take(&mut self.report), least_overlap: false };
        let flow = any.solid(object, target, pose, shape);
        self.report = any.report;
        flow
    }

    fn surface(&mut self, object: usize, area: &ThicknessArea, tree: &CellTree, view: &TargetView) -> ControlFlow<()> {
        let (part, margin) = (self.part, self.margin);
        let slot = match self.kept.iter().position(|k| k.part == part && k.object == object) {
            Some(i) => i,
            None => {
                self.kept.push(KeptLeaves { part, object, region: Aabb::new_invalid(), leaves: Vec::new(), last_hit: 0 });
                self.kept.len() - 1
            }
        };
        let kept = &mut self.kept[slot];
        if !fits(&kept.region, &view.aabb, 3.0 * margin) {
            kept.region = view.aabb.loosened(margin);
            kept.last_hit = 0;
            if !tree.leaves_meeting(&kept.region, MAX_KEPT_LEAVES, &mut kept.leaves) {
                kept.region = Aabb::new_invalid();
                let mut any = AnyHit { report: std::mem::take(&mut self.report), least_overlap: false };
                let flow = any.surface(object, area, tree, view);
                self.report = any.report;
                return flow;
            }
        }
        let mut first = None;
        let mut stop_at_first = |hit| {
            first = Some(hit);
            ControlFlow::Break(())
        };
        let mut search = EachHit::new(area, false, &mut stop_at_first);
        let n = kept.leaves.len();
        for k in 0..n {
            let at = (kept.last_hit + k) % n;
            if search.leaf(tree, kept.leaves[at], view).is_break() {
                kept.last_hit = at;
                break;
            }
        }
        self.report.candidates += search.candidates;
        let Some(hit) = first else {
            return ControlFlow::Continue(());
        };
        self.report.objects.push(object);
        self.report.contacts.push(cell_contact(object, area, view, &hit));
        ControlFlow::Break(())
    }
}

/// Every colliding cell and solid, each with its contact point and least overlap.
#[derive(Default)]
pub(crate) struct AllHits {
    pub report: TargetReport,
}

impl Collector for AllHits {
    fn solid(&mut self, object: usize, target: &Target, pose: &Pose, shape: &TargetShape) -> ControlFlow<()> {
        self.report.candidates += 1;
        if let Some(contact) = collide_solid(target, object, pose, shape) {
            self.report.objects.push(object);
            self.report.contacts.push(contact);
        }
        ControlFlow::Continue(())
    }

    fn surface(&mut self, object: usize, area: &ThicknessArea, tree: &CellTree, view: &TargetView) -> ControlFlow<()> {
        let report = &mut self.report;
        let before = report.contacts.len();
        let contacts = &mut report.contacts;
        let mut search = EachHit::new(area, true, |hit| {
            contacts.push(cell_contact_with_point(object, area, view, &hit));
            ControlFlow::Continue(())
        });
        let _ = walk(tree, view, &mut search);
        report.candidates += search.candidates;
        if report.contacts.len() > before {
            report.objects.push(object);
        }
        ControlFlow::Continue(())
    }
}

/// Every colliding object, and the deepest contact over them all.
pub(crate) struct DeepestHit {
    report: TargetReport,
    deepest: Option<Contact>,
    least_overlap: bool,
}

impl DeepestHit {
    pub fn new(least_overlap: bool) -> Self {
        DeepestHit { report: TargetReport::default(), deepest: None, least_overlap }
    }

    pub fn into_report(self) -> TargetReport {
        let mut report = self.report;
        report.contacts.extend(self.deepest);
        report
    }

    fn deeper(&self, depth: Real) -> bool {
        self.deepest.as_ref().is_none_or(|d| depth > d.depth)
    }
}

impl Collector for DeepestHit {
    fn solid(&mut self, object: usize, target: &Target, pose: &Pose, shape: &TargetShape) -> ControlFlow<()> {
        self.report.candidates += 1;
        if let Some(contact) = collide_solid(target, object, pose, shape) {
            self.report.objects.push(object);
            if self.deeper(contact.depth) {
                self.deepest = Some(contact);
            }
        }
        ControlFlow::Continue(())
    }

    fn surface(&mut self, object: usize, area: &ThicknessArea, tree: &CellTree, view: &TargetView) -> ControlFlow<()> {
        if let Some(found) = deepest_cell(area, tree, view, &mut self.report.candidates, self.least_overlap) {
            self.report.objects.push(object);
            if self.deeper(found.depth) {
                self.deepest = Some(cell_contact_with_point(object, area, view, &found));
            }
        }
        ControlFlow::Continue(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::collision::{CollideSettings, ConvexHull, Scene};
    use crate::math::{Rotation, Vector};
    use crate::mesh::{generate, MeshTopology, TopologySettings};
    use crate::thickness::{ThicknessArea, ThicknessSettings};
    use std::sync::Arc;

    /// A link wandering near a wavy sheet, asked again and again with the same kept leaves (as
    /// a motion asks): every answer is the tree walk's, through regions kept, remade and
    /// outgrown; a link asked with no margin and one far away alike.
    #[test]
    fn kept_leaves_give_the_walks_answers() {
        let mut rng = oorandom::Rand64::new(451);
        let mut rf = |lo: Real, hi: Real| lo + (hi - lo) * rng.rand_float();
        let (v, t) = generate::wavy_sheet(60, 60, 1.2, 1.2, 0.05, 0.5);
        let mesh = MeshTopology::build(&v, &t, &TopologySettings::default()).unwrap();
        let area = ThicknessArea::build(&mesh, &ThicknessSettings { thickness: 0.02, ..Default::default() }).unwrap();
        let mut scene = Scene::new();
        let _ = scene.add_surface("sheet", Pose::from_translation(Vector::new(-0.6, -0.6, 0.0)), area);
        let points: Vec<Vector> = (0..16).map(|_| Vector::new(rf(-0.05, 0.05), rf(-0.03, 0.03), rf(-0.1, 0.1))).collect();
        let hull = TargetShape::Polytope(Arc::new(ConvexHull::from_points(&points).unwrap()));
        let flags = CollideSettings { flag_only: true, least_overlap: false, ..Default::default() };
        let mut kept = Vec::new();
        let (mut centre, mut hits, mut misses) = (Vector::new(0.0, 0.0, 0.1), 0, 0);
        for k in 0..3000 {
            // A small step most of the time, now and then a jump (a region outgrown).
            let step = if k % 97 == 0 { 0.4 } else { 0.01 };
            centre = (centre + Vector::new(rf(-step, step), rf(-step, step), rf(-step, step) * 0.5)).clamp(Vector::new(-0.7, -0.7, -0.15), Vector::new(0.7, 0.7, 0.2));
            let rotation = Rotation::from_axis_angle(Vector::new(rf(-1.0, 1.0), rf(-1.0, 1.0), 1.0).normalize(), rf(0.0, 3.0));
            let target = Target::new(hull.clone(), Pose::from_parts(centre, rotation));
            let walked = !scene.collide(&target, &flags).contacts.is_empty();
            let margin = [0.0, 0.005, 0.03][k % 3];
            assert_eq!(scene.any_hit_kept(&target, &|_| true, 0, margin, &mut kept), walked, "query {k} at {centre:?}, margin {margin}");
            if walked {
                hits += 1;
            } else {
                misses += 1;
            }
        }
        assert!(hits > 300 && misses > 300, "{hits} hits, {misses} misses");
        assert_eq!(kept.len(), 1, "one region per part and surface");
    }
}
