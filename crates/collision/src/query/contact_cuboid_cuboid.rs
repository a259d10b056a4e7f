//! Box–box: the separating-axis test over the 15 axes (3 face normals of each box and the
//! 9 edge–edge cross products) of Gottschalk et al., "OBBTree" (SIGGRAPH 1996), as in
//! Bullet's `btBoxBoxDetector.cpp` and Box3D's `manifold.c`.
//!
//! When an axis separates, the exact distance comes from GJK (exact on polytopes). When
//! every axis overlaps, the axis of least overlap is the minimum translational distance of
//! the two boxes (for convex polytopes, the MTD direction is a face normal or an edge–edge
//! cross product), and the witness points are taken on the reference face (the incident
//! face of the other box clipped to it, its deepest point) or on the two edges.

use super::closest_points::closest_points_segment_segment;
use super::contact_convex::contact_gjk_epa;
use super::gjk::{gjk, GjkResult};
use super::guard::guarded_separated;
use super::result::Contact;
use super::support_adapters::{Core, Transformed};
use crate::math::{Isometry, Mat3, Real, Vec3, EPSILON};
use crate::shape::{ConvexRef, Cuboid};

/// The axis of least overlap of two overlapping boxes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Axis {
    /// Face normal `i` of A.
    FaceA(usize),
    /// Face normal `j` of B.
    FaceB(usize),
    /// Edge `i` of A crossed with edge `j` of B.
    Edge(usize, usize),
}

/// The outcome of the boxes' separating-axis test.
#[derive(Debug, Clone, Copy)]
pub enum CuboidSat {
    /// Apart or touching: the final contact (`None` beyond the prediction).
    Final(Option<Contact>),
    /// Overlapping: the least overlap `depth` along `normal` (from A to B) and its axis;
    /// [`cuboid_cuboid_witness`] gives the witness points.
    Overlap {
        /// Penetration depth (>= 0).
        depth: Real,
        /// Unit normal from A towards B, in A's frame.
        normal: Vec3,
        /// The axis that gave it.
        axis: Axis,
    },
}

/// Box A against box B.
pub fn contact_cuboid_cuboid(
    a: &Cuboid,
    b: &Cuboid,
    pose_ab: &Isometry,
    prediction: Real,
) -> Option<Contact> {
    match cuboid_cuboid_sat(a, b, pose_ab, prediction) {
        CuboidSat::Final(c) => c,
        CuboidSat::Overlap {
            depth,
            normal,
            axis,
        } => (-depth <= prediction).then(|| {
            let c = cuboid_cuboid_witness(a, b, pose_ab, depth, normal, axis);
            if matches!(axis, Axis::Edge(..)) && !edge_witness_realised(&c, a, b) {
                // Coplanar faces make the cross product of two in-plane edges the face
                // normal, which can win by round-off although those edges do not meet
                // (their closest points were 0.15 m apart): the best face axis instead.
                let (depth, normal, axis) = best_face_axis(a, b, pose_ab);
                cuboid_cuboid_witness(a, b, pose_ab, depth, normal, axis)
            } else {
                c
            }
        }),
    }
}

/// True when the edge witnesses of `c` are `c.distance` apart along `c.normal`, up to
/// round-off on the boxes' size (the closest points of the two supporting edges realise the
/// overlap only when the edges do meet there).
fn edge_witness_realised(c: &Contact, a: &Cuboid, b: &Cuboid) -> bool {
    let scale = a.half_extents().max_element() + b.half_extents().max_element();
    let off = (c.point_b - c.point_a - c.normal * c.distance).length();
    off <= 1.0e3 * EPSILON * scale + 1.0e-3 * c.distance.abs()
}

/// The face axis (of A or B) of least overlap of two overlapping boxes, as
/// `(overlap, normal from A towards B, axis)`, with the projections of
/// [`cuboid_cuboid_sat`].
fn best_face_axis(a: &Cuboid, b: &Cuboid, pose_ab: &Isometry) -> (Real, Vec3, Axis) {
    let (ha, hb) = (a.half_extents(), b.half_extents());
    let rot = pose_ab.rotation_matrix();
    let t = pose_ab.translation;
    let bx = [rot.x_axis, rot.y_axis, rot.z_axis];
    let mut best = (Real::INFINITY, Vec3::X, Axis::FaceA(0));
    for (axis, kind) in (0..3)
        .map(|i| (Vec3::AXES[i], Axis::FaceA(i)))
        .chain((0..3).map(|j| (bx[j], Axis::FaceB(j))))
    {
        let ra = ha.x * axis.x.abs() + ha.y * axis.y.abs() + ha.z * axis.z.abs();
        let rb = (0..3).map(|j| hb[j] * axis.dot(bx[j]).abs()).sum::<Real>();
        let dist = axis.dot(t);
        let overlap = ra + rb - dist.abs();
        if overlap < best.0 {
            best = (overlap, if dist < 0.0 { -axis } else { axis }, kind);
        }
    }
    best
}

/// The separating-axis test of [`contact_cuboid_cuboid`] without the witness points of an
/// overlap (a caller that clips faces does not need them).
pub fn cuboid_cuboid_sat(
    a: &Cuboid,
    b: &Cuboid,
    pose_ab: &Isometry,
    prediction: Real,
) -> CuboidSat {
    let ha = a.half_extents();
    let hb = b.half_extents();
    let rot = pose_ab.rotation_matrix();
    let t = pose_ab.translation;
    let bx = [rot.x_axis, rot.y_axis, rot.z_axis];
    let mut best: Option<(Real, Vec3, Axis)> = None;
    // The separating axis found, if any (its overlap is negative: minus the gap).
    let mut sep: Option<(Real, Vec3)> = None;
    let mut test = |axis: Vec3, kind: Axis| -> bool {
        let ra = ha.x * axis.x.abs() + ha.y * axis.y.abs() + ha.z * axis.z.abs();
        let rb = (0..3).map(|j| hb[j] * axis.dot(bx[j]).abs()).sum::<Real>();
        let dist = axis.dot(t);
        let overlap = ra + rb - dist.abs();
        if overlap < 0.0 {
            let n = if dist < 0.0 { -axis } else { axis };
            sep = Some((overlap, n));
            return false;
        }
        if best.is_none_or(|(d, _, _)| overlap < d) {
            let n = if dist < 0.0 { -axis } else { axis };
            best = Some((overlap, n, kind));
        }
        true
    };
    let mut overlapping = true;
    for i in 0..3 {
        let mut e = Vec3::ZERO;
        e[i] = 1.0;
        overlapping &= test(e, Axis::FaceA(i));
    }
    for (j, &axis) in bx.iter().enumerate() {
        overlapping &= overlapping && test(axis, Axis::FaceB(j));
    }
    if overlapping {
        for i in 0..3 {
            let mut e = Vec3::ZERO;
            e[i] = 1.0;
            for (j, &axis_b) in bx.iter().enumerate() {
                let c = e.cross(axis_b);
                let len = c.length();
                if len > 1e3 * EPSILON && !test(c / len, Axis::Edge(i, j)) {
                    overlapping = false;
                    break;
                }
            }
        }
    }
    if !overlapping {
        let Some((overlap, n)) = sep else {
            return CuboidSat::Final(contact_gjk_epa(
                ConvexRef::Cuboid(a),
                ConvexRef::Cuboid(b),
                pose_ab,
                prediction,
            ));
        };
        let core_b = Transformed::new(Core(ConvexRef::Cuboid(b)), pose_ab);
        return CuboidSat::Final(
            match gjk(&Core(ConvexRef::Cuboid(a)), &core_b, -t, prediction) {
                GjkResult::BeyondMaxDistance => None,
                GjkResult::Separated {
                    distance,
                    point_a,
                    point_b,
                } => {
                    let c = Contact {
                        distance,
                        point_a,
                        point_b,
                        normal: (point_b - point_a) / distance,
                    };
                    // f32 GJK against a much larger box stops early (see `query::guard`).
                    let c =
                        guarded_separated(ConvexRef::Cuboid(a), ConvexRef::Cuboid(b), pose_ab, c);
                    (c.distance <= prediction).then_some(c)
                }
                // A separating axis exists, yet GJK counts the boxes as overlapping: they touch
                // within round-off, where EPA's polytope is degenerate (it reported depths of
                // metres in the polytope oracle). GJK's witnesses are the touching points and
                // the separating axis is the normal.
                GjkResult::Overlapping(simplex) => {
                    let (point_a, _) = simplex.witnesses();
                    let gap = -overlap;
                    (gap <= prediction).then_some(Contact {
                        distance: gap,
                        point_a,
                        point_b: point_a + n * gap,
                        normal: n,
                    })
                }
            },
        );
    }
    let (depth, normal, axis) = best.expect("at least the face axes were tested");
    CuboidSat::Overlap {
        depth,
        normal,
        axis,
    }
}

/// The axis of least overlap of the two boxes over all 15 axes of [`cuboid_cuboid_sat`],
/// as `(overlap, normal, axis)` with the unit `normal` from A towards B in A's frame, or
/// `None` when one axis separates the boxes by more than `prediction`.
///
/// Unlike [`cuboid_cuboid_sat`], a separated pair within `prediction` is not handed to GJK:
/// `overlap` is then negative, minus the largest separation over the 15 axes. That is a
/// lower bound of the boxes' distance (exact when the closest features are a face and what
/// lies over it, or two edges), which is what a speculative contact needs: box–box manifolds
/// clip faces along this axis, as Box3D's `b3CollideBoxes` and parry's
/// `contact_manifold_cuboid_cuboid` do. For an overlapping pair the result is bit for bit
/// the overlap branch of [`cuboid_cuboid_sat`] (same axes, same order, first on ties).
pub fn cuboid_cuboid_axis(
    a: &Cuboid,
    b: &Cuboid,
    pose_ab: &Isometry,
    prediction: Real,
) -> Option<(Real, Vec3, Axis)> {
    cuboid_cuboid_axis_or_separation(a, b, pose_ab, prediction).ok()
}

/// [`cuboid_cuboid_axis`], telling why a pair was rejected: `Err((separation, axis))` with
/// the first axis found to separate the boxes by more than `prediction` (unit, from A
/// towards B in A's frame) and the separation along it (NaN for non-finite input). The
/// persistent manifold keeps it as a certificate that the pair is apart
/// ([`crate::narrowphase::manifold::Separation`]).
pub fn cuboid_cuboid_axis_or_separation(
    a: &Cuboid,
    b: &Cuboid,
    pose_ab: &Isometry,
    prediction: Real,
) -> Result<(Real, Vec3, Axis), (Real, Vec3)> {
    let ha = a.half_extents();
    let hb = b.half_extents();
    let rot = pose_ab.rotation_matrix();
    let t = pose_ab.translation;
    let bx = [rot.x_axis, rot.y_axis, rot.z_axis];
    let abs_b = [bx[0].abs(), bx[1].abs(), bx[2].abs()];
    let mut best = (Real::INFINITY, Vec3::ZERO, Axis::FaceA(0));
    let mut apart = (Real::NAN, Vec3::ZERO);
    // False when `axis` separates the boxes by more than the prediction.
    let mut consider = |overlap: Real, dist: Real, axis: Vec3, kind: Axis| -> bool {
        if overlap < -prediction || overlap.is_nan() {
            apart = (-overlap, if dist < 0.0 { -axis } else { axis });
            return false;
        }
        if overlap < best.0 {
            best = (overlap, if dist < 0.0 { -axis } else { axis }, kind);
        }
        true
    };
    // A's faces: B projects on e_i as Σ_j hb_j |b_j · e_i|.
    let rb_faces = abs_b[0] * hb.x + abs_b[1] * hb.y + abs_b[2] * hb.z;
    for i in 0..3 {
        let mut e = Vec3::ZERO;
        e[i] = 1.0;
        if !consider(ha[i] + rb_faces[i] - t[i].abs(), t[i], e, Axis::FaceA(i)) {
            return Err(apart);
        }
    }
    // B's faces and the edge pairs: B's projection summed over its three axes, as in
    // `cuboid_cuboid_sat` (so that both give the same bits).
    let rb_of = |axis: Vec3| (0..3).map(|k| hb[k] * axis.dot(bx[k]).abs()).sum::<Real>();
    for (j, &axis) in bx.iter().enumerate() {
        let ra = ha.x * abs_b[j].x + ha.y * abs_b[j].y + ha.z * abs_b[j].z;
        let dist = axis.dot(t);
        if !consider(ra + rb_of(axis) - dist.abs(), dist, axis, Axis::FaceB(j)) {
            return Err(apart);
        }
    }
    for i in 0..3 {
        let mut e = Vec3::ZERO;
        e[i] = 1.0;
        for (j, &axis_b) in bx.iter().enumerate() {
            let c = e.cross(axis_b);
            let len = c.length();
            // Parallel edges: the face axes decide.
            if len <= 1e3 * EPSILON {
                continue;
            }
            let axis = c / len;
            let ra = ha.x * axis.x.abs() + ha.y * axis.y.abs() + ha.z * axis.z.abs();
            let dist = axis.dot(t);
            if !consider(ra + rb_of(axis) - dist.abs(), dist, axis, Axis::Edge(i, j)) {
                return Err(apart);
            }
        }
    }
    Ok(best)
}

/// The witness points of an overlap found by [`cuboid_cuboid_sat`].
pub fn cuboid_cuboid_witness(
    a: &Cuboid,
    b: &Cuboid,
    pose_ab: &Isometry,
    depth: Real,
    n: Vec3,
    kind: Axis,
) -> Contact {
    let (ha, hb) = (a.half_extents(), b.half_extents());
    let rot = pose_ab.rotation_matrix();
    let t = pose_ab.translation;
    let bx = [rot.x_axis, rot.y_axis, rot.z_axis];
    match kind {
        Axis::FaceA(i) => {
            let (pa, pb) = face_witness(ha, hb, &Mat3::from_cols(bx[0], bx[1], bx[2]), t, i, n);
            Contact {
                distance: -depth,
                point_a: pa,
                point_b: pb,
                normal: n,
            }
        }
        Axis::FaceB(j) => {
            // B is the reference: work in B's frame with A as the incident box.
            let pose_ba = pose_ab.inverse();
            let rba = pose_ba.rotation_matrix();
            let n_b = pose_ab.inverse_transform_vector(-n);
            let (pb, pa) = face_witness(hb, ha, &rba, pose_ba.translation, j, n_b);
            Contact {
                distance: -depth,
                point_a: pose_ab.transform_point(pa),
                point_b: pose_ab.transform_point(pb),
                normal: n,
            }
        }
        Axis::Edge(i, j) => {
            // Edge of A: the support edge along e_i in +n; edge of B along b_j in -n.
            let mut ca = Vec3::ZERO;
            for k in 0..3 {
                if k != i {
                    ca[k] = if n[k] < 0.0 { -ha[k] } else { ha[k] };
                }
            }
            let mut ea = Vec3::ZERO;
            ea[i] = ha[i];
            let mut cb = t;
            for l in 0..3 {
                if l != j {
                    let s = if n.dot(bx[l]) > 0.0 { -1.0 } else { 1.0 };
                    cb += bx[l] * (s * hb[l]);
                }
            }
            let eb = bx[j] * hb[j];
            let (pa, pb) = closest_points_segment_segment(ca - ea, ca + ea, cb - eb, cb + eb);
            Contact {
                distance: -depth,
                point_a: pa,
                point_b: pb,
                normal: n,
            }
        }
    }
}

/// Witness points for a face axis of the reference box (half extents `hr`, at the origin)
/// against the incident box (half extents `hi`, axes the columns of `rot`, centre `t`):
/// the incident face clipped to the reference face, its deepest point, and that point
/// projected on the reference face. `n` is the reference face normal (towards the incident
/// box), along axis `i`.
fn face_witness(hr: Vec3, hi: Vec3, rot: &Mat3, t: Vec3, i: usize, n: Vec3) -> (Vec3, Vec3) {
    let axes = [rot.x_axis, rot.y_axis, rot.z_axis];
    // Incident face: the face of the incident box most anti-parallel to n.
    let mut j = 0;
    for k in 1..3 {
        if axes[k].dot(n).abs() > axes[j].dot(n).abs() {
            j = k;
        }
    }
    let m = if axes[j].dot(n) > 0.0 {
        -axes[j]
    } else {
        axes[j]
    };
    let (k1, k2) = ((j + 1) % 3, (j + 2) % 3);
    let centre = t + m * hi[j];
    let (u, v) = (axes[k1] * hi[k1], axes[k2] * hi[k2]);
    let mut poly: Poly = smallvec::smallvec![
        centre + u + v,
        centre - u + v,
        centre - u - v,
        centre + u - v,
    ];
    for k in 0..3 {
        if k == i {
            continue;
        }
        for sign in [1.0, -1.0] {
            poly = clip(&poly, k, sign, hr[k]);
        }
    }
    let deepest = poly
        .into_iter()
        .min_by(|x, y| x.dot(n).total_cmp(&y.dot(n)))
        .unwrap_or_else(|| {
            // Clipping lost everything to round-off: the incident box's support point.
            t + axes.iter().enumerate().fold(Vec3::ZERO, |acc, (l, ax)| {
                let s = if ax.dot(n) > 0.0 { -1.0 } else { 1.0 };
                acc + *ax * (s * hi[l])
            })
        });
    let face_offset = hr[i];
    let point_ref = deepest + n * (face_offset - n.dot(deepest));
    (point_ref, deepest)
}

/// A clipped face: at most 8 corners (a quadrilateral clipped by four planes), on the stack.
type Poly = smallvec::SmallVec<[Vec3; 8]>;

/// Sutherland–Hodgman clip of `poly` to `sign * x[k] <= limit`.
fn clip(poly: &[Vec3], k: usize, sign: Real, limit: Real) -> Poly {
    let mut out = Poly::new();
    for idx in 0..poly.len() {
        let p = poly[idx];
        let q = poly[(idx + 1) % poly.len()];
        let dp = sign * p[k] - limit;
        let dq = sign * q[k] - limit;
        if dp <= 0.0 {
            out.push(p);
        }
        if (dp < 0.0 && dq > 0.0) || (dp > 0.0 && dq < 0.0) {
            out.push(p + (q - p) * (dp / (dp - dq)));
        }
    }
    out
}
