//! A yes/no GJK between a hull and a cell whose every answer carries its own proof, so that it can
//! stand in for the separating-axis test where the SAT would be costly: a "yes" is a tetrahedron
//! of Minkowski-difference points holding the origin at least [`MARGIN`] inside (then no axis
//! separates the shapes, and the exact SAT finds overlap on every axis), a "no" an axis on which
//! the hull's maximum is at most the cell's minimum (the SAT's own test on that axis). When neither
//! comes within [`MAX_ITERATIONS`] (touching or razor-thin overlaps), the caller runs the SAT.
//!
//! Why: on a Panda link hull (150 vertices, 300 faces, 450 edges) a SAT that finds overlap tests
//! every face and ~4,000 edge pairs; GJK needs a handful of support queries.

use super::convex_hull::ConvexHull;
use super::target::sweep_end;
use crate::math::{Real, Vector};

/// How far inside the tetrahedron (metres) the origin must be for a "yes".
const MARGIN: Real = 1e-9;

/// Iterations before giving up (GJK on polytopes of this size ends in well under 20).
const MAX_ITERATIONS: usize = 32;

/// A GJK verdict, each with its proof checked.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Verdict {
    /// The interiors meet.
    Overlap,
    /// This axis (target frame, not unit) separates the shapes; touching counts as apart.
    Apart(Vector),
    /// No proof either way: run the SAT.
    Unknown,
}

/// A Minkowski-difference point `a - b` (hull point `a`, cell point `b`).
type Point = Vector;

/// GJK of `hull` against the convex hull of `cell` (points in the hull's frame).
pub(crate) fn hull_cell(hull: &ConvexHull, cell: &[Vector; 6]) -> Verdict {
    swept_hull_cell(hull, Vector::ZERO, cell)
}

/// [`hull_cell`] for `hull` swept along the segment from `-sweep` to `sweep` (every point of it
/// moved by `t · sweep`, `t` in `[-1, 1]`): its support along `d` is the hull's, moved by `sweep`
/// to the side `d` points to.
pub(crate) fn swept_hull_cell(hull: &ConvexHull, sweep: Vector, cell: &[Vector; 6]) -> Verdict {
    let support = |d: Vector| -> (Point, Real, Real) {
        let a = hull.support_point(d) + sweep_end(sweep, d);
        let (mut b, mut b_min) = (cell[0], d.dot(cell[0]));
        for p in &cell[1..] {
            let x = d.dot(*p);
            if x < b_min {
                (b, b_min) = (*p, x);
            }
        }
        (a - b, d.dot(a), b_min)
    };
    let centre = cell.iter().copied().sum::<Vector>() / 6.0;
    convex_pair(support, centre - hull.centroid)
}

/// GJK of two convex shapes given by `support(d) = (a - b, d·a, d·b)`, with `a` the first shape's
/// point extreme along `d` and `b` the second's extreme along `-d`; `d0` a first direction (from
/// the first shape's centre towards the second's).
pub(crate) fn convex_pair(support: impl Fn(Vector) -> (Point, Real, Real), d0: Vector) -> Verdict {
    let mut d = d0;
    if !(d.length_squared() > 1e-24) {
        d = Vector::X;
    }
    let mut simplex: [Point; 4] = [Vector::ZERO; 4];
    let mut len = 0usize;
    for _ in 0..MAX_ITERATIONS {
        let (w, a_max, b_min) = support(d);
        // The SAT's test on axis d: the hull's maximum at most the cell's minimum.
        if !(a_max > b_min) {
            return if a_max.is_finite() && b_min.is_finite() { Verdict::Apart(d) } else { Verdict::Unknown };
        }
        if simplex[..len].contains(&w) {
            return Verdict::Unknown; // no progress: the origin is on or near the boundary
        }
        simplex[len] = w;
        len += 1;
        match next(&mut simplex, &mut len) {
            Next::Direction(n) => {
                if !(n.length_squared() > 1e-30) || !n.is_finite() {
                    return Verdict::Unknown;
                }
                d = n;
            }
            Next::Contains => {
                return if strictly_inside(&simplex) { Verdict::Overlap } else { Verdict::Unknown };
            }
        }
    }
    Verdict::Unknown
}

enum Next {
    Direction(Vector),
    Contains,
}

/// Reduces the simplex (newest point last) to the feature nearest the origin and returns the
/// direction from it towards the origin (the classic case analysis of the boolean GJK).
fn next(s: &mut [Point; 4], len: &mut usize) -> Next {
    match *len {
        1 => Next::Direction(-s[0]),
        2 => line(s, len),
        3 => triangle(s, len),
        _ => tetrahedron(s, len),
    }
}

fn line(s: &mut [Point; 4], len: &mut usize) -> Next {
    let (b, a) = (s[0], s[1]);
    let ab = b - a;
    let ao = -a;
    if ab.dot(ao) > 0.0 {
        Next::Direction(ab.cross(ao).cross(ab))
    } else {
        s[0] = a;
        *len = 1;
        Next::Direction(ao)
    }
}

fn triangle(s: &mut [Point; 4], len: &mut usize) -> Next {
    let (c, b, a) = (s[0], s[1], s[2]);
    let (ab, ac, ao) = (b - a, c - a, -a);
    let abc = ab.cross(ac);
    if abc.cross(ac).dot(ao) > 0.0 {
        if ac.dot(ao) > 0.0 {
            s[0] = c;
            s[1] = a;
            *len = 2;
            return Next::Direction(ac.cross(ao).cross(ac));
        }
        s[0] = b;
        s[1] = a;
        *len = 2;
        return line(s, len);
    }
    if ab.cross(abc).dot(ao) > 0.0 {
        s[0] = b;
        s[1] = a;
        *len = 2;
        return line(s, len);
    }
    if abc.dot(ao) > 0.0 {
        Next::Direction(abc)
    } else {
        // Keep the winding so that `abc` points towards the origin next time.
        s[0] = b;
        s[1] = c;
        Next::Direction(-abc)
    }
}

fn tetrahedron(s: &mut [Point; 4], len: &mut usize) -> Next {
    let (d, c, b, a) = (s[0], s[1], s[2], s[3]);
    let ao = -a;
    let (ab, ac, ad) = (b - a, c - a, d - a);
    // The triangle (d, c, b) faces the origin (set up by `triangle`); check the three faces at a.
    let abc = ab.cross(ac);
    let acd = ac.cross(ad);
    let adb = ad.cross(ab);
    if abc.dot(ao) > 0.0 {
        *s = [c, b, a, a];
        *len = 3;
        return triangle(s, len);
    }
    if acd.dot(ao) > 0.0 {
        *s = [d, c, a, a];
        *len = 3;
        return triangle(s, len);
    }
    if adb.dot(ao) > 0.0 {
        *s = [b, d, a, a];
        *len = 3;
        return triangle(s, len);
    }
    Next::Contains
}

/// Whether the origin lies inside the tetrahedron, at least [`MARGIN`] from each face plane.
fn strictly_inside(t: &[Point; 4]) -> bool {
    for k in 0..4 {
        let [p, q, r] = [t[(k + 1) % 4], t[(k + 2) % 4], t[(k + 3) % 4]];
        let n = (q - p).cross(r - p);
        let len = n.length();
        if !(len > 0.0) {
            return false;
        }
        let opposite = n.dot(t[k] - p);
        let origin = -n.dot(p);
        // Same side as the opposite vertex, and far enough from the plane.
        if !(origin * opposite.signum() > MARGIN * len) {
            return false;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::collision::polytope::CellPolytope;
    use crate::collision::sat::sat_hull_cell;
    use crate::math::{Pose, Rotation};
    use crate::mesh::{generate, MeshTopology, TopologySettings};
    use crate::thickness::{ThicknessArea, ThicknessSettings};

    /// Every verdict against the exact SAT, on 20,000 random hull/cell pairs (fixed seed) and the
    /// overlapping ones moved to within 1e-7 m of touching: a "yes" must be the SAT's "yes", a
    /// "no" the SAT's "no" with an axis that separates by a scan of both point sets; and "don't
    /// know" must stay rare among the random pairs, or GJK would save nothing.
    #[test]
    fn verdicts_agree_with_the_sat() {
        let mut rng = oorandom::Rand64::new(2026);
        let mut rf = |lo: Real, hi: Real| lo + (hi - lo) * rng.rand_float();
        let (v, t) = generate::wavy_sheet(12, 12, 0.3, 0.3, 0.02, 0.1);
        let mesh = MeshTopology::build(&v, &t, &TopologySettings::default()).unwrap();
        let area = ThicknessArea::build(&mesh, &ThicknessSettings { thickness: 0.02, ..Default::default() }).unwrap();
        // Points on ellipsoids, each hull kept only when parry merged none of its triangles
        // (merging within 1.7e-4 rad leaves faces up to ~1e-6 m out of plane, and the SAT's axes
        // are exact only without it; it is rare here).
        let mut hulls: Vec<ConvexHull> = Vec::new();
        while hulls.len() < 40 {
            let n = 8 + hulls.len() * 4;
            let (a, b, c) = (rf(0.005, 0.05), rf(0.005, 0.05), rf(0.005, 0.05));
            let pts: Vec<Vector> = (0..n)
                .map(|_| {
                    let d = Vector::new(rf(-1.0, 1.0), rf(-1.0, 1.0), rf(-1.0, 1.0)).normalize_or(Vector::X);
                    Vector::new(d.x * a, d.y * b, d.z * c)
                })
                .collect();
            let hull = ConvexHull::from_points(&pts).unwrap();
            if hull.face_count() == 2 * hull.points().len() - 4 {
                hulls.push(hull);
            }
        }
        let (mut yes, mut no, mut unknown) = (0, 0, 0);
        for i in 0..20_000 {
            let hull = &hulls[i % hulls.len()];
            let cell = &area.cells[(rf(0.0, 1.0) * area.cells.len() as Real) as usize % area.cells.len()];
            // The hull placed near the cell's centroid, so that about half the pairs meet.
            let centroid = cell.vertices().iter().copied().sum::<Vector>() / 6.0;
            let axis = Vector::new(rf(-1.0, 1.0), rf(-1.0, 1.0), rf(-1.0, 1.0)).normalize_or(Vector::Z);
            let offset = Vector::new(rf(-0.04, 0.04), rf(-0.04, 0.04), rf(-0.04, 0.04));
            let pose = Pose::from_parts(centroid + offset, Rotation::from_axis_angle(axis, rf(0.0, 3.1)));
            let cell_in_hull = pose.inverse();
            let local = CellPolytope::new(cell, &cell_in_hull);
            let sat = sat_hull_cell(hull, &local);
            let check = |local: &CellPolytope, sat: &Result<_, _>, what: &str| -> Verdict {
                let verdict = hull_cell(hull, &local.verts);
                match verdict {
                    Verdict::Overlap => assert!(sat.is_ok(), "pair {i} ({what}): GJK says overlap, the SAT apart"),
                    Verdict::Apart(d) => {
                        assert!(sat.is_err(), "pair {i} ({what}): GJK says apart, the SAT overlap");
                        let a_max = hull.points().iter().map(|p| d.dot(*p)).fold(Real::NEG_INFINITY, Real::max);
                        let b_min = local.verts.iter().map(|p| d.dot(*p)).fold(Real::INFINITY, Real::min);
                        assert!(a_max <= b_min, "pair {i} ({what}): the axis does not separate ({a_max} > {b_min})");
                    }
                    Verdict::Unknown => {}
                }
                verdict
            };
            match check(&local, &sat, "random") {
                Verdict::Overlap => yes += 1,
                Verdict::Apart(_) => no += 1,
                Verdict::Unknown => unknown += 1,
            }
            // The same pair moved to within 1e-7 m of touching, either side: the proofs' margins
            // must hold there (GJK may well not know).
            if let Ok(least) = sat {
                for gap in [-1e-7, -1e-10, 1e-10, 1e-7] {
                    let moved = Pose::from_translation(-least.axis * (least.overlap + gap)) * cell_in_hull;
                    let near = CellPolytope::new(cell, &moved);
                    let _ = check(&near, &sat_hull_cell(hull, &near), "near touching");
                }
            }
        }
        eprintln!("{yes} overlap, {no} apart, {unknown} left to the SAT");
        assert!(yes > 4_000 && no > 4_000, "both verdicts exercised: {yes} yes, {no} no");
        assert!(unknown < 100, "{unknown} of 20,000 pairs left to the SAT");
    }

    #[test]
    fn strictly_inside_tells_inside_from_outside_and_boundary() {
        let t = [Vector::new(-1.0, -1.0, -1.0), Vector::new(3.0, -1.0, -1.0), Vector::new(-1.0, 3.0, -1.0), Vector::new(-1.0, -1.0, 3.0)];
        assert!(strictly_inside(&t));
        let shifted = t.map(|p| p + Vector::new(1.0, 0.0, 0.0));
        assert!(!strictly_inside(&shifted), "origin on the face x = 0");
        let far = t.map(|p| p + Vector::new(5.0, 0.0, 0.0));
        assert!(!strictly_inside(&far));
    }
}
