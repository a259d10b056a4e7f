//! Time of impact with rotation: conservative advancement (Mirtich, "Impulse-based Dynamic
//! Simulation of Rigid Body Systems", PhD thesis 1996; Coumans' CA in Bullet's
//! `btContinuousConvexCollision.cpp`, the talk's "Bullet uses Conservative Advancement for
//! CCD").
//!
//! At the current time `t`, the distance `d` and the normal `n` are computed; no point of A
//! can approach B along `n` faster than `(v_a - v_b)·n + |ω_a| R_a + |ω_b| R_b`, with `R` the
//! radius of each shape around its origin, so advancing by `(d - tolerance / 2) / bound`
//! never passes the first contact. The loop stops when `d <= tolerance`.
//!
//! The bound holds for convex shapes only: the normal of a compound's or a mesh's closest
//! piece says nothing about how fast another piece approaches (a sphere sliding along a
//! floor towards a wall would see the floor's normal and step through the wall). So
//! compounds, meshes and heightfields are split into convex pieces (children, and the
//! triangles that B can reach during the motion), each pair of pieces is advanced on its
//! own, with `R` measured from the body's origin, and the earliest time wins.

use super::composite::{cull_slack, triangle_shape};
use super::contact::contact_local;
use super::result::ShapeCastHit;
use crate::error::{CaromError, Result};
use crate::math::{check_finite_vec, Aabb, Isometry, Quat, Real, Vec3};
use crate::midphase::TriangleSource;
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
/// Planes are supported as static shapes (zero velocities). Compounds, meshes and
/// heightfields are advanced piece by piece (see the module docs).
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
    for (shape, motion, name) in [
        (a, &motion_a, "motion_a.angvel"),
        (b, &motion_b, "motion_b.angvel"),
    ] {
        if matches!(shape, Shape::Plane(_)) && motion.angvel != Vec3::ZERO {
            return Err(CaromError::invalid(
                name,
                format!("{:?}", motion.angvel.to_array()),
                "a plane may translate but not rotate in time_of_impact",
            ));
        }
    }
    let best = toi_pieces(
        &Piece::whole(a),
        &Piece::whole(b),
        &motion_a,
        &motion_b,
        t_max,
        tolerance,
    )?;
    Ok(best)
}

/// A piece of a body: a shape placed at `offset` in the body's frame.
#[derive(Clone, Copy)]
struct Piece<'a> {
    shape: &'a Shape,
    offset: Isometry,
}

impl<'a> Piece<'a> {
    fn whole(shape: &'a Shape) -> Self {
        Piece {
            shape,
            offset: Isometry::IDENTITY,
        }
    }

    fn is_composite(&self) -> bool {
        matches!(
            self.shape,
            Shape::Compound(_) | Shape::TriMesh(_) | Shape::HeightField(_)
        )
    }

    /// The reach that counts for the spin: a sphere turning about its own centre sweeps
    /// nothing new, so only its centre's distance from the body's origin counts.
    fn spin_reach(&self) -> Real {
        match self.shape {
            Shape::Sphere(_) => self.offset.translation.length(),
            _ => self.reach(),
        }
    }

    /// Largest distance from the body's origin to a point of the piece (0 for a plane,
    /// which is supported as a static shape only).
    fn reach(&self) -> Real {
        if matches!(self.shape, Shape::Plane(_)) {
            0.0
        } else {
            self.offset.translation.length() + bounding_radius(self.shape)
        }
    }
}

/// The earlier of two hits (the first one on ties).
fn earlier(best: Option<ShapeCastHit>, h: Option<ShapeCastHit>) -> Option<ShapeCastHit> {
    match (best, h) {
        (Some(b), Some(h)) if h.toi < b.toi => Some(h),
        (None, h) => h,
        (b, _) => b,
    }
}

/// The hit of the swapped pair seen from the original order.
fn swap_hit(h: ShapeCastHit) -> ShapeCastHit {
    ShapeCastHit {
        point_a: h.point_b,
        point_b: h.point_a,
        normal: -h.normal,
        ..h
    }
}

/// The earliest impact of piece `a` of body A and piece `b` of body B within `[0, t_max]`.
fn toi_pieces(
    a: &Piece<'_>,
    b: &Piece<'_>,
    motion_a: &Motion,
    motion_b: &Motion,
    t_max: Real,
    tolerance: Real,
) -> Result<Option<ShapeCastHit>> {
    if !a.is_composite() && b.is_composite() {
        let h = toi_pieces(b, a, motion_b, motion_a, t_max, tolerance)?;
        return Ok(h.map(swap_hit));
    }
    let mut best: Option<ShapeCastHit> = None;
    let each = |piece: Piece<'_>, best: &mut Option<ShapeCastHit>| -> Result<()> {
        let limit = best.map_or(t_max, |h| h.toi);
        let h = toi_pieces(&piece, b, motion_a, motion_b, limit, tolerance)?;
        *best = earlier(*best, h);
        Ok(())
    };
    match a.shape {
        Shape::Compound(c) => {
            for (child_pose, child) in c.children() {
                let offset = a.offset.mul(child_pose);
                each(
                    Piece {
                        shape: child,
                        offset,
                    },
                    &mut best,
                )?;
            }
            Ok(best)
        }
        Shape::TriMesh(_) | Shape::HeightField(_) => {
            let src = TriangleSource::of(a.shape).expect("a mesh or heightfield");
            let region = reachable_region(a, b, motion_a, motion_b, t_max);
            let mut ids = Vec::new();
            src.for_each_triangle_in_aabb(&region, |i| {
                ids.push(i);
                true
            });
            ids.sort_unstable();
            for i in ids {
                let tri = triangle_shape(&src, i);
                each(
                    Piece {
                        shape: &tri,
                        offset: a.offset,
                    },
                    &mut best,
                )?;
            }
            Ok(best)
        }
        _ => conservative_advancement(a, b, motion_a, motion_b, t_max, tolerance),
    }
}

/// A box, in the frame of piece `a` (a mesh or heightfield), holding every point of piece
/// `b` during `[0, t_max]`. Without rotation both bodies translate, and the box is B's box
/// swept by the relative motion; otherwise it is the ball about `a`'s frame origin that the
/// distance between the bodies' origins, plus the pieces' reaches, bounds.
fn reachable_region(
    a: &Piece<'_>,
    b: &Piece<'_>,
    motion_a: &Motion,
    motion_b: &Motion,
    t_max: Real,
) -> Aabb {
    let frame_a = motion_a.pose.mul(&a.offset);
    let region = if motion_a.angvel == Vec3::ZERO && motion_b.angvel == Vec3::ZERO {
        let pose_b = frame_a.inv_mul(&motion_b.pose.mul(&b.offset));
        let rel = frame_a.inverse_transform_vector(motion_b.linvel - motion_a.linvel);
        b.shape.aabb(&pose_b).swept(rel * t_max)
    } else {
        let d0 = motion_b.pose.translation - motion_a.pose.translation;
        let d1 = d0 + (motion_b.linvel - motion_a.linvel) * t_max;
        let r = d0.length().max(d1.length()) + a.offset.translation.length() + b.reach();
        Aabb::new(Vec3::splat(-r), Vec3::splat(r))
    };
    if !(region.min.is_finite() && region.max.is_finite()) {
        // A plane's box: every triangle.
        return Aabb::new(Vec3::splat(-Real::MAX), Vec3::splat(Real::MAX));
    }
    region.expanded(cull_slack(&region))
}

/// Conservative advancement of two convex pieces (or a plane and a convex piece).
fn conservative_advancement(
    a: &Piece<'_>,
    b: &Piece<'_>,
    motion_a: &Motion,
    motion_b: &Motion,
    t_max: Real,
    tolerance: Real,
) -> Result<Option<ShapeCastHit>> {
    let spin =
        motion_a.angvel.length() * a.spin_reach() + motion_b.angvel.length() * b.spin_reach();
    let pose_at = |t: Real| {
        let pa = motion_a.pose_at(t).mul(&a.offset);
        let pb = motion_b.pose_at(t).mul(&b.offset);
        (pa, pb)
    };
    // Bounding balls about the bodies' origins (not for planes, which are unbounded): once
    // they cannot meet during the rest of the motion, neither can the pieces. This ends the
    // advancement of pieces that have passed each other while spinning, whose steps the
    // spin keeps short.
    let balls = !matches!(a.shape, Shape::Plane(_)) && !matches!(b.shape, Shape::Plane(_));
    let reach = a.reach() + b.reach() + tolerance;
    let (d0, dv) = (
        motion_b.pose.translation - motion_a.pose.translation,
        motion_b.linvel - motion_a.linvel,
    );
    let balls_apart_after = |t: Real| {
        let dv2 = dv.length_squared();
        let s = if dv2 > 0.0 {
            (-d0.dot(dv) / dv2).clamp(t, t_max)
        } else {
            t
        };
        (d0 + dv * s).length() > reach
    };
    let mut t: Real = 0.0;
    for _ in 0..CA_MAX_ITERATIONS {
        if balls && balls_apart_after(t) {
            return Ok(None);
        }
        let (pa, pb) = pose_at(t);
        let pose_ab = pa.inv_mul(&pb);
        let Some(c) = contact_local(a.shape, b.shape, &pose_ab, Real::INFINITY)? else {
            return Ok(None);
        };
        let c = c.transformed(&pa);
        if c.distance <= tolerance {
            let overlapping = t == 0.0 && c.distance < 0.0;
            return Ok(Some(ShapeCastHit::at_contact(t, &c, overlapping)));
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
    let (pa, pb) = pose_at(t);
    let pose_ab = pa.inv_mul(&pb);
    Ok(contact_local(a.shape, b.shape, &pose_ab, Real::INFINITY)?
        .map(|c| ShapeCastHit::at_contact(t, &c.transformed(&pa), false)))
}
