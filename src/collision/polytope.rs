//! A thickness cell expressed in a target's frame, with its planes and edges for the SAT.

use crate::math::{Pose, Real, Vector};
use crate::thickness::ThicknessCell;

/// An edge of the cell with the outward normals of its two faces.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct CellEdge {
    pub a: Vector,
    pub b: Vector,
    pub dir: Vector,
    pub n1: Vector,
    pub n2: Vector,
}

/// A cell (at most 6 vertices, 5 planes, 9 edges) in the frame of a target.
#[derive(Clone, Debug)]
pub(crate) struct CellPolytope {
    pub verts: [Vector; 6],
    /// Outward unit normal and offset (`n . x <= d` inside): back cap, front cap, walls 0..3.
    pub planes: [(Vector, Real); 5],
    pub edges: [CellEdge; 9],
    pub edge_count: usize,
    pub back_collapsed: bool,
    pub front_collapsed: bool,
}

impl CellPolytope {
    /// The cell, given in its object's frame, seen from a frame in which the object has pose `pos`.
    pub fn new(cell: &ThicknessCell, pos: &Pose) -> CellPolytope {
        let world = cell.vertices();
        let verts = world.map(|v| pos * v);
        let rot = pos.rotation;
        let tr = pos.translation;
        let planes = cell.planes().map(|(n, d)| {
            let n2 = rot * n;
            (n2, d + n2.dot(tr))
        });
        let back_collapsed = crate::thickness::is_collapsed(&cell.back_cap);
        let front_collapsed = crate::thickness::is_collapsed(&cell.front_cap);
        let mut edges = [CellEdge::default(); 9];
        let mut edge_count = 0;
        let mut push = |a: Vector, b: Vector, f1: usize, f2: usize| {
            let d = b - a;
            let len = d.length();
            if len > 0.0 {
                edges[edge_count] = CellEdge { a, b, dir: d / len, n1: planes[f1].0, n2: planes[f2].0 };
                edge_count += 1;
            }
        };
        for i in 0..3 {
            let j = (i + 1) % 3;
            if !back_collapsed {
                push(verts[i], verts[j], 0, 2 + i);
            }
            if !front_collapsed {
                push(verts[3 + i], verts[3 + j], 1, 2 + i);
            }
            push(verts[i], verts[3 + i], 2 + (i + 2) % 3, 2 + i);
        }
        CellPolytope { verts, planes, edges, edge_count, back_collapsed, front_collapsed }
    }

    /// `[min, max]` of `dir . x` over the cell.
    #[inline]
    pub fn project(&self, dir: Vector) -> [Real; 2] {
        crate::math::project_points(&self.verts, dir)
    }

    /// The edges that exist (collapsed caps have none).
    #[inline]
    pub fn edges(&self) -> &[CellEdge] {
        &self.edges[..self.edge_count]
    }

    /// The distinct vertices.
    pub fn distinct_vertices(&self) -> Vec<Vector> {
        let mut out = Vec::with_capacity(6);
        if self.back_collapsed {
            out.push(self.verts[0]);
        } else {
            out.extend_from_slice(&self.verts[..3]);
        }
        if self.front_collapsed {
            out.push(self.verts[3]);
        } else {
            out.extend_from_slice(&self.verts[3..]);
        }
        out
    }

    /// The boundary as polygons (caps and walls), for clipping and closest points.
    pub fn faces(&self) -> Vec<Vec<Vector>> {
        let v = &self.verts;
        let mut faces = Vec::with_capacity(5);
        if !self.back_collapsed {
            faces.push(vec![v[0], v[2], v[1]]);
        }
        if !self.front_collapsed {
            faces.push(vec![v[3], v[4], v[5]]);
        }
        for i in 0..3 {
            let j = (i + 1) % 3;
            let mut f = vec![v[i], v[j], v[3 + j], v[3 + i]];
            f.dedup();
            if f.len() > 1 && f[0] == f[f.len() - 1] {
                let _ = f.pop();
            }
            faces.push(f);
        }
        faces
    }

    /// Whether `x` is inside (planes pushed out by `tol`).
    #[inline]
    pub fn contains(&self, x: Vector, tol: Real) -> bool {
        self.planes.iter().all(|(n, d)| n.dot(x) <= d + tol)
    }
}
