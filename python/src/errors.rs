//! What the library's errors become in Python: bad input is a `ValueError`, anything else a
//! `thickness_collision.Error`, each with the library's message.

use pyo3::create_exception;
use pyo3::exceptions::{PyException, PyValueError};
use pyo3::PyErr;

create_exception!(thickness_collision, Error, PyException, "A model, parameters or scene that cannot be loaded or used.");

/// A `thickness_collision.Error` with `message`.
pub fn error(message: impl std::fmt::Display) -> PyErr {
    Error::new_err(message.to_string())
}

/// A `ValueError` with `message`.
pub fn value_error(message: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(message.to_string())
}
