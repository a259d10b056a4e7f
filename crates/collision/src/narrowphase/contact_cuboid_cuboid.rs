//! The box–box manifold: the boxes' own separating-axis test over the 15 axes decides
//! everything, apart or overlapping, and the faces it selects are clipped.
//!
//! Box–box pairs dominate box scenes ("3000 fall", "1000 stack"), and most broadphase pairs
//! there are apart (within their expanded boxes but not touching). The guided polyhedron path
//! ([`super::polyhedron_guided::polyhedron_manifold_guided`]) gave every apart pair a GJK
//! distance (a third of the whole step in "3000 fall"); here the SAT's largest separation is
//! the speculative distance, as in Box3D (`b3CollideBoxes` in `manifold.c`) and parry
//! (`contact_manifold_cuboid_cuboid`): a face axis clips the incident face against the
//! reference face and keeps the points within the prediction (each with its exact distance
//! to the reference face), an edge axis gives the closest points of the two supporting edges.
//! A pair that one axis separates by more than the prediction costs a few projections.
//!
//! What the SAT cannot settle falls back to the guided path (GJK/EPA and the witness
//! clipping): a reference face whose clipped incident face keeps no point, and apart edge
//! pairs whose segments do not realise the axis separation.

use super::contact::{ContactList, FeatureId};
use super::polyhedron::{clip_faces, polyhedron_manifold_guided, Polyhedron, EPA_FEATURE};
use crate::math::{Isometry, Real, Vec3};
use crate::query::contact_cuboid_cuboid::{cuboid_cuboid_axis, cuboid_cuboid_witness, Axis};
use crate::query::Contact;
use crate::shape::{ConvexRef, Cuboid};
use smallvec::SmallVec;

/// Cosine under which a contact normal counts as a face normal when an edge axis is clipped
/// as faces (about 2.6°, as the guided polyhedron path).
const FACE_COS: Real = 0.999;

/// The full manifold of box `x` against box `y` (at `pose_ab` in A's frame), appended to
/// `out` in A's frame with the query convention (normal from A towards B): up to 8 clipped
/// points (the persistent manifold reduces them to 4), or one edge point, or nothing when
/// the boxes are more than `prediction` apart. Allocates nothing beyond `out`.
pub fn cuboid_cuboid_manifold_into(
    x: &Cuboid,
    y: &Cuboid,
    pose_ab: &Isometry,
    prediction: Real,
    out: &mut ContactList,
) {
    let Some((overlap, n, axis)) = cuboid_cuboid_axis(x, y, pose_ab, prediction) else {
        return;
    };
    let (a, b) = (Polyhedron::from_cuboid(x), Polyhedron::from_cuboid(y));
    let start = out.len();
    match axis {
        Axis::FaceA(i) => {
            let fa = 2 * i + (n[i] < 0.0) as usize;
            clip_faces(&a, fa, &b, pose_ab, prediction, face_id_a(fa), out);
        }
        Axis::FaceB(j) => {
            let nb = pose_ab.inverse_transform_vector(-n);
            let fb = 2 * j + (nb[j] < 0.0) as usize;
            clip_face_b(&a, &b, fb, pose_ab, prediction, out);
        }
        Axis::Edge(..) => {
            let c = cuboid_cuboid_witness(x, y, pose_ab, overlap, n, axis);
            // Apart: the supporting edges' closest points must realise the separation (for
            // nearly parallel edges they may not; the guided path decides then).
            let scale = x.half_extents().length() + y.half_extents().length();
            let realised = overlap >= 0.0
                || (c.point_b - c.point_a - n * c.distance).length() <= 1.0e-4 * scale;
            if realised {
                edge_manifold(&a, &b, c, pose_ab, prediction, out);
            }
        }
    }
    if out.len() == start {
        polyhedron_manifold_guided(
            &a,
            &b,
            ConvexRef::Cuboid(x),
            ConvexRef::Cuboid(y),
            pose_ab,
            prediction,
            out,
        );
    }
}

/// Feature id base of A's reference face `fa` (the layout of [`clip_faces`]' ids).
fn face_id_a(fa: usize) -> FeatureId {
    (fa as u32 & 0x3F) << 24
}

/// Clips A's face most anti-parallel to B's face `fb` against that reference face of B, and
/// appends the points in A's frame with A's normal convention.
fn clip_face_b(
    a: &Polyhedron,
    b: &Polyhedron,
    fb: usize,
    pose_ab: &Isometry,
    prediction: Real,
    out: &mut ContactList,
) {
    let id_base = ((fb as u32 & 0x3F) | 0x40) << 24;
    let mut tmp: SmallVec<[(Contact, FeatureId); 16]> = SmallVec::new();
    clip_faces(b, fb, a, &pose_ab.inverse(), prediction, id_base, &mut tmp);
    out.extend(
        tmp.into_iter()
            .map(|(c, id)| (c.swapped().transformed(pose_ab), id)),
    );
}

/// An edge–edge contact `c`: the faces when its normal is within about 2.6° of a face
/// normal of A (or B), else the single point; the single point also joins clipped faces
/// that do not reach its depth (the rule of the guided polyhedron path's `clip_guided`, with
/// the same face scan so that both give the same bits).
fn edge_manifold(
    a: &Polyhedron,
    b: &Polyhedron,
    c: Contact,
    pose_ab: &Isometry,
    prediction: Real,
    out: &mut ContactList,
) {
    let best_face = |p: &Polyhedron, n: Vec3| {
        p.faces()
            .iter()
            .enumerate()
            .fold((0, Real::NEG_INFINITY), |best, (i, f)| {
                let d = f.normal.dot(n);
                if d > best.1 {
                    (i, d)
                } else {
                    best
                }
            })
    };
    let (fa, da) = best_face(a, c.normal);
    let (fb, db) = best_face(b, pose_ab.inverse_transform_vector(-c.normal));
    let start = out.len();
    if da >= FACE_COS && da + 1.0e-4 >= db {
        clip_faces(a, fa, b, pose_ab, prediction, face_id_a(fa), out);
    } else if db >= FACE_COS {
        clip_face_b(a, b, fb, pose_ab, prediction, out);
    }
    let clipped_min = out[start..]
        .iter()
        .map(|(k, _)| k.distance)
        .fold(Real::INFINITY, Real::min);
    if out.len() == start || clipped_min > c.distance + 1.0e-3 * (1.0 + c.distance.abs()) {
        out.push((c, EPA_FEATURE));
    }
}
