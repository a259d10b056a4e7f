//! Non-uniform scaling of a convex shape.

use super::support::SupportMap;
use super::{MassProperties, Shape};
use crate::error::{CaromError, Result};
use crate::math::{check_finite_vec, Aabb, Real, Vec3};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// A convex shape scaled by a diagonal matrix `diag(scale)` in its local frame. Negative
/// factors mirror; zero factors are rejected. The support map is exact:
/// `s_{SK}(d) = S · s_K(S d)` for the diagonal `S`.
///
/// The margin is zero (a scaled sphere is an ellipsoid, not a point plus a radius).
///
/// Deserialising rebuilds it through [`Scaled::new`] and checks the result equals the stored
/// data, so inconsistent bytes give a [`CaromError`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "ScaledData")]
pub struct Scaled {
    inner: Arc<Shape>,
    scale: Vec3,
    local_aabb: Aabb,
}

/// The serialised form of a [`Scaled`], checked on load by `TryFrom`.
#[derive(Deserialize)]
pub struct ScaledData {
    inner: Arc<Shape>,
    scale: Vec3,
    local_aabb: Aabb,
}

impl TryFrom<ScaledData> for Scaled {
    type Error = CaromError;
    fn try_from(d: ScaledData) -> Result<Self> {
        super::serde_check::record((|| {
            let s = Scaled::new(d.inner.clone(), d.scale)?;
            if s.inner != d.inner || s.scale != d.scale || s.local_aabb != d.local_aabb {
                return Err(CaromError::invalid(
                    "scaled shape",
                    d.scale,
                    "inconsistent stored data (nested scaling or bounds)",
                ));
            }
            Ok(s)
        })())
    }
}

impl Scaled {
    /// Scales a convex shape; `scale` components must be finite and non-zero. Scaling a
    /// scaled shape multiplies the factors.
    pub fn new(inner: Arc<Shape>, scale: Vec3) -> Result<Self> {
        let scale = check_finite_vec("scale", scale)?;
        if scale.cmpeq(Vec3::ZERO).any() {
            return Err(CaromError::invalid(
                "scale",
                scale,
                "factors must be non-zero",
            ));
        }
        if let Shape::Scaled(s) = &*inner {
            return Scaled::new(s.inner.clone(), s.scale * scale);
        }
        if inner.as_convex().is_none() {
            return Err(CaromError::Unsupported(format!(
                "only convex shapes can be scaled, not a {}",
                inner.kind_name()
            )));
        }
        let mut s = Scaled {
            inner,
            scale,
            local_aabb: Aabb::EMPTY,
        };
        let mut aabb = Aabb::EMPTY;
        for axis in [Vec3::X, Vec3::Y, Vec3::Z] {
            aabb = aabb
                .include_point(s.support(axis))
                .include_point(s.support(-axis));
        }
        s.local_aabb = aabb;
        Ok(s)
    }

    /// The shape being scaled.
    pub fn inner(&self) -> &Arc<Shape> {
        &self.inner
    }

    /// The scale factors.
    pub fn scale(&self) -> Vec3 {
        self.scale
    }

    /// Local bounding box (exact).
    pub fn local_aabb(&self) -> Aabb {
        self.local_aabb
    }

    /// Volume `|sx sy sz| · V`.
    pub fn volume(&self) -> Real {
        self.inner.volume() * (self.scale.x * self.scale.y * self.scale.z).abs()
    }

    /// Exact mass properties of the scaled solid.
    pub fn mass_properties(&self, density: Real) -> MassProperties {
        self.inner.mass_properties(density).scaled(self.scale)
    }
}

impl SupportMap for Scaled {
    #[inline]
    fn support(&self, dir: Vec3) -> Vec3 {
        let inner = self
            .inner
            .as_convex()
            .expect("validated convex at construction");
        inner.support(dir * self.scale) * self.scale
    }
    #[inline]
    fn support_core(&self, dir: Vec3) -> Vec3 {
        self.support(dir)
    }
    #[inline]
    fn margin(&self) -> Real {
        0.0
    }
}
