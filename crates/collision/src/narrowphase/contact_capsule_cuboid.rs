//! Capsule–box manifolds in closed form: the exact capsule–box contact
//! ([`crate::query::contact_capsule_cuboid`]: segment–box closest points, or their
//! separating-axis test when the cores overlap), then, when its normal is a face normal of
//! the box, the capsule's segment clipped against that face's four side planes, giving one
//! point per end of the clipped segment (two when the capsule lies on the face, either flat
//! or tilted). Otherwise (an edge or a vertex of the box) the single contact. As in parry's
//! `contact_manifold_cuboid_capsule` (its segment is a polygonal feature clipped against the
//! box's reference face), without GJK.

use super::contact::FeatureId;
use super::convex::TwoContacts;
use crate::math::{Isometry, Real, Vec3};
use crate::query::contact_capsule_cuboid::{capsule_cuboid_local, clip_to_slabs};
use crate::query::Contact;
use crate::shape::{Capsule, Cuboid};

/// Cosine above which the contact normal counts as the box's face normal (0.8°, as for the
/// other capsule–polyhedron manifolds).
const FACE_COS: Real = 0.9999;

/// Shortest clipped part of the segment (as a fraction of its length) that still gives two
/// points.
const MIN_CLIP: Real = 1.0e-4;

/// Feature id of the single (non-clipped) contact.
const SINGLE: FeatureId = 2;

/// Capsule A against box B (placed by `pose_ab`), in A's frame with the normal from A
/// towards B: up to two points within `prediction` (see the module docs).
pub fn capsule_cuboid_manifold(
    a: &Capsule,
    b: &Cuboid,
    pose_ab: &Isometry,
    prediction: Real,
) -> TwoContacts {
    let (p, q) = a.segment();
    let (p, q) = (
        pose_ab.inverse_transform_point(p),
        pose_ab.inverse_transform_point(q),
    );
    let (r, h) = (a.radius(), b.half_extents());
    let c0 = capsule_cuboid_local(p, q, r, h);
    let mut out = TwoContacts::new();
    if c0.distance > prediction || !c0.distance.is_finite() {
        return out;
    }
    let n = c0.normal;
    let na = n.abs();
    let k = if na.x >= na.y && na.x >= na.z {
        0
    } else if na.y >= na.z {
        1
    } else {
        2
    };
    let d = q - p;
    // When the cores overlap, an edge axis within `FACE_COS` of a face normal won the
    // separating-axis test by more than its face bias: clipping on the face would measure
    // depths along the face normal, deeper than the true one.
    let on_face = na[k] == 1.0 || (na[k] > FACE_COS && c0.distance > -r);
    let clipped = on_face
        .then(|| clip_to_slabs(p, d, h, k))
        .flatten()
        .filter(|(t0, t1)| t1 - t0 >= MIN_CLIP);
    if let Some((t0, t1)) = clipped {
        // The face's outward normal m points towards the capsule, against n.
        let mut m = Vec3::ZERO;
        m[k] = if n[k] > 0.0 { -1.0 } else { 1.0 };
        for (id, t) in [t0, t1].into_iter().enumerate() {
            let e = p + d * t;
            let height = m[k] * e[k] - h[k];
            let distance = height - r;
            if distance <= prediction {
                let c = Contact {
                    distance,
                    point_a: e - m * r,
                    point_b: e - m * height,
                    normal: -m,
                };
                out.push((c.transformed(pose_ab), id as FeatureId));
            }
        }
    }
    if out.is_empty() {
        out.push((c0.transformed(pose_ab), SINGLE));
    }
    out
}
