//! Shape-level queries with world poses: `contact`, `distance`, `intersects`.
//!
//! These validate their input (poses must be finite with unit quaternions, within
//! [`crate::math::UNIT_QUAT_TOLERANCE`]; the prediction distance must not be NaN) and
//! return [`crate::Result`]. They handle every [`Shape`]: convex pairs through
//! [`contact_convex`], planes exactly through the other shape's support point, compounds by
//! recursion over their children, and meshes and heightfields over the triangles their BVH
//! or grid finds near the other shape (module `query::composite`). Plane–plane,
//! plane–mesh and plane–heightfield pairs are [`CaromError::Unsupported`].

use super::composite::contact_triangles;
use super::contact_convex::{contact_convex, intersects_convex, swap_contact};
use super::result::Contact;
use crate::error::{CaromError, Result};
use crate::math::{Isometry, Real};
use crate::midphase::TriangleSource;
use crate::shape::{ConvexRef, Plane, Shape, SupportMap};

/// Contact between `a` at `pose_a` and `b` at `pose_b` (world frame): `None` when they are
/// further apart than `prediction` (>= 0, may be infinite), else the signed distance,
/// witness points and the normal from A to B (see [`Contact`]).
pub fn contact(
    a: &Shape,
    pose_a: &Isometry,
    b: &Shape,
    pose_b: &Isometry,
    prediction: Real,
) -> Result<Option<Contact>> {
    let pose_a = crate::query::check_pose("pose_a", pose_a)?;
    let pose_b = crate::query::check_pose("pose_b", pose_b)?;
    if prediction.is_nan() {
        return Err(CaromError::invalid(
            "prediction",
            prediction,
            "must not be NaN",
        ));
    }
    let pose_ab = pose_a.inv_mul(&pose_b);
    Ok(contact_local(a, b, &pose_ab, prediction)?.map(|c| c.transformed(&pose_a)))
}

/// Signed distance between two shapes (negative when they overlap), with witness points
/// and the normal from A to B, in world space.
pub fn distance(a: &Shape, pose_a: &Isometry, b: &Shape, pose_b: &Isometry) -> Result<Contact> {
    contact(a, pose_a, b, pose_b, Real::INFINITY)?
        .ok_or_else(|| CaromError::degenerate("distance", "no closest points found"))
}

/// True when the shapes touch or overlap. Convex pairs use GJK with an early exit on the
/// first separating axis.
pub fn intersects(a: &Shape, pose_a: &Isometry, b: &Shape, pose_b: &Isometry) -> Result<bool> {
    let pose_a = crate::query::check_pose("pose_a", pose_a)?;
    let pose_b = crate::query::check_pose("pose_b", pose_b)?;
    let pose_ab = pose_a.inv_mul(&pose_b);
    match (a.as_convex(), b.as_convex()) {
        (Some(ca), Some(cb)) => Ok(intersects_convex(ca, cb, &pose_ab)),
        _ => Ok(contact_local(a, b, &pose_ab, 0.0)?.is_some()),
    }
}

/// [`contact`] in A's frame with `pose_ab` (B in A's frame), without pose validation.
pub fn contact_local(
    a: &Shape,
    b: &Shape,
    pose_ab: &Isometry,
    prediction: Real,
) -> Result<Option<Contact>> {
    if let (Some(ca), Some(cb)) = (a.as_convex(), b.as_convex()) {
        return Ok(contact_convex(ca, cb, pose_ab, prediction));
    }
    match (a, b) {
        (Shape::Plane(_), Shape::Plane(_) | Shape::TriMesh(_) | Shape::HeightField(_))
        | (Shape::TriMesh(_) | Shape::HeightField(_), Shape::Plane(_)) => {
            Err(CaromError::Unsupported(format!(
                "contact between a {} and a {}",
                a.kind_name(),
                b.kind_name()
            )))
        }
        (Shape::Plane(p), _) if b.is_convex() => Ok(contact_plane_convex(
            p,
            b.as_convex().expect("checked"),
            pose_ab,
            prediction,
        )),
        (_, Shape::Plane(_)) if a.is_convex() => {
            let pose_ba = pose_ab.inverse();
            let c = contact_local(b, a, &pose_ba, prediction)?;
            Ok(c.map(|c| c.swapped().transformed(pose_ab)))
        }
        (Shape::Compound(c), _) => {
            let mut best: Option<Contact> = None;
            for (child_pose, child) in c.children() {
                let pose_cb = child_pose.inv_mul(pose_ab);
                if let Some(k) = contact_local(child, b, &pose_cb, prediction)? {
                    let k = k.transformed(child_pose);
                    if best.is_none_or(|bk| k.distance < bk.distance) {
                        best = Some(k);
                    }
                }
            }
            Ok(best)
        }
        (_, Shape::Compound(_)) => {
            let pose_ba = pose_ab.inverse();
            Ok(
                contact_local(b, a, &pose_ba, prediction)?
                    .map(|c| c.swapped().transformed(pose_ab)),
            )
        }
        (Shape::TriMesh(_) | Shape::HeightField(_), _) => {
            let src = TriangleSource::of(a).expect("a mesh or heightfield");
            contact_triangles(src, b, pose_ab, prediction)
        }
        (_, Shape::TriMesh(_) | Shape::HeightField(_)) => {
            let pose_ba = pose_ab.inverse();
            Ok(
                contact_local(b, a, &pose_ba, prediction)?
                    .map(|c| c.swapped().transformed(pose_ab)),
            )
        }
        _ => Err(CaromError::Unsupported(format!(
            "contact between a {} and a {}",
            a.kind_name(),
            b.kind_name()
        ))),
    }
}

/// Plane A (the half-space `n·x <= offset`) against convex B: B's support point along `-n`
/// is its deepest point; exact for every convex shape.
pub fn contact_plane_convex(
    a: &Plane,
    b: ConvexRef<'_>,
    pose_ab: &Isometry,
    prediction: Real,
) -> Option<Contact> {
    let n = a.normal();
    let p = b.support_world(pose_ab, -n);
    let d = a.signed_distance(p);
    (d <= prediction).then(|| Contact {
        distance: d,
        point_a: p - n * d,
        point_b: p,
        normal: n,
    })
}

/// Convex A against plane B, through the swap adapter.
pub fn contact_convex_plane(
    a: ConvexRef<'_>,
    b: &Plane,
    pose_ab: &Isometry,
    prediction: Real,
) -> Option<Contact> {
    swap_contact(pose_ab, |p| contact_plane_convex(b, a, p, prediction))
}
