//! SAT between a capsule target (segment along local z) and a cell.

use super::{closest_on_segment, closest_segment_segment, LeastOverlap, SatOverlap};
use crate::collision::polytope::CellPolytope;
use crate::math::{Real, Vector};

/// Exact SAT. The capsule meets the cell when the distance from the origin to
/// `Q = cell - segment` is below the radius; the axes are `Q`'s face normals (the cell's planes and
/// `axis x edge`), the directions to `Q`'s edges (cell edge vs. segment end, segment vs. cell
/// vertex, segment vs. cell edge) and to `Q`'s vertices (cell vertex minus segment end).
pub(crate) fn sat_capsule_cell(half_height: Real, radius: Real, cell: &CellPolytope) -> Option<SatOverlap> {
    let p = Vector::new(0.0, 0.0, -half_height);
    let q = Vector::new(0.0, 0.0, half_height);
    let mut least = LeastOverlap::new();
    let mut axis = |d: Vector| -> bool {
        let len = d.length();
        if len < 1e-12 {
            return true;
        }
        let l = d / len;
        let s = (half_height * l.z).abs();
        least.add(l, [-s - radius, s + radius], cell.project(l))
    };
    // planes[0] (back cap) and planes[1] (front cap) lie on the same axis: test it once.
    for (n, _) in &cell.planes[1..] {
        if !axis(*n) {
            return None;
        }
    }
    for e in cell.edges() {
        let (on_seg, on_edge) = closest_segment_segment(p, q, e.a, e.b);
        if !axis(Vector::Z.cross(e.dir)) || !axis(on_edge - on_seg) || !axis(closest_on_segment(p, e.a, e.b) - p) || !axis(closest_on_segment(q, e.a, e.b) - q)
        {
            return None;
        }
    }
    for v in cell.distinct_vertices() {
        if !axis(v - closest_on_segment(v, p, q)) || !axis(v - p) || !axis(v - q) {
            return None;
        }
    }
    least.finish()
}
