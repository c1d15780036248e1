//! What a scene query keeps: the collectors of [`Scene::query`](super::scene::Scene). One walk
//! over the objects and their cell trees serves every question; a collector decides what a hit
//! means (the answer to a yes/no question, one of every contact, a candidate for the deepest)
//! and when the question is answered.

use super::cell_contact::LocalPair;
use super::cell_search::{deepest_cell, CellFound, EachHit};
use super::cell_tree::CellTree;
use super::cell_walk::walk;
use super::report::{Contact, LeastOverlap, TargetReport};
use super::target::{Target, TargetShape};
use super::target_view::TargetView;
use crate::math::{Pose, Real};
use crate::thickness::ThicknessArea;
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
