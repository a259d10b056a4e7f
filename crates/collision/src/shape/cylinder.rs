//! Cylinder along the local Y axis.

use super::cuboid::{DEFAULT_MARGIN, MAX_MARGIN_FRACTION};
use super::support::{sign_nonzero, SupportMap};
use super::MassProperties;
use crate::error::{CaromError, Result};
use crate::math::{check_non_negative, check_positive, consts::PI, Aabb, Real, Vec3};
use serde::{Deserialize, Serialize};

/// A solid cylinder along the local **Y** axis, centred at the origin: radius `radius`, from
/// `y = -half_height` to `y = half_height`. The margin lies inside (the core is the cylinder
/// shrunk by the margin).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Cylinder {
    radius: Real,
    half_height: Real,
    margin: Real,
}

/// Support point of an (unrounded) Y cylinder.
#[inline]
fn cylinder_support(radius: Real, half_height: Real, dir: Vec3) -> Vec3 {
    let radial = Vec3::new(dir.x, 0.0, dir.z);
    let len = radial.length();
    let rim = if len > 0.0 {
        radial * (radius / len)
    } else {
        Vec3::new(radius, 0.0, 0.0)
    };
    Vec3::new(rim.x, sign_nonzero(dir.y) * half_height, rim.z)
}

impl Cylinder {
    /// A cylinder; `radius` and `half_height` must be finite and > 0.
    pub fn new(radius: Real, half_height: Real) -> Result<Self> {
        let radius = check_positive("radius", radius)?;
        let half_height = check_positive("half_height", half_height)?;
        Ok(Cylinder {
            radius,
            half_height,
            margin: DEFAULT_MARGIN.min(MAX_MARGIN_FRACTION * radius.min(half_height)),
        })
    }

    /// The same cylinder with another margin, in `[0, min(radius, half_height))`.
    pub fn with_margin(mut self, margin: Real) -> Result<Self> {
        check_non_negative("margin", margin)?;
        let limit = self.radius.min(self.half_height);
        if margin >= limit {
            return Err(CaromError::invalid(
                "margin",
                margin,
                format!("must be smaller than {limit}"),
            ));
        }
        self.margin = margin;
        Ok(self)
    }

    /// The radius.
    pub fn radius(&self) -> Real {
        self.radius
    }

    /// Half the height.
    pub fn half_height(&self) -> Real {
        self.half_height
    }

    /// Local bounding box.
    pub fn local_aabb(&self) -> Aabb {
        Aabb::from_center_half_extents(
            Vec3::ZERO,
            Vec3::new(self.radius, self.half_height, self.radius),
        )
    }

    /// Volume `π r² · 2h`.
    pub fn volume(&self) -> Real {
        PI * self.radius * self.radius * 2.0 * self.half_height
    }

    /// Solid cylinder: `Iyy = m r² / 2`, `Ixx = m (3r² + H²) / 12` with `H = 2h`.
    pub fn mass_properties(&self, density: Real) -> MassProperties {
        let m = density * self.volume();
        let r2 = self.radius * self.radius;
        let hh = 2.0 * self.half_height;
        let ix = m * (3.0 * r2 + hh * hh) / 12.0;
        MassProperties::new(m, Vec3::ZERO, Vec3::new(ix, 0.5 * m * r2, ix))
    }
}

impl SupportMap for Cylinder {
    #[inline]
    fn support(&self, dir: Vec3) -> Vec3 {
        cylinder_support(self.radius, self.half_height, dir)
    }
    #[inline]
    fn support_core(&self, dir: Vec3) -> Vec3 {
        cylinder_support(
            self.radius - self.margin,
            self.half_height - self.margin,
            dir,
        )
    }
    #[inline]
    fn margin(&self) -> Real {
        self.margin
    }
}
