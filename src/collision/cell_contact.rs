//! One target against one cell: the SAT, then what is reported for a colliding pair.

use super::cell_slab::CellSlab;
use super::contact_point::{closest_on_cell, contact_capsule_cell, contact_cylinder_cell, contact_hull_cell};
use super::polytope::CellPolytope;
use super::sat::{sat_capsule_cell, sat_hull_cell, sat_sphere_cell, SatOverlap};
use super::target::{Target, TargetShape};
use super::target_view::TargetView;
use crate::math::{Pose, Real, Rotation, Vector};
use crate::thickness::{Side, ThicknessCell};
use parry3d_f64::math::Matrix;

/// What a colliding target/cell pair reports, in the world frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CellHit {
    /// How far the target reaches past the cell along `normal`: the claim's `Bmax - Amin` on the
    /// push-out axis (metres). For `back` cells `Bmax` is the face plane, so this is how far the
    /// target reaches behind the surface; a link that went right through stays "behind".
    pub depth: Real,
    /// Push-out direction: the face's front normal for `back` cells, its back normal for `front`
    /// cells, and for `both` the side the target's centre is on.
    pub normal: Vector,
    /// Least overlap over the separating-axis candidates (the minimal translation, metres).
    pub overlap: Real,
    /// Unit direction in which the target moves by `overlap` to separate.
    pub axis: Vector,
    /// A point within 1e-6 m of both shapes, at the deepest part of the overlap along `-normal`.
    /// `None` when it was not asked for.
    pub point: Option<Vector>,
}

/// A target and a cell expressed in the target's frame.
pub(crate) struct LocalPair<'a> {
    pub target: &'a Target,
    pub cell: CellPolytope,
}

impl<'a> LocalPair<'a> {
    /// `pos12` is the pose of the cell's object in the target's frame.
    #[inline]
    pub fn new(target: &'a Target, cell: &ThicknessCell, pos12: &Pose) -> Self {
        // A swept hull is tested as the ball that holds it (it has no faces): the cell is seen
        // from that ball's centre.
        let pos12 = match &target.shape {
            TargetShape::Swept { core, .. } => Pose::from_translation(-core.centroid) * *pos12,
            _ => *pos12,
        };
        LocalPair { target, cell: CellPolytope::new(cell, &pos12) }
    }

    /// The SAT; `None` when apart.
    #[inline]
    pub fn sat(&self) -> Option<SatOverlap> {
        self.sat_or_axis().ok()
    }

    /// The SAT; when apart, the axis that separates the pair (target frame; hulls only), for
    /// neighbouring cells to try first.
    #[inline]
    pub fn sat_or_axis(&self) -> Result<SatOverlap, Option<Vector>> {
        match &self.target.shape {
            TargetShape::Polytope(h) => sat_hull_cell(h, &self.cell),
            TargetShape::Sphere { radius } => sat_sphere_cell(*radius, &self.cell).ok_or(None),
            TargetShape::Capsule { half_height, radius } => sat_capsule_cell(*half_height, *radius, &self.cell).ok_or(None),
            TargetShape::Cylinder { half_height, radius } => sat_cylinder_cell(*half_height, *radius, &self.cell).ok_or(None),
            TargetShape::Swept { .. } => sat_sphere_cell(self.target.shape.bounding_radius(), &self.cell).ok_or(None),
        }
    }

    /// A point of the overlap, deepest along `-push` (target frame).
    pub fn point(&self, push: Vector) -> Option<Vector> {
        match &self.target.shape {
            TargetShape::Polytope(h) => {
                let scale = h.aabb.extents().max_element().max(1e-3);
                contact_hull_cell(h, &self.cell, push, 1e-12 * scale)
            }
            TargetShape::Sphere { .. } => Some(closest_on_cell(&self.cell, Vector::ZERO)),
            TargetShape::Capsule { half_height, .. } => {
                Some(contact_capsule_cell(&self.cell, Vector::new(0.0, 0.0, -half_height), Vector::new(0.0, 0.0, *half_height), push))
            }
            TargetShape::Cylinder { half_height, radius } => {
                // EPA's witness lies on the cylinder but not always in the cell: refine it.
                let start = cylinder_contact(*half_height, *radius, &self.cell)?.point1;
                Some(contact_cylinder_cell(&self.cell, *half_height, *radius, start, 1e-10))
            }
            TargetShape::Swept { .. } => None,
        }
    }
}

/// The SAT on the cell's own normal, first and alone because it is cheap (no cell transform) and
/// separates most candidates beside a surface. `None` when it separates; else the push-out normal
/// (target frame) and the depth the pair reports if it collides: the claim's `Bmax - Amin` on that
/// axis. `pos12` is the pose of the cell's object in the target's frame.
#[inline]
pub(crate) fn normal_axis(target: &Target, cell: &CellSlab, side: Side, pos12: &Pose) -> Option<(Vector, Real)> {
    normal_axis_deeper(target, cell, side, &Matrix::from_quat(pos12.rotation), pos12.translation, Real::NEG_INFINITY)
}

/// [`normal_axis`] for a search that only wants pairs deeper than `floor`: the end of the target
/// that gives the depth is projected first, and a cell that cannot beat `floor` costs one hill
/// climb instead of two. `rotation` and `translation` make the pose of the cell's object in the
/// target's frame (a matrix: rotating many normals by one quaternion costs more).
#[inline]
pub(crate) fn normal_axis_deeper(target: &Target, cell: &CellSlab, side: Side, rotation: &Matrix, translation: Vector, floor: Real) -> Option<(Vector, Real)> {
    let axis = NormalAxis::new(target, cell, side, rotation, translation);
    axis.finish(target, target.shape.support(axis.first_query()), floor)
}

/// [`normal_axis_deeper`] in two steps, so that a leaf's support queries can be made together
/// (see [`TargetShape::support_many`](super::target::TargetShape::support_many)): the cell's
/// normal in the target's frame, its range on it, and which end of the target gives the depth.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct NormalAxis {
    n: Vector,
    b_min: Real,
    b_max: Real,
    /// The target is pushed out along `n` (else along `-n`).
    front: bool,
}

impl NormalAxis {
    #[inline]
    pub fn new(target: &Target, cell: &CellSlab, side: Side, rotation: &Matrix, translation: Vector) -> NormalAxis {
        let n = *rotation * cell.normal;
        let shift = n.dot(translation);
        let [b_min, b_max] = cell.range.map(|x| x + shift);
        let front = match side {
            Side::Back => true,
            Side::Front => false,
            Side::Both => n.dot(target.shape.centre()) >= cell.plane_offset + shift,
        };
        NormalAxis { n, b_min, b_max, front }
    }

    /// The direction whose support gives the depth.
    #[inline]
    pub fn first_query(&self) -> Vector {
        if self.front {
            -self.n
        } else {
            self.n
        }
    }

    /// The verdict on this axis from the support along [`NormalAxis::first_query`]; the other
    /// end is asked only of a pair deeper than `floor`.
    #[inline]
    pub fn finish(&self, target: &Target, first: Real, floor: Real) -> Option<(Vector, Real)> {
        let (n, b_min, b_max) = (self.n, self.b_min, self.b_max);
        // Apart on this axis when `a_max <= b_min` or `b_max <= a_min` (touching is apart); the
        // negated comparisons also turn a NaN into "apart".
        if self.front {
            let depth = b_max + first;
            if !(depth > 0.0 && depth > floor) {
                return None;
            }
            let a_max = target.shape.support(n);
            (a_max > b_min).then_some((n, depth))
        } else {
            let depth = first - b_min;
            if !(depth > 0.0 && depth > floor) {
                return None;
            }
            let a_min = -target.shape.support(-n);
            (b_max > a_min).then_some((-n, depth))
        }
    }
}

/// Axes that separated cells near the ones a query is deciding, with the target's extent along
/// each: next to each other, cells are mostly separated by one of a few axes (the faces of the
/// link's side), and with the extent kept a cell is tested against an axis with two dot products.
/// Everything in the surface's frame.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct RecentAxes {
    /// `(axis, [min, max] of axis . x over the target)`.
    axes: [(Vector, [Real; 2]); 4],
    len: usize,
    next: usize,
}

impl RecentAxes {
    /// Keeps `axis` (surface frame, not zero) along which the target spans `range`.
    pub fn remember(&mut self, axis: Vector, range: [Real; 2]) {
        if self.axes[..self.len].iter().any(|(a, _)| *a == axis) {
            return;
        }
        self.axes[self.next] = (axis, range);
        self.len = (self.len + 1).min(self.axes.len());
        self.next = (self.next + 1) % self.axes.len();
    }

    /// Whether one of the axes separates the target from the box (centre, half extents).
    #[inline]
    pub fn separate_box(&self, centre: Vector, half: Vector) -> bool {
        self.axes[..self.len].iter().any(|(a, [lo, hi])| {
            let c = a.dot(centre);
            let r = a.abs().dot(half);
            c + r <= *lo || c - r >= *hi
        })
    }

    /// Whether one of the axes separates the target from the points.
    #[inline]
    fn separate_points(&self, points: &[Vector]) -> bool {
        self.axes[..self.len].iter().any(|(a, [lo, hi])| {
            let [b_min, b_max] = crate::math::project_points(points, *a);
            !(hi - b_min > 0.0 && b_max - lo > 0.0)
        })
    }
}

/// Decides a target/cell pair without the full SAT where that is cheap: `Some(false)` when one of
/// the `recent` axes or the line between the two centroids separates the pair (that line is then
/// remembered), `Some(true)` when the cell's centroid lies strictly inside the target (then the
/// interiors meet, and the exact SAT would find overlap on every axis), `None` when only the full
/// test can tell. For hulls only the `recent` axes are tried: the GJK that follows (see
/// `scene::decide`) settles the rest for a few support queries, where the centroid test alone
/// could read all of a hull's 300 faces (measured 2 % faster on the Panda benchmark without them).
///
/// A link pushed through a surface meets thousands of cells; most of those the search must
/// decide are either beside the link (one of a few axes separates them) or wholly inside it, and
/// the full SAT (hundreds of face and edge axes on a mesh hull) would only confirm that.
#[inline]
pub(crate) fn quick_decide(view: &TargetView, cell: &ThicknessCell, recent: &mut RecentAxes) -> Option<bool> {
    let verts = cell.vertices();
    if recent.separate_points(&verts) {
        return Some(false);
    }
    if matches!(view.target.shape, TargetShape::Polytope(_) | TargetShape::Swept { .. }) {
        return None;
    }
    let centroid = verts.iter().copied().sum::<Vector>() / 6.0;
    let between = centroid - view.centre;
    if between.length_squared() > 0.0 {
        let range = view.extent_along(between);
        let [b_min, b_max] = crate::math::project_points(&verts, between);
        if !(range[1] - b_min > 0.0 && b_max - range[0] > 0.0) {
            recent.remember(between, range);
            return Some(false);
        }
    }
    if view.target.shape.contains_strictly(view.object_in_target * centroid, INSIDE_MARGIN) && cell.contains_point(centroid, -INSIDE_MARGIN) {
        return Some(true);
    }
    None
}

/// How far inside both shapes (metres) a point must be to decide a pair without the SAT.
const INSIDE_MARGIN: Real = 1e-9;

/// Checks one target against one cell of an object posed at `object_pose`, for a thin surface of
/// the given `side`. With `want_point` the contact point is computed (clipping, the costly part).
///
/// ```
/// use thickness_collision::collision::{collide_target_cell, Target, TargetShape};
/// use thickness_collision::math::{Pose, Vector};
/// use thickness_collision::mesh::{MeshTopology, TopologySettings};
/// use thickness_collision::thickness::{Side, ThicknessArea, ThicknessSettings};
/// let v = [Vector::new(-1., -1., 0.), Vector::new(1., -1., 0.), Vector::new(0., 1., 0.)];
/// let mesh = MeshTopology::build(&v, &[[0, 1, 2]], &TopologySettings::default()).unwrap();
/// let area = ThicknessArea::build(&mesh, &ThicknessSettings { thickness: 0.02, ..Default::default() }).unwrap();
/// // A 1 cm ball whose centre is 5 mm behind the face: 15 mm past the face plane.
/// let ball = Target::new(TargetShape::Sphere { radius: 0.01 }, Pose::from_translation(Vector::new(0., 0., -0.005)));
/// let hit = collide_target_cell(&ball, &area.cells[0], Side::Back, &Pose::IDENTITY, true).unwrap();
/// assert!((hit.depth - 0.015).abs() < 1e-12 && hit.normal.z == 1.0);
/// // The same ball 2 mm in front of the face does not collide.
/// let ball = Target::new(TargetShape::Sphere { radius: 0.01 }, Pose::from_translation(Vector::new(0., 0., 0.012)));
/// assert!(collide_target_cell(&ball, &area.cells[0], Side::Back, &Pose::IDENTITY, false).is_none());
/// ```
pub fn collide_target_cell(target: &Target, cell: &ThicknessCell, side: Side, object_pose: &Pose, want_point: bool) -> Option<CellHit> {
    let pos12 = target.pose.inv_mul(object_pose);
    let (push, depth) = normal_axis(target, &CellSlab::of(cell), side, &pos12)?;
    let pair = LocalPair::new(target, cell, &pos12);
    let sat = pair.sat()?;
    let rot = target.pose.rotation;
    let point = if want_point { pair.point(push).map(|p| target.pose * p) } else { None };
    Some(CellHit { depth, normal: rot * push, overlap: sat.overlap, axis: rot * sat.axis, point })
}

/// The parry cylinder runs along `y`; URDF's (and ours) along `z`.
fn cylinder_pose() -> Pose {
    Pose::from_rotation(Rotation::from_rotation_x(std::f64::consts::FRAC_PI_2))
}

fn cell_as_parry(cell: &CellPolytope) -> Option<parry3d_f64::shape::ConvexPolyhedron> {
    parry3d_f64::shape::ConvexPolyhedron::from_convex_hull(&cell.distinct_vertices())
}

fn cylinder_contact(half_height: Real, radius: Real, cell: &CellPolytope) -> Option<parry3d_f64::query::Contact> {
    let poly = cell_as_parry(cell)?;
    let cyl = parry3d_f64::shape::Cylinder::new(half_height, radius);
    parry3d_f64::query::contact(&cylinder_pose(), &cyl, &Pose::IDENTITY, &poly, 0.0).ok().flatten()
}

/// Cylinders have no finite exact axis set: GJK decides, EPA gives the least overlap.
fn sat_cylinder_cell(half_height: Real, radius: Real, cell: &CellPolytope) -> Option<SatOverlap> {
    let c = cylinder_contact(half_height, radius, cell)?;
    if !(c.dist < 0.0) {
        return None;
    }
    // normal1 points out of the cylinder towards the cell: the cylinder backs off along -normal1.
    Some(SatOverlap { overlap: -c.dist, axis: -c.normal1 })
}
