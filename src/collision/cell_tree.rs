//! The broad phase over one thin surface's cells: a bounding-volume tree whose nodes also bound
//! the cells' normals, so a query for the deepest contact can skip whole subtrees.
//!
//! Why not parry's BVH alone: the deepest contact of a link pushed through a wall is the maximum
//! over every cell under the link's bounding box (thousands at 1M triangles), and an AABB tree can
//! only hand them all over. Each node here also carries a cone around its cells' normals and the
//! slab the cells occupy along the cone's axis; from those follow an upper bound on the depth any
//! of its cells can report (see `CellTree::bound`), and a search skips every subtree whose
//! bound cannot beat the deepest contact found. Where a surface is flat the bound is exact, and one
//! leaf answers for the whole plane. Boxes are also compared in the target's own frame (an
//! oriented-box test on three axes), which drops most of what a tilted link's world box takes in.
//!
//! Leaves hold 32 cells: on the Panda benchmark at 1M triangles, 4 and 8 were slower than 16 (more
//! nodes to bound); once a leaf's support queries were made together (their memory waits
//! overlapping), 32 beat 16 by 4 % (two trees in one process, runs interleaved), and 48 was no
//! better.

use super::cell_slab::{cell_box, f32_above, CellSlab, LeafView};
use super::target_view::TargetView;
use crate::math::{Aabb, Real, Vector};
use crate::thickness::{Side, ThicknessCell};

/// Cells per leaf.
const LEAF_CELLS: usize = 32;

// A leaf's support queries are made in one call (see `scene::deepest_search`).
const _: () = assert!(LEAF_CELLS <= super::convex_hull::MANY);

/// Slack when a node's slab is compared with the target: rounding must never prune a node whose
/// cells the exact per-cell test would keep.
const SLAB_SLACK: Real = 1e-10;

#[derive(Clone, Copy, Debug)]
pub(crate) struct CellNode {
    lo: Vector,
    hi: Vector,
    /// Unit axis of the cone around the cells' face normals.
    axis: Vector,
    /// Every cell normal `n` has `|n - axis| <= spread` (so 0 for a flat patch).
    spread: Real,
    /// `max axis . v` over the cells' vertices (an upper bound above the leaves).
    top: Real,
    /// `min axis . v` over the cells' vertices (a lower bound above the leaves).
    bottom: Real,
    /// Half the diagonal of the box.
    radius: Real,
    /// A leaf: the first index into `slabs`; an inner node: the index of its right child (the
    /// left child follows the node).
    first: u32,
    /// Cells in a leaf; 0 for an inner node.
    count: u32,
}

impl CellNode {
    fn centre(&self) -> Vector {
        (self.lo + self.hi) * 0.5
    }
}

/// The tree over one surface's cells, in the surface's frame.
#[derive(Clone, Debug, Default)]
pub struct CellTree {
    nodes: Vec<CellNode>,
    /// The cells' normal slabs in leaf order.
    slabs: Vec<CellSlab>,
}

/// `max dir . x` over a box.
fn box_support(lo: Vector, hi: Vector, dir: Vector) -> Real {
    let c = (lo + hi) * 0.5;
    let h = (hi - lo) * 0.5;
    dir.dot(c) + dir.abs().dot(h)
}

fn unit_or(v: Vector, fallback: Vector) -> Vector {
    let l = v.length();
    if l > 1e-12 && l.is_finite() {
        v / l
    } else {
        fallback
    }
}

struct Builder<'a> {
    cells: &'a [ThicknessCell],
    boxes: Vec<(Vector, Vector)>,
    nodes: Vec<CellNode>,
    /// Cell centres with their indices, permuted in place by the splits: the comparisons read
    /// contiguous memory (through an index array they cost a cache miss each at 1M cells).
    order: Vec<(Vector, u32)>,
}

impl Builder<'_> {
    /// Builds the subtree over `order[start..end]`; returns its node and the sum of its normals.
    fn build(&mut self, start: usize, end: usize) -> (usize, Vector) {
        let at = self.nodes.len();
        self.nodes.push(CellNode { lo: Vector::ZERO, hi: Vector::ZERO, axis: Vector::Z, spread: 0.0, top: 0.0, bottom: 0.0, radius: 0.0, first: 0, count: 0 });
        if end - start <= LEAF_CELLS {
            let mut leaf = [0u32; LEAF_CELLS];
            for (slot, (_, i)) in leaf.iter_mut().zip(&self.order[start..end]) {
                *slot = *i;
            }
            let ids = &leaf[..end - start];
            let (mut lo, mut hi) = self.boxes[ids[0] as usize];
            let mut sum = Vector::ZERO;
            for &i in ids {
                let (l, h) = self.boxes[i as usize];
                lo = lo.min(l);
                hi = hi.max(h);
                sum += self.cells[i as usize].normal;
            }
            let axis = unit_or(sum, self.cells[ids[0] as usize].normal);
            let (mut spread, mut top, mut bottom) = (Real::default(), Real::NEG_INFINITY, Real::INFINITY);
            for &i in ids {
                let cell = &self.cells[i as usize];
                spread = spread.max((cell.normal - axis).length());
                for v in cell.vertices() {
                    let d = axis.dot(v);
                    top = top.max(d);
                    bottom = bottom.min(d);
                }
            }
            self.nodes[at] = CellNode { lo, hi, axis, spread, top, bottom, radius: (hi - lo).length() * 0.5, first: start as u32, count: (end - start) as u32 };
            return (at, sum);
        }
        // Median split on the longest axis of the cells' centres.
        let (clo, chi) =
            self.order[start..end].iter().fold((Vector::splat(Real::INFINITY), Vector::splat(Real::NEG_INFINITY)), |(lo, hi), (c, _)| (lo.min(*c), hi.max(*c)));
        let ext = chi - clo;
        let k = if ext.x >= ext.y && ext.x >= ext.z {
            0
        } else if ext.y >= ext.z {
            1
        } else {
            2
        };
        let mid = (end - start) / 2;
        let _ = self.order[start..end].select_nth_unstable_by(mid, |a, b| a.0[k].total_cmp(&b.0[k]));
        let (left, sum_l) = self.build(start, start + mid);
        let (right, sum_r) = self.build(start + mid, end);
        let (l, r) = (self.nodes[left], self.nodes[right]);
        let sum = sum_l + sum_r;
        let axis = unit_or(sum, l.axis);
        let (lo, hi) = (l.lo.min(r.lo), l.hi.max(r.hi));
        let mut spread: Real = 0.0;
        let mut top = Real::NEG_INFINITY;
        let mut bottom = Real::INFINITY;
        for c in [l, r] {
            // Each child's cells: `axis . v = c.axis . v + (axis - c.axis) . v`, and `v` lies in
            // the child's box, within `c.radius` of its centre.
            let tilt = (axis - c.axis).length();
            spread = spread.max(tilt + c.spread);
            let moved = (axis - c.axis).dot(c.centre());
            top = top.max(c.top + moved + tilt * c.radius);
            bottom = bottom.min(c.bottom + moved - tilt * c.radius);
        }
        top = top.min(box_support(lo, hi, axis));
        bottom = bottom.max(-box_support(lo, hi, -axis));
        self.nodes[at] = CellNode { lo, hi, axis, spread: spread.min(2.0), top, bottom, radius: (hi - lo).length() * 0.5, first: right as u32, count: 0 };
        (at, sum)
    }
}

impl CellTree {
    /// The tree over `cells` (given in the surface's frame), which are put in the tree's leaf
    /// order: the cells a query decides lie next to each other in memory (on a 1M-triangle
    /// surface, input order cost a cache miss per cell). Each cell keeps its `triangle`.
    pub fn build(cells: &mut Vec<ThicknessCell>) -> CellTree {
        if cells.is_empty() {
            return CellTree::default();
        }
        let boxes: Vec<(Vector, Vector)> = cells.iter().map(cell_box).collect();
        let order = boxes.iter().enumerate().map(|(i, (lo, hi))| ((*lo + *hi) * 0.5, i as u32)).collect();
        let mut b = Builder { cells, boxes, nodes: Vec::with_capacity(2 * cells.len() / LEAF_CELLS + 2), order };
        let _ = b.build(0, cells.len());
        let (nodes, order) = (b.nodes, b.order);
        let sorted: Vec<ThicknessCell> = order.iter().map(|(_, i)| cells[*i as usize]).collect();
        *cells = sorted;
        let mut slabs: Vec<CellSlab> = cells.iter().map(CellSlab::of).collect();
        let mut nodes = nodes;
        nodes.shrink_to_fit();
        for n in nodes.iter().filter(|n| n.count > 0) {
            for slab in &mut slabs[n.first as usize..(n.first + n.count) as usize] {
                slab.tilt = f32_above((slab.normal - n.axis).length());
            }
        }
        CellTree { nodes, slabs }
    }

    /// The box around every cell (invalid when there are none).
    pub(crate) fn root_aabb(&self) -> Aabb {
        self.nodes.first().map_or(Aabb::new_invalid(), |n| Aabb::new(n.lo, n.hi))
    }

    /// Bytes held by the tree.
    pub fn memory(&self) -> usize {
        std::mem::size_of::<Self>() + self.nodes.capacity() * std::mem::size_of::<CellNode>() + self.slabs.capacity() * std::mem::size_of::<CellSlab>()
    }

    pub(crate) fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The cells of a leaf (none for an inner node), with their indices in the area (the cells
    /// are in leaf order).
    #[inline]
    pub(crate) fn leaf_cells(&self, node: u32) -> impl Iterator<Item = (u32, &CellSlab)> {
        let n = &self.nodes[node as usize];
        (n.first..n.first + n.count).zip(&self.slabs[n.first as usize..(n.first + n.count) as usize])
    }

    /// The centre and half extents of a node's box.
    #[inline]
    pub(crate) fn node_box(&self, node: u32) -> (Vector, Vector) {
        let n = &self.nodes[node as usize];
        (n.centre(), (n.hi - n.lo) * 0.5)
    }

    /// What the cells of leaf `node` need to bound their depths against the target.
    pub(crate) fn leaf_view(&self, node: u32, view: &TargetView) -> LeafView {
        let axis = self.nodes[node as usize].axis;
        LeafView { extent: view.depth_extent_along(axis), centre: view.centre, axis_centre: axis.dot(view.centre), radius: view.radius, side: view.side }
    }

    /// Asks the memory system for what a search reads when it pops `node`, ahead of that pop: a
    /// leaf's slabs (2.5 kB), or an inner node's two children. At 1M cells these loads missed
    /// every cache, and the search then waited on each in turn (prefetching both took the Panda
    /// benchmark's full check from 125 to 111 us per state). Only a hint: a no-op off x86-64.
    #[inline]
    pub(crate) fn prefetch(&self, node: u32) {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
            let lines = |start: *const u8, bytes: usize| {
                for at in (0..bytes).step_by(64) {
                    // SAFETY: a prefetch is a hint that never faults; the address lies in `self`.
                    unsafe { _mm_prefetch::<_MM_HINT_T0>(start.wrapping_add(at) as *const i8) };
                }
            };
            let n = &self.nodes[node as usize];
            if n.count == 0 {
                for child in [node as usize + 1, n.first as usize] {
                    lines(&self.nodes[child] as *const CellNode as *const u8, std::mem::size_of::<CellNode>());
                }
            } else {
                let slabs = &self.slabs[n.first as usize..(n.first + n.count) as usize];
                lines(slabs.as_ptr() as *const u8, std::mem::size_of_val(slabs));
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = node;
    }

    /// The children of an inner node; `None` for a leaf.
    #[inline]
    pub(crate) fn children(&self, node: u32) -> Option<[u32; 2]> {
        let n = &self.nodes[node as usize];
        (n.count == 0).then(|| [node + 1, n.first])
    }

    /// Whether a cell's box, seen from the target's frame, meets the target's own box.
    #[inline(always)]
    pub(crate) fn slab_meets_target_box(slab: &CellSlab, view: &TargetView) -> bool {
        view.meets_own_box(slab.centre(), slab.half())
    }

    /// `None` when no cell of `node` can meet the target (its box misses the target's box, or the
    /// slab the cells fill along the cone axis misses the target's extent on that axis). Else an
    /// upper bound on the depth any of its cells reports.
    ///
    /// The bound, for a `back` cell with normal `n`, whose depth is `max n . (q - x)` over `q` in
    /// the cell and `x` in the target: with `m` the cone axis, `n . (q - x) = m . q - m . x +
    /// (n - m) . (q - x)`, so `depth <= top - min(m . x) + max (n - m) . (q - x)`. With `o` the box
    /// centre and `c` the target's centre, `q - x` is `o - c` give or take the box's radius and
    /// the target's; `n - m` has length at most `spread`, and `-spread^2 / 2` of it lies along
    /// `m`. A `front` cell is the mirror image (`max(m . x) - bottom`); a `both` cell takes the
    /// larger.
    #[inline]
    pub(crate) fn bound(&self, node: u32, view: &TargetView) -> Option<Real> {
        if !self.boxes_meet(node, view) {
            return None;
        }
        let extent = view.depth_extent_along(self.nodes[node as usize].axis);
        self.bound_from(node, view, extent)
    }

    /// [`CellTree::bound`] of two nodes (those with `keep` set; `None` for the others), their
    /// support queries made together (see `TargetShape::support_many`).
    #[inline]
    pub(crate) fn bounds(&self, nodes: [u32; 2], keep: [bool; 2], view: &TargetView) -> [Option<Real>; 2] {
        let mut out = [None, None];
        if matches!(view.side, Side::Both) {
            for k in 0..2 {
                if keep[k] {
                    out[k] = self.bound(nodes[k], view);
                }
            }
            return out;
        }
        let (mut dirs, mut queries, mut which, mut count) = ([Vector::ZERO; 2], [Vector::ZERO; 2], [0usize; 2], 0);
        for k in 0..2 {
            if keep[k] && self.boxes_meet(nodes[k], view) {
                let (d, query) = view.depth_query(self.nodes[nodes[k] as usize].axis);
                // `back` or `front` here (`both` went above): the query is there.
                (dirs[count], queries[count], which[count]) = (d, query.unwrap_or(d), k);
                count += 1;
            }
        }
        let mut supports = [0.0; 2];
        view.target.shape.support_many(&queries[..count], &mut supports[..count]);
        for j in 0..count {
            out[which[j]] = self.bound_from(nodes[which[j]], view, view.depth_extent_from(dirs[j], supports[j]));
        }
        out
    }

    /// Whether a node's box meets the target's, in the surface's frame and in the target's.
    #[inline]
    fn boxes_meet(&self, node: u32, view: &TargetView) -> bool {
        let n = &self.nodes[node as usize];
        let a = &view.aabb;
        if n.lo.x > a.maxs.x || n.lo.y > a.maxs.y || n.lo.z > a.maxs.z || n.hi.x < a.mins.x || n.hi.y < a.mins.y || n.hi.z < a.mins.z {
            return false;
        }
        // The node's box seen from the target's frame, against the target's own box: for a
        // link tilted across a surface this drops most of what its world box takes in.
        view.meets_own_box(n.centre(), (n.hi - n.lo) * 0.5)
    }

    /// The rest of [`CellTree::bound`], given the target's extent along the node's axis.
    #[inline]
    fn bound_from(&self, node: u32, view: &TargetView, [a_min, a_max]: [Real; 2]) -> Option<Real> {
        let n = &self.nodes[node as usize];
        if a_max < n.bottom - SLAB_SLACK || a_min > n.top + SLAB_SLACK || !(a_min.is_finite() && a_max.is_finite()) {
            return None;
        }
        // `(n - m) . v` for `|n - m| <= s`: `n - m` is `-s^2/2` along `m` and at most `s` across it.
        let d = n.centre() - view.centre;
        let along = d.dot(n.axis);
        let across = (d - n.axis * along).length();
        let reach = n.radius + view.radius;
        let slack = n.spread * (across + reach) + 0.5 * n.spread * n.spread * (along.abs() + reach);
        let depth = match view.side {
            Side::Back => n.top - a_min,
            Side::Front => a_max - n.bottom,
            Side::Both => (n.top - a_min).max(a_max - n.bottom),
        };
        Some(depth + slack)
    }
}
