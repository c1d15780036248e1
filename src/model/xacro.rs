//! Unexpanded xacro, recognised where a URDF or an SRDF is read.
//!
//! urdf-rs reads past the elements it does not know, so a `.urdf.xacro` parses as a robot whose
//! links sit inside `<xacro:macro>` bodies and are never seen: a robot with nothing to check,
//! reported free in every state. An `.srdf.xacro` likewise reads as an SRDF without pairs. Both are
//! refused here, before anything is built from them, with the command that expands them.
//!
//! A namespace declaration alone is not xacro: example-robot-data's plain URDFs declare
//! `xmlns:xacro` and use none of it.

/// The namespace URIs xacro files declare (ROS wiki, old and new spelling).
const XACRO_NAMESPACES: [&str; 3] = ["http://www.ros.org/wiki/xacro", "http://ros.org/wiki/xacro", "https://www.ros.org/wiki/xacro"];

/// Characters of an attribute value shown in the error.
const SHOWN: usize = 60;

/// What marks `text` (read from `name`) as unexpanded xacro, naming the element or attribute and
/// its line; `None` for plain XML. `text` has passed the XML guard, so parsing it is bounded.
pub(crate) fn xacro_evidence(text: &str, name: &str) -> Option<String> {
    if name.to_ascii_lowercase().ends_with(".xacro") {
        return Some("its name ends in .xacro".to_owned());
    }
    let doc = match roxmltree::Document::parse(text) {
        Ok(doc) => doc,
        // An undeclared `xacro:` prefix is an XML error; say what it is rather than only that.
        Err(_) => {
            return text.find("<xacro:").map(|at| format!("line {}: a <xacro:...> element", 1 + text[..at].matches('\n').count()));
        }
    };
    let line = |n: roxmltree::Node| doc.text_pos_at(n.range().start).row;
    for n in doc.descendants().filter(roxmltree::Node::is_element) {
        let tag = n.tag_name();
        if tag.namespace().is_some_and(|ns| XACRO_NAMESPACES.contains(&ns)) {
            return Some(format!("line {}: a <xacro:{}> element", line(n), tag.name()));
        }
        for a in n.attributes() {
            let v = a.value();
            if v.contains("$(") || v.contains("${") {
                let shown: String = v.chars().take(SHOWN).collect();
                let more = if v.chars().count() > SHOWN { "..." } else { "" };
                return Some(format!("line {}: <{}> {}=\"{shown}{more}\" is a xacro substitution", line(n), tag.name(), a.name()));
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    const NS: &str = "xmlns:xacro=\"http://www.ros.org/wiki/xacro\"";

    #[test]
    fn macros_properties_and_substitutions_are_xacro() {
        let cases = [
            (format!("<robot name=\"r\" {NS}><xacro:macro name=\"m\"><link name=\"a\"/></xacro:macro></robot>"), "line 1: a <xacro:macro> element"),
            (format!("<robot name=\"r\" {NS}>\n<xacro:property name=\"w\" value=\"1\"/></robot>"), "line 2: a <xacro:property> element"),
            (
                "<robot name=\"r\"><link name=\"a\"><visual><geometry><mesh filename=\"$(find pkg)/m.stl\"/></geometry></visual></link></robot>".to_owned(),
                "filename=\"$(find pkg)/m.stl\"",
            ),
            ("<robot name=\"r\"><link name=\"${prefix}base\"/></robot>".to_owned(), "name=\"${prefix}base\""),
            // Undeclared prefix: not XML, still recognised.
            ("<robot name=\"r\">\n\n<xacro:include filename=\"a.xacro\"/></robot>".to_owned(), "line 3: a <xacro:...> element"),
        ];
        for (text, want) in cases {
            let got = xacro_evidence(&text, "robot.urdf").unwrap_or_default();
            assert!(got.contains(want), "{text}: got {got:?}, want {want:?}");
        }
        assert_eq!(xacro_evidence("<robot name=\"r\"/>", "arm.URDF.XACRO").as_deref(), Some("its name ends in .xacro"));
    }

    #[test]
    fn a_namespace_declaration_alone_is_plain_urdf() {
        let text = format!("<robot name=\"panda\" {NS}><link name=\"a\"/><joint name=\"j\" type=\"fixed\"><parent link=\"a\"/><child link=\"b\"/></joint><link name=\"b\"/></robot>");
        assert_eq!(xacro_evidence(&text, "panda.urdf"), None);
        // A dollar sign without a parenthesis or brace is ordinary text.
        assert_eq!(xacro_evidence("<robot name=\"cost$1\"/>", "r.urdf"), None);
    }
}
