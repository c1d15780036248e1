//! Geometry helpers shared by `tests/thickness_rule.rs` and `tests/thickness_properties.rs`.
#![allow(dead_code)]

use std::f64::consts::PI;
use thickness_collision::math::{Aabb, Real, Vector};
use thickness_collision::mesh::generate::Soup;

/// The box around `points` (at least one).
pub fn aabb_of(points: &[Vector]) -> Aabb {
    let (lo, hi) = points.iter().fold((points[0], points[0]), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    Aabb::new(lo, hi)
}

/// Möller–Trumbore: does the segment `p + s d`, `s` in `(w_min, 1]`, cross triangle `abc`? (`w_min`
/// keeps the segment's own start off its own face.)
pub fn segment_crosses_triangle(p: Vector, d: Vector, [a, b, c]: [Vector; 3], w_min: Real) -> bool {
    let (e1, e2) = (b - a, c - a);
    let h = d.cross(e2);
    let det = e1.dot(h);
    if det.abs() < 1e-300 {
        return false;
    }
    let inv = 1.0 / det;
    let s = p - a;
    let u = inv * s.dot(h);
    let q = s.cross(e1);
    let v = inv * d.dot(q);
    let w = inv * e2.dot(q);
    u >= 0.0 && v >= 0.0 && u + v <= 1.0 && w > w_min && w <= 1.0
}

/// Two triangle fans meeting along a crease of length `l` split in `m` segments, at dihedral angle
/// `angle`: every face has the crease as an edge, so only the crease vertices are "near a vertex".
pub fn fan_fold(angle: Real, ridge: bool, w: Real, l: Real, m: usize) -> Soup {
    let half = (PI - angle) / 2.0;
    let s = if ridge { -1.0 } else { 1.0 };
    let at = |u: Real, y: Real| Vector::new(u * half.cos(), y, s * u.abs() * half.sin());
    let mut v: Vec<Vector> = (0..=m).map(|j| at(0.0, l * j as Real / m as Real)).collect();
    v.push(at(-w, l / 2.0));
    v.push(at(w, l / 2.0));
    let (left, right) = (m as u32 + 1, m as u32 + 2);
    let mut t = Vec::new();
    for j in 0..m as u32 {
        t.push([left, j, j + 1]);
        t.push([j, right, j + 1]);
    }
    (v, t)
}
