//! The error type of the whole library.
//!
//! Invalid input is rejected when shapes, bodies and worlds are built, so hot paths carry no
//! error plumbing. Every message names the bad value.

use std::fmt;

/// Every error Carom reports.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CaromError {
    /// An argument has a value outside its valid domain (negative size, NaN, ...).
    #[error("invalid {name} = {value}: {reason}")]
    InvalidValue {
        /// Name of the offending argument, e.g. `"radius"` or `"indices[3][1]"`.
        name: String,
        /// The offending value, formatted.
        value: String,
        /// Why it is rejected.
        reason: String,
    },
    /// The input is geometrically degenerate for the requested object
    /// (e.g. a convex hull of coplanar points).
    #[error("degenerate {name}: {reason}")]
    Degenerate {
        /// What was being built.
        name: String,
        /// Why it cannot be built.
        reason: String,
    },
    /// A shape of this kind cannot be used where it was given.
    #[error("unsupported: {0}")]
    Unsupported(String),
    /// A handle that does not name a live object.
    #[error("unknown handle: {0}")]
    UnknownHandle(String),
    /// A file or byte buffer could not be parsed.
    #[error("cannot parse {what}: {reason}")]
    Parse {
        /// What was being parsed (a path or a format name).
        what: String,
        /// What went wrong.
        reason: String,
    },
}

/// Result alias used throughout Carom.
pub type Result<T> = std::result::Result<T, CaromError>;

impl CaromError {
    /// Builds an [`CaromError::InvalidValue`].
    pub fn invalid(
        name: impl Into<String>,
        value: impl fmt::Debug,
        reason: impl Into<String>,
    ) -> Self {
        CaromError::InvalidValue {
            name: name.into(),
            value: format!("{value:?}"),
            reason: reason.into(),
        }
    }

    /// Builds a [`CaromError::Degenerate`].
    pub fn degenerate(name: impl Into<String>, reason: impl Into<String>) -> Self {
        CaromError::Degenerate {
            name: name.into(),
            reason: reason.into(),
        }
    }
}
