//! A pass over a COLLADA document before mesh-loader 0.1.13 reads it. mesh-loader trusts the
//! counts, strides, offsets, ids and indices in the file: a `<p>` index past the vertices, an
//! accessor with stride 0 or 4,000,000,000, an `<input>` naming a source that does not exist each
//! panic inside it, `<triangles count="4000000000">` reserves 48 GB before reading one index, and
//! a non-empty `<Name_array>` in a mesh source loops forever. The defects, one reproducer each,
//! are in `docs/upstream/mesh-loader.md` and `docs/upstream/mesh-loader/repro_*.dae`.
//!
//! The pass parses the text with roxmltree (the parser mesh-loader uses; it does not recurse) and
//! replays what mesh-loader does with it, in the same order and with the same "the last one wins"
//! rules for repeated ids and elements: the reservations made while parsing (each must fit in the
//! text that is to fill it), then, for every geometry mesh-loader builds, every lookup, every
//! accessor slice and every index it reads. Nothing is copied: `<p>` lists are scanned twice
//! instead. [`check_xml`](super::xml_guard::check_xml) has already bounded the depth.
//!
//! Besides the panics it refuses two inputs mesh-loader reads wrongly without a word (a polygon of
//! fewer than 3 vertices in a `<polylist>`/`<polygons>`, after which every polygon is misread;
//! `<tristrips>`, read as fans) and one that costs time quadratic in the file: every primitive
//! copies its whole position, normal, texcoord and colour accessors, so 30,000 `<triangles>` over
//! one 30,000-vertex source (2.6 MB) take 4 s; past [`MAX_MESH_TRIANGLES`] triangles the file is
//! refused here, before mesh-loader allocates them.

use crate::limits::MAX_MESH_TRIANGLES;
use roxmltree::{Document, Node};
use std::borrow::Cow;
use std::collections::HashMap;

/// Accessor elements mesh-loader may copy (summed over primitives) whatever the file's size.
const MIN_COPY_BUDGET: u64 = 1 << 24;
/// Accessor elements mesh-loader may copy per byte of the file. Real files copy each accessor
/// once per primitive that uses it: the 286 meshes of example-robot-data copy at most 0.15 per
/// byte (`romeo`'s, 334,160 copies for 2.2 MB) and 526,082 in all (the largest). At about 4 ns a
/// copy, a 1 GiB file may then take some 9 s; 30,000 primitives over one 30,000-vertex source
/// (2.6 MB, 900 million copies) are refused.
const COPIES_PER_BYTE: u64 = 2;
/// Longest attribute value quoted in an error.
const MAX_QUOTED: usize = 40;

/// Checks `bytes` (a `.dae` file) for what makes mesh-loader 0.1.13 panic, loop or allocate
/// without bound. `Err` is one line: the line of the file, the element, the attribute and its
/// value, and what is allowed. Files mesh-loader refuses with an error of its own may pass.
pub fn check_collada(bytes: &[u8]) -> Result<(), String> {
    let text = decode(bytes)?;
    let doc = Document::parse(&text).map_err(|e| format!("not well-formed XML: {e}"))?;
    let root = doc.root_element();
    if root.tag_name().name() != "COLLADA" {
        // mesh-loader refuses it before reading anything else.
        return Ok(());
    }
    let mut walk = Walk::default();
    for library in elements(root).filter(|n| n.tag_name().name() == "library_geometries") {
        for geometry in elements(library).filter(|n| n.tag_name().name() == "geometry") {
            walk.geometry(geometry)?;
        }
    }
    walk.check_build(bytes.len())
}

/// The text as mesh-loader decodes it (`utils::utf16::decode_string`): UTF-8, with or without a
/// byte-order mark, or UTF-16 with one.
fn decode(bytes: &[u8]) -> Result<Cow<'_, str>, String> {
    let utf16 = |rest: &[u8], be: bool| -> Result<Cow<'_, str>, String> {
        if rest.len() % 2 != 0 {
            return Err("invalid UTF-16: odd number of bytes".to_owned());
        }
        let units = rest.chunks_exact(2).map(|c| if be { u16::from_be_bytes([c[0], c[1]]) } else { u16::from_le_bytes([c[0], c[1]]) });
        char::decode_utf16(units).collect::<Result<String, _>>().map(Cow::Owned).map_err(|e| format!("invalid UTF-16: {e}"))
    };
    if let Some(rest) = bytes.strip_prefix(&[0xEF, 0xBB, 0xBF]) {
        std::str::from_utf8(rest).map(Cow::Borrowed).map_err(|e| format!("invalid UTF-8: {e}"))
    } else if bytes.starts_with(&[0xFF, 0xFE, 0, 0]) || bytes.starts_with(&[0, 0, 0xFE, 0xFF]) {
        Err("UTF-32 text is not supported".to_owned())
    } else if let Some(rest) = bytes.strip_prefix(&[0xFE, 0xFF]) {
        utf16(rest, true)
    } else if let Some(rest) = bytes.strip_prefix(&[0xFF, 0xFE]) {
        utf16(rest, false)
    } else {
        std::str::from_utf8(bytes).map(Cow::Borrowed).map_err(|e| format!("invalid UTF-8: {e}"))
    }
}

fn elements<'a, 'i>(node: Node<'a, 'i>) -> impl Iterator<Item = Node<'a, 'i>> {
    node.children().filter(Node::is_element)
}

/// `line N: <name attr="value">` for errors; long values are cut.
fn at(node: Node<'_, '_>, attr: Option<&str>) -> String {
    let line = node.document().text_pos_at(node.range().start).row;
    let name = node.tag_name().name();
    match attr {
        Some(a) => {
            let value = node.attribute(a).unwrap_or("");
            let cut: String = value.chars().take(MAX_QUOTED).collect();
            let more = if cut.len() < value.len() { "..." } else { "" };
            format!("line {line}: <{name}> {a}=\"{cut}{more}\"")
        }
        None => format!("line {line}: <{name}>"),
    }
}

/// An unsigned 32-bit attribute, parsed as mesh-loader parses it (`str::parse::<u32>`).
fn attr_u32(node: Node<'_, '_>, name: &str) -> Result<Option<u32>, String> {
    match node.attribute(name) {
        None => Ok(None),
        Some(v) => v.parse::<u32>().map(Some).map_err(|_| format!("{}: must be an integer from 0 to {}", at(node, Some(name)), u32::MAX)),
    }
}

fn required_u32(node: Node<'_, '_>, name: &str) -> Result<u32, String> {
    attr_u32(node, name)?.ok_or_else(|| format!("{}: the {name} attribute is missing", at(node, None)))
}

/// A `#id` reference, without the `#`.
fn url<'a>(node: Node<'a, '_>, name: &str) -> Result<&'a str, String> {
    match node.attribute(name) {
        Some(v) => v.strip_prefix('#').ok_or_else(|| format!("{}: must be \"#\" and an id", at(node, Some(name)))),
        None => Err(format!("{}: the {name} attribute is missing", at(node, None))),
    }
}

/// The text mesh-loader reads (`trimmed_text`: the first child if it is text, trimmed).
fn text_of<'a>(node: Node<'a, '_>) -> &'a str {
    node.text().unwrap_or("").trim_matches(|c| matches!(c, ' ' | '\t' | '\n' | '\r'))
}

fn tokens(text: &str) -> impl Iterator<Item = &str> {
    text.split([' ', '\t', '\n', '\r']).filter(|t| !t.is_empty())
}

/// Counts the indices of a `<p>` or `<vcount>`, each an unsigned 32-bit integer.
fn count_indices(node: Node<'_, '_>) -> Result<u64, String> {
    let mut n = 0u64;
    for t in tokens(text_of(node)) {
        if t.parse::<u32>().is_err() {
            return Err(format!("{}: {:?} is not an integer from 0 to {}", at(node, None), t.chars().take(MAX_QUOTED).collect::<String>(), u32::MAX));
        }
        n += 1;
    }
    Ok(n)
}

struct AccessorInfo<'a, 'i> {
    node: Node<'a, 'i>,
    count: u32,
    stride: u32,
    array: &'a str,
    params: usize,
    all_float: bool,
}

struct ArrayInfo<'a, 'i> {
    node: Node<'a, 'i>,
    float: bool,
    len: u64,
}

#[derive(Clone, Copy)]
struct InputRef<'a, 'i> {
    node: Node<'a, 'i>,
    source: &'a str,
    offset: u32,
    set: u32,
}

#[derive(Default)]
struct VerticesInfo<'a, 'i> {
    id: &'a str,
    position: Option<InputRef<'a, 'i>>,
    normal: Option<InputRef<'a, 'i>>,
    texcoord: Option<InputRef<'a, 'i>>,
    color: Option<InputRef<'a, 'i>>,
}

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Kind {
    Lines,
    LineStrips,
    Polygons,
    Polylist,
    Triangles,
    TriFans,
    TriStrips,
}

impl Kind {
    fn of(name: &str) -> Option<Kind> {
        Some(match name {
            "lines" => Kind::Lines,
            "linestrips" => Kind::LineStrips,
            "polygons" => Kind::Polygons,
            "polylist" => Kind::Polylist,
            "triangles" => Kind::Triangles,
            "trifans" => Kind::TriFans,
            "tristrips" => Kind::TriStrips,
            _ => return None,
        })
    }

    /// Fewest indices per `<p>` of the kinds with one `<p>` per primitive (mesh-loader's
    /// `min_face_size`).
    fn min_face_size(self) -> u64 {
        match self {
            Kind::Lines | Kind::LineStrips => 2,
            Kind::Triangles | Kind::TriFans | Kind::TriStrips => 3,
            Kind::Polygons | Kind::Polylist => 1,
        }
    }
}

/// One primitive element as mesh-loader's `parse_primitive` leaves it.
struct PrimitiveInfo<'a, 'i> {
    node: Node<'a, 'i>,
    kind: Kind,
    count: u32,
    /// Indices per vertex: one more than the largest `<input>` offset.
    stride: u64,
    vertex: Option<InputRef<'a, 'i>>,
    normal: Option<InputRef<'a, 'i>>,
    color: Option<InputRef<'a, 'i>>,
    texcoords: Vec<InputRef<'a, 'i>>,
    vcount: Vec<u32>,
    vcount_reserved: bool,
    p: Vec<Node<'a, 'i>>,
    p_len: u64,
}

struct MeshInfo<'a, 'i> {
    vertices: Option<VerticesInfo<'a, 'i>>,
    primitives: Vec<PrimitiveInfo<'a, 'i>>,
}

/// What mesh-loader keeps of the document: sources by id, arrays by id, geometries in order.
#[derive(Default)]
struct Walk<'a, 'i> {
    accessors: HashMap<&'a str, AccessorInfo<'a, 'i>>,
    arrays: HashMap<&'a str, ArrayInfo<'a, 'i>>,
    geometries: Vec<(&'a str, MeshInfo<'a, 'i>)>,
}

impl<'a, 'i> Walk<'a, 'i> {
    fn geometry(&mut self, node: Node<'a, 'i>) -> Result<(), String> {
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

    fn mesh(&mut self, node: Node<'a, 'i>) -> Result<MeshInfo<'a, 'i>, String> {
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

    fn source(&mut self, node: Node<'a, 'i>) -> Result<(), String> {
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
    fn resolve(&self, input: InputRef<'a, 'i>, role: &str) -> Result<(&AccessorInfo<'a, 'i>, &ArrayInfo<'a, 'i>), String> {
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
    fn accessor_len(&self, input: InputRef<'a, 'i>, role: &str, texcoord: bool) -> Result<u64, String> {
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

    /// Replays `collada::instance::build` over the geometries mesh-loader keeps.
    fn check_build(&self, n_bytes: usize) -> Result<(), String> {
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

fn accessor_info<'a, 'i>(node: Node<'a, 'i>) -> Result<AccessorInfo<'a, 'i>, String> {
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

fn input_ref<'a, 'i>(node: Node<'a, 'i>, shared: bool) -> Result<InputRef<'a, 'i>, String> {
    let source = url(node, "source")?;
    let offset = if shared { required_u32(node, "offset")? } else { 0 };
    let set = attr_u32(node, "set")?.unwrap_or(0);
    Ok(InputRef { node, source, offset, set })
}

fn vertices<'a, 'i>(node: Node<'a, 'i>) -> Result<VerticesInfo<'a, 'i>, String> {
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

/// Replays `collada::geometry::parse_primitive`, refusing its unbounded reservations and its
/// division by a stride of 0.
fn primitive<'a, 'i>(node: Node<'a, 'i>, kind: Kind) -> Result<PrimitiveInfo<'a, 'i>, String> {
    let count = required_u32(node, "count")?;
    let mut prim = PrimitiveInfo {
        node,
        kind,
        count,
        stride: 0,
        vertex: None,
        normal: None,
        color: None,
        texcoords: Vec::new(),
        vcount: Vec::new(),
        vcount_reserved: false,
        p: Vec::new(),
        p_len: 0,
    };
    let primitives_in_text = elements(node).filter(|n| matches!(n.tag_name().name(), "p" | "ph")).count() as u64;
    for child in elements(node) {
        match child.tag_name().name() {
            "input" => {
                let input = input_ref(child, true)?;
                if input.offset == u32::MAX {
                    return Err(format!("{}: at most {} (mesh-loader adds 1 to it)", at(child, Some("offset")), u32::MAX - 1));
                }
                prim.stride = prim.stride.max(u64::from(input.offset) + 1);
                match child.attribute("semantic") {
                    Some("VERTEX") if input.set == 0 => prim.vertex = Some(input),
                    Some("NORMAL") if input.set == 0 => prim.normal = Some(input),
                    Some("COLOR") => prim.color = Some(input),
                    Some("TEXCOORD") => prim.texcoords.push(input),
                    _ => {}
                }
            }
            "vcount" if kind == Kind::Polylist => {
                if !prim.vcount.is_empty() || count == 0 {
                    continue;
                }
                let text = text_of(child);
                if u64::from(count) > text.len() as u64 {
                    // mesh-loader reserves `count` entries before reading the text.
                    return Err(format!("{}: more polygons than its <vcount> of {} characters can hold", at(node, Some("count")), text.len()));
                }
                for t in tokens(text).take(count as usize) {
                    match t.parse::<u32>() {
                        Ok(v) if v > 0 => prim.vcount.push(v),
                        _ => {
                            return Err(format!(
                                "{}: {:?} is not an integer from 1 to {}",
                                at(child, None),
                                t.chars().take(MAX_QUOTED).collect::<String>(),
                                u32::MAX
                            ))
                        }
                    }
                }
            }
            "p" => {
                if count == 0 {
                    continue;
                }
                let len = text_of(child).len() as u128;
                if matches!(kind, Kind::Lines | Kind::Polylist | Kind::Triangles) {
                    if prim.p_len > 0 {
                        continue;
                    }
                    let expected: u64 = match kind {
                        Kind::Polylist => prim.vcount.iter().map(|&v| u64::from(v)).sum(),
                        Kind::Lines => u64::from(count) * 2,
                        _ => u64::from(count) * 3,
                    };
                    // mesh-loader reserves expected × stride indices before reading the text.
                    let reserve = u128::from(expected) * u128::from(prim.stride);
                    if reserve > len {
                        return Err(format!(
                            "{}: with {} indices per vertex that is {reserve} indices, more than its <p> of {len} characters can hold",
                            at(node, Some("count")),
                            prim.stride
                        ));
                    }
                } else {
                    if !prim.vcount_reserved && u64::from(count) > primitives_in_text {
                        // mesh-loader reserves `count` entries at the first <p>.
                        return Err(format!("{}: more than its {primitives_in_text} <p> and <ph> elements", at(node, Some("count"))));
                    }
                    prim.vcount_reserved = true;
                    if prim.stride == 0 {
                        return Err(format!(
                            "{}: a <p> with no <input> before it (mesh-loader 0.1.13 divides by the number of inputs and panics)",
                            at(node, None)
                        ));
                    }
                }
                let added = count_indices(child)?;
                if !matches!(kind, Kind::Lines | Kind::Polylist | Kind::Triangles) {
                    let vc = added / prim.stride;
                    if added % prim.stride != 0 || vc < kind.min_face_size() {
                        // mesh-loader refuses the file.
                        continue;
                    }
                    prim.vcount.push(u32::try_from(vc).map_err(|_| format!("{}: more than {} vertices", at(child, None), u32::MAX))?);
                }
                prim.p_len += added;
                prim.p.push(child);
            }
            _ => {}
        }
    }
    // mesh-loader sorts the texcoord inputs by set (a stable sort) and reads the first.
    prim.texcoords.sort_by_key(|t| t.set);
    Ok(prim)
}

/// Triangles mesh-loader makes of a primitive (`vertex_indices_size`).
fn faces(prim: &PrimitiveInfo<'_, '_>) -> u64 {
    match prim.kind {
        Kind::Triangles => u64::from(prim.count),
        Kind::Polylist | Kind::Polygons | Kind::TriFans | Kind::TriStrips => prim.vcount.iter().map(|&v| u64::from(v.saturating_sub(2))).sum(),
        Kind::Lines | Kind::LineStrips => 0,
    }
}

/// The indices mesh-loader reads for the faces of a primitive: within the `<p>` text, and each
/// below the length of the accessor it indexes (`roles`: offset, length, name; length 0 means the
/// accessor is not read, except for VERTEX, where it means no positions: a panic).
fn check_faces(prim: &PrimitiveInfo<'_, '_>, vertex: InputRef<'_, '_>, roles: [(u32, u64, &str); 4]) -> Result<(), String> {
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::{Path, PathBuf};

    fn repro_dir() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/upstream/mesh-loader")
    }

    fn load(bytes: &[u8]) -> Result<usize, String> {
        let r = std::panic::catch_unwind(|| mesh_loader::Loader::default().load_from_slice(bytes, "x.dae"));
        match r {
            Ok(Ok(scene)) => Ok(scene.meshes.iter().map(|m| m.faces.len()).sum()),
            Ok(Err(e)) => Err(e.to_string()),
            Err(_) => Err("panic".to_owned()),
        }
    }

    /// Every reproducer is refused with one line naming a line of the file and an element.
    #[test]
    fn every_reproducer_is_refused() {
        let mut n = 0;
        for entry in std::fs::read_dir(repro_dir()).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().and_then(|e| e.to_str()) != Some("dae") {
                continue;
            }
            let bytes = std::fs::read(&path).unwrap();
            let err = check_collada(&bytes).expect_err(&path.display().to_string());
            eprintln!("{}: {err}", path.display());
            assert!(err.starts_with("line ") && err.contains('<') && !err.contains('\n'), "{}: {err}", path.display());
            n += 1;
        }
        assert!(n >= 20, "{n} reproducers");
    }

    fn mesh(body: &str) -> String {
        let p3 = r##"<param type="float"/><param type="float"/><param type="float"/>"##;
        format!(
            r##"<COLLADA version="1.4.1"><library_geometries><geometry id="g"><mesh>
<source id="s"><float_array id="a" count="12">0 0 0 1 0 0 0 1 0 0 0 1</float_array><technique_common><accessor source="#a" count="4" stride="3">{p3}</accessor></technique_common></source>
<vertices id="v"><input semantic="POSITION" source="#s"/></vertices>
{body}
</mesh></geometry></library_geometries></COLLADA>"##
        )
    }

    #[test]
    fn good_primitives_pass_and_load() {
        let vin = r##"<input semantic="VERTEX" source="#v" offset="0"/>"##;
        for body in [
            format!(r##"<triangles count="2">{vin}<p>0 1 2 0 2 3</p></triangles>"##),
            format!(r##"<polylist count="2">{vin}<vcount>3 4</vcount><p>0 1 2 0 1 2 3</p></polylist>"##),
            format!(r##"<polygons count="2">{vin}<p>0 1 2</p><p>0 1 2 3</p></polygons>"##),
            format!(r##"<trifans count="1">{vin}<p>0 1 2 3</p></trifans>"##),
            format!(r##"<lines count="2">{vin}<p>0 1 2 3</p></lines>"##),
            format!(r##"<triangles count="0">{vin}</triangles>"##),
            // A NORMAL input with an offset of its own.
            format!(r##"<triangles count="1">{vin}<input semantic="NORMAL" source="#s" offset="1"/><p>0 3 1 3 2 3</p></triangles>"##),
        ] {
            let text = mesh(&body);
            assert_eq!(check_collada(text.as_bytes()), Ok(()), "{body}");
            assert!(load(text.as_bytes()).is_ok(), "{body}");
        }
    }

    /// Hostile variants beyond the reproducer files: each refused; without the guard each panics.
    #[test]
    fn variants_are_refused_and_would_panic() {
        let vin = r##"<input semantic="VERTEX" source="#v" offset="0"/>"##;
        for body in [
            // A normal index past the normals (the positions are fine).
            format!(r##"<triangles count="1">{vin}<input semantic="NORMAL" source="#s" offset="1"/><p>0 0 1 4 2 0</p></triangles>"##),
            // A texcoord index past the texcoords (4 triples of source s).
            format!(r##"<triangles count="1">{vin}<input semantic="TEXCOORD" source="#s" offset="1"/><p>0 0 1 1 2 4</p></triangles>"##),
            // Polygons: an <input> after the first <p> widens the stride.
            format!(r##"<polygons count="1">{vin}<p>0 1 2</p><input semantic="TEXCOORD" source="#s" offset="1"/></polygons>"##),
            // A colour source that is not there.
            format!(r##"<triangles count="1">{vin}<input semantic="COLOR" source="#nothing" offset="0"/><p>0 1 2</p></triangles>"##),
        ] {
            let text = mesh(&body);
            let err = check_collada(text.as_bytes()).expect_err(&body);
            assert!(err.starts_with("line "), "{err}");
            assert_eq!(load(text.as_bytes()), Err("panic".to_owned()), "{body}");
        }
    }

    /// Many primitives over one large source: quadratic in mesh-loader, refused here.
    #[test]
    fn shared_source_copies_are_bounded() {
        let vertices = 20_000;
        let floats = vec!["0"; 3 * vertices].join(" ");
        let p3 = r##"<param type="float"/><param type="float"/><param type="float"/>"##;
        let prims = r##"<triangles count="0"><input semantic="VERTEX" source="#v" offset="0"/></triangles>"##.repeat(2_000);
        let text = format!(
            r##"<COLLADA version="1.4.1"><library_geometries><geometry id="g"><mesh><source id="s"><float_array id="a" count="{}">{floats}</float_array><technique_common><accessor source="#a" count="{vertices}" stride="3">{p3}</accessor></technique_common></source><vertices id="v"><input semantic="POSITION" source="#s"/></vertices>{prims}</mesh></geometry></library_geometries></COLLADA>"##,
            3 * vertices
        );
        let err = check_collada(text.as_bytes()).unwrap_err();
        assert!(err.contains("copy more than"), "{err}");
    }

    #[test]
    fn utf16_and_non_collada() {
        let text = mesh(r##"<triangles count="1"><input semantic="VERTEX" source="#v" offset="0"/><p>0 1 9</p></triangles>"##);
        let mut utf16 = vec![0xFF, 0xFE];
        utf16.extend(text.encode_utf16().flat_map(u16::to_le_bytes));
        assert!(check_collada(&utf16).unwrap_err().contains("index 9"));
        assert_eq!(check_collada(b"<robot/>"), Ok(()));
        assert!(check_collada(b"<COLLADA").unwrap_err().starts_with("not well-formed XML"));
    }

    /// Every .dae mesh on this machine (the robots of example-robot-data in the project's venv,
    /// and config/) passes the guard and loads in mesh-loader. Skipped where the venv is absent.
    #[test]
    fn real_meshes_pass() {
        let mut files = Vec::new();
        let mut dirs: Vec<PathBuf> = vec![Path::new(env!("CARGO_MANIFEST_DIR")).join("config")];
        if let Ok(home) = std::env::var("HOME") {
            let lib = Path::new(&home).join(".cache/thickness_collision/venv/lib");
            for py in std::fs::read_dir(&lib).into_iter().flatten().flatten() {
                dirs.push(py.path().join("site-packages/cmeel.prefix/share/example-robot-data/robots"));
            }
        }
        while let Some(dir) = dirs.pop() {
            for entry in std::fs::read_dir(&dir).into_iter().flatten().flatten() {
                let path = entry.path();
                if path.is_dir() {
                    dirs.push(path);
                } else if path.extension().and_then(|e| e.to_str()).is_some_and(|e| e.eq_ignore_ascii_case("dae")) {
                    files.push(path);
                }
            }
        }
        for path in &files {
            let bytes = std::fs::read(path).unwrap();
            assert_eq!(check_collada(&bytes), Ok(()), "{}", path.display());
            assert!(load(&bytes).is_ok(), "{}", path.display());
        }
        eprintln!("{} real .dae files pass", files.len());
    }
}
