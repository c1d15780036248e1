//! A pass over XML text before any parser sees it. The parsers behind urdf-rs (RustyXML) and
//! mesh-loader (its own reader) recurse once per nested element, so 20,000 nested elements
//! overflow the stack and abort the process; roxmltree-style DTDs expand entities. This pass
//! walks the text in a loop, refuses a document type declaration (URDF, SRDF and COLLADA never
//! need one) and any nesting past [`MAX_XML_DEPTH`].

use crate::limits::MAX_XML_DEPTH;

/// Why the text was refused; `Display` is one line naming the line of the text.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub(crate) enum XmlGuardError {
    /// Elements nested deeper than allowed.
    #[error("line {line}: elements nested more than {MAX_XML_DEPTH} deep")]
    TooDeep {
        /// 1-based line of the element past the bound.
        line: usize,
    },
    /// `<!DOCTYPE` or `<!ENTITY`.
    #[error("line {line}: a document type declaration (<!DOCTYPE or <!ENTITY); entities are not expanded, so it is refused")]
    Dtd {
        /// 1-based line.
        line: usize,
    },
    /// A comment, CDATA section, declaration or tag without its end.
    #[error("line {line}: unterminated {what}")]
    Unterminated {
        /// 1-based line where it starts.
        line: usize,
        /// What is unterminated.
        what: &'static str,
    },
}

fn find(hay: &[u8], from: usize, needle: &[u8]) -> Option<usize> {
    hay.get(from..)?.windows(needle.len()).position(|w| w == needle).map(|p| p + from)
}

/// Checks nesting depth and the absence of a DTD. Malformed XML otherwise passes: the parser
/// that comes next reports it in its own words.
pub(crate) fn check_xml(text: &[u8]) -> Result<(), XmlGuardError> {
    let line_at = |pos: usize| 1 + text[..pos.min(text.len())].iter().filter(|&&b| b == b'\n').count();
    let mut depth = 0usize;
    let mut i = 0usize;
    while let Some(off) = text.get(i..).and_then(|t| t.iter().position(|&b| b == b'<')) {
        let start = i + off;
        let rest = &text[start..];
        let skip_to = |end: &[u8], what: &'static str| {
            find(text, start, end).map(|p| p + end.len()).ok_or_else(|| XmlGuardError::Unterminated { line: line_at(start), what })
        };
        if rest.starts_with(b"<!--") {
            i = skip_to(b"-->", "comment")?;
        } else if rest.starts_with(b"<![CDATA[") {
            i = skip_to(b"]]>", "CDATA section")?;
        } else if rest.starts_with(b"<?") {
            i = skip_to(b"?>", "processing instruction")?;
        } else if rest.starts_with(b"<!") {
            return Err(XmlGuardError::Dtd { line: line_at(start) });
        } else if rest.starts_with(b"</") {
            depth = depth.saturating_sub(1);
            i = skip_to(b">", "closing tag")?;
        } else {
            // A start tag: to its '>' outside quoted attribute values.
            let mut quote = None;
            let mut end = None;
            for (k, &b) in rest.iter().enumerate().skip(1) {
                match (quote, b) {
                    (None, b'"' | b'\'') => quote = Some(b),
                    (Some(q), _) if b == q => quote = None,
                    (None, b'>') => {
                        end = Some(k);
                        break;
                    }
                    _ => {}
                }
            }
            let end = end.ok_or_else(|| XmlGuardError::Unterminated { line: line_at(start), what: "tag" })?;
            if rest[end - 1] != b'/' {
                depth += 1;
                if depth > MAX_XML_DEPTH {
                    return Err(XmlGuardError::TooDeep { line: line_at(start) });
                }
            }
            i = start + end + 1;
        }
    }
    Ok(())
}

/// A start or end tag seen by [`for_each_tag`].
#[derive(Debug)]
pub(crate) struct Tag<'a> {
    /// 1-based line of its `<`.
    pub line: usize,
    /// Element name.
    pub name: &'a str,
    /// Attributes in document order (values not unescaped).
    pub attributes: Vec<(&'a str, &'a str)>,
    /// An end tag (`</name>`).
    pub end: bool,
    /// A self-closing tag (`<name/>`), which also ends the element.
    pub empty: bool,
}

/// Calls `f` for every start and end tag of text [`check_xml`] accepted, in a loop.
pub(crate) fn for_each_tag<'a>(text: &'a str, mut f: impl FnMut(&Tag<'a>) -> Result<(), String>) -> Result<(), String> {
    let bytes = text.as_bytes();
    let mut line = 1usize;
    let mut counted = 0usize;
    let mut i = 0usize;
    while let Some(off) = bytes.get(i..).and_then(|t| t.iter().position(|&b| b == b'<')) {
        let start = i + off;
        line += bytes[counted..start].iter().filter(|&&b| b == b'\n').count();
        counted = start;
        let rest = &text[start..];
        let skip = |end: &str| rest.find(end).map(|p| start + p + end.len()).unwrap_or(bytes.len());
        if rest.starts_with("<!--") {
            i = skip("-->");
            continue;
        }
        if rest.starts_with("<![CDATA[") {
            i = skip("]]>");
            continue;
        }
        if rest.starts_with("<?") || rest.starts_with("<!") {
            i = skip(">");
            continue;
        }
        let mut quote = None;
        let mut close = rest.len();
        for (k, b) in rest.bytes().enumerate().skip(1) {
            match (quote, b) {
                (None, b'"' | b'\'') => quote = Some(b),
                (Some(q), _) if b == q => quote = None,
                (None, b'>') => {
                    close = k;
                    break;
                }
                _ => {}
            }
        }
        let inner = &rest[1..close];
        i = start + close + 1;
        let end = inner.starts_with('/');
        let empty = !end && inner.ends_with('/');
        let inner = inner.trim_start_matches('/').trim_end_matches('/');
        let name_len = inner.find(|c: char| c.is_whitespace()).unwrap_or(inner.len());
        let (name, mut attrs) = inner.split_at(name_len);
        let mut attributes = Vec::new();
        while let Some((key, after)) = attrs.split_once('=') {
            let after = after.trim_start();
            let Some(q) = after.chars().next().filter(|c| *c == '"' || *c == '\'') else {
                break;
            };
            let Some((value, next)) = after[1..].split_once(q) else {
                break;
            };
            attributes.push((key.trim(), value));
            attrs = next;
        }
        f(&Tag { line, name, attributes, end, empty })?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn nested(n: usize) -> String {
        format!("<robot name=\"r\">{}{}</robot>", "<a>".repeat(n), "</a>".repeat(n))
    }

    #[test]
    fn depth_dtd_and_real_files() {
        assert_eq!(check_xml(nested(MAX_XML_DEPTH - 1).as_bytes()), Ok(()));
        assert_eq!(check_xml(nested(MAX_XML_DEPTH).as_bytes()), Err(XmlGuardError::TooDeep { line: 1 }));
        assert!(check_xml(nested(20_000).as_bytes()).is_err());
        // Siblings and self-closing tags do not nest; quoted '>' and '/>' do not end a tag.
        let flat = format!("<robot>{}</robot>", "<link name=\"a>b\"/><x y='/>'></x>".repeat(10_000));
        assert_eq!(check_xml(flat.as_bytes()), Ok(()));
        let bomb = "<?xml version=\"1.0\"?>\n<!DOCTYPE lolz [<!ENTITY lol \"lol\">]>\n<robot/>";
        assert_eq!(check_xml(bomb.as_bytes()), Err(XmlGuardError::Dtd { line: 2 }));
        assert_eq!(check_xml(b"<!-- <!DOCTYPE in a comment> --><robot><![CDATA[<<<]]></robot>"), Ok(()));
        assert!(matches!(check_xml(b"<robot><!-- open"), Err(XmlGuardError::Unterminated { what: "comment", .. })));
        let urdf = std::fs::read(crate::model::bundled_config_dir().join("example_workcell/robot.urdf")).unwrap();
        assert_eq!(check_xml(&urdf), Ok(()));
    }

    #[test]
    fn tags_and_attributes() {
        let mut seen = Vec::new();
        let text = "<robot name=\"r\">\n<!-- <x/> -->\n<origin xyz='0 0 1' rpy=\"0 0 0\"/>\n</robot>";
        for_each_tag(text, |t| {
            seen.push(format!("{}{}{}@{}{:?}", if t.end { "/" } else { "" }, t.name, if t.empty { "/" } else { "" }, t.line, t.attributes));
            Ok(())
        })
        .unwrap();
        assert_eq!(seen, ["robot@1[(\"name\", \"r\")]", "origin/@3[(\"xyz\", \"0 0 1\"), (\"rpy\", \"0 0 0\")]", "/robot@4[]"]);
    }
}
