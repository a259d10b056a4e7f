//! # carom-dynamics
//!
//! Rigid-body dynamics for Carom: bodies with generational handles and flat hot arrays, a
//! contact input that persistent manifolds fill, two constraint solvers (sequential impulses
//! with split impulses, and Box2D v3's substepping soft step), joints for ragdolls, islands
//! and sleeping, and a [`DynamicsWorld::step`] with per-stage timings.
//!
//! ## The seam with collision detection
//!
//! [`DynamicsWorld::step`] takes this step's contacts as `&mut [ContactManifold]`: one
//! manifold per touching pair, with body-local witness points, the refreshed separation and
//! the accumulated impulses of the previous step. It writes the new impulses (and the
//! friction direction) back into the same manifolds. [`World`] (module [`pipeline`]) bundles
//! it with a `CollisionWorld`: its `step(dt)` syncs poses with speculative margins, runs the
//! broadphase and narrowphase, turns the persistent manifolds into solver contacts (normal
//! from A to B), solves, and writes the impulses back for the next step's warm start.
//!
//! ## Solver choice
//!
//! The soft step ([`SolverKind::SoftStep`], 4 substeps, 1 iteration + 1 relax each) is the
//! default. Measured with `cargo run --release -p carom-dynamics --example solver_compare`
//! (unit boxes of 1000 kg, dt = 1/60 s, 2000 steps, analytic face contacts; drift after the
//! first second):
//!
//! | scene      | solver                  | settling | drift  |
//! |------------|-------------------------|----------|--------|
//! | 10-stack   | soft step               | 2.6 cm   | 0.5 cm |
//! | 10-stack   | sequential impulses, 10 | collapses (13 m)  |
//! | 10-stack   | sequential impulses, 40 | 0.6 cm   | 1.4 cm |
//! | pyramid 20 | soft step               | 3.8 cm   | 0.7 cm |
//! | pyramid 20 | sequential impulses, 10 | 5.5 cm   | 4.3 cm |
//! | pyramid 20 | sequential impulses, 40 | 1.0 cm   | 0.1 cm |
//!
//! At equal cost (10 iterations vs 4 substeps) the soft step is the stable one; sequential
//! impulses need about four times the work to hold the same stacks. The soft step's settling
//! is the compression of its 30 Hz contact springs under the stack's weight. Sequential
//! impulses remain selectable with [`DynamicsWorld::set_solver`].
#![warn(missing_docs)]

pub use carom_collision as collision;

mod body;
mod body_set;
mod contact;
mod integrate;
mod island;
pub mod joint;
pub mod pipeline;
pub mod solver;
mod world;

pub use body::{mix_friction, mix_restitution, BodyDesc, BodyType, MassSpec, ResolvedMass};
pub use body_set::{BodyHandle, BodyInfo, BodySet};
pub use contact::{ContactManifold, ContactPoint, MAX_MANIFOLD_POINTS};
pub use island::SleepParams;
pub use joint::{
    Axis, AxisMode, Joint, JointDesc, JointHandle, JointKind, JointSet, Motor, Spring,
};
pub use pipeline::{
    BodyRayHit, BodyShapeCastHit, PipelineParams, PipelineReport, PipelineTimings, World,
    WorldQuery,
};
pub use solver::{SolverKind, SolverParams, StepTimings};
pub use world::{DynamicsWorld, StepReport, WorldParams};
