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
pub fn project_points(points: &[Vector], dir: Vector) -> [Real; 2] {
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
pub fn intersect_three_planes(n: [Vector; 3], d: [Real; 3], eps: Real) -> Option<Vector> {
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

/// nalgebra (kinematics) to parry/glam (geometry): the one conversion point.
pub fn pose_from_isometry(iso: &nalgebra::Isometry3<Real>) -> Pose {
    let q = iso.rotation.quaternion();
    let t = iso.translation.vector;
    Pose::from_parts(Vector::new(t.x, t.y, t.z), Rotation::from_xyzw(q.i, q.j, q.k, q.w))
}
