//! One line of a `check --states` file (JSON lines): a joint state or a set of link transforms,
//! turned into the message the node would receive and put through the pipeline.

use super::{CheckedState, Pipeline, RobotState};
use crate::checker::StateReport;
use crate::msgs::{Header, JointState, Quaternion, TfMessage, Time, Transform, TransformStamped, Vector3};
use serde::Deserialize;

/// A parsed states-file line.
#[derive(Clone, Debug, PartialEq)]
pub enum StateLine {
    /// `{"name": [...], "position": [...], "stamp": ns}`.
    Joints {
        /// Joint names.
        name: Vec<String>,
        /// Positions, one per name.
        position: Vec<f64>,
        /// Stamp in nanoseconds (0 when absent).
        stamp: i64,
    },
    /// `{"transforms": [{"link", "translation", "rotation"}...], "stamp": ns}`.
    Transforms {
        /// Link poses in `world_frame`.
        transforms: Vec<LinkTransform>,
        /// Stamp in nanoseconds (0 when absent).
        stamp: i64,
    },
}

/// The pose of one link in a `transforms` line.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LinkTransform {
    /// Link name (without `frame_prefix`).
    pub link: String,
    /// Metres.
    pub translation: [f64; 3],
    /// Quaternion x, y, z, w.
    pub rotation: [f64; 4],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JointsLine {
    name: Vec<String>,
    position: Vec<f64>,
    #[serde(default)]
    stamp: i64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TransformsLine {
    transforms: Vec<LinkTransform>,
    #[serde(default)]
    stamp: i64,
}

const EXPECTED: &str =
    "expected {\"name\": [...], \"position\": [...]} or {\"transforms\": [{\"link\", \"translation\", \"rotation\"}]}, with an optional \"stamp\"";

/// Why a `check --states` line is not a state: one line saying what is wrong and what is expected.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct StateLineError(String);

/// Parses a line of a `check --states` file.
pub fn parse_state_line(line: &str) -> Result<StateLine, StateLineError> {
    parse(line).map_err(StateLineError)
}

fn parse(line: &str) -> Result<StateLine, String> {
    let line = line.strip_prefix('\u{feff}').unwrap_or(line);
    let value: serde_json::Value = serde_json::from_str(line).map_err(|e| format!("not JSON ({e}); {EXPECTED}"))?;
    let Some(object) = value.as_object() else {
        return Err(format!("a JSON {} instead of an object; {EXPECTED}", kind(&value)));
    };
    if object.contains_key("transforms") {
        let t: TransformsLine = serde_json::from_value(value).map_err(|e| format!("a transforms state: {e}; {EXPECTED}"))?;
        Ok(StateLine::Transforms { transforms: t.transforms, stamp: t.stamp })
    } else if object.contains_key("name") || object.contains_key("position") {
        let j: JointsLine = serde_json::from_value(value).map_err(|e| format!("a joint state: {e}; {EXPECTED}"))?;
        Ok(StateLine::Joints { name: j.name, position: j.position, stamp: j.stamp })
    } else {
        let keys: Vec<&str> = object.keys().map(String::as_str).collect();
        Err(format!("an object with keys [{}]; {EXPECTED}", crate::limits::name_list(&keys)))
    }
}

fn kind(v: &serde_json::Value) -> &'static str {
    match v {
        serde_json::Value::Null => "null",
        serde_json::Value::Bool(_) => "boolean",
        serde_json::Value::Number(_) => "number",
        serde_json::Value::String(_) => "string",
        serde_json::Value::Array(_) => "array",
        serde_json::Value::Object(_) => "object",
    }
}

impl Pipeline {
    /// Checks a states-file line as the node checks the message it stands for; a state the
    /// pipeline cannot check fails closed in its place (`in_collision` and `error`).
    pub fn check_line(&mut self, state: StateLine) -> CheckedState {
        let (stamp, result) = self.line_state(state);
        match result {
            Ok(state) => self.check(&state),
            Err(skip) => CheckedState { stamp, report: StateReport::failed(skip.message) },
        }
    }

    /// The state a line stands for (through the pipeline: merged, validated), or why there is none.
    pub fn line_state(&mut self, state: StateLine) -> (Time, Result<RobotState, super::Skip>) {
        match state {
            StateLine::Joints { name, position, stamp } => {
                let stamp = Time::from_nanos(stamp);
                let msg = JointState { header: Header { stamp, frame_id: String::new() }, name, position, ..Default::default() };
                (stamp, self.joint_state(&msg))
            }
            StateLine::Transforms { transforms, stamp } => {
                let stamp = Time::from_nanos(stamp);
                let (world, prefix) = (self.params().world_frame.clone(), self.params().frame_prefix.clone());
                let transforms = transforms
                    .into_iter()
                    .map(|t| {
                        let ([x, y, z], [qx, qy, qz, qw]) = (t.translation, t.rotation);
                        TransformStamped {
                            header: Header { stamp, frame_id: world.clone() },
                            child_frame_id: format!("{prefix}{}", t.link),
                            transform: Transform { translation: Vector3 { x, y, z }, rotation: Quaternion { x: qx, y: qy, z: qz, w: qw } },
                        }
                    })
                    .collect();
                (stamp, self.tf(&TfMessage { transforms }))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_and_their_errors() {
        let j = parse_state_line("\u{feff}{\"name\": [\"a\"], \"position\": [1.5], \"stamp\": 7}").unwrap();
        assert_eq!(j, StateLine::Joints { name: vec!["a".into()], position: vec![1.5], stamp: 7 });
        let e = parse_state_line("[1, 2]").unwrap_err().to_string();
        assert!(e.starts_with("a JSON array instead of an object"), "{e}");
        let e = parse_state_line("{\"joints\": {}}").unwrap_err().to_string();
        assert!(e.starts_with("an object with keys [joints]"), "{e}");
        let e = parse_state_line("{\"name\": [\"a\"], \"position\": [\"x\"]}").unwrap_err().to_string();
        assert!(e.starts_with("a joint state: invalid type: string \"x\", expected f64"), "{e}");
        let e = parse_state_line("{\"transforms\": [{\"link\": \"a\", \"translation\": [0, 0], \"rotation\": [0, 0, 0, 1]}]}").unwrap_err().to_string();
        assert!(e.starts_with("a transforms state:") && e.contains("length 2"), "{e}");
        assert!(!e.contains('\n'));
    }
}
