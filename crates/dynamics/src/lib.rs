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
//! friction direction) back into the same manifolds. The full `World::step` on top of
//! `CollisionWorld` (issue 6) will:
//! 1. copy body poses ([`BodySet::pose`]) into the collision objects;
//! 2. run broadphase → midphase → narrowphase, skipping pairs for which
//!    [`DynamicsWorld::should_collide`] is false (joints with `disable_collisions`, two
//!    non-dynamic bodies);
//! 3. fill a [`ContactManifold`] per persistent manifold (its points keep their impulses by
//!    feature id), call `step`, and copy the impulses back into the persistent manifolds;
//! 4. move the bodies of [`StepReport::slept`] / [`StepReport::woken`] between the
//!    broadphase's resting and active trees.
//!
//! ## Solver choice
//!
//! The soft step ([`SolverKind::SoftStep`]) is the default: on the stacking tests it drifts
//! less than sequential impulses at a similar cost (figures in the crate's tests and the
//! project report); sequential impulses remain selectable with
//! [`DynamicsWorld::set_solver`].
#![warn(missing_docs)]

pub use carom_collision as collision;

mod body;
mod body_set;
mod contact;
mod integrate;
mod island;
pub mod joint;
pub mod solver;
mod world;

pub use body::{mix_friction, mix_restitution, BodyDesc, BodyType, MassSpec, ResolvedMass};
pub use body_set::{BodyHandle, BodyInfo, BodySet};
pub use contact::{ContactManifold, ContactPoint, MAX_MANIFOLD_POINTS};
pub use island::SleepParams;
pub use joint::{
    Axis, AxisMode, Joint, JointDesc, JointHandle, JointKind, JointSet, Motor, Spring,
};
pub use solver::{SolverKind, SolverParams, StepTimings};
pub use world::{DynamicsWorld, StepReport, WorldParams};
