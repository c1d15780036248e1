//! Joint positions from Python: a sequence or NumPy array in `joint_names` order, or a
//! `{name: value}` dict; batches as `N x dof` arrays. Checked here for length and finiteness so
//! that the message names the joint; names are checked by the library.

use crate::errors::value_error;
use numpy::{PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Names and values of one state.
pub struct State {
    /// The names a dict gave; empty for values in `joint_names` order (not copied per call).
    names: Vec<String>,
    pub values: Vec<f64>,
}

impl State {
    /// The joints the values are for.
    pub fn names<'a>(&'a self, joint_names: &'a [String]) -> &'a [String] {
        if self.names.is_empty() {
            joint_names
        } else {
            &self.names
        }
    }
}

/// `values` checked against `names` (the checker's `joint_names`): as many, all finite.
fn checked(names: &[String], values: Vec<f64>, what: &str) -> PyResult<Vec<f64>> {
    if values.len() != names.len() {
        return Err(value_error(format!("{what} has {} values; joint_names has {}: {}", values.len(), names.len(), names.join(", "))));
    }
    if let Some((i, v)) = values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(value_error(format!("{what}[{i}] ({}) is {v}: a position must be a finite number", names[i])));
    }
    Ok(values)
}

/// One state from `q`.
pub fn state(q: &Bound<'_, PyAny>, joint_names: &[String], what: &str) -> PyResult<State> {
    if let Ok(d) = q.cast::<PyDict>() {
        let mut names = Vec::with_capacity(d.len());
        let mut values = Vec::with_capacity(d.len());
        for (k, v) in d.iter() {
            let name: String =
                k.extract().map_err(|_| value_error(format!("{what}: a key is {}, not a joint name", k.repr().map_or("?".into(), |r| r.to_string()))))?;
            let value: f64 = v.extract().map_err(|_| value_error(format!("{what}['{name}'] is not a number")))?;
            if !value.is_finite() {
                return Err(value_error(format!("{what}['{name}'] is {value}: a position must be a finite number")));
            }
            names.push(name);
            values.push(value);
        }
        return Ok(State { names, values });
    }
    let values: Vec<f64> = if let Ok(a) = q.extract::<PyReadonlyArray1<'_, f64>>() {
        a.as_array().to_vec()
    } else {
        q.extract().map_err(|_| value_error(format!("{what}: a sequence of numbers in joint_names order, or a dict of name: value")))?
    };
    Ok(State { names: Vec::new(), values: checked(joint_names, values, what)? })
}

/// Rows of an `N x dof` array (or a sequence of sequences), each checked as a state.
pub fn rows(q: &Bound<'_, PyAny>, joint_names: &[String], what: &str) -> PyResult<Vec<Vec<f64>>> {
    let rows: Vec<Vec<f64>> = if let Ok(a) = q.extract::<PyReadonlyArray2<'_, f64>>() {
        a.as_array().rows().into_iter().map(|r| r.to_vec()).collect()
    } else {
        q.extract().map_err(|_| value_error(format!("{what}: an N x {} array of numbers (rows in joint_names order)", joint_names.len())))?
    };
    rows.into_iter().enumerate().map(|(i, r)| checked(joint_names, r, &format!("{what}[{i}]"))).collect()
}
