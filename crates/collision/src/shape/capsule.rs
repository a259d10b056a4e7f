//! Capsule along the local Y axis: a segment with its radius as margin.

use super::support::{sign_nonzero, SupportMap};
use super::MassProperties;
use crate::error::Result;
use crate::math::{check_positive, consts::PI, Aabb, Real, Vec3};
use serde::{Deserialize, Serialize};

/// A capsule along the local **Y** axis: the points within `radius` of the segment from
/// `(0, -half_height, 0)` to `(0, half_height, 0)`. Total length `2·(half_height + radius)`.
/// (Bullet's `btCapsuleShape(r, h)` is `Capsule::new(r, h / 2)`.)
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Capsule {
    radius: Real,
    half_height: Real,
}

impl Capsule {
    /// A capsule; `radius` and `half_height` must be finite and > 0 (use a sphere for a zero
    /// half height).
    pub fn new(radius: Real, half_height: Real) -> Result<Self> {
        Ok(Capsule {
            radius: check_positive("radius", radius)?,
            half_height: check_positive("half_height", half_height)?,
        })
    }

    /// The radius.
    pub fn radius(&self) -> Real {
        self.radius
    }

    /// Half the distance between the two hemisphere centres.
    pub fn half_height(&self) -> Real {
        self.half_height
    }

    /// The end points of the core segment.
    pub fn segment(&self) -> (Vec3, Vec3) {
        (
            Vec3::new(0.0, -self.half_height, 0.0),
            Vec3::new(0.0, self.half_height, 0.0),
        )
    }

    /// Local bounding box.
    pub fn local_aabb(&self) -> Aabb {
        let r = self.radius;
        Aabb::from_center_half_extents(Vec3::ZERO, Vec3::new(r, self.half_height + r, r))
    }

    /// Volume: a cylinder plus a sphere.
    pub fn volume(&self) -> Real {
        let r2 = self.radius * self.radius;
        PI * r2 * 2.0 * self.half_height + 4.0 / 3.0 * PI * r2 * self.radius
    }

    /// Exact solid capsule: cylinder plus two hemispheres, each hemisphere shifted by the
    /// parallel-axis theorem from its own centre of mass (`3r/8` from its flat face).
    pub fn mass_properties(&self, density: Real) -> MassProperties {
        let (r, h) = (self.radius, self.half_height);
        let r2 = r * r;
        let m_cyl = density * PI * r2 * 2.0 * h;
        let m_hemis = density * 4.0 / 3.0 * PI * r2 * r;
        let iy = m_cyl * r2 * 0.5 + m_hemis * 0.4 * r2;
        let ix = m_cyl * (r2 / 4.0 + (2.0 * h) * (2.0 * h) / 12.0)
            + m_hemis * (0.4 * r2 + h * h + 0.75 * h * r);
        MassProperties::new(m_cyl + m_hemis, Vec3::ZERO, Vec3::new(ix, iy, ix))
    }
}

impl SupportMap for Capsule {
    #[inline]
    fn support(&self, dir: Vec3) -> Vec3 {
        self.support_core(dir) + dir.try_normalize().unwrap_or(Vec3::Y) * self.radius
    }
    #[inline]
    fn support_core(&self, dir: Vec3) -> Vec3 {
        Vec3::new(0.0, sign_nonzero(dir.y) * self.half_height, 0.0)
    }
    #[inline]
    fn margin(&self) -> Real {
        self.radius
    }
}
