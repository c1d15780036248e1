//! Property tests of the mesh topology and the thickness cells (design.md, "The thickness area of
//! one triangle"), with fixed seeds. Run with `--nocapture` to see the tables. Debugging aids:
//! `TP_ONLY=<part of a mesh name>` runs only those meshes, `TP_DEBUG=1` prints the violations.
//!
//! - `back_cells_on_many_meshes`: 55 meshes (flat and jittered grids, jittered wavy sheets, V-folds
//!   30..175 degrees both ways, spheres, boxes, saddles, a sheet with a hole, a non-manifold fan,
//!   faces wound the wrong way, fan folds), each under a random rigid motion. Per mesh: the cells
//!   move with the mesh; every cell matches the rule recomputed here independently (walls as the
//!   planes equidistant from two face planes, cross point by Gaussian elimination, tetrahedron
//!   apex = cross point, ratioed vertex = v + (c - v) t/h); 10,000 points behind the surface lie in
//!   exactly one cell; 10,000 points in front lie in none; flat meshes give right prisms; closed
//!   convex meshes give inward cells and tetrahedra where `t` reaches the apex.
//! - `front_and_both_sides`: the same meshes with `side = front` and `side = both`: same wall
//!   planes, mirrored properties, the two-sided cell is the union of the one-sided ones.
//! - `topology_reports_winding_and_edges`: the topology and cell reports, a face wound the wrong
//!   way (flipped back, same cells), dihedral angles and convexity of V-fold creases.
//! - `gap_and_overlap_volume_fractions`: Monte-Carlo over the true thickness region (uniform in
//!   volume, the points within `t` behind the surface by their closest feature), per mesh family.
//! - `shared_walls_against_naive_prisms_on_v_folds`: why the method exists.
//!
//! On the exactly-one property. design.md claims it for a point behind a face at depth below
//! `min(t, cell height)`, at least `2t` from free edges, farther than `t / sin(a/2)` from every
//! vertex, with no other part of the mesh within `t` behind the face (here: crossing the ray from
//! the foot). Measured, those exclusions are not quite enough, for two reasons:
//! 1. near a vertex, faces that share only that vertex have different walls, and the mismatch
//!    reaches beyond `t / sin(a/2)`: a face that touches a fold at one vertex only keeps
//!    perpendicular walls, and its prism crosses the fold's bisecting wall in a sliver whose length
//!    grows as the face's angle at that vertex narrows; diverging cells reach past their faces;
//! 2. on sharp folds the other sheet can lie within `t` of the point without crossing its ray,
//!    and its cells then hold the point too.
//!
//! So for every point that passes the design's exclusions the test asserts: never in the cells of
//! two faces that share an edge (their common wall is exact); on the other side, never in the cell
//! of the point's face or an edge neighbour; no violation at all farther than `2 t / sin(a/2)`
//! from every vertex, except an overlap with the cell of an unconnected face within `t`; and the
//! near-vertex violations below 2% of the tested points where `t` is not thick against the
//! triangles. Every violation is counted and printed per mesh (nothing is hidden), and the volume
//! the near-vertex mismatch occupies is measured separately.

mod common;
mod shapes;

use oorandom::Rand64;
use parry3d_f64::bounding_volume::BoundingVolume;
use parry3d_f64::partitioning::{Bvh, BvhBuildStrategy};
use shapes::{aabb_of, fan_fold, segment_crosses_triangle};
use std::f64::consts::PI;
use std::time::Instant;
use thickness_collision::math::{Aabb, Pose, Real, Rotation, Vector};
use thickness_collision::mesh::generate::{self, Soup};
use thickness_collision::mesh::{EdgeLink, MeshTopology};
use thickness_collision::thickness::{is_collapsed, CellKind, Side, ThicknessArea, ThicknessCell, ThicknessSettings, WallRule};

/// Sampled points per mesh and property.
const POINTS: usize = 10_000;

// ---------------------------------------------------------------------------------------------
// Random numbers and small geometry, written here independently of the crate.

fn uniform(rng: &mut Rand64, lo: Real, hi: Real) -> Real {
    lo + (hi - lo) * rng.rand_float()
}

fn random_pose(rng: &mut Rand64) -> Pose {
    let axis = loop {
        let a = Vector::new(uniform(rng, -1., 1.), uniform(rng, -1., 1.), uniform(rng, -1., 1.));
        if a.length() > 0.1 && a.length() < 1.0 {
            break a.normalize();
        }
    };
    let shift = Vector::new(uniform(rng, -3., 3.), uniform(rng, -3., 3.), uniform(rng, -3., 3.));
    Pose::from_parts(shift, Rotation::from_axis_angle(axis, uniform(rng, 0.0, 2.0 * PI)))
}

fn aabb_around(p: Vector, r: Real) -> Aabb {
    Aabb::new(p - Vector::splat(r), p + Vector::splat(r))
}

fn dist_to_segment(p: Vector, a: Vector, b: Vector) -> Real {
    let d = b - a;
    let s = ((p - a).dot(d) / d.length_squared()).clamp(0.0, 1.0);
    p.distance(a + d * s)
}

/// The feature of a triangle that holds the closest point.
#[derive(Clone, Copy, Debug)]
enum Feature {
    Face,
    /// Edge `i`, from corner `i` to corner `i + 1`.
    Edge(usize),
    Vertex(usize),
}

/// Closest point of triangle `abc` to `p` (Ericson, Real-Time Collision Detection, 5.1.5).
fn closest_on_triangle(p: Vector, [a, b, c]: [Vector; 3]) -> (Vector, Feature) {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, Feature::Vertex(0));
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return (b, Feature::Vertex(1));
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return (a + ab * (d1 / (d1 - d3)), Feature::Edge(0));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return (c, Feature::Vertex(2));
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return (a + ac * (d2 / (d2 - d6)), Feature::Edge(2));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))), Feature::Edge(1));
    }
    let denom = 1.0 / (va + vb + vc);
    (a + ab * (vb * denom) + ac * (vc * denom), Feature::Face)
}

/// Solves `m x = r` by Gaussian elimination with partial pivoting; also returns `|det m|`
/// (rows are unit vectors here, so it measures how far from parallel the planes are).
fn solve3(mut m: [[Real; 3]; 3], mut r: [Real; 3]) -> (Option<Vector>, Real) {
    let mut det = 1.0;
    for col in 0..3 {
        let piv = (col..3).max_by(|&i, &j| m[i][col].abs().total_cmp(&m[j][col].abs())).unwrap();
        if m[piv][col] == 0.0 {
            return (None, 0.0);
        }
        m.swap(col, piv);
        r.swap(col, piv);
        det *= m[col][col];
        for row in col + 1..3 {
            let k = m[row][col] / m[col][col];
            for j in col..3 {
                m[row][j] -= k * m[col][j];
            }
            r[row] -= k * r[col];
        }
    }
    let mut x = [0.0; 3];
    for i in (0..3).rev() {
        let s: Real = (i + 1..3).map(|j| m[i][j] * x[j]).sum();
        x[i] = (r[i] - s) / m[i][i];
    }
    (Some(Vector::new(x[0], x[1], x[2])), det.abs())
}

// ---------------------------------------------------------------------------------------------
// The meshes.

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Family {
    Flat,
    Wavy,
    VFold,
    Sphere,
    Cuboid,
    Saddle,
    Holed,
    NonManifold,
    WrongWay,
    FanFold,
}

struct Case {
    name: String,
    family: Family,
    soup: Soup,
    t: Real,
    /// Closed and convex: cells must point inward.
    convex: bool,
    /// The same mesh with every face wound right (for the wrong-way cases).
    reference: Option<Soup>,
    /// The fraction of the sampled points that must pass the design's exclusions. 0.25 unless
    /// `t` is so large against the triangles that the vertex radii `t / sin(a/2)` cover nearly
    /// the whole region (the thick spheres and the coarse box, there for tetrahedra).
    min_admitted: Real,
}

/// Moves the vertices of a `height_field`-style grid (`nx + 1` by `ny + 1`) in x and y by up to
/// `amount` times the spacing, keeping their height: irregular triangles on the same surface.
/// Boundary vertices stay, so the outline stays a rectangle.
fn jitter_in_plane(soup: Soup, nx: usize, ny: usize, sx: Real, sy: Real, amount: Real, rng: &mut Rand64) -> Soup {
    let (mut v, t) = soup;
    for j in 1..ny {
        for i in 1..nx {
            let p = &mut v[j * (nx + 1) + i];
            p.x += uniform(rng, -amount, amount) * sx / nx as Real;
            p.y += uniform(rng, -amount, amount) * sy / ny as Real;
        }
    }
    (v, t)
}

fn cases() -> Vec<Case> {
    let mut rng = Rand64::new(0x5eed_0001);
    let mut out: Vec<Case> = Vec::new();
    let mut add = |name: String, family: Family, soup: Soup, t: Real, min_admitted: Real| {
        let convex = matches!(family, Family::Sphere | Family::Cuboid);
        out.push(Case { name, family, soup, t, convex, reference: None, min_admitted });
    };
    for (nx, ny, sx, sy, t) in [(6, 4, 0.6, 0.4, 0.01), (10, 10, 1.0, 1.0, 0.02), (3, 7, 0.3, 0.9, 0.04)] {
        add(format!("flat grid {nx}x{ny} t={t}"), Family::Flat, generate::flat_grid(nx, ny, sx, sy), t, 0.25);
    }
    for k in 0..2 {
        let soup = jitter_in_plane(generate::flat_grid(12, 9, 1.2, 0.9), 12, 9, 1.2, 0.9, 0.35, &mut rng);
        add(format!("jittered flat grid {k}"), Family::Flat, soup, 0.015 + 0.01 * k as Real, 0.25);
    }
    for k in 0..10 {
        let (a, w, t) = (uniform(&mut rng, 0.01, 0.08), uniform(&mut rng, 0.3, 0.9), uniform(&mut rng, 0.005, 0.03));
        let soup = jitter_in_plane(generate::wavy_sheet(16, 16, 1.0, 1.0, a, w), 16, 16, 1.0, 1.0, 0.3, &mut rng);
        add(format!("wavy {k} a={a:.3} w={w:.2} t={t:.3}"), Family::Wavy, soup, t, 0.25);
    }
    // Strongly curved: t beyond the radius of curvature at the crests gives tetrahedra there.
    for (a, w, t) in [(0.08, 0.3, 0.03), (0.06, 0.35, 0.05)] {
        let soup = jitter_in_plane(generate::wavy_sheet(16, 16, 1.0, 1.0, a, w), 16, 16, 1.0, 1.0, 0.3, &mut rng);
        // t beyond the crest radius: the vertex radii cover most of the sheet.
        add(format!("wavy a={a} w={w} t={t}"), Family::Wavy, soup, t, 0.03);
    }
    for deg in [30, 45, 60, 75, 90, 105, 120, 135, 150, 165, 175] {
        for ridge in [true, false] {
            let soup = generate::v_fold((deg as Real).to_radians(), ridge, 0.3, 0.6, 6);
            add(format!("v-fold {deg} {}", if ridge { "ridge" } else { "valley" }), Family::VFold, soup, 0.02, 0.25);
        }
    }
    // t below the radius (half the diameter); the thick ones are there for the tetrahedra, and
    // their vertex radii t / sin(a/2) cover nearly everything.
    for (r, rings, segs, t, min) in
        [(0.1, 10, 16, 0.008, 0.25), (0.1, 12, 20, 0.005, 0.25), (0.1, 8, 12, 0.05, 0.01), (0.1, 6, 8, 0.09, 0.0), (0.5, 12, 20, 0.45, 0.0)]
    {
        add(format!("sphere r={r} {rings}x{segs} t={t}"), Family::Sphere, generate::uv_sphere(r, rings, segs), t, min);
    }
    // Half-sizes 0.2, 0.3, 0.25: t below the smallest.
    for (n, t, min) in [(3, 0.03, 0.25), (2, 0.15, 0.01)] {
        add(format!("box {n}x{n} per side t={t}"), Family::Cuboid, generate::cuboid(Vector::new(0.2, 0.3, 0.25), n), t, min);
    }
    for k in [0.3, 0.6, 1.0] {
        add(format!("saddle k={k}"), Family::Saddle, generate::saddle(14, 1.0, k), 0.02, 0.25);
    }
    {
        // An open sheet with a hole: a 4x3-quad block removed from its middle.
        let (v, t) = generate::wavy_sheet(12, 12, 1.0, 1.0, 0.03, 0.5);
        let t = t.into_iter().enumerate().filter(|(i, _)| !((i / 24) >= 4 && (i / 24) < 7 && (i % 24) >= 8 && (i % 24) < 16)).map(|(_, f)| f).collect();
        add("wavy sheet with a hole".into(), Family::Holed, (v, t), 0.02, 0.25);
    }
    {
        // Non-manifold fan: a flat grid and two fins on one interior edge (4 faces on it).
        let (mut v, mut t) = generate::flat_grid(8, 8, 0.8, 0.8);
        let find = |v: &[Vector], x: Real, y: Real| v.iter().position(|p| (p.x - x).abs() < 1e-12 && (p.y - y).abs() < 1e-12).unwrap() as u32;
        let (a, b) = (find(&v, 0.4, 0.3), find(&v, 0.4, 0.4));
        let top = v.len() as u32;
        v.push(Vector::new(0.42, 0.35, 0.2));
        v.push(Vector::new(0.33, 0.35, -0.15));
        t.push([a, b, top]);
        t.push([b, a, top + 1]);
        add("non-manifold fan".into(), Family::NonManifold, (v, t), 0.02, 0.25);
    }
    add("fan fold 90 ridge".into(), Family::FanFold, fan_fold(PI / 2.0, true, 0.4, 1.0, 8), 0.03, 0.25);
    add("fan fold 120 valley".into(), Family::FanFold, fan_fold(2.0 * PI / 3.0, false, 0.4, 1.0, 8), 0.03, 0.25);
    for (k, good) in [generate::flat_grid(8, 8, 1.0, 1.0), generate::wavy_sheet(12, 12, 1.0, 1.0, 0.04, 0.6)].into_iter().enumerate() {
        let mut bad = good.clone();
        bad.1[37 + 11 * k].swap(0, 2);
        out.push(Case {
            name: format!("{} with one face wound wrong", if k == 0 { "grid" } else { "wavy" }),
            family: Family::WrongWay,
            soup: bad,
            t: 0.02,
            convex: false,
            reference: Some(good),
            min_admitted: 0.25,
        });
    }
    if let Ok(only) = std::env::var("TP_ONLY") {
        out.retain(|c| c.name.contains(&only));
    }
    out
}

// ---------------------------------------------------------------------------------------------
// One built mesh, with everything the samplers need.

struct Probe {
    mesh: MeshTopology,
    area: ThicknessArea,
    t: Real,
    /// The band on the walls: 1e-9 times the mesh size.
    eps: Real,
    cell_bvh: Bvh,
    tri_bvh: Bvh,
    /// Edges with a perpendicular wall: boundary, non-manifold, inconsistent, folded.
    free_edges: Vec<(Vector, Vector)>,
    free_bvh: Bvh,
    /// `t / sin(a/2)`, `a` the smallest dihedral angle at the vertex (`pi/2` on a free edge).
    vertex_radius: Vec<Real>,
    on_free_edge: Vec<bool>,
    vertex_bvh: Bvh,
    /// Shared edges sharper than 60 degrees, with their exclusion radius `t / sin(a/2)`.
    sharp_edges: Vec<(Vector, Vector, Real)>,
    sharp_bvh: Bvh,
    /// Angle-weighted vertex normals and edge normals (`n_f + n_g`): the pseudo-normals that
    /// classify a point by its closest feature.
    vertex_pn: Vec<Vector>,
    edge_pn: Vec<[Vector; 3]>,
}

fn build_probe(soup: &Soup, t: Real, side: Side, walls: WallRule) -> Probe {
    let mesh = common::topology(&soup.0, &soup.1);
    let area = common::topology_area(&mesh, &ThicknessSettings { thickness: t, side, walls, ..Default::default() });
    assert_eq!(area.cells.len(), mesh.triangles.len(), "every face of these meshes gets a cell");
    for (f, cell) in area.cells.iter().enumerate() {
        assert_eq!(cell.triangle, mesh.source_triangle[f]);
    }
    let nv = mesh.vertices.len();
    let mut free_edges = Vec::new();
    let mut sharp_edges = Vec::new();
    let mut min_angle = vec![PI; nv];
    let mut on_free_edge = vec![false; nv];
    let mut vertex_pn = vec![Vector::ZERO; nv];
    let mut edge_pn = vec![[Vector::ZERO; 3]; mesh.triangles.len()];
    let fold_cos = 1f64.to_radians().cos();
    for f in 0..mesh.triangles.len() {
        let (c, tri, n) = (mesh.corners(f), mesh.triangles[f], mesh.normals[f]);
        for i in 0..3 {
            let (a, b) = (c[i], c[(i + 1) % 3]);
            let ends = [tri[i] as usize, tri[(i + 1) % 3] as usize];
            let angle = (c[(i + 2) % 3] - c[i]).angle_between(c[(i + 1) % 3] - c[i]);
            vertex_pn[tri[i] as usize] += n * angle;
            edge_pn[f][i] = n;
            let link = mesh.links[f][i];
            let free = match link {
                EdgeLink::Shared { face, consistent } => {
                    let g = face as usize;
                    edge_pn[f][i] = n + mesh.normals[g];
                    if !consistent || n.dot(mesh.normals[g]) < -fold_cos {
                        true
                    } else {
                        let a_dih = mesh.dihedral_angle(f, i).unwrap();
                        for v in ends {
                            min_angle[v] = min_angle[v].min(a_dih);
                        }
                        if f < g && a_dih < 60f64.to_radians() {
                            sharp_edges.push((a, b, t / (a_dih / 2.0).sin()));
                        }
                        false
                    }
                }
                EdgeLink::Boundary | EdgeLink::NonManifold => true,
            };
            if free {
                // A shared edge is seen from both faces; list it once. (A non-manifold edge is
                // listed once per face on it: harmless.)
                if !matches!(link, EdgeLink::Shared { face, .. } if (face as usize) < f) {
                    free_edges.push((a, b));
                }
                for v in ends {
                    on_free_edge[v] = true;
                    min_angle[v] = min_angle[v].min(PI / 2.0);
                }
            }
        }
    }
    let vertex_radius: Vec<Real> = min_angle.iter().map(|a| t / (a / 2.0).sin()).collect();
    let leaves = |boxes: Vec<Aabb>| {
        // For an empty list, one far-away dummy leaf (its index is out of range of every list,
        // and every lookup checks the range).
        if boxes.is_empty() {
            Bvh::from_leaves(BvhBuildStrategy::Binned, &[aabb_around(Vector::splat(1e9), 1.0)])
        } else {
            Bvh::from_leaves(BvhBuildStrategy::Binned, &boxes)
        }
    };
    let cell_bvh = leaves(area.cells.iter().map(|c| aabb_of(&c.vertices())).collect());
    let tri_bvh = leaves((0..mesh.triangles.len()).map(|f| aabb_of(&mesh.corners(f))).collect());
    let free_bvh = leaves(free_edges.iter().map(|&(a, b)| aabb_of(&[a, b]).loosened(2.0 * t)).collect());
    let vertex_bvh = leaves(mesh.vertices.iter().zip(&vertex_radius).map(|(v, r)| aabb_around(*v, *r)).collect());
    let sharp_bvh = leaves(sharp_edges.iter().map(|&(a, b, r)| aabb_of(&[a, b]).loosened(r)).collect());
    let vertex_pn = vertex_pn.into_iter().map(|n| n.normalize()).collect();
    let eps = 1e-9 * mesh.size;
    Probe { mesh, area, t, eps, cell_bvh, tri_bvh, free_edges, free_bvh, vertex_radius, on_free_edge, vertex_bvh, sharp_edges, sharp_bvh, vertex_pn, edge_pn }
}

impl Probe {
    /// `min_v |x - v| / radius(v)`: how far outside the vertex balls `x` lies (brute force).
    fn vertex_ratio(&self, x: Vector) -> Real {
        self.mesh.vertices.iter().zip(&self.vertex_radius).map(|(v, r)| v.distance(x) / r).fold(Real::INFINITY, Real::min)
    }

    fn faces(&self) -> usize {
        self.mesh.triangles.len()
    }

    /// Cells holding `x`: `(planes pushed out by eps, strictly inside by eps)`.
    fn count_cells(&self, x: Vector) -> (usize, usize) {
        let q = aabb_around(x, self.eps);
        let (mut loose, mut strict) = (0, 0);
        for k in self.cell_bvh.intersect_aabb(&q) {
            if let Some(cell) = self.area.cells.get(k as usize) {
                loose += cell.contains_point(x, self.eps) as usize;
                strict += cell.contains_point(x, -self.eps) as usize;
            }
        }
        (loose, strict)
    }

    /// The cells that hold `x` strictly (by `eps`).
    fn holders(&self, x: Vector) -> Vec<usize> {
        let q = aabb_around(x, self.eps);
        let holders =
            self.cell_bvh.intersect_aabb(&q).map(|k| k as usize).filter(|&k| k < self.faces() && self.area.cells[k].contains_point(x, -self.eps)).collect();
        holders
    }

    fn near_free_edge(&self, x: Vector) -> bool {
        let q = aabb_around(x, 0.0);
        let near = self.free_bvh.intersect_aabb(&q).any(|k| self.free_edges.get(k as usize).is_some_and(|&(a, b)| dist_to_segment(x, a, b) <= 2.0 * self.t));
        near
    }

    /// Within the radius of a vertex (of any vertex, or only of those on a free edge).
    fn near_vertex(&self, x: Vector, only_free: bool) -> bool {
        let q = aabb_around(x, 0.0);
        let near = self.vertex_bvh.intersect_aabb(&q).any(|k| {
            let k = k as usize;
            k < self.mesh.vertices.len() && (!only_free || self.on_free_edge[k]) && self.mesh.vertices[k].distance(x) <= self.vertex_radius[k]
        });
        near
    }

    fn near_sharp_edge(&self, x: Vector) -> bool {
        let q = aabb_around(x, 0.0);
        let near = self.sharp_bvh.intersect_aabb(&q).any(|k| self.sharp_edges.get(k as usize).is_some_and(|&(a, b, r)| dist_to_segment(x, a, b) <= r));
        near
    }

    /// Whether a face other than `f` crosses the segment from `p` to `q`.
    fn other_face_on_segment(&self, f: usize, p: Vector, q: Vector) -> bool {
        let bb = aabb_of(&[p, q]);
        let hit = self.tri_bvh.intersect_aabb(&bb).any(|g| {
            let g = g as usize;
            g < self.faces() && g != f && segment_crosses_triangle(p, q - p, self.mesh.corners(g), 1e-12)
        });
        hit
    }

    /// A face chosen uniformly and a foot uniformly in it.
    fn random_foot(&self, rng: &mut Rand64) -> (usize, Vector) {
        let f = rng.rand_range(0..self.faces() as u64) as usize;
        let [a, b, c] = self.mesh.corners(f);
        let (mut u, mut v) = (rng.rand_float(), rng.rand_float());
        if u + v > 1.0 {
            (u, v) = (1.0 - u, 1.0 - v);
        }
        (f, a + (b - a) * u + (c - a) * v)
    }

    /// Distance from `x` to the mesh and the signed side of `x` there (pseudo-normal test), for
    /// points within `t` of the mesh.
    fn closest(&self, x: Vector) -> Option<(Real, Real)> {
        let q = aabb_around(x, self.t);
        let mut best: Option<(Real, Vector, Vector)> = None;
        for g in self.tri_bvh.intersect_aabb(&q) {
            let g = g as usize;
            if g >= self.faces() {
                continue;
            }
            let (p, feature) = closest_on_triangle(x, self.mesh.corners(g));
            let d = p.distance(x);
            if best.is_none_or(|(bd, _, _)| d < bd) {
                let pn = match feature {
                    Feature::Face => self.mesh.normals[g],
                    Feature::Edge(i) => self.edge_pn[g][i],
                    Feature::Vertex(i) => self.vertex_pn[self.mesh.triangles[g][i] as usize],
                };
                best = Some((d, p, pn));
            }
        }
        let (d, p, pn) = best?;
        (d < self.t).then(|| (d, pn.dot(x - p)))
    }
}

// ---------------------------------------------------------------------------------------------
// Samplers.

#[derive(Default, Clone, Copy)]
struct Tally {
    sampled: usize,
    /// Passed the design's exclusions: the points the property is claimed for.
    admitted: usize,
    /// In no cell.
    gaps: usize,
    /// Held by the cells of two faces that share an edge: their common wall failed. Must never
    /// happen.
    edge_overlaps: usize,
    /// Held by the cells of faces that share only a vertex (the vertex mismatch of the per-face
    /// rule).
    vertex_overlaps: usize,
    /// Held by the cells of two faces that share nothing.
    apart_overlaps: usize,
    /// Violations farther than twice the design's radius `t / sin(a/2)` from every vertex.
    beyond_2r: usize,
    /// Violations that are not the inherent ones: an overlap across a shared wall, or anything
    /// farther than 2 t/sin(a/2) from every vertex that is not an overlap with the cell of an
    /// unconnected face within `t` of the point. Must be zero.
    unexplained: usize,
    /// Largest `min_v |x - v| / radius(v)` over the violations.
    worst_ratio: Real,
}

impl Tally {
    fn violations(&self) -> usize {
        self.gaps + self.edge_overlaps + self.vertex_overlaps + self.apart_overlaps
    }
    fn add(&mut self, o: &Tally) {
        self.sampled += o.sampled;
        self.admitted += o.admitted;
        self.gaps += o.gaps;
        self.edge_overlaps += o.edge_overlaps;
        self.vertex_overlaps += o.vertex_overlaps;
        self.apart_overlaps += o.apart_overlaps;
        self.beyond_2r += o.beyond_2r;
        self.unexplained += o.unexplained;
        self.worst_ratio = self.worst_ratio.max(o.worst_ratio);
    }
    /// Records a violation at `x`, sampled from face `f`: `holders` are the cells that strictly
    /// hold it (empty for a gap). The holders are compared pairwise; without `own_ok` (a point on
    /// the side that gets no cells) each is also compared with `f`, so that `f`'s own cell or an
    /// edge neighbour's counts as a failure. The worst pair classifies the violation: two faces
    /// that share an edge (their common wall failed), only a vertex (the inherent vertex
    /// mismatch), or nothing.
    fn violation(&mut self, p: &Probe, f: usize, x: Vector, holders: &[usize], own_ok: bool) {
        let ratio = p.vertex_ratio(x);
        self.worst_ratio = self.worst_ratio.max(ratio);
        self.beyond_2r += (ratio > 2.0) as usize;
        let shared = |a: usize, b: usize| p.mesh.triangles[a].iter().filter(|v| p.mesh.triangles[b].contains(v)).count();
        // With own_ok, the point's face stands in for "the cell that should hold it"; without,
        // the point's face itself must not hold it, and neither may an edge neighbour.
        let mut pairs: Vec<(usize, usize)> = Vec::new();
        for (i, &a) in holders.iter().enumerate() {
            for &b in &holders[i + 1..] {
                pairs.push((a, b));
            }
            if !own_ok {
                pairs.push((a, f));
            }
        }
        let worst = pairs.iter().map(|&(a, b)| if a == b { 3 } else { shared(a, b) }).max().unwrap_or(0);
        // Another part of the mesh within t: an unconnected face near the point whose cell holds it.
        let other_part = holders.iter().any(|&g| shared(g, f) == 0 && closest_on_triangle(x, p.mesh.corners(g)).0.distance(x) < p.t);
        let unexplained = worst >= 2 || (ratio > 2.0 && !other_part);
        self.unexplained += unexplained as usize;
        if holders.is_empty() {
            self.gaps += 1;
        } else if worst >= 2 {
            self.edge_overlaps += 1;
        } else if worst == 1 {
            self.vertex_overlaps += 1;
        } else {
            self.apart_overlaps += 1;
        }
        if debug() && (unexplained || holders.is_empty()) {
            eprintln!("  violation at face {f}, x = {x:?}, vertex ratio {ratio:.3}, holders:");
            for &g in holders {
                let dg = closest_on_triangle(x, p.mesh.corners(g)).0.distance(x);
                eprintln!("    cell {g} {:?}: face {dg:.4} away, shares {} vertices with face {f} (t = {})", p.area.cells[g].kind, shared(g, f), p.t);
            }
        }
    }
}

fn debug() -> bool {
    std::env::var_os("TP_DEBUG").is_some()
}

/// Exactly one cell holds a point on the thickness side of a face (for `Side::Both`, either side),
/// at depth below `min(t, cell height)`, away from free edges (2t) and vertices (t / sin(a/2)),
/// with no other face within `t` on the ray from the foot.
fn exactly_one(p: &Probe, side: Side, rng: &mut Rand64) -> Tally {
    let mut tally = Tally::default();
    for _ in 0..POINTS {
        let (f, foot) = p.random_foot(rng);
        let s: Real = match side {
            Side::Back => -1.0,
            Side::Front => 1.0,
            Side::Both => {
                if rng.rand_u64() & 1 == 0 {
                    -1.0
                } else {
                    1.0
                }
            }
        };
        let cell = &p.area.cells[f];
        let [lo, hi] = cell.normal_range();
        let height = if s < 0.0 { cell.plane_offset - lo } else { hi - cell.plane_offset };
        let depth = uniform(rng, 0.0, p.t.min(height));
        let n = p.mesh.normals[f];
        let x = foot + n * (s * depth);
        tally.sampled += 1;
        if depth <= 0.0 || p.near_free_edge(x) || p.near_vertex(x, false) || p.other_face_on_segment(f, foot, foot + n * (s * p.t)) {
            continue;
        }
        tally.admitted += 1;
        let (loose, strict) = p.count_cells(x);
        if loose == 0 || strict > 1 {
            let holders = p.holders(x);
            tally.violation(p, f, x, &holders, true);
        }
    }
    tally
}

/// No cell holds a point on the other side: `foot + d n_f` with `d` in `(0, t]` (`-n_f` for
/// `Side::Front`), with the same exclusions, and away from shared edges sharper than 60 degrees.
fn none_on_the_other_side(p: &Probe, side: Side, rng: &mut Rand64) -> Tally {
    let s = if side == Side::Front { -1.0 } else { 1.0 };
    let mut tally = Tally::default();
    for _ in 0..POINTS {
        let (f, foot) = p.random_foot(rng);
        let n = p.mesh.normals[f];
        let d = p.t * (1.0 - rng.rand_float()); // (0, t]
        let x = foot + n * (s * d);
        tally.sampled += 1;
        if p.near_free_edge(x) || p.near_vertex(x, false) || p.near_sharp_edge(x) || p.other_face_on_segment(f, foot, foot + n * (s * p.t)) {
            continue;
        }
        tally.admitted += 1;
        if p.count_cells(x).1 > 0 {
            let holders = p.holders(x);
            // Here even one cell is too many; it must not be the face's own or a neighbour's.
            tally.violation(p, f, x, &holders, false);
        }
    }
    tally
}

#[derive(Default, Clone, Copy)]
struct Fractions {
    tested: usize,
    gaps: usize,
    overlaps: usize,
    /// The same, restricted to points outside every vertex's radius.
    far: usize,
    far_gaps: usize,
    far_overlaps: usize,
    /// Overlaps by the closest relation between two holding faces: nothing, a vertex, an edge.
    overlap_pairs: [usize; 3],
}

fn pct(k: usize, n: usize) -> Real {
    100.0 * k as Real / n.max(1) as Real
}

/// Monte-Carlo over the true thickness region: points uniform in volume whose distance to the
/// mesh is below `t` and that lie on the thickness side (`sign` -1 behind, +1 in front) of their
/// closest feature. Points within `2t` of a free edge are skipped (and, with `boundary_vertices`,
/// those within the radius of a vertex on a free edge: the strip ends of a fold); nothing is
/// skipped near interior vertices.
fn volume_fractions(p: &Probe, rng: &mut Rand64, target: usize, sign: Real, boundary_vertices: bool) -> Fractions {
    let bb = aabb_of(&p.mesh.vertices).loosened(p.t);
    let mut fr = Fractions::default();
    let mut attempts = 0;
    while fr.tested < target {
        attempts += 1;
        assert!(attempts < 200 * target, "the thickness region is too small to sample");
        let x = Vector::new(uniform(rng, bb.mins.x, bb.maxs.x), uniform(rng, bb.mins.y, bb.maxs.y), uniform(rng, bb.mins.z, bb.maxs.z));
        let Some((_, side)) = p.closest(x) else { continue };
        if side * sign <= 0.0 || p.near_free_edge(x) || (boundary_vertices && p.near_vertex(x, true)) {
            continue;
        }
        let (loose, strict) = p.count_cells(x);
        let (gap, overlap) = ((loose == 0) as usize, (strict > 1) as usize);
        if overlap == 1 {
            let h = p.holders(x);
            let shared = |a: usize, b: usize| p.mesh.triangles[a].iter().filter(|v| p.mesh.triangles[b].contains(v)).count();
            let mut worst = 0;
            for (i, &a) in h.iter().enumerate() {
                for &b in &h[i + 1..] {
                    worst = worst.max(shared(a, b));
                }
            }
            fr.overlap_pairs[worst.min(2)] += 1;
        }
        fr.tested += 1;
        fr.gaps += gap;
        fr.overlaps += overlap;
        if !p.near_vertex(x, false) {
            fr.far += 1;
            fr.far_gaps += gap;
            fr.far_overlaps += overlap;
        }
    }
    fr
}

// ---------------------------------------------------------------------------------------------
// The rule, recomputed independently.

/// The expected kind of a one-sided cell whose walls cross at height `h` on that side (`None`:
/// the walls are parallel).
fn expected_kind(h: Option<Real>, t: Real) -> CellKind {
    match h {
        None => CellKind::Prism,
        Some(h) if h <= 0.0 => CellKind::Diverging,
        Some(h) if h <= t => CellKind::Tetrahedron,
        Some(_) => CellKind::Ratioed,
    }
}

/// Kinds that rounding may swap when the height is within a hair of a threshold (used where the
/// cells' vertices are compared as well).
fn kinds_close(a: CellKind, b: CellKind) -> bool {
    use CellKind::*;
    a == b || matches!((a, b), (Prism | Ratioed | Diverging, Prism | Ratioed | Diverging) | (Tetrahedron, Ratioed) | (Ratioed, Tetrahedron))
}

#[derive(Default, Debug, Clone, Copy)]
struct KindCount {
    tetra: usize,
    ratioed: usize,
    prism: usize,
    diverging: usize,
    /// Tetrahedron apexes and ratioed vertices compared with the cross point.
    apex_checked: usize,
    ratio_checked: usize,
}

impl KindCount {
    fn add(&mut self, o: &KindCount) {
        self.tetra += o.tetra;
        self.ratioed += o.ratioed;
        self.prism += o.prism;
        self.diverging += o.diverging;
        self.apex_checked += o.apex_checked;
        self.ratio_checked += o.ratio_checked;
    }
}

/// Checks every cell of `p` against the rule computed here:
/// - walls: across a consistent, unfolded shared edge the plane of the points equally far from the
///   two face planes, `(n_f - n_g) . x = (n_f - n_g) . p` (perpendicular when `n_f = n_g`);
///   elsewhere the plane through the edge containing `n_f`;
/// - the cross point by Gaussian elimination (the crate uses Cramer's rule), its height `h`;
/// - the kind; a tetrahedron's apex is the cross point; a ratioed vertex is `v + (c - v) t / h`;
///   every far-cap vertex lies at the cell's depth, on its two walls, and, on a shared edge, at
///   equal signed distance from the two face planes.
fn check_rule(p: &Probe, side: Side, name: &str) -> KindCount {
    let mesh = &p.mesh;
    let (t, size) = (p.t, mesh.size);
    let tol = 1e-9 * size;
    let fold_cos = 1f64.to_radians().cos();
    let mut count = KindCount::default();
    for (f, cell) in p.area.cells.iter().enumerate() {
        let c = mesh.corners(f);
        let n = mesh.normals[f];
        assert!((cell.normal - n).length() < 1e-12, "{name}: face {f}: cell normal");
        assert!((cell.plane_offset - n.dot(c[0])).abs() < tol);
        // Walls: unit normal, and the other face across the edge when it is a bisector.
        let mut walls = [Vector::ZERO; 3];
        let mut across: [Option<usize>; 3] = [None; 3];
        for i in 0..3 {
            let e = c[(i + 1) % 3] - c[i];
            walls[i] = n.cross(e).normalize();
            if let EdgeLink::Shared { face, consistent: true } = mesh.links[f][i] {
                let ng = mesh.normals[face as usize];
                if n.dot(ng) >= -fold_cos {
                    across[i] = Some(face as usize);
                    let d = n - ng;
                    if d.length() > 1e-7 {
                        walls[i] = d.normalize();
                    }
                }
            }
        }
        let (cross, det) = solve3(walls.map(|w| w.to_array()), [0, 1, 2].map(|i| walls[i].dot(c[i])));
        // The crate treats |det| <= 1e-12 as parallel; near that, either answer is a prism to 1e-12.
        let parallel = cross.is_none() || det < 1e-12;
        let ambiguous_parallel = det < 1e-10;
        let h_front = if parallel { None } else { cross.map(|x| n.dot(x - c[0])) };
        // Kinds that rounding may give next to a threshold (h = 0, h = t, parallel walls).
        let allowed = |h: Option<Real>| -> Vec<CellKind> {
            let mut k = vec![expected_kind(h, t)];
            if let Some(h) = h {
                let d = 1e-9 * size;
                k.push(expected_kind(Some(h - d), t));
                k.push(expected_kind(Some(h + d), t));
            }
            if ambiguous_parallel || h.is_some_and(|h| h.abs() > 1e6 * size) {
                k.extend([CellKind::Prism, CellKind::Ratioed, CellKind::Diverging]);
            }
            k
        };
        let sides: &[Real] = match side {
            Side::Back => &[-1.0],
            Side::Front => &[1.0],
            Side::Both => &[-1.0, 1.0],
        };
        // Per side: height of the cross point on that side, expected kind, kinds allowed.
        let per_side: Vec<(Real, Option<Real>, CellKind, Vec<CellKind>)> = sides
            .iter()
            .map(|&s| {
                let h = h_front.map(|h| s * h);
                (s, h, expected_kind(h, t), allowed(h))
            })
            .collect();
        // The kind the cell reports (design: for `both`, the converging side names it).
        let name_of = |kb: CellKind, kf: CellKind| if kb == CellKind::Diverging { kf } else { kb };
        let (want, ok) = match side {
            Side::Both => {
                let (b, fr) = (&per_side[0], &per_side[1]);
                let ok: Vec<CellKind> = b.3.iter().flat_map(|&kb| fr.3.iter().map(move |&kf| name_of(kb, kf))).collect();
                (name_of(b.2, fr.2), ok)
            }
            _ => (per_side[0].2, per_side[0].3.clone()),
        };
        assert!(ok.contains(&cell.kind), "{name}: face {f}: kind {:?}, expected {want:?} (h_front = {h_front:?}, t = {t}, det {det:e})", cell.kind);
        match cell.kind {
            CellKind::Tetrahedron => count.tetra += 1,
            CellKind::Ratioed => count.ratioed += 1,
            CellKind::Prism => count.prism += 1,
            CellKind::Diverging => count.diverging += 1,
        }
        // The caps.
        for (s, h, kind, ok) in per_side {
            let cap = if s < 0.0 { cell.back_cap } else { cell.front_cap };
            let clear = ok.iter().all(|k| *k == kind); // not next to a threshold
            let tetra = is_collapsed(&cap);
            if side != Side::Both {
                assert_eq!(tetra, cell.kind == CellKind::Tetrahedron, "{name}: face {f}");
            }
            if clear {
                assert_eq!(tetra, kind == CellKind::Tetrahedron, "{name}: face {f}: collapsed cap {tetra}, expected {kind:?}");
            }
            let depth = if tetra { s * n.dot(cap[0] - c[0]) } else { t };
            if tetra {
                assert!(depth > 0.0 && depth <= t + tol, "{name}: face {f}: apex at height {depth}");
                if clear && det > 1e-6 {
                    let apex = cross.unwrap();
                    assert!(cap[0].distance(apex) < tol, "{name}: face {f}: tetrahedron apex {:?}, cross point {apex:?}", cap[0]);
                    count.apex_checked += 1;
                }
            }
            for i in 0..3 {
                let q = cap[i];
                assert!((s * n.dot(q - c[0]) - depth).abs() < tol, "{name}: face {f}: cap vertex {i} at depth {} not {depth}", s * n.dot(q - c[0]));
                for j in [(i + 2) % 3, i] {
                    // Vertex i lies on the walls of edges i-1 and i.
                    match across[j] {
                        Some(g) => {
                            let ng = mesh.normals[g];
                            let (df, dg) = (n.dot(q - c[j]), ng.dot(q - c[j]));
                            assert!((df - dg).abs() < tol, "{name}: face {f}: cap vertex {i} is {df} from its face plane, {dg} from face {g}'s");
                        }
                        None => {
                            let w = n.cross(c[(j + 1) % 3] - c[j]).normalize();
                            assert!(w.dot(q - c[j]).abs() < tol, "{name}: face {f}: cap vertex {i} off the perpendicular wall of edge {j}");
                        }
                    }
                }
            }
            if kind == CellKind::Ratioed && clear && det > 1e-6 {
                let (apex, h) = (cross.unwrap(), h.unwrap());
                if h < 1e3 * size {
                    for i in 0..3 {
                        let want = c[i] + (apex - c[i]) * (t / h);
                        assert!(
                            cap[i].distance(want) < tol * (1.0 + h / size),
                            "{name}: face {f}: ratioed vertex {i} {:?} vs v + (c - v) t/h = {want:?}",
                            cap[i]
                        );
                    }
                    count.ratio_checked += 1;
                }
            }
        }
        // The side that gets no volume has its cap on the face.
        match side {
            Side::Back => assert_eq!(cell.front_cap, c, "{name}: face {f}: front cap off the face"),
            Side::Front => assert_eq!(cell.back_cap, c, "{name}: face {f}: back cap off the face"),
            Side::Both => {}
        }
    }
    count
}

/// Every cell of `moved` is the cell of `base` moved by `pose`.
fn check_transform(base: &ThicknessArea, moved: &ThicknessArea, pose: &Pose, size: Real, name: &str) {
    assert_eq!(base.cells.len(), moved.cells.len(), "{name}");
    let tol = 1e-9 * size;
    for (a, b) in base.cells.iter().zip(&moved.cells) {
        assert_eq!(a.triangle, b.triangle);
        assert!((pose.rotation * a.normal - b.normal).length() < 1e-12, "{name}: normal of triangle {}", a.triangle);
        for (p, q) in a.vertices().iter().zip(b.vertices()) {
            assert!(
                (pose * *p).distance(q) < tol,
                "{name}: triangle {}: cell vertex {:?} moved is {:?}, built on the moved mesh {q:?}",
                a.triangle,
                pose * *p,
                q
            );
        }
        assert!(kinds_close(a.kind, b.kind) || a.kind == b.kind, "{name}: kind {:?} vs {:?}", a.kind, b.kind);
    }
}

/// Right prisms: kind `Prism`, back cap = face corner - t n (side = back).
fn check_right_prisms(p: &Probe, name: &str) {
    for (f, cell) in p.area.cells.iter().enumerate() {
        assert_eq!(cell.kind, CellKind::Prism, "{name}: face {f}");
        let c = p.mesh.corners(f);
        for i in 0..3 {
            let want = c[i] - cell.normal * p.t;
            assert!(cell.back_cap[i].distance(want) <= 1e-12 * p.mesh.size.max(1.0), "{name}: face {f}: not a right prism");
        }
    }
}

/// Closed convex mesh, side = back: every cell's far cap lies inside the shape (behind every
/// face plane), and no walls diverge.
fn check_inward(p: &Probe, name: &str) {
    assert_eq!(p.mesh.report.closed_components, 1, "{name}");
    assert_eq!(p.mesh.report.open_components, 0, "{name}");
    let tol = 1e-9 * p.mesh.size;
    for cell in &p.area.cells {
        assert_ne!(cell.kind, CellKind::Diverging, "{name}: walls diverge on a convex shape");
        for q in cell.back_cap {
            for g in 0..p.faces() {
                let d = p.mesh.normals[g].dot(q - p.mesh.vertices[p.mesh.triangles[g][0] as usize]);
                assert!(d <= tol, "{name}: a back cap vertex of triangle {} lies {d} outside face {g}", cell.triangle);
            }
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Tests.

fn print_row(name: &str, p: &Probe, k: &KindCount, one: &Tally, none: Option<&Tally>) {
    let other = none.map_or(String::new(), |n| format!("{:>6} {:>4} {:>5.2} {:>4}", n.admitted, n.violations(), n.worst_ratio, n.unexplained));
    eprintln!(
        "{name:<38} {:>5} {:>4}/{:>4}/{:>4}/{:>4} | {:>6} {:>4} {:>4} {:>4} {:>4} {:>4} {:>5.2} {:>4} | {other}",
        p.faces(),
        k.tetra,
        k.ratioed,
        k.prism,
        k.diverging,
        one.admitted,
        one.gaps,
        one.edge_overlaps,
        one.vertex_overlaps,
        one.apart_overlaps,
        one.beyond_2r,
        one.worst_ratio,
        one.unexplained,
    );
}

fn print_header(title: &str, other: &str) {
    eprintln!("{title}");
    eprintln!(
        "{:<38} {:>5} {:>19} | {:>6} {:>4} {:>4} {:>4} {:>4} {:>4} {:>5} {:>4} | {other}",
        "mesh", "faces", "tet/rat/pri/div", "tested", "gap", "e-ov", "v-ov", "a-ov", ">2R", "worst", "unex"
    );
}

const LEGEND: &str = "tested: points that passed the design's exclusions (of 10,000); gap: in no cell; e-ov: in the cells of two faces that share an edge \
(or, on the other side, in the cell of the point's face or an edge neighbour); v-ov: in the cells of two faces that share only a vertex; a-ov: ... \
that share nothing; >2R: violations farther than 2 t/sin(a/2) from every vertex; worst: largest min_v |x - v| / (t/sin(a_v/2)) over the \
violations; unex: e-ov, or >2R without an unconnected face within t whose cell holds the point (must be 0)";

/// The assertions on a tally. The design's exclusions alone do not make the property exact (see
/// the file's header): the inherent violations near vertices, and overlaps with the cells of
/// unconnected faces within `t`, are counted and printed; everything else must be absent.
fn assert_tally(t: &Tally, case: &Case, what: &str) {
    assert_eq!(t.sampled, POINTS);
    assert_eq!(t.edge_overlaps, 0, "{}: {what}: {} points in two cells across a shared wall (or in their own cell's side)", case.name, t.edge_overlaps);
    assert_eq!(t.unexplained, 0, "{}: {what}: {} violations away from the vertices ({} beyond 2 t/sin(a/2))", case.name, t.unexplained, t.beyond_2r);
    assert!(t.admitted as Real >= case.min_admitted * POINTS as Real, "{}: {what}: only {} of {POINTS} points were tested", case.name, t.admitted);
    // The inherent violations near vertices are rare: at most 2% of the tested points, unless t
    // is thick against the triangles (those cases are marked by their low `min_admitted`).
    // Overlaps with unconnected faces within t are outside the claim and not bounded here.
    if case.min_admitted >= 0.25 {
        let near_vertex = t.gaps + t.vertex_overlaps;
        assert!(near_vertex * 50 <= t.admitted, "{}: {what}: {near_vertex} violations near vertices in {} points", case.name, t.admitted);
    }
}

fn summary(what: &str, t: &Tally) {
    eprintln!(
        "{what}: {} sampled, {} tested ({:.1}%); violations: {} gaps, {} across shared walls, {} between faces sharing a vertex ({:.3}% of tested), {} between unconnected faces; worst vertex ratio {:.2}; unexplained {}",
        t.sampled,
        t.admitted,
        pct(t.admitted, t.sampled),
        t.gaps,
        t.edge_overlaps,
        t.vertex_overlaps,
        pct(t.vertex_overlaps, t.admitted),
        t.apart_overlaps,
        t.worst_ratio,
        t.unexplained
    );
}

#[test]
fn back_cells_on_many_meshes() {
    let start = Instant::now();
    let cases = cases();
    assert!(cases.len() >= 50 || std::env::var_os("TP_ONLY").is_some(), "{} meshes", cases.len());
    let mut rng = Rand64::new(0x5eed_0002);
    let mut one_total = Tally::default();
    let mut none_total = Tally::default();
    let mut kinds_by_family: Vec<(Family, KindCount)> = Vec::new();
    print_header(
        &format!("side = back, {} meshes under random rigid motions, {POINTS} points per mesh and property", cases.len()),
        "in front: tested, in a cell, worst",
    );
    for case in &cases {
        let pose = random_pose(&mut rng);
        let local = build_probe(&case.soup, case.t, Side::Back, WallRule::Shared);
        let p = build_probe(&generate::transformed(case.soup.clone(), &pose), case.t, Side::Back, WallRule::Shared);
        check_transform(&local.area, &p.area, &pose, p.mesh.size, &case.name);
        let k = check_rule(&p, Side::Back, &case.name);
        match kinds_by_family.iter_mut().find(|(f, _)| *f == case.family) {
            Some((_, acc)) => acc.add(&k),
            None => kinds_by_family.push((case.family, k)),
        }
        if case.family == Family::Flat {
            check_right_prisms(&local, &case.name);
            check_right_prisms(&p, &case.name);
        }
        if case.convex {
            check_inward(&p, &case.name);
        }
        let one = exactly_one(&p, Side::Back, &mut rng);
        let none = none_on_the_other_side(&p, Side::Back, &mut rng);
        print_row(&case.name, &p, &k, &one, Some(&none));
        assert_tally(&one, case, "exactly one behind");
        assert_tally(&none, case, "none in front");
        one_total.add(&one);
        none_total.add(&none);
    }
    eprintln!("{LEGEND}");
    summary("exactly one behind", &one_total);
    summary("none in front", &none_total);
    for (family, k) in &kinds_by_family {
        eprintln!("kinds {family:?}: {k:?}");
    }
    assert!(one_total.admitted * 2 > one_total.sampled, "fewer than half the points behind were tested");
    assert!(none_total.admitted * 2 > none_total.sampled, "fewer than half the points in front were tested");
    if std::env::var_os("TP_ONLY").is_none() {
        for family in [Family::Sphere, Family::Wavy] {
            let k = kinds_by_family.iter().find(|(f, _)| *f == family).unwrap().1;
            assert!(k.tetra > 0 && k.ratioed > 0, "{family:?}: tetrahedra and ratioed frustums must both occur: {k:?}");
            assert!(k.apex_checked > 0 && k.ratio_checked > 0, "{family:?}: {k:?}");
        }
    }
    eprintln!("back_cells_on_many_meshes: {:.1} s", start.elapsed().as_secs_f64());
}

#[test]
fn front_and_both_sides() {
    let start = Instant::now();
    let cases = cases();
    let mut rng = Rand64::new(0x5eed_0003);
    let mut totals = [Tally::default(); 3];
    print_header("side = front (exactly one in front) and side = both (exactly one on either side)", "behind (front only): tested, in a cell, worst");
    for case in &cases {
        let pose = random_pose(&mut rng);
        let soup = generate::transformed(case.soup.clone(), &pose);
        let back = build_probe(&soup, case.t, Side::Back, WallRule::Shared);
        let front = build_probe(&soup, case.t, Side::Front, WallRule::Shared);
        let both = build_probe(&soup, case.t, Side::Both, WallRule::Shared);
        let kf = check_rule(&front, Side::Front, &case.name);
        let kb = check_rule(&both, Side::Both, &case.name);
        let tol = 1e-9 * back.mesh.size;
        for f in 0..back.faces() {
            let (b, fr, o) = (&back.area.cells[f], &front.area.cells[f], &both.area.cells[f]);
            // Front cells mirror back cells: the same three wall planes.
            for i in 0..3 {
                let (wb, wf) = (b.planes()[2 + i], fr.planes()[2 + i]);
                for q in [b.back_cap[i], b.back_cap[(i + 1) % 3], fr.front_cap[i], fr.front_cap[(i + 1) % 3]] {
                    assert!(
                        (wb.0.dot(q) - wb.1).abs() < tol && (wf.0.dot(q) - wf.1).abs() < tol,
                        "{}: face {f}: wall {i} differs between back and front",
                        case.name
                    );
                }
                assert!(wb.0.dot(wf.0) > 1.0 - 1e-9, "{}: face {f}: wall {i} turned", case.name);
            }
            // Both spans both: its caps are the back cell's back cap and the front cell's front cap.
            for i in 0..3 {
                assert!(
                    o.back_cap[i].distance(b.back_cap[i]) < tol && o.front_cap[i].distance(fr.front_cap[i]) < tol,
                    "{}: face {f}: both != back + front",
                    case.name
                );
            }
            let [lo, hi] = o.normal_range();
            assert!((lo - b.normal_range()[0]).abs() < tol && (hi - fr.normal_range()[1]).abs() < tol);
            // ... and is their union: points of either lie in it, points of it lie in one of them.
            for _ in 0..4 {
                let from_one = |cell: &ThicknessCell, rng: &mut Rand64| {
                    let w: Vec<Real> = (0..6).map(|_| -(1.0 - rng.rand_float()).ln()).collect();
                    let sum: Real = w.iter().sum();
                    cell.vertices().iter().zip(&w).fold(Vector::ZERO, |acc, (v, w)| acc + *v * (w / sum))
                };
                let x = from_one(if rng.rand_u64() & 1 == 0 { b } else { fr }, &mut rng);
                assert!(o.contains_point(x, tol), "{}: face {f}: a point of a one-sided cell is outside the two-sided one", case.name);
                let y = from_one(o, &mut rng);
                assert!(b.contains_point(y, tol) || fr.contains_point(y, tol), "{}: face {f}: a point of the two-sided cell is in neither side", case.name);
            }
        }
        let one_f = exactly_one(&front, Side::Front, &mut rng);
        let none_f = none_on_the_other_side(&front, Side::Front, &mut rng);
        let one_b = exactly_one(&both, Side::Both, &mut rng);
        print_row(&format!("{} [front]", case.name), &front, &kf, &one_f, Some(&none_f));
        print_row(&format!("{} [both]", case.name), &both, &kb, &one_b, None);
        assert_tally(&one_f, case, "front: exactly one");
        assert_tally(&none_f, case, "front: none behind");
        assert_tally(&one_b, case, "both: exactly one");
        totals[0].add(&one_f);
        totals[1].add(&none_f);
        totals[2].add(&one_b);
    }
    eprintln!("{LEGEND}");
    for (what, t) in ["front: exactly one in front", "front: none behind", "both: exactly one"].iter().zip(&totals) {
        summary(what, t);
        assert!(t.admitted * 2 > t.sampled, "{what}: fewer than half the points tested");
    }
    eprintln!("front_and_both_sides: {:.1} s", start.elapsed().as_secs_f64());
}

#[test]
fn topology_reports_winding_and_edges() {
    let mut rng = Rand64::new(0x5eed_0004);
    for case in
        cases().iter().filter(|c| matches!(c.family, Family::WrongWay | Family::NonManifold | Family::Holed | Family::Sphere | Family::Cuboid | Family::VFold))
    {
        let pose = random_pose(&mut rng);
        let soup = generate::transformed(case.soup.clone(), &pose);
        let p = build_probe(&soup, case.t, Side::Back, WallRule::Shared);
        let r = &p.area.report;
        match case.family {
            Family::WrongWay => {
                assert_eq!(p.mesh.report.flipped_faces, 1, "{}", case.name);
                assert_eq!(r.flipped_faces, 1, "{}", case.name);
                assert_eq!(p.mesh.report.inconsistent_edges, 0);
                let good = build_probe(&generate::transformed(case.reference.clone().unwrap(), &pose), case.t, Side::Back, WallRule::Shared);
                assert_eq!(good.mesh.report.flipped_faces, 0);
                let tol = 1e-12 * p.mesh.size;
                for (a, b) in good.area.cells.iter().zip(&p.area.cells) {
                    assert_eq!((a.triangle, a.kind), (b.triangle, b.kind), "{}", case.name);
                    assert!(a.normal.distance(b.normal) < 1e-15, "{}: normal of triangle {}", case.name, a.triangle);
                    let (va, vb) = (a.distinct_vertices(), b.distinct_vertices());
                    assert_eq!(va.len(), vb.len());
                    for q in va {
                        assert!(vb.iter().any(|r| r.distance(q) <= tol), "{}: cell of triangle {} differs", case.name, a.triangle);
                    }
                }
            }
            Family::NonManifold => {
                assert_eq!(p.mesh.report.non_manifold_edges, 1);
                // One edge with four faces: counted once, like every edge in the reports.
                assert_eq!(r.non_manifold_edges, 1, "{}: the cell report counts the non-manifold edge more than once", case.name);
                assert_eq!(p.mesh.links.iter().flatten().filter(|l| **l == EdgeLink::NonManifold).count(), 4);
                for f in 0..p.faces() {
                    for i in 0..3 {
                        if p.mesh.links[f][i] == EdgeLink::NonManifold {
                            assert_eq!(p.mesh.dihedral_angle(f, i), None);
                        }
                    }
                }
                assert_eq!(p.mesh.report.open_components + p.mesh.report.closed_components, p.mesh.component_closed.len());
            }
            Family::VFold => {
                // The crease: dihedral angle as built, convex from the front exactly for ridges.
                let deg: Real = case.name.split_whitespace().nth(1).unwrap().parse().unwrap();
                let ridge = case.name.ends_with("ridge");
                let mut crease = 0;
                for f in 0..p.faces() {
                    for i in 0..3 {
                        let Some(a) = p.mesh.dihedral_angle(f, i) else { continue };
                        if (a - PI).abs() > 1e-6 {
                            crease += 1;
                            assert!((a - deg.to_radians()).abs() < 1e-9, "{}: dihedral angle {} deg", case.name, a.to_degrees());
                            assert_eq!(p.mesh.is_convex_edge(f, i), Some(ridge), "{}", case.name);
                        }
                    }
                }
                assert_eq!(crease, 2 * 6, "{}: crease edges seen from both sides", case.name);
            }
            Family::Holed => {
                // 8 x 12 outer boundary edges per side pair, plus the hole's rim (2 * (4 + 3)).
                assert_eq!(p.mesh.report.boundary_edges, 4 * 12 + 2 * (4 + 3), "{}", case.name);
                assert_eq!(r.boundary_edges, p.mesh.report.boundary_edges);
            }
            Family::Sphere | Family::Cuboid => {
                assert_eq!(p.mesh.report.boundary_edges, 0);
                assert_eq!(p.mesh.report.closed_components, 1);
                assert_eq!(p.mesh.report.flipped_faces, 0, "{}: generated outward", case.name);
                // Inverted input: every face flipped back to outward.
                let inverted: Vec<[u32; 3]> = soup.1.iter().map(|t| [t[0], t[2], t[1]]).collect();
                let m = common::topology(&soup.0, &inverted);
                assert_eq!(m.report.flipped_faces, soup.1.len());
                for (a, b) in m.normals.iter().zip(&p.mesh.normals) {
                    assert!(a.distance(*b) < 1e-12);
                }
            }
            _ => {}
        }
    }
}

/// Mean edge length of a soup (for the tables: the mismatch grows with t / edge).
fn mean_edge(soup: &Soup) -> Real {
    let (v, t) = soup;
    let sum: Real = t.iter().map(|f| (0..3).map(|i| v[f[i] as usize].distance(v[f[(i + 1) % 3] as usize])).sum::<Real>()).sum();
    sum / (3 * t.len()) as Real
}

#[test]
fn gap_and_overlap_volume_fractions() {
    let start = Instant::now();
    let mut rng = Rand64::new(0x5eed_0005);
    let mut jitter_rng = Rand64::new(0x5eed_0006);
    let target = 40_000;
    // (name, mesh, t, smallest radius of curvature of the smooth surface, bound on each fraction
    // in percent). The mismatch grows with t against both the edges and the radius of curvature;
    // the last two rows are deliberately thick (t beyond the crest radius; t half the box's
    // edges) and get a looser bound: there the mismatch is not small, and the table says so.
    let crest = |a: Real, w: Real| 1.0 / (a * (2.0 * PI / w).powi(2));
    let meshes: Vec<(&str, Soup, Real, Real, Real)> = vec![
        ("wavy a=0.05 w=0.5, t=0.02", generate::wavy_sheet(16, 16, 1.0, 1.0, 0.05, 0.5), 0.02, crest(0.05, 0.5), 2.0),
        (
            "wavy a=0.03 w=0.4 jittered, t=0.01",
            jitter_in_plane(generate::wavy_sheet(20, 20, 1.0, 1.0, 0.03, 0.4), 20, 20, 1.0, 1.0, 0.3, &mut jitter_rng),
            0.01,
            crest(0.03, 0.4),
            2.0,
        ),
        (
            "wavy a=0.08 w=0.3 jittered, t=0.015",
            jitter_in_plane(generate::wavy_sheet(16, 16, 1.0, 1.0, 0.08, 0.3), 16, 16, 1.0, 1.0, 0.3, &mut jitter_rng),
            0.015,
            crest(0.08, 0.3),
            2.0,
        ),
        ("sphere r=0.1 12x18, t=0.02", generate::uv_sphere(0.1, 12, 18), 0.02, 0.1, 2.0),
        ("sphere r=0.1 8x12, t=0.05", generate::uv_sphere(0.1, 8, 12), 0.05, 0.1, 2.0),
        ("saddle k=0.6, t=0.02", generate::saddle(16, 1.0, 0.6), 0.02, 1.0 / 1.2, 2.0),
        ("saddle k=1.0, t=0.03", generate::saddle(12, 1.0, 1.0), 0.03, 0.5, 2.0),
        ("box 3x3 per side, t=0.03", generate::cuboid(Vector::new(0.2, 0.3, 0.25), 3), 0.03, Real::INFINITY, 2.0),
        (
            "thick: wavy a=0.08 w=0.3 jit., t=0.03",
            jitter_in_plane(generate::wavy_sheet(16, 16, 1.0, 1.0, 0.08, 0.3), 16, 16, 1.0, 1.0, 0.3, &mut jitter_rng),
            0.03,
            crest(0.08, 0.3),
            10.0,
        ),
        ("thick: box 2x2 per side, t=0.15", generate::cuboid(Vector::new(0.2, 0.3, 0.25), 2), 0.15, Real::INFINITY, 20.0),
    ];
    eprintln!("gap / overlap volume fractions of the true thickness region behind the surface (side = back): points uniform in volume within t");
    eprintln!("of the surface and behind it by their closest feature, >= 2t from boundary edges, NOT excluded near vertices; 'far' = the subset outside every");
    eprintln!("vertex radius t/sin(a/2); pairs: overlaps between cells of faces sharing nothing / a vertex / an edge");
    eprintln!(
        "{:<38} {:>6} {:>5} {:>6} {:>7} {:>9} | {:>6} {:>7} {:>9} | pairs",
        "mesh", "t/edge", "t/R", "points", "gap %", "overlap %", "far", "gap %", "overlap %"
    );
    for (name, soup, t, radius, bound) in meshes {
        let pose = random_pose(&mut rng);
        let ratio = t / mean_edge(&soup);
        let p = build_probe(&generate::transformed(soup, &pose), t, Side::Back, WallRule::Shared);
        let fr = volume_fractions(&p, &mut rng, target, -1.0, false);
        let (g, o) = (pct(fr.gaps, fr.tested), pct(fr.overlaps, fr.tested));
        eprintln!(
            "{name:<38} {ratio:>6.2} {:>5.2} {:>6} {g:>7.3} {o:>9.3} | {:>6} {:>7.3} {:>9.3} | {:?}",
            t / radius,
            fr.tested,
            fr.far,
            pct(fr.far_gaps, fr.far),
            pct(fr.far_overlaps, fr.far),
            fr.overlap_pairs,
        );
        assert_eq!(fr.tested, target);
        // Two faces that share an edge share its wall: their cells never overlap.
        assert_eq!(fr.overlap_pairs[2], 0, "{name}: cells of edge neighbours overlap");
        assert!(g < bound && o < bound, "{name}: gap {g}%, overlap {o}%");
    }
    eprintln!("gap_and_overlap_volume_fractions: {:.1} s", start.elapsed().as_secs_f64());
}

#[test]
fn shared_walls_against_naive_prisms_on_v_folds() {
    let start = Instant::now();
    let mut rng = Rand64::new(0x5eed_0007);
    let target = 20_000;
    let t = 0.03;
    eprintln!("shared walls vs naive perpendicular prisms (WallRule::Perpendicular) on folds: volume fractions of the true thickness region within t on the");
    eprintln!("cells' side, >= 2t from the boundary edges and outside the vertex radii of the strip ends; interior crease vertices NOT excluded.");
    eprintln!("fan fold: every face touching the crease has an edge on it; v_fold (generate::v_fold): some faces touch the crease at one vertex only.");
    eprintln!("'far' = shared walls, only the points outside every vertex radius t/sin(a/2).");
    eprintln!(
        "{:<22} {:<6} {:<8} {:>6} | {:>7} {:>9} | {:>6} {:>7} {:>9} | {:>7} {:>9}",
        "fold", "side", "that is", "points", "gap %", "overlap %", "far", "gap %", "overlap %", "gap %", "overlap %"
    );
    eprintln!("{:<22} {:<6} {:<8} {:>6} | {:>17} | {:>24} | {:>17}", "", "", "", "", "shared walls", "shared walls, far", "naive prisms");
    for deg in [60, 90, 120, 150] {
        for ridge in [true, false] {
            let a = (deg as Real).to_radians();
            let shape = if ridge { "ridge" } else { "valley" };
            for (mesh_name, soup) in [("fan fold", fan_fold(a, ridge, 0.4, 1.2, 6)), ("v_fold", generate::v_fold(a, ridge, 0.4, 1.2, 6))] {
                let pose = random_pose(&mut rng);
                let soup = generate::transformed(soup, &pose);
                for side in [Side::Back, Side::Front] {
                    let sign = if side == Side::Back { -1.0 } else { 1.0 };
                    let shared = build_probe(&soup, t, side, WallRule::Shared);
                    let naive = build_probe(&soup, t, side, WallRule::Perpendicular);
                    let fs = volume_fractions(&shared, &mut rng, target, sign, true);
                    let fnv = volume_fractions(&naive, &mut rng, target, sign, true);
                    let (sg, so, ng, no) = (pct(fs.gaps, fs.tested), pct(fs.overlaps, fs.tested), pct(fnv.gaps, fnv.tested), pct(fnv.overlaps, fnv.tested));
                    // The cells' side is convex at a ridge seen from the front and at a valley
                    // seen from behind: naive prisms part there (a wedge-shaped gap along the
                    // crease); on the concave side they cross (a double-counted kite).
                    let convex_side = ridge == (side == Side::Front);
                    let name = format!("{mesh_name} {deg} {shape}");
                    eprintln!(
                        "{name:<22} {:<6} {:<8} {:>6} | {sg:>7.3} {so:>9.3} | {:>6} {:>7.3} {:>9.3} | {ng:>7.3} {no:>9.3}",
                        side.as_str(),
                        if convex_side { "convex" } else { "concave" },
                        fs.tested,
                        fs.far,
                        pct(fs.far_gaps, fs.far),
                        pct(fs.far_overlaps, fs.far),
                    );
                    if convex_side {
                        assert!(ng > 0.3, "{name} {side:?}: naive gap only {ng}%");
                        assert_eq!(fnv.overlaps, 0, "{name} {side:?}: naive overlap on the convex side");
                    } else {
                        assert!(no > 0.3, "{name} {side:?}: naive overlap only {no}%");
                        assert_eq!(fnv.gaps, 0, "{name} {side:?}: naive gap on the concave side");
                    }
                    assert_eq!(fs.overlap_pairs[2], 0, "{name} {side:?}: cells of edge neighbours overlap");
                    if mesh_name == "fan fold" {
                        assert_eq!((fs.gaps, fs.overlaps), (0, 0), "{name} {side:?}: shared walls leave gaps or overlaps");
                    } else {
                        // Faces touching the crease at one vertex keep perpendicular walls; near
                        // those vertices a mismatch remains (printed), well below the naive one.
                        assert!(2 * (fs.gaps + fs.overlaps) < fnv.gaps + fnv.overlaps, "{name} {side:?}: shared {sg}% + {so}%, naive {ng}% + {no}%");
                    }
                }
            }
        }
    }
    eprintln!("shared_walls_against_naive_prisms_on_v_folds: {:.1} s", start.elapsed().as_secs_f64());
}
