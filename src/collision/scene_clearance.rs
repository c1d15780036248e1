//! Clearance: the distance from a target to the nearest cell or solid within a threshold.
//!
//! It is a collector on the scene's one walk (`collector`, `cell_walk`). The same cell tree that
//! bounds depth per node bounds distance: a node's box is at least as far
//! from the target as the target's bounding box (in the surface's frame) and its bounding ball
//! are, and a subtree whose lower bound is not below the nearest distance found so far (at first
//! the threshold) is pruned. Children are visited nearer bound first, so the first leaves reached
//! usually settle the answer. Each cell (and each solid) that survives its own box bound gets an
//! exact distance from GJK (parry's, in f64, with this crate's hill-climbing support for hulls),
//! which stops as soon as it proves the pair farther apart than the best so far.

use super::cell_tree::CellTree;
use super::cell_walk::{walk, CellVisitor};
use super::collector::Collector;
use super::scene::Scene;
use super::target::{Target, TargetShape};
use super::target_view::TargetView;
use crate::math::{Aabb, Pose, Real, Vector};
use crate::thickness::ThicknessArea;
use parry3d_f64::query::gjk::{GJKResult, VoronoiSimplex};
use parry3d_f64::shape::SupportMap;
use std::ops::ControlFlow;

/// The nearest cell or solid to a target, in the world frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Clearance {
    /// Index of the object in the scene.
    pub object: usize,
    /// Input index of the triangle whose cell is nearest (`u32::MAX` for solids).
    pub triangle: u32,
    /// Distance between the two shapes (metres, at least 0: a query for clearance does not
    /// measure overlap; a colliding target reports its contact instead).
    pub distance: Real,
    /// The nearest point on the target.
    pub point1: Vector,
    /// The nearest point on the object.
    pub point2: Vector,
}

/// A target shape as parry's GJK sees it (hulls climb their own vertex graph).
struct ShapeSupport<'a>(&'a TargetShape);

impl SupportMap for ShapeSupport<'_> {
    fn local_support_point(&self, dir: Vector) -> Vector {
        let unit = |v: Vector| v.try_normalize().unwrap_or(Vector::ZERO);
        match self.0 {
            TargetShape::Polytope(h) => h.support_point(dir),
            TargetShape::Sphere { radius } => unit(dir) * *radius,
            TargetShape::Capsule { half_height, radius } => Vector::new(0.0, 0.0, half_height.copysign(dir.z)) + unit(dir) * *radius,
            TargetShape::Cylinder { half_height, radius } => {
                let xy = unit(Vector::new(dir.x, dir.y, 0.0)) * *radius;
                Vector::new(xy.x, xy.y, half_height.copysign(dir.z))
            }
            TargetShape::Swept { .. } => self.0.support_point(dir),
        }
    }
}

/// A cell's six vertices (caps collapsed to a point repeat it).
struct CellSupport([Vector; 6]);

impl SupportMap for CellSupport {
    fn local_support_point(&self, dir: Vector) -> Vector {
        let mut best = self.0[0];
        let mut d = dir.dot(best);
        for p in &self.0[1..] {
            let x = dir.dot(*p);
            if x > d {
                (best, d) = (*p, x);
            }
        }
        best
    }
}

/// Distance between two boxes given by centre and half extents (0 when they meet).
#[inline]
fn box_box_distance(c1: Vector, h1: Vector, c2: Vector, h2: Vector) -> Real {
    ((c1 - c2).abs() - h1 - h2).max(Vector::ZERO).length()
}

/// A lower bound on the distance from the target (its box `aabb` and its ball `centre`,
/// `radius`, in the surface's frame) to anything inside the box `(c, h)`.
#[inline]
fn lower_bound(aabb: &Aabb, centre: Vector, radius: Real, c: Vector, h: Vector) -> Real {
    let by_box = box_box_distance(aabb.center(), aabb.half_extents(), c, h);
    let by_ball = ((centre - c).abs() - h).max(Vector::ZERO).length() - radius;
    by_box.max(by_ball)
}

/// Exact distance and nearest points (both in frame 1) of two support maps, or `None` when they
/// are farther apart than `max_dist`.
fn gjk_distance<G1: SupportMap, G2: SupportMap>(pos12: &Pose, g1: &G1, g2: &G2, max_dist: Real) -> Option<(Real, Vector, Vector)> {
    let mut simplex = VoronoiSimplex::new();
    match parry3d_f64::query::details::contact_support_map_support_map_with_params(pos12, g1, g2, max_dist, &mut simplex, None) {
        // `n` points from shape 1 to shape 2: the signed distance is the witnesses' gap along it,
        // and an overlap (EPA's answer) counts as touching here (see `Clearance::distance`).
        GJKResult::ClosestPoints(p1, p2, n) => Some(((p2 - p1).dot(n).max(0.0), p1, p2)),
        _ => None,
    }
}

impl Scene {
    /// The nearest cell or solid, among the objects for which `check(object index)` is true, at a
    /// distance of at most `threshold` from the target; `None` when nothing is that close. Meant
    /// for targets that do not collide (a colliding one may report any distance near 0).
    pub fn clearance_filtered(&self, target: &Target, threshold: Real, check: impl Fn(usize) -> bool) -> Option<Clearance> {
        if !(threshold > 0.0) {
            return None;
        }
        self.query(target, &check, Nearest { support: ShapeSupport(&target.shape), best: None, best_dist: threshold }).best
    }
}

/// The collector of a clearance query: the nearest so far, whose distance is the reach.
struct Nearest<'a> {
    support: ShapeSupport<'a>,
    best: Option<Clearance>,
    best_dist: Real,
}

impl Nearest<'_> {
    /// Keeps a distance (and nearest points, in the target's frame) if it is the nearest yet.
    fn offer(&mut self, target: &Target, object: usize, triangle: u32, found: Option<(Real, Vector, Vector)>) {
        if let Some((distance, p1, p2)) = found.filter(|f| f.0 <= self.best_dist) {
            self.best_dist = distance;
            self.best = Some(Clearance { object, triangle, distance, point1: target.pose * p1, point2: target.pose * p2 });
        }
    }
}

impl Collector for Nearest<'_> {
    fn reach(&self) -> Real {
        self.best_dist
    }

    fn solid(&mut self, object: usize, target: &Target, pose: &Pose, shape: &TargetShape) -> ControlFlow<()> {
        let found = gjk_distance(&target.pose.inv_mul(pose), &self.support, &ShapeSupport(shape), self.best_dist);
        self.offer(target, object, u32::MAX, found);
        ControlFlow::Continue(())
    }

    fn surface(&mut self, object: usize, area: &ThicknessArea, tree: &CellTree, view: &TargetView) -> ControlFlow<()> {
        walk(tree, view, &mut NearestCell { nearest: self, object, area })
    }
}

/// The visitor of one surface for [`Nearest`]: keys are the subtrees' distance bounds, negated.
struct NearestCell<'n, 'a> {
    nearest: &'n mut Nearest<'a>,
    object: usize,
    area: &'n ThicknessArea,
}

impl NearestCell<'_, '_> {
    /// The surface-frame bounds, and the gap to the target's own box (tighter for a tilted,
    /// elongated link).
    fn bound(view: &TargetView, (c, h): (Vector, Vector)) -> Real {
        lower_bound(&view.aabb, view.centre, view.radius, c, h).max(view.own_box_gap(c, h))
    }
}

impl CellVisitor for NearestCell<'_, '_> {
    fn root(&mut self, tree: &CellTree, view: &TargetView) -> Option<Real> {
        Some(-Self::bound(view, tree.node_box(0)))
    }

    fn children(&mut self, tree: &CellTree, children: [u32; 2], view: &TargetView) -> [Option<Real>; 2] {
        children.map(|child| Some(-Self::bound(view, tree.node_box(child))))
    }

    fn worth(&self, key: Real) -> bool {
        -key <= self.nearest.best_dist
    }

    fn leaf(&mut self, tree: &CellTree, node: u32, view: &TargetView) -> ControlFlow<()> {
        for (index, slab) in tree.leaf_cells(node) {
            let best_dist = self.nearest.best_dist;
            if Self::bound(view, (slab.centre(), slab.half())) > best_dist {
                continue;
            }
            // The gap along the cell's normal (two support queries) before GJK.
            let [lo, hi] = view.extent_along(slab.normal);
            if (lo - slab.range[1]).max(slab.range[0] - hi) > best_dist {
                continue;
            }
            let cell = &self.area.cells[index as usize];
            let found = gjk_distance(&view.object_in_target, &self.nearest.support, &CellSupport(cell.vertices()), best_dist);
            self.nearest.offer(view.target, self.object, cell.triangle, found);
        }
        ControlFlow::Continue(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Rotation;
    use crate::mesh::{generate, MeshTopology, TopologySettings};
    use crate::thickness::{ThicknessArea, ThicknessSettings};

    /// Against closed-form distances (fixed seed): a sphere, a capsule and a cylinder beside a
    /// box solid (the nearest point on a box face, away from its edges), and a cube above a flat
    /// sheet whose cells lie behind it; nothing reported beyond the threshold.
    #[test]
    fn distances_match_closed_forms() {
        let mut rng = oorandom::Rand64::new(13);
        let mut rf = |lo: Real, hi: Real| lo + (hi - lo) * rng.rand_float();
        let mut scene = Scene::new();
        let _ = scene.add_solid("block", Pose::IDENTITY, TargetShape::cuboid(Vector::new(0.2, 0.2, 0.2)).unwrap());
        let (v, t) = generate::flat_grid(20, 20, 1.0, 1.0);
        let mesh = MeshTopology::build(&v, &t, &TopologySettings::default()).unwrap();
        let area = ThicknessArea::build(&mesh, &ThicknessSettings { thickness: 0.02, ..Default::default() }).unwrap();
        let _ = scene.add_surface("sheet", Pose::from_translation(Vector::new(2.0, 0.0, 0.0)), area);
        for _ in 0..500 {
            let gap = rf(1e-4, 0.08);
            let (y, z) = (rf(-0.1, 0.1), rf(-0.1, 0.1));
            // A sphere of radius r beside the face x = 0.2.
            let r = rf(0.01, 0.05);
            let sphere = Target::new(TargetShape::Sphere { radius: r }, Pose::from_translation(Vector::new(0.2 + gap + r, y, z)));
            // A capsule lying along y (its axis turned from z), beside the face x = 0.2.
            let capsule = Target::new(
                TargetShape::Capsule { half_height: 0.05, radius: r },
                Pose::from_parts(Vector::new(0.2 + gap + r, y * 0.3, z), Rotation::from_rotation_x(std::f64::consts::FRAC_PI_2)),
            );
            // A cylinder standing on the top face z = 0.2.
            let cylinder = Target::new(TargetShape::Cylinder { half_height: 0.03, radius: r }, Pose::from_translation(Vector::new(y, z, 0.2 + gap + 0.03)));
            // A cube above the sheet (whose cells lie behind its plane z = 0).
            let cube = Target::new(TargetShape::cuboid(Vector::splat(0.03)).unwrap(), Pose::from_translation(Vector::new(2.5 + y, 0.5 + z, gap + 0.03)));
            for (what, target, object) in [("sphere", &sphere, 0), ("capsule", &capsule, 0), ("cylinder", &cylinder, 0), ("cube", &cube, 1)] {
                let c = scene.clearance_filtered(target, 0.05, |_| true);
                if gap > 0.05 {
                    assert!(c.is_none(), "{what}: {gap} m away, beyond the threshold: {c:?}");
                    continue;
                }
                let c = c.unwrap_or_else(|| panic!("{what}: {gap} m away, not reported"));
                assert_eq!(c.object, object);
                assert!((c.distance - gap).abs() < 1e-7, "{what}: {} against {gap}", c.distance);
                assert!(((c.point1 - c.point2).length() - gap).abs() < 1e-7, "{what}: points {c:?}");
                assert_eq!(c.triangle == u32::MAX, object == 0);
            }
        }
        assert!(scene.clearance_filtered(&sphere_at(0.21), 0.0, |_| true).is_none(), "a threshold of 0 is off");
        assert!(scene.clearance_filtered(&sphere_at(0.21), 0.05, |_| false).is_none(), "filtered objects are skipped");
    }

    fn sphere_at(x: Real) -> Target {
        Target::new(TargetShape::Sphere { radius: 0.005 }, Pose::from_translation(Vector::new(x, 0.0, 0.0)))
    }
}
