//! Axis-aligned bounding boxes.

use super::{Isometry, Mat3, Real, Vec3};
use serde::{Deserialize, Serialize};

/// An axis-aligned box `[min, max]`. Valid boxes have `min <= max` componentwise; a box with
/// zero extent on some axis (a point, a flat box) is valid. [`Aabb::EMPTY`] is the identity of
/// [`Aabb::merge`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Aabb {
    /// Lower corner.
    pub min: Vec3,
    /// Upper corner.
    pub max: Vec3,
}

impl Aabb {
    /// The empty box (inverted infinite bounds): merging anything into it gives that thing.
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::splat(Real::INFINITY),
        max: Vec3::splat(Real::NEG_INFINITY),
    };

    /// A box from its corners. No check; see [`Aabb::is_valid`].
    #[inline]
    pub const fn new(min: Vec3, max: Vec3) -> Self {
        Aabb { min, max }
    }

    /// The box centred at `center` with half extents `half_extents`.
    #[inline]
    pub fn from_center_half_extents(center: Vec3, half_extents: Vec3) -> Self {
        Aabb {
            min: center - half_extents,
            max: center + half_extents,
        }
    }

    /// The smallest box containing all `points` ([`Aabb::EMPTY`] for none).
    pub fn from_points<I: IntoIterator<Item = Vec3>>(points: I) -> Self {
        points
            .into_iter()
            .fold(Aabb::EMPTY, |b, p| b.include_point(p))
    }

    /// True when the bounds are finite and `min <= max` on every axis.
    #[inline]
    pub fn is_valid(&self) -> bool {
        // Masks combined without short circuits: no branch per component.
        (self.min.is_finite_mask() & self.max.is_finite_mask() & self.min.cmple(self.max)).all()
    }

    /// True for [`Aabb::EMPTY`]-like boxes (some `min > max`).
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.min.cmpgt(self.max).any()
    }

    /// Centre point.
    #[inline]
    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    /// Half extents.
    #[inline]
    pub fn half_extents(&self) -> Vec3 {
        (self.max - self.min) * 0.5
    }

    /// Full extents (`max - min`).
    #[inline]
    pub fn extents(&self) -> Vec3 {
        self.max - self.min
    }

    /// The smallest box containing both.
    #[inline]
    pub fn merge(&self, other: &Aabb) -> Aabb {
        Aabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// The smallest box containing `self` and `p`.
    #[inline]
    pub fn include_point(&self, p: Vec3) -> Aabb {
        Aabb {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    /// True when `other` lies inside `self` (boundaries included).
    #[inline]
    pub fn contains(&self, other: &Aabb) -> bool {
        self.min.cmple(other.min).all() && self.max.cmpge(other.max).all()
    }

    /// True when `p` lies inside or on the boundary.
    #[inline]
    pub fn contains_point(&self, p: Vec3) -> bool {
        self.min.cmple(p).all() && self.max.cmpge(p).all()
    }

    /// True when the boxes overlap; touching boxes (shared face, edge or corner) intersect.
    #[inline]
    pub fn intersects(&self, other: &Aabb) -> bool {
        self.min.cmple(other.max).all() && other.min.cmple(self.max).all()
    }

    /// The overlap of two boxes, or `None` when they do not intersect.
    #[inline]
    pub fn intersection(&self, other: &Aabb) -> Option<Aabb> {
        self.intersects(other).then(|| Aabb {
            min: self.min.max(other.min),
            max: self.max.min(other.max),
        })
    }

    /// The box grown by `margin` on every side (`margin` may be negative; the result is then
    /// clamped so it never inverts).
    #[inline]
    pub fn expanded(&self, margin: Real) -> Aabb {
        let min = self.min - Vec3::splat(margin);
        let max = self.max + Vec3::splat(margin);
        let c = self.center();
        Aabb {
            min: min.min(c),
            max: max.max(c),
        }
    }

    /// The box swept by a translation `motion`: contains the box at the start and at the end.
    #[inline]
    pub fn swept(&self, motion: Vec3) -> Aabb {
        Aabb {
            min: self.min + motion.min(Vec3::ZERO),
            max: self.max + motion.max(Vec3::ZERO),
        }
    }

    /// Surface area (`2(xy + yz + zx)`), the cost metric of the surface-area heuristic.
    #[inline]
    pub fn surface_area(&self) -> Real {
        let e = self.extents().max(Vec3::ZERO);
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }

    /// Volume.
    #[inline]
    pub fn volume(&self) -> Real {
        let e = self.extents().max(Vec3::ZERO);
        e.x * e.y * e.z
    }

    /// Sum of the extents (the "Manhattan" size Bullet's dynamic tree uses).
    #[inline]
    pub fn perimeter(&self) -> Real {
        let e = self.extents();
        e.x + e.y + e.z
    }

    /// The box containing this box after the rigid transform `pose`.
    /// Arvo's method: the half extents map through `|R|`.
    #[inline]
    pub fn transformed(&self, pose: &Isometry) -> Aabb {
        let r = Mat3::from_quat(pose.rotation);
        let abs_r = Mat3::from_cols(r.x_axis.abs(), r.y_axis.abs(), r.z_axis.abs());
        let c = pose.transform_point(self.center());
        let h = abs_r * self.half_extents();
        Aabb::from_center_half_extents(c, h)
    }

    /// Slab test of the ray `origin + t * dir` for `t` in `[0, max_t]`: the entry parameter
    /// `t` (0 if the origin is inside), or `None` when the ray misses. `dir` need not be unit;
    /// zero components are handled (a ray parallel to a slab misses unless it lies within it).
    #[inline]
    pub fn ray_intersection(&self, origin: Vec3, dir: Vec3, max_t: Real) -> Option<Real> {
        let inv = dir.recip();
        let t1 = (self.min - origin) * inv;
        let t2 = (self.max - origin) * inv;
        // With dir = 0 on an axis, t1/t2 are ±inf (or NaN when origin lies on the slab plane);
        // min/max below ignore NaN, which treats "on the plane" as inside the slab.
        let tmin = t1.min(t2);
        let tmax = t1.max(t2);
        let mut enter: Real = 0.0;
        let mut exit = max_t;
        for i in 0..3 {
            let (lo, hi) = (tmin[i], tmax[i]);
            if dir[i] == 0.0 {
                if origin[i] < self.min[i] || origin[i] > self.max[i] {
                    return None;
                }
                continue;
            }
            enter = enter.max(lo);
            exit = exit.min(hi);
        }
        (enter <= exit).then_some(enter)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Quat;

    fn unit() -> Aabb {
        Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0))
    }

    #[test]
    fn merge_contains_intersects() {
        let a = unit();
        let b = Aabb::new(Vec3::new(1.0, -1.0, -1.0), Vec3::new(3.0, 1.0, 1.0));
        assert!(a.intersects(&b), "touching boxes intersect");
        let m = a.merge(&b);
        assert!(m.contains(&a) && m.contains(&b));
        assert_eq!(Aabb::EMPTY.merge(&a), a);
        let c = Aabb::new(Vec3::new(1.01, 0.0, 0.0), Vec3::new(2.0, 0.5, 0.5));
        assert!(!a.intersects(&c));
        assert!(a.intersection(&c).is_none());
        assert!(Aabb::EMPTY.is_empty() && !a.is_empty());
        assert!(!Aabb::new(Vec3::ONE, Vec3::ZERO).is_valid());
        let p = Aabb::new(Vec3::ONE, Vec3::ONE);
        assert!(p.is_valid() && a.intersects(&p));
    }

    #[test]
    fn expand_sweep_area() {
        let a = unit();
        assert_eq!(
            a.expanded(0.5),
            Aabb::new(Vec3::splat(-1.5), Vec3::splat(1.5))
        );
        assert_eq!(a.expanded(-5.0).extents(), Vec3::ZERO);
        let s = a.swept(Vec3::new(2.0, -3.0, 0.0));
        assert_eq!(
            s,
            Aabb::new(Vec3::new(-1.0, -4.0, -1.0), Vec3::new(3.0, 1.0, 1.0))
        );
        assert_eq!(a.surface_area(), 24.0);
        assert_eq!(a.volume(), 8.0);
    }

    #[test]
    fn transformed_contains_corners() {
        let a = Aabb::new(Vec3::new(-1.0, 0.0, 2.0), Vec3::new(3.0, 0.5, 2.5));
        let pose = Isometry::new(
            Vec3::new(1.0, 2.0, -3.0),
            Quat::from_euler(glam::EulerRot::XYZ, 0.3, 1.1, -0.7),
        );
        let t = a.transformed(&pose);
        for i in 0..8 {
            let c = Vec3::new(
                if i & 1 == 0 { a.min.x } else { a.max.x },
                if i & 2 == 0 { a.min.y } else { a.max.y },
                if i & 4 == 0 { a.min.z } else { a.max.z },
            );
            assert!(t.expanded(1e-5).contains_point(pose.transform_point(c)));
        }
    }

    #[test]
    fn ray_slab() {
        let a = unit();
        let t = a
            .ray_intersection(Vec3::new(-3.0, 0.0, 0.0), Vec3::X, 10.0)
            .unwrap();
        assert!((t - 2.0).abs() < 1e-6);
        assert_eq!(a.ray_intersection(Vec3::ZERO, Vec3::X, 10.0), Some(0.0));
        assert!(a
            .ray_intersection(Vec3::new(-3.0, 0.0, 0.0), Vec3::X, 1.0)
            .is_none());
        assert!(a
            .ray_intersection(Vec3::new(-3.0, 2.0, 0.0), Vec3::X, 10.0)
            .is_none());
        // Grazing along a face: a ray in the plane x = 1 travelling along y hits.
        assert!(a
            .ray_intersection(Vec3::new(1.0, -3.0, 0.0), Vec3::Y, 10.0)
            .is_some());
        assert!(a
            .ray_intersection(Vec3::new(-3.0, 0.0, 0.0), -Vec3::X, 10.0)
            .is_none());
    }
}
