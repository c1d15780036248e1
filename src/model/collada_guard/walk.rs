//! What mesh-loader keeps of a COLLADA document while it parses it (sources, arrays, vertices
//! and geometries by id), with the reservations parsing makes, and the accessor lookups that the
//! build then does.

use super::nodes::{at, attr_u32, elements, input_ref, required_u32, text_of, url, InputRef};
use super::primitive::{primitive, Kind, PrimitiveInfo};
use roxmltree::Node;
use std::collections::HashMap;

pub(super) struct AccessorInfo<'a, 'i> {
    pub(super) node: Node<'a, 'i>,
    pub(super) count: u32,
    pub(super) stride: u32,
    pub(super) array: &'a str,
    pub(super) params: usize,
    pub(super) all_float: bool,
}

pub(super) struct ArrayInfo<'a, 'i> {
    pub(super) node: Node<'a, 'i>,
    pub(super) float: bool,
    pub(super) len: u64,
}

#[derive(Default)]
pub(super) struct VerticesInfo<'a, 'i> {
    pub(super) id: &'a str,
    pub(super) position: Option<InputRef<'a, 'i>>,
    pub(super) normal: Option<InputRef<'a, 'i>>,
    pub(super) texcoord: Option<InputRef<'a, 'i>>,
    pub(super) color: Option<InputRef<'a, 'i>>,
}

pub(super) struct MeshInfo<'a, 'i> {
    pub(super) vertices: Option<VerticesInfo<'a, 'i>>,
    pub(super) primitives: Vec<PrimitiveInfo<'a, 'i>>,
}

/// What mesh-loader keeps of the document: sources by id, arrays by id, geometries in order.
#[derive(Default)]
pub(super) struct Walk<'a, 'i> {
    pub(super) accessors: HashMap<&'a str, AccessorInfo<'a, 'i>>,
    pub(super) arrays: HashMap<&'a str, ArrayInfo<'a, 'i>>,
    pub(super) geometries: Vec<(&'a str, MeshInfo<'a, 'i>)>,
}

impl<'a, 'i> Walk<'a, 'i> {
    pub(super) fn geometry(&mut self, node: Node<'a, 'i>) -> Result<(), String> {
        let mut mesh = None;
        for child in elements(node) {
            match child.tag_name().name() {
                "mesh" => mesh = Some(self.mesh(child)?),
                // mesh-loader drops the geometry (the sources of a <mesh> before it stay).
                "convex_mesh" | "spline" | "brep" => return Ok(()),
                _ => {}
            }
        }
        if let (Some(id), Some(mesh)) = (node.attribute("id"), mesh) {
            self.geometries.push((id, mesh));
        }
        Ok(())
    }

    pub(super) fn mesh(&mut self, node: Node<'a, 'i>) -> Result<MeshInfo<'a, 'i>, String> {
        let mut mesh = MeshInfo { vertices: None, primitives: Vec::new() };
        for child in elements(node) {
            let name = child.tag_name().name();
            match name {
                "source" => self.source(child)?,
                "vertices" => mesh.vertices = Some(vertices(child)?),
                _ => {
                    if let Some(kind) = Kind::of(name) {
                        mesh.primitives.push(primitive(child, kind)?);
                    }
                }
            }
        }
        Ok(mesh)
    }

    pub(super) fn source(&mut self, node: Node<'a, 'i>) -> Result<(), String> {
        let mut array = None;
        let mut accessor = None;
        for child in elements(node) {
            match child.tag_name().name() {
                name @ ("float_array" | "IDREF_array" | "Name_array") => {
                    let count = required_u32(child, "count")?;
                    let text = text_of(child);
                    let float = name == "float_array";
                    if !text.is_empty() && float && u64::from(count) > text.len() as u64 {
                        // mesh-loader reserves `count` floats before reading the text.
                        return Err(format!("{}: more values than its {} characters of text can hold", at(child, Some("count")), text.len()));
                    }
                    if !text.is_empty() && !float && count > 0 {
                        return Err(format!(
                            "{}: a non-empty <{name}> in a mesh <source> makes mesh-loader 0.1.13 loop forever; only <float_array> is read",
                            at(child, Some("count"))
                        ));
                    }
                    let len = if text.is_empty() { 0 } else { u64::from(count) };
                    if let Some(id) = child.attribute("id") {
                        array = Some((id, ArrayInfo { node: child, float, len }));
                    }
                }
                "technique_common" => {
                    for a in elements(child).filter(|n| n.tag_name().name() == "accessor") {
                        accessor = Some(accessor_info(a)?);
                    }
                }
                _ => {}
            }
        }
        if let (Some(id), Some(accessor)) = (node.attribute("id"), accessor) {
            let _ = self.accessors.insert(id, accessor);
        }
        if let Some((id, array)) = array {
            let _ = self.arrays.insert(id, array);
        }
        Ok(())
    }

    /// The accessor a primitive's input reads and its array, as mesh-loader looks them up
    /// (`Document::index`, which panics on a missing id, then `as_float().unwrap()`).
    pub(super) fn resolve(&self, input: InputRef<'a, 'i>, role: &str) -> Result<(&AccessorInfo<'a, 'i>, &ArrayInfo<'a, 'i>), String> {
        let acc = self
            .accessors
            .get(input.source)
            .ok_or_else(|| format!("{} ({role}): no <source> with that id and an <accessor> in a <mesh>", at(input.node, Some("source"))))?;
        let array = self.arrays.get(acc.array).ok_or_else(|| format!("{}: no <float_array> with that id in a mesh <source>", at(acc.node, Some("source"))))?;
        if !array.float {
            return Err(format!("{}: names a <{}>; only a <float_array> can be read", at(acc.node, Some("source")), array.node.tag_name().name()));
        }
        Ok((acc, array))
    }

    /// How many elements mesh-loader reads from an accessor it uses (0 when it ignores it: fewer
    /// than `min` components or params, or params not all float). Position, normal and colour
    /// accessors (`Positions` in mesh-loader) yield `count` elements and panic on 0; texcoords yield
    /// every `stride` floats of the array and panic on a last chunk of 1.
    pub(super) fn accessor_len(&self, input: InputRef<'a, 'i>, role: &str, texcoord: bool) -> Result<u64, String> {
        let (acc, array) = self.resolve(input, role)?;
        let min = if texcoord { 2 } else { 3 };
        if acc.stride < min || acc.params < min as usize || !acc.all_float {
            return Ok(0);
        }
        let need = u64::from(acc.count) * u64::from(acc.stride);
        if need > array.len {
            return Err(format!(
                "{} stride=\"{}\" ({role}): count × stride = {need} values, more than the {} of <{} id=\"{}\">",
                at(acc.node, Some("count")),
                acc.stride,
                array.len,
                array.node.tag_name().name(),
                acc.array
            ));
        }
        if texcoord {
            if array.len % u64::from(acc.stride) == 1 {
                return Err(format!(
                    "{} ({role}): the {} values of <float_array id=\"{}\"> leave one value over, which mesh-loader reads as a pair",
                    at(acc.node, Some("stride")),
                    array.len,
                    acc.array
                ));
            }
            Ok(array.len.div_ceil(u64::from(acc.stride)))
        } else if acc.count == 0 {
            Err(format!("{} ({role}): must be at least 1 (mesh-loader panics on an empty accessor)", at(acc.node, Some("count"))))
        } else {
            Ok(u64::from(acc.count))
        }
    }
}

pub(super) fn accessor_info<'a, 'i>(node: Node<'a, 'i>) -> Result<AccessorInfo<'a, 'i>, String> {
    let count = required_u32(node, "count")?;
    let array = url(node, "source")?;
    let _offset = attr_u32(node, "offset")?;
    let stride = attr_u32(node, "stride")?.unwrap_or(1);
    let mut params = 0;
    let mut all_float = true;
    for p in elements(node).filter(|n| n.tag_name().name() == "param") {
        params += 1;
        all_float &= p.attribute("type") == Some("float");
    }
    Ok(AccessorInfo { node, count, stride, array, params, all_float })
}

pub(super) fn vertices<'a, 'i>(node: Node<'a, 'i>) -> Result<VerticesInfo<'a, 'i>, String> {
    let mut v = VerticesInfo { id: node.attribute("id").unwrap_or(""), ..Default::default() };
    for input in elements(node).filter(|n| n.tag_name().name() == "input") {
        let r = input_ref(input, false)?;
        match input.attribute("semantic") {
            Some("POSITION") => v.position = Some(r),
            Some("NORMAL") => v.normal = Some(r),
            Some("TEXCOORD") => v.texcoord = Some(r),
            Some("COLOR") => v.color = Some(r),
            _ => {}
        }
    }
    Ok(v)
}
