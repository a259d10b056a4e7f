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
use super::polyhedron_sat::{max_dot, Buf};
use crate::math::{Isometry, Real, Vec3};
use smallvec::SmallVec;

/// Relative margin of the crossing-point prefilter: a pair is dropped early only when
/// `m · o > PREFILTER_SIN · |m| · |o|` (its axis more than about 3° on the wrong side of the
/// triangle edge's half circle); nearer pairs take the exact test.
const PREFILTER_SIN: Real = 0.05;

/// Scratch of [`triangle_hull_manifold`], reused across the triangles of a pair: per hull
/// face, its normal's dots with the three triangle edges and their signs (bit `k` set when
/// dot `k` is positive, bit `k + 3` when it is negative); the hull edges whose arcs cross
/// some triangle edge's great circle, with one bit per triangle edge. On the stack up to 64
/// faces and 64 crossing edges.
#[derive(Debug, Default)]
pub(crate) struct EdgeScratch {
    dots: SmallVec<[[Real; 3]; 64]>,
    signs: SmallVec<[u8; 64]>,
    crossing: SmallVec<[(u32, u8); 64]>,
}

/// Hull `b` placed in the mesh's frame by `pose_ab` for [`triangle_hull_manifold`]: its
/// vertices, face normals and plane offsets (no edge arcs), rotated by the pose's matrix
/// (9 products a vector instead of the quaternion's ~20; `PosedPolyhedron::new` rotates by
/// the quaternion, so the two agree to round-off, not bit for bit).
pub(crate) fn posed_hull(b: &Polyhedron, pose_ab: &Isometry) -> PosedPolyhedron {
    let m = pose_ab.rotation_matrix();
    let t = pose_ab.translation;
    let vertices: Buf = b.vertices().iter().map(|v| m * *v + t).collect();
    let normals: Buf = b.faces().iter().map(|f| m * f.normal).collect();
    let offsets = b
        .faces()
        .iter()
        .zip(&normals)
        .map(|(f, n)| f.offset + n.dot(t))
        .collect();
    PosedPolyhedron {
        vertices,
        normals,
        offsets,
        arcs: SmallVec::new(),
    }
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
    let (mut lo, mut hi) = (Real::INFINITY, Real::NEG_INFINITY);
    for v in vb {
        let d = front.normal.dot(*v);
        if d < lo {
            lo = d;
        }
        if d > hi {
            hi = d;
        }
    }
    let (s0, s1) = (lo - front.offset, -hi - a.faces()[1].offset);
    let (sa, fa) = if s1 > s0 { (s1, 1) } else { (s0, 0) };
    if sa > prediction {
        return;
    }
    // The hull's faces against the triangle's corners (the general face query, stopping
    // at the first face that separates beyond the prediction).
    let [t0, t1, t2] = [0, 1, 2].map(|k| a.vertices()[k]);
    let (mut sb, mut fb) = (Real::NEG_INFINITY, 0);
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
    let masks = nb.len() <= 64;
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
    let EdgeScratch {
        dots,
        signs,
        crossing,
    } = scratch;
    dots.clear();
    dots.extend(
        nb.iter()
            .map(|n| [n.dot(da[0]), n.dot(da[1]), n.dot(da[2])]),
    );
    let dots = &dots[..];
    crossing.clear();
    if masks {
        // The signs once per face (not once per adjacent edge): an edge's faces lie on one
        // side of circle `k` when both dots `k` are positive or both negative, i.e. when
        // bit `k` or bit `k + 3` survives the AND of their sign masks.
        signs.clear();
        signs.extend(dots.iter().map(|d| {
            let mut m = 0u8;
            for (k, &x) in d.iter().enumerate() {
                m |= (u8::from(x > 0.0) << k) | (u8::from(x < 0.0) << (k + 3));
            }
            m
        }));
        let signs = &signs[..];
        for (j, fb) in b.edge_faces().iter().enumerate() {
            let both = signs[fb[0] as usize] & signs[fb[1] as usize];
            let bits = !(both | (both >> 3)) & 0b111;
            if bits != 0 {
                crossing.push((j as u32, bits));
            }
        }
    } else {
        for (j, fb) in b.edge_faces().iter().enumerate() {
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
    }
    let crossing = &crossing[..];
    let (edges_b, faces_b) = (b.edges(), b.edge_faces());
    let mut best = (floor, 0, 0, Vec3::ZERO);
    for (i, ea) in a.edges().iter().enumerate() {
        let pa = va[ea[0] as usize];
        let (da, o) = (da[i], o[i]);
        let oo = o.length_squared();
        for &(j, bits) in crossing {
            if bits & (1 << i) == 0 {
                continue;
            }
            let j = j as usize;
            let (eb, fb) = (edges_b[j], faces_b[j]);
            let (a0, a1) = (dots[fb[0] as usize][i], dots[fb[1] as usize][i]);
            let (n0, n1) = (nb[fb[0] as usize], nb[fb[1] as usize]);
            // The arc's crossing point `m`; the pair's axis is `-m`, which must not lie
            // clearly beyond the triangle edge's half circle (`m · o > 0`).
            let m = if a0 > 0.0 {
                n1 * a0 - n0 * a1
            } else {
                n0 * a1 - n1 * a0
            };
            let mo = m.dot(o);
            if mo > 0.0 && mo * mo > PREFILTER_SIN * PREFILTER_SIN * m.length_squared() * oo {
                continue;
            }
            // The exact test of the general path.
            let (pb, qb) = (vb[eb[0] as usize], vb[eb[1] as usize]);
            let db = qb - pb;
            let axis = da.cross(db);
            let len = axis.length();
            if !(len >= PARALLEL_SIN * da.length() * db.length() && len != 0.0) {
                continue;
            }
            let axis = axis / len;
            let ua = axis.dot(o);
            let sep = pb.dot(axis) - pa.dot(axis);
            // The pair counts as `sep` (axis `u`, needs `ua >= 0`) or `-sep` (axis `-u`,
            // needs `ua <= 0`) and only when that beats the best so far: decide that before
            // building the hull edge's arc.
            let reach = if ua > 0.0 {
                sep
            } else if ua < 0.0 {
                -sep
            } else {
                sep.abs()
            };
            if !(reach > best.0) {
                continue;
            }
            let c = n0.cross(n1);
            let (g0, g1) = (c.cross(n0), n1.cross(c));
            let (ub0, ub1) = (axis.dot(g0), axis.dot(g1));
            let fwd = (ua >= 0.0 && ub0 <= 0.0 && ub1 <= 0.0).then_some(sep);
            let bwd = (ua <= 0.0 && ub0 >= 0.0 && ub1 >= 0.0).then_some(-sep);
            let (s, ax) = match (fwd, bwd) {
                (Some(s1), Some(s2)) if s2 > s1 => (s2, -axis),
                (Some(s1), _) => (s1, axis),
                (None, Some(s2)) => (s2, -axis),
                (None, None) => continue,
            };
            // The edge formula holds only on a true Minkowski face: a new best is checked
            // by projecting both shapes (as the general path does).
            if s > best.0 {
                let exact = -max_dot(vb, -ax) - max_dot(va, ax);
                if exact > best.0 {
                    best = (exact, i, j, ax);
                }
            }
        }
    }
    best
}

#[cfg(test)]
#[path = "mesh_hull_tests.rs"]
mod tests;
