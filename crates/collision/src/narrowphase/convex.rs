//! Manifolds of round and general convex shapes: analytic two-point manifolds for capsules
//! (capsule–capsule when parallel, capsule–polyhedron and capsule–plane when lying flat),
//! and the talk's multi-point by perturbation for everything else (Coumans, "Contact
//! Generation", "Multiple contact points using perturbation"; Bullet's
//! `btConvexConvexAlgorithm` with `btPerturbedContactResult`), with its fixes for round
//! shapes: the perturbed contact is moved back to the actual position, the angle is kept
//! small, and spheres are never perturbed.

use super::contact::FeatureId;
use super::polyhedron::Polyhedron;
use crate::math::{consts::PI, orthonormal_basis, Isometry, Quat, Real, Vec3};
use crate::query::closest_points::closest_point_segment;
use crate::query::{contact_convex, Contact};
use crate::shape::{Capsule, ConvexRef};
use smallvec::{smallvec, SmallVec};

/// The contacts of a capsule pair or a capsule on a polyhedron: at most two, on the stack.
pub type TwoContacts = SmallVec<[(Contact, FeatureId); 2]>;

/// Bullet's perturbation angle limit (radians).
pub const MAX_PERTURBATION_ANGLE: Real = 0.125;

/// Contacts from perturbing A's rotation about axes orthogonal to the normal of `c0`
/// (the talk's pseudo-code), each moved back to A's actual pose: the point on A is kept in
/// A's frame, the point on B is placed along the normal and the distance recomputed.
/// `f` computes a contact in A's frame for a given pose of B.
pub fn perturbed_contacts(
    f: &dyn Fn(&Isometry) -> Option<Contact>,
    pose_ab: &Isometry,
    c0: &Contact,
    angle: Real,
    iterations: u32,
) -> Vec<Contact> {
    let n = c0.normal;
    let angle = angle.clamp(0.0, MAX_PERTURBATION_ANGLE);
    if iterations == 0 || angle == 0.0 || !n.is_finite() {
        return Vec::new();
    }
    let (t0, t1) = orthonormal_basis(n);
    let mut out = Vec::new();
    for i in 0..iterations {
        let phi = 2.0 * PI * i as Real / iterations as Real;
        let axis = t0 * phi.cos() + t1 * phi.sin();
        let p = Quat::from_axis_angle(axis, angle);
        // Rotating A by `p` about its origin = rotating B by `p⁻¹` in A's frame.
        let pose = Isometry::from_rotation(p.inverse()).mul(pose_ab);
        if let Some(c) = f(&pose) {
            let pb = p * c.point_b;
            let d = (pb - c.point_a).dot(n);
            if d.is_finite() {
                out.push(Contact {
                    distance: d,
                    point_a: c.point_a,
                    point_b: c.point_a + n * d,
                    normal: n,
                });
            }
        }
    }
    out
}

fn capsule_segment(c: &Capsule, pose: &Isometry) -> (Vec3, Vec3) {
    let (p, q) = c.segment();
    (pose.transform_point(p), pose.transform_point(q))
}

/// Capsule A against capsule B: two points when the axes are parallel and overlap (within
/// `cos` of 0.5°), else the single closest-point contact.
pub fn capsule_capsule_manifold(
    a: &Capsule,
    b: &Capsule,
    pose_ab: &Isometry,
    prediction: Real,
) -> TwoContacts {
    let Some(c0) = contact_convex(
        ConvexRef::Capsule(a),
        ConvexRef::Capsule(b),
        pose_ab,
        prediction,
    ) else {
        return TwoContacts::new();
    };
    let (pa, qa) = capsule_segment(a, &Isometry::IDENTITY);
    let (pb, qb) = capsule_segment(b, pose_ab);
    let (da, db) = ((qa - pa).normalize_or_zero(), (qb - pb).normalize_or_zero());
    if da.dot(db).abs() > 0.99996 {
        let len = (qa - pa).length();
        let (t0, t1) = {
            let (u, v) = ((pb - pa).dot(da), (qb - pa).dot(da));
            (u.min(v).max(0.0), u.max(v).min(len))
        };
        if t1 - t0 > 1.0e-4 * (1.0 + len) {
            let (ra, rb) = (a.radius(), b.radius());
            let out: TwoContacts = [t0, t1]
                .iter()
                .enumerate()
                .filter_map(|(k, &t)| {
                    let x = pa + da * t;
                    let (y, _) = closest_point_segment(x, pb, qb);
                    let dist = (y - x).length();
                    let n = if dist > 1.0e-6 {
                        (y - x) / dist
                    } else {
                        c0.normal
                    };
                    let d = n.dot(y - x) - ra - rb;
                    (d <= prediction).then(|| {
                        (
                            Contact {
                                distance: d,
                                point_a: x + n * ra,
                                point_b: y - n * rb,
                                normal: n,
                            },
                            k as FeatureId,
                        )
                    })
                })
                .collect();
            if !out.is_empty() {
                return out;
            }
        }
    }
    smallvec![(c0, 2)]
}

/// Capsule A against polyhedron B (`poly` is B's polyhedron view, `b` its convex shape):
/// when the contact normal is a face normal of B, the capsule's segment is clipped against
/// that face's side planes, giving two points when it lies flat; else one point.
pub fn capsule_polyhedron_manifold(
    a: &Capsule,
    b: ConvexRef<'_>,
    poly: &Polyhedron,
    pose_ab: &Isometry,
    prediction: Real,
) -> TwoContacts {
    let Some(c0) = contact_convex(ConvexRef::Capsule(a), b, pose_ab, prediction) else {
        return TwoContacts::new();
    };
    let nb = pose_ab.inverse_transform_vector(c0.normal);
    let mut face = None;
    let mut best: Real = 0.9999;
    for (i, f) in poly.faces().iter().enumerate() {
        let d = -f.normal.dot(nb);
        if d > best {
            best = d;
            face = Some(i);
        }
    }
    let Some(fi) = face else {
        return smallvec![(c0, 2)];
    };
    let pose_ba = pose_ab.inverse();
    let (p, q) = capsule_segment(a, &pose_ba);
    let (fnorm, off) = (poly.faces()[fi].normal, poly.faces()[fi].offset);
    let (mut t0, mut t1): (Real, Real) = (0.0, 1.0);
    let lp = poly.face_loop(fi);
    for k in 0..lp.len() {
        let v0 = poly.vertices()[lp[k] as usize];
        let v1 = poly.vertices()[lp[(k + 1) % lp.len()] as usize];
        let side = (v1 - v0).cross(fnorm).normalize_or_zero();
        let (dp, dq) = (side.dot(p - v0), side.dot(q - v0));
        if dp > 0.0 && dq > 0.0 {
            return smallvec![(c0, 2)];
        }
        if (dp > 0.0) != (dq > 0.0) {
            let t = dp / (dp - dq);
            if dp > 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
        }
    }
    if t1 - t0 < 1.0e-4 {
        return smallvec![(c0, 2)];
    }
    let r = a.radius();
    let mut out = TwoContacts::new();
    for (k, t) in [t0, t1].into_iter().enumerate() {
        let e = p + (q - p) * t;
        let h = fnorm.dot(e) - off;
        let d = h - r;
        if d <= prediction {
            let c = Contact {
                distance: d,
                point_a: e - fnorm * r,
                point_b: e - fnorm * h,
                normal: -fnorm,
            };
            out.push((c.transformed(pose_ab), k as FeatureId));
        }
    }
    if out.is_empty() {
        out.push((c0, 2));
    }
    out
}

/// Capsule B (at `pose_ab`) against the half-space `n · x <= offset` of A: its two segment
/// ends, each within `prediction`.
pub fn plane_capsule_manifold(
    n: Vec3,
    offset: Real,
    b: &Capsule,
    pose_ab: &Isometry,
    prediction: Real,
) -> Vec<(Contact, FeatureId)> {
    let (p, q) = capsule_segment(b, pose_ab);
    let r = b.radius();
    [p, q]
        .into_iter()
        .enumerate()
        .filter_map(|(k, e)| {
            let h = n.dot(e) - offset;
            let d = h - r;
            (d <= prediction).then(|| {
                (
                    Contact {
                        distance: d,
                        point_a: e - n * h,
                        point_b: e - n * r,
                        normal: n,
                    },
                    k as FeatureId,
                )
            })
        })
        .collect()
}
