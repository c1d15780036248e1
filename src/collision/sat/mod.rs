//! Separating-axis tests of each target kind against a cell, in the target's frame.
//!
//! Each returns `None` when an axis separates the pair (overlap `<= 0`, so touching is apart),
//! else the least overlap over the candidate axes and its axis, oriented as the direction in
//! which the target moves to separate. With exact axis sets that is the minimal translation.

mod gauss_map;
mod sat_capsule_cell;
mod sat_hull_cell;
mod sat_sphere_cell;

pub(crate) use self::sat_capsule_cell::sat_capsule_cell;
pub(crate) use self::sat_hull_cell::sat_hull_cell;
pub(crate) use self::sat_sphere_cell::sat_sphere_cell;

use crate::math::{Real, Vector};

/// The least overlap found and the direction that separates the target.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct SatOverlap {
    /// Least overlap (metres, `> 0`).
    pub overlap: Real,
    /// Unit direction in which the target moves by `overlap` to separate.
    pub axis: Vector,
}

/// Keeps the least overlap over the axes seen; says when an axis separates.
pub(crate) struct LeastOverlap {
    best: SatOverlap,
}

impl LeastOverlap {
    pub fn new() -> Self {
        LeastOverlap { best: SatOverlap { overlap: Real::INFINITY, axis: Vector::ZERO } }
    }

    /// Records unit axis `l` with target range `a` and cell range `b`. Returns `false` when it
    /// separates them.
    #[inline]
    pub fn add(&mut self, l: Vector, a: [Real; 2], b: [Real; 2]) -> bool {
        // Target below the cell: move it down by a_max - b_min; above: up by b_max - a_min.
        let down = a[1] - b[0];
        let up = b[1] - a[0];
        let (overlap, axis) = if down <= up { (down, -l) } else { (up, l) };
        if !(overlap > 0.0) {
            return false;
        }
        if overlap < self.best.overlap {
            self.best = SatOverlap { overlap, axis };
        }
        true
    }

    /// Records an axis whose overlap is known (already oriented).
    #[inline]
    pub fn add_oriented(&mut self, overlap: Real, axis: Vector) -> bool {
        if !(overlap > 0.0) {
            return false;
        }
        if overlap < self.best.overlap {
            self.best = SatOverlap { overlap, axis };
        }
        true
    }

    pub fn finish(self) -> Option<SatOverlap> {
        (self.best.overlap.is_finite()).then_some(self.best)
    }
}

/// Closest point to `p` on segment `[a, b]`.
#[inline]
pub(crate) fn closest_on_segment(p: Vector, a: Vector, b: Vector) -> Vector {
    let d = b - a;
    let l2 = d.length_squared();
    if l2 <= 0.0 {
        return a;
    }
    a + d * ((p - a).dot(d) / l2).clamp(0.0, 1.0)
}

/// Closest points between segments `[p1, q1]` and `[p2, q2]` (Ericson, RTCD 5.1.9).
pub(crate) fn closest_segment_segment(p1: Vector, q1: Vector, p2: Vector, q2: Vector) -> (Vector, Vector) {
    let d1 = q1 - p1;
    let d2 = q2 - p2;
    let r = p1 - p2;
    let a = d1.dot(d1);
    let e = d2.dot(d2);
    let f = d2.dot(r);
    let eps = 1e-30;
    let (s, t);
    if a <= eps && e <= eps {
        return (p1, p2);
    }
    if a <= eps {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = d1.dot(r);
        if e <= eps {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            let mut s0 = if denom > eps * a * e { ((b * f - c * e) / denom).clamp(0.0, 1.0) } else { 0.0 };
            let mut t0 = (b * s0 + f) / e;
            if t0 < 0.0 {
                t0 = 0.0;
                s0 = (-c / a).clamp(0.0, 1.0);
            } else if t0 > 1.0 {
                t0 = 1.0;
                s0 = ((b - c) / a).clamp(0.0, 1.0);
            }
            s = s0;
            t = t0;
        }
    }
    (p1 + d1 * s, p2 + d2 * t)
}
