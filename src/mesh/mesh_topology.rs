//! The welded, oriented mesh and the report of what was done to it.

use crate::math::{Real, Vector};
use serde::Serialize;

/// What lies across one edge of a face (edge `i` of face `[a, b, c]` runs from vertex `i` to `i + 1`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EdgeLink {
    /// No other face uses this edge.
    Boundary,
    /// Three or more faces use this edge.
    NonManifold,
    /// Exactly one other face uses this edge. `consistent` is true when the two faces traverse the
    /// edge in opposite directions (after orientation); false marks a non-orientable seam.
    Shared {
        /// Index of the other face in [`MeshTopology::triangles`].
        face: u32,
        /// The two windings agree across the edge.
        consistent: bool,
    },
}

/// Tolerances of the topology stage, relative to the diagonal `D` of the mesh's bounding box.
#[derive(Clone, Copy, Debug)]
pub struct TopologySettings {
    /// Vertices closer than `weld_tolerance * D` are merged (unit: fraction of `D`).
    pub weld_tolerance: Real,
    /// Triangles with an area below `degenerate_area * D^2` are dropped (unit: fraction of `D^2`).
    pub degenerate_area: Real,
}

impl Default for TopologySettings {
    fn default() -> Self {
        // 1e-7 D is below the resolution of an f32 STL coordinate a few metres from the origin
        // relative to its own size (2^-24 ~ 6e-8), so bit-identical repeats always weld, and
        // distinct vertices of any mesh that an f32 format can store stay apart.
        TopologySettings { weld_tolerance: 1e-7, degenerate_area: 1e-14 }
    }
}

/// Counts from the topology stage. Edges are counted once (undirected).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize)]
pub struct TopologyReport {
    /// Triangles in the input, in file order.
    pub input_triangles: usize,
    /// Vertices in the input.
    pub input_vertices: usize,
    /// Vertices after welding.
    pub vertices: usize,
    /// Triangles dropped because they are degenerate (repeated vertex or tiny area).
    pub degenerate_triangles: usize,
    /// Triangles dropped because another triangle uses the same three vertices.
    pub duplicate_triangles: usize,
    /// Edges used by one face.
    pub boundary_edges: usize,
    /// Edges used by two faces.
    pub shared_edges: usize,
    /// Edges used by three or more faces.
    pub non_manifold_edges: usize,
    /// Shared edges whose two faces cannot be wound consistently (non-orientable seams).
    pub inconsistent_edges: usize,
    /// Faces whose winding was reversed by the orientation step.
    pub flipped_faces: usize,
    /// Connected components (over shared edges) with no boundary and no non-manifold edge.
    pub closed_components: usize,
    /// The other connected components.
    pub open_components: usize,
}

/// A welded triangle mesh with consistent winding and edge adjacency.
#[derive(Clone, Debug)]
pub struct MeshTopology {
    /// Welded vertices.
    pub vertices: Vec<Vector>,
    /// Oriented triangles (indices into `vertices`).
    pub triangles: Vec<[u32; 3]>,
    /// For each triangle, its index in the input before anything was dropped.
    pub source_triangle: Vec<u32>,
    /// Unit normal of each triangle, from its (oriented) winding: the front side.
    pub normals: Vec<Vector>,
    /// What lies across edge `i` (from vertex `i` to `i + 1`) of each triangle.
    pub links: Vec<[EdgeLink; 3]>,
    /// Connected component of each triangle.
    pub component: Vec<u32>,
    /// Whether each component is closed.
    pub component_closed: Vec<bool>,
    /// Diagonal of the bounding box of the input (metres); the scale of every relative tolerance.
    pub size: Real,
    /// What the stage did.
    pub report: TopologyReport,
}

/// A triangle soup that cannot be turned into a mesh.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum MeshError {
    /// No triangles at all.
    #[error("the mesh has no triangles")]
    Empty,
    /// Every triangle is degenerate.
    #[error("all {0} triangles of the mesh are degenerate (zero area)")]
    AllDegenerate(usize),
    /// A vertex coordinate is NaN or infinite.
    #[error("vertex {index} has a non-finite coordinate ({x}, {y}, {z})")]
    NonFiniteVertex {
        /// Index of the vertex in the input.
        index: usize,
        /// Its coordinates.
        x: Real,
        /// Its coordinates.
        y: Real,
        /// Its coordinates.
        z: Real,
    },
    /// A triangle refers to a vertex that does not exist.
    #[error("triangle {triangle} refers to vertex {vertex}, but the mesh has {vertices} vertices")]
    IndexOutOfRange {
        /// Index of the triangle in the input.
        triangle: usize,
        /// The bad vertex index.
        vertex: u32,
        /// Number of vertices.
        vertices: usize,
    },
}

impl MeshTopology {
    /// Builds the topology of an indexed triangle soup.
    ///
    /// ```
    /// use thickness_collision::math::Vector;
    /// use thickness_collision::mesh::{MeshTopology, TopologySettings};
    /// // Two triangles of a unit square, the second wound the wrong way.
    /// let v = [Vector::new(0., 0., 0.), Vector::new(1., 0., 0.), Vector::new(1., 1., 0.), Vector::new(0., 1., 0.)];
    /// let mesh = MeshTopology::build(&v, &[[0, 1, 2], [0, 3, 2]], &TopologySettings::default()).unwrap();
    /// assert_eq!(mesh.report.flipped_faces, 1);
    /// assert_eq!(mesh.report.boundary_edges, 4);
    /// assert!(mesh.normals.iter().all(|n| n.z > 0.99) || mesh.normals.iter().all(|n| n.z < -0.99));
    /// ```
    pub fn build(vertices: &[Vector], triangles: &[[u32; 3]], settings: &TopologySettings) -> Result<MeshTopology, MeshError> {
        let welded = super::weld(vertices, triangles, settings)?;
        Ok(Self::from_welded(welded))
    }

    /// Builds adjacency and orientation on an already welded mesh.
    pub fn from_welded(welded: super::WeldedMesh) -> MeshTopology {
        let super::WeldedMesh { vertices, triangles, source_triangle, size, mut report } = welded;
        let links = super::adjacency::link_edges(&triangles, &mut report);
        let mut mesh = MeshTopology {
            vertices,
            triangles,
            source_triangle,
            normals: Vec::new(),
            links,
            component: Vec::new(),
            component_closed: Vec::new(),
            size,
            report,
        };
        super::orient::orient(&mut mesh);
        mesh.normals = mesh
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| mesh.vertices[i as usize]);
                (b - a).cross(c - a).normalize_or_zero()
            })
            .collect();
        mesh
    }

    /// The three corners of triangle `f`.
    #[inline]
    pub fn corners(&self, f: usize) -> [Vector; 3] {
        self.triangles[f].map(|i| self.vertices[i as usize])
    }

    /// The dihedral angle across edge `i` of face `f`, in radians: `pi` for a flat continuation,
    /// towards 0 for a sheet folded back onto itself. `None` unless the edge is shared.
    pub fn dihedral_angle(&self, f: usize, i: usize) -> Option<Real> {
        match self.links[f][i] {
            EdgeLink::Shared { face, .. } => {
                let c = self.normals[f].dot(self.normals[face as usize]).clamp(-1.0, 1.0);
                Some(std::f64::consts::PI - c.acos())
            }
            _ => None,
        }
    }

    /// Whether the shared edge `i` of face `f` is convex seen from the front (a ridge), as opposed
    /// to concave (a valley). `None` unless the edge is shared.
    pub fn is_convex_edge(&self, f: usize, i: usize) -> Option<bool> {
        match self.links[f][i] {
            EdgeLink::Shared { face, .. } => {
                let g = face as usize;
                let apex = self.triangles[g].iter().copied().find(|v| !self.triangles[f].contains(v))?;
                let p = self.vertices[apex as usize] - self.vertices[self.triangles[f][i] as usize];
                Some(p.dot(self.normals[f]) < 0.0)
            }
            _ => None,
        }
    }
}
