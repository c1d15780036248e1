//! Contact points: a point of the overlap, at its deepest part along the reported normal.
//!
//! For polytopes the cell is clipped by the hull's planes (a convex polyhedron kept as a list of
//! face polygons; each cut adds a cap polygon made of the cut points sorted by angle), and the
//! vertices of the intersection deepest along the push-out normal are averaged, so the point lies
//! in both shapes. For curved targets the point is the cell's closest point to the sphere centre or
//! to the capsule segment (or a point of the segment inside the cell).

use super::convex_hull::ConvexHull;
use super::polytope::CellPolytope;
use crate::math::{Real, Vector};

/// The point of `hull ∩ cell` deepest along `-normal` (averaged over ties), or `None` if the
/// intersection is empty after clipping with tolerance `tol`.
pub(crate) fn contact_hull_cell(hull: &ConvexHull, cell: &CellPolytope, normal: Vector, tol: Real) -> Option<Vector> {
    let mut faces = cell.faces();
    // A ball around the cell: a hull face whose plane it does not reach cannot cut, and on a
    // link much larger than the cell that is most of them (one dot product instead of ~18).
    let centre = cell.verts.iter().copied().sum::<Vector>() / 6.0;
    let radius = cell.verts.iter().map(|v| (*v - centre).length()).fold(0.0, Real::max);
    for f in &hull.faces {
        if f.normal.dot(centre) + radius <= f.max + tol {
            continue;
        }
        if !clip(&mut faces, f.normal, f.max + tol, tol) {
            return None;
        }
    }
    deepest(faces.iter().flatten().copied(), normal, tol)
}

/// Average of the points within `tol` of the least `normal . x`.
fn deepest(points: impl Iterator<Item = Vector> + Clone, normal: Vector, tol: Real) -> Option<Vector> {
    let min = points.clone().map(|p| normal.dot(p)).fold(Real::INFINITY, Real::min);
    if !min.is_finite() {
        return None;
    }
    let (sum, n) = points.filter(|p| normal.dot(*p) <= min + tol).fold((Vector::ZERO, 0usize), |(s, n), p| (s + p, n + 1));
    Some(sum / n as Real)
}

/// Clips a convex polyhedron (as face polygons) to `n . x <= d`. Returns `false` when nothing is left.
fn clip(faces: &mut Vec<Vec<Vector>>, n: Vector, d: Real, tol: Real) -> bool {
    let max = faces.iter().flatten().map(|p| n.dot(*p) - d).fold(Real::NEG_INFINITY, Real::max);
    if max <= 0.0 {
        return true;
    }
    let mut cut: Vec<Vector> = Vec::new();
    let mut out = Vec::with_capacity(faces.len() + 1);
    for face in faces.iter() {
        let mut poly = Vec::with_capacity(face.len() + 1);
        for i in 0..face.len() {
            let (a, b) = (face[i], face[(i + 1) % face.len()]);
            let (da, db) = (n.dot(a) - d, n.dot(b) - d);
            if da <= 0.0 {
                poly.push(a);
                if da == 0.0 {
                    cut.push(a);
                }
            }
            if (da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0) {
                let x = a + (b - a) * (da / (da - db));
                poly.push(x);
                cut.push(x);
            }
        }
        if poly.len() >= 3 {
            out.push(poly);
        }
    }
    if cut.len() >= 3 {
        out.push(order_on_plane(cut, n, tol));
    }
    *faces = out;
    !faces.is_empty()
}

/// The points of a convex polygon in plane normal `n`, deduplicated and ordered by angle.
fn order_on_plane(pts: Vec<Vector>, n: Vector, tol: Real) -> Vec<Vector> {
    let c = pts.iter().copied().sum::<Vector>() / pts.len() as Real;
    let u = n.any_orthonormal_vector();
    let v = n.cross(u);
    // Each angle once: in the comparator, two atan2 per comparison were most of a contact point.
    let mut keyed: Vec<(Real, Vector)> = pts.iter().map(|p| ((*p - c).dot(v).atan2((*p - c).dot(u)), *p)).collect();
    keyed.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut out: Vec<Vector> = keyed.into_iter().map(|(_, p)| p).collect();
    out.dedup_by(|a, b| a.distance(*b) <= tol);
    out
}

/// Closest point to `p` on triangle `abc` (Ericson, RTCD 5.1.5).
pub(crate) fn closest_on_triangle(p: Vector, a: Vector, b: Vector, c: Vector) -> Vector {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    a + ab * (vb * denom) + ac * (vc * denom)
}

/// Closest point of the cell to `p` (`p` itself when inside).
pub(crate) fn closest_on_cell(cell: &CellPolytope, p: Vector) -> Vector {
    if cell.contains(p, 0.0) {
        return p;
    }
    let mut best = p;
    let mut best_d = Real::INFINITY;
    for face in cell.faces() {
        for k in 1..face.len() - 1 {
            let q = closest_on_triangle(p, face[0], face[k], face[k + 1]);
            let d = q.distance_squared(p);
            if d < best_d {
                best_d = d;
                best = q;
            }
        }
    }
    best
}

/// A contact point of a capsule (segment `[p, q]`, `radius`) with a cell it overlaps: the deepest
/// point along `-normal` of the part of the segment inside the cell, or else the cell's point
/// closest to the segment.
pub(crate) fn contact_capsule_cell(cell: &CellPolytope, p: Vector, q: Vector, normal: Vector) -> Vector {
    // Clip the segment to the cell (Cyrus-Beck).
    let (mut s0, mut s1) = (0.0, 1.0);
    let d = q - p;
    for (n, off) in &cell.planes {
        let num = off - n.dot(p);
        let den = n.dot(d);
        if den.abs() < 1e-300 {
            if num < 0.0 {
                s0 = 2.0;
                break;
            }
        } else if den > 0.0 {
            s1 = Real::min(s1, num / den);
        } else {
            s0 = Real::max(s0, num / den);
        }
    }
    if s0 <= s1 {
        let (a, b) = (p + d * s0, p + d * s1);
        return if normal.dot(a) <= normal.dot(b) { a } else { b };
    }
    // The distance from a point moving along a segment to a convex set is convex in the parameter:
    // golden-section search finds its minimum.
    let f = |s: Real| closest_on_cell(cell, p + d * s).distance(p + d * s);
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut lo, mut hi) = (0.0, 1.0);
    let (mut x1, mut x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
    let (mut f1, mut f2) = (f(x1), f(x2));
    // 45 steps shrink the bracket to 0.618^45 ~ 4e-10 of the segment.
    for _ in 0..45 {
        if f1 <= f2 {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = hi - g * (hi - lo);
            f1 = f(x1);
        } else {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = lo + g * (hi - lo);
            f2 = f(x2);
        }
    }
    let s = 0.5 * (lo + hi);
    closest_on_cell(cell, p + d * s)
}

/// A point of `cylinder ∩ cell` (cylinder along `z`, centred at the origin), found by alternating
/// projections from `start`: both sets are convex, so the iteration converges to a point of the
/// intersection when there is one. Returns the last point on the cell (within `tol` of the
/// cylinder when converged).
pub(crate) fn contact_cylinder_cell(cell: &CellPolytope, half_height: Real, radius: Real, start: Vector, tol: Real) -> Vector {
    let project_cylinder = |p: Vector| {
        let r = p.x.hypot(p.y);
        let s = if r > radius { radius / r } else { 1.0 };
        Vector::new(p.x * s, p.y * s, p.z.clamp(-half_height, half_height))
    };
    let mut x = project_cylinder(start);
    let mut y = closest_on_cell(cell, x);
    for _ in 0..2000 {
        x = project_cylinder(y);
        if x.distance(y) <= tol {
            break;
        }
        y = closest_on_cell(cell, x);
    }
    y
}
