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
//! The clipping is the polyhedron clipper's, specialised to boxes (`clip_box_faces`).
//! A pair that one axis separates by more than the prediction costs a few projections.
//!
//! What the SAT cannot settle falls back to the guided path (GJK/EPA and the witness
//! clipping): a reference face whose clipped incident face keeps no point, and apart edge
//! pairs whose segments do not realise the axis separation.

use super::contact::{ContactList, FeatureId};
use super::manifold::Separation;
use super::polyhedron::{polyhedron_manifold_guided, Polyhedron, BOX_LOOPS, EPA_FEATURE};
use super::polyhedron_guided::witness_realises_depth;
use crate::math::{Isometry, Mat3, Real, Vec3, Vec3A};
use crate::query::contact_cuboid_cuboid::{
    cuboid_cuboid_axis_or_separation_mat, cuboid_cuboid_witness_mat, Axis,
};
use crate::query::Contact;
use crate::shape::{ConvexRef, Cuboid};

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
    // The certificate of an apart pair is for the persistent manifold only.
    let _ = cuboid_cuboid_manifold_or_separation(x, y, pose_ab, prediction, out);
}

/// [`cuboid_cuboid_manifold_into`], returning for a pair that one axis separates by more
/// than `prediction` (nothing appended) that axis as a [`Separation`] certificate, which
/// the persistent manifold keeps to skip the pair while the relative motion cannot close
/// the gap; `None` otherwise (points appended, or a pair within `prediction` that has none).
pub fn cuboid_cuboid_manifold_or_separation(
    x: &Cuboid,
    y: &Cuboid,
    pose_ab: &Isometry,
    prediction: Real,
    out: &mut ContactList,
) -> Option<Separation> {
    // B's rotation in A's frame, once for the separating-axis test and the clipping (each
    // built it from the quaternion before; the same bits).
    let rot = pose_ab.rotation_matrix();
    let sat = cuboid_cuboid_axis_or_separation_mat(x, y, &rot, pose_ab.translation, prediction);
    let (overlap, n, axis) = match sat {
        Ok(found) => found,
        Err((distance, axis)) => {
            return distance.is_finite().then_some(Separation {
                pose_ab: *pose_ab,
                axis,
                distance,
                reach: y.half_extents().length(),
            })
        }
    };
    let (ha, hb) = (x.half_extents(), y.half_extents());
    let start = out.len();
    match axis {
        Axis::FaceA(i) => {
            let fa = 2 * i + (n[i] < 0.0) as usize;
            clip_box_faces(ha, fa, hb, &rot, pose_ab, prediction, face_id_a(fa), out);
        }
        Axis::FaceB(j) => {
            let nb = pose_ab.inverse_transform_vector(-n);
            let fb = 2 * j + (nb[j] < 0.0) as usize;
            clip_face_b(ha, hb, fb, &rot, pose_ab, prediction, out);
        }
        Axis::Edge(..) => {
            let c = cuboid_cuboid_witness_mat(x, y, pose_ab, &rot, overlap, n, axis);
            // The supporting edges' closest points must realise the separation or the
            // overlap: for nearly parallel edges, or touching boxes whose edge axis is not
            // where the edges meet, they may not (the polytope oracle found a point 0.116 m
            // off a box); the guided path, then the full SAT, decide then.
            let realised = if overlap >= 0.0 {
                witness_realises_depth(&c, x, y)
            } else {
                let scale = x.half_extents().length() + y.half_extents().length();
                (c.point_b - c.point_a - n * c.distance).length() <= 1.0e-4 * scale
            };
            if realised {
                edge_manifold(ha, hb, c, &rot, pose_ab, prediction, out);
            }
        }
    }
    if out.len() == start {
        let (a, b) = (Polyhedron::from_cuboid(x), Polyhedron::from_cuboid(y));
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
    None
}

/// Feature id base of A's reference face `fa` (the layout of the polyhedron clipper's ids).
fn face_id_a(fa: usize) -> FeatureId {
    (fa as u32 & 0x3F) << 24
}

/// Clips A's face most anti-parallel to B's face `fb` against that reference face of B, and
/// appends the points in A's frame with A's normal convention. `rot` is
/// `pose_ab.rotation_matrix()`.
fn clip_face_b(
    ha: Vec3,
    hb: Vec3,
    fb: usize,
    rot: &Mat3,
    pose_ab: &Isometry,
    prediction: Real,
    out: &mut ContactList,
) {
    let id_base = ((fb as u32 & 0x3F) | 0x40) << 24;
    // Clipped in B's frame, each point mapped back to A's frame as it is appended (no
    // intermediate list), by B's rotation matrix in A's frame (three matrix products per
    // point instead of three quaternion rotations). A's rotation in B's frame is its
    // transpose: `Mat3::from_quat` of the conjugate quaternion forms the same products with
    // the signs of the `w` terms flipped, so the transpose has its bits exactly (checked by
    // `transpose_is_the_inverse_matrix`); the translation is `pose_ab.inverse()`'s.
    let t = pose_ab.translation;
    let t_ba = -(pose_ab.rotation.inverse() * t);
    // Every clipped point has the reference face's normal: mapped once, not per point.
    let mut nr = Vec3::ZERO;
    nr[fb / 2] = if fb.is_multiple_of(2) { 1.0 } else { -1.0 };
    let normal = *rot * -nr;
    // The points' two products on SIMD columns (`Vec3A`), summed in `Mat3 * Vec3`'s order
    // (column by column, nothing fused), so the same bits as the scalar products; in f64
    // `Vec3A` is `Vec3`.
    let cols = [rot.x_axis, rot.y_axis, rot.z_axis].map(to_vec3a);
    let ta = to_vec3a(t);
    let map = |p: Vec3| {
        let v = to_vec3a(p);
        let r = cols[0] * v.x + cols[1] * v.y + cols[2] * v.z + ta;
        to_vec3(r)
    };
    clip_box_faces_with(
        hb,
        fb,
        ha,
        &rot.transpose(),
        t_ba,
        prediction,
        id_base,
        |c, id| {
            let c = Contact {
                distance: c.distance,
                point_a: map(c.point_b),
                point_b: map(c.point_a),
                normal,
            };
            out.push((c, id))
        },
    );
}

/// A [`Vec3`] as a SIMD vector (the identity in f64, where `Vec3A` is `Vec3`).
#[inline(always)]
#[allow(clippy::useless_conversion)]
fn to_vec3a(v: Vec3) -> Vec3A {
    v.into()
}

/// A SIMD vector back to [`Vec3`] (the identity in f64).
#[inline(always)]
#[allow(clippy::useless_conversion)]
fn to_vec3(v: Vec3A) -> Vec3 {
    v.into()
}

/// Room for the corners of a box face through the four side-plane clips: a clip of a convex
/// polygon adds at most one corner, so a quad ends with at most 8. (A clip keeps every
/// corner on or inside the plane and adds one per sign change along the polygon, so a
/// polygon made non-convex by round-off could gain more; the clip then gives up and emits
/// nothing, and the caller takes its fallback, as when the faces miss.)
const CLIP_CAP: usize = 8;

/// A polygon being clipped: corners (as arrays, so a runtime axis index is a plain index,
/// not `Vec3`'s `match`) with feature ids, in a fixed buffer.
#[derive(Clone, Copy)]
struct Poly {
    pts: [([Real; 3], u32); CLIP_CAP],
    len: usize,
}

impl Poly {
    const EMPTY: Poly = Poly {
        pts: [([0.0; 3], 0); CLIP_CAP],
        len: 0,
    };

    /// Appends a corner; false (nothing appended) when the buffer is full.
    #[inline(always)]
    #[must_use]
    fn push(&mut self, p: [Real; 3], id: u32) -> bool {
        if self.len == CLIP_CAP {
            return false;
        }
        self.pts[self.len] = (p, id);
        self.len += 1;
        true
    }
}

/// The face clipping of [`super::polyhedron`]'s `clip_faces` for two boxes: the incident
/// box (half extents `hi`, at `pose_ri` in the reference box's frame) clips its face most
/// anti-parallel to the reference face `rf` (axis `rf / 2`, outward along `+` for even `rf`)
/// against the reference face's four side planes `±x_k <= hr_k`, which are axis-aligned in
/// the reference frame: comparisons of one coordinate instead of the general clipper's plane
/// built from each reference edge (a third of its instructions in "3000 fall"). The points
/// within `prediction` of the reference face are appended in the reference frame (normal
/// from the reference towards the incident box), with feature ids in `clip_faces`' layout:
/// `id_base | face << 16 | corner << 8 | 0xFF` for incident corners, the corner's id with
/// the side plane's index in the low byte for points made by the clip, and in its order:
/// the incident corners in their face's outward loop ([`BOX_LOOPS`]), the side planes in the
/// order of the reference face's loop edges. (The solver sweeps a manifold's points in
/// order; listing every face's corners the same way round made the 20-row pyramid of
/// `pipeline_stacking` creep 2.2 cm in 2000 steps instead of 0.7.) Nothing is appended
/// when the incident face misses the reference face's prism (the caller then falls back).
/// `rot_ri` is `pose_ri.rotation_matrix()`, built once by the caller.
#[allow(clippy::too_many_arguments)]
fn clip_box_faces(
    hr: Vec3,
    rf: usize,
    hi: Vec3,
    rot_ri: &Mat3,
    pose_ri: &Isometry,
    prediction: Real,
    id_base: u32,
    out: &mut ContactList,
) {
    let t = pose_ri.translation;
    clip_box_faces_with(hr, rf, hi, rot_ri, t, prediction, id_base, |c, id| {
        out.push((c, id))
    });
}

/// The side planes `s · x_k <= h_k` of each box face, in the order of the edges of the
/// face's loop in [`BOX_LOOPS`] (edge `a → b` bounds the plane along `(b − a) × n`).
const SIDE_PLANES: [[(usize, Real); 4]; 6] = side_planes();

const fn side_planes() -> [[(usize, Real); 4]; 6] {
    let mut out = [[(0usize, 0.0 as Real); 4]; 6];
    let mut f = 0;
    while f < 6 {
        let i = f / 2;
        let sn: i32 = if f % 2 == 0 { 1 } else { -1 };
        let mut e = 0;
        while e < 4 {
            let a = BOX_LOOPS[4 * f + e];
            let b = BOX_LOOPS[4 * f + (e + 1) % 4];
            let d = (a ^ b).trailing_zeros() as usize;
            let sd: i32 = if b & (1 << d) != 0 { 1 } else { -1 };
            // e_d × e_i = ε(d, i, k) e_k with k the third axis.
            let k = 3 - d - i;
            let eps: i32 = if (d + 1) % 3 == i { 1 } else { -1 };
            out[f][e] = (k, (sd * sn * eps) as Real);
            e += 1;
        }
        f += 1;
    }
    out
}

/// [`clip_box_faces`] with the incident box's pose given as its rotation matrix `rot` and
/// centre `t` in the reference frame, handing each kept point to `emit` (in the reference
/// frame). The polygon lives in two fixed buffers used in turn (it was a pair of 16-point
/// `SmallVec`s swapped after each clip, and a `Vec3` indexed by a runtime axis: the copies and the
/// index `match`es were half of the clip's instructions in "3000 fall"). The arithmetic is
/// the same, operation for operation, so the points are the same bits.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn clip_box_faces_with(
    hr: Vec3,
    rf: usize,
    hi: Vec3,
    rot: &Mat3,
    t: Vec3,
    prediction: Real,
    id_base: u32,
    mut emit: impl FnMut(Contact, FeatureId),
) {
    let i = rf / 2;
    let sign: Real = if rf.is_multiple_of(2) { 1.0 } else { -1.0 };
    let mut nr = Vec3::ZERO;
    nr[i] = sign;
    let axes = [rot.x_axis, rot.y_axis, rot.z_axis];
    let hi = hi.to_array();
    let hr = hr.to_array();
    // The incident face: the incident axis most parallel to the normal, on the side facing
    // the reference face.
    let col = |k: usize| axes[k].to_array()[i].abs();
    let mut j = 0;
    for k in 1..3 {
        if col(k) > col(j) {
            j = k;
        }
    }
    let facing_away = axes[j].to_array()[i] * sign > 0.0;
    let inc_face = 2 * j + facing_away as usize;
    let m = if facing_away { -axes[j] } else { axes[j] };
    let centre = t + m * hi[j];
    let (k1, k2) = ((j + 1) % 3, (j + 2) % 3);
    let (u, v) = (axes[k1] * hi[k1], axes[k2] * hi[k2]);
    let id = id_base | ((inc_face as u32 & 0xFF) << 16) | 0xFF;
    let mut bufs = [Poly::EMPTY; 2];
    // The incident face's corners in the polyhedron's loop order (outward, counter-clockwise),
    // so the points, their ids and their order are the general clipper's.
    // The four sums `±u ± v` formed once: `(-u) + v` is `-(u - v)` and `(-u) + (-v)` is
    // `-(u + v)` exactly (IEEE addition commutes and negation is exact), so every corner
    // has the bits of `centre + (su + sv)` with `su = ±u`, `sv = ±v` chosen per corner.
    let (sum, diff) = (u + v, u - v);
    let offsets = [-sum, -diff, diff, sum]; // indexed by (u's sign bit, v's sign bit)
    for (k, &c) in BOX_LOOPS[4 * inc_face..4 * inc_face + 4].iter().enumerate() {
        let code = (((c >> k1) & 1) << 1 | ((c >> k2) & 1)) as usize;
        let _ = bufs[0].push(
            (centre + offsets[code]).to_array(),
            id | ((k as u32 & 0xFF) << 8),
        );
    }
    let mut cur = 0;
    let mut tag = 0;
    // The reference face's side planes in the order of its loop's edges (the tags of the
    // general clipper).
    for &(k, s) in &SIDE_PLANES[rf] {
        {
            let limit = hr[k];
            // Each corner's signed distance to the side plane, once (the loop below used to
            // compute it twice, as an edge's start and as the previous edge's end). When every
            // corner is strictly inside, the clip would copy the polygon unchanged (no sign
            // change, so no new corner): the pass is skipped, keeping the buffer and the tag
            // sequence, so the points and ids are the same bits.
            let src = &bufs[cur];
            let n = src.len;
            // One more slot: the first corner's distance again, so the edge from the last
            // corner back to the first reads its end without an index wrap.
            let mut dist = [0.0 as Real; CLIP_CAP + 1];
            let mut all_inside = true;
            for (d, (p, _)) in dist.iter_mut().zip(&src.pts[..n]) {
                *d = s * p[k] - limit;
                all_inside &= *d < 0.0;
            }
            dist[n] = dist[0];
            if all_inside {
                tag += 1;
                continue;
            }
            let (lo, hi_buf) = bufs.split_at_mut(1);
            let (src, dst) = if cur == 0 {
                (&lo[0], &mut hi_buf[0])
            } else {
                (&hi_buf[0], &mut lo[0])
            };
            // The output length in a local (not reloaded from the buffer after each store),
            // and the corners and distances as slices of the polygon's length, so the
            // indexing below needs no bounds checks.
            let (pts, dist) = (&src.pts[..n], &dist[..=n]);
            let mut len = 0;
            for e in 0..n {
                let (p, ip) = pts[e];
                let (dp, dq) = (dist[e], dist[e + 1]);
                if dp <= 0.0 {
                    if len == CLIP_CAP {
                        return;
                    }
                    dst.pts[len] = (p, ip);
                    len += 1;
                }
                // A sign change implies `dp != dq` (equal values, and NaN against anything,
                // compare alike with 0), the general clipper's second condition.
                if (dp < 0.0) != (dq < 0.0) {
                    let t = dp / (dp - dq);
                    let q = pts[if e + 1 == n { 0 } else { e + 1 }].0;
                    let (pv, qv) = (Vec3::from_array(p), Vec3::from_array(q));
                    if len == CLIP_CAP {
                        return;
                    }
                    dst.pts[len] = ((pv + (qv - pv) * t).to_array(), (ip & 0xFFFF_FF00) | tag);
                    len += 1;
                }
            }
            dst.len = len;
            cur ^= 1;
            if len == 0 {
                return;
            }
            tag += 1;
        }
    }
    let poly = &bufs[cur];
    for &(p, fid) in &poly.pts[..poly.len] {
        let d = sign * p[i] - hr[i];
        if d <= prediction {
            let p = Vec3::from_array(p);
            emit(
                Contact {
                    distance: d,
                    point_a: p - nr * d,
                    point_b: p,
                    normal: nr,
                },
                fid,
            );
        }
    }
}

/// An edge–edge contact `c`: the faces when its normal is within about 2.6° of a face
/// normal of A (or B), else the single point; the single point also joins clipped faces
/// that do not reach its depth (the rule of the guided polyhedron path's `clip_guided`).
fn edge_manifold(
    ha: Vec3,
    hb: Vec3,
    c: Contact,
    rot: &Mat3,
    pose_ab: &Isometry,
    prediction: Real,
    out: &mut ContactList,
) {
    // The face of a box whose outward normal is closest to `n` (faces numbered 2k for +e_k,
    // 2k + 1 for -e_k; the first on ties), and that cosine.
    let best_face = |n: Vec3| {
        let mut best = (0, Real::NEG_INFINITY);
        for f in 0..6usize {
            let d = if f.is_multiple_of(2) {
                n[f / 2]
            } else {
                -n[f / 2]
            };
            if d > best.1 {
                best = (f, d);
            }
        }
        best
    };
    let (fa, da) = best_face(c.normal);
    let (fb, db) = best_face(pose_ab.inverse_transform_vector(-c.normal));
    let start = out.len();
    if da >= FACE_COS && da + 1.0e-4 >= db {
        clip_box_faces(ha, fa, hb, rot, pose_ab, prediction, face_id_a(fa), out);
    } else if db >= FACE_COS {
        clip_face_b(ha, hb, fb, rot, pose_ab, prediction, out);
    }
    let clipped_min = out[start..]
        .iter()
        .map(|(k, _)| k.distance)
        .fold(Real::INFINITY, Real::min);
    if out.len() == start || clipped_min > c.distance + 1.0e-3 * (1.0 + c.distance.abs()) {
        out.push((c, EPA_FEATURE));
    }
}

#[cfg(test)]
#[path = "contact_cuboid_cuboid_tests.rs"]
mod tests;
