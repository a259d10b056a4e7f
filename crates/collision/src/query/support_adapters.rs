//! Support-function adapters that make GJK, EPA and the casts generic and testable without
//! bodies, after Jolt's `Jolt/Geometry/ConvexSupport.h`: a shape placed at a pose, a shape
//! swept by a sphere, and a Minkowski difference.
//!
//! Every query works in the frame of shape A: B is placed with `pose_ab` (B in A's frame).

use crate::math::{Mat3, Real, Vec3};
use crate::shape::{ConvexRef, SupportMap};

/// A convex set given by its support function.
pub trait Support {
    /// A point of the set maximising `p · dir`. Zero directions give any point, never NaN.
    fn support(&self, dir: Vec3) -> Vec3;
}

impl<T: Support + ?Sized> Support for &T {
    #[inline]
    fn support(&self, dir: Vec3) -> Vec3 {
        (**self).support(dir)
    }
}

/// The exact shape the user described (`SupportMap::support`).
#[derive(Debug, Clone, Copy)]
pub struct Exact<'a>(pub ConvexRef<'a>);

impl Support for Exact<'_> {
    #[inline]
    fn support(&self, dir: Vec3) -> Vec3 {
        match self.0 {
            ConvexRef::Cone(c) => cone_support_rim_first(c, dir),
            other => other.support(dir),
        }
    }
}

/// A cone's exact support that prefers the base rim when the apex and the rim tie within
/// round-off. Every lateral-surface normal is perpendicular to a generator, so near a cone's
/// side the apex and the rim point tie; returning the apex every time stalls GJK (the apex is
/// already in the simplex), while the rim point at the query angle makes progress.
#[inline]
fn cone_support_rim_first(c: &crate::shape::Cone, dir: Vec3) -> Vec3 {
    let (r, h) = (c.radius(), c.half_height());
    let radial = Vec3::new(dir.x, 0.0, dir.z);
    let len = radial.length();
    let rim = if len > 0.0 {
        Vec3::new(dir.x * r / len, -h, dir.z * r / len)
    } else {
        Vec3::new(r, -h, 0.0)
    };
    let apex = Vec3::new(0.0, h, 0.0);
    let slack = 16.0 * crate::math::EPSILON * (r + h) * dir.length();
    if apex.dot(dir) > rim.dot(dir) + slack {
        apex
    } else {
        rim
    }
}

/// The "core" used by GJK, following the talk: spheres are their centre and capsules their
/// segment (the radius is added back analytically, so results stay exact), every other shape
/// is its exact self (GJK on polytopes is exact, so they need no margin).
#[derive(Debug, Clone, Copy)]
pub struct Core<'a>(pub ConvexRef<'a>);

impl Support for Core<'_> {
    #[inline]
    fn support(&self, dir: Vec3) -> Vec3 {
        match self.0 {
            ConvexRef::Sphere(_) => Vec3::ZERO,
            ConvexRef::Capsule(c) => c.support_core(dir),
            other => other.support(dir),
        }
    }
}

/// The radius that [`Core`] removes from `shape`: the sphere or capsule radius, else 0.
#[inline]
pub fn core_radius(shape: ConvexRef<'_>) -> Real {
    match shape {
        ConvexRef::Sphere(s) => s.radius(),
        ConvexRef::Capsule(c) => c.radius(),
        _ => 0.0,
    }
}

/// A support function placed by a rigid transform, given as a rotation matrix and a
/// translation (`x ↦ rotation · x + translation`). Matrices are faster than quaternions in
/// the support loop.
#[derive(Debug, Clone, Copy)]
pub struct Transformed<S> {
    /// The shape in its local frame.
    pub inner: S,
    /// Rotation from the inner frame to the outer frame.
    pub rotation: Mat3,
    /// Transpose of `rotation`.
    pub rotation_t: Mat3,
    /// Translation.
    pub translation: Vec3,
}

impl<S> Transformed<S> {
    /// Places `inner` with `pose` (inner frame to outer frame).
    #[inline]
    pub fn new(inner: S, pose: &crate::math::Isometry) -> Self {
        let rotation = pose.rotation_matrix();
        Transformed {
            inner,
            rotation,
            rotation_t: rotation.transpose(),
            translation: pose.translation,
        }
    }
}

impl<S: Support> Support for Transformed<S> {
    #[inline]
    fn support(&self, dir: Vec3) -> Vec3 {
        self.rotation * self.inner.support(self.rotation_t * dir) + self.translation
    }
}

/// A support function swept by a sphere of radius `radius` (Minkowski sum with a ball).
#[derive(Debug, Clone, Copy)]
pub struct AddRadius<S> {
    /// The core.
    pub inner: S,
    /// The sphere's radius.
    pub radius: Real,
}

impl<S: Support> Support for AddRadius<S> {
    #[inline]
    fn support(&self, dir: Vec3) -> Vec3 {
        let p = self.inner.support(dir);
        if self.radius == 0.0 {
            return p;
        }
        p + dir.try_normalize().unwrap_or(Vec3::Y) * self.radius
    }
}

/// A single point.
#[derive(Debug, Clone, Copy)]
pub struct PointSupport(pub Vec3);

impl Support for PointSupport {
    #[inline]
    fn support(&self, _dir: Vec3) -> Vec3 {
        self.0
    }
}

/// A segment between two points.
#[derive(Debug, Clone, Copy)]
pub struct SegmentSupport(pub Vec3, pub Vec3);

impl Support for SegmentSupport {
    #[inline]
    fn support(&self, dir: Vec3) -> Vec3 {
        if self.1.dot(dir) > self.0.dot(dir) {
            self.1
        } else {
            self.0
        }
    }
}

/// A point set given by a slice of vertices (support by linear scan).
#[derive(Debug, Clone, Copy)]
pub struct PolytopeSupport<'a>(pub &'a [Vec3]);

impl Support for PolytopeSupport<'_> {
    #[inline]
    fn support(&self, dir: Vec3) -> Vec3 {
        let mut best = self.0[0];
        let mut best_dot = best.dot(dir);
        for &v in &self.0[1..] {
            let d = v.dot(dir);
            if d > best_dot {
                best_dot = d;
                best = v;
            }
        }
        best
    }
}

/// The Minkowski difference `A - B` of two support functions, also returning the two
/// support points so that witness points can be recovered.
#[derive(Debug, Clone, Copy)]
pub struct MinkowskiDiff<A, B> {
    /// The first set.
    pub a: A,
    /// The second set.
    pub b: B,
}

impl<A: Support, B: Support> MinkowskiDiff<A, B> {
    /// Support of `A - B` in `dir`: `(s_A(dir) - s_B(-dir), s_A(dir), s_B(-dir))`.
    #[inline]
    pub fn support_pair(&self, dir: Vec3) -> (Vec3, Vec3, Vec3) {
        let pa = self.a.support(dir);
        let pb = self.b.support(-dir);
        (pa - pb, pa, pb)
    }
}

impl<A: Support, B: Support> Support for MinkowskiDiff<A, B> {
    #[inline]
    fn support(&self, dir: Vec3) -> Vec3 {
        self.support_pair(dir).0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Isometry, Quat};
    use crate::shape::{Capsule, Cuboid, Sphere};

    #[test]
    fn transformed_support_is_the_moved_support() {
        let b = Cuboid::new(Vec3::new(1.0, 2.0, 3.0)).unwrap();
        let pose = Isometry::new(
            Vec3::new(5.0, -1.0, 2.0),
            Quat::from_axis_angle(Vec3::new(1.0, 1.0, 0.0).normalize(), 0.7),
        );
        let t = Transformed::new(Exact(ConvexRef::Cuboid(&b)), &pose);
        for d in [Vec3::X, Vec3::new(0.3, -0.2, 0.9), -Vec3::Z] {
            let expect = ConvexRef::Cuboid(&b).support_world(&pose, d);
            assert!((t.support(d) - expect).length() < 1e-4);
        }
    }

    #[test]
    fn core_plus_radius_is_the_exact_round_shape() {
        let s = Sphere::new(0.7).unwrap();
        let c = Capsule::new(0.3, 1.1).unwrap();
        for shape in [ConvexRef::Sphere(&s), ConvexRef::Capsule(&c)] {
            let round = AddRadius {
                inner: Core(shape),
                radius: core_radius(shape),
            };
            for d in [Vec3::X, Vec3::new(0.3, -0.2, 0.9), Vec3::Y] {
                assert!((round.support(d) - shape.support(d)).length() < 1e-5);
            }
        }
    }

    #[test]
    fn minkowski_difference_pairs() {
        let m = MinkowskiDiff {
            a: SegmentSupport(Vec3::ZERO, Vec3::X),
            b: PointSupport(Vec3::Y),
        };
        let (w, a, b) = m.support_pair(Vec3::X);
        assert_eq!(w, a - b);
        assert_eq!(a, Vec3::X);
        assert_eq!(b, Vec3::Y);
    }
}
