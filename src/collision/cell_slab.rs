//! What the first tests of a cell read: its box and normal slab, kept beside the tree in leaf order.

use crate::math::{Real, Vector};
use crate::thickness::{Side, ThicknessCell};

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
    pub(super) tilt: f32,
}

/// `x` rounded to single precision, then pushed up by more than the rounding.
pub(super) fn f32_above(x: Real) -> f32 {
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
    pub(super) extent: [Real; 2],
    /// The target's centre, and `axis . centre`.
    pub(super) centre: Vector,
    pub(super) axis_centre: Real,
    pub(super) radius: Real,
    pub(super) side: Side,
}

pub(super) fn cell_box(cell: &ThicknessCell) -> (Vector, Vector) {
    let v = cell.vertices();
    v.iter().fold((v[0], v[0]), |(lo, hi), p| (lo.min(*p), hi.max(*p)))
}
