//! Rigid-body dynamics (in progress).
#![warn(missing_docs)]
pub use carom_collision as collision;
