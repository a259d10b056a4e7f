//! Box (cuboid), `carom.Box` in Python.

use super::support::{sign_nonzero, SupportMap};
use super::MassProperties;
use crate::error::{CaromError, Result};
use crate::math::{check_non_negative, check_positive_vec, Aabb, Real, Vec3};
use serde::{Deserialize, Serialize};

/// Default collision margin, Bullet's `CONVEX_DISTANCE_MARGIN` (0.04 length units). Shapes
/// clamp it to a fraction of their smallest dimension so small shapes keep a real core.
pub const DEFAULT_MARGIN: Real = 0.04;

/// Fraction of the smallest half-dimension a default margin may take.
pub(crate) const MAX_MARGIN_FRACTION: Real = 0.2;

/// An axis-aligned box centred at the origin with half extents `half_extents`.
/// The margin lies inside the box: the core is the box shrunk by the margin.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Cuboid {
    half_extents: Vec3,
    margin: Real,
}

impl Cuboid {
    /// A box; every half extent must be finite and > 0. The margin defaults to
    /// `min(DEFAULT_MARGIN, 0.2 · smallest half extent)`.
    pub fn new(half_extents: Vec3) -> Result<Self> {
        let he = check_positive_vec("half_extents", half_extents)?;
        Ok(Cuboid {
            half_extents: he,
            margin: DEFAULT_MARGIN.min(MAX_MARGIN_FRACTION * he.min_element()),
        })
    }

    /// The same box with another margin, in `[0, smallest half extent)`.
    pub fn with_margin(mut self, margin: Real) -> Result<Self> {
        check_non_negative("margin", margin)?;
        if margin >= self.half_extents.min_element() {
            return Err(CaromError::invalid(
                "margin",
                margin,
                format!(
                    "must be smaller than the smallest half extent {}",
                    self.half_extents.min_element()
                ),
            ));
        }
        self.margin = margin;
        Ok(self)
    }

    /// Half extents.
    pub fn half_extents(&self) -> Vec3 {
        self.half_extents
    }

    /// Local bounding box.
    pub fn local_aabb(&self) -> Aabb {
        Aabb::from_center_half_extents(Vec3::ZERO, self.half_extents)
    }

    /// Volume `8 hx hy hz`.
    pub fn volume(&self) -> Real {
        8.0 * self.half_extents.x * self.half_extents.y * self.half_extents.z
    }

    /// Solid box: `Ixx = m (hy² + hz²) / 3`.
    pub fn mass_properties(&self, density: Real) -> MassProperties {
        let m = density * self.volume();
        let h2 = self.half_extents * self.half_extents;
        MassProperties::new(
            m,
            Vec3::ZERO,
            Vec3::new(h2.y + h2.z, h2.x + h2.z, h2.x + h2.y) * (m / 3.0),
        )
    }

    /// The 8 corners; corner `i` has `+x` when bit 0 is set, `+y` bit 1, `+z` bit 2.
    pub fn vertices(&self) -> [Vec3; 8] {
        let h = self.half_extents;
        std::array::from_fn(|i| {
            Vec3::new(
                if i & 1 != 0 { h.x } else { -h.x },
                if i & 2 != 0 { h.y } else { -h.y },
                if i & 4 != 0 { h.z } else { -h.z },
            )
        })
    }
}

impl SupportMap for Cuboid {
    #[inline]
    fn support(&self, dir: Vec3) -> Vec3 {
        Vec3::new(
            sign_nonzero(dir.x),
            sign_nonzero(dir.y),
            sign_nonzero(dir.z),
        ) * self.half_extents
    }
    #[inline]
    fn support_core(&self, dir: Vec3) -> Vec3 {
        Vec3::new(
            sign_nonzero(dir.x),
            sign_nonzero(dir.y),
            sign_nonzero(dir.z),
        ) * (self.half_extents - Vec3::splat(self.margin))
    }
    #[inline]
    fn margin(&self) -> Real {
        self.margin
    }
}
