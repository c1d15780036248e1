//! The node's parameters as ROS 2 parameter values: declared from [`Params::flat`], and a value
//! set through the parameter services turned back into typed parameters.

use crate::model::{glob_match, Params};
use ros2_client::{NodeOptions, ParameterValue};
use serde_json::Value;
use std::sync::{Arc, Mutex};

/// Parameters that shape the node's topics and services, fixed once they are created, and the
/// list that fixes others.
const FIXED: [&str; 7] =
    ["planning_scene", "pose_source", "service_mapping", "use_sim_time", "robot_description_topic", "robot_description_semantic_topic", "read_only_parameters"];

/// Which parameters a remote `set_parameters` may not change: [`FIXED`], and those the
/// deployment's `read_only_parameters` names (read at start).
#[derive(Clone, Debug)]
pub(crate) struct ReadOnly {
    patterns: Vec<String>,
}

impl ReadOnly {
    pub(crate) fn of(params: &Params) -> ReadOnly {
        ReadOnly { patterns: params.read_only_parameters.clone() }
    }

    /// Why `name` may not be changed while the node runs; `None` when it may.
    pub(crate) fn reason(&self, name: &str) -> Option<String> {
        if FIXED.contains(&name) {
            return Some(format!("parameter '{name}' is read-only while the node runs (it shapes the node's topics)"));
        }
        let pattern = self.patterns.iter().find(|p| glob_match(p, name))?;
        Some(format!("parameter '{name}' is read-only: read_only_parameters names it ('{pattern}')"))
    }
}

/// Every parameter with its ROS 2 value. An empty list takes its element type from
/// [`Params::array_kinds`] (JSON cannot tell an empty list of numbers from one of strings).
pub(crate) fn declarations(params: &Params) -> Vec<(String, ParameterValue)> {
    let kinds = Params::array_kinds();
    params
        .flat()
        .into_iter()
        .map(|(name, v)| {
            let value = match v {
                Value::Array(a) if a.is_empty() => match kinds.iter().find(|(n, _)| *n == name).map(|(_, k)| k.clone()) {
                    Some(Value::Number(_)) => ParameterValue::DoubleArray(vec![]),
                    _ => ParameterValue::StringArray(vec![]),
                },
                v => to_parameter(&v),
            };
            (name, value)
        })
        .collect()
}

fn to_parameter(v: &Value) -> ParameterValue {
    match v {
        Value::Bool(b) => ParameterValue::Boolean(*b),
        Value::Number(n) if n.is_f64() => ParameterValue::Double(n.as_f64().unwrap_or(f64::NAN)),
        Value::Number(n) => n.as_i64().map_or(ParameterValue::Double(n.as_f64().unwrap_or(f64::NAN)), ParameterValue::Integer),
        Value::String(s) => ParameterValue::String(s.clone()),
        Value::Array(a) if a.iter().all(Value::is_number) => ParameterValue::DoubleArray(a.iter().filter_map(Value::as_f64).collect()),
        Value::Array(a) => ParameterValue::StringArray(a.iter().map(|x| x.as_str().map_or_else(|| x.to_string(), str::to_owned)).collect()),
        Value::Null | Value::Object(_) => ParameterValue::NotSet,
    }
}

/// A parameter value as JSON, for [`Params::with_value`] (which checks its type).
pub(crate) fn to_json(value: &ParameterValue) -> Value {
    let num = |x: f64| serde_json::Number::from_f64(x).map_or(Value::Null, Value::Number);
    match value {
        ParameterValue::NotSet => Value::Null,
        ParameterValue::Boolean(b) => Value::Bool(*b),
        ParameterValue::Integer(i) => Value::from(*i),
        ParameterValue::Double(d) => num(*d),
        ParameterValue::String(s) => Value::String(s.clone()),
        ParameterValue::ByteArray(a) => Value::Array(a.iter().map(|x| Value::from(*x)).collect()),
        ParameterValue::BooleanArray(a) => Value::Array(a.iter().map(|x| Value::Bool(*x)).collect()),
        ParameterValue::IntegerArray(a) => Value::Array(a.iter().map(|x| Value::from(*x)).collect()),
        ParameterValue::DoubleArray(a) => Value::Array(a.iter().map(|x| num(*x)).collect()),
        ParameterValue::StringArray(a) => Value::Array(a.iter().map(|x| Value::String(x.clone())).collect()),
    }
}

/// The node's options: its parameters declared, and where accepted changes go: the
/// set-parameters service only validates (it runs in the spinner's task); the loop rebuilds.
pub(crate) fn parameter_options(params: &Params, changes: smol::channel::Sender<Params>) -> NodeOptions {
    let accepted = Arc::new(Mutex::new(params.clone()));
    let read_only = ReadOnly::of(params);
    let action = move |name: &str, value: &ParameterValue| -> Result<(), String> {
        let mut current = accepted.lock().map_err(|_| "parameter state poisoned".to_string())?;
        let fresh = current.with_value(name, to_json(value)).map_err(|e| e.to_string())?;
        if fresh == *current {
            return Ok(());
        }
        if let Some(reason) = read_only.reason(name) {
            return Err(reason);
        }
        changes.try_send(fresh.clone()).map_err(|_| "the node is shutting down".to_string())?;
        *current = fresh;
        Ok(())
    };
    // The node serves the parameter services itself (param_services.rs): ros2-client's serve
    // the enhanced mapping only, and describe every parameter as writable.
    let mut options = NodeOptions::new().enable_rosout(true).start_parameter_services(false);
    for (name, value) in declarations(params) {
        options = options.declare_parameter(&name, value);
    }
    options.parameter_set_action(Box::new(action))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn declared_values_set_back_to_the_same_parameters() {
        let p = Params::default();
        for (name, value) in declarations(&p) {
            assert_eq!(p.with_value(&name, to_json(&value)).unwrap(), p, "{name} = {value:?}");
        }
        let kinds: Vec<_> = declarations(&p).into_iter().filter(|(n, _)| n == "padding.values" || n == "thin_surfaces.thickness").collect();
        assert!(kinds.iter().all(|(_, v)| matches!(v, ParameterValue::DoubleArray(_))), "{kinds:?}");
    }
}
