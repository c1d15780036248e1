//! Replays mesh-loader's build of each geometry it keeps: the accessor elements it copies, the
//! triangles it makes, and every index it reads.

use super::nodes::{at, text_of, tokens, InputRef};
use super::primitive::{Kind, PrimitiveInfo};
use super::walk::Walk;
use super::{COPIES_PER_BYTE, MIN_COPY_BUDGET};
use crate::limits::MAX_MESH_TRIANGLES;
use std::collections::HashMap;

impl<'a, 'i> Walk<'a, 'i> {
    /// Replays `collada::instance::build` over the geometries mesh-loader keeps.
    pub(super) fn check_build(&self, n_bytes: usize) -> Result<(), String> {
        let mut last = HashMap::new();
        for (i, (id, _)) in self.geometries.iter().enumerate() {
            let _ = last.insert(*id, i);
        }
        let budget = MIN_COPY_BUDGET.max(COPIES_PER_BYTE.saturating_mul(n_bytes as u64));
        let mut copies = 0u64;
        let mut triangles = 0u64;
        for (i, (id, mesh)) in self.geometries.iter().enumerate() {
            if last.get(id) != Some(&i) {
                continue;
            }
            // Without <vertices> and its POSITION input mesh-loader refuses the file.
            let Some(vertices) = &mesh.vertices else { continue };
            let Some(position) = vertices.position else { continue };
            for prim in &mesh.primitives {
                let Some(vertex) = prim.vertex else { continue };
                if vertex.source != vertices.id {
                    return Err(format!(
                        "{} semantic=\"VERTEX\": must name the <vertices id=\"{}\"> of its own mesh (mesh-loader 0.1.13 reaches a todo!() otherwise)",
                        at(vertex.node, Some("source")),
                        vertices.id
                    ));
                }
                let pos_len = self.accessor_len(position, "POSITION", false)?;
                let (normal_len, normal_offset) = match (prim.normal, vertices.normal) {
                    (Some(n), _) => (self.accessor_len(n, "NORMAL", false)?, n.offset),
                    (None, Some(n)) => (self.accessor_len(n, "NORMAL", false)?, vertex.offset),
                    (None, None) => (0, 0),
                };
                let (tex_len, tex_offset) = match (prim.texcoords.first(), vertices.texcoord) {
                    (Some(t), _) => (self.accessor_len(*t, "TEXCOORD", true)?, t.offset),
                    (None, Some(t)) => (self.accessor_len(t, "TEXCOORD", true)?, vertex.offset),
                    (None, None) => (0, 0),
                };
                let (color_len, color_offset) = match (prim.color, vertices.color) {
                    (Some(c), _) => (self.accessor_len(c, "COLOR", false)?, c.offset),
                    (None, Some(c)) => (self.accessor_len(c, "COLOR", false)?, vertex.offset),
                    (None, None) => (0, 0),
                };
                copies += pos_len + normal_len + tex_len + color_len;
                if copies > budget {
                    return Err(format!(
                        "{}: its primitives make mesh-loader copy more than {budget} accessor elements (each primitive copies every source it uses)",
                        at(prim.node, None)
                    ));
                }
                let faces = faces(prim);
                triangles += faces;
                if triangles > MAX_MESH_TRIANGLES as u64 {
                    return Err(format!("{}: the file has more than {MAX_MESH_TRIANGLES} triangles", at(prim.node, Some("count"))));
                }
                if faces == 0 {
                    continue;
                }
                check_faces(
                    prim,
                    vertex,
                    [
                        (vertex.offset, pos_len, "VERTEX"),
                        (normal_offset, normal_len, "NORMAL"),
                        (tex_offset, tex_len, "TEXCOORD"),
                        (color_offset, color_len, "COLOR"),
                    ],
                )?;
            }
        }
        Ok(())
    }
}

/// Triangles mesh-loader makes of a primitive (`vertex_indices_size`).
pub(super) fn faces(prim: &PrimitiveInfo<'_, '_>) -> u64 {
    match prim.kind {
        Kind::Triangles => u64::from(prim.count),
        Kind::Polylist | Kind::Polygons | Kind::TriFans | Kind::TriStrips => prim.vcount.iter().map(|&v| u64::from(v.saturating_sub(2))).sum(),
        Kind::Lines | Kind::LineStrips => 0,
    }
}

/// The indices mesh-loader reads for the faces of a primitive: within the `<p>` text, and each
/// below the length of the accessor it indexes (`roles`: offset, length, name; length 0 means the
/// accessor is not read, except for VERTEX, where it means no positions: a panic).
pub(super) fn check_faces(prim: &PrimitiveInfo<'_, '_>, vertex: InputRef<'_, '_>, roles: [(u32, u64, &str); 4]) -> Result<(), String> {
    if roles[0].1 == 0 {
        return Err(format!(
            "{}: its POSITION accessor is not read by mesh-loader (it needs stride >= 3 and 3 <param type=\"float\">), which then panics on the first index",
            at(vertex.node, Some("source"))
        ));
    }
    if prim.kind == Kind::TriStrips {
        return Err(format!("{}: mesh-loader 0.1.13 reads triangle strips as fans (wrong triangles); export triangles", at(prim.node, None)));
    }
    if matches!(prim.kind, Kind::Polylist | Kind::Polygons) {
        if let Some(v) = prim.vcount.iter().find(|&&v| v < 3) {
            return Err(format!(
                "{}: a polygon of {v} vertices; mesh-loader 0.1.13 then misreads every later polygon (at least 3 allowed)",
                at(prim.node, None)
            ));
        }
    }
    let s = prim.stride;
    let vertices_read: u64 = match prim.kind {
        Kind::Triangles => 3 * u64::from(prim.count),
        _ => prim.vcount.iter().map(|&v| u64::from(v)).sum(),
    };
    let limit = vertices_read * s;
    if limit > prim.p_len {
        return Err(format!(
            "{}: {vertices_read} vertices × {s} indices = {limit} indices, but its <p> hold {} (an <input> after the <p>, a <vcount> after it, or no <p>?)",
            at(prim.node, Some("count")),
            prim.p_len
        ));
    }
    let mut k = 0u64;
    for p in &prim.p {
        for t in tokens(text_of(*p)) {
            if k >= limit {
                return Ok(());
            }
            let value = t.parse::<u32>().map_err(|_| format!("{}: {t:?} is not an integer", at(*p, None)))?;
            for (offset, len, role) in roles {
                if u64::from(offset) == k % s && len > 0 && u64::from(value) >= len {
                    return Err(format!(
                        "{}: index {value} at position {k} ({role}, offset {offset}) must be below {len}, the size of its source",
                        at(*p, None)
                    ));
                }
            }
            k += 1;
        }
    }
    Ok(())
}
