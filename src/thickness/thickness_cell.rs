//! One thickness cell: a convex polyhedron of at most 6 vertices and 5 faces.

use crate::math::{Real, Vector};
use serde::{Deserialize, Serialize};

/// Where the volume of a thin surface goes, relative to the front normal `n` of each face.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Side {
    /// Along `-n`, behind the visible face (the default).
    #[default]
    Back,
    /// Along `+n`.
    Front,
    /// One cell spanning both sides.
    Both,
}

impl Side {
    /// The name used in parameters and reports.
    pub fn as_str(self) -> &'static str {
        match self {
            Side::Back => "back",
            Side::Front => "front",
            Side::Both => "both",
        }
    }
}

impl std::str::FromStr for Side {
    type Err = String;

    fn from_str(s: &str) -> Result<Side, String> {
        match s {
            "back" => Ok(Side::Back),
            "front" => Ok(Side::Front),
            "both" => Ok(Side::Both),
            _ => Err(format!("'{s}' is not a side (back, front or both)")),
        }
    }
}

/// How the cell of a face was formed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum CellKind {
    /// The walls meet at the cross point within the thickness: the face and the cross point.
    Tetrahedron,
    /// The walls converge beyond the thickness: a frustum, the claim's ratioed area (ratio `t/h`).
    Ratioed,
    /// The walls are parallel (a flat strip): a prism of height `t`.
    Prism,
    /// The walls diverge (cross point in front of the face): a frustum wider than the face.
    Diverging,
}

/// The thickness cell of one triangle.
///
/// The cell is the convex hull of two triangular caps across the face normal `normal`: `back_cap`
/// lies farther along `-normal`, `front_cap` farther along `+normal`. Vertex `i` of both caps lies on
/// the side walls through corner `i` of the face. A cap collapsed to one point (all three vertices
/// equal) is the apex of a tetrahedron. Coordinates are in the frame of the mesh (metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThicknessCell {
    /// The cap farthest behind the face (along `-normal`).
    pub back_cap: [Vector; 3],
    /// The cap farthest in front of the face (along `+normal`).
    pub front_cap: [Vector; 3],
    /// Unit front normal of the face (from its oriented winding).
    pub normal: Vector,
    /// `normal . x` on the face's plane.
    pub plane_offset: Real,
    /// Index of the face's triangle in the input, before anything was dropped.
    pub triangle: u32,
    /// How the cell was formed.
    pub kind: CellKind,
}

impl ThicknessCell {
    /// The six cap vertices, back cap first (a collapsed cap repeats its apex).
    #[inline]
    pub fn vertices(&self) -> [Vector; 6] {
        let [a, b, c] = self.back_cap;
        let [d, e, f] = self.front_cap;
        [a, b, c, d, e, f]
    }

    /// The distinct vertices: 4 for a tetrahedron, 6 for a frustum.
    pub fn distinct_vertices(&self) -> Vec<Vector> {
        let mut out = Vec::with_capacity(6);
        for cap in [self.back_cap, self.front_cap] {
            if is_collapsed(&cap) {
                out.push(cap[0]);
            } else {
                out.extend_from_slice(&cap);
            }
        }
        out
    }

    /// Extent of the cell along `normal`, as `[min, max]` of `normal . x`.
    #[inline]
    pub fn normal_range(&self) -> [Real; 2] {
        [self.normal.dot(self.back_cap[0]), self.normal.dot(self.front_cap[0])]
    }

    /// The bounding planes as `(outward unit normal, offset)`: `normal . x <= offset` inside.
    /// The caps first (back, front), then the walls through face edges 0, 1, 2. A collapsed cap
    /// still yields its plane (through the apex), which then only touches the cell.
    pub fn planes(&self) -> [(Vector, Real); 5] {
        let n = self.normal;
        let mut out = [(-n, -n.dot(self.back_cap[0])), (n, n.dot(self.front_cap[0])), (n, 0.0), (n, 0.0), (n, 0.0)];
        for i in 0..3 {
            let w = self.wall_normal(i);
            out[2 + i] = (w, w.dot(self.front_cap[i].lerp(self.back_cap[i], 0.5)));
        }
        out
    }

    /// Outward unit normal of the wall through face edge `i` (from corner `i` to `i + 1`).
    pub fn wall_normal(&self, i: usize) -> Vector {
        let j = (i + 1) % 3;
        // The longer cap gives the better-conditioned edge direction.
        let (eb, ef) = (self.back_cap[j] - self.back_cap[i], self.front_cap[j] - self.front_cap[i]);
        let edge = if eb.length_squared() > ef.length_squared() { eb } else { ef };
        let lateral = (self.front_cap[i] - self.back_cap[i]) + (self.front_cap[j] - self.back_cap[j]);
        let w = edge.cross(lateral).normalize_or_zero();
        // The opposite corner is inside: orient away from it.
        let k = (i + 2) % 3;
        let inside = self.front_cap[k] + self.back_cap[k] - self.front_cap[i] - self.back_cap[i];
        if w.dot(inside) > 0.0 {
            -w
        } else {
            w
        }
    }

    /// Whether `x` lies in the cell, with the planes pushed out by `tol` (negative `tol` asks for
    /// the strict interior, `tol` metres inside every plane).
    pub fn contains_point(&self, x: Vector, tol: Real) -> bool {
        self.planes().iter().all(|&(n, d)| n.dot(x) <= d + tol)
    }

    /// The face's corners (on the face plane), recovered from the caps.
    pub fn face(&self) -> [Vector; 3] {
        let [b0, f0] = self.normal_range();
        let (lo, hi) = (self.plane_offset - b0, f0 - self.plane_offset);
        let span = lo + hi;
        if span <= 0.0 {
            return self.front_cap;
        }
        std::array::from_fn(|i| self.back_cap[i].lerp(self.front_cap[i], lo / span))
    }
}

/// Whether the three points of a cap coincide (an apex).
#[inline]
pub fn is_collapsed(cap: &[Vector; 3]) -> bool {
    cap[0] == cap[1] && cap[1] == cap[2]
}
