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
use crate::math::{Isometry, Mat3, Real, Vec3, Vec3A, Vec3Swizzles, EPSILON};
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

/// The 15 axes of two boxes in A's frame, with B's axes the columns of its rotation `r`
/// (`r[j][i]` is component `i` of B's axis `j`): each axis gives the boxes' overlap along it
/// (negative: minus their separation) and the signed distance of B's centre along it.
///
/// The projections use the rotation's entries directly, as Gottschalk et al.'s OBB test
/// (and Bullet's `btBoxBoxDetector`, Box3D's `b3CollideBoxes`): on B's face axis `j`, B
/// projects to `hb[j]`; on the edge axis `e_i × b_j` (length `|e_i × b_j|`), A projects to
/// `ha[i1] |b_j[i2]| + ha[i2] |b_j[i1]|` and B to `hb[j1] |b_j2[i]| + hb[j2] |b_j1[i]|`
/// (the other two indices in cyclic order, since `b_j × b_j1 = b_j2`), then the overlap is
/// divided by the axis' length. Every function of this module goes through it, so they agree
/// bit for bit. (The explicit dot products with the normalised cross product cost three
/// times the instructions, and their round-off on nearly parallel edges was the larger.)
struct SatFrame {
    /// Half extents, as arrays: indexing a `Vec3` by a runtime index is a `match`, which
    /// cost a third of the test's instructions.
    ha: [Real; 3],
    hb: [Real; 3],
    /// B's centre in A's frame.
    t: [Real; 3],
    /// B's axes in A's frame (`r[j][i]`: component `i` of axis `j`), and as vectors.
    r: [[Real; 3]; 3],
    bx: [Vec3; 3],
    /// `|r[j][i]|`.
    abs_r: [[Real; 3]; 3],
}

impl SatFrame {
    #[inline(always)]
    fn new(ha: Vec3, hb: Vec3, pose_ab: &Isometry) -> Self {
        Self::with_rotation(ha, hb, &pose_ab.rotation_matrix(), pose_ab.translation)
    }

    /// [`SatFrame::new`] with B's rotation matrix in A's frame (`pose_ab.rotation_matrix()`)
    /// and centre `t` already at hand.
    #[inline(always)]
    fn with_rotation(ha: Vec3, hb: Vec3, rot: &Mat3, t: Vec3) -> Self {
        let bx = [rot.x_axis, rot.y_axis, rot.z_axis];
        SatFrame {
            ha: ha.to_array(),
            hb: hb.to_array(),
            t: t.to_array(),
            r: bx.map(|v| v.to_array()),
            bx,
            abs_r: bx.map(|v| v.abs().to_array()),
        }
    }

    /// B's centre in A's frame.
    #[inline(always)]
    fn t(&self) -> Vec3 {
        Vec3::from_array(self.t)
    }

    /// A's face axis `i`: `(overlap, distance)`.
    #[inline(always)]
    fn face_a(&self, i: usize) -> (Real, Real) {
        let (hb, ar) = (&self.hb, &self.abs_r);
        let rb = ar[0][i] * hb[0] + ar[1][i] * hb[1] + ar[2][i] * hb[2];
        let d = self.t[i];
        (self.ha[i] + rb - d.abs(), d)
    }

    /// B's face axis `j`: `(overlap, distance)`.
    #[inline(always)]
    fn face_b(&self, j: usize) -> (Real, Real) {
        let (ha, ar, r, t) = (&self.ha, &self.abs_r[j], &self.r[j], &self.t);
        let ra = ha[0] * ar[0] + ha[1] * ar[1] + ha[2] * ar[2];
        let d = r[0] * t[0] + r[1] * t[1] + r[2] * t[2];
        (ra + self.hb[j] - d.abs(), d)
    }

    /// The edge axis `e_i × b_j`: `(overlap, distance, length of the cross product)`, with
    /// the overlap and distance along the unit axis; `None` for (nearly) parallel edges,
    /// where the face axes decide.
    #[inline(always)]
    fn edge(&self, i: usize, j: usize) -> Option<(Real, Real, Real)> {
        let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
        let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
        let v = &self.r[j];
        let len = (v[i1] * v[i1] + v[i2] * v[i2]).sqrt();
        if len <= 1e3 * EPSILON {
            return None;
        }
        let (ha, hb, ar) = (&self.ha, &self.hb, &self.abs_r);
        let ra = ha[i1] * ar[j][i2] + ha[i2] * ar[j][i1];
        let rb = hb[j1] * ar[j2][i] + hb[j2] * ar[j1][i];
        let d = v[i1] * self.t[i2] - v[i2] * self.t[i1];
        let inv = 1.0 / len;
        Some(((ra + rb - d.abs()) * inv, d * inv, len))
    }

    /// The unit axis `e_i × b_j / len`.
    #[inline(always)]
    fn edge_axis(&self, i: usize, j: usize, len: Real) -> Vec3 {
        let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
        let v = &self.r[j];
        let mut c = [0.0; 3];
        c[i1] = -v[i2];
        c[i2] = v[i1];
        Vec3::from_array(c) / len
    }
}

/// `axis` pointing along `dist`'s sign (from A towards B).
#[inline(always)]
fn towards_b(axis: Vec3, dist: Real) -> Vec3 {
    if dist < 0.0 {
        -axis
    } else {
        axis
    }
}

/// The face axis (of A or B) of least overlap of two overlapping boxes, as
/// `(overlap, normal from A towards B, axis)`, with the projections of
/// [`cuboid_cuboid_sat`].
fn best_face_axis(a: &Cuboid, b: &Cuboid, pose_ab: &Isometry) -> (Real, Vec3, Axis) {
    let f = SatFrame::new(a.half_extents(), b.half_extents(), pose_ab);
    let mut best = (Real::INFINITY, Vec3::X, Axis::FaceA(0));
    for i in 0..3 {
        let (overlap, dist) = f.face_a(i);
        if overlap < best.0 {
            best = (overlap, towards_b(Vec3::AXES[i], dist), Axis::FaceA(i));
        }
    }
    for j in 0..3 {
        let (overlap, dist) = f.face_b(j);
        if overlap < best.0 {
            best = (overlap, towards_b(f.bx[j], dist), Axis::FaceB(j));
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
    let f = SatFrame::new(a.half_extents(), b.half_extents(), pose_ab);
    let t = f.t();
    let mut best: Option<(Real, Vec3, Axis)> = None;
    // The separating axis found, if any (its overlap is negative: minus the gap).
    let mut sep: Option<(Real, Vec3)> = None;
    // False (and `sep` set) when the axis separates the boxes.
    let mut test = |(overlap, dist): (Real, Real), axis: &dyn Fn() -> Vec3, kind: Axis| -> bool {
        if overlap < 0.0 {
            sep = Some((overlap, towards_b(axis(), dist)));
            return false;
        }
        if best.is_none_or(|(d, _, _)| overlap < d) {
            best = Some((overlap, towards_b(axis(), dist), kind));
        }
        true
    };
    let mut overlapping = true;
    for i in 0..3 {
        overlapping &= test(f.face_a(i), &|| Vec3::AXES[i], Axis::FaceA(i));
    }
    for j in 0..3 {
        overlapping &= overlapping && test(f.face_b(j), &|| f.bx[j], Axis::FaceB(j));
    }
    if overlapping {
        'edges: for i in 0..3 {
            for j in 0..3 {
                if let Some((overlap, dist, len)) = f.edge(i, j) {
                    if !test(
                        (overlap, dist),
                        &|| f.edge_axis(i, j, len),
                        Axis::Edge(i, j),
                    ) {
                        overlapping = false;
                        break 'edges;
                    }
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
    let rot = pose_ab.rotation_matrix();
    cuboid_cuboid_axis_or_separation_mat(a, b, &rot, pose_ab.translation, prediction)
}

/// [`cuboid_cuboid_axis_or_separation`] with B's rotation matrix in A's frame
/// (`pose_ab.rotation_matrix()`, bit for bit) and B's centre `t` (`pose_ab.translation`)
/// already at hand: the box–box manifold builds the matrix once and clips with it too.
///
/// The projections of [`SatFrame`] three axes at a time on SIMD lanes ([`Vec3A`]): A's three
/// face axes in one vector, B's in another, and the edge axes `e_i × b_j` of one `b_j` for
/// the three `e_i` in a third (lane `i`; the cyclic indices `i + 1`, `i + 2` become the
/// swizzles `yzx`, `zxy`). Each lane forms the same products and sums in the same order as
/// the scalar projection (no fused multiply–add, IEEE square root and division), so the
/// overlaps are the same bits. The axes are then taken in the scalar test's order: the
/// first that separates (a lane mask, its lowest bit) or the least overlap, the first on
/// ties (the lanes' minimum, then the first axis equal to it, which is what the scalar
/// test's strict `<` keeps), and only that axis' unit normal is built. The face axes decide
/// before the edge axes are projected, so a pair apart along a face axis costs only those.
/// (Bullet's `dBoxBox2` and parry's `cuboid_cuboid_find_local_separating_edge_twoway` also
/// test the edge axes without normalising the ones that cannot win; here every edge axis is
/// divided by its length, three at a time, to keep the scalar test's bits.)
#[inline]
pub(crate) fn cuboid_cuboid_axis_or_separation_mat(
    a: &Cuboid,
    b: &Cuboid,
    rot: &Mat3,
    t: Vec3,
    prediction: Real,
) -> Result<(Real, Vec3, Axis), (Real, Vec3)> {
    let (ha, hb) = (va(a.half_extents()), va(b.half_extents()));
    let hb_s = b.half_extents().to_array();
    let bx = [rot.x_axis, rot.y_axis, rot.z_axis];
    let c = bx.map(va);
    let ac = c.map(|v| v.abs());
    let ta = va(t);
    let lim = Vec3A::splat(-prediction);
    // Lanes that separate by more than the prediction, or are NaN.
    let sep = |o: Vec3A| (o.cmplt(lim) | o.cmpne(o)).bitmask();
    // A's face axis `i` (lane `i`): `ha[i] + Σ_j |r[j][i]| hb[j] - |t[i]|`.
    let over_a = (ha + (ac[0] * hb.x + ac[1] * hb.y + ac[2] * hb.z)) - ta.abs();
    // B's face axis `j` (lane `j`): `Σ_i ha[i] |r[j][i]| + hb[j] - |r[j] · t|`, on the
    // transposed matrix.
    let row = |v: [Vec3A; 3], k: usize| Vec3A::new(v[0][k], v[1][k], v[2][k]);
    let ra_b = row(ac, 0) * ha.x + row(ac, 1) * ha.y + row(ac, 2) * ha.z;
    let d_b = row(c, 0) * ta.x + row(c, 1) * ta.y + row(c, 2) * ta.z;
    let over_b = (ra_b + hb) - d_b.abs();
    let face_normal = |k: usize| {
        if k < 3 {
            towards_b(Vec3::AXES[k], t[k])
        } else {
            towards_b(bx[k - 3], d_b[k - 3])
        }
    };
    let face_kind = |k: usize| {
        if k < 3 {
            Axis::FaceA(k)
        } else {
            Axis::FaceB(k - 3)
        }
    };
    let over_f = |k: usize| {
        if k < 3 {
            over_a[k]
        } else {
            over_b[k - 3]
        }
    };
    let sep_f = sep(over_a) | sep(over_b) << 3;
    if sep_f != 0 {
        let k = sep_f.trailing_zeros() as usize;
        return Err((-over_f(k), face_normal(k)));
    }
    // The least face overlap, the first on ties; none below infinity keeps the scalar
    // test's initial `(∞, 0, FaceA(0))`.
    let mut best = Real::INFINITY;
    let mut best_k = usize::MAX;
    let m = over_a.min(over_b).min_element();
    if m < best {
        let eq =
            over_a.cmpeq(Vec3A::splat(m)).bitmask() | over_b.cmpeq(Vec3A::splat(m)).bitmask() << 3;
        best_k = eq.trailing_zeros() as usize;
        best = over_f(best_k);
    }
    // The edge axes `e_i × b_j`, lane `i` of `over_e[j]`; parallel edges (length at most
    // `1e3 ε`, not NaN) are masked out: the face axes decide.
    let mut over_e = [Vec3A::ZERO; 3];
    let mut dist_e = [Vec3A::ZERO; 3];
    let mut len_e = [Vec3A::ZERO; 3];
    let mut over_m = [Vec3A::ZERO; 3];
    let mut valid = [0u32; 3];
    let mut sep_e = [0u32; 3];
    let inf = Vec3A::splat(Real::INFINITY);
    let par = Vec3A::splat(1e3 * EPSILON);
    for j in 0..3 {
        let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
        let (v1, v2) = (c[j].yzx(), c[j].zxy());
        let l2 = v1 * v1 + v2 * v2;
        let len = Vec3A::new(l2.x.sqrt(), l2.y.sqrt(), l2.z.sqrt());
        let ra = ha.yzx() * ac[j].zxy() + ha.zxy() * ac[j].yzx();
        let rb = ac[j2] * hb_s[j1] + ac[j1] * hb_s[j2];
        let d = v1 * ta.zxy() - v2 * ta.yzx();
        let inv = Vec3A::ONE / len;
        let o = ((ra + rb) - d.abs()) * inv;
        let ok = !len.cmple(par);
        valid[j] = ok.bitmask() & 7;
        sep_e[j] = sep(o) & valid[j];
        over_e[j] = o;
        over_m[j] = Vec3A::select(ok, o, inf);
        dist_e[j] = d * inv;
        len_e[j] = len;
    }
    let edge_normal = |i: usize, j: usize| {
        let v = bx[j].to_array();
        let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
        let mut n = [0.0; 3];
        n[i1] = -v[i2];
        n[i2] = v[i1];
        towards_b(Vec3::from_array(n) / len_e[j][i], dist_e[j][i])
    };
    // The lane masks of the three `b_j` as one 9-bit mask in the scalar test's order
    // (`i` major: bit `3 i + j`), so its lowest bit is the first axis in that order.
    let in_order = |m: [u32; 3]| {
        let mut r = 0u32;
        for (j, mj) in m.into_iter().enumerate() {
            for i in 0..3 {
                r |= (mj >> i & 1) << (3 * i + j);
            }
        }
        r
    };
    // The first separating edge axis.
    let first_sep = in_order(sep_e);
    if first_sep != 0 {
        let k = first_sep.trailing_zeros() as usize;
        let (i, j) = (k / 3, k % 3);
        return Err((-over_e[j][i], edge_normal(i, j)));
    }
    let [m0, m1, m2] = over_m;
    let m = m0.min(m1).min(m2).min_element();
    if m < best {
        let ms = Vec3A::splat(m);
        let eq = in_order([
            m0.cmpeq(ms).bitmask(),
            m1.cmpeq(ms).bitmask(),
            m2.cmpeq(ms).bitmask(),
        ]);
        let k = eq.trailing_zeros() as usize;
        let (i, j) = (k / 3, k % 3);
        return Ok((over_e[j][i], edge_normal(i, j), Axis::Edge(i, j)));
    }
    if best_k == usize::MAX {
        return Ok((best, Vec3::ZERO, Axis::FaceA(0)));
    }
    Ok((best, face_normal(best_k), face_kind(best_k)))
}

/// A [`Vec3`] as a SIMD vector (the identity in f64, where `Vec3A` is `Vec3`).
#[inline(always)]
#[allow(clippy::useless_conversion)]
fn va(v: Vec3) -> Vec3A {
    v.into()
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
    cuboid_cuboid_witness_mat(a, b, pose_ab, &pose_ab.rotation_matrix(), depth, n, kind)
}

/// [`cuboid_cuboid_witness`] with B's rotation matrix in A's frame (`rot`, which must be
/// `pose_ab.rotation_matrix()`) already at hand, as the box–box manifold has it. The edge
/// case indexes arrays rather than `Vec3`s by a runtime axis (a `match` per access); the
/// arithmetic is the same, so the same bits.
pub(crate) fn cuboid_cuboid_witness_mat(
    a: &Cuboid,
    b: &Cuboid,
    pose_ab: &Isometry,
    rot: &Mat3,
    depth: Real,
    n: Vec3,
    kind: Axis,
) -> Contact {
    let (ha, hb) = (a.half_extents(), b.half_extents());
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
            let (ha, hb, ns) = (ha.to_array(), hb.to_array(), n.to_array());
            let mut ca = [0.0; 3];
            for k in 0..3 {
                if k != i {
                    ca[k] = if ns[k] < 0.0 { -ha[k] } else { ha[k] };
                }
            }
            let ca = Vec3::from_array(ca);
            let mut ea = [0.0; 3];
            ea[i] = ha[i];
            let ea = Vec3::from_array(ea);
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

#[cfg(test)]
#[path = "contact_cuboid_cuboid_tests.rs"]
mod tests;
