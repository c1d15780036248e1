//! Reading ROS 2 parameters files for one node.
//!
//! Sections merge as rclcpp and rclpy merge them (`parameter_map_from`, over the
//! `rcl_params_t` that rcl_yaml_param_parser builds): every section whose key matches the node's
//! fully qualified name applies. A key without a leading `/` gets one (so `thickness_collision`
//! is the node in the root namespace), `/**` stands for any number of names and `/*` for one
//! (rclcpp turns the key into the regex `/*` -> `(/\w+)`). Sections apply in the order their keys
//! first appear (rcl keeps one entry per key, in first-seen order, across all files); a later
//! section's value for a parameter replaces an earlier one's.
//!
//! Unknown keys in a section that names this node are an error naming the key. A section whose
//! node name is a wildcard (`/**`, `/robot1/*`) speaks to every node, so keys meant for other
//! nodes are expected there: they are ignored with one warning.

use super::params::{Params, ParamsError};
use std::path::{Path, PathBuf};

/// The node's fully qualified name when nothing renames it: `thickness_collision` in the root
/// namespace (what `check` and `replay` read a parameters file for).
pub const DEFAULT_NODE_FQN: &str = "/thickness_collision";

/// The fully qualified name of the node after `-r __ns:=namespace` and `-r __node:=name` (each
/// `None` when not given).
pub fn node_fqn(namespace: Option<&str>, name: Option<&str>) -> String {
    let ns = namespace.unwrap_or("/").trim_end_matches('/');
    let slash = if ns.is_empty() || ns.starts_with('/') { "" } else { "/" };
    format!("{slash}{ns}/{}", name.unwrap_or("thickness_collision"))
}

/// Parameters read from parameters files, with what the reader ignored.
#[derive(Clone, Debug, PartialEq)]
pub struct LoadedParams {
    /// The merged, validated parameters.
    pub params: Params,
    /// One line per thing ignored (keys of wildcard sections this node does not have).
    pub warnings: Vec<String>,
}

impl Params {
    /// Reads a ROS 2 parameters file for the node [`DEFAULT_NODE_FQN`]; warnings are dropped
    /// (see [`Params::from_files_for_node`]).
    pub fn from_file(path: &Path) -> Result<Params, ParamsError> {
        Self::from_files_for_node(&[path.to_owned()], DEFAULT_NODE_FQN).map(|l| l.params)
    }

    /// Parses a ROS 2 parameters YAML for the node [`DEFAULT_NODE_FQN`] (`path` names it in
    /// errors); warnings are dropped.
    pub fn from_yaml(text: &str, path: &Path) -> Result<Params, ParamsError> {
        Self::from_yaml_for_node(text, path, DEFAULT_NODE_FQN).map(|l| l.params)
    }

    /// Parses a ROS 2 parameters YAML for the node named `node_fqn` (`/ns/name`).
    pub(crate) fn from_yaml_for_node(text: &str, path: &Path, node_fqn: &str) -> Result<LoadedParams, ParamsError> {
        let mut sections = Vec::new();
        read_sections(text, 0, path, &mut sections)?;
        merge_sections(&sections, &[path.to_owned()], node_fqn)
    }

    /// Reads ROS 2 parameters files, in order, for the node named `node_fqn` (`/ns/name`): the
    /// sections of all files that match the node merge as rcl merges several `--params-file`s.
    pub fn from_files_for_node(paths: &[PathBuf], node_fqn: &str) -> Result<LoadedParams, ParamsError> {
        let mut sections = Vec::new();
        for (i, path) in paths.iter().enumerate() {
            let text = crate::limits::read_regular_text(path, "parameters file", crate::limits::MAX_PARAMS_BYTES)
                .map_err(|e| ParamsError::Io(path.to_owned(), std::io::Error::other(e.to_string())))?;
            read_sections(&text, i, path, &mut sections)?;
        }
        merge_sections(&sections, paths, node_fqn)
    }
}

/// One node entry of parameters files, as rcl keeps it: the key as written (nested keys joined
/// with `/`), and its parameters by dotted name with the file each value came from, in
/// first-seen order (a later value for the same name replaces the earlier one in place).
pub(super) struct Section {
    key: String,
    params: Vec<(String, serde_yaml_ng::Value, usize)>,
}

/// The node entries of one file (`file` is its index in the list read), added to `out`: a key
/// already there (from an earlier file) takes the new values in its first place, as rcl's
/// `find_node` does.
pub(super) fn read_sections(text: &str, file: usize, path: &Path, out: &mut Vec<Section>) -> Result<(), ParamsError> {
    let yaml = |message: String| ParamsError::Yaml(path.to_owned(), message);
    if text.len() as u64 > crate::limits::MAX_PARAMS_BYTES {
        return Err(yaml(format!("{} bytes, more than the {} allowed", text.len(), crate::limits::MAX_PARAMS_BYTES)));
    }
    // A parameters file has no use for anchors and aliases; refusing them stops an alias
    // bomb before the parser expands it.
    if let Some((n, _)) = text.lines().enumerate().find(|(_, l)| has_alias(l)) {
        return Err(yaml(format!("line {}: YAML anchors and aliases (& and *) are not accepted in a parameters file", n + 1)));
    }
    let doc: serde_yaml_ng::Value = serde_yaml_ng::from_str(text).map_err(|e| yaml(e.to_string()))?;
    match doc {
        serde_yaml_ng::Value::Null => Ok(()),
        serde_yaml_ng::Value::Mapping(map) => read_node_map(&map, "", file, path, out),
        _ => Err(yaml("the file is not a mapping of node names to `ros__parameters`".into())),
    }
}

/// The YAML key as text; parameters files have string keys only.
pub(super) fn key_text(key: &serde_yaml_ng::Value, path: &Path) -> Result<String, ParamsError> {
    match key {
        serde_yaml_ng::Value::String(s) => Ok(s.clone()),
        serde_yaml_ng::Value::Number(n) => Ok(n.to_string()),
        serde_yaml_ng::Value::Bool(b) => Ok(b.to_string()),
        other => Err(ParamsError::Yaml(path.to_owned(), format!("a key {other:?} is not a name"))),
    }
}

/// Keys above `ros__parameters` name the node; nested ones join with `/` (rcl's node namespace
/// tracker), so `robot1: {thickness_collision: {ros__parameters: ...}}` is the section
/// `robot1/thickness_collision`.
pub(super) fn read_node_map(map: &serde_yaml_ng::Mapping, prefix: &str, file: usize, path: &Path, out: &mut Vec<Section>) -> Result<(), ParamsError> {
    let yaml = |message: String| ParamsError::Yaml(path.to_owned(), message);
    for (k, v) in map {
        let k = key_text(k, path)?;
        // rcl compares the key's first 15 bytes with ros__parameters, no more.
        if k.starts_with("ros__parameters") {
            if prefix.is_empty() {
                return Err(yaml("`ros__parameters` has no node name above it".into()));
            }
            check_node_key(prefix).map_err(|m| yaml(format!("section `{prefix}`: {m}")))?;
            let mut params = Vec::new();
            match v {
                serde_yaml_ng::Value::Mapping(m) => flatten_params(m, "", path, &mut params)?,
                serde_yaml_ng::Value::Null => {}
                _ => return Err(yaml(format!("section `{prefix}`: `ros__parameters` is not a mapping of parameter names to values"))),
            }
            let index = match out.iter().position(|s| s.key == prefix) {
                Some(i) => i,
                None => {
                    out.push(Section { key: prefix.to_owned(), params: Vec::new() });
                    out.len() - 1
                }
            };
            let section = &mut out[index];
            for (name, value) in params {
                match section.params.iter_mut().find(|(n, _, _)| *n == name) {
                    Some(slot) => *slot = (name, value, file),
                    None => section.params.push((name, value, file)),
                }
            }
            continue;
        }
        let key = if prefix.is_empty() { k.clone() } else { format!("{prefix}/{k}") };
        match v {
            serde_yaml_ng::Value::Mapping(m) => read_node_map(m, &key, file, path, out)?,
            _ => return Err(yaml(format!("`{key}` has a value where a node name or `ros__parameters` was expected"))),
        }
    }
    Ok(())
}

/// Nested parameter maps become dotted names, as rcl reads them (`thin_surfaces: {patterns: ..}`
/// is `thin_surfaces.patterns`; so is a key written `thin_surfaces.patterns`).
pub(super) fn flatten_params(
    map: &serde_yaml_ng::Mapping,
    prefix: &str,
    path: &Path,
    out: &mut Vec<(String, serde_yaml_ng::Value)>,
) -> Result<(), ParamsError> {
    for (k, v) in map {
        let k = key_text(k, path)?;
        let name = if prefix.is_empty() { k } else { format!("{prefix}.{k}") };
        match v {
            serde_yaml_ng::Value::Mapping(m) => flatten_params(m, &name, path, out)?,
            v => out.push((name, v.clone())),
        }
    }
    Ok(())
}

/// A section key rcl_yaml_param_parser accepts (its `__validate_name`): `/**`, or an optional
/// namespace (`/**`, or names) and a node name (a name, or `*`). Names are letters, digits and
/// `_`, not starting with a digit.
pub(super) fn check_node_key(key: &str) -> Result<(), String> {
    if key == "/**" {
        return Ok(());
    }
    let is_name = |t: &str| !t.is_empty() && t.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') && !t.starts_with(|c: char| c.is_ascii_digit());
    let (namespace, node) = key.rsplit_once('/').unwrap_or(("", key));
    if node != "*" && !is_name(node) {
        return Err(format!("'{node}' is not a node name (letters, digits and _, not starting with a digit; or * for any)"));
    }
    let namespace = namespace.strip_prefix('/').unwrap_or(namespace);
    if !namespace.is_empty() && namespace != "**" {
        if let Some(t) = namespace.split('/').find(|t| !is_name(t)) {
            return Err(format!(
                "namespace '/{namespace}': '{t}' is not a name (letters, digits and _, not starting with a digit; the whole namespace may be /**)"
            ));
        }
    }
    Ok(())
}

/// Whether the section key `key` applies to the node `node_fqn`: rclcpp's regex match of the
/// key (a leading `/` added) with `/*` as `(/\w+)`, so `/**` is `(/\w+)*`, written over tokens.
pub(super) fn key_matches(key: &str, node_fqn: &str) -> bool {
    fn tokens_match(pattern: &[&str], name: &[&str]) -> bool {
        match pattern.split_first() {
            None => name.is_empty(),
            Some((&"**", rest)) => (0..=name.len()).any(|i| tokens_match(rest, &name[i..])),
            Some((&"*", rest)) => !name.is_empty() && tokens_match(rest, &name[1..]),
            Some((t, rest)) => name.first() == Some(t) && tokens_match(rest, &name[1..]),
        }
    }
    let pattern: Vec<&str> = key.trim_start_matches('/').split('/').collect();
    let name: Vec<&str> = node_fqn.trim_start_matches('/').split('/').collect();
    tokens_match(&pattern, &name)
}

/// Whether a section speaks to every node (its node name is `*` or it is `/**`) rather than to
/// this one by name.
pub(super) fn is_shared_key(key: &str) -> bool {
    matches!(key.rsplit('/').next(), Some("*" | "**"))
}

/// The sections that match `node_fqn`, applied in order into one [`Params`].
pub(super) fn merge_sections(sections: &[Section], paths: &[PathBuf], node_fqn: &str) -> Result<LoadedParams, ParamsError> {
    let path_of = |file: usize| paths.get(file).cloned().unwrap_or_default();
    let matching: Vec<&Section> = sections.iter().filter(|s| key_matches(&s.key, node_fqn)).collect();
    if matching.is_empty() {
        let files = paths.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ");
        return Err(ParamsError::NoSection { files, node: node_fqn.to_owned(), keys: sections.iter().map(|s| s.key.clone()).collect() });
    }
    // Every leaf parameter and every group (`thin_surfaces`): a group given a scalar is ours,
    // with a wrong type, and serde says so.
    let mut known: Vec<String> = Params::default().flat().into_iter().map(|(n, _)| n).collect();
    let groups: Vec<String> = known.iter().filter_map(|n| n.rsplit_once('.').map(|(g, _)| g.to_owned())).collect();
    known.extend(groups);
    let mut merged: Vec<(String, serde_yaml_ng::Value, usize)> = Vec::new();
    let mut ignored: Vec<String> = Vec::new();
    for section in matching {
        let shared = is_shared_key(&section.key);
        for (name, value, file) in &section.params {
            if !known.contains(name) {
                if shared {
                    if !ignored.contains(name) {
                        ignored.push(name.clone());
                    }
                    continue;
                }
                return Err(ParamsError::Yaml(
                    path_of(*file),
                    format!("section `{}`: unknown parameter `{name}` (`thickness_collision check --show-params` lists them all)", section.key),
                ));
            }
            match merged.iter_mut().find(|(n, _, _)| n == name) {
                Some(slot) => *slot = (name.clone(), value.clone(), *file),
                None => merged.push((name.clone(), value.clone(), *file)),
            }
        }
    }
    let mut root = serde_yaml_ng::Mapping::new();
    for (name, value, file) in &merged {
        insert_dotted(&mut root, name, value.clone()).map_err(|m| ParamsError::Yaml(path_of(*file), m))?;
    }
    let first_file = merged.first().map_or_else(|| path_of(0), |(_, _, f)| path_of(*f));
    let params: Params = serde_yaml_ng::from_value(serde_yaml_ng::Value::Mapping(root)).map_err(|e| ParamsError::Yaml(first_file, e.to_string()))?;
    params.validate()?;
    let mut warnings = Vec::new();
    if !ignored.is_empty() {
        warnings.push(format!(
            "parameters for node {node_fqn}: ignored {} not known to thickness_collision from wildcard sections (/**, /ns/*): {}",
            if ignored.len() == 1 { "a parameter" } else { "parameters" },
            ignored.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ")
        ));
    }
    Ok(LoadedParams { params, warnings })
}

/// Puts `value` at the dotted `name` of `root`, making the groups on the way.
pub(super) fn insert_dotted(root: &mut serde_yaml_ng::Mapping, name: &str, value: serde_yaml_ng::Value) -> Result<(), String> {
    let mut at = root;
    let mut parts = name.split('.').peekable();
    while let Some(part) = parts.next() {
        let key = serde_yaml_ng::Value::String(part.to_owned());
        if parts.peek().is_none() {
            let _ = at.insert(key, value);
            return Ok(());
        }
        let slot = at.entry(key).or_insert_with(|| serde_yaml_ng::Value::Mapping(serde_yaml_ng::Mapping::new()));
        at = match slot {
            serde_yaml_ng::Value::Mapping(m) => m,
            _ => return Err(format!("parameter `{name}`: `{part}` is a value, not a group")),
        };
    }
    Ok(())
}

/// Whether a YAML line has an anchor (`&name`) or an alias (`*name`) outside quotes and comments.
pub(super) fn has_alias(line: &str) -> bool {
    let mut quote = None;
    let mut prev = ' ';
    for c in line.chars() {
        match (quote, c) {
            (None, '#') if prev.is_whitespace() => return false,
            (None, '"' | '\'') => quote = Some(c),
            (Some(q), _) if c == q => quote = None,
            (None, '&' | '*') if prev.is_whitespace() || prev == '[' || prev == ',' || prev == ':' => return true,
            _ => {}
        }
        prev = c;
    }
    false
}
