//! Mesh topology: from a triangle soup to a welded, consistently oriented mesh with edge adjacency.
//!
//! The thickness rule needs, for every edge of every face, the face across it and whether the two
//! are wound consistently. Scanned and exported meshes rarely give that directly: vertices are
//! repeated per triangle (STL), slivers and duplicates occur, and one-layer sheets are often wound
//! at random. The pipeline is:
//! 1. [`weld`]: merge vertices closer than a tolerance relative to the mesh size, drop degenerate and
//!    duplicate triangles (counted, never silently);
//! 2. adjacency: sort the undirected edges and classify them as boundary (1 face), shared (2 faces)
//!    or non-manifold (3+ faces);
//! 3. orientation: flood every connected component over its shared edges and flip faces so that
//!    each shared edge is traversed in opposite directions; a closed component then faces outward
//!    (positive signed volume), an open one keeps the winding of the larger area.

mod adjacency;
pub mod generate;
mod mesh_topology;
mod orient;
mod weld;

pub use self::mesh_topology::{EdgeLink, MeshError, MeshTopology, TopologyReport, TopologySettings};
pub use self::weld::{weld, WeldedMesh};
