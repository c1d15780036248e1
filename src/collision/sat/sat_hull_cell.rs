//! SAT between a convex polytope target and a cell.

use super::gauss_map::is_minkowski_face_arcs;
use super::{LeastOverlap, SatOverlap};
use crate::collision::convex_hull::ConvexHull;
use crate::collision::polytope::CellPolytope;
use crate::math::Vector;

/// Exact SAT of `hull` against `cell` (both in the hull's frame): the least overlap, or when an
/// axis separates them, that axis (for neighbouring cells to try first).
pub(crate) fn sat_hull_cell(hull: &ConvexHull, cell: &CellPolytope) -> Result<SatOverlap, Option<Vector>> {
    let mut least = LeastOverlap::new();
    sat_axes(hull, cell, &mut least).map_err(Some)?;
    least.finish().ok_or(None)
}

/// Every axis of the exact test; `Err(axis)` when one separates.
fn sat_axes(hull: &ConvexHull, cell: &CellPolytope, least: &mut LeastOverlap) -> Result<(), Vector> {
    // The cell's planes first: for a link beside a wall the front/back cap separates at once.
    // planes[0] (back cap) and planes[1] (front cap) lie on the same axis: test it once.
    for (n, _) in &cell.planes[1..] {
        if !least.add(*n, hull.project(*n), cell.project(*n)) {
            return Err(*n);
        }
    }
    for f in &hull.faces {
        if !least.add(f.normal, [f.min, f.max], cell.project(f.normal)) {
            return Err(f.normal);
        }
    }
    for eb in cell.edges() {
        // The cell edge's arc, once for all hull edges (theirs are precomputed).
        let arc_b = eb.n2.cross(eb.n1);
        for ea in &hull.edges {
            if !is_minkowski_face_arcs(ea.n1, ea.n2, ea.arc, eb.n1, eb.n2, arc_b) {
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
                return Err(l);
            }
        }
    }
    Ok(())
}
