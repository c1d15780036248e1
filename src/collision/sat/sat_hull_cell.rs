//! SAT between a convex polytope target and a cell.

use super::gauss_map::is_minkowski_face;
use super::{LeastOverlap, SatOverlap};
use crate::collision::polytope::CellPolytope;
use crate::collision::target::ConvexHull;

/// Exact SAT of `hull` against `cell` (both in the hull's frame).
pub(crate) fn sat_hull_cell(hull: &ConvexHull, cell: &CellPolytope) -> Option<SatOverlap> {
    let mut least = LeastOverlap::new();
    // The cell's planes first: for a link beside a wall the front/back cap separates at once.
    // planes[0] (back cap) and planes[1] (front cap) lie on the same axis: test it once.
    for (n, _) in &cell.planes[1..] {
        if !least.add(*n, hull.project(*n), cell.project(*n)) {
            return None;
        }
    }
    for f in &hull.faces {
        if !least.add(f.normal, [f.min, f.max], cell.project(f.normal)) {
            return None;
        }
    }
    for ea in &hull.edges {
        for eb in cell.edges() {
            if !is_minkowski_face(ea.n1, ea.n2, eb.n1, eb.n2) {
                continue;
            }
            let l = ea.dir.cross(eb.dir);
            let len = l.length();
            // Parallel edges: the face normals already cover the pair.
            if len < 1e-9 {
                continue;
            }
            let mut l = l / len;
            if l.dot(ea.point - hull.centroid) < 0.0 {
                l = -l;
            }
            // `l` points out of the hull at edge A, and edge B supports the cell along `-l`.
            let overlap = l.dot(ea.point - eb.a);
            if !least.add_oriented(overlap, -l) {
                return None;
            }
        }
    }
    least.finish()
}
