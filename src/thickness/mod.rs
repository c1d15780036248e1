//! Thickness areas: the convex cell behind (or in front of) every triangle of a thin surface.
//!
//! The rule is `design.md`'s, from the claim of US 9,495,485 B2. Each edge of a face gets a side
//! wall: across a consistently wound shared edge, the plane through the edge that bisects the
//! dihedral angle (it contains `n_f + n_g`), so the two neighbours use the same plane and their
//! cells meet exactly; elsewhere (boundary, non-manifold, inconsistent, folded back by less than
//! 1 degree) the plane through the edge perpendicular to the face. The three walls meet in the
//! cross point `c` at signed height `h` on the thickness side. If `0 < h <= t` the cell is the
//! tetrahedron of the face and `c`; otherwise it is the frustum between the face and the plane at
//! depth `t` (the claim's *ratioed thickness area*, ratio `t / h`, when `h > t`). Deviation from the
//! claim, on purpose: a cross point in front of the face (`h <= 0`, diverging walls) gives the
//! frustum, not a tetrahedron in front of the surface.

mod thickness_area;
mod thickness_cell;

pub use self::thickness_area::{ThicknessArea, ThicknessError, ThicknessReport, ThicknessSettings, WallRule};
pub use self::thickness_cell::{is_collapsed, CellKind, Side, ThicknessCell};
