//! # carom-collision
//!
//! Collision detection for Carom, usable on its own like FCL or parry: shapes with support
//! maps and mass properties, proximity queries, broadphase, midphase and narrowphase.
//!
//! The modules follow the pipeline of Erwin Coumans' talks (see `docs/ARCHITECTURE.md`):
//! `math` → `bvh` → `shape` → `midphase` → `query` → `broadphase` → `narrowphase` → `world`;
//! a module only uses the ones listed before it. The hierarchies (`bvh`) come before `shape`
//! because meshes and compounds own them; the midphase comes before `query` because ray casts
//! and point queries on meshes and heightfields run its traversals.
//!
//! Precision is chosen once, at build time: `Real` is `f32` by default and `f64` with the
//! `f64` feature. Nothing outside [`math`] names a concrete float or glam type.
#![warn(missing_docs)]
#![deny(unsafe_code)]

pub mod broadphase;
pub mod bvh;
pub mod error;
pub mod math;
pub mod midphase;
pub mod narrowphase;
pub mod query;
pub mod shape;
pub mod world;

pub use error::{CaromError, Result};
