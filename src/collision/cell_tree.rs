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

use super::target::Target;
use crate::math::{Aabb, Pose, Real, Vector};
use crate::thickness::{Side, ThicknessCell};
use parry3d_f64::math::Matrix;

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

/// What the cheap first tests of a cell (its box, its normal axis) read, kept beside the tree in
/// leaf order: a leaf's cells are then one contiguous read, where the cells themselves (328 bytes
/// each, in input order) would cost a cache miss each on a large surface. 80 bytes: the box and
/// the tilt, which only ever prune, are single precision, rounded outwards (at 1M cells the
/// search streams these from memory, and 104 bytes in double precision were a quarter more).
#[derive(Clone, Copy, Debug)]
pub(crate) struct CellSlab {
    /// The face's front normal.
    pub normal: Vector,
    /// `[min, max]` of `normal . x` over the cell.
    pub range: [Real; 2],
    /// `normal . x` on the face.
    pub plane_offset: Real,
    /// The centre and half extents of a box holding the cell's bounding box.
    centre: [f32; 3],
    half: [f32; 3],
    /// At least `|normal - axis|` for the cone axis of the cell's leaf (0 outside a tree).
    tilt: f32,
}

/// `x` rounded to single precision, then pushed up by more than the rounding.
fn f32_above(x: Real) -> f32 {
    ((x.abs() * (1.0 + 1e-6) + 1e-12) as f32).max(0.0)
}

impl CellSlab {
    pub fn of(cell: &ThicknessCell) -> CellSlab {
        let (lo, hi) = cell_box(cell);
        let (c, h) = ((lo + hi) * 0.5, (hi - lo) * 0.5);
        let centre = c.to_array().map(|x| x as f32);
        // The half extents grow by the centre's rounding error, so the box still holds the cell.
        let half = std::array::from_fn(|k| f32_above(h[k] + (c[k] - centre[k] as Real).abs()));
        CellSlab { normal: cell.normal, range: cell.normal_range(), plane_offset: cell.plane_offset, centre, half, tilt: 0.0 }
    }

    /// The centre of the cell's (slightly grown) box.
    #[inline]
    pub fn centre(&self) -> Vector {
        Vector::new(self.centre[0] as Real, self.centre[1] as Real, self.centre[2] as Real)
    }

    /// The half extents of the cell's (slightly grown) box.
    #[inline]
    pub fn half(&self) -> Vector {
        Vector::new(self.half[0] as Real, self.half[1] as Real, self.half[2] as Real)
    }

    /// An upper bound on the depth this cell reports against the target of `leaf`, from the
    /// leaf's projection of the target on its cone axis (see [`LeafView`]): with `n` the cell's
    /// normal, `m` the axis and `c` the target's centre, `n . x = m . x + (n - m) . c + (n - m) .
    /// (x - c)`, so `min n . x >= min m . x + (n - m) . c - tilt * radius`. A cell whose bound
    /// cannot beat the deepest contact found needs no support query of its own.
    #[inline]
    pub fn depth_bound(&self, leaf: &LeafView) -> Real {
        let shift = self.normal.dot(leaf.centre) - leaf.axis_centre;
        let slack = self.tilt as Real * leaf.radius;
        let back = self.range[1] - leaf.extent[0] + slack - shift;
        let front = leaf.extent[1] + slack + shift - self.range[0];
        match leaf.side {
            Side::Back => back,
            Side::Front => front,
            Side::Both => back.max(front),
        }
    }
}

/// A target seen from one leaf: what [`CellSlab::depth_bound`] needs (surface frame).
pub(crate) struct LeafView {
    /// `[min, max]` of `axis . x` over the target.
    extent: [Real; 2],
    /// The target's centre, and `axis . centre`.
    centre: Vector,
    axis_centre: Real,
    radius: Real,
    side: Side,
}

/// The tree over one surface's cells, in the surface's frame.
#[derive(Clone, Debug, Default)]
pub struct CellTree {
    nodes: Vec<CellNode>,
    /// The cells' normal slabs in leaf order.
    slabs: Vec<CellSlab>,
}

/// A target seen from a surface's frame, with what the node tests need.
pub(crate) struct TargetView<'a> {
    pub target: &'a Target,
    /// The pose of the surface's frame in the target's frame.
    pub object_in_target: Pose,
    /// The target's bounding box in the surface's frame.
    pub aabb: Aabb,
    /// The target's bounding box in its own frame, and the rotation part of `object_in_target`
    /// as a matrix and with its entries made positive: a node's box seen from the target.
    local_aabb: Aabb,
    pub rotation: Matrix,
    rotation_abs: Matrix,
    /// The target's centre in the surface's frame.
    pub centre: Vector,
    /// Radius of a ball about `centre` that holds the target.
    radius: Real,
    side: Side,
}

impl<'a> TargetView<'a> {
    /// `world_aabb` is the target's exact box in the world.
    pub fn new(target: &'a Target, object_pose: &Pose, side: Side, world_aabb: &Aabb) -> Self {
        let target_in_object = object_pose.inv_mul(&target.pose);
        let object_in_target = target_in_object.inverse();
        let rotation = Matrix::from_quat(object_in_target.rotation);
        // Walls, shelves and tables usually stand square to the world: then the world box, turned
        // into the surface's frame, is the exact box there too (to rounding), and the six support
        // queries of an exact box are saved.
        let square = Matrix::from_quat(object_pose.rotation).abs();
        let aabb = if [square.row(0), square.row(1), square.row(2)].iter().all(|r| r.max_element() > 1.0 - 1e-12 && r.element_sum() < 1.0 + 1e-9) {
            transformed_box(world_aabb, &object_pose.inverse())
        } else {
            target.aabb_in(&target_in_object)
        };
        TargetView {
            target,
            object_in_target,
            local_aabb: target.shape.local_aabb(),
            rotation,
            rotation_abs: rotation.abs(),
            aabb,
            centre: target_in_object * target.shape.centre(),
            radius: target.shape.bounding_radius(),
            side,
        }
    }

    /// Whether a box of the surface's frame (centre, half extents), seen from the target's frame,
    /// meets the target's own bounding box (touching counts; a NaN does not).
    #[inline]
    pub fn meets_own_box(&self, centre: Vector, half: Vector) -> bool {
        let c = self.rotation * centre + self.object_in_target.translation;
        let h = self.rotation_abs * half;
        let b = &self.local_aabb;
        (c - h).cmple(b.maxs).all() && b.mins.cmple(c + h).all()
    }

    /// A lower bound on the distance from the target to anything in a box of the surface's frame
    /// (centre, half extents): the gap between that box, seen from the target's frame, and the
    /// target's own bounding box (0 when they meet).
    #[inline]
    pub fn own_box_gap(&self, centre: Vector, half: Vector) -> Real {
        let c = self.rotation * centre + self.object_in_target.translation;
        let h = self.rotation_abs * half;
        let b = &self.local_aabb;
        let gap = (b.mins - (c + h)).max(c - h - b.maxs).max(Vector::ZERO);
        gap.length()
    }

    /// `[min, max]` of `dir . x` over the target where the surface's side makes it a depth (the
    /// minimum for `back`, the maximum for `front`, both for `both`), and the other end from the
    /// target's own box (outside the exact extent): one support query where two were.
    #[inline]
    pub fn depth_extent_along(&self, dir: Vector) -> [Real; 2] {
        let (d, query) = self.depth_query(dir);
        self.depth_extent_from(d, query.map_or(0.0, |q| self.target.shape.support(q)))
    }

    /// `dir` in the target's frame, and the one support query [`TargetView::depth_extent_along`]
    /// makes: along it negated for `back` (its support gives the minimum), along it for `front`,
    /// none for `both` (both ends are queried in [`TargetView::depth_extent_from`]).
    #[inline]
    pub fn depth_query(&self, dir: Vector) -> (Vector, Option<Vector>) {
        let d = self.rotation * dir;
        let query = match self.side {
            Side::Back => Some(-d),
            Side::Front => Some(d),
            Side::Both => None,
        };
        (d, query)
    }

    /// [`TargetView::depth_extent_along`] for `d`, the direction already in the target's frame,
    /// given the support along [`TargetView::depth_query`] (unused for `both`, which queries
    /// both ends here).
    #[inline]
    pub fn depth_extent_from(&self, d: Vector, support: Real) -> [Real; 2] {
        let shift = d.dot(self.object_in_target.translation);
        let b = &self.local_aabb;
        let c = d.dot((b.mins + b.maxs) * 0.5);
        let r = d.abs().dot((b.maxs - b.mins) * 0.5);
        match self.side {
            Side::Back => [-support - shift, c + r - shift],
            Side::Front => [c - r - shift, support - shift],
            Side::Both => self.target.shape.project(d).map(|x| x - shift),
        }
    }

    /// `[min, max]` of `dir . x` over the target, for a direction in the surface's frame.
    #[inline]
    pub fn extent_along(&self, dir: Vector) -> [Real; 2] {
        let d = self.rotation * dir;
        let shift = d.dot(self.object_in_target.translation);
        self.target.shape.project(d).map(|x| x - shift)
    }
}

/// The box around a box of another frame (`pose` maps that frame into this one).
pub(crate) fn transformed_box(local: &Aabb, pose: &Pose) -> Aabb {
    let c = *pose * local.center();
    let h = local.half_extents();
    let m = Matrix::from_quat(pose.rotation).abs();
    let e = Vector::new(m.row(0).dot(h), m.row(1).dot(h), m.row(2).dot(h));
    Aabb::new(c - e, c + e)
}

fn cell_box(cell: &ThicknessCell) -> (Vector, Vector) {
    let v = cell.vertices();
    v.iter().fold((v[0], v[0]), |(lo, hi), p| (lo.min(*p), hi.max(*p)))
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
    pub fn root_aabb(&self) -> Aabb {
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
    #[inline]
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
