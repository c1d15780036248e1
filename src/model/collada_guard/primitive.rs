//! One primitive element (`<triangles>`, `<polylist>`, `<lines>`, ...) as mesh-loader's
//! `parse_primitive` reads it.

use super::nodes::{at, count_indices, elements, input_ref, required_u32, text_of, tokens, InputRef};
use super::MAX_QUOTED;
use roxmltree::Node;

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(super) enum Kind {
    Lines,
    LineStrips,
    Polygons,
    Polylist,
    Triangles,
    TriFans,
    TriStrips,
}

impl Kind {
    pub(super) fn of(name: &str) -> Option<Kind> {
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
    pub(super) fn min_face_size(self) -> u64 {
        match self {
            Kind::Lines | Kind::LineStrips => 2,
            Kind::Triangles | Kind::TriFans | Kind::TriStrips => 3,
            Kind::Polygons | Kind::Polylist => 1,
        }
    }
}

/// One primitive element as mesh-loader's `parse_primitive` leaves it.
pub(super) struct PrimitiveInfo<'a, 'i> {
    pub(super) node: Node<'a, 'i>,
    pub(super) kind: Kind,
    pub(super) count: u32,
    /// Indices per vertex: one more than the largest `<input>` offset.
    pub(super) stride: u64,
    pub(super) vertex: Option<InputRef<'a, 'i>>,
    pub(super) normal: Option<InputRef<'a, 'i>>,
    pub(super) color: Option<InputRef<'a, 'i>>,
    pub(super) texcoords: Vec<InputRef<'a, 'i>>,
    pub(super) vcount: Vec<u32>,
    pub(super) vcount_reserved: bool,
    pub(super) p: Vec<Node<'a, 'i>>,
    pub(super) p_len: u64,
}

/// Replays `collada::geometry::parse_primitive`, refusing its unbounded reservations and its
/// division by a stride of 0.
pub(super) fn primitive<'a, 'i>(node: Node<'a, 'i>, kind: Kind) -> Result<PrimitiveInfo<'a, 'i>, String> {
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
            "input" => prim.input(child)?,
            "vcount" if kind == Kind::Polylist => prim.vcount(child)?,
            "p" => prim.p(child, primitives_in_text)?,
            _ => {}
        }
    }
    // mesh-loader sorts the texcoord inputs by set (a stable sort) and reads the first.
    prim.texcoords.sort_by_key(|t| t.set);
    Ok(prim)
}

impl<'a, 'i> PrimitiveInfo<'a, 'i> {
    /// An `<input>`: its offset widens the stride; VERTEX and NORMAL of set 0 and COLOR are kept
    /// (the last of each wins), and every TEXCOORD.
    fn input(&mut self, child: Node<'a, 'i>) -> Result<(), String> {
        let input = input_ref(child, true)?;
        if input.offset == u32::MAX {
            return Err(format!("{}: at most {} (mesh-loader adds 1 to it)", at(child, Some("offset")), u32::MAX - 1));
        }
        self.stride = self.stride.max(u64::from(input.offset) + 1);
        match child.attribute("semantic") {
            Some("VERTEX") if input.set == 0 => self.vertex = Some(input),
            Some("NORMAL") if input.set == 0 => self.normal = Some(input),
            Some("COLOR") => self.color = Some(input),
            Some("TEXCOORD") => self.texcoords.push(input),
            _ => {}
        }
        Ok(())
    }

    /// The first `<vcount>` of a `<polylist>`: its first `count` entries, each at least 1.
    fn vcount(&mut self, child: Node<'a, 'i>) -> Result<(), String> {
        if !self.vcount.is_empty() || self.count == 0 {
            return Ok(());
        }
        let text = text_of(child);
        if u64::from(self.count) > text.len() as u64 {
            // mesh-loader reserves `count` entries before reading the text.
            return Err(format!("{}: more polygons than its <vcount> of {} characters can hold", at(self.node, Some("count")), text.len()));
        }
        for t in tokens(text).take(self.count as usize) {
            match t.parse::<u32>() {
                Ok(v) if v > 0 => self.vcount.push(v),
                _ => return Err(format!("{}: {:?} is not an integer from 1 to {}", at(child, None), t.chars().take(MAX_QUOTED).collect::<String>(), u32::MAX)),
            }
        }
        Ok(())
    }

    /// A `<p>`: the reservation mesh-loader makes for it, then its indices counted (and, for the
    /// kinds with one `<p>` per face, the face's vertex count kept).
    fn p(&mut self, child: Node<'a, 'i>, primitives_in_text: u64) -> Result<(), String> {
        if self.count == 0 {
            return Ok(());
        }
        let one_p = matches!(self.kind, Kind::Lines | Kind::Polylist | Kind::Triangles);
        if one_p {
            if self.p_len > 0 {
                return Ok(());
            }
            self.check_one_p_reserve(child)?;
        } else {
            if !self.vcount_reserved && u64::from(self.count) > primitives_in_text {
                // mesh-loader reserves `count` entries at the first <p>.
                return Err(format!("{}: more than its {primitives_in_text} <p> and <ph> elements", at(self.node, Some("count"))));
            }
            self.vcount_reserved = true;
            if self.stride == 0 {
                return Err(format!(
                    "{}: a <p> with no <input> before it (mesh-loader 0.1.13 divides by the number of inputs and panics)",
                    at(self.node, None)
                ));
            }
        }
        let added = count_indices(child)?;
        if !one_p {
            let vc = added / self.stride;
            if added % self.stride != 0 || vc < self.kind.min_face_size() {
                // mesh-loader refuses the file.
                return Ok(());
            }
            self.vcount.push(u32::try_from(vc).map_err(|_| format!("{}: more than {} vertices", at(child, None), u32::MAX))?);
        }
        self.p_len += added;
        self.p.push(child);
        Ok(())
    }

    /// The kinds with one `<p>` for all faces: mesh-loader reserves expected × stride indices
    /// before reading the text, so they must fit in it.
    fn check_one_p_reserve(&self, child: Node<'a, 'i>) -> Result<(), String> {
        let len = text_of(child).len() as u128;
        let expected: u64 = match self.kind {
            Kind::Polylist => self.vcount.iter().map(|&v| u64::from(v)).sum(),
            Kind::Lines => u64::from(self.count) * 2,
            _ => u64::from(self.count) * 3,
        };
        let reserve = u128::from(expected) * u128::from(self.stride);
        if reserve > len {
            return Err(format!(
                "{}: with {} indices per vertex that is {reserve} indices, more than its <p> of {len} characters can hold",
                at(self.node, Some("count")),
                self.stride
            ));
        }
        Ok(())
    }
}
