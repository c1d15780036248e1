//! Vertex welding and removal of degenerate and duplicate triangles.
//!
//! A hash grid with cells of twice the tolerance: the points within the tolerance of `p` lie in
//! the at most 2x2x2 cells covering `[p - tol, p + tol]`, so each vertex costs eight lookups.
//! Welding is greedy (the first vertex of a cluster becomes its representative), which is exact
//! for repeated coordinates, the case that matters for STL files.

use super::mesh_topology::{MeshError, TopologyReport, TopologySettings};
use crate::math::{Real, Vector};
use rustc_hash::{FxHashMap, FxHashSet};

/// A triangle soup after welding, before adjacency.
#[derive(Clone, Debug)]
pub struct WeldedMesh {
    /// Representative vertices.
    pub vertices: Vec<Vector>,
    /// Triangles that survived, in input order.
    pub triangles: Vec<[u32; 3]>,
    /// Input index of each surviving triangle.
    pub source_triangle: Vec<u32>,
    /// Diagonal of the input's bounding box (metres).
    pub size: Real,
    /// Counts so far (vertices, degenerate, duplicate).
    pub report: TopologyReport,
}

/// Welds the vertices of an indexed triangle soup and drops degenerate and duplicate triangles.
pub fn weld(vertices: &[Vector], triangles: &[[u32; 3]], settings: &TopologySettings) -> Result<WeldedMesh, MeshError> {
    if triangles.is_empty() {
        return Err(MeshError::Empty);
    }
    let mut lo = Vector::splat(Real::INFINITY);
    let mut hi = Vector::splat(Real::NEG_INFINITY);
    for (index, v) in vertices.iter().enumerate() {
        if !v.is_finite() {
            return Err(MeshError::NonFiniteVertex { index, x: v.x, y: v.y, z: v.z });
        }
        lo = lo.min(*v);
        hi = hi.max(*v);
    }
    for (triangle, t) in triangles.iter().enumerate() {
        if let Some(&vertex) = t.iter().find(|&&i| i as usize >= vertices.len()) {
            return Err(MeshError::IndexOutOfRange { triangle, vertex, vertices: vertices.len() });
        }
    }
    let size = (hi - lo).length();
    let tol = settings.weld_tolerance * size;
    let remap = weld_vertices(vertices, tol);
    let mut welded: Vec<Vector> = Vec::new();
    let mut new_index = vec![u32::MAX; vertices.len()];
    // Renumber representatives densely, in order of first use.
    for (i, &r) in remap.iter().enumerate() {
        if r as usize == i {
            new_index[i] = welded.len() as u32;
            welded.push(vertices[i]);
        }
    }
    let min_double_area = 2.0 * settings.degenerate_area * size * size;
    let mut report = TopologyReport { input_triangles: triangles.len(), input_vertices: vertices.len(), vertices: welded.len(), ..TopologyReport::default() };
    let mut seen: FxHashSet<[u32; 3]> = FxHashSet::default();
    seen.reserve(triangles.len());
    let mut out = Vec::with_capacity(triangles.len());
    let mut source = Vec::with_capacity(triangles.len());
    for (i, t) in triangles.iter().enumerate() {
        let w = t.map(|v| new_index[remap[v as usize] as usize]);
        let [a, b, c] = w.map(|v| welded[v as usize]);
        let degenerate = w[0] == w[1] || w[1] == w[2] || w[0] == w[2] || !((b - a).cross(c - a).length() > min_double_area);
        if degenerate {
            report.degenerate_triangles += 1;
            continue;
        }
        let mut key = w;
        key.sort_unstable();
        if !seen.insert(key) {
            report.duplicate_triangles += 1;
            continue;
        }
        out.push(w);
        source.push(i as u32);
    }
    if out.is_empty() {
        return Err(MeshError::AllDegenerate(triangles.len()));
    }
    Ok(WeldedMesh { vertices: welded, triangles: out, source_triangle: source, size, report })
}

/// For each vertex, the index of its representative (itself if it is one).
fn weld_vertices(vertices: &[Vector], tol: Real) -> Vec<u32> {
    let mut remap = Vec::with_capacity(vertices.len());
    if !(tol > 0.0) {
        // A mesh of size zero has nothing to weld; the degenerate test then drops everything.
        remap.extend(0..vertices.len() as u32);
        return remap;
    }
    let cell = 2.0 * tol;
    let key = |p: Vector| -> [i64; 3] {
        let q = (p / cell).floor();
        [q.x as i64, q.y as i64, q.z as i64]
    };
    // Head of a linked list of representatives per grid cell; `next` chains them.
    let mut heads: FxHashMap<[i64; 3], u32> = FxHashMap::default();
    heads.reserve(vertices.len() / 2);
    let mut next: Vec<u32> = vec![u32::MAX; vertices.len()];
    let tol2 = tol * tol;
    for (i, &p) in vertices.iter().enumerate() {
        let lo = key(p - Vector::splat(tol));
        let hi = key(p + Vector::splat(tol));
        let mut found = u32::MAX;
        'search: for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    let mut r = heads.get(&[x, y, z]).copied().unwrap_or(u32::MAX);
                    while r != u32::MAX {
                        if vertices[r as usize].distance_squared(p) <= tol2 {
                            found = r;
                            break 'search;
                        }
                        r = next[r as usize];
                    }
                }
            }
        }
        if found == u32::MAX {
            let slot = heads.entry(key(p)).or_insert(u32::MAX);
            next[i] = *slot;
            *slot = i as u32;
            found = i as u32;
        }
        remap.push(found);
    }
    remap
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn repeated_and_nearby_vertices_weld_distant_ones_do_not() {
        let v = [
            Vector::new(0.0, 0.0, 0.0),
            Vector::new(1.0, 0.0, 0.0),
            Vector::new(0.0, 1.0, 0.0),
            Vector::new(1.0, 0.0, 1e-9), // within 1e-7 * sqrt(2)
            Vector::new(0.0, 1.0, 0.0),
            Vector::new(1.0, 1.0, 0.0),
        ];
        let m = weld(&v, &[[0, 1, 2], [3, 5, 4]], &TopologySettings::default()).unwrap();
        assert_eq!(m.vertices.len(), 4);
        assert_eq!(m.triangles[1][0], m.triangles[0][1]);
        assert_eq!(m.triangles[1][2], m.triangles[0][2]);
    }

    #[test]
    fn degenerate_and_duplicate_triangles_are_counted_and_dropped() {
        let v = [Vector::new(0.0, 0.0, 0.0), Vector::new(1.0, 0.0, 0.0), Vector::new(0.0, 1.0, 0.0), Vector::new(2.0, 0.0, 0.0)];
        let m = weld(&v, &[[0, 1, 2], [0, 0, 1], [0, 1, 3], [2, 0, 1], [0, 2, 1]], &TopologySettings::default()).unwrap();
        assert_eq!(m.report.degenerate_triangles, 2); // repeated index, collinear
        assert_eq!(m.report.duplicate_triangles, 2); // same vertex set, either winding
        assert_eq!(m.source_triangle, vec![0]);
    }

    #[test]
    fn bad_input_is_an_error() {
        let v = [Vector::new(0.0, 0.0, 0.0), Vector::new(1.0, Real::NAN, 0.0), Vector::new(0.0, 1.0, 0.0)];
        assert!(matches!(weld(&v, &[[0, 1, 2]], &TopologySettings::default()), Err(MeshError::NonFiniteVertex { index: 1, .. })));
        assert_eq!(weld(&v[..1], &[], &TopologySettings::default()).err(), Some(MeshError::Empty));
        let ok = [Vector::ZERO, Vector::X, Vector::Y];
        assert!(matches!(weld(&ok, &[[0, 1, 7]], &TopologySettings::default()), Err(MeshError::IndexOutOfRange { vertex: 7, .. })));
    }
}
