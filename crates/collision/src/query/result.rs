//! Plain result types shared by every query.
//!
//! Conventions (ARCHITECTURE.md, "Contact point" and "Python conventions"): `distance` is
//! signed (negative = minus the penetration depth), `point_a` and `point_b` are witness points
//! on A and B, and `normal` is the unit vector from A towards B, so that
//! `point_b = point_a + normal * distance` holds in every case, separated or penetrating.
//! The talk's contact point (distance, normal on B pointing to A, point on B) is the same
//! information with the opposite sign of the normal: see [`Contact::normal_on_b`].

use crate::math::{Isometry, Real, Vec3};
use serde::{Deserialize, Serialize};

/// Closest points or penetration between two shapes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Contact {
    /// Signed distance: positive when apart, negative when overlapping (minus the depth of the
    /// minimum translational distance).
    pub distance: Real,
    /// Witness point on A.
    pub point_a: Vec3,
    /// Witness point on B.
    pub point_b: Vec3,
    /// Unit normal from A towards B: translating B by `-distance * normal` makes the shapes
    /// touch.
    pub normal: Vec3,
}

impl Contact {
    /// The same contact seen from B: A and B exchanged, normal flipped.
    #[inline]
    pub fn swapped(&self) -> Contact {
        Contact {
            distance: self.distance,
            point_a: self.point_b,
            point_b: self.point_a,
            normal: -self.normal,
        }
    }

    /// The contact with points and normal mapped by `pose` (e.g. from A's frame to world).
    #[inline]
    pub fn transformed(&self, pose: &Isometry) -> Contact {
        Contact {
            distance: self.distance,
            point_a: pose.transform_point(self.point_a),
            point_b: pose.transform_point(self.point_b),
            normal: pose.transform_vector(self.normal),
        }
    }

    /// The talk's normal "on B", pointing from B towards A (`-normal`).
    #[inline]
    pub fn normal_on_b(&self) -> Vec3 {
        -self.normal
    }

    /// True when the shapes overlap (`distance < 0`).
    #[inline]
    pub fn is_penetrating(&self) -> bool {
        self.distance < 0.0
    }
}

/// A ray hit.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RayHit {
    /// Distance along the (unit) ray direction: the hit point is `origin + distance * dir`.
    pub distance: Real,
    /// The hit point.
    pub point: Vec3,
    /// Outward unit surface normal at the hit point (for a ray starting inside a solid shape,
    /// `-dir`; for triangles and meshes, the side facing the ray's origin).
    pub normal: Vec3,
    /// True when the ray's origin was inside the (solid) shape.
    pub inside: bool,
    /// The triangle hit, for meshes; the child index for compounds; `None` otherwise.
    pub feature: Option<u32>,
}

impl RayHit {
    /// The hit mapped by `pose` (local frame to world).
    #[inline]
    pub fn transformed(&self, pose: &Isometry) -> RayHit {
        RayHit {
            point: pose.transform_point(self.point),
            normal: pose.transform_vector(self.normal),
            ..*self
        }
    }
}

/// Result of a shape cast or a time-of-impact query.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ShapeCastHit {
    /// Time of impact as a fraction of the motion (in `[0, 1]` for a full step; for a linear
    /// cast, the motion vector is scaled by this).
    pub toi: Real,
    /// Witness point on A at the time of impact (world space).
    pub point_a: Vec3,
    /// Witness point on B at the time of impact (world space).
    pub point_b: Vec3,
    /// Unit normal from A towards B at the time of impact (world space).
    pub normal: Vec3,
    /// True when the shapes already overlapped at the start (`toi == 0`).
    pub initially_overlapping: bool,
}

impl ShapeCastHit {
    /// The hit at time `toi` whose witnesses and normal are those of the contact `c` at that
    /// time (the contact query that ends a cast or an advancement).
    pub fn at_contact(toi: Real, c: &Contact, initially_overlapping: bool) -> Self {
        ShapeCastHit {
            toi,
            point_a: c.point_a,
            point_b: c.point_b,
            normal: c.normal,
            initially_overlapping,
        }
    }
}

/// Projection of a point on a shape's surface.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PointProjection {
    /// The closest point on the shape's boundary.
    pub point: Vec3,
    /// Signed distance from the query point to the boundary (negative inside).
    pub distance: Real,
    /// True when the query point is inside the shape (or on its boundary).
    pub inside: bool,
}
