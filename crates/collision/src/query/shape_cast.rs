//! Linear shape cast (convex sweep): van den Bergen's GJK ray cast (JGT 2004) on the
//! Minkowski difference of the two cores, with the radii of round shapes as the margin, so
//! spheres and capsules are swept exactly. B moves relative to A by `v_b - v_a`; the cast
//! finds the first time the shapes touch.

use super::composite::shape_cast_triangles;
use super::contact_convex::contact_convex;
use super::ray::gjk_ray::gjk_raycast;
use super::result::{Contact, ShapeCastHit};
use super::support_adapters::{core_radius, Core, MinkowskiDiff, Transformed};
use crate::error::{CaromError, Result};
use crate::math::{check_finite_vec, Isometry, Real, Vec3, EPSILON};
use crate::midphase::TriangleSource;
use crate::shape::{ConvexRef, Plane, Shape, SupportMap};

/// Casts `a` (at `pose_a`, moving by `vel_a` per unit time) and `b` (at `pose_b`, moving by
/// `vel_b`) until they touch, for times in `[0, max_toi]`. Returns the first time of contact
/// with the witness points and normal at that time (world space), or `None`. Convex shapes,
/// compounds (by recursion), meshes and heightfields (over the triangles B's swept box meets)
/// are supported, and planes against convex shapes and compounds of them (not against
/// meshes, heightfields or planes).
pub fn shape_cast(
    a: &Shape,
    pose_a: &Isometry,
    vel_a: Vec3,
    b: &Shape,
    pose_b: &Isometry,
    vel_b: Vec3,
    max_toi: Real,
) -> Result<Option<ShapeCastHit>> {
    let pose_a = crate::query::check_pose("pose_a", pose_a)?;
    let pose_b = crate::query::check_pose("pose_b", pose_b)?;
    let vel_a = check_finite_vec("vel_a", vel_a)?;
    let vel_b = check_finite_vec("vel_b", vel_b)?;
    if max_toi.is_nan() || max_toi < 0.0 {
        return Err(CaromError::invalid("max_toi", max_toi, "must be >= 0"));
    }
    let pose_ab = pose_a.inv_mul(&pose_b);
    let rel = pose_a.inverse_transform_vector(vel_b - vel_a);
    let hit = shape_cast_local(a, b, &pose_ab, rel, max_toi)?;
    Ok(hit.map(|h| {
        let shift = vel_a * h.toi;
        ShapeCastHit {
            point_a: pose_a.transform_point(h.point_a) + shift,
            point_b: pose_a.transform_point(h.point_b) + shift,
            normal: pose_a.transform_vector(h.normal),
            ..h
        }
    }))
}

/// [`shape_cast`] in A's frame: B at `pose_ab` moves by `rel_vel` (A's frame) per unit time.
/// Witness points are in A's frame at the time of impact (B already moved).
pub fn shape_cast_local(
    a: &Shape,
    b: &Shape,
    pose_ab: &Isometry,
    rel_vel: Vec3,
    max_toi: Real,
) -> Result<Option<ShapeCastHit>> {
    if let (Some(ca), Some(cb)) = (a.as_convex(), b.as_convex()) {
        return Ok(shape_cast_convex(ca, cb, pose_ab, rel_vel, max_toi));
    }
    let mut best: Option<ShapeCastHit> = None;
    let mut keep = |h: Option<ShapeCastHit>| {
        if let Some(h) = h {
            if best.is_none_or(|b| h.toi < b.toi) {
                best = Some(h);
            }
        }
    };
    match (a, b) {
        (Shape::Plane(p), _) if b.is_convex() => {
            return Ok(shape_cast_plane_convex(
                p,
                b.as_convex().expect("checked"),
                pose_ab,
                rel_vel,
                max_toi,
            ));
        }
        (Shape::Plane(_), Shape::Plane(_))
        | (Shape::Plane(_), Shape::TriMesh(_) | Shape::HeightField(_))
        | (Shape::TriMesh(_) | Shape::HeightField(_), Shape::Plane(_)) => {
            return Err(CaromError::Unsupported(format!(
                "shape cast between a {} and a {}",
                a.kind_name(),
                b.kind_name()
            )))
        }
        (Shape::Compound(c), _) => {
            for (child_pose, child) in c.children() {
                let pose_cb = child_pose.inv_mul(pose_ab);
                let rel = child_pose.inverse_transform_vector(rel_vel);
                keep(
                    shape_cast_local(child, b, &pose_cb, rel, max_toi)?.map(|h| ShapeCastHit {
                        point_a: child_pose.transform_point(h.point_a),
                        point_b: child_pose.transform_point(h.point_b),
                        normal: child_pose.transform_vector(h.normal),
                        ..h
                    }),
                );
            }
        }
        (Shape::TriMesh(_) | Shape::HeightField(_), _) => {
            let src = TriangleSource::of(a).expect("a mesh or heightfield");
            keep(shape_cast_triangles(src, b, pose_ab, rel_vel, max_toi)?);
        }
        (_, Shape::Compound(_) | Shape::TriMesh(_) | Shape::HeightField(_) | Shape::Plane(_)) => {
            // B is the compound, mesh, heightfield or plane: swap roles (A moves by -rel_vel
            // relative to B).
            let pose_ba = pose_ab.inverse();
            let rel = pose_ba.transform_vector(-rel_vel);
            keep(shape_cast_local(b, a, &pose_ba, rel, max_toi)?.map(|h| {
                // Back to A's frame; B's witness moved with B, so undo B's frame shift.
                let moved = pose_ab.translation + rel_vel * h.toi;
                let to_a = Isometry::new(moved, pose_ab.rotation);
                ShapeCastHit {
                    point_a: to_a.transform_point(h.point_b),
                    point_b: to_a.transform_point(h.point_a),
                    normal: -pose_ab.transform_vector(h.normal),
                    ..h
                }
            }));
        }
        // Every other pair is convex (handled above); kept so that a new shape kind
        // cannot recurse through the swap forever.
        _ => {
            return Err(CaromError::Unsupported(format!(
                "shape cast between a {} and a {}",
                a.kind_name(),
                b.kind_name()
            )))
        }
    }
    Ok(best)
}

/// Linear cast of convex B (at `pose_ab`, moving by `rel_vel`) against plane A (the
/// half-space `n·x <= offset`), exact: B's support point along `-n` is the first to reach
/// the plane. Already touching or overlapping gives time 0 with the contact.
pub fn shape_cast_plane_convex(
    a: &Plane,
    b: ConvexRef<'_>,
    pose_ab: &Isometry,
    rel_vel: Vec3,
    max_toi: Real,
) -> Option<ShapeCastHit> {
    let n = a.normal();
    let p = b.support_world(pose_ab, -n);
    let d = a.signed_distance(p);
    if d <= 0.0 {
        return Some(ShapeCastHit {
            toi: 0.0,
            point_a: p - n * d,
            point_b: p,
            normal: n,
            initially_overlapping: d < 0.0,
        });
    }
    let approach = -rel_vel.dot(n);
    if approach <= 0.0 {
        return None;
    }
    let toi = d / approach;
    (toi <= max_toi).then(|| {
        let q = p + rel_vel * toi;
        // On the plane: B's point moved onto it, A's is its projection.
        let on = q - n * a.signed_distance(q);
        ShapeCastHit {
            toi,
            point_a: on,
            point_b: on,
            normal: n,
            initially_overlapping: false,
        }
    })
}

/// Linear cast of two convex shapes in A's frame.
pub fn shape_cast_convex(
    a: ConvexRef<'_>,
    b: ConvexRef<'_>,
    pose_ab: &Isometry,
    rel_vel: Vec3,
    max_toi: Real,
) -> Option<ShapeCastHit> {
    let (ra, rb) = (core_radius(a), core_radius(b));
    let diff = MinkowskiDiff {
        a: Core(a),
        b: Transformed::new(Core(b), pose_ab),
    };
    let hit = gjk_raycast(&diff, ra + rb, Vec3::ZERO, rel_vel, max_toi)?;
    if hit.inside {
        let c: Contact = contact_convex(a, b, pose_ab, Real::INFINITY)?;
        return Some(ShapeCastHit::at_contact(0.0, &c, c.distance < 0.0));
    }
    // The ray normal is the outward normal of A - B at the hit. As for distances (the
    // normal from A to B is minus the direction of the closest point of A - B, i.e. the
    // outward normal there), it is the normal from A towards B.
    let n = hit.normal;
    let shift = rel_vel * hit.lambda;
    let cast = ShapeCastHit {
        toi: hit.lambda,
        point_a: hit.core_a + n * ra,
        point_b: hit.core_b + shift - n * rb,
        normal: n,
        initially_overlapping: false,
    };
    refine_cast(a, b, pose_ab, rel_vel, max_toi, cast)
}

/// Conservative-advancement steps from the GJK ray cast's time, which stops within its
/// tolerance of the contact (curved shapes: up to 1e-3 of the size early, with the normal
/// 0.2° off). At time `t` the shapes are `d` apart along the contact normal `n`, and under a
/// translation their distance is at least `d - (t' - t)·(-v·n)`, so `t + d / (-v·n)` never
/// passes the contact; a few steps reach it to round-off, and the last contact query gives
/// the witnesses and the normal. A contact past `max_toi` is no hit.
fn refine_cast(
    a: ConvexRef<'_>,
    b: ConvexRef<'_>,
    pose_ab: &Isometry,
    rel_vel: Vec3,
    max_toi: Real,
    cast: ShapeCastHit,
) -> Option<ShapeCastHit> {
    const STEPS: usize = 4;
    let at = |t: Real| {
        let moved = Isometry::new(pose_ab.translation + rel_vel * t, pose_ab.rotation);
        contact_convex(a, b, &moved, Real::INFINITY)
    };
    let mut t = cast.toi;
    let Some(mut c) = at(t) else {
        return Some(cast);
    };
    let size = a.local_aabb().half_extents().length() + b.local_aabb().half_extents().length();
    let tol = 16.0 * EPSILON * (size + pose_ab.translation.length() + rel_vel.length() * t);
    for _ in 0..STEPS {
        if c.distance <= tol {
            break;
        }
        let approach = -rel_vel.dot(c.normal);
        if approach <= 0.0 {
            break;
        }
        let next = t + c.distance / approach;
        if next > max_toi {
            return None;
        }
        match at(next) {
            // Past the contact by round-off only: keep the last time proven apart.
            Some(k) if k.distance >= -tol => (t, c) = (next, k),
            _ => break,
        }
    }
    let unit = (c.normal.length() - 1.0).abs() < 1.0e-3;
    if c.distance < -tol || !unit {
        return Some(cast);
    }
    Some(ShapeCastHit::at_contact(t, &c, false))
}
