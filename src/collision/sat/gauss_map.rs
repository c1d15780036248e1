//! The Gauss-map test for edge pairs (Gregorius, "The Separating Axis Test between Convex
//! Polyhedra", GDC 2013): edge A (faces with normals `a`, `b`) and edge B (faces `c`, `d`) form a
//! face of the Minkowski difference `A - B` exactly when the arcs `a-b` and `-c`-`-d` cross on the
//! unit sphere. Only those pairs can give a separating or least-overlap axis that the face normals
//! do not; on a 200-face hull against a cell this drops ~97% of the 2,700 pairs.

use crate::math::Vector;

#[inline]
pub(crate) fn is_minkowski_face(a: Vector, b: Vector, c: Vector, d: Vector) -> bool {
    let (c, d) = (-c, -d);
    let bxa = b.cross(a);
    let dxc = d.cross(c);
    let cba = c.dot(bxa);
    let dba = d.dot(bxa);
    let adc = a.dot(dxc);
    let bdc = b.dot(dxc);
    cba * dba < 0.0 && adc * bdc < 0.0 && cba * bdc > 0.0
}

/// [`is_minkowski_face`] with the arcs' normals given (`bxa = b x a`, `dxc = d x c`), for loops
/// that test one edge against many: the cheap half of the test comes first, and most pairs stop
/// there.
#[inline]
pub(crate) fn is_minkowski_face_arcs(a: Vector, b: Vector, bxa: Vector, c: Vector, d: Vector, dxc: Vector) -> bool {
    let adc = a.dot(dxc);
    let bdc = b.dot(dxc);
    if !(adc * bdc < 0.0) {
        return false;
    }
    // With the second edge's normals negated: cba = -c . bxa, dba = -d . bxa.
    let cba = -c.dot(bxa);
    let dba = -d.dot(bxa);
    cba * dba < 0.0 && cba * bdc > 0.0
}
