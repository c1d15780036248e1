//! Convex polytopes as the checks read them: faces and edges for the separating-axis test, and
//! support queries by hill climbing from a cube map of start vertices.

use crate::math::{Aabb, Real, Vector};
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
    /// `n2 x n1`: the normal of the edge's arc on the Gauss map.
    pub arc: Vector,
}

/// A convex polytope in its own frame, with what the separating-axis test needs precomputed.
#[derive(Clone, Debug)]
pub struct ConvexHull {
    pub(crate) points: Vec<Vector>,
    pub(crate) faces: Vec<HullFace>,
    pub(crate) edges: Vec<HullEdge>,
    pub(crate) centroid: Vector,
    /// `max |x - centroid|` over the vertices.
    pub(crate) radius: Real,
    pub(crate) aabb: Aabb,
    /// The vertices that share a face with each vertex (CSR: those of `i` are
    /// `adjacent[first[i]..first[i + 1]]`).
    adjacency_first: Vec<u32>,
    adjacency: Vec<u32>,
    /// For each bin of a cube map over directions (see `start_bin`): the vertex extreme along
    /// every direction of the bin, flagged with `EXACT`, when one vertex is (then no climb is
    /// needed); else the vertex extreme along the bin's centre, where climbing starts. 16 bits,
    /// for half the cache footprint of 32 (the map is read at random); a hull of `2^15` vertices
    /// or more has no map and climbs from vertex 0.
    starts: Vec<u16>,
    parry: ConvexPolyhedron,
    /// For a hull grown by a ball ([`ConvexHull::grown_by_ball`]): the hull it grew from and the
    /// radius. Its extremes are that hull's plus the ball's (a Minkowski sum's support is the sum
    /// of the supports), read from the smaller hull's cube map: one map per part stays in cache,
    /// where each growth's own map (49 kB, a motion tests a part at a dozen growths) missed it.
    grown: Option<(Arc<ConvexHull>, Real)>,
}

/// Below this many vertices a linear scan beats hill climbing.
const CLIMB_MIN_POINTS: usize = 24;

/// The most directions [`TargetShape::support_many`](super::target::TargetShape::support_many) takes at once (a leaf's cells: `LEAF_CELLS`
/// in `cell_tree`).
pub(crate) const MANY: usize = 32;

/// Bins per side of each face of the cube map of climb starts.
const START_BINS: usize = 64;

/// Flags a cube-map bin whose every direction has the same extreme vertex.
const EXACT: u16 = 1 << 15;

/// The cube-map bin of a direction: the face of its largest coordinate, then the two others
/// divided by it, binned.
#[inline]
fn start_bin(dir: Vector) -> usize {
    let a = dir.abs();
    let (k, u, v) = if a.x >= a.y && a.x >= a.z {
        (0, dir.y, dir.z)
    } else if a.y >= a.z {
        (1, dir.z, dir.x)
    } else {
        (2, dir.x, dir.y)
    };
    let face = 2 * k + (dir[k] < 0.0) as usize;
    let half = 0.5 * START_BINS as Real;
    let scale = half / a[k];
    // `t * scale` lies in [-half, half]; a NaN direction lands in bin 0 (the cast saturates).
    let cell = |t: Real| ((t * scale + half) as usize).min(START_BINS - 1);
    (face * START_BINS + cell(u)) * START_BINS + cell(v)
}

/// The direction through point `(u, v)` (each in `[-1, 1]`) of a cube-map face (not normalised).
fn cube_direction(face: usize, u: Real, v: Real) -> Vector {
    let s = if face.is_multiple_of(2) { 1.0 } else { -1.0 };
    match face / 2 {
        0 => Vector::new(s, u, v),
        1 => Vector::new(v, s, u),
        _ => Vector::new(u, v, s),
    }
}

/// The cube map of [`ConvexHull::starts`], for a hull whose map is still empty. A bin's directions
/// are the positive combinations of its four corner directions, and the directions along which a
/// vertex is extreme form a convex cone: when one vertex is the unique extreme at all four
/// corners, it is at every direction of the bin.
fn support_cube_map(hull: &ConvexHull) -> Vec<u16> {
    let n = START_BINS;
    let grid = |i: usize| i as Real / n as Real * 2.0 - 1.0;
    // The extreme vertex along `dir`, climbing from the last one, and whether it is unique (by
    // more than rounding): the maximisers of a convex polytope form a face, so a tie would show
    // at a neighbour.
    let mut at = 0usize;
    let mut extreme = |dir: Vector| {
        let (best, end) = hull.climb_from(dir, at);
        at = end;
        let margin = 1e-12 * (1.0 + best.abs());
        let unique = hull.neighbours(at).iter().all(|&nb| dir.dot(hull.points[nb as usize]) < best - margin);
        (at as u16, unique)
    };
    let mut starts = Vec::with_capacity(6 * n * n);
    for face in 0..6 {
        let corners: Vec<(u16, bool)> =
            (0..=n).flat_map(|i| (0..=n).map(move |j| (i, j))).map(|(i, j)| extreme(cube_direction(face, grid(i), grid(j)))).collect();
        for i in 0..n {
            for j in 0..n {
                let c = [corners[i * (n + 1) + j], corners[i * (n + 1) + j + 1], corners[(i + 1) * (n + 1) + j], corners[(i + 1) * (n + 1) + j + 1]];
                let exact = c.iter().all(|&(v, unique)| unique && v == c[0].0);
                let centre = (grid(i) + grid(i + 1)) * 0.5;
                starts.push(if exact { c[0].0 | EXACT } else { extreme(cube_direction(face, centre, (grid(j) + grid(j + 1)) * 0.5)).0 });
            }
        }
    }
    starts
}

/// The corners of the box `[-h, h]`: corner `i` has x, y, z positive where bits 0, 1, 2 of `i`
/// are set.
fn cube_corners(h: Vector) -> [Vector; 8] {
    std::array::from_fn(|i| Vector::new(if i & 1 == 0 { -h.x } else { h.x }, if i & 2 == 0 { -h.y } else { h.y }, if i & 4 == 0 { -h.z } else { h.z }))
}

impl ConvexHull {
    /// The convex hull of `points` (at least 4 points not in one plane), with coplanar faces merged.
    pub fn from_points(points: &[Vector]) -> Option<ConvexHull> {
        Self::hull_of(points, true)
    }

    /// [`ConvexHull::from_points`], with the cube map of climb starts or without it.
    fn hull_of(points: &[Vector], cube_map: bool) -> Option<ConvexHull> {
        if points.len() < 4 || points.iter().any(|p| !p.is_finite()) {
            return None;
        }
        Self::from_parry(ConvexPolyhedron::from_convex_hull(points)?, cube_map)
    }

    /// An axis-aligned box `[-half, half]`. Its faces are given, not found: parry's hull
    /// algorithm refuses boxes flatter than about 1:1000 (a 100 m x 100 m x 1 cm plate).
    pub fn cuboid(half_extents: Vector) -> Option<ConvexHull> {
        let h = half_extents;
        if !(h.min_element() > 0.0) || !h.is_finite() {
            return None;
        }
        let corners = cube_corners(h).to_vec();
        const FACES: [[u32; 3]; 12] =
            [[0, 4, 6], [0, 6, 2], [1, 3, 7], [1, 7, 5], [0, 1, 5], [0, 5, 4], [2, 6, 7], [2, 7, 3], [0, 2, 3], [0, 3, 1], [4, 5, 7], [4, 7, 6]];
        Self::from_parry(ConvexPolyhedron::from_convex_mesh(corners, &FACES)?, true)
    }

    fn from_parry(parry: ConvexPolyhedron, cube_map: bool) -> Option<ConvexHull> {
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
            let (n1, n2) = (faces[fs[0]].normal, faces[fs[1]].normal);
            edges.push(HullEdge { point: pa, dir: (pb - pa).normalize(), n1, n2, arc: n2.cross(n1) });
        }
        // Climbing neighbours: every vertex that shares a face, not only the polygon's edges.
        // parry merges nearly coplanar triangles into one polygon, and a vertex no polygon
        // neighbour beats could still lose to a vertex across the polygon (by ~1e-6 m on a
        // random point cloud's hull); the true hull's edges at a vertex all lie in its faces.
        for f in parry.faces() {
            let verts = &adj[f.first_vertex_or_edge as usize..(f.first_vertex_or_edge + f.num_vertices_or_edges) as usize];
            for &a in verts {
                for &b in verts {
                    if a != b && !neighbours[a as usize].contains(&b) {
                        neighbours[a as usize].push(b);
                    }
                }
            }
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
        let radius = points.iter().map(|p| (*p - centroid).length()).fold(0.0, Real::max);
        let mut hull =
            ConvexHull { points, faces, edges, centroid, radius, aabb: Aabb::new(lo, hi), adjacency_first, adjacency, starts: Vec::new(), parry, grown: None };
        if cube_map && hull.points.len() >= CLIMB_MIN_POINTS && hull.points.len() < EXACT as usize {
            hull.starts = support_cube_map(&hull);
        }
        Some(hull)
    }

    /// `core` grown by the ball of radius `pad`, as the motion check tests it. Its extremes and
    /// support points are exactly the rounded shape's (`core`'s plus `pad·|d|`, from `core`'s cube
    /// map); its own vertices, faces, edges and box are those of `core`'s Minkowski sum with the
    /// cube `[-pad, pad]³`, which holds the rounded shape, for the separating-axis test: an axis
    /// that separates that polytope separates the rounded shape too, and its box is the rounded
    /// shape's. Growing by the cube alone reached √3 times as far along its corners, and the
    /// motion check split stretches for contacts the displacement bound cannot reach.
    pub(crate) fn grown_by_ball(core: &Arc<ConvexHull>, pad: Real) -> Option<ConvexHull> {
        let corners = cube_corners(Vector::splat(pad));
        let points: Vec<Vector> = core.points.iter().flat_map(|p| corners.iter().map(move |c| *p + *c)).collect();
        let mut grown = Self::hull_of(&points, false)?;
        grown.grown = Some((core.clone(), pad));
        Some(grown)
    }

    /// The hull grown by `padding` metres: every vertex moved out along the normal of each of its
    /// faces, then hulled again. Every face moves out by exactly `padding`; edges and corners are
    /// bevelled, short of the rounded Minkowski sum by at most `padding * (1 - cos(a/2))` for a
    /// dihedral angle `a` between face normals.
    pub(crate) fn padded(&self, padding: Real) -> Option<ConvexHull> {
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

    /// The hull as a triangle mesh (each face fanned from its first vertex), for handing the same
    /// shape to another checker.
    pub fn vertices_and_triangles(&self) -> (Vec<[Real; 3]>, Vec<[u32; 3]>) {
        let poly = &self.parry;
        let points = poly.points().iter().map(|p| p.to_array()).collect();
        let adj = poly.vertices_adj_to_face();
        let mut triangles = Vec::new();
        for f in poly.faces() {
            let first = f.first_vertex_or_edge as usize;
            let vs = &adj[first..first + f.num_vertices_or_edges as usize];
            for k in 1..vs.len().saturating_sub(1) {
                triangles.push([vs[0], vs[k], vs[k + 1]]);
            }
        }
        (points, triangles)
    }

    /// The same hull as a parry shape (for GJK-based queries and as a test oracle).
    pub fn as_parry(&self) -> &ConvexPolyhedron {
        &self.parry
    }

    /// `[min, max]` of `dir . x` over the hull.
    #[inline]
    pub(crate) fn project(&self, dir: Vector) -> [Real; 2] {
        if self.points.len() >= CLIMB_MIN_POINTS || self.grown.is_some() {
            return [-self.climb(-dir), self.climb(dir)];
        }
        crate::math::project_points(&self.points, dir)
    }
}

impl ConvexHull {
    /// `max dir . x`: looked up in the cube map where one vertex is extreme over the whole bin of
    /// `dir` (~80 % of bins on a Panda link hull), else by hill climbing over the vertex graph from
    /// the vertex extreme at the bin's centre, a step or two away (on a convex polytope a vertex
    /// no neighbour improves on is the global maximum).
    fn climb(&self, dir: Vector) -> Real {
        if let Some((core, pad)) = &self.grown {
            return core.extreme(dir) + pad * dir.length();
        }
        self.climb_vertex(dir).0
    }

    /// `max dir . x`, by climbing or, on a small hull, a scan.
    #[inline]
    pub(crate) fn extreme(&self, dir: Vector) -> Real {
        if self.points.len() >= CLIMB_MIN_POINTS || self.grown.is_some() {
            self.climb(dir)
        } else {
            crate::math::project_points(&self.points, dir)[1]
        }
    }

    /// [`ConvexHull::extreme`] for each of `dirs` into `out`, climbed together when there are at
    /// most [`MANY`].
    #[inline]
    pub(crate) fn extremes(&self, dirs: &[Vector], out: &mut [Real]) {
        if (self.points.len() >= CLIMB_MIN_POINTS || self.grown.is_some()) && dirs.len() <= MANY {
            self.climb_many(dirs, out);
        } else {
            for (o, d) in out.iter_mut().zip(dirs) {
                *o = self.extreme(*d);
            }
        }
    }

    /// [`ConvexHull::climb`] and the vertex it ends at.
    #[inline]
    fn climb_vertex(&self, dir: Vector) -> (Real, usize) {
        self.climb_from_entry(dir, self.entry(dir))
    }

    /// The cube-map entry of `dir`; with no map (a hull of `2^15` vertices or more), vertex 0.
    #[inline]
    fn entry(&self, dir: Vector) -> u16 {
        self.starts.get(start_bin(dir)).copied().unwrap_or(0)
    }

    /// The extreme along `dir` from its cube-map entry: the flagged vertex, or a climb from it.
    #[inline]
    fn climb_from_entry(&self, dir: Vector, entry: u16) -> (Real, usize) {
        if entry & EXACT != 0 {
            let at = (entry & !EXACT) as usize;
            return (dir.dot(self.points[at]), at);
        }
        self.climb_from(dir, entry as usize)
    }

    /// The vertices that share a face with vertex `at`.
    #[inline]
    fn neighbours(&self, at: usize) -> &[u32] {
        &self.adjacency[self.adjacency_first[at] as usize..self.adjacency_first[at + 1] as usize]
    }

    /// Hill climbing along `dir` from vertex `at`.
    #[inline]
    fn climb_from(&self, dir: Vector, mut at: usize) -> (Real, usize) {
        let mut best = dir.dot(self.points[at]);
        loop {
            let mut moved = false;
            for &nb in self.neighbours(at) {
                let d = dir.dot(self.points[nb as usize]);
                if d > best {
                    best = d;
                    at = nb as usize;
                    moved = true;
                }
            }
            if !moved {
                return (best, at);
            }
        }
    }

    /// [`ConvexHull::climb`] for several directions (at most [`MANY`]): every cube-map bin is read
    /// before any is used, so that the memory waits of the run overlap.
    #[inline]
    fn climb_many(&self, dirs: &[Vector], out: &mut [Real]) {
        if let Some((core, pad)) = &self.grown {
            core.extremes(dirs, out);
            for (o, d) in out.iter_mut().zip(dirs) {
                *o += pad * d.length();
            }
            return;
        }
        let mut entries = [0u16; MANY];
        for (e, d) in entries.iter_mut().zip(dirs) {
            *e = self.entry(*d);
        }
        for ((e, d), o) in entries.iter().zip(dirs).zip(out) {
            *o = self.climb_from_entry(*d, *e).0;
        }
    }

    /// A vertex extreme along `dir`.
    #[inline]
    pub(crate) fn support_point(&self, dir: Vector) -> Vector {
        if let Some((core, pad)) = &self.grown {
            let length = dir.length();
            let out = if length > 0.0 { dir * (pad / length) } else { Vector::ZERO };
            return core.support_point(dir) + out;
        }
        if self.points.len() >= CLIMB_MIN_POINTS {
            return self.points[self.climb_vertex(dir).1];
        }
        let mut best = self.points[0];
        let mut d = dir.dot(best);
        for p in &self.points[1..] {
            let x = dir.dot(*p);
            if x > d {
                (best, d) = (*p, x);
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::collision::target::TargetShape;

    /// A grown hull answers the extremes of the hull it grew from grown by the ball: over random
    /// hulls, growths and directions, every answer is `core`'s plus `pad·|d|`, no more than its own
    /// (cube-grown) vertices reach, at least what the core's vertices pushed `pad` along `d`
    /// reach (points of the rounded shape), and its box is the rounded shape's.
    #[test]
    fn a_grown_hull_has_the_extremes_of_the_rounded_hull() {
        let mut rng = oorandom::Rand64::new(5);
        let mut unit = || 2.0 * rng.rand_float() - 1.0;
        let mut checked = 0;
        for case in 0..60 {
            // Small hulls are scanned, large ones climbed: both sides of `CLIMB_MIN_POINTS`.
            let n = if case % 2 == 0 { 10 } else { 200 };
            let points: Vec<Vector> = (0..n).map(|_| Vector::new(unit() * 0.3, unit() * 0.1, unit() * 0.05)).collect();
            let core = Arc::new(ConvexHull::from_points(&points).unwrap());
            let pad = [0.0005, 0.02, 0.3][case % 3];
            let grown = ConvexHull::grown_by_ball(&core, pad).unwrap();
            assert!(grown.grown.is_some());
            for k in 0..3 {
                assert!((grown.aabb.mins[k] - (core.aabb.mins[k] - pad)).abs() < 1e-12 && (grown.aabb.maxs[k] - (core.aabb.maxs[k] + pad)).abs() < 1e-12);
            }
            let dirs: Vec<Vector> = (0..MANY).map(|_| Vector::new(unit(), unit(), unit())).collect();
            let mut many = [0.0; MANY];
            TargetShape::Polytope(Arc::new(grown.clone())).support_many(&dirs, &mut many);
            for (d, m) in dirs.iter().zip(many) {
                let rounded = |d: Vector| core.points.iter().map(|p| d.dot(*p)).fold(Real::NEG_INFINITY, Real::max) + pad * d.length();
                let own = grown.points.iter().map(|p| d.dot(*p)).fold(Real::NEG_INFINITY, Real::max);
                let want = rounded(*d);
                let tol = 1e-12 * (1.0 + want.abs());
                assert!(want <= own + tol, "the cube-grown vertices hold the rounded hull along {d:?}");
                assert!((grown.project(*d)[1] - want).abs() < tol, "project {d:?}");
                assert!((d.dot(grown.support_point(*d)) - want).abs() < tol, "support_point {d:?}");
                assert!((m - want).abs() < tol, "support_many {d:?}: {m} against {want}");
                assert!((grown.project(*d)[0] + rounded(-*d)).abs() < tol, "project's low end {d:?}");
                checked += 1;
            }
        }
        assert_eq!(checked, 60 * MANY);
    }
}
