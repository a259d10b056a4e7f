//! Exact special cases for round shapes (spheres and capsules), in A's frame with B placed
//! by `pose_ab`: sphere–sphere, sphere–box, sphere–capsule, sphere–triangle,
//! capsule–capsule and capsule–triangle (while the segment clears the triangle). Each
//! reduces to the closest points between the cores (a point or a segment) and the other
//! shape, then adds the radii — the talk's "point + radius".

use super::closest_points::{
    closest_point_segment, closest_point_triangle, closest_points_segment_segment,
};
use super::result::Contact;
use crate::math::{orthonormal_basis, Isometry, Real, Vec3};
use crate::shape::{Capsule, Cuboid, Sphere, Triangle};

/// Contact between two balls of radii `ra` at `ca` and `rb` at `cb`; `fallback` is the
/// normal used when the centres coincide.
#[inline]
pub fn contact_balls(ca: Vec3, ra: Real, cb: Vec3, rb: Real, fallback: Vec3) -> Contact {
    let d = cb - ca;
    let len = d.length();
    let normal = if len > 0.0 { d / len } else { fallback };
    Contact {
        distance: len - ra - rb,
        point_a: ca + normal * ra,
        point_b: cb - normal * rb,
        normal,
    }
}

fn within(c: Contact, prediction: Real) -> Option<Contact> {
    (c.distance <= prediction).then_some(c)
}

/// Sphere A against sphere B.
pub fn contact_sphere_sphere(
    a: &Sphere,
    b: &Sphere,
    pose_ab: &Isometry,
    prediction: Real,
) -> Option<Contact> {
    within(
        contact_balls(
            Vec3::ZERO,
            a.radius(),
            pose_ab.translation,
            b.radius(),
            Vec3::Y,
        ),
        prediction,
    )
}

/// Sphere A against box B: closest point on the box to the centre; inside, the face of
/// least penetration (lowest axis index on ties).
pub fn contact_sphere_cuboid(
    a: &Sphere,
    b: &Cuboid,
    pose_ab: &Isometry,
    prediction: Real,
) -> Option<Contact> {
    let r = a.radius();
    let h = b.half_extents();
    // Everything in B's frame, then back to A's frame.
    let p = pose_ab.inverse_transform_point(Vec3::ZERO);
    let q = p.clamp(-h, h);
    let local = if q != p {
        // Outside: the normal from A to B points from the centre to the box.
        let d = q - p;
        let len = d.length();
        let n = d / len;
        Contact {
            distance: len - r,
            point_a: p + n * r,
            point_b: q,
            normal: n,
        }
    } else {
        let gaps = h - p.abs();
        let mut axis = 0;
        for i in 1..3 {
            if gaps[i] < gaps[axis] {
                axis = i;
            }
        }
        let mut face = Vec3::ZERO;
        face[axis] = if p[axis] < 0.0 { -1.0 } else { 1.0 };
        let mut on_face = p;
        on_face[axis] = face[axis] * h[axis];
        Contact {
            distance: -gaps[axis] - r,
            point_a: p - face * r,
            point_b: on_face,
            normal: -face,
        }
    };
    if local.distance > prediction {
        return None;
    }
    Some(local.transformed(pose_ab))
}

/// Sphere A against capsule B: the centre against B's segment.
pub fn contact_sphere_capsule(
    a: &Sphere,
    b: &Capsule,
    pose_ab: &Isometry,
    prediction: Real,
) -> Option<Contact> {
    let (p, q) = b.segment();
    let (p, q) = (pose_ab.transform_point(p), pose_ab.transform_point(q));
    let (c, _) = closest_point_segment(Vec3::ZERO, p, q);
    let fallback = orthonormal_basis((q - p).normalize_or(Vec3::Y)).0;
    within(
        contact_balls(Vec3::ZERO, a.radius(), c, b.radius(), fallback),
        prediction,
    )
}

/// Capsule A against capsule B: closest points of the two segments. When the segments
/// cross, the normal is perpendicular to both (the exact minimum translation).
pub fn contact_capsule_capsule(
    a: &Capsule,
    b: &Capsule,
    pose_ab: &Isometry,
    prediction: Real,
) -> Option<Contact> {
    let (p1, q1) = a.segment();
    let (p2, q2) = b.segment();
    let (p2, q2) = (pose_ab.transform_point(p2), pose_ab.transform_point(q2));
    let (c1, c2) = closest_points_segment_segment(p1, q1, p2, q2);
    let fallback = {
        let da = q1 - p1;
        let db = q2 - p2;
        let n = da.cross(db).normalize_or_zero();
        let n = if n == Vec3::ZERO {
            orthonormal_basis(da.normalize_or(Vec3::Y)).0
        } else {
            n
        };
        // Orient from A towards B's centre when possible.
        if n.dot(pose_ab.translation) < 0.0 {
            -n
        } else {
            n
        }
    };
    within(
        contact_balls(c1, a.radius(), c2, b.radius(), fallback),
        prediction,
    )
}

/// Sphere A against triangle B (two-sided). A centre in the triangle's plane and inside it
/// is pushed out along the front normal.
pub fn contact_sphere_triangle(
    a: &Sphere,
    b: &Triangle,
    pose_ab: &Isometry,
    prediction: Real,
) -> Option<Contact> {
    let [ta, tb, tc] = b.vertices().map(|v| pose_ab.transform_point(v));
    let c = closest_point_triangle(Vec3::ZERO, ta, tb, tc);
    let n = (tb - ta).cross(tc - ta).normalize_or(Vec3::Y);
    within(
        contact_balls(Vec3::ZERO, a.radius(), c, 0.0, -n),
        prediction,
    )
}

/// Capsule A against triangle B (two-sided) in closed form while the capsule's segment
/// stays clear of the triangle: the closest points of a segment and a triangle are those of
/// an endpoint and the triangle or of the segment and an edge (Ericson, "Real-Time Collision
/// Detection", §5.1.10), so the smallest of five closest-point queries is the cores'
/// distance, which GJK would approach iteratively. `Some(None)` beyond `prediction`;
/// `None` when the segment meets the triangle (or comes within round-off of it) or the
/// triangle is degenerate or a sliver: the caller then runs GJK/EPA.
pub fn contact_capsule_triangle_separated(
    a: &Capsule,
    b: &Triangle,
    pose_ab: &Isometry,
    prediction: Real,
) -> Option<Option<Contact>> {
    let m = pose_ab.rotation_matrix();
    let [t0, t1, t2] = b.vertices().map(|v| m * v + pose_ab.translation);
    let (p, q) = a.segment();
    contact_segment_triangle_separated(p, q, a.radius(), [t0, t1, t2], prediction)
}

/// [`contact_capsule_triangle_separated`] with the capsule given as its segment `p`–`q` and
/// radius `r`, and the triangle's corners `t`, all in one frame (any frame: the narrowphase
/// calls it in a mesh's frame, with the segment placed once for all of a pair's triangles).
/// The contact's A is the capsule, B the triangle.
#[inline]
pub fn contact_segment_triangle_separated(
    p: Vec3,
    q: Vec3,
    r: Real,
    t: [Vec3; 3],
    prediction: Real,
) -> Option<Option<Contact>> {
    let [t0, t1, t2] = t;
    let size = (t1 - t0)
        .length()
        .max((t2 - t1).length())
        .max((t0 - t2).length());
    let tol = 1.0e-5 * (size + (q - p).length() + r);
    // Slivers (area under 1e-3 of the longest edge's square: a normal no better than
    // round-off, and barycentric closest points dividing by near zero) go to GJK/EPA.
    let cross = (t1 - t0).cross(t2 - t0);
    let area2 = cross.length();
    if !(area2 > 1.0e-3 * size * size && tol > 0.0 && tol.is_finite()) {
        return None;
    }
    let n = cross / area2;
    // A segment crossing the triangle's plane inside the triangle meets it: penetration.
    let (sp, sq) = (n.dot(p - t0), n.dot(q - t0));
    if (sp <= tol && sq >= -tol) || (sq <= tol && sp >= -tol) {
        if sp == sq {
            return None;
        }
        let x = p + (q - p) * (sp / (sp - sq)).clamp(0.0, 1.0);
        if (closest_point_triangle(x, t0, t1, t2) - x).length() <= tol {
            return None;
        }
    }
    let mut best = {
        let c = closest_point_triangle(p, t0, t1, t2);
        (p, c, (c - p).length_squared())
    };
    let mut take = |s: Vec3, t: Vec3| {
        let d2 = (t - s).length_squared();
        if d2 < best.2 {
            best = (s, t, d2);
        }
    };
    take(q, closest_point_triangle(q, t0, t1, t2));
    for (u, v) in [(t0, t1), (t1, t2), (t2, t0)] {
        let (s, t) = closest_points_segment_segment(p, q, u, v);
        take(s, t);
    }
    let (s, t, d2) = best;
    let d = d2.sqrt();
    if d <= tol || !d.is_finite() {
        return None;
    }
    let normal = (t - s) / d;
    Some((d - r <= prediction).then_some(Contact {
        distance: d - r,
        point_a: s + normal * r,
        point_b: t,
        normal,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Quat;

    #[test]
    fn sphere_box_outside_inside_and_on_edge() {
        let s = Sphere::new(0.5).unwrap();
        let b = Cuboid::new(Vec3::new(1.0, 2.0, 3.0)).unwrap();
        // B placed so that the sphere centre is at (3, 0, 0) in B's frame.
        let pose_ab = Isometry::from_translation(Vec3::new(-3.0, 0.0, 0.0));
        let c = contact_sphere_cuboid(&s, &b, &pose_ab, 10.0).unwrap();
        assert!((c.distance - 1.5).abs() < 1e-6);
        assert!((c.normal - -Vec3::X).length() < 1e-6);
        // Centre inside, nearest face +x at gap 0.2.
        let pose_ab = Isometry::from_translation(Vec3::new(-0.8, 0.0, 0.0));
        let c = contact_sphere_cuboid(&s, &b, &pose_ab, 10.0).unwrap();
        assert!((c.distance + 0.7).abs() < 1e-6, "{c:?}");
        assert!((c.point_b - (c.point_a + c.normal * c.distance)).length() < 1e-6);
        // Rotated box.
        let q = Quat::from_rotation_y(0.5);
        let pose_ab = Isometry::new(q * Vec3::new(-3.0, 0.0, 0.0), q);
        let c = contact_sphere_cuboid(&s, &b, &pose_ab, 10.0).unwrap();
        assert!((c.distance - 1.5).abs() < 1e-5);
    }

    #[test]
    fn crossing_capsules_push_apart_along_the_common_normal() {
        let a = Capsule::new(0.2, 1.0).unwrap();
        let b = Capsule::new(0.3, 1.0).unwrap();
        let pose_ab =
            Isometry::from_rotation(Quat::from_rotation_x(crate::math::consts::FRAC_PI_2));
        let c = contact_capsule_capsule(&a, &b, &pose_ab, 0.0).unwrap();
        assert!((c.distance + 0.5).abs() < 1e-6);
        assert!(c.normal.dot(Vec3::X).abs() > 0.999, "{c:?}");
    }
}
