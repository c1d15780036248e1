//! A target seen from a surface's frame: what the tree's node and cell tests need.

use super::target::Target;
use crate::math::{Aabb, Pose, Real, Vector};
use crate::thickness::Side;
use parry3d_f64::math::Matrix;

/// A target seen from a surface's frame, with what the node tests need.
pub(crate) struct TargetView<'a> {
    pub target: &'a Target,
    /// The pose of the surface's frame in the target's frame.
    pub object_in_target: Pose,
    /// The target's bounding box in the surface's frame.
    pub aabb: Aabb,
    /// The target's bounding box in its own frame, and the rotation part of `object_in_target`
    /// as a matrix and with its entries made positive: a node's box seen from the target.
    pub(crate) local_aabb: Aabb,
    pub rotation: Matrix,
    pub(crate) rotation_abs: Matrix,
    /// The target's centre in the surface's frame.
    pub centre: Vector,
    /// Radius of a ball about `centre` that holds the target.
    pub(crate) radius: Real,
    pub(crate) side: Side,
}

impl<'a> TargetView<'a> {
    /// `world_aabb` is the target's exact box in the world.
    pub fn new(target: &'a Target, object_pose: &Pose, side: Side, world_aabb: &Aabb) -> Self {
        let target_in_object = object_pose.inv_mul(&target.pose);
        let object_in_target = target_in_object.inverse();
        let rotation = Matrix::from_quat(object_in_target.rotation);
        // Walls, shelves and tables usually stand square to the world: then the world box, turned
        // into the surface's frame, is the exact box there too (to rounding), and the six support
        // queries of an exact box are saved.
        let square = Matrix::from_quat(object_pose.rotation).abs();
        let aabb = if [square.row(0), square.row(1), square.row(2)].iter().all(|r| r.max_element() > 1.0 - 1e-12 && r.element_sum() < 1.0 + 1e-9) {
            transformed_box(world_aabb, &object_pose.inverse())
        } else {
            target.aabb_in(&target_in_object)
        };
        TargetView {
            target,
            object_in_target,
            local_aabb: target.shape.local_aabb(),
            rotation,
            rotation_abs: rotation.abs(),
            aabb,
            centre: target_in_object * target.shape.centre(),
            radius: target.shape.bounding_radius(),
            side,
        }
    }

    /// Whether a box of the surface's frame (centre, half extents), seen from the target's frame,
    /// meets the target's own bounding box (touching counts; a NaN does not).
    // Always inlined: out of line, its call cost a tenth of the deepest search (callgrind,
    // peer_compare).
    #[inline(always)]
    pub fn meets_own_box(&self, centre: Vector, half: Vector) -> bool {
        let c = self.rotation * centre + self.object_in_target.translation;
        let h = self.rotation_abs * half;
        let b = &self.local_aabb;
        (c - h).cmple(b.maxs).all() && b.mins.cmple(c + h).all()
    }

    /// A lower bound on the distance from the target to anything in a box of the surface's frame
    /// (centre, half extents): the gap between that box, seen from the target's frame, and the
    /// target's own bounding box (0 when they meet).
    #[inline]
    pub fn own_box_gap(&self, centre: Vector, half: Vector) -> Real {
        let c = self.rotation * centre + self.object_in_target.translation;
        let h = self.rotation_abs * half;
        let b = &self.local_aabb;
        let gap = (b.mins - (c + h)).max(c - h - b.maxs).max(Vector::ZERO);
        gap.length()
    }

    /// `[min, max]` of `dir . x` over the target where the surface's side makes it a depth (the
    /// minimum for `back`, the maximum for `front`, both for `both`), and the other end from the
    /// target's own box (outside the exact extent): one support query where two were.
    #[inline]
    pub fn depth_extent_along(&self, dir: Vector) -> [Real; 2] {
        let (d, query) = self.depth_query(dir);
        self.depth_extent_from(d, query.map_or(0.0, |q| self.target.shape.support(q)))
    }

    /// `dir` in the target's frame, and the one support query [`TargetView::depth_extent_along`]
    /// makes: along it negated for `back` (its support gives the minimum), along it for `front`,
    /// none for `both` (both ends are queried in [`TargetView::depth_extent_from`]).
    #[inline]
    pub fn depth_query(&self, dir: Vector) -> (Vector, Option<Vector>) {
        let d = self.rotation * dir;
        let query = match self.side {
            Side::Back => Some(-d),
            Side::Front => Some(d),
            Side::Both => None,
        };
        (d, query)
    }

    /// [`TargetView::depth_extent_along`] for `d`, the direction already in the target's frame,
    /// given the support along [`TargetView::depth_query`] (unused for `both`, which queries
    /// both ends here).
    #[inline]
    pub fn depth_extent_from(&self, d: Vector, support: Real) -> [Real; 2] {
        let shift = d.dot(self.object_in_target.translation);
        let b = &self.local_aabb;
        let c = d.dot((b.mins + b.maxs) * 0.5);
        let r = d.abs().dot((b.maxs - b.mins) * 0.5);
        match self.side {
            Side::Back => [-support - shift, c + r - shift],
            Side::Front => [c - r - shift, support - shift],
            Side::Both => self.target.shape.project(d).map(|x| x - shift),
        }
    }

    /// `[min, max]` of `dir . x` over the target, for a direction in the surface's frame.
    #[inline]
    pub fn extent_along(&self, dir: Vector) -> [Real; 2] {
        let d = self.rotation * dir;
        let shift = d.dot(self.object_in_target.translation);
        self.target.shape.project(d).map(|x| x - shift)
    }
}

/// The box around a box of another frame (`pose` maps that frame into this one).
pub(crate) fn transformed_box(local: &Aabb, pose: &Pose) -> Aabb {
    let c = *pose * local.center();
    let h = local.half_extents();
    let m = Matrix::from_quat(pose.rotation).abs();
    let e = Vector::new(m.row(0).dot(h), m.row(1).dot(h), m.row(2).dot(h));
    Aabb::new(c - e, c + e)
}
