//! Proximity queries: pure algorithms on shapes in their local frames plus relative poses.
//!
//! The narrowphase "black box" of Coumans' talks, usable on its own like FCL or parry:
//! GJK closest points, EPA penetration depth, special cases (analytic and SAT), ray casts,
//! shape casts, time of impact with rotation, point projection, and batch forms.
//!
//! Conventions: see [`result`]. Functions taking [`crate::shape::Shape`]s and world poses
//! validate their input and return [`crate::Result`]; the `*_local` / `*_convex` forms work in
//! A's frame with `pose_ab` and skip validation (hot paths of the narrowphase).

pub mod epa;
pub mod gjk;
pub mod result;
pub mod simplex;
pub mod support_adapters;

pub use result::{Contact, PointProjection, RayHit, ShapeCastHit};
pub mod closest_points;
pub mod contact_convex;
pub mod contact_cuboid_cuboid;
pub mod contact_round;

pub use contact_convex::{contact_convex, distance_convex, intersects_convex};
pub mod contact;
pub use contact::{contact, contact_local, distance, intersects};
pub mod ray;
pub use ray::{raycast, raycast_local, Ray};
pub mod point;
pub use point::{contains_point, project_point, project_point_local};
pub mod shape_cast;
pub use shape_cast::{shape_cast, shape_cast_local};
pub mod toi;
pub use toi::{time_of_impact, Motion};
pub mod batch;
pub use batch::{
    contact_batch, distance_batch, intersects_batch, project_point_batch, raycast_batch,
    shape_cast_batch,
};
