//! A mesh triangle against a convex hull: the separating-axis test of [`super::polyhedron`]
//! specialised to a flat triangle A (two faces `±n`, three edges) and a solid hull B placed
//! once per pair in the mesh's frame ([`PosedPolyhedron`], built without edge arcs).
//!
//! It gives the same separations, features and contacts as `polyhedron_manifold_posed`, bit
//! for bit (the tests compare them), with less work per triangle:
//!
//! - the triangle's two faces take one pass over the hull's vertices (the minimum and the
//!   maximum along `n`) instead of two;
//! - edge pairs: a hull edge's Gauss-map arc (between its face normals `n0`, `n1`) must
//!   cross the great circle perpendicular to the triangle edge `d_A` (Gregorius, "The
//!   Separating Axis Test between Convex Polyhedra", GDC 2013; the same sign test as
//!   [`super::polyhedron`]'s edge query). Where it crosses, the crossing point is
//!   `m = a0·n1 − a1·n0` (for `a_k = n_k · d_A`, `a0 > 0 > a1`, and the mirror case), so the
//!   pair's axis from A to B is `−m` up to scale. It must lie on the triangle edge's half
//!   circle, i.e. on the side of the edge's outward in-plane normal `o`: pairs with
//!   `m · o` clearly positive (beyond a 0.05 relative margin, far above the round-off of the
//!   hull's normals) are dropped with a few products and no square root, cross product or
//!   hull arc. The survivors take the exact test of the general path, with the hull edge's
//!   arc built on the fly, so the hull's arcs (one cross product triple per edge and pair)
//!   are never built.
//!
//! Jolt (`CollideConvexVsTriangles`) and Box3D (`b3CollideHullAndTriangle`) also treat the
//! triangle as a two-sided face with three edges whose arcs are half circles; the
//! crossing-point test is the closed form of Gregorius' `IsMinkowskiFace` for such an arc.

use super::contact::ContactList;
use super::polyhedron::{manifold_from_sat, Polyhedron, PosedPolyhedron, PARALLEL_SIN};
use super::polyhedron_sat::max_dot;
use crate::math::{Isometry, Real, Vec3};
use smallvec::SmallVec;

/// Relative margin of the crossing-point prefilter: a pair is dropped early only when
/// `m · o > PREFILTER_SIN · |m| · |o|` (its axis more than about 3° on the wrong side of the
/// triangle edge's half circle); nearer pairs take the exact test.
const PREFILTER_SIN: Real = 0.05;

/// Four lanes of [`Real`] (`wide`'s `f32x4`, or `f64x4` in the f64 build).
#[cfg(not(feature = "f64"))]
type W = wide::f32x4;
/// Four lanes of [`Real`] (`wide`'s `f32x4`, or `f64x4` in the f64 build).
#[cfg(feature = "f64")]
type W = wide::f64x4;

/// Hulls with at most this many faces take the four-lane face and sign passes.
const LANE_FACES: usize = 64;
/// ... and at most this many edges (a closed polyhedron with 64 faces has at most 186).
const LANE_EDGES: usize = 192;

/// Face indices of a lane hull are below [`LANE_FACES`], a power of two: the edge query
/// masks them with `FACE_MASK` (a no-op on them) so the compiler drops the bounds checks
/// of the per-face rows.
const FACE_MASK: usize = LANE_FACES - 1;
/// The crossing lists are [`LIST_LEN`] long, a power of two above [`LANE_EDGES`]: their
/// lengths (at most the hull's edge count) are masked with `LIST_LEN - 1` (a no-op) so the
/// compiler drops the bounds checks of the appends.
const LIST_LEN: usize = 256;
const _: () = assert!(LANE_FACES.is_power_of_two() && LIST_LEN.is_power_of_two());
const _: () = assert!(LIST_LEN > LANE_EDGES && LANE_EDGES <= 1 + u8::MAX as usize);

/// Four face planes of the placed hull, one per lane (normal `x`, `y`, `z`, offset). The
/// last block is padded with zero normals and an infinite offset: a padding face separates
/// by `-inf` (never the best) and has no sign.
#[derive(Debug, Clone, Copy)]
struct FaceBlock {
    x: W,
    y: W,
    z: W,
    off: W,
}

/// `SPREAD[m]` has bit `l` of `m` in bit 0 of byte `l`: four lanes' comparison bits become
/// four faces' sign bytes with a shift and an OR.
const SPREAD: [u32; 16] = {
    let mut t = [0u32; 16];
    let mut m = 0;
    while m < 16 {
        let mut l = 0;
        while l < 4 {
            t[m] |= (((m >> l) & 1) as u32) << (8 * l);
            l += 1;
        }
        m += 1;
    }
    t
};

/// Scratch of [`triangle_hull_manifold`], bound to one placed hull ([`EdgeScratch::new`])
/// and reused across the triangles of a pair.
///
/// Hulls of up to [`LANE_FACES`] faces and [`LANE_EDGES`] edges keep their placed face
/// planes as blocks of four lanes: the hull-face pass and the edge query's dots and signs
/// run four faces at a time, with the products and sums in `Vec3::dot`'s order and the
/// comparisons of the scalar code, so every value and decision is the scalar one. The edge
/// query keeps per face its normal's dots with the three triangle edges (one row per edge)
/// and their signs (bit `k` set when dot `k` is positive, bit `k + 3` when negative), and
/// per triangle edge the hull edges whose arcs cross its great circle, in hull-edge order.
/// Larger hulls take the scalar passes (`dots_aos`, `crossing`).
///
/// The placed vertices are kept as blocks of four lanes too (`verts`, the last block padded
/// with copies of the first vertex, which change no minimum or maximum), for the triangle's
/// two faces: the dots with the triangle's normal four vertices at a time, in `Vec3::dot`'s
/// order, and the same strict comparisons as a scalar scan, so the minimum and maximum are
/// the scalar ones (up to the sign of an exact zero; NaN dots are skipped alike).
pub(crate) struct EdgeScratch {
    blocks: SmallVec<[FaceBlock; 16]>,
    verts: SmallVec<[[W; 3]; 16]>,
    dots: [[Real; LANE_FACES]; 3],
    odots: [[Real; LANE_FACES]; 3],
    signs: [u8; LANE_FACES],
    lists: [[u8; LIST_LEN]; 3],
    dots_aos: SmallVec<[[Real; 3]; 64]>,
    crossing: SmallVec<[(u32, u8); 64]>,
}

impl EdgeScratch {
    /// The scratch for hull `b` placed by `posed` (see [`EdgeScratch::set_hull`]; tests).
    #[cfg(test)]
    pub(crate) fn new(b: &Polyhedron, posed: &PosedPolyhedron) -> EdgeScratch {
        let mut s = EdgeScratch::empty();
        s.set_hull(b, posed);
        s
    }

    /// A scratch bound to no hull (the scalar passes until [`EdgeScratch::set_hull`]).
    fn empty() -> EdgeScratch {
        EdgeScratch {
            blocks: SmallVec::new(),
            verts: SmallVec::new(),
            dots: [[0.0; LANE_FACES]; 3],
            odots: [[0.0; LANE_FACES]; 3],
            signs: [0; LANE_FACES],
            lists: [[0; LIST_LEN]; 3],
            dots_aos: SmallVec::new(),
            crossing: SmallVec::new(),
        }
    }

    /// Binds the scratch to hull `b` placed by `posed`: its face planes in lanes when it has
    /// at most [`LANE_FACES`] faces and [`LANE_EDGES`] edges.
    fn set_hull(&mut self, b: &Polyhedron, posed: &PosedPolyhedron) {
        let (nb, ob) = (&posed.normals[..], &posed.offsets[..]);
        self.verts.clear();
        if let Some(&first) = posed.vertices.first() {
            for v in posed.vertices.chunks(4) {
                let ls = [0, 1, 2, 3].map(|l| v.get(l).copied().unwrap_or(first));
                self.verts.push([
                    W::new(ls.map(|v| v.x)),
                    W::new(ls.map(|v| v.y)),
                    W::new(ls.map(|v| v.z)),
                ]);
            }
        }
        self.blocks.clear();
        if nb.len() <= LANE_FACES && b.edge_faces().len() <= LANE_EDGES {
            debug_assert!(b
                .edge_faces()
                .iter()
                .flatten()
                .all(|&f| (f as usize) < nb.len()));
            for (n, off) in nb.chunks(4).zip(ob.chunks(4)) {
                let lane = |l: usize| n.get(l).copied().unwrap_or(Vec3::ZERO);
                let off = |l: usize| off.get(l).copied().unwrap_or(Real::INFINITY);
                let ls = [lane(0), lane(1), lane(2), lane(3)];
                self.blocks.push(FaceBlock {
                    x: W::new(ls.map(|v| v.x)),
                    y: W::new(ls.map(|v| v.y)),
                    z: W::new(ls.map(|v| v.z)),
                    off: W::new([off(0), off(1), off(2), off(3)]),
                });
            }
        }
    }
}

/// A hull placed in the mesh's frame ([`fill_posed_hull`]) with its [`EdgeScratch`], refilled in
/// place for each pair: together they hold several kB, and building them per pair and
/// moving them into place cost more in `memcpy` than the lanes saved. One per thread in
/// [`super::mesh::mesh_hull_contacts`].
pub(crate) struct PlacedHull {
    /// The hull's vertices and face planes in the mesh's frame.
    pub(crate) posed: PosedPolyhedron,
    /// The scratch bound to `posed`.
    pub(crate) scratch: EdgeScratch,
}

impl PlacedHull {
    /// An empty placement (place a hull with [`PlacedHull::place`] before use).
    pub(crate) fn new() -> PlacedHull {
        PlacedHull {
            posed: PosedPolyhedron {
                vertices: SmallVec::new(),
                normals: SmallVec::new(),
                offsets: SmallVec::new(),
                arcs: SmallVec::new(),
            },
            scratch: EdgeScratch::empty(),
        }
    }

    /// Places hull `b` by `pose_ab` ([`fill_posed_hull`]) and binds the scratch to it.
    pub(crate) fn place(&mut self, b: &Polyhedron, pose_ab: &Isometry) {
        fill_posed_hull(b, pose_ab, &mut self.posed);
        self.scratch.set_hull(b, &self.posed);
    }
}

/// [`fill_posed_hull`] into a new placement (tests).
#[cfg(test)]
pub(crate) fn posed_hull(b: &Polyhedron, pose_ab: &Isometry) -> PosedPolyhedron {
    let mut p = PlacedHull::new().posed;
    fill_posed_hull(b, pose_ab, &mut p);
    p
}

/// Hull `b` placed in the mesh's frame by `pose_ab` for [`triangle_hull_manifold`]: its
/// vertices, face normals and plane offsets (no edge arcs), rotated by the pose's matrix
/// (9 products a vector instead of the quaternion's ~20; `PosedPolyhedron::new` rotates by
/// the quaternion, so the two agree to round-off, not bit for bit).
///
/// Written into `out`, reusing its buffers.
fn fill_posed_hull(b: &Polyhedron, pose_ab: &Isometry, out: &mut PosedPolyhedron) {
    let m = pose_ab.rotation_matrix();
    let t = pose_ab.translation;
    out.vertices.clear();
    out.vertices.extend(b.vertices().iter().map(|v| m * *v + t));
    out.normals.clear();
    out.normals.extend(b.faces().iter().map(|f| m * f.normal));
    out.offsets.clear();
    out.offsets.extend(
        b.faces()
            .iter()
            .zip(&out.normals)
            .map(|(f, n)| f.offset + n.dot(t)),
    );
    out.arcs.clear();
}

/// Contacts of triangle A (`a`, a view built by [`Polyhedron::from_triangle`]) against hull
/// B (`b`, placed in A's frame by `posed`, arcs not needed), in A's frame with the query
/// convention, appended to `out`: the same as `polyhedron_manifold_posed(a, b, posed, ..)`.
pub(crate) fn triangle_hull_manifold(
    a: &Polyhedron,
    b: &Polyhedron,
    posed: &PosedPolyhedron,
    pose_ab: &Isometry,
    prediction: Real,
    scratch: &mut EdgeScratch,
    out: &mut ContactList,
) {
    debug_assert!(a.flat && !b.flat && a.faces().len() == 2);
    let (vb, nb, ob) = (&posed.vertices[..], &posed.normals[..], &posed.offsets[..]);
    // The triangle's faces `n · x <= off` and `-n · x <= -off` in one pass: the
    // separations `min(n · v) - off` and `off - max(n · v)`, exactly those of the general
    // face query (negation is exact).
    let front = a.faces()[0];
    let (lo, hi) = if scratch.verts.is_empty() {
        normal_range(vb, front.normal)
    } else {
        normal_range_lanes(&scratch.verts, front.normal)
    };
    let (s0, s1) = (lo - front.offset, -hi - a.faces()[1].offset);
    let (sa, fa) = if s1 > s0 { (s1, 1) } else { (s0, 0) };
    if sa > prediction {
        return;
    }
    // The hull's faces against the triangle's corners (the general face query, stopping
    // at the first face that separates beyond the prediction).
    let [t0, t1, t2] = [0, 1, 2].map(|k| a.vertices()[k]);
    let (mut sb, mut fb) = (Real::NEG_INFINITY, 0);
    if scratch.blocks.is_empty() {
        for (f, (n, off)) in nb.iter().zip(ob).enumerate() {
            let m = -*n;
            let (x, y, z) = (m.dot(t0), m.dot(t1), m.dot(t2));
            let top = if y > x { y } else { x };
            let top = if z > top { z } else { top };
            let s = -top - off;
            if s > sb {
                (sb, fb) = (s, f);
                if s > prediction {
                    return;
                }
            }
        }
    } else {
        // The same pass four faces at a time (the scalar products, sums and selections),
        // then the scalar scan for the first best face over the separations.
        let mut seps = [Real::NEG_INFINITY; LANE_FACES];
        let t = [t0, t1, t2].map(|p| [W::splat(p.x), W::splat(p.y), W::splat(p.z)]);
        for (blk, out) in scratch.blocks.iter().zip(seps.chunks_exact_mut(4)) {
            let (mx, my, mz) = (-blk.x, -blk.y, -blk.z);
            let [x, y, z] = t.map(|[px, py, pz]| mx * px + my * py + mz * pz);
            let top = y.simd_gt(x).bitselect(y, x);
            let top = z.simd_gt(top).bitselect(z, top);
            let s = -top - blk.off;
            out.copy_from_slice(&s.to_array());
        }
        for (f, &s) in seps[..nb.len()].iter().enumerate() {
            if s > sb {
                (sb, fb) = (s, f);
                if s > prediction {
                    return;
                }
            }
        }
    }
    // Only an edge pair separating more than both faces can change the manifold (see
    // `triangle_hull_edge_query`), so the faces' best is the edge query's floor.
    let edge = triangle_hull_edge_query(a, b, posed, sa.max(sb), scratch);
    if edge.0 > prediction {
        return;
    }
    manifold_from_sat(
        a,
        b,
        posed,
        pose_ab,
        prediction,
        (sa, fa),
        (sb, fb),
        edge,
        out,
    );
}

/// The minimum and maximum of `n · v` over the vertices `vb` (infinite when empty; NaN dots
/// are skipped).
fn normal_range(vb: &[Vec3], n: Vec3) -> (Real, Real) {
    let (mut lo, mut hi) = (Real::INFINITY, Real::NEG_INFINITY);
    for v in vb {
        let d = n.dot(*v);
        if d < lo {
            lo = d;
        }
        if d > hi {
            hi = d;
        }
    }
    (lo, hi)
}

/// [`normal_range`] over vertex blocks of four lanes ([`EdgeScratch`]'s `verts`): the same
/// products and sums per vertex and the same strict comparisons, per lane and then across
/// the lanes, so the same values (a minimum or maximum does not depend on the order in
/// which it is found, except for the sign of an exact zero).
fn normal_range_lanes(verts: &[[W; 3]], n: Vec3) -> (Real, Real) {
    let (nx, ny, nz) = (W::splat(n.x), W::splat(n.y), W::splat(n.z));
    let (mut lo, mut hi) = (W::splat(Real::INFINITY), W::splat(Real::NEG_INFINITY));
    for [x, y, z] in verts {
        let d = *x * nx + *y * ny + *z * nz;
        lo = d.simd_lt(lo).bitselect(d, lo);
        hi = d.simd_gt(hi).bitselect(d, hi);
    }
    let (lo, hi) = (lo.to_array(), hi.to_array());
    let (mut l, mut h) = (lo[0], hi[0]);
    for k in 1..4 {
        if lo[k] < l {
            l = lo[k];
        }
        if hi[k] > h {
            h = hi[k];
        }
    }
    (l, h)
}

/// The edge query of the general path for a flat triangle A and a solid B, with the
/// crossing-point prefilter (module docs): the best `(separation, edge of A, edge of B,
/// axis from A to B)`.
///
/// The sign test runs once per hull edge for the three triangle edges together (the dots
/// of every hull face normal with the three edge directions side by side in `dots`); the
/// hull edges that cross some triangle edge's circle are kept with a 3-bit mask, and each
/// triangle edge then visits its own in hull-edge order, so the pairs are considered in
/// the general path's order (ties resolve alike).
///
/// `floor` is the best face separation `max(sa, sb)`: the search starts from it (as if a
/// pair at that separation had been found), so pairs that cannot beat it skip the hull
/// edge's arc and the re-measure. Only an edge pair separating by more than both faces can
/// be chosen by `manifold_from_sat` or raise its best separation, and the result is the
/// unfloored search's whenever that exceeds `floor`: a re-measured separation never exceeds
/// the pair's formula value (`min_B − max_A` along the axis is at most `pb·u − pa·u` for
/// the edges' own points, in floating point too), so by induction the floored running best
/// is the unfloored one raised to `floor`. Otherwise `(floor, 0, 0, 0)` is returned, which
/// `manifold_from_sat` treats as the unfloored answer (a face is chosen either way, with
/// the same best separation).
fn triangle_hull_edge_query(
    a: &Polyhedron,
    b: &Polyhedron,
    posed: &PosedPolyhedron,
    floor: Real,
    scratch: &mut EdgeScratch,
) -> (Real, usize, usize, Vec3) {
    let (vb, nb) = (&posed.vertices[..], &posed.normals[..]);
    let va = a.vertices();
    let centre = va.iter().fold(Vec3::ZERO, |s, x| s + *x) / va.len().max(1) as Real;
    let mut da = [Vec3::ZERO; 3];
    let mut o = [Vec3::ZERO; 3];
    for (k, (ea, fa)) in a.edges().iter().zip(a.edge_faces()).enumerate() {
        let (pa, qa) = (va[ea[0] as usize], va[ea[1] as usize]);
        da[k] = qa - pa;
        // The triangle edge's outward in-plane normal: its half circle's middle.
        let ok = da[k].cross(a.faces()[fa[0] as usize].normal);
        o[k] = if ok.dot((pa + qa) * 0.5 - centre) < 0.0 {
            -ok
        } else {
            ok
        };
    }
    let (edges_b, faces_b) = (b.edges(), b.edge_faces());
    let mut best = (floor, 0, 0, Vec3::ZERO);
    let pair = PairInputs {
        va,
        vb,
        nb,
        edges_b,
        faces_b,
    };
    if !scratch.blocks.is_empty() {
        // Four faces at a time: the dots (in `Vec3::dot`'s order) in one row per triangle
        // edge, and the six sign bits of four faces from the lanes' comparison masks.
        let EdgeScratch {
            blocks,
            dots,
            odots,
            signs,
            lists,
            ..
        } = scratch;
        let d = da.map(|e| [W::splat(e.x), W::splat(e.y), W::splat(e.z)]);
        let od = o.map(|e| [W::splat(e.x), W::splat(e.y), W::splat(e.z)]);
        let zero = W::splat(0.0);
        for (k, blk) in blocks.iter().enumerate() {
            let mut four = 0u32;
            for (e, ([dx, dy, dz], [ox, oy, oz])) in d.iter().zip(&od).enumerate() {
                let v = blk.x * *dx + blk.y * *dy + blk.z * *dz;
                dots[e][4 * k..4 * k + 4].copy_from_slice(&v.to_array());
                let w = blk.x * *ox + blk.y * *oy + blk.z * *oz;
                odots[e][4 * k..4 * k + 4].copy_from_slice(&w.to_array());
                let pos = v.simd_gt(zero).to_bitmask() as usize & 0xF;
                let neg = v.simd_lt(zero).to_bitmask() as usize & 0xF;
                four |= (SPREAD[pos] << e) | (SPREAD[neg] << (e + 3));
            }
            signs[4 * k..4 * k + 4].copy_from_slice(&four.to_le_bytes());
        }
        // An edge's faces lie on one side of circle `k` when both dots `k` are positive or
        // both negative, i.e. when bit `k` or bit `k + 3` survives the AND of their signs.
        let mut counts = [0usize; 3];
        for (j, fb) in faces_b.iter().enumerate() {
            let both = signs[fb[0] as usize & FACE_MASK] & signs[fb[1] as usize & FACE_MASK];
            let bits = !(both | (both >> 3)) & 0b111;
            if bits == 0 {
                continue;
            }
            for (k, list) in lists.iter_mut().enumerate() {
                list[counts[k] & (LIST_LEN - 1)] = j as u8;
                counts[k] += usize::from((bits >> k) & 1 != 0);
            }
        }
        for (i, ea) in a.edges().iter().enumerate() {
            let edge = TriEdge::new(va[ea[0] as usize], da[i], o[i]);
            let (row, orow) = (&dots[i], &odots[i]);
            let bound = PREFILTER_SIN * PREFILTER_SIN * edge.oo;
            for &j in &lists[i][..counts[i]] {
                let j = j as usize;
                let fb = faces_b[j];
                let (f0, f1) = (fb[0] as usize & FACE_MASK, fb[1] as usize & FACE_MASK);
                let (a0, a1) = (row[f0], row[f1]);
                // The prefilter with `m · o = a0 (n1 · o) - a1 (n0 · o)` from the faces'
                // dots with `o`, and `|m|² <= (|a0| + |a1|)²` (unit normals): it drops no
                // pair the exact prefilter keeps (up to round-off, far inside its margin).
                let mo = if a0 > 0.0 {
                    a0 * orow[f1] - a1 * orow[f0]
                } else {
                    a1 * orow[f0] - a0 * orow[f1]
                };
                let mm = a0.abs() + a1.abs();
                if mo > 0.0 && mo * mo > bound * mm * mm {
                    continue;
                }
                pair_exact(&pair, &edge, i, j, &mut best);
            }
        }
        return best;
    }
    let EdgeScratch {
        dots_aos: dots,
        crossing,
        ..
    } = scratch;
    dots.clear();
    dots.extend(
        nb.iter()
            .map(|n| [n.dot(da[0]), n.dot(da[1]), n.dot(da[2])]),
    );
    let dots = &dots[..];
    crossing.clear();
    for (j, fb) in faces_b.iter().enumerate() {
        let (d0, d1) = (dots[fb[0] as usize], dots[fb[1] as usize]);
        let mut bits = 0u8;
        for k in 0..3 {
            let one_side = d0[k] * d1[k] > 0.0;
            bits |= u8::from(!one_side) << k;
        }
        if bits != 0 {
            crossing.push((j as u32, bits));
        }
    }
    for (i, ea) in a.edges().iter().enumerate() {
        let edge = TriEdge::new(va[ea[0] as usize], da[i], o[i]);
        for &(j, bits) in crossing.iter() {
            if bits & (1 << i) == 0 {
                continue;
            }
            let j = j as usize;
            let fb = faces_b[j];
            let (a0, a1) = (dots[fb[0] as usize][i], dots[fb[1] as usize][i]);
            pair_test(&pair, &edge, i, j, a0, a1, &mut best);
        }
    }
    best
}

/// What [`pair_test`] reads of the triangle and the placed hull.
struct PairInputs<'a> {
    va: &'a [Vec3],
    vb: &'a [Vec3],
    nb: &'a [Vec3],
    edges_b: &'a [[u32; 2]],
    faces_b: &'a [[u32; 2]],
}

/// A triangle edge for [`pair_test`]: its first corner, direction and length, and its
/// outward in-plane normal `o` (the middle of its Gauss-map half circle) and `|o|²`.
struct TriEdge {
    pa: Vec3,
    da: Vec3,
    la: Real,
    o: Vec3,
    oo: Real,
}

impl TriEdge {
    fn new(pa: Vec3, da: Vec3, o: Vec3) -> TriEdge {
        TriEdge {
            pa,
            da,
            la: da.length(),
            o,
            oo: o.length_squared(),
        }
    }
}

/// Triangle edge `i` (`e`) against hull edge `j`, whose face normals have dots `a0`, `a1`
/// with the triangle edge's direction and lie on both sides of its great circle: the
/// crossing-point prefilter, then [`pair_exact`].
#[inline(always)]
fn pair_test(
    p: &PairInputs<'_>,
    e: &TriEdge,
    i: usize,
    j: usize,
    a0: Real,
    a1: Real,
    best: &mut (Real, usize, usize, Vec3),
) {
    let fb = p.faces_b[j];
    let (n0, n1) = (p.nb[fb[0] as usize], p.nb[fb[1] as usize]);
    // The arc's crossing point `m`; the pair's axis is `-m`, which must not lie clearly
    // beyond the triangle edge's half circle (`m · o > 0`).
    let m = if a0 > 0.0 {
        n1 * a0 - n0 * a1
    } else {
        n0 * a1 - n1 * a0
    };
    let mo = m.dot(e.o);
    if mo > 0.0 && mo * mo > PREFILTER_SIN * PREFILTER_SIN * m.length_squared() * e.oo {
        return;
    }
    pair_exact(p, e, i, j, best);
}

/// The general path's exact test of triangle edge `i` (`e`) against hull edge `j`,
/// updating `best` when the pair separates more than it.
#[inline(always)]
fn pair_exact(
    p: &PairInputs<'_>,
    e: &TriEdge,
    i: usize,
    j: usize,
    best: &mut (Real, usize, usize, Vec3),
) {
    let (eb, fb) = (p.edges_b[j], p.faces_b[j]);
    let (pa, da, o) = (e.pa, e.da, e.o);
    // The exact test of the general path.
    let (pb, qb) = (p.vb[eb[0] as usize], p.vb[eb[1] as usize]);
    let db = qb - pb;
    let axis = da.cross(db);
    let len = axis.length();
    if !(len >= PARALLEL_SIN * e.la * db.length() && len != 0.0) {
        return;
    }
    let axis = axis / len;
    let ua = axis.dot(o);
    let sep = pb.dot(axis) - pa.dot(axis);
    // The pair counts as `sep` (axis `u`, needs `ua >= 0`) or `-sep` (axis `-u`, needs
    // `ua <= 0`) and only when that beats the best so far: decide that before building
    // the hull edge's arc.
    let reach = if ua > 0.0 {
        sep
    } else if ua < 0.0 {
        -sep
    } else {
        sep.abs()
    };
    let beats = reach > best.0; // false for NaN
    if !beats {
        return;
    }
    let (n0, n1) = (p.nb[fb[0] as usize], p.nb[fb[1] as usize]);
    let c = n0.cross(n1);
    let (g0, g1) = (c.cross(n0), n1.cross(c));
    let (ub0, ub1) = (axis.dot(g0), axis.dot(g1));
    let fwd = (ua >= 0.0 && ub0 <= 0.0 && ub1 <= 0.0).then_some(sep);
    let bwd = (ua <= 0.0 && ub0 >= 0.0 && ub1 >= 0.0).then_some(-sep);
    let (s, ax) = match (fwd, bwd) {
        (Some(s1), Some(s2)) if s2 > s1 => (s2, -axis),
        (Some(s1), _) => (s1, axis),
        (None, Some(s2)) => (s2, -axis),
        (None, None) => return,
    };
    // The edge formula holds only on a true Minkowski face: a new best is checked by
    // projecting both shapes (as the general path does).
    if s > best.0 {
        let exact = -max_dot(p.vb, -ax) - max_dot(p.va, ax);
        if exact > best.0 {
            *best = (exact, i, j, ax);
        }
    }
}

#[cfg(test)]
#[path = "mesh_hull_tests.rs"]
mod tests;
