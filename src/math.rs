//! The one place that picks the scalar and the vector types.
//!
//! The core works in `f64`: cells are thin (a few millimetres) next to workcells of several metres,
//! and the shared-wall property is checked at 1e-9 of the mesh size, which `f32` cannot hold. The
//! types are parry's (`parry3d-f64`, glam underneath), so that the BVH and the test oracle take them
//! without conversion. A parry upgrade touches this file only.

pub use parry3d_f64::math::{Pose, Real, Rotation, Vector};

/// Axis-aligned bounding box, as the BVH wants it.
pub use parry3d_f64::bounding_volume::Aabb;

/// `[min, max]` of `dir . p` over `points` (the projection of a point set on an axis).
#[inline]
pub(crate) fn project_points(points: &[Vector], dir: Vector) -> [Real; 2] {
    let mut lo = Real::INFINITY;
    let mut hi = Real::NEG_INFINITY;
    for p in points {
        let d = dir.dot(*p);
        lo = lo.min(d);
        hi = hi.max(d);
    }
    [lo, hi]
}

/// Solves `[n0; n1; n2] x = [d0, d1, d2]` (three planes `n_i . x = d_i`) by Cramer's rule.
///
/// Returns `None` when the normals are linearly dependent relative to their lengths
/// (`|det| <= eps * |n0||n1||n2|`): the planes do not meet in one point.
#[inline]
pub(crate) fn intersect_three_planes(n: [Vector; 3], d: [Real; 3], eps: Real) -> Option<Vector> {
    let c12 = n[1].cross(n[2]);
    let det = n[0].dot(c12);
    let scale = n[0].length() * n[1].length() * n[2].length();
    if !(det.abs() > eps * scale) {
        return None;
    }
    let x = (c12 * d[0] + n[2].cross(n[0]) * d[1] + n[0].cross(n[1]) * d[2]) / det;
    if x.is_finite() {
        Some(x)
    } else {
        None
    }
}

/// A pose as the Python peers read it (`tests/peers/hull_parts.py`, coal's `Transform3s`): the
/// rotation matrix row by row, then the translation. A test fixture (feature `testing`).
#[cfg(feature = "testing")]
pub fn pose_rows(p: &Pose) -> [Real; 12] {
    // glam's `DMat3::from_quat`, term for term, so the peers see the matrices they always saw.
    let q = p.rotation;
    let (x2, y2, z2) = (q.x + q.x, q.y + q.y, q.z + q.z);
    let (xx, xy, xz) = (q.x * x2, q.x * y2, q.x * z2);
    let (yy, yz, zz) = (q.y * y2, q.y * z2, q.z * z2);
    let (wx, wy, wz) = (q.w * x2, q.w * y2, q.w * z2);
    let t = p.translation;
    #[rustfmt::skip]
    let rows = [
        1.0 - (yy + zz), xy - wz, xz + wy,
        xy + wz, 1.0 - (xx + zz), yz - wx,
        xz - wy, yz + wx, 1.0 - (xx + yy),
        t.x, t.y, t.z,
    ];
    rows
}

/// nalgebra (kinematics) to parry/glam (geometry): the one conversion point.
pub fn pose_from_isometry(iso: &nalgebra::Isometry3<Real>) -> Pose {
    let q = iso.rotation.quaternion();
    let t = iso.translation.vector;
    Pose::from_parts(Vector::new(t.x, t.y, t.z), Rotation::from_xyzw(q.i, q.j, q.k, q.w))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pose_rows_are_glams_matrix_row_by_row() {
        let mut rng = oorandom::Rand64::new(7);
        for _ in 0..1000 {
            let mut r = || rng.rand_float() * 2.0 - 1.0;
            let q = Rotation::from_xyzw(r(), r(), r(), r()).normalize();
            let p = Pose::from_parts(Vector::new(r(), r(), r()), q);
            let m = glam::DMat3::from_quat(q);
            let want: Vec<Real> = (0..3).flat_map(|row| (0..3).map(move |c| m.col(c)[row])).chain(p.translation.to_array()).collect();
            assert_eq!(pose_rows(&p).to_vec(), want);
        }
    }
}
