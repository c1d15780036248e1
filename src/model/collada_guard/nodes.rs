//! Reading a COLLADA element the way mesh-loader reads it: its attributes, its text and its
//! whitespace-separated tokens, and the `line N: <element>` every error starts with.

use super::MAX_QUOTED;
use roxmltree::Node;

pub(super) fn elements<'a, 'i>(node: Node<'a, 'i>) -> impl Iterator<Item = Node<'a, 'i>> {
    node.children().filter(Node::is_element)
}

/// `line N: <name attr="value">` for errors; long values are cut.
pub(super) fn at(node: Node<'_, '_>, attr: Option<&str>) -> String {
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
pub(super) fn attr_u32(node: Node<'_, '_>, name: &str) -> Result<Option<u32>, String> {
    match node.attribute(name) {
        None => Ok(None),
        Some(v) => v.parse::<u32>().map(Some).map_err(|_| format!("{}: must be an integer from 0 to {}", at(node, Some(name)), u32::MAX)),
    }
}

pub(super) fn required_u32(node: Node<'_, '_>, name: &str) -> Result<u32, String> {
    attr_u32(node, name)?.ok_or_else(|| format!("{}: the {name} attribute is missing", at(node, None)))
}

/// A `#id` reference, without the `#`.
pub(super) fn url<'a>(node: Node<'a, '_>, name: &str) -> Result<&'a str, String> {
    match node.attribute(name) {
        Some(v) => v.strip_prefix('#').ok_or_else(|| format!("{}: must be \"#\" and an id", at(node, Some(name)))),
        None => Err(format!("{}: the {name} attribute is missing", at(node, None))),
    }
}

/// The text mesh-loader reads (`trimmed_text`: the first child if it is text, trimmed).
pub(super) fn text_of<'a>(node: Node<'a, '_>) -> &'a str {
    node.text().unwrap_or("").trim_matches(|c| matches!(c, ' ' | '\t' | '\n' | '\r'))
}

pub(super) fn tokens(text: &str) -> impl Iterator<Item = &str> {
    text.split([' ', '\t', '\n', '\r']).filter(|t| !t.is_empty())
}

/// Counts the indices of a `<p>` or `<vcount>`, each an unsigned 32-bit integer.
pub(super) fn count_indices(node: Node<'_, '_>) -> Result<u64, String> {
    let mut n = 0u64;
    for t in tokens(text_of(node)) {
        if t.parse::<u32>().is_err() {
            return Err(format!("{}: {:?} is not an integer from 0 to {}", at(node, None), t.chars().take(MAX_QUOTED).collect::<String>(), u32::MAX));
        }
        n += 1;
    }
    Ok(n)
}

/// An `<input>`: the source it names, its offset among the indices, and its set.
#[derive(Clone, Copy)]
pub(super) struct InputRef<'a, 'i> {
    pub(super) node: Node<'a, 'i>,
    pub(super) source: &'a str,
    pub(super) offset: u32,
    pub(super) set: u32,
}

/// An `<input>` as mesh-loader reads it: `offset` required where inputs share the indices.
pub(super) fn input_ref<'a, 'i>(node: Node<'a, 'i>, shared: bool) -> Result<InputRef<'a, 'i>, String> {
    let source = url(node, "source")?;
    let offset = if shared { required_u32(node, "offset")? } else { 0 };
    let set = attr_u32(node, "set")?.unwrap_or(0);
    Ok(InputRef { node, source, offset, set })
}
