//! Infinite plane (half-space), for static bodies only.

use crate::error::{CaromError, Result};
use crate::math::{check_finite, check_finite_vec, Aabb, Real, Vec3, UNBOUNDED};
use serde::{Deserialize, Serialize};

/// The half-space `n · x <= offset` with unit normal `n` pointing out of the solid. Bodies
/// with a plane shape must be static; it has no mass and no support map.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Plane {
    normal: Vec3,
    offset: Real,
}

impl Plane {
    /// A plane from a (not necessarily unit) non-zero finite normal and an offset along the
    /// unit normal. The normal is normalised; the offset is taken along the normalised normal.
    pub fn new(normal: Vec3, offset: Real) -> Result<Self> {
        let normal = check_finite_vec("normal", normal)?;
        let offset = check_finite("offset", offset)?;
        let n = normal
            .try_normalize()
            .ok_or_else(|| CaromError::invalid("normal", normal, "must be non-zero"))?;
        Ok(Plane { normal: n, offset })
    }

    /// Unit outward normal.
    pub fn normal(&self) -> Vec3 {
        self.normal
    }

    /// Offset: the plane is `normal · x = offset`.
    pub fn offset(&self) -> Real {
        self.offset
    }

    /// Signed distance of `p` from the plane (negative inside the solid).
    pub fn signed_distance(&self, p: Vec3) -> Real {
        self.normal.dot(p) - self.offset
    }

    /// Bounds of the half-space, clamped to [`UNBOUNDED`]. When the normal is a coordinate
    /// axis the box is tight on that side.
    pub fn local_aabb(&self) -> Aabb {
        let mut min = Vec3::splat(-UNBOUNDED);
        let mut max = Vec3::splat(UNBOUNDED);
        for i in 0..3 {
            let n = self.normal[i];
            let others = (0..3).filter(|&j| j != i).all(|j| self.normal[j] == 0.0);
            if others && n == 1.0 {
                max[i] = self.offset;
            } else if others && n == -1.0 {
                min[i] = -self.offset;
            }
        }
        Aabb::new(min, max)
    }
}
