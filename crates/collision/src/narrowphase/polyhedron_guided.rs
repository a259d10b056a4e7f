//! Polyhedral manifolds guided by GJK/EPA (linear in the shapes' size, for boxes and hulls)
//! and the GJK/EPA contact of two polyhedron views, the fallback of the clipping paths.

use super::contact::FeatureId;
use super::dispatcher::as_polyhedron;
use super::manifold::Separation;
use super::polyhedron::{clip_faces, polyhedron_manifold_into, Polyhedron, FACE_PREFERENCE};
use crate::math::{Isometry, Real, Vec3};
use crate::query::contact_convex::{contact_gjk_epa_unguarded_warm, GjkEpa};
use crate::query::contact_cuboid_cuboid::{
    cuboid_cuboid_sat, cuboid_cuboid_witness, Axis, CuboidSat,
};
use crate::query::epa::epa;
use crate::query::gjk::WarmSimplex;
use crate::query::gjk::{gjk, GjkResult};
use crate::query::guard::{contact_is_consistent, remeasured_near};
use crate::query::support_adapters::{Support, Transformed};
use crate::query::Contact;
use crate::shape::{ConvexHull, ConvexRef, Cuboid, Shape, SupportMap};
use smallvec::SmallVec;

/// The feature id of a single GJK/EPA point.
pub const EPA_FEATURE: FeatureId = 0x8000_0000 | 0x7FFF_FFFF;

impl Support for Polyhedron<'_> {
    /// The vertex maximising `v · dir` (first on ties), by a scan of the vertices.
    fn support(&self, dir: Vec3) -> Vec3 {
        let v = self.vertices();
        let mut best = v.first().copied().unwrap_or(Vec3::ZERO);
        let mut best_d = best.dot(dir);
        for p in v.iter().skip(1) {
            let d = p.dot(dir);
            if d > best_d {
                best_d = d;
                best = *p;
            }
        }
        best
    }
}

/// GJK/EPA contact of two polyhedra (B at `pose_ab`), in A's frame; `None` beyond
/// `prediction`.
pub fn polyhedron_contact(
    a: &Polyhedron,
    b: &Polyhedron,
    pose_ab: &Isometry,
    prediction: Real,
) -> Option<Contact> {
    let tb = Transformed::new(*b, pose_ab);
    match gjk(a, &tb, -pose_ab.translation, prediction) {
        GjkResult::BeyondMaxDistance => None,
        GjkResult::Separated {
            distance,
            point_a,
            point_b,
        } => (distance <= prediction && distance > 0.0).then(|| Contact {
            distance,
            point_a,
            point_b,
            normal: (point_b - point_a) / distance,
        }),
        GjkResult::Overlapping(simplex) => {
            let p = epa(a, &tb, &simplex);
            (p.depth.is_finite() && p.normal.is_finite()).then_some(Contact {
                distance: -p.depth,
                point_a: p.point_a,
                point_b: p.point_b,
                normal: p.normal,
            })
        }
    }
}

/// How many guard tolerances EPA's distance may be off before the guided manifold gives
/// way to the full separating-axis test (see [`polyhedron_manifold_guided`]).
const REMEASURE_SLACK: Real = 10.0;

/// Up to this many edge pairs (and always with a triangle) the dispatcher runs the full
/// separating-axis test, quadratic in the edge count; boxes and hulls go through
/// [`polyhedron_manifold_guided`].
pub const SAT_MAX_EDGE_PAIRS: usize = 16;

/// Cosine under which a contact normal counts as a face normal in
/// [`polyhedron_manifold_guided`] (about 2.6 degrees).
const FACE_COS: Real = 0.999;

/// The full manifold of two polyhedra guided by GJK/EPA instead of the full SAT (the approach
/// of parry's `contact_manifolds_pfm_pfm` and Bullet's `btPolyhedralContactClipping` after
/// a GJK normal): one penetration query gives the normal `n`; when `n` is within about 2.6°
/// of a face normal of A (or of B), that face is the reference face and the other shape's
/// most anti-parallel face is clipped against it as in [`super::polyhedron::polyhedron_manifold`]; otherwise
/// (edge–edge, vertex contacts) the single GJK/EPA point is the manifold. Cost: one GJK/EPA
/// plus a scan of the faces, linear in the size of the shapes. `ca`/`cb` are the shapes
/// behind the views `a`/`b`.
#[allow(clippy::too_many_arguments)]
pub fn polyhedron_manifold_guided(
    a: &Polyhedron,
    b: &Polyhedron,
    ca: ConvexRef<'_>,
    cb: ConvexRef<'_>,
    pose_ab: &Isometry,
    prediction: Real,
    out: &mut Vec<(Contact, FeatureId)>,
) {
    polyhedron_manifold_or_separation(a, b, ca, cb, pose_ab, prediction, out);
}

/// The built-in table's manifold of a hull against a hull or a box, `a` and `b` (B at
/// `pose_ab`), appended to `out`, and a certificate that they are apart (see
/// [`polyhedron_manifold_or_separation`]); `None` for other shapes, which write nothing.
/// `hint` is a guess of the contact normal (A's frame, from A towards B: the persistent
/// manifold's last normal) that seeds GJK; the answer does not depend on it beyond
/// round-off.
pub fn hull_manifold_or_separation(
    a: &Shape,
    b: &Shape,
    pose_ab: &Isometry,
    prediction: Real,
    hint: Option<Vec3>,
    out: &mut Vec<(Contact, FeatureId)>,
) -> Option<Separation> {
    hull_manifold_or_separation_warm(a, b, pose_ab, prediction, hint, None, out)
}

/// [`hull_manifold_or_separation`] keeping the pair's GJK simplex in `warm` between calls
/// (see [`contact_gjk_epa_unguarded_warm`]): GJK starts from it and leaves its final simplex
/// there. `warm` must come from earlier calls with the same two shapes, in the same order.
#[allow(clippy::too_many_arguments)]
pub fn hull_manifold_or_separation_warm(
    a: &Shape,
    b: &Shape,
    pose_ab: &Isometry,
    prediction: Real,
    hint: Option<Vec3>,
    warm: Option<&mut WarmSimplex>,
    out: &mut Vec<(Contact, FeatureId)>,
) -> Option<Separation> {
    let (ca, cb) = (a.as_convex()?, b.as_convex()?);
    let (pa, pb) = (as_polyhedron(ca)?, as_polyhedron(cb)?);
    if pa.flat || pb.flat || pa.edges().len() * pb.edges().len() <= SAT_MAX_EDGE_PAIRS {
        polyhedron_manifold_into(&pa, &pb, pose_ab, prediction, out);
        return None;
    }
    manifold_or_separation_hinted(&pa, &pb, ca, cb, pose_ab, prediction, hint, warm, out)
}

/// [`polyhedron_manifold_guided`], returning, when GJK finds the shapes farther apart than
/// the prediction, the separating axis it stopped on with the exact separation along it (two
/// support queries), as a [`Separation`] for the manifold (`ContactManifold::apart`: the
/// pair is skipped while the motion bound proves it still apart, as box–box pairs are).
/// `None` for pairs in contact, for a box much larger than the hull, and when the measured
/// separation does not exceed the prediction.
#[allow(clippy::too_many_arguments)]
pub fn polyhedron_manifold_or_separation(
    a: &Polyhedron,
    b: &Polyhedron,
    ca: ConvexRef<'_>,
    cb: ConvexRef<'_>,
    pose_ab: &Isometry,
    prediction: Real,
    out: &mut Vec<(Contact, FeatureId)>,
) -> Option<Separation> {
    manifold_or_separation_hinted(a, b, ca, cb, pose_ab, prediction, None, None, out)
}

/// [`polyhedron_manifold_or_separation`] with GJK seeded by a guessed normal `hint` (A's
/// frame, from A towards B; see [`hull_manifold_or_separation`]).
#[allow(clippy::too_many_arguments)]
fn manifold_or_separation_hinted(
    a: &Polyhedron,
    b: &Polyhedron,
    ca: ConvexRef<'_>,
    cb: ConvexRef<'_>,
    pose_ab: &Isometry,
    prediction: Real,
    hint: Option<Vec3>,
    warm: Option<&mut WarmSimplex>,
    out: &mut Vec<(Contact, FeatureId)>,
) -> Option<Separation> {
    if let (ConvexRef::Cuboid(x), ConvexRef::Cuboid(y)) = (ca, cb) {
        cuboid_cuboid_manifold_into(x, y, a, b, pose_ab, prediction, out);
        return None;
    }
    let near = match (ca, cb) {
        (ConvexRef::Cuboid(x), ConvexRef::ConvexHull(h)) => {
            large_box_hull(x, h, pose_ab, None, prediction, hint, out)
        }
        (ConvexRef::ConvexHull(h), ConvexRef::Cuboid(x)) => {
            // The hint turned into the box's frame, from the box towards the hull.
            let hint = hint.map(|n| -pose_ab.transform_vector(n));
            large_box_hull(
                x,
                h,
                &pose_ab.inverse(),
                Some(pose_ab),
                prediction,
                hint,
                out,
            )
        }
        _ => false,
    };
    if near {
        return None;
    }
    guided_general(a, b, ca, cb, pose_ab, prediction, hint, warm, out)
}

/// The separation of `ca` and `cb` (B at `pose_ab`) along `axis` (A's frame, from A towards
/// B), measured exactly, as a [`Separation`] when it exceeds `prediction`.
fn separation_along(
    ca: ConvexRef<'_>,
    cb: ConvexRef<'_>,
    pose_ab: &Isometry,
    axis: Vec3,
    prediction: Real,
) -> Option<Separation> {
    let u = axis.normalize_or_zero();
    if u == Vec3::ZERO || !u.is_finite() {
        return None;
    }
    let support_b = pose_ab.transform_point(cb.support(pose_ab.inverse_transform_vector(-u)));
    let distance = u.dot(support_b) - u.dot(ca.support(u));
    let b_box = cb.local_aabb();
    let reach = b_box.center().length() + b_box.half_extents().length();
    (distance > prediction && distance.is_finite() && reach.is_finite()).then_some(Separation {
        pose_ab: *pose_ab,
        axis: u,
        distance,
        reach,
    })
}

/// A box whose largest half extent exceeds this many times the hull's reach (radius about its
/// origin) is cut down to the hull's neighbourhood by `large_box_hull`.
pub const LARGE_BOX_RATIO: Real = 4.0;

/// Box–hull contact for a box much larger than the hull (a ground box), box `x` first, the
/// hull at `pose_xh` in the box's frame: the same manifold computed against the part of the
/// box near the hull, so that GJK/EPA and the guard see a Minkowski difference of the hull's
/// size instead of the box's (in f32, support points hundreds of metres away made EPA's
/// normal off by 1e-4 rad, the guard failed and the full separating-axis test ran: on
/// "1000 convex", 85 % of the guided path's fallbacks were ground pairs).
///
/// Why it is the same contact: let `K` be the hull's box in `x`'s frame grown by `m` on every
/// side, with `m` at least the prediction and at least the penetration depth, and `C = x ∩ K`.
/// `C ⊂ x`, so the hull's depth against `C` is at most its depth `d` against `x`; and a
/// translation `v` with `|v| < d` leaves the moved hull meeting `x` at some point `p`, which
/// lies within `|v| <= m` of the hull, so in `K`, so in `C`: the translations that separate
/// the hull from `C` within radius `m` are those that separate it from `x`, and the depth and
/// its direction are the same. Likewise closest points within the prediction. `d` is bounded
/// by the smallest push of the hull's box out through one of `x`'s faces. The faces clip to
/// the same points, since the hull lies inside `K`. (The same argument is behind Bullet's
/// and Jolt's clipping of large triangle meshes and heightfields to the query box.)
///
/// `swap_back` is the caller's `pose_ab` when the hull was its A (the contacts are turned
/// back into the hull's frame, hull first). `hint` seeds GJK (a guessed normal in the box's
/// frame, from the box towards the hull). Returns false (nothing written) when the box is
/// not large against the hull, or the cut box would be degenerate.
#[allow(clippy::too_many_arguments)]
fn large_box_hull(
    x: &Cuboid,
    h: &ConvexHull,
    pose_xh: &Isometry,
    swap_back: Option<&Isometry>,
    prediction: Real,
    hint: Option<Vec3>,
    out: &mut Vec<(Contact, FeatureId)>,
) -> bool {
    let he = x.half_extents();
    let hull_box = h.local_aabb();
    let reach = hull_box.center().length() + hull_box.half_extents().length();
    // (NaN sizes take the general path too.)
    if he.max_element() <= LARGE_BOX_RATIO * reach || !reach.is_finite() {
        return false;
    }
    let (lo, hi) = h.rotated_bounds(pose_xh.rotation);
    let (lo, hi) = (lo + pose_xh.translation, hi + pose_xh.translation);
    // Pushing the hull's box out through a face of `x` separates them: a bound of the depth.
    let push = (hi + he).min(he - lo).min_element();
    // Round-off slack: a larger `m` only keeps more of the box.
    let m = push.max(prediction).max(0.0) + 0.01 * reach;
    let (lo_c, hi_c) = ((lo - m).max(-he), (hi + m).min(he));
    if !(m.is_finite() && lo.is_finite() && hi.is_finite()) {
        return false;
    }
    if lo_c.cmpgt(hi_c).any() {
        // `x` does not meet the hull's box grown by `m`: farther apart than the prediction.
        return true;
    }
    let Ok(cut) = Cuboid::new(0.5 * (hi_c - lo_c)) else {
        return false;
    };
    let centre = 0.5 * (hi_c + lo_c);
    let pose_ch = Isometry::new(pose_xh.translation - centre, pose_xh.rotation);
    let start = out.len();
    guided_general(
        &Polyhedron::from_cuboid(&cut),
        &Polyhedron::from_hull(h),
        ConvexRef::Cuboid(&cut),
        ConvexRef::ConvexHull(h),
        &pose_ch,
        prediction,
        hint,
        // The cut box is a new shape at every call: no simplex of its own to keep.
        None,
        out,
    );
    for (k, _) in &mut out[start..] {
        k.point_a += centre;
        k.point_b += centre;
        if let Some(pose_ab) = swap_back {
            *k = k.swapped().transformed(pose_ab);
        }
    }
    true
}

/// The guided path for pairs other than box–box: GJK/EPA, the guard's check, then clipping;
/// a separation certificate when GJK finds the shapes apart (see
/// [`polyhedron_manifold_or_separation`]). `hint` seeds GJK (see
/// [`crate::query::contact_convex::contact_gjk_epa_unguarded_hinted`]).
#[allow(clippy::too_many_arguments)]
fn guided_general(
    a: &Polyhedron,
    b: &Polyhedron,
    ca: ConvexRef<'_>,
    cb: ConvexRef<'_>,
    pose_ab: &Isometry,
    prediction: Real,
    hint: Option<Vec3>,
    warm: Option<&mut WarmSimplex>,
    out: &mut Vec<(Contact, FeatureId)>,
) -> Option<Separation> {
    // GJK/EPA unguarded, then the guard's one check: the shapes' exact separation along the
    // returned normal must be the returned distance; when it is not (EPA on a degenerate
    // polytope, e.g. shapes touching within round-off), the full separating-axis test runs
    // instead (the guard's own fallback for polyhedra, here giving the whole manifold).
    let c = match contact_gjk_epa_unguarded_warm(ca, cb, pose_ab, prediction, hint, warm) {
        (GjkEpa::Beyond, axis) => return separation_along(ca, cb, pose_ab, axis, prediction),
        (GjkEpa::Separated(c) | GjkEpa::Penetrating(c), _) => c,
    };
    if !contact_is_consistent(ca, cb, pose_ab, &c) {
        // About half the failures on "1000 convex" are hulls touching within
        // round-off, where EPA's depth is off by a few times the guard's tolerance but its
        // normal is right: the contact re-measured exactly along that normal is kept when it
        // agrees with EPA's depth within `REMEASURE_SLACK` tolerances (when the faces
        // it selects clip to points, whose depths are exact); anything farther off still runs the full separating-axis test.
        // The re-measured witness is only a support point (possibly beside the contact
        // region), so it may not become a manifold point: when the clipping needs it, the
        // full separating-axis test runs after all.
        let start = out.len();
        if let Some(k) = remeasured_near(ca, cb, pose_ab, &c, REMEASURE_SLACK) {
            clip_guided(a, b, k, pose_ab, prediction, out);
            if out.len() > start && out[start..].iter().all(|(_, id)| *id != EPA_FEATURE) {
                return None;
            }
            out.truncate(start);
        }
        polyhedron_manifold_into(a, b, pose_ab, prediction, out);
        return None;
    }
    clip_guided(a, b, c, pose_ab, prediction, out);
    None
}

/// Box–box: the boxes' own separating-axis test (15 axes, exact) gives the normal; a face
/// axis is the reference face directly (its witness points are not needed when clipping
/// succeeds), an edge axis or a separated pair goes through [`clip_guided`] as for hulls.
fn cuboid_cuboid_manifold_into(
    x: &Cuboid,
    y: &Cuboid,
    a: &Polyhedron,
    b: &Polyhedron,
    pose_ab: &Isometry,
    prediction: Real,
    out: &mut Vec<(Contact, FeatureId)>,
) {
    let (depth, n, axis) = match cuboid_cuboid_sat(x, y, pose_ab, prediction) {
        CuboidSat::Final(None) => return,
        CuboidSat::Final(Some(c)) => return clip_guided(a, b, c, pose_ab, prediction, out),
        CuboidSat::Overlap {
            depth,
            normal,
            axis,
        } => (depth, normal, axis),
    };
    if -depth > prediction {
        return;
    }
    let start = out.len();
    match axis {
        Axis::FaceA(i) => {
            let fa = 2 * i + (n[i] < 0.0) as usize;
            clip_faces(a, fa, b, pose_ab, prediction, (fa as u32 & 0x3F) << 24, out);
        }
        Axis::FaceB(j) => {
            let nb = pose_ab.inverse_transform_vector(-n);
            let fb = 2 * j + (nb[j] < 0.0) as usize;
            let id_base = ((fb as u32 & 0x3F) | 0x40) << 24;
            let mut tmp: SmallVec<[(Contact, FeatureId); 16]> = SmallVec::new();
            clip_faces(b, fb, a, &pose_ab.inverse(), prediction, id_base, &mut tmp);
            out.extend(
                tmp.into_iter()
                    .map(|(c, id)| (c.swapped().transformed(pose_ab), id)),
            );
        }
        Axis::Edge(..) => {}
    }
    if out.len() == start {
        let c = cuboid_cuboid_witness(x, y, pose_ab, depth, n, axis);
        if matches!(axis, Axis::Edge(..)) && !witness_realises_depth(&c, x, y) {
            // The edges' closest points do not realise the overlap along the edge axis (the
            // lines' closest points fall outside the segments; the polytope oracle caught
            // points 0.5 mm off the box): the full separating-axis test rejects such a pair
            // and clips faces instead.
            polyhedron_manifold_into(a, b, pose_ab, prediction, out);
            return;
        }
        clip_guided(a, b, c, pose_ab, prediction, out);
    }
}

/// True when the witness points of `c` are `c.distance` apart along `c.normal` (as
/// [`super::polyhedron::edge_contact`] requires of an edge pair), up to round-off on
/// boxes `x` and `y`.
pub(super) fn witness_realises_depth(c: &Contact, x: &Cuboid, y: &Cuboid) -> bool {
    let scale = x.half_extents().max_element() + y.half_extents().max_element();
    let off = (c.point_b - c.point_a - c.normal * c.distance).length();
    off <= 1.0e-4 * scale + FACE_PREFERENCE * c.distance.abs()
}

/// Clips the faces selected by the contact `c` (within about 2.6° of a face normal of A or
/// B), else keeps `c` as the single point.
fn clip_guided(
    a: &Polyhedron,
    b: &Polyhedron,
    c: Contact,
    pose_ab: &Isometry,
    prediction: Real,
    out: &mut Vec<(Contact, FeatureId)>,
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
        let id_base = (fa as u32 & 0x3F) << 24;
        clip_faces(a, fa, b, pose_ab, prediction, id_base, out);
    } else if db >= FACE_COS {
        let id_base = ((fb as u32 & 0x3F) | 0x40) << 24;
        let mut tmp: SmallVec<[(Contact, FeatureId); 16]> = SmallVec::new();
        clip_faces(b, fb, a, &pose_ab.inverse(), prediction, id_base, &mut tmp);
        out.extend(
            tmp.into_iter()
                .map(|(c, id)| (c.swapped().transformed(pose_ab), id)),
        );
    }
    // Clipping keeps the incident face only; when the deepest point is elsewhere (deep or
    // lateral contacts) the GJK/EPA point joins, so the manifold's depth stays exact. A
    // manifold has one normal: when the GJK/EPA normal is not the reference face's (it
    // may differ by up to `FACE_COS`), the clipped points, too shallow to state the depth,
    // give way to the GJK/EPA point alone.
    let clipped_min = out[start..]
        .iter()
        .map(|(k, _)| k.distance)
        .fold(Real::INFINITY, Real::min);
    if out.len() == start || clipped_min > c.distance + 1.0e-3 * (1.0 + c.distance.abs()) {
        let same_normal = out[start..]
            .iter()
            .all(|(k, _)| (k.normal - c.normal).length() <= SAME_NORMAL);
        if !same_normal {
            out.truncate(start);
        }
        out.push((c, EPA_FEATURE));
    }
}

/// Normals closer than this (length of their difference, about 0.006 degrees) count as one
/// manifold normal.
const SAME_NORMAL: Real = 1.0e-4;
