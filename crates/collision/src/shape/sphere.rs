//! Sphere: a point with its radius as margin.

use super::support::SupportMap;
use super::MassProperties;
use crate::error::Result;
use crate::math::{check_positive, consts::PI, Aabb, Real, Vec3};
use serde::{Deserialize, Serialize};

/// A sphere of radius `radius` centred at the local origin. As in the talk, its core is the
/// centre point and its margin is the radius.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Sphere {
    radius: Real,
}

impl Sphere {
    /// A sphere; `radius` must be finite and > 0.
    pub fn new(radius: Real) -> Result<Self> {
        Ok(Sphere {
            radius: check_positive("radius", radius)?,
        })
    }

    /// The radius.
    pub fn radius(&self) -> Real {
        self.radius
    }

    /// Local bounding box.
    pub fn local_aabb(&self) -> Aabb {
        Aabb::from_center_half_extents(Vec3::ZERO, Vec3::splat(self.radius))
    }

    /// Volume `4/3 π r³`.
    pub fn volume(&self) -> Real {
        4.0 / 3.0 * PI * self.radius.powi(3)
    }

    /// Solid sphere: `I = 2/5 m r²`.
    pub fn mass_properties(&self, density: Real) -> MassProperties {
        let m = density * self.volume();
        MassProperties::new(
            m,
            Vec3::ZERO,
            Vec3::splat(0.4 * m * self.radius * self.radius),
        )
    }
}

impl SupportMap for Sphere {
    #[inline]
    fn support(&self, dir: Vec3) -> Vec3 {
        // A zero direction gives the top point (deterministic, on the surface).
        dir.try_normalize().unwrap_or(Vec3::Y) * self.radius
    }
    #[inline]
    fn support_core(&self, _dir: Vec3) -> Vec3 {
        Vec3::ZERO
    }
    #[inline]
    fn margin(&self) -> Real {
        self.radius
    }
}
