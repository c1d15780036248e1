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
    /// A hull swept along a segment: every point of `core` moved by `t · sweep` for every `t` in
    /// `[-1, 1]` (the motion loop's link over a stretch: its translation along the segment, the
    /// rest of its motion in the growth of `core`). Asked only whether it meets the cells, and
    /// answered "yes" whenever the proof-carrying GJK cannot prove it apart (it has no faces
    /// for the SAT); parry sees the ball that holds it.
    Swept {
        /// The hull swept.
        core: Arc<ConvexHull>,
        /// Half the segment, in the shape's frame.
        sweep: Vector,
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
            TargetShape::Swept { core, sweep } => Aabb::new(core.aabb.mins - sweep.abs(), core.aabb.maxs + sweep.abs()),
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
            TargetShape::Swept { core, sweep } => core.extreme(dir) + dir.dot(*sweep).abs(),
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
            TargetShape::Swept { core, sweep } => {
                core.extremes(dirs, out);
                for (d, o) in dirs.iter().zip(out) {
                    *o += d.dot(*sweep).abs();
                }
            }
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
            TargetShape::Swept { core, sweep } => {
                let ([lo, hi], along) = (core.project(dir), dir.dot(*sweep).abs());
                return [lo - along, hi + along];
            }
            TargetShape::Sphere { radius } => dir.length() * radius,
            TargetShape::Capsule { half_height, radius } => (half_height * dir.z).abs() + dir.length() * radius,
            TargetShape::Cylinder { half_height, radius } => (half_height * dir.z).abs() + radius * dir.x.hypot(dir.y),
        };
        [-r, r]
    }

    /// A point inside the shape that names "its centre" (the centroid of a hull, else the origin).
    pub(crate) fn centre(&self) -> Vector {
        match self {
            TargetShape::Polytope(h) | TargetShape::Swept { core: h, .. } => h.centroid,
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
            // Never asked to decide a contact on its own.
            TargetShape::Swept { .. } => false,
        }
    }

    /// The radius of a ball about [`TargetShape::centre`] that holds the shape.
    pub(crate) fn bounding_radius(&self) -> Real {
        match self {
            TargetShape::Polytope(h) => h.radius,
            TargetShape::Sphere { radius } => *radius,
            TargetShape::Capsule { half_height, radius } => half_height + radius,
            TargetShape::Cylinder { half_height, radius } => half_height.hypot(*radius),
            TargetShape::Swept { core, sweep } => core.radius + sweep.length(),
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
            // The ball that holds it: what parry finds against it, it finds against more.
            TargetShape::Swept { core, sweep } => f(&Ball::new(core.radius + sweep.length()), &Pose::from_translation(core.centroid)),
        }
    }

    /// Whether the shape's sizes are positive and finite.
    pub(crate) fn is_valid(&self) -> bool {
        match self {
            TargetShape::Polytope(_) => true,
            TargetShape::Swept { sweep, .. } => sweep.is_finite(),
            TargetShape::Sphere { radius } => *radius > 0.0 && radius.is_finite(),
            TargetShape::Capsule { half_height, radius } | TargetShape::Cylinder { half_height, radius } => {
                *radius > 0.0 && radius.is_finite() && *half_height >= 0.0 && half_height.is_finite()
            }
        }
    }
}

/// The end of the segment from `-sweep` to `sweep` extreme along `dir`: what a swept hull's
/// support point adds to its core's (see [`TargetShape::Swept`]).
#[inline]
pub(crate) fn sweep_end(sweep: Vector, dir: Vector) -> Vector {
    if dir.dot(sweep) < 0.0 {
        -sweep
    } else {
        sweep
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::collision::{CollideSettings, Scene};
    use crate::math::Rotation;
    use crate::mesh::{generate, MeshTopology, TopologySettings};
    use crate::thickness::{Side, ThicknessArea, ThicknessSettings};

    /// A swept hull against a wavy sheet's cells and a box, over random hulls, poses, sweeps and
    /// growths (fixed seed), against the hull itself placed at 201 points along the segment (the
    /// oracle: plain polytope queries): it meets whenever one of them does (never "apart" when
    /// a placement collides), and is "apart" for nearly all sweeps whose placements, grown by
    /// 5 mm more, all stay apart (the GJK on the swept support proves those).
    #[test]
    fn a_swept_hull_meets_whatever_a_placement_along_its_segment_meets() {
        let mut rng = oorandom::Rand64::new(46);
        let mut rf = |lo: Real, hi: Real| lo + (hi - lo) * rng.rand_float();
        let mut scene = Scene::new();
        let (v, t) = generate::wavy_sheet(60, 60, 1.2, 1.2, 0.03, 0.3);
        let mesh = MeshTopology::build(&v, &t, &TopologySettings::default()).unwrap();
        let area = ThicknessArea::build(&mesh, &ThicknessSettings { thickness: 0.02, side: Side::Back, ..Default::default() }).unwrap();
        let _ = scene.add_surface("sheet", Pose::IDENTITY, area);
        let _ = scene.add_solid("box", Pose::from_translation(Vector::new(1.6, 0.6, 0.0)), TargetShape::cuboid(Vector::splat(0.15)).unwrap());
        let flags = CollideSettings { all_contacts: false, flag_only: true, least_overlap: false };
        let (mut met_by_placement, mut clear_by_margin, mut proved_apart) = (0usize, 0usize, 0usize);
        for _ in 0..600 {
            let points: Vec<Vector> = (0..14).map(|_| Vector::new(rf(-0.05, 0.05), rf(-0.04, 0.04), rf(-0.12, 0.12))).collect();
            let core = Arc::new(ConvexHull::from_points(&points).expect("a hull"));
            let pad = rf(0.0005, 0.03);
            let grown = Arc::new(ConvexHull::grown_by_ball(&core, pad).expect("grown"));
            let wider = Arc::new(ConvexHull::grown_by_ball(&core, pad + 0.005).expect("grown"));
            let axis = Vector::new(rf(-1.0, 1.0), rf(-1.0, 1.0), rf(-1.0, 1.0)).normalize_or(Vector::Z);
            let pose = Pose::from_parts(Vector::new(rf(0.0, 1.9), rf(0.0, 1.2), rf(-0.25, 0.25)), Rotation::from_axis_angle(axis, rf(0.0, 3.1)));
            let sweep = Vector::new(rf(-0.08, 0.08), rf(-0.08, 0.08), rf(-0.08, 0.08));
            let swept = Target::new(TargetShape::Swept { core: grown.clone(), sweep }, pose);
            let meets = !scene.collide(&swept, &flags).contacts.is_empty();
            let placed = |hull: &Arc<ConvexHull>, k: usize| {
                let t = -1.0 + 2.0 * k as Real / 200.0;
                let at = Target::new(TargetShape::Polytope(hull.clone()), pose * Pose::from_translation(sweep * t));
                !scene.collide(&at, &flags).contacts.is_empty()
            };
            if (0..=200).any(|k| placed(&grown, k)) {
                met_by_placement += 1;
                assert!(meets, "a placement of the hull along {sweep:?} at {pose:?} (growth {pad}) collides, the swept hull is called apart");
            } else if !(0..=200).any(|k| placed(&wider, k)) {
                clear_by_margin += 1;
                proved_apart += usize::from(!meets);
            }
        }
        assert!(met_by_placement > 100 && clear_by_margin > 100, "{met_by_placement} met, {clear_by_margin} clear by 5 mm");
        assert!(proved_apart * 10 >= clear_by_margin * 9, "{proved_apart} of {clear_by_margin} sweeps clear by 5 mm proved apart");
    }
}
