//! A single triangle (a flat convex shape).

use super::support::SupportMap;
use crate::error::Result;
use crate::math::{check_finite_vec, Aabb, Real, Vec3};
use serde::{Deserialize, Serialize};

/// A triangle with vertices `a, b, c`; its front face is counter-clockwise
/// (normal `(b - a) × (c - a)`). Zero-area triangles are allowed (queries never produce NaN
/// on them); they have no normal.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Triangle {
    /// First vertex.
    pub a: Vec3,
    /// Second vertex.
    pub b: Vec3,
    /// Third vertex.
    pub c: Vec3,
}

impl Triangle {
    /// A triangle; every coordinate must be finite.
    pub fn new(a: Vec3, b: Vec3, c: Vec3) -> Result<Self> {
        Ok(Triangle {
            a: check_finite_vec("a", a)?,
            b: check_finite_vec("b", b)?,
            c: check_finite_vec("c", c)?,
        })
    }

    /// The three vertices.
    pub fn vertices(&self) -> [Vec3; 3] {
        [self.a, self.b, self.c]
    }

    /// Unnormalised normal `(b - a) × (c - a)` (twice the area in length).
    pub fn scaled_normal(&self) -> Vec3 {
        (self.b - self.a).cross(self.c - self.a)
    }

    /// Unit normal, or `None` for a degenerate triangle.
    pub fn normal(&self) -> Option<Vec3> {
        self.scaled_normal().try_normalize()
    }

    /// Area.
    pub fn area(&self) -> Real {
        0.5 * self.scaled_normal().length()
    }

    /// Local bounding box.
    pub fn local_aabb(&self) -> Aabb {
        Aabb::from_points([self.a, self.b, self.c])
    }
}

impl SupportMap for Triangle {
    #[inline]
    fn support(&self, dir: Vec3) -> Vec3 {
        let (da, db, dc) = (self.a.dot(dir), self.b.dot(dir), self.c.dot(dir));
        if da >= db && da >= dc {
            self.a
        } else if db >= dc {
            self.b
        } else {
            self.c
        }
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
