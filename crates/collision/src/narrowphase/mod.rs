//! Contact generation (Coumans, "Contact Generation", GDC 2010): turns overlapping pairs into
//! persistent multi-point contact manifolds.
//!
//! - [`contact`]: the contact point; [`manifold`]: the persistent manifold;
//! - [`pipeline`]: the [`NarrowPhase`] stage of the collision world (events, sensors);
//! - [`contact_cuboid_cuboid`]: box–box, settled by the boxes' own separating-axis test;
//!   [`contact_capsule_cuboid`]: capsule–box, segment–box closest points and face clipping;
//! - [`polyhedron`]: SAT with Gauss-map pruning and face clipping for boxes, hulls and
//!   triangles, and plane–polyhedron; [`convex`]: analytic manifolds for round shapes and
//!   multi-point by perturbation; [`triangle_cuboid`]: the triangle–box special case of the
//!   separating-axis test; [`mesh`]: convex against triangle meshes and compounds
//!   with internal-edge correction; [`dispatcher`]: the shape-pair table.

pub mod contact;
pub mod manifold;

pub use contact::{ContactList, ContactPoint, FeatureId, NO_FEATURE};
pub use manifold::{
    ContactManifold, ManifoldConfig, Separation, COHERENCE_ANGLE, COHERENCE_DISTANCE,
    MAX_MANIFOLD_POINTS,
};
pub mod contact_capsule_cuboid;
pub mod contact_cuboid_cuboid;
pub mod convex;
pub mod dispatcher;
pub mod mesh;
mod mesh_hull;
mod mesh_round;
pub mod polyhedron;
pub mod polyhedron_guided;
mod polyhedron_sat;
pub mod triangle_cuboid;

pub use dispatcher::{Dispatcher, Generated, UserAlgorithm};
pub mod pipeline;
pub use pipeline::{ContactEvent, ContactEventKind, NarrowObject, NarrowPhase, PairContact};
