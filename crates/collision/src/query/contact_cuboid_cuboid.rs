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
/// The nine edge axes are written out (a macro per `(i, j)`), so their cyclic indices
/// `(i + 1) % 3`, `(i + 2) % 3` are constants rather than a runtime remainder per axis; same
/// axes, same order, same arithmetic, so the same bits as the loop.
#[inline]
pub(crate) fn cuboid_cuboid_axis_or_separation_mat(
    a: &Cuboid,
    b: &Cuboid,
    rot: &Mat3,
    t: Vec3,
    prediction: Real,
) -> Result<(Real, Vec3, Axis), (Real, Vec3)> {
    let f = SatFrame::with_rotation(a.half_extents(), b.half_extents(), rot, t);
    let mut best = (Real::INFINITY, Vec3::ZERO, Axis::FaceA(0));
    // `Err` with the separation and the unit axis (from A towards B) when the axis separates
    // the boxes by more than the prediction; the axis is only built when it is kept.
    macro_rules! consider {
        ($found:expr, $axis:expr, $kind:expr) => {{
            let (overlap, dist): (Real, Real) = $found;
            if overlap < -prediction || overlap.is_nan() {
                return Err((-overlap, towards_b($axis, dist)));
            }
            if overlap < best.0 {
                best = (overlap, towards_b($axis, dist), $kind);
            }
        }};
    }
    for i in 0..3 {
        consider!(f.face_a(i), Vec3::AXES[i], Axis::FaceA(i));
    }
    for j in 0..3 {
        consider!(f.face_b(j), f.bx[j], Axis::FaceB(j));
    }
    // Parallel edges (`None`): the face axes decide.
    macro_rules! edge {
        ($i:literal, $j:literal) => {
            if let Some((overlap, dist, len)) = f.edge($i, $j) {
                consider!(
                    (overlap, dist),
                    f.edge_axis($i, $j, len),
                    Axis::Edge($i, $j)
                );
            }
        };
    }
    edge!(0, 0);
    edge!(0, 1);
    edge!(0, 2);
    edge!(1, 0);
    edge!(1, 1);
    edge!(1, 2);
    edge!(2, 0);
    edge!(2, 1);
    edge!(2, 2);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{consts::FRAC_PI_4, Quat};

    /// The separating-axis test as it was, with the edge axes in a loop (runtime cyclic
    /// indices) and the pose's own matrix: the oracle of the unrolled test.
    fn axis_reference(
        a: &Cuboid,
        b: &Cuboid,
        pose_ab: &Isometry,
        prediction: Real,
    ) -> Result<(Real, Vec3, Axis), (Real, Vec3)> {
        let f = SatFrame::new(a.half_extents(), b.half_extents(), pose_ab);
        let mut best = (Real::INFINITY, Vec3::ZERO, Axis::FaceA(0));
        let mut consider = |(overlap, dist): (Real, Real),
                            axis: &dyn Fn() -> Vec3,
                            kind: Axis|
         -> Result<(), (Real, Vec3)> {
            if overlap < -prediction || overlap.is_nan() {
                return Err((-overlap, towards_b(axis(), dist)));
            }
            if overlap < best.0 {
                best = (overlap, towards_b(axis(), dist), kind);
            }
            Ok(())
        };
        for i in 0..3 {
            consider(f.face_a(i), &|| Vec3::AXES[i], Axis::FaceA(i))?;
        }
        for j in 0..3 {
            consider(f.face_b(j), &|| f.bx[j], Axis::FaceB(j))?;
        }
        for i in 0..3 {
            for j in 0..3 {
                if let Some((overlap, dist, len)) = f.edge(i, j) {
                    consider(
                        (overlap, dist),
                        &|| f.edge_axis(i, j, len),
                        Axis::Edge(i, j),
                    )?;
                }
            }
        }
        Ok(best)
    }

    /// The unrolled test gives the loop's result bit for bit (axis, overlap, normal, or the
    /// separating axis and gap): overlapping, touching, apart within and beyond the
    /// prediction, parallel faces (identity and 90° turns, where edge axes vanish), 45°,
    /// edge–edge crossings, thin and zero-thickness boxes, 1 km from the origin, NaN.
    #[test]
    fn unrolled_sat_matches_the_loop_bit_for_bit() {
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut rnd = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as Real / (1u64 << 53) as Real
        };
        let bits = |v: Vec3| v.to_array().map(Real::to_bits);
        let (mut overlaps, mut aparts, mut edges) = (0, 0, 0);
        for case in 0..30000 {
            let mut h = || Vec3::new(0.05 + rnd(), 0.05 + rnd(), 0.05 + rnd());
            let (ha, mut hb) = (h(), h());
            if case % 13 == 0 {
                hb.z = 1e-6; // (nearly) zero thickness
            } else if case % 13 == 1 {
                hb.y = 1e-3; // thin plate
            }
            let rot = match case % 6 {
                0 => Quat::IDENTITY,
                1 => Quat::from_rotation_z(crate::math::consts::FRAC_PI_2),
                2 => Quat::from_rotation_y(FRAC_PI_4),
                3 => Quat::from_rotation_x(FRAC_PI_4) * Quat::from_rotation_y(FRAC_PI_4),
                4 => Quat::from_rotation_y(1e-5 * rnd()),
                _ => Quat::from_axis_angle(
                    Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5).normalize(),
                    rnd() * 6.0,
                ),
            };
            let mut t = Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * 4.0;
            if case % 7 == 0 {
                // Face to face, exactly touching along x.
                t.x = ha.x + hb.x;
            }
            let (a, b) = (Cuboid::new(ha).unwrap(), Cuboid::new(hb).unwrap());
            let mut pose = Isometry::new(t, rot);
            if case % 5 == 0 {
                // 1 km out: the relative pose of two world poses there (with its round-off).
                let wa = Isometry::new(
                    Vec3::new(1000.0, -1000.0, 1000.0),
                    Quat::from_rotation_y(0.3 * rnd()),
                );
                pose = wa.inv_mul(&wa.mul(&pose));
            }
            let rot_m = pose.rotation_matrix();
            for prediction in [0.0 as Real, 0.02, 5.0] {
                let want = axis_reference(&a, &b, &pose, prediction);
                let got = cuboid_cuboid_axis_or_separation_mat(
                    &a,
                    &b,
                    &rot_m,
                    pose.translation,
                    prediction,
                );
                match (got, want) {
                    (Ok((go, gn, gk)), Ok((wo, wn, wk))) => {
                        assert_eq!((go.to_bits(), bits(gn), gk), (wo.to_bits(), bits(wn), wk));
                        overlaps += 1;
                        edges += matches!(gk, Axis::Edge(..)) as usize;
                    }
                    (Err((gd, gn)), Err((wd, wn))) => {
                        assert_eq!((gd.to_bits(), bits(gn)), (wd.to_bits(), bits(wn)));
                        aparts += 1;
                    }
                    (g, w) => panic!("case {case}: {g:?} vs {w:?}"),
                }
                let public = cuboid_cuboid_axis_or_separation(&a, &b, &pose, prediction);
                assert_eq!(format!("{public:?}"), format!("{want:?}"));
            }
        }
        // The paths the test means to cover do occur.
        assert!(
            overlaps > 1000 && aparts > 1000 && edges > 100,
            "{overlaps} {aparts} {edges}"
        );
        // Non-finite input is rejected the same way.
        let (a, b) = (
            Cuboid::new(Vec3::ONE).unwrap(),
            Cuboid::new(Vec3::ONE).unwrap(),
        );
        let pose = Isometry::new(Vec3::new(Real::NAN, 0.0, 0.0), Quat::IDENTITY);
        let got = cuboid_cuboid_axis_or_separation_mat(
            &a,
            &b,
            &pose.rotation_matrix(),
            pose.translation,
            0.02,
        );
        assert!(matches!(got, Err((d, _)) if d.is_nan()));
        assert!(matches!(axis_reference(&a, &b, &pose, 0.02), Err((d, _)) if d.is_nan()));
    }
}
