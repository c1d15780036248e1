//! SAT between a convex polytope target and a cell.

use super::gauss_map::is_minkowski_face_arcs;
use super::{LeastOverlap, SatOverlap};
use crate::collision::polytope::CellPolytope;
use crate::collision::target::{ConvexHull, LANES};
use crate::math::{Real, Vector};

/// Exact SAT of `hull` against `cell` (both in the hull's frame). `separating` is an axis that
/// separated a neighbouring cell (zero when there is none): tried first, because next to each
/// other cells are mostly separated by the same axis, and the full test runs ~350 axes on a
/// Panda link. When the pair is apart, the axis that separated it is written back.
pub(crate) fn sat_hull_cell(hull: &ConvexHull, cell: &CellPolytope, separating: &mut Vector) -> Option<SatOverlap> {
    if *separating != Vector::ZERO {
        // Only as a reject: the axis does not enter the least overlap, so the result does not
        // depend on which cell came before.
        let (a, b) = (hull.project(*separating), cell.project(*separating));
        if !(a[1] - b[0] > 0.0 && b[1] - a[0] > 0.0) {
            return None;
        }
    }
    let mut least = LeastOverlap::new();
    if let Err(axis) = sat_axes(hull, cell, &mut least) {
        *separating = axis;
        return None;
    }
    least.finish()
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
    // The hull's faces, LANES at a time: the cell's extent on each normal, then the checks.
    let [nx, ny, nz, fmin, fmax] = &hull.face_soa;
    let v = &cell.verts;
    for c in (0..nx.len()).step_by(LANES) {
        let mut lo = [Real::INFINITY; LANES];
        let mut hi = [Real::NEG_INFINITY; LANES];
        for p in v {
            for k in 0..LANES {
                let d = nx[c + k] * p.x + ny[c + k] * p.y + nz[c + k] * p.z;
                lo[k] = if d < lo[k] { d } else { lo[k] };
                hi[k] = if d > hi[k] { d } else { hi[k] };
            }
        }
        for k in 0..LANES {
            let i = c + k;
            let normal = Vector::new(nx[i], ny[i], nz[i]);
            if i < hull.faces.len() && !least.add(normal, [fmin[i], fmax[i]], [lo[k], hi[k]]) {
                return Err(normal);
            }
        }
    }
    // Edge pairs: the Gauss-map test's first half over all hull edges at once (the hull edge's
    // face normals on both sides of the cell edge's arc plane), the rest for the few that pass.
    let [ax, ay, az, bx, by, bz] = &hull.edge_soa;
    for eb in cell.edges() {
        let arc_b = eb.n2.cross(eb.n1);
        for c in (0..ax.len()).step_by(LANES) {
            let mut mask = 0u32;
            for k in 0..LANES {
                let adc = ax[c + k] * arc_b.x + ay[c + k] * arc_b.y + az[c + k] * arc_b.z;
                let bdc = bx[c + k] * arc_b.x + by[c + k] * arc_b.y + bz[c + k] * arc_b.z;
                mask |= ((adc * bdc < 0.0) as u32) << k;
            }
            while mask != 0 {
                let ea = &hull.edges[c + mask.trailing_zeros() as usize];
                mask &= mask - 1;
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
    }
    Ok(())
}
