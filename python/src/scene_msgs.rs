//! MoveIt's scene objects from Python: a `moveit_msgs/CollisionObject` or
//! `AttachedCollisionObject` as a dict with the message's field names, applied to a checker's
//! pipeline exactly as the node applies the `collision_object` and `attached_collision_object`
//! topics. Fields left out keep the message's defaults; a field the message does not have is an
//! error (a typo must not be ignored).

use crate::checker::Checker;
use crate::errors::value_error;
use pyo3::prelude::*;
use serde::de::DeserializeOwned;
use serde::Serialize;
use serde_json::Value;
use thickness_collision::msgs::planning_scene::{AttachedCollisionObject, CollisionObject};
use thickness_collision::msgs::JointState;

/// `given` laid over `base`: objects field by field (every field must be one of `base`'s), anything
/// else replaced whole. Recursion follows `base`, a message's own nesting, not the input's.
fn overlay(base: &mut Value, given: Value, path: &str) -> PyResult<()> {
    match (base, given) {
        (Value::Object(fields), Value::Object(given)) => {
            for (key, value) in given {
                let Some(slot) = fields.get_mut(&key) else {
                    let known: Vec<&str> = fields.keys().map(String::as_str).collect();
                    return Err(value_error(format!("{path} has no field '{key}' (its fields: {})", known.join(", "))));
                };
                overlay(slot, value, &format!("{path}.{key}"))?;
            }
            Ok(())
        }
        (slot, given) => {
            *slot = given;
            Ok(())
        }
    }
}

/// A message of type `T` from a dict (through JSON: lists, not arrays).
fn message<T: Default + Serialize + DeserializeOwned>(msg: &Bound<'_, PyAny>, what: &str) -> PyResult<T> {
    let text: String = msg
        .py()
        .import("json")?
        .call_method1("dumps", (msg,))
        .map_err(|e| value_error(format!("{what}: not JSON-like ({e}); give lists, not arrays")))?
        .extract()?;
    let given: Value = serde_json::from_str(&text).map_err(|e| value_error(format!("{what}: {e}")))?;
    let mut base = serde_json::to_value(T::default()).map_err(|e| value_error(format!("{what}: {e}")))?;
    overlay(&mut base, given, what)?;
    serde_json::from_value(base).map_err(|e| value_error(format!("{what}: {e}")))
}

/// The joint state `q` (when given) made the pipeline's current one: objects placed on robot
/// links, and attachments, use it.
fn set_state(checker: &Checker, q: Option<&Bound<'_, PyAny>>) -> PyResult<()> {
    let Some(q) = q else { return Ok(()) };
    let s = crate::positions::state(q, checker.names(), "q")?;
    let msg = JointState { name: s.names(checker.names()).to_vec(), position: s.values, ..Default::default() };
    checker.pipeline().joint_state(&msg).map(|_| ()).map_err(|skip| value_error(skip.message))
}

/// Applies a `CollisionObject` dict, with `q` first made the current state when given.
pub fn apply_collision_object(checker: &Checker, msg: &Bound<'_, PyAny>, q: Option<&Bound<'_, PyAny>>) -> PyResult<()> {
    let msg: CollisionObject = message(msg, "CollisionObject")?;
    set_state(checker, q)?;
    checker.pipeline().collision_object(&msg).map_err(|skip| value_error(skip.message))
}

/// Applies an `AttachedCollisionObject` dict, with `q` first made the current state when given.
pub fn apply_attached_collision_object(checker: &Checker, msg: &Bound<'_, PyAny>, q: Option<&Bound<'_, PyAny>>) -> PyResult<()> {
    let msg: AttachedCollisionObject = message(msg, "AttachedCollisionObject")?;
    set_state(checker, q)?;
    checker.pipeline().attached_collision_object(&msg).map_err(|skip| value_error(skip.message))
}
