//! The Python exception hierarchy and the panic guard.
//!
//! Every [`carom_collision::CaromError`] becomes a `carom.CaromError` (a `ValueError`
//! subclass) whose message names the bad value. Every call into the Rust core goes through
//! [`guard`], so a Rust panic becomes a Python `RuntimeError` instead of reaching the
//! interpreter.

use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};

pyo3::create_exception!(
    carom,
    CaromError,
    PyValueError,
    "Invalid input rejected by Carom (a ValueError subclass); the message names the bad value."
);

/// Converts a core error into a `carom.CaromError`.
pub fn carom_err(e: carom_collision::CaromError) -> PyErr {
    CaromError::new_err(e.to_string())
}

/// A `carom.CaromError` with a free-form message.
pub fn invalid(message: impl Into<String>) -> PyErr {
    CaromError::new_err(message.into())
}

/// Runs `f`, turning a Rust panic into a `RuntimeError` (a bug in Carom, never the user's
/// fault) so it never unwinds into the interpreter.
pub fn guard<T>(f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(result) => result,
        Err(payload) => {
            let msg = if let Some(s) = payload.downcast_ref::<&str>() {
                s.to_string()
            } else if let Some(s) = payload.downcast_ref::<String>() {
                s.clone()
            } else {
                "unknown panic".to_string()
            };
            Err(PyRuntimeError::new_err(format!(
                "internal error in carom (please report it): {msg}"
            )))
        }
    }
}

/// Runs a fallible core call under [`guard`], converting its error.
pub fn core<T>(f: impl FnOnce() -> carom_collision::Result<T>) -> PyResult<T> {
    guard(|| f().map_err(carom_err))
}
