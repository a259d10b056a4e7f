//! # carom-collision
//!
//! Collision detection for Carom, usable on its own like FCL or parry: shapes with support
//! maps and mass properties, proximity queries, broadphase, midphase and narrowphase.
//!
//! The modules follow the pipeline of Erwin Coumans' talks (see `docs/ARCHITECTURE.md`):
//! `math` → `shape` → `query` → `broadphase` → `midphase` → `narrowphase` → `world`; a module
//! only uses the ones listed before it.
//!
//! Precision is chosen once, at build time: `Real` is `f32` by default and `f64` with the
//! `f64` feature. Nothing outside [`math`] names a concrete float or glam type.
#![warn(missing_docs)]
#![deny(unsafe_code)]

pub mod error;
pub mod math;
pub mod midphase;
pub mod query;
pub mod shape;

pub use error::{CaromError, Result};
