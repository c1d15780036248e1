//! The contact searches of one surface for one target, as [`walk`] visitors: every colliding
//! cell in turn ([`EachHit`]), or the deepest ([`deepest_cell`]).

use super::cell_contact::{normal_axis_deeper, quick_decide, LocalPair, NormalAxis, RecentAxes};
use super::cell_tree::CellTree;
use super::cell_walk::{walk, CellVisitor};
use super::convex_hull::MANY;
use super::gjk::{self, Verdict};
use super::sat::SatOverlap;
use super::target::TargetShape;
use super::target_view::TargetView;
use crate::math::{Real, Vector};
use crate::thickness::{ThicknessArea, ThicknessCell};
use std::ops::ControlFlow;

/// A colliding cell, in the target's frame: its index in the area, its depth along the push-out
/// normal `push`, and the SAT's result when it ran.
pub(crate) struct CellFound {
    pub index: u32,
    pub depth: Real,
    pub push: Vector,
    pub sat: Option<SatOverlap>,
}

/// Hands every colliding cell to `on_hit`, which may end the walk. Subtrees nearer the target's
/// centre go first: a yes/no question ends at the first cell that collides, most likely under the
/// target (on the motion benchmark, where most such questions are asked, a test that hit cost
/// ~24 µs walking the tree left first).
pub(crate) struct EachHit<'a, F> {
    area: &'a ThicknessArea,
    /// Cells reached (owned, not a reference into the report: a store through a reference in
    /// the hot loop made the compiler reload the visitor's state after it).
    pub candidates: usize,
    /// Whether a "yes" is confirmed by the SAT (for its least overlap).
    need_sat: bool,
    recent: RecentAxes,
    on_hit: F,
}

impl<'a, F: FnMut(CellFound) -> ControlFlow<()>> EachHit<'a, F> {
    pub fn new(area: &'a ThicknessArea, need_sat: bool, on_hit: F) -> Self {
        EachHit { area, candidates: 0, need_sat, recent: RecentAxes::default(), on_hit }
    }
}

// The visitors' methods are inlined into the walk, so that its state stays in registers: with
// them out of line the walk measured 3-7 % slower than one hand-written loop (peer_compare).
impl<F: FnMut(CellFound) -> ControlFlow<()>> CellVisitor for EachHit<'_, F> {
    #[inline(always)]
    fn root(&mut self, tree: &CellTree, view: &TargetView) -> Option<Real> {
        tree.bound(0, view).map(|_| 0.0)
    }

    #[inline(always)]
    fn children(&mut self, tree: &CellTree, children: [u32; 2], view: &TargetView) -> [Option<Real>; 2] {
        let boxes = children.map(|child| tree.node_box(child));
        let keep = boxes.map(|(centre, half)| !self.recent.separate_box(centre, half));
        let bounds = tree.bounds(children, keep, view);
        [0, 1].map(|k| bounds[k].map(|_| -(boxes[k].0 - view.centre).length_squared()))
    }

    #[inline(always)]
    fn worth(&self, _: Real) -> bool {
        true
    }

    #[inline(always)]
    fn leaf(&mut self, tree: &CellTree, node: u32, view: &TargetView) -> ControlFlow<()> {
        // Counted in a register, added once: the loop stays free of a store-to-load chain.
        let mut reached = 0;
        let mut flow = ControlFlow::Continue(());
        for (index, slab) in tree.leaf_cells(node) {
            reached += 1;
            if !CellTree::slab_meets_target_box(slab, view) || self.recent.separate_box(slab.centre(), slab.half()) {
                continue;
            }
            let translation = view.object_in_target.translation;
            let Some((push, depth)) = normal_axis_deeper(view.target, slab, view.side, &view.rotation, translation, Real::NEG_INFINITY) else {
                continue;
            };
            let (hit, sat) = decide(view, &self.area.cells[index as usize], &mut self.recent, self.need_sat);
            if hit {
                flow = (self.on_hit)(CellFound { index, depth, push, sat });
                if flow.is_break() {
                    break;
                }
            }
        }
        self.candidates += reached;
        flow
    }
}

/// How much deeper than the deepest contact found a subtree's bound must be to be searched: the
/// reported contact is the deepest to within this (metres), and flat patches, whose bound equals
/// their depth up to rounding, are not searched again and again.
const DEPTH_TOLERANCE: Real = 1e-9;

/// The deepest colliding cell of one surface. Depth first, the child with the deeper bound first,
/// and a subtree is skipped when its bound cannot beat the deepest collision found. (A best-first
/// search with a heap, which stops at the first bound that cannot, measured 2 % slower on the
/// Panda benchmark: with these bounds it expands nearly the same nodes, and pays for the heap.)
/// Pairs are decided by [`decide`]'s quick tests and GJK where they can; with `least_overlap` the
/// winner's full SAT gives its least overlap (and, were it to disagree with them, the search is
/// run again with the SAT alone deciding).
pub(crate) fn deepest_cell(area: &ThicknessArea, tree: &CellTree, view: &TargetView, candidates: &mut usize, least_overlap: bool) -> Option<CellFound> {
    let found = Deepest::search(area, tree, view, candidates, true)?;
    if found.sat.is_some() || !least_overlap {
        return Some(found);
    }
    if let Some(sat) = LocalPair::new(view.target, &area.cells[found.index as usize], &view.object_in_target).sat() {
        return Some(CellFound { sat: Some(sat), ..found });
    }
    // A quick verdict and the SAT disagreed (rounding on a razor-thin overlap): search again
    // with the SAT alone deciding.
    Deepest::search(area, tree, view, candidates, false)
}

/// The visitor of [`deepest_cell`]: keys are the subtrees' depth bounds.
struct Deepest<'a> {
    area: &'a ThicknessArea,
    /// Cells reached (owned: see [`EachHit::candidates`]).
    candidates: usize,
    /// Whether quick verdicts may decide (else the SAT decides every pair).
    quick: bool,
    recent: RecentAxes,
    best: Option<CellFound>,
    best_depth: Real,
    leaf_hits: Vec<(Real, u32, Vector)>,
}

impl<'a> Deepest<'a> {
    fn search(area: &'a ThicknessArea, tree: &CellTree, view: &TargetView, candidates: &mut usize, quick: bool) -> Option<CellFound> {
        let mut search =
            Deepest { area, candidates: 0, quick, recent: RecentAxes::default(), best: None, best_depth: Real::NEG_INFINITY, leaf_hits: Vec::with_capacity(8) };
        let _ = walk(tree, view, &mut search);
        *candidates += search.candidates;
        search.best
    }

    /// The cells of a leaf whose bounds beat the deepest found, into `leaf_hits` with their
    /// depths; their support queries are made together (a leaf holds at most MANY cells:
    /// `cell_tree` asserts it).
    #[inline(always)]
    fn leaf_candidates(&mut self, tree: &CellTree, node: u32, view: &TargetView) {
        self.leaf_hits.clear();
        let floor = self.best_depth + DEPTH_TOLERANCE;
        let leaf = tree.leaf_view(node, view);
        let mut axes = [(0u32, NormalAxis::default()); MANY];
        let mut dirs = [Vector::ZERO; MANY];
        let mut count = 0;
        let mut reached = 0;
        for (index, slab) in tree.leaf_cells(node) {
            reached += 1;
            if slab.depth_bound(&leaf) <= floor {
                continue;
            }
            if !CellTree::slab_meets_target_box(slab, view) || self.recent.separate_box(slab.centre(), slab.half()) {
                continue;
            }
            let axis = NormalAxis::new(view.target, slab, view.side, &view.rotation, view.object_in_target.translation);
            dirs[count] = axis.first_query();
            axes[count] = (index, axis);
            count += 1;
        }
        self.candidates += reached;
        let mut supports = [0.0; MANY];
        view.target.shape.support_many(&dirs[..count], &mut supports[..count]);
        for ((index, axis), first) in axes[..count].iter().zip(supports) {
            if let Some((push, depth)) = axis.finish(view.target, first, floor) {
                self.leaf_hits.push((depth, *index, push));
            }
        }
    }
}

impl CellVisitor for Deepest<'_> {
    #[inline(always)]
    fn root(&mut self, tree: &CellTree, view: &TargetView) -> Option<Real> {
        tree.bound(0, view)
    }

    #[inline(always)]
    fn children(&mut self, tree: &CellTree, children: [u32; 2], view: &TargetView) -> [Option<Real>; 2] {
        let keep = children.map(|child| {
            let (centre, half) = tree.node_box(child);
            !self.recent.separate_box(centre, half)
        });
        tree.bounds(children, keep, view)
    }

    #[inline(always)]
    fn worth(&self, bound: Real) -> bool {
        bound > self.best_depth + DEPTH_TOLERANCE
    }

    #[inline(always)]
    fn leaf(&mut self, tree: &CellTree, node: u32, view: &TargetView) -> ControlFlow<()> {
        self.leaf_candidates(tree, node, view);
        // Deepest first: the first that collides is the leaf's deepest contact. Picked one by
        // one, as the first pick usually settles the leaf.
        let hits = &mut self.leaf_hits;
        while let Some(k) = (0..hits.len()).max_by(|&a, &b| hits[a].0.total_cmp(&hits[b].0)) {
            let (depth, index, push) = hits.swap_remove(k);
            let (hit, sat) = decide(view, &self.area.cells[index as usize], &mut self.recent, !self.quick);
            if hit {
                self.best = Some(CellFound { index, depth, push, sat });
                self.best_depth = depth;
                break;
            }
        }
        ControlFlow::Continue(())
    }
}

/// Whether a target and a cell whose normal axis does not separate them collide. Quick tests
/// first ([`quick_decide`]), then for hulls a GJK whose verdicts carry their proofs
/// ([`gjk::hull_cell`]); the SAT when neither can tell, or to confirm a "yes" when `need_sat` (its
/// least overlap is wanted). Separating axes found are remembered in `recent`. Returns the
/// verdict and the SAT's result when it ran.
fn decide(view: &TargetView, cell: &ThicknessCell, recent: &mut RecentAxes, need_sat: bool) -> (bool, Option<SatOverlap>) {
    match quick_decide(view, cell, recent) {
        Some(false) => return (false, None),
        Some(true) if !need_sat => return (true, None),
        _ => {}
    }
    // A separating axis (target frame) found below, kept for the neighbouring cells.
    let mut remember = |axis: Vector| {
        let axis = view.object_in_target.rotation.inverse() * axis;
        recent.remember(axis, view.extent_along(axis));
    };
    if let TargetShape::Swept { core, sweep } = &view.target.shape {
        // No faces for the SAT: what the GJK cannot prove apart counts as met (a swept hull is
        // asked only whether a stretch might meet something, and "yes" splits it).
        return match gjk::swept_hull_cell(core, *sweep, &cell.vertices().map(|v| view.object_in_target * v)) {
            Verdict::Apart(axis) => {
                remember(axis.normalize());
                (false, None)
            }
            Verdict::Overlap | Verdict::Unknown => (true, None),
        };
    }
    if let TargetShape::Polytope(hull) = &view.target.shape {
        match gjk::hull_cell(hull, &cell.vertices().map(|v| view.object_in_target * v)) {
            // With `need_sat` the SAT below confirms it and gives the least overlap.
            Verdict::Overlap if !need_sat => return (true, None),
            Verdict::Overlap | Verdict::Unknown => {}
            Verdict::Apart(axis) => {
                remember(axis.normalize());
                return (false, None);
            }
        }
    }
    match LocalPair::new(view.target, cell, &view.object_in_target).sat_or_axis() {
        Ok(sat) => (true, Some(sat)),
        Err(separating) => {
            if let Some(axis) = separating {
                remember(axis);
            }
            (false, None)
        }
    }
}
