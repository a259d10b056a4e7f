//! Polyhedral manifolds guided by GJK/EPA (linear in the shapes' size, for boxes and hulls)
//! and the GJK/EPA contact of two polyhedron views, the fallback of the clipping paths.

use super::contact::FeatureId;
use super::polyhedron::{clip_faces, polyhedron_manifold_into, Polyhedron, FACE_PREFERENCE};
use crate::math::{Isometry, Real, Vec3};
use crate::query::contact_convex::{contact_gjk_epa_unguarded, GjkEpa};
use crate::query::contact_cuboid_cuboid::{
    cuboid_cuboid_sat, cuboid_cuboid_witness, Axis, CuboidSat,
};
use crate::query::epa::epa;
use crate::query::gjk::{gjk, GjkResult};
use crate::query::guard::{contact_is_consistent, remeasured_near};
use crate::query::support_adapters::{Support, Transformed};
use crate::query::Contact;
use crate::shape::{ConvexRef, Cuboid};
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
/// most anti-parallel face is clipped against it as in [`polyhedron_manifold`]; otherwise
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
    if let (ConvexRef::Cuboid(x), ConvexRef::Cuboid(y)) = (ca, cb) {
        cuboid_cuboid_manifold_into(x, y, a, b, pose_ab, prediction, out);
        return;
    }
    // GJK/EPA unguarded, then the guard's one check: the shapes' exact separation along the
    // returned normal must be the returned distance; when it is not (EPA on a degenerate
    // polytope, e.g. shapes touching within round-off), the full separating-axis test runs
    // instead (the guard's own fallback for polyhedra, here giving the whole manifold).
    let c = match contact_gjk_epa_unguarded(ca, cb, pose_ab, prediction) {
        GjkEpa::Beyond => return,
        GjkEpa::Separated(c) | GjkEpa::Penetrating(c) => c,
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
                return;
            }
            out.truncate(start);
        }
        return polyhedron_manifold_into(a, b, pose_ab, prediction, out);
    }
    clip_guided(a, b, c, pose_ab, prediction, out);
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
