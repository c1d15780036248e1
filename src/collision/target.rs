//! Convex targets: the shapes robot links are checked as.

use crate::math::{Aabb, Pose, Real, Vector};
use parry3d_f64::shape::ConvexPolyhedron;
use std::collections::HashMap;
use std::sync::Arc;

/// One face of a hull: outward unit normal and the hull's extent along it.
#[derive(Clone, Copy, Debug)]
pub(crate) struct HullFace {
    pub normal: Vector,
    /// `max normal . x` over the hull (the face's own plane).
    pub max: Real,
    /// `min normal . x` over the hull.
    pub min: Real,
}

/// One edge of a hull with the outward normals of its two faces (for the Gauss-map test).
#[derive(Clone, Copy, Debug)]
pub(crate) struct HullEdge {
    pub point: Vector,
    pub dir: Vector,
    pub n1: Vector,
    pub n2: Vector,
}

/// A convex polytope in its own frame, with what the separating-axis test needs precomputed.
#[derive(Clone, Debug)]
pub struct ConvexHull {
    pub(crate) points: Vec<Vector>,
    pub(crate) faces: Vec<HullFace>,
    pub(crate) edges: Vec<HullEdge>,
    pub(crate) centroid: Vector,
    pub(crate) aabb: Aabb,
    /// Vertex adjacency (CSR: the neighbours of `i` are `adjacent[first[i]..first[i + 1]]`).
    adjacency_first: Vec<u32>,
    adjacency: Vec<u32>,
    /// The vertex extreme along +x, -x, +y, -y, +z, -z: where hill climbing starts.
    extreme: [u32; 6],
    parry: ConvexPolyhedron,
}

/// Below this many vertices a linear scan beats hill climbing.
const CLIMB_MIN_POINTS: usize = 24;

impl ConvexHull {
    /// The convex hull of `points` (at least 4 points not in one plane), with coplanar faces merged.
    pub fn from_points(points: &[Vector]) -> Option<ConvexHull> {
        if points.len() < 4 || points.iter().any(|p| !p.is_finite()) {
            return None;
        }
        Self::from_parry(ConvexPolyhedron::from_convex_hull(points)?)
    }

    /// An axis-aligned box `[-half, half]`.
    pub fn cuboid(half_extents: Vector) -> Option<ConvexHull> {
        let h = half_extents;
        if !(h.min_element() > 0.0) {
            return None;
        }
        let corners: Vec<Vector> =
            (0..8).map(|i| Vector::new(if i & 1 == 0 { -h.x } else { h.x }, if i & 2 == 0 { -h.y } else { h.y }, if i & 4 == 0 { -h.z } else { h.z })).collect();
        Self::from_points(&corners)
    }

    fn from_parry(parry: ConvexPolyhedron) -> Option<ConvexHull> {
        let points = parry.points().to_vec();
        let (lo, hi) = points.iter().fold((Vector::splat(Real::INFINITY), Vector::splat(Real::NEG_INFINITY)), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
        let centroid = points.iter().copied().sum::<Vector>() / points.len() as Real;
        // Faces and edges from the face polygons (parry merges coplanar triangles). Edge-to-face
        // links are rebuilt here from the polygons rather than taken from parry's `Edge::faces`,
        // which pointed past the face list on a 524-face hull of a Solo12 mesh.
        let adj = parry.vertices_adj_to_face();
        let mut faces: Vec<HullFace> = Vec::with_capacity(parry.faces().len());
        let mut edge_faces: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
        for (fi, f) in parry.faces().iter().enumerate() {
            let verts = &adj[f.first_vertex_or_edge as usize..(f.first_vertex_or_edge + f.num_vertices_or_edges) as usize];
            let on_face = points[*verts.first()? as usize];
            let min = points.iter().map(|p| f.normal.dot(*p)).fold(Real::INFINITY, Real::min);
            faces.push(HullFace { normal: f.normal, max: f.normal.dot(on_face), min });
            for k in 0..verts.len() {
                let (a, b) = (verts[k], verts[(k + 1) % verts.len()]);
                edge_faces.entry((a.min(b), a.max(b))).or_default().push(fi);
            }
        }
        let mut edges = Vec::with_capacity(edge_faces.len());
        let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); points.len()];
        let mut keys: Vec<(u32, u32)> = edge_faces.keys().copied().collect();
        keys.sort_unstable();
        for (a, b) in keys {
            let fs = &edge_faces[&(a, b)];
            if fs.len() != 2 {
                return None; // not a closed polytope
            }
            let (pa, pb) = (points[a as usize], points[b as usize]);
            edges.push(HullEdge { point: pa, dir: (pb - pa).normalize(), n1: faces[fs[0]].normal, n2: faces[fs[1]].normal });
            neighbours[a as usize].push(b);
            neighbours[b as usize].push(a);
        }
        if faces.len() < 4 || !centroid.is_finite() || edges.iter().any(|e| !e.dir.is_finite()) {
            return None;
        }
        let mut adjacency_first = vec![0u32; points.len() + 1];
        let mut adjacency = Vec::new();
        for (i, n) in neighbours.iter().enumerate() {
            adjacency.extend_from_slice(n);
            adjacency_first[i + 1] = adjacency.len() as u32;
        }
        let mut extreme = [0u32; 6];
        for (k, dir) in [Vector::X, -Vector::X, Vector::Y, -Vector::Y, Vector::Z, -Vector::Z].into_iter().enumerate() {
            let best = (0..points.len()).max_by(|&i, &j| dir.dot(points[i]).total_cmp(&dir.dot(points[j])));
            extreme[k] = best.unwrap_or(0) as u32;
        }
        Some(ConvexHull { points, faces, edges, centroid, aabb: Aabb::new(lo, hi), adjacency_first, adjacency, extreme, parry })
    }

    /// The hull grown by `padding` metres: every vertex moved out along the normal of each of its
    /// faces, then hulled again. Every face moves out by exactly `padding`; edges and corners are
    /// bevelled, short of the rounded Minkowski sum by at most `padding * (1 - cos(a/2))` for a
    /// dihedral angle `a` between face normals.
    pub fn padded(&self, padding: Real) -> Option<ConvexHull> {
        if padding == 0.0 {
            return Some(self.clone());
        }
        let adj = self.parry.vertices_adj_to_face();
        let mut pts = Vec::new();
        for f in self.parry.faces() {
            for k in 0..f.num_vertices_or_edges {
                let v = self.points[adj[(f.first_vertex_or_edge + k) as usize] as usize];
                pts.push(v + f.normal * padding);
            }
        }
        Self::from_points(&pts)
    }

    /// The hull's vertices.
    pub fn points(&self) -> &[Vector] {
        &self.points
    }

    /// Number of faces (coplanar triangles merged).
    pub fn face_count(&self) -> usize {
        self.faces.len()
    }

    /// The same hull as a parry shape (for GJK-based queries and as a test oracle).
    pub fn as_parry(&self) -> &ConvexPolyhedron {
        &self.parry
    }

    /// `[min, max]` of `dir . x` over the hull.
    #[inline]
    pub(crate) fn project(&self, dir: Vector) -> [Real; 2] {
        if self.points.len() >= CLIMB_MIN_POINTS {
            return [-self.climb(-dir), self.climb(dir)];
        }
        crate::math::project_points(&self.points, dir)
    }
}

impl ConvexHull {
    /// `max dir . x` by hill climbing over the vertex graph: on a convex polytope a vertex no
    /// neighbour improves on is the global maximum. Starts at the extreme vertex of the closest
    /// coordinate axis; on a ~100-vertex link hull that visits ~5 vertices instead of 100.
    fn climb(&self, dir: Vector) -> Real {
        self.climb_from(dir, u32::MAX).0
    }

    /// Hill climbing from vertex `start` (`u32::MAX`: the extreme vertex of the closest axis);
    /// returns the maximum and the vertex where it is reached, the start for a nearby direction.
    fn climb_from(&self, dir: Vector, start: u32) -> (Real, u32) {
        let mut at = if (start as usize) < self.points.len() {
            start as usize
        } else {
            let a = dir.abs();
            let k = if a.x >= a.y && a.x >= a.z { 0 } else if a.y >= a.z { 2 } else { 4 };
            let k = k + (dir[k / 2] < 0.0) as usize;
            self.extreme[k] as usize
        };
        let mut best = dir.dot(self.points[at]);
        loop {
            let mut moved = false;
            let (s, e) = (self.adjacency_first[at] as usize, self.adjacency_first[at + 1] as usize);
            for &nb in &self.adjacency[s..e] {
                let d = dir.dot(self.points[nb as usize]);
                if d > best {
                    best = d;
                    at = nb as usize;
                    moved = true;
                }
            }
            if !moved {
                return (best, at as u32);
            }
        }
    }
}

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

    /// As [`TargetShape::project`], starting the hill climbs of a hull at the vertices of the
    /// previous call (`hint`, `[u32::MAX; 2]` at first): the cells a query visits have similar
    /// normals, and a warm start takes a climb from ~15 steps to ~2 on a Panda link.
    #[inline]
    pub(crate) fn project_hinted(&self, dir: Vector, hint: &mut [u32; 2]) -> [Real; 2] {
        match self {
            TargetShape::Polytope(h) if h.points.len() >= CLIMB_MIN_POINTS => {
                let (hi, at_hi) = h.climb_from(dir, hint[0]);
                let (lo, at_lo) = h.climb_from(-dir, hint[1]);
                *hint = [at_hi, at_lo];
                [-lo, hi]
            }
            _ => self.project(dir),
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

    /// Calls `f` with the same shape for parry's GJK/EPA queries and its pose in this shape's
    /// frame (parry's cylinders run along `y`). Hulls are lent, not cloned: a clone of a
    /// 100-vertex polyhedron cost more than the query.
    pub fn with_parry<R>(&self, f: impl FnOnce(&dyn parry3d_f64::shape::Shape, &Pose) -> R) -> R {
        use parry3d_f64::shape::{Ball, Capsule, Cylinder};
        match self {
            TargetShape::Polytope(h) => f(h.as_parry(), &Pose::IDENTITY),
            TargetShape::Sphere { radius } => f(&Ball::new(*radius), &Pose::IDENTITY),
            TargetShape::Capsule { half_height, radius } => f(&Capsule::new_z(*half_height, *radius), &Pose::IDENTITY),
            TargetShape::Cylinder { half_height, radius } => f(
                &Cylinder::new(*half_height, *radius),
                &Pose::from_rotation(crate::math::Rotation::from_rotation_x(std::f64::consts::FRAC_PI_2)),
            ),
        }
    }

    /// Whether the shape's sizes are positive and finite.
    pub fn is_valid(&self) -> bool {
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
