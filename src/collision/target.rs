//! Convex targets: the shapes robot links are checked as.

use super::convex_hull::ConvexHull;
use crate::math::{Aabb, Pose, Real, Vector};
use std::sync::Arc;

/// The shape of a target, in the target's own frame. Capsules and cylinders run along local `z`
/// and are centred at the origin, as in URDF.
#[derive(Clone, Debug)]
pub enum TargetShape {
    /// A convex polytope (a box, or the convex hull of a link mesh).
    Polytope(Arc<ConvexHull>),
    /// A ball centred at the origin.
    Sphere {
        /// Radius (metres).
        radius: Real,
    },
    /// A capsule from `(0, 0, -half_height)` to `(0, 0, half_height)`.
    Capsule {
        /// Half the length of the segment (metres).
        half_height: Real,
        /// Radius (metres).
        radius: Real,
    },
    /// A cylinder along `z`, from `-half_height` to `half_height`.
    Cylinder {
        /// Half the length (metres).
        half_height: Real,
        /// Radius (metres).
        radius: Real,
    },
}

impl TargetShape {
    /// A box with the given half extents (metres); `None` unless all are positive.
    pub fn cuboid(half_extents: Vector) -> Option<TargetShape> {
        Some(TargetShape::Polytope(Arc::new(ConvexHull::cuboid(half_extents)?)))
    }

    /// Bounding box in the shape's frame.
    pub fn local_aabb(&self) -> Aabb {
        match self {
            TargetShape::Polytope(h) => h.aabb,
            TargetShape::Sphere { radius } => Aabb::new(Vector::splat(-radius), Vector::splat(*radius)),
            TargetShape::Capsule { half_height, radius } | TargetShape::Cylinder { half_height, radius } => {
                let extra = if matches!(self, TargetShape::Capsule { .. }) { *radius } else { 0.0 };
                let h = Vector::new(*radius, *radius, half_height + extra);
                Aabb::new(-h, h)
            }
        }
    }

    /// `max dir . x` over the shape (in its frame).
    #[inline]
    pub(crate) fn support(&self, dir: Vector) -> Real {
        match self {
            TargetShape::Polytope(h) => h.extreme(dir),
            _ => self.project(dir)[1],
        }
    }

    /// `max dir . x` for each of `dirs` (at most [`MANY`]) into `out`. For a hull, the run's
    /// cube-map reads are issued together: one by one, each query waited on its bin (at 1M cells
    /// the map falls out of the nearest caches between queries).
    #[inline]
    pub(crate) fn support_many(&self, dirs: &[Vector], out: &mut [Real]) {
        match self {
            TargetShape::Polytope(h) => h.extremes(dirs, out),
            _ => {
                for (d, o) in dirs.iter().zip(out) {
                    *o = self.support(*d);
                }
            }
        }
    }

    /// `[min, max]` of `dir . x` over the shape (in its frame).
    #[inline]
    pub(crate) fn project(&self, dir: Vector) -> [Real; 2] {
        let r = match self {
            TargetShape::Polytope(h) => return h.project(dir),
            TargetShape::Sphere { radius } => dir.length() * radius,
            TargetShape::Capsule { half_height, radius } => (half_height * dir.z).abs() + dir.length() * radius,
            TargetShape::Cylinder { half_height, radius } => (half_height * dir.z).abs() + radius * dir.x.hypot(dir.y),
        };
        [-r, r]
    }

    /// A point inside the shape that names "its centre" (the centroid of a hull, else the origin).
    pub(crate) fn centre(&self) -> Vector {
        match self {
            TargetShape::Polytope(h) => h.centroid,
            _ => Vector::ZERO,
        }
    }

    /// Whether `p` (in the shape's frame) lies inside the shape, at least `margin` from its boundary.
    pub(crate) fn contains_strictly(&self, p: Vector, margin: Real) -> bool {
        match self {
            TargetShape::Polytope(h) => h.aabb.mins.cmplt(p).all() && p.cmplt(h.aabb.maxs).all() && h.faces.iter().all(|f| f.normal.dot(p) < f.max - margin),
            TargetShape::Sphere { radius } => p.length() < radius - margin,
            TargetShape::Capsule { half_height, radius } => {
                let z = p.z.clamp(-half_height, *half_height);
                (p - Vector::new(0.0, 0.0, z)).length() < radius - margin
            }
            TargetShape::Cylinder { half_height, radius } => p.z.abs() < half_height - margin && p.x.hypot(p.y) < radius - margin,
        }
    }

    /// The radius of a ball about [`TargetShape::centre`] that holds the shape.
    pub(crate) fn bounding_radius(&self) -> Real {
        match self {
            TargetShape::Polytope(h) => h.radius,
            TargetShape::Sphere { radius } => *radius,
            TargetShape::Capsule { half_height, radius } => half_height + radius,
            TargetShape::Cylinder { half_height, radius } => half_height.hypot(*radius),
        }
    }

    /// Calls `f` with the same shape for parry's GJK/EPA queries and its pose in this shape's
    /// frame (parry's cylinders run along `y`). Hulls are lent, not cloned: a clone of a
    /// 100-vertex polyhedron cost more than the query.
    pub(crate) fn with_parry<R>(&self, f: impl FnOnce(&dyn parry3d_f64::shape::Shape, &Pose) -> R) -> R {
        use parry3d_f64::shape::{Ball, Capsule, Cylinder};
        match self {
            TargetShape::Polytope(h) => f(h.as_parry(), &Pose::IDENTITY),
            TargetShape::Sphere { radius } => f(&Ball::new(*radius), &Pose::IDENTITY),
            TargetShape::Capsule { half_height, radius } => f(&Capsule::new_z(*half_height, *radius), &Pose::IDENTITY),
            TargetShape::Cylinder { half_height, radius } => {
                f(&Cylinder::new(*half_height, *radius), &Pose::from_rotation(crate::math::Rotation::from_rotation_x(std::f64::consts::FRAC_PI_2)))
            }
        }
    }

    /// Whether the shape's sizes are positive and finite.
    pub(crate) fn is_valid(&self) -> bool {
        match self {
            TargetShape::Polytope(_) => true,
            TargetShape::Sphere { radius } => *radius > 0.0 && radius.is_finite(),
            TargetShape::Capsule { half_height, radius } | TargetShape::Cylinder { half_height, radius } => {
                *radius > 0.0 && radius.is_finite() && *half_height >= 0.0 && half_height.is_finite()
            }
        }
    }
}

/// A posed convex shape: a robot link (or part of one) in the world.
#[derive(Clone, Debug)]
pub struct Target {
    /// The shape in its own frame.
    pub shape: TargetShape,
    /// The pose of the shape's frame in the world.
    pub pose: Pose,
}

impl Target {
    /// A target.
    pub fn new(shape: TargetShape, pose: Pose) -> Target {
        Target { shape, pose }
    }

    /// Bounding box of the target seen from a frame in which the target has pose `pos`: exact for
    /// every shape (hulls by their support along the three axes), because a loose box around a
    /// tilted link hands the SAT hundreds of cells that a tight one does not.
    pub fn aabb_in(&self, pos: &Pose) -> Aabb {
        let inv = pos.rotation.inverse();
        let mut lo = Vector::ZERO;
        let mut hi = Vector::ZERO;
        for (k, axis) in [Vector::X, Vector::Y, Vector::Z].into_iter().enumerate() {
            let [a, b] = self.shape.project(inv * axis);
            lo[k] = a;
            hi[k] = b;
        }
        Aabb::new(lo + pos.translation, hi + pos.translation)
    }
}
