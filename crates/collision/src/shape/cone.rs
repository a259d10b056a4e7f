//! Cone along the local Y axis.

use super::cuboid::{DEFAULT_MARGIN, MAX_MARGIN_FRACTION};
use super::support::SupportMap;
use super::MassProperties;
use crate::error::{CaromError, Result};
use crate::math::{check_non_negative, check_positive, consts::PI, Aabb, Real, Vec3};
use serde::{Deserialize, Serialize};

/// A solid cone along the local **Y** axis, centred on its bounding box: the apex is at
/// `(0, half_height, 0)` and the base disc of radius `radius` at `y = -half_height`. Its
/// centre of mass is at `(0, -half_height / 2, 0)`.
///
/// The margin lies inside: the core is the inward offset cone (same apex angle, base raised by
/// the margin, apex lowered by `margin / sin α`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Cone {
    radius: Real,
    half_height: Real,
    margin: Real,
}

/// Support point of a Y cone with apex at `apex_y` and base disc (radius `radius`) at `base_y`.
#[inline]
fn cone_support(radius: Real, base_y: Real, apex_y: Real, dir: Vec3) -> Vec3 {
    let radial = Vec3::new(dir.x, 0.0, dir.z);
    let len = radial.length();
    let rim = if len > 0.0 {
        Vec3::new(dir.x * radius / len, base_y, dir.z * radius / len)
    } else {
        Vec3::new(radius, base_y, 0.0)
    };
    let apex = Vec3::new(0.0, apex_y, 0.0);
    if apex.dot(dir) >= rim.dot(dir) {
        apex
    } else {
        rim
    }
}

impl Cone {
    /// A cone; `radius` and `half_height` must be finite and > 0.
    pub fn new(radius: Real, half_height: Real) -> Result<Self> {
        let radius = check_positive("radius", radius)?;
        let half_height = check_positive("half_height", half_height)?;
        let mut cone = Cone {
            radius,
            half_height,
            margin: 0.0,
        };
        cone.margin = DEFAULT_MARGIN
            .min(MAX_MARGIN_FRACTION * radius.min(half_height))
            .min(0.25 * cone.max_margin());
        Ok(cone)
    }

    /// Largest margin that leaves a non-empty core: `m (1 + 1/sin α) < H`.
    fn max_margin(&self) -> Real {
        let h = 2.0 * self.half_height;
        let sin_a = self.radius / (self.radius * self.radius + h * h).sqrt();
        h / (1.0 + 1.0 / sin_a)
    }

    /// The same cone with another margin (non-negative, leaving a non-empty core).
    pub fn with_margin(mut self, margin: Real) -> Result<Self> {
        check_non_negative("margin", margin)?;
        let limit = self.max_margin();
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

    /// The base radius.
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

    /// Volume `π r² H / 3`.
    pub fn volume(&self) -> Real {
        PI * self.radius * self.radius * 2.0 * self.half_height / 3.0
    }

    /// Solid cone: centre of mass at a quarter of the height above the base,
    /// `Iyy = 3/10 m r²`, `Ixx = m (3/20 r² + 3/80 H²)` about the centre of mass.
    pub fn mass_properties(&self, density: Real) -> MassProperties {
        let m = density * self.volume();
        let r2 = self.radius * self.radius;
        let h = 2.0 * self.half_height;
        let ix = m * (3.0 / 20.0 * r2 + 3.0 / 80.0 * h * h);
        MassProperties::new(
            m,
            Vec3::new(0.0, -0.5 * self.half_height, 0.0),
            Vec3::new(ix, 0.3 * m * r2, ix),
        )
    }
}

impl SupportMap for Cone {
    #[inline]
    fn support(&self, dir: Vec3) -> Vec3 {
        cone_support(self.radius, -self.half_height, self.half_height, dir)
    }
    #[inline]
    fn support_core(&self, dir: Vec3) -> Vec3 {
        if self.margin == 0.0 {
            return self.support(dir);
        }
        let h = 2.0 * self.half_height;
        let sin_a = self.radius / (self.radius * self.radius + h * h).sqrt();
        let base_y = -self.half_height + self.margin;
        let apex_y = self.half_height - self.margin / sin_a;
        let r = self.radius * (apex_y - base_y) / h;
        cone_support(r, base_y, apex_y, dir)
    }
    #[inline]
    fn margin(&self) -> Real {
        self.margin
    }
}
