//! Building the cells of a whole mesh, and the build report.

use super::thickness_cell::{CellKind, Side, ThicknessCell};
use crate::math::{intersect_three_planes, Real, Vector};
use crate::mesh::{EdgeLink, MeshTopology, TopologyReport};
use rustc_hash::FxHashSet;
use serde::Serialize;

/// Which side walls the cells get.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum WallRule {
    /// The patent's rule: walls shared with the neighbours (bisecting planes). The product.
    #[default]
    Shared,
    /// Every wall perpendicular to its own face: the naive per-triangle prism, kept only to
    /// measure what the shared walls buy (gaps at convex edges, overlaps at concave ones).
    Perpendicular,
}

/// Settings of the cell stage.
#[derive(Clone, Copy, Debug)]
pub struct ThicknessSettings {
    /// Thickness `t` (unit: metre), `> 0`.
    pub thickness: Real,
    /// Where the volume goes.
    pub side: Side,
    /// Two faces folded back onto each other by less than this angle get perpendicular walls
    /// (unit: radian; default 1 degree, from design.md).
    pub fold_angle: Real,
    /// The side-wall rule.
    pub walls: WallRule,
}

impl Default for ThicknessSettings {
    fn default() -> Self {
        ThicknessSettings { thickness: 0.02, side: Side::Back, fold_angle: 1f64.to_radians(), walls: WallRule::Shared }
    }
}

/// Counts from the cell stage; edges are counted once.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct ThicknessReport {
    /// What the topology stage did.
    pub topology: TopologyReport,
    /// Cells built.
    pub cells: usize,
    /// Cells that are tetrahedra (`0 < h <= t`).
    pub tetrahedra: usize,
    /// Frustums from converging walls (`h > t`), the claim's ratioed areas.
    pub ratioed: usize,
    /// Frustums from parallel walls (`h` infinite).
    pub prisms: usize,
    /// Frustums from diverging walls (`h <= 0`).
    pub diverging: usize,
    /// Faces that got no cell: degenerate triangles dropped by the topology stage, and faces whose
    /// walls do not form a cell.
    pub degenerate_skipped: usize,
    /// Edges with a perpendicular wall because they are boundary edges.
    pub boundary_edges: usize,
    /// ... because three or more faces share them.
    pub non_manifold_edges: usize,
    /// ... because their two faces are wound inconsistently.
    pub inconsistent_edges: usize,
    /// ... because the two faces fold back onto each other.
    pub folded_edges: usize,
    /// Faces whose winding the orientation step reversed.
    pub flipped_faces: usize,
}

/// The thickness cells of one mesh, in the mesh's frame.
#[derive(Clone, Debug)]
pub struct ThicknessArea {
    /// One cell per non-degenerate face (two caps for `Side::Both` are one cell).
    pub cells: Vec<ThicknessCell>,
    /// The thickness used (metres).
    pub thickness: Real,
    /// The side used.
    pub side: Side,
    /// What was built.
    pub report: ThicknessReport,
}

/// Settings that cannot build cells.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum ThicknessError {
    /// The thickness is not a positive finite number.
    #[error("thickness must be a positive number of metres, got {0}")]
    BadThickness(Real),
}

impl ThicknessArea {
    /// Builds the cell of every face of `mesh`.
    ///
    /// ```
    /// use thickness_collision::math::Vector;
    /// use thickness_collision::mesh::{MeshTopology, TopologySettings};
    /// use thickness_collision::thickness::{CellKind, ThicknessArea, ThicknessSettings};
    /// let v = [Vector::new(0., 0., 0.), Vector::new(1., 0., 0.), Vector::new(0., 1., 0.)];
    /// let mesh = MeshTopology::build(&v, &[[0, 1, 2]], &TopologySettings::default()).unwrap();
    /// let area = ThicknessArea::build(&mesh, &ThicknessSettings { thickness: 0.01, ..Default::default() }).unwrap();
    /// // One flat triangle: a right prism 1 cm deep behind the face (+z is the front).
    /// assert_eq!(area.cells[0].kind, CellKind::Prism);
    /// assert!((area.cells[0].back_cap[0].z + 0.01).abs() < 1e-15);
    /// ```
    pub fn build(mesh: &MeshTopology, settings: &ThicknessSettings) -> Result<ThicknessArea, ThicknessError> {
        let t = settings.thickness;
        if !(t > 0.0 && t.is_finite()) {
            return Err(ThicknessError::BadThickness(t));
        }
        let mut report = ThicknessReport {
            topology: mesh.report.clone(),
            degenerate_skipped: mesh.report.degenerate_triangles,
            flipped_faces: mesh.report.flipped_faces,
            ..ThicknessReport::default()
        };
        let fold_cos = settings.fold_angle.cos();
        // Every face on a non-manifold edge sees it; count each edge once (by its vertex pair).
        let mut non_manifold: FxHashSet<(u32, u32)> = FxHashSet::default();
        let mut cells = Vec::with_capacity(mesh.triangles.len());
        for f in 0..mesh.triangles.len() {
            let p = mesh.corners(f);
            let n = mesh.normals[f];
            let mut walls = [Vector::ZERO; 3];
            for i in 0..3 {
                let mut m = n;
                match mesh.links[f][i] {
                    EdgeLink::Boundary => report.boundary_edges += 1,
                    EdgeLink::NonManifold => {
                        let (a, b) = (mesh.triangles[f][i], mesh.triangles[f][(i + 1) % 3]);
                        let _ = non_manifold.insert((a.min(b), a.max(b)));
                    }
                    EdgeLink::Shared { face, consistent } => {
                        let first = (f as u32) < face;
                        let ng = mesh.normals[face as usize];
                        if !consistent {
                            report.inconsistent_edges += first as usize;
                        } else if n.dot(ng) < -fold_cos {
                            report.folded_edges += first as usize;
                        } else if settings.walls == WallRule::Shared {
                            m = n + ng;
                        }
                    }
                }
                // m x e points into the face for a counter-clockwise face whenever m . n > 0.
                walls[i] = (m.cross(p[(i + 1) % 3] - p[i])).normalize_or_zero();
            }
            match face_cell(p, n, walls, t, settings.side) {
                Some((back_cap, front_cap, kind)) => {
                    match kind {
                        CellKind::Tetrahedron => report.tetrahedra += 1,
                        CellKind::Ratioed => report.ratioed += 1,
                        CellKind::Prism => report.prisms += 1,
                        CellKind::Diverging => report.diverging += 1,
                    }
                    cells.push(ThicknessCell { back_cap, front_cap, normal: n, plane_offset: n.dot(p[0]), triangle: mesh.source_triangle[f], kind });
                }
                None => report.degenerate_skipped += 1,
            }
        }
        report.non_manifold_edges = non_manifold.len();
        report.cells = cells.len();
        Ok(ThicknessArea { cells, thickness: t, side: settings.side, report })
    }
}

/// The walls' cross point and its height above the face along `+n` (`None`: parallel walls).
#[inline]
fn cross_point(p: [Vector; 3], n: Vector, walls: [Vector; 3]) -> Option<(Vector, Real)> {
    // 1e-12: below it the cross point is farther than ~1e12 face sizes away, a prism in all but name.
    let c = intersect_three_planes(walls, [0, 1, 2].map(|i| walls[i].dot(p[i])), 1e-12)?;
    Some((c, n.dot(c - p[0])))
}

/// The two caps and the kind of the cell of face `p` (normal `n`, inward wall normals `walls`).
#[inline]
fn face_cell(p: [Vector; 3], n: Vector, walls: [Vector; 3], t: Real, side: Side) -> Option<([Vector; 3], [Vector; 3], CellKind)> {
    if walls.contains(&Vector::ZERO) {
        return None;
    }
    let cross = cross_point(p, n, walls);
    let h_front = cross.map(|(_, h)| h);
    // Extent on one side (sign: +1 front, -1 back) and the kind that side gives.
    let extent = |sign: Real| -> (Real, CellKind) {
        match h_front.map(|h| sign * h) {
            None => (t, CellKind::Prism),
            Some(h) if h <= 0.0 => (t, CellKind::Diverging),
            Some(h) if h <= t => (h, CellKind::Tetrahedron),
            Some(_) => (t, CellKind::Ratioed),
        }
    };
    let (back, front, kind) = match side {
        Side::Back => {
            let (e, k) = extent(-1.0);
            (e, 0.0, k)
        }
        Side::Front => {
            let (e, k) = extent(1.0);
            (0.0, e, k)
        }
        Side::Both => {
            let (eb, kb) = extent(-1.0);
            let (ef, kf) = extent(1.0);
            // One side converges (or both are parallel): that side names the cell.
            let k = if kb == CellKind::Diverging { kf } else { kb };
            (eb, ef, k)
        }
    };
    let cap = |s: Real| match cross {
        Some((c, h)) if s == h => Some([c; 3]),
        _ => cap_at(p, n, walls, s),
    };
    let back_cap = cap(-back)?;
    let front_cap = cap(front)?;
    Some((back_cap, front_cap, kind))
}

/// The cap at signed height `s` along `n`: vertex `i` where the walls through corner `i` meet the
/// plane `n . x = n . p0 + s`. Computed from the walls, not as `v + (c - v) s / h`, which loses
/// precision as `h` grows.
#[inline]
fn cap_at(p: [Vector; 3], n: Vector, walls: [Vector; 3], s: Real) -> Option<[Vector; 3]> {
    if s == 0.0 {
        return Some(p);
    }
    let mut cap = [Vector::ZERO; 3];
    for i in 0..3 {
        let u = walls[(i + 2) % 3].cross(walls[i]);
        let q = p[i] + u * (s / n.dot(u));
        if !q.is_finite() {
            return None;
        }
        cap[i] = q;
    }
    Some(cap)
}
