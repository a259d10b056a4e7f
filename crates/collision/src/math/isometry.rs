//! Rigid transforms: a rotation followed by a translation.

use super::{Mat3, Quat, Vec3};
use serde::{Deserialize, Serialize};

/// A rigid transform `x ↦ rotation * x + translation`.
///
/// Naming convention used throughout Carom: `pose_ab` is the pose of frame B expressed in
/// frame A (it maps B-local coordinates to A-local coordinates).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Isometry {
    /// Unit quaternion rotation.
    pub rotation: Quat,
    /// Translation applied after the rotation.
    pub translation: Vec3,
}

impl Default for Isometry {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Isometry {
    /// The identity transform.
    pub const IDENTITY: Isometry = Isometry {
        rotation: Quat::IDENTITY,
        translation: Vec3::ZERO,
    };

    /// A transform from a rotation and a translation. The rotation must be a unit quaternion
    /// (use [`crate::math::check_isometry`] on untrusted input).
    #[inline]
    pub fn new(translation: Vec3, rotation: Quat) -> Self {
        Isometry {
            rotation,
            translation,
        }
    }

    /// A pure translation.
    #[inline]
    pub fn from_translation(translation: Vec3) -> Self {
        Isometry {
            rotation: Quat::IDENTITY,
            translation,
        }
    }

    /// A pure rotation.
    #[inline]
    pub fn from_rotation(rotation: Quat) -> Self {
        Isometry {
            rotation,
            translation: Vec3::ZERO,
        }
    }

    /// Applies the transform to a point.
    #[inline]
    pub fn transform_point(&self, p: Vec3) -> Vec3 {
        self.rotation * p + self.translation
    }

    /// Applies the rotation only (for directions and normals).
    #[inline]
    pub fn transform_vector(&self, v: Vec3) -> Vec3 {
        self.rotation * v
    }

    /// Applies the inverse transform to a point.
    #[inline]
    pub fn inverse_transform_point(&self, p: Vec3) -> Vec3 {
        self.rotation.inverse() * (p - self.translation)
    }

    /// Applies the inverse rotation to a vector.
    #[inline]
    pub fn inverse_transform_vector(&self, v: Vec3) -> Vec3 {
        self.rotation.inverse() * v
    }

    /// The inverse transform.
    #[inline]
    pub fn inverse(&self) -> Isometry {
        let rotation = self.rotation.inverse();
        Isometry {
            rotation,
            translation: -(rotation * self.translation),
        }
    }

    /// Composition `self * rhs`: applies `rhs` first, then `self`.
    /// With `pose_ab` and `pose_bc`, `pose_ab.mul(&pose_bc)` is `pose_ac`.
    #[inline]
    #[allow(clippy::should_implement_trait)]
    pub fn mul(&self, rhs: &Isometry) -> Isometry {
        Isometry {
            rotation: (self.rotation * rhs.rotation).normalize(),
            translation: self.rotation * rhs.translation + self.translation,
        }
    }

    /// `self.inverse() * rhs` without forming the inverse: with world poses `pose_a` and
    /// `pose_b`, `pose_a.inv_mul(&pose_b)` is `pose_ab`, B expressed in A's frame.
    #[inline]
    pub fn inv_mul(&self, rhs: &Isometry) -> Isometry {
        let inv_rot = self.rotation.inverse();
        Isometry {
            rotation: (inv_rot * rhs.rotation).normalize(),
            translation: inv_rot * (rhs.translation - self.translation),
        }
    }

    /// The rotation as a 3x3 matrix.
    #[inline]
    pub fn rotation_matrix(&self) -> Mat3 {
        Mat3::from_quat(self.rotation)
    }
}

impl std::ops::Mul for Isometry {
    type Output = Isometry;
    #[inline]
    fn mul(self, rhs: Isometry) -> Isometry {
        Isometry::mul(&self, &rhs)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Real;

    fn pose(seed: Real) -> Isometry {
        Isometry::new(
            Vec3::new(seed, -2.0 * seed, 0.5),
            Quat::from_axis_angle(Vec3::new(1.0, seed, 0.3).normalize(), 0.7 * seed),
        )
    }

    #[test]
    fn inverse_and_composition() {
        let a = pose(1.3);
        let b = pose(-0.4);
        let p = Vec3::new(0.2, 0.9, -1.5);
        let ab = a.inv_mul(&b);
        assert!((a.mul(&ab).transform_point(p) - b.transform_point(p)).length() < 1e-5);
        assert!((a.inverse().transform_point(a.transform_point(p)) - p).length() < 1e-5);
        assert!((a.inverse_transform_point(a.transform_point(p)) - p).length() < 1e-5);
        assert!(
            ((a * b).transform_point(p) - a.transform_point(b.transform_point(p))).length() < 1e-5
        );
        let v = Vec3::new(1.0, 2.0, 3.0);
        assert!((a.inverse_transform_vector(a.transform_vector(v)) - v).length() < 1e-5);
        assert!((a.rotation_matrix() * v - a.transform_vector(v)).length() < 1e-5);
    }
}
