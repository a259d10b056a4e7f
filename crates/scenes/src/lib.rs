//! # carom-scenes
//!
//! The scenes of Bullet's benchmark (`shared/bench/SCENES.md`), built once as plain
//! descriptions (shapes, poses, masses, joints, rays) so that tests, benchmarks, the demo and
//! the Python parity tests all simulate exactly the same thing. The data (Taru hull points,
//! the landscape mesh, the Halton cells) is embedded from `data/`.
#![warn(missing_docs)]

pub mod bullet;
pub mod data;
pub mod glibc_rand;
mod scene;

pub use scene::{JointDesc, JointKind, Scene, SceneBody, SolverSettings};
