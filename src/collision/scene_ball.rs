//! A ball's quick verdict against the environment: apart from the boxes around everything it may
//! not touch, or no verdict. The motion loop asks it before a grown link's hull test: a ball around
//! the link, grown by the stretch's bound, that is apart from every box clears the stretch at any
//! growth, at the cost of a few box distances instead of a walk of the cells.

use super::cell_tree::CellTree;
use super::scene::{ObjectBody, Scene};
use crate::math::{Aabb, Real, Vector};

/// Tree nodes a ball may visit before it gives up: past that it is near enough to the cells that
/// the hull test is the better question.
const NODE_BUDGET: usize = 48;

/// The squared distance from `p` to the box of `centre` and half extents `half`.
#[inline]
fn box_distance_squared(p: Vector, centre: Vector, half: Vector) -> Real {
    let d = ((p - centre).abs() - half).max(Vector::ZERO);
    d.dot(d)
}

/// [`box_distance_squared`] to an axis-aligned box given by its corners.
#[inline]
fn aabb_distance_squared(p: Vector, b: &Aabb) -> Real {
    box_distance_squared(p, (b.mins + b.maxs) * 0.5, (b.maxs - b.mins) * 0.5)
}

/// A box (centre and half extents, in an object's frame) found within a ball that was not
/// clear: a cell's box, or a solid's. Kept by the caller, it settles the next ball near it with
/// one box distance instead of a walk (see [`Scene::ball_is_clear`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct BallWitness {
    object: usize,
    centre: Vector,
    half: Vector,
}

/// Whether the ball about `local` (the tree's frame) with squared radius `r2` is apart from the
/// box of every cell of `tree`, walking down the node boxes it meets; `visits` counts the nodes
/// against [`NODE_BUDGET`] (spent: no verdict). A cell box found within the ball goes to
/// `witness`.
fn apart_from_cells(tree: &CellTree, local: Vector, r2: Real, visits: &mut usize, witness: &mut Option<(Vector, Vector)>) -> bool {
    if tree.is_empty() {
        return true;
    }
    // No allocation: each visit pops one node and pushes at most two, so after `k` visits at most
    // `k + 1` wait, and the budget stops the walk at `NODE_BUDGET` visits.
    let mut stack = [0u32; NODE_BUDGET + 2];
    let mut len = 1;
    while len > 0 {
        len -= 1;
        let node = stack[len];
        *visits += 1;
        if *visits > NODE_BUDGET {
            return false;
        }
        let (c, h) = tree.node_box(node);
        if box_distance_squared(local, c, h) > r2 {
            continue;
        }
        match tree.children(node) {
            Some(children) => {
                stack[len..len + 2].copy_from_slice(&children);
                len += 2;
            }
            None => {
                if let Some((_, slab)) = tree.leaf_cells(node).find(|(_, slab)| !(box_distance_squared(local, slab.centre(), slab.half()) > r2)) {
                    *witness = Some((slab.centre(), slab.half()));
                    return false;
                }
            }
        }
    }
    true
}

impl Scene {
    /// Whether the ball of `radius` about `centre` (world) is apart from the box of every cell,
    /// and of every solid, of the objects `check` selects. `false` is no verdict: it may still be
    /// apart from the cells themselves (also when the walk ran out of its budget, or for a NaN).
    pub(crate) fn ball_is_clear(&self, centre: Vector, radius: Real, check: impl Fn(usize) -> bool) -> bool {
        self.ball_is_clear_near(centre, radius, check, &mut None)
    }

    /// [`Scene::ball_is_clear`], first asking `witness` (a box found within an earlier ball of
    /// the same `check`): still within this ball, the answer is no verdict without a walk. A box
    /// found within this ball replaces it.
    pub(crate) fn ball_is_clear_near(&self, centre: Vector, radius: Real, check: impl Fn(usize) -> bool, witness: &mut Option<BallWitness>) -> bool {
        // A NaN coordinate drops out of a box distance (`max` ignores it): no verdict.
        if !(centre.is_finite() && radius >= 0.0) {
            return false;
        }
        let r2 = radius * radius;
        if let Some(w) = witness {
            if let Some(object) = self.objects().get(w.object) {
                if box_distance_squared(object.pose.inverse() * centre, w.centre, w.half) <= r2 {
                    return false;
                }
            }
        }
        let mut visits = 0usize;
        self.objects().iter().enumerate().all(|(oi, object)| {
            if !check(oi) || aabb_distance_squared(centre, &object.world_aabb) > r2 {
                return true;
            }
            let local = object.pose.inverse() * centre;
            let mut found = None;
            let apart = match &*object.body {
                ObjectBody::Solid(shape) => {
                    let b = shape.local_aabb();
                    let apart = aabb_distance_squared(local, &b) > r2;
                    if !apart {
                        found = Some(((b.mins + b.maxs) * 0.5, (b.maxs - b.mins) * 0.5));
                    }
                    apart
                }
                ObjectBody::Surface { tree, .. } => apart_from_cells(tree, local, r2, &mut visits, &mut found),
            };
            if let Some((centre, half)) = found {
                *witness = Some(BallWitness { object: oi, centre, half });
            }
            apart
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::collision::TargetShape;
    use crate::math::Pose;
    use crate::mesh::{generate, MeshTopology, TopologySettings};
    use crate::thickness::{ThicknessArea, ThicknessSettings};

    /// Against closed-form distances (fixed seed): a flat 1 m sheet of 2 cm cells and a 0.4 m
    /// cube. A ball said to be clear is farther than its radius from the sheet's own square (which
    /// its cells hold) and from the cube; balls well apart from both are nearly all said clear;
    /// an object filtered out is ignored; a NaN gives no verdict. A box kept from the last ball
    /// that was not clear gives the same verdicts.
    #[test]
    fn a_clear_ball_is_apart_from_every_cell_and_solid() {
        let mut rng = oorandom::Rand64::new(21);
        let mut rf = |lo: Real, hi: Real| lo + (hi - lo) * rng.rand_float();
        let mut scene = Scene::new();
        let (v, t) = generate::flat_grid(50, 50, 1.0, 1.0);
        let mesh = MeshTopology::build(&v, &t, &TopologySettings::default()).unwrap();
        let area = ThicknessArea::build(&mesh, &ThicknessSettings { thickness: 0.02, ..Default::default() }).unwrap();
        let _ = scene.add_surface("sheet", Pose::IDENTITY, area);
        let _ = scene.add_solid("cube", Pose::from_translation(Vector::new(2.0, 0.5, 0.0)), TargetShape::cuboid(Vector::splat(0.2)).unwrap());
        let (mut apart, mut cleared, mut said_clear) = (0usize, 0usize, 0usize);
        let (mut witness, mut reused) = (None, 0usize);
        for _ in 0..4000 {
            let c = Vector::new(rf(-0.5, 2.5), rf(-0.5, 1.5), rf(-0.6, 0.6));
            let r = rf(0.0, 0.4);
            let sheet = box_distance_squared(c, Vector::new(0.5, 0.5, 0.0), Vector::new(0.5, 0.5, 0.0)).sqrt();
            let cube = box_distance_squared(c, Vector::new(2.0, 0.5, 0.0), Vector::splat(0.2)).sqrt();
            // Every cell lies within 2 cm of the square (its thickness, either side).
            let sheet_cells = box_distance_squared(c, Vector::new(0.5, 0.5, 0.0), Vector::new(0.5, 0.5, 0.02)).sqrt();
            let clear = scene.ball_is_clear(c, r, |_| true);
            // A box kept from an earlier ball changes no verdict, only how it is reached.
            let kept_before = witness;
            assert_eq!(scene.ball_is_clear_near(c, r, |_| true, &mut witness), clear, "ball at {c:?} of radius {r}, kept {kept_before:?}");
            reused += usize::from(!clear && witness == kept_before && kept_before.is_some());
            if clear {
                said_clear += 1;
                assert!(sheet > r && cube > r, "ball at {c:?} of radius {r} said clear: {sheet} m from the sheet, {cube} m from the cube");
            }
            if sheet_cells > r + 0.01 && cube > r + 0.01 {
                apart += 1;
                cleared += clear as usize;
            }
            if cube > r && !clear {
                assert!(!scene.ball_is_clear(c, r, |oi| oi == 0) || sheet > r, "only the sheet asked");
            }
        }
        assert!(said_clear > 500 && cleared * 10 >= apart * 9, "{cleared} of {apart} balls well apart said clear ({said_clear} in all)");
        assert!(reused > 100, "a kept box settled {reused} balls");
        let under_the_cube = Vector::new(2.0, 0.5, 0.0);
        assert!(!scene.ball_is_clear(under_the_cube, 0.01, |_| true));
        assert!(scene.ball_is_clear(under_the_cube, 0.01, |oi| oi == 0), "the cube filtered out");
        assert!(!scene.ball_is_clear(Vector::new(f64::NAN, 0.0, 5.0), 0.1, |_| true));
        assert!(!scene.ball_is_clear(Vector::new(0.5, 0.5, 5.0), f64::NAN, |_| true));
    }
}
