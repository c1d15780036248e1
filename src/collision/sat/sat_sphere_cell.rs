//! SAT between a sphere target (centred at the origin of its frame) and a cell.

use super::{closest_on_segment, LeastOverlap, SatOverlap};
use crate::collision::polytope::CellPolytope;
use crate::math::{Real, Vector};

/// Exact SAT: the cell's planes, and the directions from the cell's edges and vertices to the
/// centre, which cover every closest feature.
pub(crate) fn sat_sphere_cell(radius: Real, cell: &CellPolytope) -> Option<SatOverlap> {
    let mut least = LeastOverlap::new();
    let r = [-radius, radius];
    // planes[0] (back cap) and planes[1] (front cap) lie on the same axis: test it once.
    for (n, _) in &cell.planes[1..] {
        if !least.add(*n, r, cell.project(*n)) {
            return None;
        }
    }
    let mut axis = |d: Vector| -> bool {
        let len = d.length();
        if len < 1e-12 {
            return true;
        }
        let l = d / len;
        least.add(l, r, cell.project(l))
    };
    for e in cell.edges() {
        if !axis(-closest_on_segment(Vector::ZERO, e.a, e.b)) {
            return None;
        }
    }
    for v in cell.distinct_vertices() {
        if !axis(-v) {
            return None;
        }
    }
    least.finish()
}
