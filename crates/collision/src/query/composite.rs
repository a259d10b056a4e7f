//! The shape-level queries of meshes and heightfields (`contact`, `distance`, `intersects`,
//! `shape_cast`): the triangles that can matter are found through the shape's acceleration
//! structure ([`TriangleSource`]: a mesh's BVH, a heightfield's grid), then each is queried
//! as a convex [`Triangle`]. The answer is the one the brute force over every triangle gives
//! (the smallest distance or time, ties to the smallest triangle index), which the tests use
//! as the oracle.
//!
//! Culling is conservative: a triangle is skipped only when its bounding box is provably
//! farther from B's bounding box than the bound (a distance already found, the prediction,
//! or the swept box of the cast), with a relative slack for the rounding of the boxes.

use super::contact::contact_local;
use super::result::{Contact, ShapeCastHit};
use super::shape_cast::shape_cast_local;
use crate::error::Result;
use crate::math::{Aabb, Isometry, Real, Vec3, EPSILON};
use crate::midphase::TriangleSource;
use crate::shape::{Shape, Triangle};

/// A triangle of `src` as a shape.
#[inline]
pub(crate) fn triangle_shape(src: &TriangleSource<'_>, i: u32) -> Shape {
    let [a, b, c] = src.triangle(i);
    Shape::Triangle(Triangle { a, b, c })
}

/// Slack for the rounding of bounding boxes whose coordinates reach `b`'s: 64 ε of the
/// largest coordinate magnitude and extent (never zero, so touching boxes stay in).
#[inline]
pub(crate) fn cull_slack(b: &Aabb) -> Real {
    let m = b.min.abs().max(b.max.abs()).max_element() + b.extents().max_element();
    64.0 * EPSILON * m.max(Real::MIN_POSITIVE)
}

/// Triangle indices of `src` whose boxes overlap `query`, ascending (so that every caller
/// breaks ties as the brute force in index order does).
fn candidates(src: &TriangleSource<'_>, query: &Aabb) -> Vec<u32> {
    let mut out = Vec::new();
    src.for_each_triangle_in_aabb(query, |i| {
        out.push(i);
        true
    });
    out.sort_unstable();
    out
}

/// [`contact_local`] of a mesh or heightfield A against any shape B at `pose_ab` (B in A's
/// frame): the contact of smallest signed distance over the triangles within `prediction`.
///
/// For an unbounded prediction (a distance query) the triangle nearest B's box centre gives
/// a first distance `d`, and only triangles whose boxes lie within `d` of B's box can beat
/// it (B lies inside its box, the triangle inside its own).
pub(crate) fn contact_triangles(
    src: TriangleSource<'_>,
    b: &Shape,
    pose_ab: &Isometry,
    prediction: Real,
) -> Result<Option<Contact>> {
    let b_box = b.aabb(pose_ab);
    let mut radius = prediction.max(0.0);
    if radius > 0.0 {
        let Some(near) = src.closest_point(b_box.center(), Real::INFINITY) else {
            return Ok(None);
        };
        let tri = triangle_shape(&src, near.triangle);
        if let Some(c) = contact_local(&tri, b, pose_ab, prediction)? {
            radius = radius.min(c.distance.max(0.0));
        }
    }
    let query = b_box.expanded(radius + cull_slack(&b_box.expanded(radius)));
    let mut best: Option<(Contact, u32)> = None;
    for i in candidates(&src, &query) {
        if let Some(c) = contact_local(&triangle_shape(&src, i), b, pose_ab, prediction)? {
            if best.is_none_or(|(k, _)| c.distance < k.distance) {
                best = Some((c, i));
            }
        }
    }
    Ok(best.map(|(c, _)| c))
}

/// The time window `[t0, t1]` within `[0, max_toi]` during which the box `b`, moving by
/// `vel` per unit time, overlaps the box `target`; `None` when it never does.
fn sweep_window(b: &Aabb, vel: Vec3, target: &Aabb, max_toi: Real) -> Option<(Real, Real)> {
    let (mut t0, mut t1): (Real, Real) = (0.0, max_toi);
    for k in 0..3 {
        let v = vel[k];
        if v == 0.0 {
            if b.max[k] < target.min[k] || b.min[k] > target.max[k] {
                return None;
            }
            continue;
        }
        let (enter, exit) = (
            (target.min[k] - b.max[k]) / v,
            (target.max[k] - b.min[k]) / v,
        );
        let (enter, exit) = if v > 0.0 {
            (enter, exit)
        } else {
            (exit, enter)
        };
        t0 = t0.max(enter);
        t1 = t1.min(exit);
    }
    (t0 <= t1).then_some((t0, t1))
}

/// [`shape_cast_local`] of a mesh or heightfield A against any shape B at `pose_ab` moving
/// by `rel_vel` (A's frame): the first hit over the triangles that B's box meets on its way
/// (the box swept over the part of the cast during which it overlaps A's box).
pub(crate) fn shape_cast_triangles(
    src: TriangleSource<'_>,
    b: &Shape,
    pose_ab: &Isometry,
    rel_vel: Vec3,
    max_toi: Real,
) -> Result<Option<ShapeCastHit>> {
    let b_box = b.aabb(pose_ab);
    let target = src.local_aabb();
    let target = target.expanded(cull_slack(&target.merge(&b_box)));
    let Some((t0, t1)) = sweep_window(&b_box, rel_vel, &target, max_toi) else {
        return Ok(None);
    };
    let at = |t: Real| {
        let shift = if t == 0.0 || rel_vel == Vec3::ZERO {
            Vec3::ZERO
        } else {
            rel_vel * t
        };
        Aabb::new(b_box.min + shift, b_box.max + shift)
    };
    let swept = at(t0).merge(&at(t1));
    let query = swept.expanded(cull_slack(&swept));
    let mut best: Option<(ShapeCastHit, u32)> = None;
    for i in candidates(&src, &query) {
        let limit = best.map_or(max_toi, |(h, _)| h.toi);
        if let Some(h) = shape_cast_local(&triangle_shape(&src, i), b, pose_ab, rel_vel, limit)? {
            if best.is_none_or(|(k, _)| h.toi < k.toi) {
                best = Some((h, i));
            }
        }
    }
    Ok(best.map(|(h, _)| h))
}
