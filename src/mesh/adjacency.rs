//! Edge adjacency by sorting the undirected edges.
//!
//! Sorting 3 n `(edge, half-edge)` pairs is cache friendly and needs no hash map; runs of equal
//! keys are the faces around one edge.

use super::mesh_topology::{EdgeLink, TopologyReport};

/// Classifies every edge of every triangle. `Shared` links carry `consistent = true` when the two
/// faces traverse the edge in opposite directions in the input winding.
pub(super) fn link_edges(triangles: &[[u32; 3]], report: &mut TopologyReport) -> Vec<[EdgeLink; 3]> {
    let mut half_edges: Vec<(u64, u32)> = Vec::with_capacity(triangles.len() * 3);
    for (f, t) in triangles.iter().enumerate() {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            let key = ((a.min(b) as u64) << 32) | a.max(b) as u64;
            half_edges.push((key, (f * 3 + i) as u32));
        }
    }
    half_edges.sort_unstable();
    let mut links = vec![[EdgeLink::Boundary; 3]; triangles.len()];
    let mut start = 0;
    while start < half_edges.len() {
        let key = half_edges[start].0;
        let mut end = start + 1;
        while end < half_edges.len() && half_edges[end].0 == key {
            end += 1;
        }
        match end - start {
            1 => report.boundary_edges += 1,
            2 => {
                report.shared_edges += 1;
                let (h1, h2) = (half_edges[start].1 as usize, half_edges[start + 1].1 as usize);
                let (f1, i1, f2, i2) = (h1 / 3, h1 % 3, h2 / 3, h2 % 3);
                let consistent = triangles[f1][i1] != triangles[f2][i2];
                links[f1][i1] = EdgeLink::Shared { face: f2 as u32, consistent };
                links[f2][i2] = EdgeLink::Shared { face: f1 as u32, consistent };
            }
            _ => {
                report.non_manifold_edges += 1;
                for &(_, h) in &half_edges[start..end] {
                    links[h as usize / 3][h as usize % 3] = EdgeLink::NonManifold;
                }
            }
        }
        start = end;
    }
    links
}
