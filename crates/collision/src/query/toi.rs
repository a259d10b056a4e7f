//! Time of impact with rotation: conservative advancement (Mirtich, "Impulse-based Dynamic
//! Simulation of Rigid Body Systems", PhD thesis 1996; Coumans' CA in Bullet's
//! `btContinuousConvexCollision.cpp`, the talk's "Bullet uses Conservative Advancement for
//! CCD").
//!
//! At the current time `t`, the distance `d` and the normal `n` are computed; no point of A
//! can approach B along `n` faster than `(v_a - v_b)·n + |ω_a| R_a + |ω_b| R_b`, with `R` the
//! radius of each shape around its origin, so advancing by `(d - tolerance / 2) / bound`
//! never passes the first contact. The loop stops when `d <= tolerance`.

use super::contact::contact_local;
use super::result::ShapeCastHit;
use crate::error::{CaromError, Result};
use crate::math::{check_finite_vec, Isometry, Quat, Real, Vec3};
use crate::shape::Shape;

/// Iteration cap of conservative advancement.
pub const CA_MAX_ITERATIONS: usize = 256;

/// A rigid motion over a step: the pose at time 0 and constant linear and angular
/// velocities (world frame; the angular velocity turns the shape about its own origin).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Motion {
    /// Pose at time 0.
    pub pose: Isometry,
    /// Linear velocity of the shape's origin.
    pub linvel: Vec3,
    /// Angular velocity (axis times radians per unit time).
    pub angvel: Vec3,
}

impl Motion {
    /// A motion; the pose is checked and velocities must be finite.
    pub fn new(pose: Isometry, linvel: Vec3, angvel: Vec3) -> Result<Motion> {
        Ok(Motion {
            pose: crate::query::check_pose("pose", &pose)?,
            linvel: check_finite_vec("linvel", linvel)?,
            angvel: check_finite_vec("angvel", angvel)?,
        })
    }

    /// The pose at time `t` (exact integration of constant velocities).
    pub fn pose_at(&self, t: Real) -> Isometry {
        Isometry::new(
            self.pose.translation + self.linvel * t,
            (Quat::from_scaled_axis(self.angvel * t) * self.pose.rotation).normalize(),
        )
    }
}

/// Largest distance from a shape's origin to a point of the shape.
fn bounding_radius(shape: &Shape) -> Real {
    let aabb = shape.local_aabb();
    aabb.min.abs().max(aabb.max.abs()).length()
}

/// First time in `[0, t_max]` at which `a` and `b`, moving by `motion_a` and `motion_b`,
/// come within `tolerance` (> 0) of each other. Returns the time, the witness points and the
/// normal at that time (world space), or `None` when they stay apart. If the iteration cap
/// is reached first, the last time proven safe is returned (never later than the impact).
/// Planes are supported as static shapes (zero velocities).
pub fn time_of_impact(
    a: &Shape,
    motion_a: &Motion,
    b: &Shape,
    motion_b: &Motion,
    t_max: Real,
    tolerance: Real,
) -> Result<Option<ShapeCastHit>> {
    let motion_a = Motion::new(motion_a.pose, motion_a.linvel, motion_a.angvel)?;
    let motion_b = Motion::new(motion_b.pose, motion_b.linvel, motion_b.angvel)?;
    if t_max.is_nan() || t_max < 0.0 || !t_max.is_finite() {
        return Err(CaromError::invalid(
            "t_max",
            t_max,
            "must be finite and >= 0",
        ));
    }
    if !(tolerance > 0.0 && tolerance.is_finite()) {
        return Err(CaromError::invalid(
            "tolerance",
            tolerance,
            "must be finite and > 0",
        ));
    }
    let ra = if matches!(a, Shape::Plane(_)) {
        0.0
    } else {
        bounding_radius(a)
    };
    let rb = if matches!(b, Shape::Plane(_)) {
        0.0
    } else {
        bounding_radius(b)
    };
    let spin = motion_a.angvel.length() * ra + motion_b.angvel.length() * rb;
    let mut t: Real = 0.0;
    for _ in 0..CA_MAX_ITERATIONS {
        let pa = motion_a.pose_at(t);
        let pb = motion_b.pose_at(t);
        let pose_ab = pa.inv_mul(&pb);
        let Some(c) = contact_local(a, b, &pose_ab, Real::INFINITY)? else {
            return Ok(None);
        };
        let c = c.transformed(&pa);
        if c.distance <= tolerance {
            return Ok(Some(ShapeCastHit {
                toi: t,
                point_a: c.point_a,
                point_b: c.point_b,
                normal: c.normal,
                initially_overlapping: t == 0.0 && c.distance < 0.0,
            }));
        }
        let bound = (motion_a.linvel - motion_b.linvel).dot(c.normal) + spin;
        if bound <= 0.0 {
            return Ok(None);
        }
        t += (c.distance - 0.5 * tolerance) / bound;
        if t > t_max {
            return Ok(None);
        }
    }
    // Cap reached: report the last safe time.
    let pa = motion_a.pose_at(t);
    let pose_ab = pa.inv_mul(&motion_b.pose_at(t));
    Ok(contact_local(a, b, &pose_ab, Real::INFINITY)?.map(|c| {
        let c = c.transformed(&pa);
        ShapeCastHit {
            toi: t,
            point_a: c.point_a,
            point_b: c.point_b,
            normal: c.normal,
            initially_overlapping: false,
        }
    }))
}
