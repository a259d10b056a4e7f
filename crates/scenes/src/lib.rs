//! Shared scenes.
#![warn(missing_docs)]
