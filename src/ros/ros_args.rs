//! The usual `--ros-args` arguments: `-r __ns:=/robot1`, `-r __node:=name`, `-r from:=to`,
//! `-p key:=value`, `--params-file F`.

use anyhow::{bail, Result};

/// What `--ros-args` said.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RosArgs {
    /// `__ns` remap.
    pub namespace: Option<String>,
    /// `__node` remap.
    pub node_name: Option<String>,
    /// Topic and service remaps `from:=to`.
    pub remaps: Vec<(String, String)>,
    /// `-p key:=value` parameters (values as YAML scalars).
    pub params: Vec<(String, String)>,
    /// `--params-file` files.
    pub params_files: Vec<String>,
}

/// Parses the arguments after `--ros-args` (up to an optional `--`).
pub fn parse_ros_args(args: &[String]) -> Result<RosArgs> {
    let mut out = RosArgs::default();
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--" => break,
            "--ros-args" => {}
            "-r" | "--remap" => {
                let Some(rule) = it.next() else { bail!("--ros-args: {a} needs from:=to") };
                let Some((from, to)) = rule.split_once(":=") else { bail!("--ros-args: remap '{rule}' is not from:=to") };
                match from {
                    "__ns" => out.namespace = Some(to.to_owned()),
                    "__node" | "__name" => out.node_name = Some(to.to_owned()),
                    _ => out.remaps.push((from.to_owned(), to.to_owned())),
                }
            }
            "-p" | "--param" => {
                let Some(kv) = it.next() else { bail!("--ros-args: {a} needs key:=value") };
                let Some((k, v)) = kv.split_once(":=") else { bail!("--ros-args: parameter '{kv}' is not key:=value") };
                out.params.push((k.to_owned(), v.to_owned()));
            }
            "--params-file" => {
                let Some(f) = it.next() else { bail!("--ros-args: --params-file needs a file") };
                out.params_files.push(f.clone());
            }
            "--log-level" | "-e" | "--enclave" => {
                let _ = it.next();
            }
            other => bail!("--ros-args: unknown argument '{other}'"),
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn remaps_params_and_files() {
        let v: Vec<String> =
            ["-r", "__ns:=/robot1", "-r", "__node:=tc", "-r", "joint_states:=/arm/js", "-p", "default_thickness:=0.03", "--params-file", "p.yaml"]
                .iter()
                .map(|s| s.to_string())
                .collect();
        let a = parse_ros_args(&v).unwrap();
        assert_eq!(a.namespace.as_deref(), Some("/robot1"));
        assert_eq!(a.node_name.as_deref(), Some("tc"));
        assert_eq!(a.remaps, vec![("joint_states".to_owned(), "/arm/js".to_owned())]);
        assert_eq!(a.params, vec![("default_thickness".to_owned(), "0.03".to_owned())]);
        assert_eq!(a.params_files, vec!["p.yaml".to_owned()]);
        assert!(parse_ros_args(&["-x".to_string()]).is_err());
    }
}
