//! The support-map abstraction: all GJK, EPA, shape casts and conservative advancement need.

use crate::math::{Isometry, Real, Vec3};

/// A convex shape described by its support function.
///
/// Following Coumans' contact-generation talk, a convex shape is a *core* shape swept by a
/// sphere of radius [`SupportMap::margin`]: a sphere is a point with its radius as margin, a
/// capsule a segment. Boxes, cylinders and cones keep their margin *inside* the user's shape
/// (the core is the shape shrunk by the margin), so [`SupportMap::support_with_margin`]
/// rounds their edges slightly, while [`SupportMap::support`] is always the exact support of
/// the shape the user described. Queries that work on cores compensate for the margin.
///
/// Directions need not be normalised. For a zero direction any point of the shape is a valid
/// answer; implementations return a deterministic one and never NaN.
pub trait SupportMap {
    /// Exact support point of the shape in local coordinates: a point `p` of the shape
    /// maximising `p · dir`.
    fn support(&self, dir: Vec3) -> Vec3;

    /// Support point of the core shape (the shape "without margin").
    fn support_core(&self, dir: Vec3) -> Vec3;

    /// Radius of the sphere swept around the core ("the margin"). Zero for shapes without one.
    fn margin(&self) -> Real;

    /// Support point of the core swept by the margin ("with margin"): `core + margin · d̂`.
    #[inline]
    fn support_with_margin(&self, dir: Vec3) -> Vec3 {
        let core = self.support_core(dir);
        let m = self.margin();
        if m == 0.0 {
            core
        } else {
            core + dir.normalize_or_zero() * m
        }
    }

    /// Exact support point in world space for the shape placed at `pose`; `dir` is a world
    /// direction.
    #[inline]
    fn support_world(&self, pose: &Isometry, dir: Vec3) -> Vec3 {
        pose.transform_point(self.support(pose.inverse_transform_vector(dir)))
    }
}

/// Sign function that maps `0` (and `-0`) to `+1`, so support points of symmetric shapes are
/// deterministic for zero direction components.
#[inline(always)]
pub(crate) fn sign_nonzero(x: Real) -> Real {
    if x < 0.0 {
        -1.0
    } else {
        1.0
    }
}
