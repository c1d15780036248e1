//! Two convex robot parts against each other (self-collision): a bounding-ball test, then the
//! proof-carrying GJK ([`super::gjk`]), and parry's GJK/EPA for the depth of a pair that overlaps
//! (or that the GJK could not decide: touching or razor-thin overlaps).

use super::gjk::{convex_pair, Verdict};
use super::target::{sweep_end, Target, TargetShape};
use crate::math::{Real, Vector};

/// A contact between two parts, in the world frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PairContact {
    /// Penetration depth: the least translation that separates them (metres, `> 0`).
    pub depth: Real,
    /// Unit direction in which the first part moves by `depth` to separate.
    pub normal: Vector,
    /// Midway between the two deepest points.
    pub position: Vector,
}

impl TargetShape {
    /// A point of the shape extreme along `dir` (in its frame).
    pub(crate) fn support_point(&self, dir: Vector) -> Vector {
        let unit = |v: Vector| if v.length_squared() > 0.0 { v.normalize() } else { Vector::ZERO };
        match self {
            TargetShape::Polytope(h) => h.support_point(dir),
            TargetShape::Sphere { radius } => unit(dir) * *radius,
            TargetShape::Capsule { half_height, radius } => Vector::new(0.0, 0.0, half_height.copysign(dir.z)) + unit(dir) * *radius,
            TargetShape::Cylinder { half_height, radius } => {
                let side = unit(Vector::new(dir.x, dir.y, 0.0)) * *radius;
                Vector::new(side.x, side.y, half_height.copysign(dir.z))
            }
            TargetShape::Swept { core, sweep } => core.support_point(dir) + sweep_end(*sweep, dir),
        }
    }
}

/// Whether two posed parts overlap, and how deep; touching counts as apart.
pub(crate) fn collide_pair(a: &Target, b: &Target) -> Option<PairContact> {
    match verdict(a, 0.0, b, 0.0)? {
        Verdict::Apart(_) => None,
        Verdict::Overlap | Verdict::Unknown => depth(a, b),
    }
}

/// Whether two posed parts, each grown by a ball (radii `grow_a`, `grow_b`), may meet: `false`
/// only with a proof (their grown bounding balls apart, or an axis `d` along which the grown
/// supports separate: `h_a(d) + grow_a·|d| <= -h_b(-d) - grow_b·|d|`). A motion's self pair is
/// cleared on this: the ball is the displacement bound's own shape, so nothing is tested that
/// the stretch cannot reach (a hull grown by a cube reaches √3 times as far along its corners).
/// No depth is sought: the EPA of a pair that overlaps cost 24 µs a test on the motion benchmark,
/// the whole answer ~1 µs.
///
/// `hint` (in `a`'s frame; zero: none) is where the search starts, and gets the separating axis
/// when one is found: a pair asked again a little further along a motion is mostly separated by
/// the axis that separated it before, and then one pair of supports answers.
pub(crate) fn pair_may_meet_grown(a: &Target, grow_a: Real, b: &Target, grow_b: Real, hint: &mut Vector) -> bool {
    match verdict_from(a, grow_a, b, grow_b, a.pose.rotation * *hint) {
        None => false,
        Some(Verdict::Apart(d)) => {
            *hint = a.pose.rotation.inverse() * d;
            false
        }
        Some(_) => true,
    }
}

/// The proof-carrying GJK's verdict on two posed parts, each grown by a ball of its radius
/// (`0`: as it is); `None` when their grown bounding balls are apart.
fn verdict(a: &Target, grow_a: Real, b: &Target, grow_b: Real) -> Option<Verdict> {
    verdict_from(a, grow_a, b, grow_b, Vector::ZERO)
}

/// [`verdict`], the search starting along `start` (zero: the line between the parts' centres).
fn verdict_from(a: &Target, grow_a: Real, b: &Target, grow_b: Real, start: Vector) -> Option<Verdict> {
    let (ca, cb) = (a.pose * a.shape.centre(), b.pose * b.shape.centre());
    let reach = a.shape.bounding_radius() + b.shape.bounding_radius() + grow_a + grow_b;
    if !((ca - cb).length_squared() < reach * reach) {
        return None;
    }
    let (ra, rb) = (a.pose.rotation.inverse(), b.pose.rotation.inverse());
    // The state check's pairs are not grown: no square root per support for them.
    let grown = grow_a != 0.0 || grow_b != 0.0;
    let support = |d: Vector| {
        let (mut pa, mut pb) = (a.pose * a.shape.support_point(ra * d), b.pose * b.shape.support_point(rb * -d));
        if grown {
            // `convex_pair` asks only along directions of positive length.
            let unit = d / d.length();
            pa += unit * grow_a;
            pb -= unit * grow_b;
        }
        (pa - pb, d.dot(pa), d.dot(pb))
    };
    Some(convex_pair(support, if start.length_squared() > 0.0 { start } else { cb - ca }))
}

/// parry's contact query (GJK, then EPA) for a pair that may overlap.
fn depth(a: &Target, b: &Target) -> Option<PairContact> {
    let c =
        a.shape.with_parry(|s1, o1| b.shape.with_parry(|s2, o2| parry3d_f64::query::contact(&(a.pose * *o1), s1, &(b.pose * *o2), s2, 0.0).ok().flatten()))?;
    if !(c.dist < 0.0) {
        return None;
    }
    Some(PairContact { depth: -c.dist, normal: -c.normal1, position: (c.point1 + c.point2) * 0.5 })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::collision::ConvexHull;
    use crate::math::{Pose, Rotation};
    use std::sync::Arc;

    /// Two random hulls, each grown by a ball, against parry's distance between the hulls as they
    /// are: "apart" only when the distance exceeds the two radii, and "apart" for nearly every
    /// pair farther than that by a millimetre (the GJK on rounded shapes ends with its proof).
    /// The same from a random starting axis, and again from the axis a pair was separated by
    /// (which, asked again, separates it at once).
    #[test]
    fn grown_pairs_are_apart_only_when_their_distance_exceeds_the_growth() {
        let mut rng = oorandom::Rand64::new(35);
        let mut rf = |lo: Real, hi: Real| lo + (hi - lo) * rng.rand_float();
        let (mut far, mut far_apart, mut near) = (0, 0, 0);
        for _ in 0..2000 {
            let mut hull = || {
                let points: Vec<Vector> = (0..12).map(|_| Vector::new(rf(-0.1, 0.1), rf(-0.05, 0.05), rf(-0.2, 0.2))).collect();
                let axis = Vector::new(rf(-1.0, 1.0), rf(-1.0, 1.0), rf(0.1, 1.0)).normalize();
                let pose = Pose::from_parts(Vector::new(rf(-0.3, 0.3), rf(-0.3, 0.3), rf(-0.3, 0.3)), Rotation::from_axis_angle(axis, rf(0.0, 3.0)));
                Target::new(TargetShape::Polytope(Arc::new(ConvexHull::from_points(&points).expect("a hull"))), pose)
            };
            let (a, b) = (hull(), hull());
            let (ga, gb) = (rf(0.0, 0.1), rf(0.0, 0.1));
            let distance = a.shape.with_parry(|sa, oa| {
                b.shape.with_parry(|sb, ob| parry3d_f64::query::distance(&(a.pose * *oa), sa, &(b.pose * *ob), sb).expect("convex shapes").distance)
            });
            let mut hint = Vector::ZERO;
            let may_meet = pair_may_meet_grown(&a, ga, &b, gb, &mut hint);
            assert!(may_meet || distance > ga + gb - 1e-9, "apart at distance {distance} with growths {ga} + {gb}");
            let mut random = Vector::new(rf(-1.0, 1.0), rf(-1.0, 1.0), rf(-1.0, 1.0));
            let from_random = pair_may_meet_grown(&a, ga, &b, gb, &mut random);
            assert!(from_random || distance > ga + gb - 1e-9, "apart from a random start at distance {distance} with growths {ga} + {gb}");
            // (No axis when the grown bounding balls are already apart.)
            if !may_meet && distance > ga + gb + 1e-6 && hint != Vector::ZERO {
                let separating = hint.normalize();
                assert!(!pair_may_meet_grown(&a, ga, &b, gb, &mut hint), "the axis that separated the pair separates it again");
                assert!((hint.normalize() - separating).length() < 1e-9, "at once: {hint:?} from {separating:?}");
            }
            if distance > ga + gb + 1e-3 {
                far += 1;
                far_apart += usize::from(!may_meet);
            } else {
                near += 1;
            }
        }
        assert!(far > 300 && near > 300, "{far} far, {near} near");
        assert!(far_apart as f64 >= 0.99 * far as f64, "{far_apart} of {far} pairs a millimetre past their growth called apart");
    }
}
