//! Scalar and vector types, rigid poses and axis-aligned boxes.
//!
//! This is the only module that names a concrete float type or glam type: everything else
//! uses [`Real`], [`Vec3`], [`Quat`] and [`Mat3`], so the `f64` feature switches the whole
//! library to double precision. glam's `fast-math` stays off so results are deterministic.

mod aabb;
mod isometry;
mod order_key;
mod validate;

pub use aabb::Aabb;
pub use isometry::Isometry;
pub use order_key::{f32_to_ordered, ordered_to_real, real_ceil_key, real_floor_key};
pub use validate::*;

#[cfg(not(feature = "f64"))]
mod types {
    /// The scalar type: `f32` by default, `f64` with the `f64` feature.
    pub type Real = f32;
    /// A 3D vector of [`Real`].
    pub type Vec3 = glam::Vec3;
    /// A 16-byte aligned (SIMD) 3D vector of [`Real`] for hot loops; [`Vec3`] itself in `f64`.
    pub type Vec3A = glam::Vec3A;
    /// A quaternion of [`Real`] (`x, y, z, w`).
    pub type Quat = glam::Quat;
    /// A 3x3 column-major matrix of [`Real`].
    pub type Mat3 = glam::Mat3;
    /// A 3x3 matrix of 16-byte aligned (SIMD) columns for hot loops; [`Mat3`] itself in
    /// `f64`. Its products are the same operations, lane by lane, as [`Mat3`]'s.
    pub type Mat3A = glam::Mat3A;
    /// Mathematical constants at [`Real`] precision.
    pub use std::f32::consts;
}

#[cfg(feature = "f64")]
mod types {
    /// The scalar type: `f32` by default, `f64` with the `f64` feature.
    pub type Real = f64;
    /// A 3D vector of [`Real`].
    pub type Vec3 = glam::DVec3;
    /// A 16-byte aligned (SIMD) 3D vector of [`Real`] for hot loops; [`Vec3`] itself in `f64`.
    pub type Vec3A = glam::DVec3;
    /// A quaternion of [`Real`] (`x, y, z, w`).
    pub type Quat = glam::DQuat;
    /// A 3x3 column-major matrix of [`Real`].
    pub type Mat3 = glam::DMat3;
    /// A 3x3 matrix of 16-byte aligned (SIMD) columns for hot loops; [`Mat3`] itself in
    /// `f64`. Its products are the same operations, lane by lane, as [`Mat3`]'s.
    pub type Mat3A = glam::DMat3;
    /// Mathematical constants at [`Real`] precision.
    pub use std::f64::consts;
}

pub use types::*;

/// glam's swizzle methods (`v.yzx()`…) on [`Vec3`] and [`Vec3A`] (one trait in both builds).
pub use glam::Vec3Swizzles;

/// Machine epsilon of [`Real`].
pub const EPSILON: Real = Real::EPSILON;

/// Half-size of the box used as the bounds of unbounded shapes (planes): large enough to
/// contain any scene, small enough that surface areas stay finite in `f32`.
pub const UNBOUNDED: Real = 1.0e15;

/// Converts an `f64` to [`Real`] (a no-op in the `f64` build).
#[inline(always)]
pub fn real(x: f64) -> Real {
    x as Real
}

/// Converts `[f64; 3]` to [`Vec3`].
#[inline]
pub fn vec3_from_f64(v: [f64; 3]) -> Vec3 {
    Vec3::new(v[0] as Real, v[1] as Real, v[2] as Real)
}

/// Converts a [`Vec3`] to `[f64; 3]`.
#[inline]
#[allow(clippy::unnecessary_cast)] // a no-op in the f64 build
pub fn vec3_to_f64(v: Vec3) -> [f64; 3] {
    [v.x as f64, v.y as f64, v.z as f64]
}

/// Two unit vectors that, with the unit vector `n`, form a right-handed orthonormal basis
/// `(t1, t2, n)`. Branch-free construction of Duff et al., "Building an Orthonormal Basis,
/// Revisited" (JCGT 2017).
#[inline]
pub fn orthonormal_basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = (1.0 as Real).copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        Vec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

/// Matrix whose product with `v` is `a × v`.
#[inline]
pub fn skew(a: Vec3) -> Mat3 {
    Mat3::from_cols(
        Vec3::new(0.0, a.z, -a.y),
        Vec3::new(-a.z, 0.0, a.x),
        Vec3::new(a.y, -a.x, 0.0),
    )
}

/// Outer product `a bᵀ`.
#[inline]
pub fn outer(a: Vec3, b: Vec3) -> Mat3 {
    Mat3::from_cols(a * b.x, a * b.y, a * b.z)
}

/// A bound on how far any point within `reach` of a frame's origin moved when the frame went
/// from (`t0`, `q0`) to (`t`, `q`): a point `x` moves by `|Δt + (R - R0) x| <= |Δt| +
/// 2 sin(θ/2) |x|`, `θ` the angle between the rotations, and for unit quaternions
/// `2 sin(θ/2) = 4 sin(θ/4) cos(θ/4) <= 2 |q - q0|` (`q0`'s sign chosen to match `q`). Not
/// `sqrt(1 - (q·q0)²)`: in f32, `q·q0` rounds to 1 for angles under about 5e-4 rad. Used by
/// the narrowphase's separation certificates and by the sleep rule of the dynamics.
#[inline]
pub fn motion_bound(t0: Vec3, q0: Quat, t: Vec3, q: Quat, reach: Real) -> Real {
    let q0 = if q0.dot(q) < 0.0 { -q0 } else { q0 };
    (t - t0).length() + 2.0 * (q - q0).length() * reach
}

/// A process-wide unique number naming some contents: a [`crate::shape::TriMesh`]'s
/// triangles, a [`crate::world::CollisionWorld`]'s objects. Caches compare it instead of the
/// contents, so their owners take a fresh one whenever the contents change; a clone keeps it
/// (same contents). Equality of the owners ignores it (always equal): it names contents,
/// it is not part of them.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Stamp(u64);

impl Stamp {
    /// A number no earlier stamp in this process had (from 1 up).
    pub(crate) fn fresh() -> Stamp {
        use std::sync::atomic::{AtomicU64, Ordering};
        static NEXT: AtomicU64 = AtomicU64::new(1);
        Stamp(NEXT.fetch_add(1, Ordering::Relaxed))
    }

    /// The number.
    pub(crate) fn get(self) -> u64 {
        self.0
    }
}

impl Default for Stamp {
    fn default() -> Self {
        Stamp::fresh()
    }
}

impl PartialEq for Stamp {
    /// Always true (see the type's docs).
    fn eq(&self, _: &Stamp) -> bool {
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orthonormal_basis_is_orthonormal_and_right_handed() {
        let dirs = [
            Vec3::X,
            Vec3::Y,
            Vec3::Z,
            -Vec3::Z,
            Vec3::new(1.0, 2.0, -3.0).normalize(),
            Vec3::new(0.0, 0.0, -1.0 + 1e-7).normalize(),
        ];
        for n in dirs {
            let (t1, t2) = orthonormal_basis(n);
            assert!((t1.length() - 1.0).abs() < 1e-5);
            assert!((t2.length() - 1.0).abs() < 1e-5);
            assert!(t1.dot(n).abs() < 1e-5 && t2.dot(n).abs() < 1e-5 && t1.dot(t2).abs() < 1e-5);
            assert!((t1.cross(t2) - n).length() < 1e-4);
        }
    }

    #[test]
    fn skew_is_cross_product() {
        let a = Vec3::new(1.0, -2.0, 0.5);
        let v = Vec3::new(0.3, 4.0, -1.0);
        assert!((skew(a) * v - a.cross(v)).length() < 1e-5);
    }
}
