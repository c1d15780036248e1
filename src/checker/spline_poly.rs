//! One joint's position over one trajectory segment as `joint_trajectory_controller` commands it:
//! a polynomial of degree 1, 3 or 5 in the segment's own parameter `s ∈ [0, 1]` (time
//! `t = s·T` from the segment's start), and the extremes of that polynomial over any
//! sub-interval (at its ends or at roots of its derivative), which bound how far the joint
//! strays on it.
//!
//! The coefficients are those of ros2_controllers' `Trajectory::interpolate_between_points`
//! (`joint_trajectory_controller/src/trajectory.cpp`), computed in seconds exactly as there and
//! then scaled by `T^k` into `s`.

/// A polynomial of degree at most 5 in `s`: `c[0] + c[1] s + … + c[5] s⁵`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SegmentPoly {
    /// Coefficients, lowest degree first.
    pub c: [f64; 6],
}

/// Bisection steps for one root: `2^-60` of a sub-interval of `[0, 1]` is below `f64` spacing.
const ROOT_STEPS: usize = 60;

impl SegmentPoly {
    /// A joint that stays at `p`.
    pub fn constant(p: f64) -> SegmentPoly {
        SegmentPoly { c: [p, 0.0, 0.0, 0.0, 0.0, 0.0] }
    }

    /// Linear from `p0` to `p1`.
    pub fn linear(p0: f64, p1: f64) -> SegmentPoly {
        SegmentPoly { c: [p0, p1 - p0, 0.0, 0.0, 0.0, 0.0] }
    }

    /// Cubic through positions and velocities (per second) at both ends over `duration` seconds,
    /// with the controller's coefficients.
    pub fn cubic(p0: f64, v0: f64, p1: f64, v1: f64, duration: f64) -> SegmentPoly {
        let t = duration;
        let (t2, t3) = (t * t, t * t * t);
        let c = [p0, v0, (-3.0 * p0 + 3.0 * p1 - 2.0 * v0 * t - v1 * t) / t2, (2.0 * p0 - 2.0 * p1 + v0 * t + v1 * t) / t3, 0.0, 0.0];
        SegmentPoly::from_seconds(c, t)
    }

    /// Quintic through positions, velocities and accelerations at both ends over `duration`
    /// seconds, with the controller's coefficients.
    pub fn quintic(p0: f64, v0: f64, a0: f64, p1: f64, v1: f64, a1: f64, duration: f64) -> SegmentPoly {
        let t = duration;
        let (t2, t3, t4, t5) = (t * t, t * t * t, t * t * t * t, t * t * t * t * t);
        let c = [
            p0,
            v0,
            0.5 * a0,
            (-20.0 * p0 + 20.0 * p1 - 3.0 * a0 * t2 + a1 * t2 - 12.0 * v0 * t - 8.0 * v1 * t) / (2.0 * t3),
            (30.0 * p0 - 30.0 * p1 + 3.0 * a0 * t2 - 2.0 * a1 * t2 + 16.0 * v0 * t + 14.0 * v1 * t) / (2.0 * t4),
            (-12.0 * p0 + 12.0 * p1 - a0 * t2 + a1 * t2 - 6.0 * v0 * t - 6.0 * v1 * t) / (2.0 * t5),
        ];
        SegmentPoly::from_seconds(c, t)
    }

    /// Coefficients in seconds turned into coefficients in `s = t / duration`.
    fn from_seconds(c: [f64; 6], duration: f64) -> SegmentPoly {
        let mut scale = 1.0;
        let mut out = [0.0; 6];
        for (o, ci) in out.iter_mut().zip(c) {
            *o = ci * scale;
            scale *= duration;
        }
        SegmentPoly { c: out }
    }

    /// `self(s)`, by Horner's rule.
    pub fn at(&self, s: f64) -> f64 {
        self.c.iter().rev().fold(0.0, |acc, c| acc * s + c)
    }

    /// `self` times `k` plus `offset` (a mimic joint following this one).
    pub fn scaled(&self, k: f64, offset: f64) -> SegmentPoly {
        let mut c = self.c.map(|x| x * k);
        c[0] += offset;
        SegmentPoly { c }
    }

    /// The derivative, `d/ds`.
    pub(crate) fn derivative(&self) -> SegmentPoly {
        let mut c = [0.0; 6];
        for k in 1..6 {
            c[k - 1] = self.c[k] * k as f64;
        }
        SegmentPoly { c }
    }

    /// Highest power with a coefficient other than 0 (0 for a constant).
    fn degree(&self) -> usize {
        (0..6).rev().find(|&k| self.c[k] != 0.0).unwrap_or(0)
    }

    /// Where the derivative changes sign in `(0, 1)`, ascending: with the ends, the only places
    /// the polynomial can take its extremes on any sub-interval.
    pub fn turning_points(&self) -> Vec<f64> {
        roots_in(&self.derivative(), 0.0, 1.0, 0)
    }

    /// The largest `|self(s') - self(s)|` over `s'` in `[a, b]` (which holds `s`), given the
    /// turning points from [`SegmentPoly::turning_points`].
    pub fn excursion(&self, turning: &[f64], s: f64, a: f64, b: f64) -> f64 {
        let centre = self.at(s);
        let ends = (self.at(a) - centre).abs().max((self.at(b) - centre).abs());
        turning.iter().filter(|&&r| r > a && r < b).fold(ends, |m, &r| m.max((self.at(r) - centre).abs()))
    }

    /// The least and largest value over `[0, 1]`, given the turning points.
    pub fn range(&self, turning: &[f64]) -> (f64, f64) {
        let values = turning.iter().map(|&r| self.at(r)).chain([self.at(0.0), self.at(1.0)]);
        values.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| (lo.min(x), hi.max(x)))
    }

    /// The largest `|self(s)|` over `[a, b]`, given the turning points.
    pub fn max_abs(&self, turning: &[f64], a: f64, b: f64) -> f64 {
        let ends = self.at(a).abs().max(self.at(b).abs());
        turning.iter().filter(|&&r| r > a && r < b).fold(ends, |m, &r| m.max(self.at(r).abs()))
    }

    /// The largest `|self'(s)|` over `[0, 1]`: how fast the joint moves per unit of `s`.
    pub fn top_speed(&self) -> f64 {
        let d = self.derivative();
        let ends = d.at(0.0).abs().max(d.at(1.0).abs());
        d.turning_points().iter().fold(ends, |m, &r| m.max(d.at(r).abs()))
    }
}

/// The roots of `p` in `(lo, hi)` where it changes sign, ascending. The polynomial is monotone
/// between consecutive roots of its derivative (found the same way, one degree lower; the depth
/// is at most 5, whatever the input), so each such piece holds at most one root, found by
/// bisection. A root of even multiplicity (a touch without a sign change) is not a turning point
/// and is left out; so is one at `lo` or `hi`.
fn roots_in(p: &SegmentPoly, lo: f64, hi: f64, depth: usize) -> Vec<f64> {
    let degree = p.degree();
    if degree == 0 || depth > 5 {
        return Vec::new();
    }
    if degree == 1 {
        let r = -p.c[0] / p.c[1];
        return if r > lo && r < hi { vec![r] } else { Vec::new() };
    }
    let mut cuts = vec![lo];
    cuts.extend(roots_in(&p.derivative(), lo, hi, depth + 1));
    cuts.push(hi);
    let mut roots = Vec::new();
    for w in cuts.windows(2) {
        let (mut a, mut b) = (w[0], w[1]);
        let (fa, fb) = (p.at(a), p.at(b));
        if !(fa < 0.0 && fb > 0.0 || fa > 0.0 && fb < 0.0) {
            continue;
        }
        let rising = fb > fa;
        for _ in 0..ROOT_STEPS {
            let m = 0.5 * (a + b);
            if (p.at(m) < 0.0) == rising {
                a = m;
            } else {
                b = m;
            }
        }
        let r = 0.5 * (a + b);
        if r > lo && r < hi {
            roots.push(r);
        }
    }
    roots
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The controller's own sampling (`interpolate_between_points`), written from its formulas in
    /// seconds, as an oracle: position at `t` for the quintic.
    fn jtc_quintic([p0, v0, a0]: [f64; 3], [p1, v1, a1]: [f64; 3], tt: f64, t: f64) -> f64 {
        let c3 = (-20.0 * p0 + 20.0 * p1 - 3.0 * a0 * tt * tt + a1 * tt * tt - 12.0 * v0 * tt - 8.0 * v1 * tt) / (2.0 * tt.powi(3));
        let c4 = (30.0 * p0 - 30.0 * p1 + 3.0 * a0 * tt * tt - 2.0 * a1 * tt * tt + 16.0 * v0 * tt + 14.0 * v1 * tt) / (2.0 * tt.powi(4));
        let c5 = (-12.0 * p0 + 12.0 * p1 - a0 * tt * tt + a1 * tt * tt - 6.0 * v0 * tt - 6.0 * v1 * tt) / (2.0 * tt.powi(5));
        p0 + v0 * t + 0.5 * a0 * t * t + c3 * t.powi(3) + c4 * t.powi(4) + c5 * t.powi(5)
    }

    #[test]
    fn the_segments_meet_their_ends_and_match_the_controller() {
        let mut rng = oorandom::Rand64::new(3);
        let mut draw = |lo: f64, hi: f64| lo + (hi - lo) * rng.rand_float();
        for _ in 0..500 {
            let (p0, v0, a0, p1, v1, a1) = (draw(-3.0, 3.0), draw(-2.0, 2.0), draw(-5.0, 5.0), draw(-3.0, 3.0), draw(-2.0, 2.0), draw(-5.0, 5.0));
            let t = draw(0.01, 4.0);
            let q = SegmentPoly::quintic(p0, v0, a0, p1, v1, a1, t);
            assert!((q.at(0.0) - p0).abs() < 1e-9 && (q.at(1.0) - p1).abs() < 1e-7 * (1.0 + p1.abs()), "{q:?}");
            // Velocity at the ends, per second.
            let d = q.derivative();
            assert!((d.at(0.0) / t - v0).abs() < 1e-9 && (d.at(1.0) / t - v1).abs() < 1e-6 * (1.0 + v1.abs()));
            for k in 0..=10 {
                let s = k as f64 / 10.0;
                let want = jtc_quintic([p0, v0, a0], [p1, v1, a1], t, s * t);
                assert!((q.at(s) - want).abs() < 1e-8 * (1.0 + want.abs()), "s {s}: {} vs {want}", q.at(s));
            }
            let c = SegmentPoly::cubic(p0, v0, p1, v1, t);
            assert!((c.at(0.0) - p0).abs() < 1e-12 && (c.at(1.0) - p1).abs() < 1e-9 * (1.0 + p1.abs()));
            assert!((c.derivative().at(1.0) / t - v1).abs() < 1e-8 * (1.0 + v1.abs()));
        }
    }

    /// The excursion over a sub-interval is the largest deviation a dense sampling finds (never
    /// less, and at most rounding more), on random quintics with several turning points.
    #[test]
    fn the_excursion_bounds_every_sample_and_is_tight() {
        let mut rng = oorandom::Rand64::new(5);
        let mut draw = |lo: f64, hi: f64| lo + (hi - lo) * rng.rand_float();
        let mut turned = 0;
        for _ in 0..400 {
            let q =
                SegmentPoly::quintic(draw(-1.0, 1.0), draw(-6.0, 6.0), draw(-40.0, 40.0), draw(-1.0, 1.0), draw(-6.0, 6.0), draw(-40.0, 40.0), draw(0.2, 2.0));
            let turning = q.turning_points();
            turned += turning.len();
            assert!(turning.windows(2).all(|w| w[0] < w[1]), "{turning:?}");
            let a = draw(0.0, 0.9);
            let b = (a + draw(0.0, 0.5)).min(1.0);
            let s = draw(a, b);
            let e = q.excursion(&turning, s, a, b);
            let mut dense = 0.0f64;
            for k in 0..=4000 {
                let x = a + (b - a) * k as f64 / 4000.0;
                dense = dense.max((q.at(x) - q.at(s)).abs());
            }
            assert!(dense <= e + 1e-12, "sampled {dense} > excursion {e}");
            assert!(e <= dense + 1e-6 * (1.0 + e), "excursion {e} much above the samples' {dense}");
            let top = q.top_speed();
            for k in 0..=400 {
                assert!(q.derivative().at(k as f64 / 400.0).abs() <= top + 1e-9);
            }
        }
        assert!(turned > 300, "the cases must turn: {turned} turning points");
    }
}
