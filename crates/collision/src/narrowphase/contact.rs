//! The talk's contact point (Coumans, "Contact Generation", GDC 2010: distance, normal on B,
//! point on B; the point on A is derived as `a = b + n·d`), extended with the local points
//! used by the persistent manifold, a feature id and the solver's accumulated impulses
//! (Bullet's `btManifoldPoint`).

use crate::math::{Isometry, Mat3, Real, Vec3};
use crate::query::Contact;
use serde::{Deserialize, Serialize};

/// Identifies the pair of features (faces, edges, vertices, triangles, children) that
/// produced a contact, so the same contact is recognised from one step to the next.
pub type FeatureId = u32;

/// Generated contacts with feature ids, in A's frame with the query convention (normal from
/// A towards B): what the dispatcher's algorithms append to.
pub type ContactList = Vec<(Contact, FeatureId)>;

/// A feature id that matches nothing: such points are matched by distance only.
pub const NO_FEATURE: FeatureId = u32::MAX;

/// One contact point of a manifold.
///
/// Conventions (the talk's): `normal` is the world unit normal **on B, pointing from B towards
/// A**; `distance` is signed (negative = penetration depth); `point_b` is the world point on
/// B and the world point on A is `point_b + normal * distance` ([`ContactPoint::point_a`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ContactPoint {
    /// Signed distance along `normal` (negative when penetrating).
    pub distance: Real,
    /// World unit normal on B, from B towards A.
    pub normal: Vec3,
    /// World point on B.
    pub point_b: Vec3,
    /// The point on A in A's local frame.
    pub local_a: Vec3,
    /// The point on B in B's local frame.
    pub local_b: Vec3,
    /// The normal in B's local frame (so [`crate::narrowphase::ContactManifold::refresh`]
    /// follows B's rotation).
    pub local_normal_b: Vec3,
    /// The features that produced the point.
    pub feature: FeatureId,
    /// Accumulated normal impulse (solver warm starting), carried across steps.
    pub normal_impulse: Real,
    /// Accumulated friction impulses along the two tangents of [`ContactPoint::tangents`].
    pub tangent_impulse: [Real; 2],
    /// Number of steps the point has persisted (0 when new).
    pub lifetime: u32,
}

impl ContactPoint {
    /// A point from a query [`Contact`] expressed in A's local frame (query convention: normal
    /// from A towards B), for bodies at world poses `pose_a` and `pose_b`.
    pub fn from_local_contact(
        c: &Contact,
        pose_a: &Isometry,
        pose_b: &Isometry,
        feature: FeatureId,
    ) -> ContactPoint {
        let point_b = pose_a.transform_point(c.point_b);
        let normal = -pose_a.transform_vector(c.normal);
        ContactPoint {
            distance: c.distance,
            normal,
            point_b,
            local_a: c.point_a,
            local_b: pose_b.inverse_transform_point(point_b),
            local_normal_b: pose_b.inverse_transform_vector(normal),
            feature,
            normal_impulse: 0.0,
            tangent_impulse: [0.0; 2],
            lifetime: 0,
        }
    }

    /// [`ContactPoint::from_local_contact`] with the bodies' poses as rotation matrices
    /// (`ra`, `rb`, e.g. [`Isometry::rotation_matrix`]) and translations (`ta`, `tb`), and
    /// `rb_t` the transpose of `rb` (its inverse): four matrix–vector products instead of
    /// four quaternion rotations, with the matrices built once per pair. The persistent
    /// manifold refreshes its points with the same matrices.
    #[inline]
    pub fn from_local_contact_mat(
        c: &Contact,
        (ra, ta): (&Mat3, Vec3),
        (rb_t, tb): (&Mat3, Vec3),
        feature: FeatureId,
    ) -> ContactPoint {
        let point_b = *ra * c.point_b + ta;
        let normal = -(*ra * c.normal);
        ContactPoint {
            distance: c.distance,
            normal,
            point_b,
            local_a: c.point_a,
            local_b: *rb_t * (point_b - tb),
            local_normal_b: *rb_t * normal,
            feature,
            normal_impulse: 0.0,
            tangent_impulse: [0.0; 2],
            lifetime: 0,
        }
    }

    /// The world point on A derived from the point on B: `a = b + n·d`.
    #[inline]
    pub fn point_a(&self) -> Vec3 {
        self.point_b + self.normal * self.distance
    }

    /// The midpoint of the two witness points (where a solver applies the impulse).
    #[inline]
    pub fn midpoint(&self) -> Vec3 {
        self.point_b + self.normal * (0.5 * self.distance)
    }

    /// Two world unit tangents orthogonal to `normal`, a fixed function of the normal (the
    /// friction directions of `tangent_impulse`).
    #[inline]
    pub fn tangents(&self) -> (Vec3, Vec3) {
        crate::math::orthonormal_basis(self.normal)
    }

    /// True when every field is finite.
    pub fn is_finite(&self) -> bool {
        self.distance.is_finite()
            && self.normal.is_finite()
            && self.point_b.is_finite()
            && self.local_a.is_finite()
            && self.local_b.is_finite()
    }
}
