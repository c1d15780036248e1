//! The broad phase prunes: the cell tree's boxes, its normal-cone depth bounds, axes that
//! separated neighbouring cells, and the centroid test that accepts a pair without the SAT. None of
//! that may change an answer. Here every query is repeated by brute force — every cell of the
//! surface through the public one-cell check (`collide_target_cell`: the normal axis, then the
//! full SAT) — and the two must agree, over many random targets of every kind near noisy, wavy
//! and folded surfaces, on every side rule:
//! - the same collision verdict per surface;
//! - the deepest contact's depth equal to the brute-force maximum (within the 1e-9 m search
//!   tolerance), on a cell that brute force says collides, with the depth brute force gives it;
//! - `all_contacts` giving exactly the brute-force set of colliding cells;
//! - `flag_only` giving the same verdict, on a cell that collides, with or without the least
//!   overlap (without it, a cell can be accepted by the centroid test alone).

mod common;

use oorandom::Rand64;
use std::sync::Arc;
use thickness_collision::collision::{collide_target_cell, CollideSettings, ConvexHull, Scene, Target, TargetShape};
use thickness_collision::math::{Pose, Real, Rotation, Vector};
use thickness_collision::mesh::generate;
use thickness_collision::thickness::{Side, ThicknessCell, ThicknessSettings};

struct Rng(Rand64);

impl Rng {
    fn f(&mut self) -> Real {
        self.0.rand_float()
    }
    fn range(&mut self, lo: Real, hi: Real) -> Real {
        lo + (hi - lo) * self.f()
    }
    fn unit(&mut self) -> Vector {
        loop {
            let v = Vector::new(self.range(-1.0, 1.0), self.range(-1.0, 1.0), self.range(-1.0, 1.0));
            if v.length_squared() > 0.01 && v.length_squared() <= 1.0 {
                return v.normalize();
            }
        }
    }
    fn rotation(&mut self) -> Rotation {
        Rotation::from_axis_angle(self.unit(), self.range(0.0, std::f64::consts::TAU))
    }
}

/// Surfaces near z = 0 over [0, 0.4]^2: a scan-like noisy field, a corrugated sheet, a fold.
fn surfaces() -> Vec<(&'static str, generate::Soup)> {
    let noisy = generate::height_field(40, 40, 0.4, 0.4, |x, y| {
        let mut k = x.to_bits().wrapping_mul(0x9E3779B97F4A7C15) ^ y.to_bits().rotate_left(29);
        k = (k ^ (k >> 31)).wrapping_mul(0xBF58476D1CE4E5B9);
        0.01 * (9.0 * x).sin() + ((k >> 11) as Real / (1u64 << 53) as Real - 0.5) * 0.006
    });
    let wavy = generate::height_field(50, 30, 0.4, 0.4, |x, y| 0.012 * (2.0 * std::f64::consts::PI * x / 0.08).sin() + 0.004 * (8.0 * y).cos());
    let fold = generate::v_fold(100f64.to_radians(), true, 0.2, 0.4, 24);
    vec![("noisy", noisy), ("wavy", wavy), ("fold", fold)]
}

/// A random convex target of any kind, 1 to 8 cm across, centred near the surface.
fn random_target(rng: &mut Rng) -> Target {
    let shape = match (rng.f() * 6.0) as usize {
        0 => TargetShape::cuboid(Vector::new(rng.range(0.005, 0.04), rng.range(0.005, 0.04), rng.range(0.005, 0.04))).unwrap(),
        1 => TargetShape::Sphere { radius: rng.range(0.005, 0.04) },
        2 => TargetShape::Capsule { half_height: rng.range(0.0, 0.04), radius: rng.range(0.005, 0.03) },
        3 => TargetShape::Cylinder { half_height: rng.range(0.005, 0.04), radius: rng.range(0.005, 0.03) },
        _ => {
            // A hull of 30..300 points on an ellipsoid: above the 24 points where hulls are
            // projected through the cube map and hill climbing rather than a scan.
            let n = 30 + (rng.f() * 270.0) as usize;
            let axes = Vector::new(rng.range(0.01, 0.05), rng.range(0.01, 0.05), rng.range(0.01, 0.08));
            let pts: Vec<Vector> = (0..n).map(|_| rng.unit() * axes).collect();
            TargetShape::Polytope(Arc::new(ConvexHull::from_points(&pts).unwrap()))
        }
    };
    let centre = Vector::new(rng.range(0.0, 0.4), rng.range(0.0, 0.4), rng.range(-0.06, 0.05));
    Target::new(shape, Pose::from_parts(centre, rng.rotation()))
}

/// Every colliding cell by brute force: `(triangle, depth)`.
fn brute_force(target: &Target, cells: &[ThicknessCell], side: Side, pose: &Pose) -> Vec<(u32, Real)> {
    cells.iter().filter_map(|c| collide_target_cell(target, c, side, pose, false).map(|hit| (c.triangle, hit.depth))).collect()
}

#[test]
fn pruned_queries_agree_with_brute_force() {
    let mut rng = Rng(Rand64::new(2026));
    let (mut queries, mut colliding, mut deep_cells) = (0, 0, 0usize);
    for (name, (v, t)) in surfaces() {
        let mesh = common::topology(&v, &t);
        for side in [Side::Back, Side::Front, Side::Both] {
            let area = common::topology_area(&mesh, &ThicknessSettings { thickness: 0.02, side, ..Default::default() });
            // The surface placed somewhere in the world, so that frames are exercised too.
            let pose = Pose::from_parts(Vector::new(rng.range(-1.0, 1.0), rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)), rng.rotation());
            let mut scene = Scene::new();
            let _ = scene.add_surface(name, pose, area);
            let cells = &scene.objects()[0].area().unwrap().cells;
            for _ in 0..250 {
                let local = random_target(&mut rng);
                let target = Target::new(local.shape.clone(), pose * local.pose);
                let truth = brute_force(&target, cells, side, &pose);
                queries += 1;
                let kind = match &target.shape {
                    TargetShape::Polytope(h) => format!("hull of {} points", h.points().len()),
                    other => format!("{other:?}"),
                };
                let context = format!("{name}, {side:?}, query {queries}: {kind} at {:?}", target.pose);

                let deepest = scene.collide(&target, &CollideSettings::default());
                assert_eq!(deepest.in_collision(), !truth.is_empty(), "verdict: {context}");
                if let Some(c) = deepest.deepest() {
                    colliding += 1;
                    deep_cells += truth.len();
                    let max = truth.iter().map(|(_, d)| *d).fold(Real::NEG_INFINITY, Real::max);
                    assert!((c.depth - max).abs() <= 1e-9, "deepest {} vs brute force {max}: {context}", c.depth);
                    let own = truth.iter().find(|(tri, _)| *tri == c.triangle);
                    assert!(
                        own.is_some_and(|(_, d)| (*d - c.depth).abs() <= 1e-12),
                        "the reported cell {} must collide at the reported depth {}, brute force {own:?}: {context}",
                        c.triangle,
                        c.depth
                    );
                    assert!(
                        c.least.is_some_and(|l| l.overlap > 0.0 && l.axis.is_finite()) && c.position.is_some_and(|p| p.is_finite()),
                        "least overlap and point: {context}"
                    );
                }
                // Without the least overlap the same contact (its least overlap may be left out).
                let lean = scene.collide(&target, &CollideSettings { least_overlap: false, ..Default::default() });
                assert_eq!(
                    lean.deepest().map(|c| (c.triangle, c.depth, c.position)),
                    deepest.deepest().map(|c| (c.triangle, c.depth, c.position)),
                    "{context}"
                );

                let all = scene.collide(&target, &CollideSettings { all_contacts: true, ..Default::default() });
                let mut got: Vec<u32> = all.contacts.iter().map(|c| c.triangle).collect();
                let mut want: Vec<u32> = truth.iter().map(|(tri, _)| *tri).collect();
                got.sort_unstable();
                want.sort_unstable();
                assert_eq!(got, want, "all contacts: {context}");

                for least_overlap in [true, false] {
                    let flag = scene.collide(&target, &CollideSettings { flag_only: true, least_overlap, ..Default::default() });
                    assert_eq!(flag.in_collision(), !truth.is_empty(), "flag only: {context}");
                    if let Some(c) = flag.contacts.first() {
                        assert!(truth.iter().any(|(tri, _)| *tri == c.triangle), "flag only names a colliding cell: {context}");
                        assert!(!least_overlap || c.least.is_some_and(|l| l.overlap > 0.0), "flag only: the overlap is there when asked for: {context}");
                        assert!(c.position.is_none(), "flag only computes no point: {context}");
                    }
                }
            }
        }
    }
    // The random cases must exercise what they claim to.
    assert!(colliding > queries / 4 && colliding < queries * 9 / 10, "{colliding} of {queries} queries collide");
    assert!(deep_cells > 20 * colliding, "colliding queries meet {deep_cells} cells in all: too few for the pruning to matter");
    println!("{queries} queries, {colliding} colliding, {deep_cells} colliding cells checked by brute force");
}

/// A hull's support through the cube map (and hill climbing where a bin has no single extreme
/// vertex) against a scan of every vertex, over many directions, through the public projection
/// of a target's bounding box.
#[test]
fn hull_support_matches_a_scan() {
    let mut rng = Rng(Rand64::new(7));
    for _ in 0..40 {
        let n = 24 + (rng.f() * 500.0) as usize;
        let axes = Vector::new(rng.range(0.01, 0.2), rng.range(0.01, 0.2), rng.range(0.01, 0.2));
        // Some points on an ellipsoid, some inside, and some repeated coordinates (flat faces).
        let pts: Vec<Vector> = (0..n)
            .map(|_| {
                let p = rng.unit() * axes * if rng.f() < 0.2 { rng.f() } else { 1.0 };
                if rng.f() < 0.1 {
                    p.with_z(axes.z)
                } else {
                    p
                }
            })
            .collect();
        let Some(hull) = ConvexHull::from_points(&pts) else { continue };
        let shape = TargetShape::Polytope(Arc::new(hull.clone()));
        for _ in 0..5_000 {
            let rot = rng.rotation();
            let target = Target::new(shape.clone(), Pose::from_rotation(rot));
            // aabb_in projects the hull on the three axes of the given frame.
            let aabb = target.aabb_in(&Pose::from_rotation(rot));
            let inv = rot.inverse();
            for (k, axis) in [Vector::X, Vector::Y, Vector::Z].into_iter().enumerate() {
                let d = inv * axis;
                let (lo, hi) = hull.points().iter().fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), p| (lo.min(d.dot(*p)), hi.max(d.dot(*p))));
                assert!(
                    (aabb.mins[k] - lo).abs() <= 1e-12 && (aabb.maxs[k] - hi).abs() <= 1e-12,
                    "axis {k}: [{}, {}] vs scan [{lo}, {hi}]",
                    aabb.mins[k],
                    aabb.maxs[k]
                );
            }
        }
    }
}
