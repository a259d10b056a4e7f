//! EPA: penetration depth (minimum translational distance) of two overlapping convex sets.
//!
//! The Expanding Polytope Algorithm of van den Bergen, "Proximity Queries and Penetration
//! Depth Computation on 3D Game Objects" (GDC 2001), as in Jolt's
//! `Jolt/Geometry/EPAPenetrationDepth.h` and Bullet's `btGjkEpa2.cpp`:
//!
//! 1. Start from a full tetrahedron (or a triangular bipyramid) of `A - B` points that
//!    contains the origin, grown from GJK's final simplex by support queries.
//! 2. Take the face closest to the origin; query the support point `w` along its normal.
//! 3. If `w` is no further than the face (within a scale-relative tolerance), the face's
//!    distance is the depth and its normal the direction; stop.
//! 4. Otherwise remove every face that sees `w`, and connect `w` to the horizon edges.
//!
//! Round-off cannot make it loop or produce NaN: iterations and vertices are capped, a
//! degenerate new face ends the expansion with the best face so far, and when no 3D
//! polytope can be built (a flat Minkowski difference, e.g. coplanar triangles) the depth is
//! *sampled* along fixed directions with the support map, as on the GPU in Coumans' 2010
//! talk ("instead of EPA, sample penetration depth using support mapping").

use super::gjk::Simplex;
use super::simplex::{closest_to_origin, Barycentric};
use super::support_adapters::{MinkowskiDiff, Support};
use crate::math::{Real, Vec3, EPSILON};

/// Iteration cap of EPA.
pub const EPA_MAX_ITERATIONS: usize = 128;

/// Relative tolerance on the gap between a face and the support point along its normal.
pub const EPA_REL_TOL: Real = 64.0 * EPSILON;

/// Cosine above which two polytope faces count as coplanar in the final tie-break (~2.6°).
const COPLANAR_COS: Real = 0.999;

/// Penetration of A and B: translating B by `depth * normal` makes them touch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Penetration {
    /// Penetration depth (>= 0).
    pub depth: Real,
    /// Unit direction from A towards B.
    pub normal: Vec3,
    /// Deepest point of A inside B.
    pub point_a: Vec3,
    /// Deepest point of B inside A (`point_a - depth * normal`).
    pub point_b: Vec3,
}

/// A polytope face: vertex indices (counter-clockwise seen from outside), the face across
/// each edge `idx[e] → idx[(e + 1) % 3]`, the outward unit normal and the plane's distance
/// from the origin. Faces are never moved: removed ones are flagged, so adjacency indices
/// stay valid (as in Bullet's `btGjkEpa2.cpp` and Jolt's `EPAConvexHullBuilder`).
#[derive(Debug, Clone, Copy)]
struct Face {
    idx: [u32; 3],
    adj: [u32; 3],
    normal: Vec3,
    dist: Real,
    removed: bool,
}

#[derive(Debug, Clone, Copy)]
struct Vertex {
    w: Vec3,
    a: Vec3,
    b: Vec3,
}

/// A horizon edge `i → j` of the visible region, and the kept face `outer` across it.
#[derive(Debug, Clone, Copy)]
struct HorizonEdge {
    i: u32,
    j: u32,
    outer: u32,
}

/// The buffers of one EPA run, kept per thread so that steady-state calls do not allocate.
#[derive(Default)]
struct Scratch {
    verts: Vec<Vertex>,
    faces: Vec<Face>,
    horizon: Vec<HorizonEdge>,
    stack: Vec<(u32, u8)>,
    /// Faces removed by the current expansion step (to undo it).
    carved: Vec<u32>,
    /// Per vertex: the new face whose horizon edge starts there, stamped with the step.
    start_of: Vec<(u32, u32)>,
    /// Stamp of the current stitching step (never `u32::MAX`, the "unset" stamp).
    stamp: u32,
}

thread_local! {
    static SCRATCH: std::cell::RefCell<Scratch> = std::cell::RefCell::new(Scratch::default());
}

/// Runs `f` with this thread's scratch buffers (fresh ones if they are already in use).
fn with_scratch<R>(f: impl FnOnce(&mut Scratch) -> R) -> R {
    SCRATCH.with(|cell| match cell.try_borrow_mut() {
        Ok(mut s) => f(&mut s),
        Err(_) => f(&mut Scratch::default()),
    })
}

const NO_FACE: u32 = u32::MAX;

fn make_face(verts: &[Vertex], idx: [u32; 3], tol: Real) -> Option<Face> {
    let (p, q, r) = (
        verts[idx[0] as usize].w,
        verts[idx[1] as usize].w,
        verts[idx[2] as usize].w,
    );
    let n = (q - p).cross(r - p);
    let len = n.length();
    // A sliver: its height over the longest edge (`len / edge`) at most `tol` times that
    // edge. Relative, so that the test means the same at every scale: an absolute height
    // (`len <= tol * edge`, as before) dropped the faces of millimetre shapes whose height
    // was under 8 µm, EPA then stopped at a coarse face, and a 0.1 mm cone's depth against
    // a triangle came out 13 % deep in one argument order (`tests/query_scale.rs`).
    let edge_sq = (q - p)
        .length_squared()
        .max((r - p).length_squared())
        .max((r - q).length_squared());
    if len.is_nan() || len <= tol * edge_sq {
        return None;
    }
    let normal = n / len;
    Some(Face {
        idx,
        adj: [NO_FACE; 3],
        normal,
        dist: normal.dot(p),
        removed: false,
    })
}

/// Support directions used to grow a degenerate simplex and by the sampled fallback: the
/// 6 axes, 12 edge midpoints and 8 corners of a cube.
fn sample_directions() -> impl Iterator<Item = Vec3> {
    (0..27).filter(|&i| i != 13).map(|i| {
        Vec3::new(
            (i % 3) as Real - 1.0,
            ((i / 3) % 3) as Real - 1.0,
            (i / 9) as Real - 1.0,
        )
        .normalize()
    })
}

/// Penetration depth of `a` and `b` (same frame), starting from GJK's final simplex.
/// Falls back to the sampled depth when the Minkowski difference is flat.
pub fn epa<A: Support, B: Support>(a: &A, b: &B, simplex: &Simplex) -> Penetration {
    epa_polytope(a, b, simplex).unwrap_or_else(|| sampled(&MinkowskiDiff { a, b }, simplex))
}

/// EPA proper: `None` when no 3D polytope can be built (flat Minkowski difference).
pub fn epa_polytope<A: Support, B: Support>(
    a: &A,
    b: &B,
    simplex: &Simplex,
) -> Option<Penetration> {
    with_scratch(|scratch| {
        let diff = MinkowskiDiff { a, b };
        let scale = initial_tetrahedron(&diff, simplex, scratch)?;
        Some(expand(&diff, scratch, scale))
    })
}

/// Grows GJK's final simplex to a tetrahedron of `A - B` points with adjacency; returns the
/// polytope's scale, or `None` when the difference is flat.
fn initial_tetrahedron<A: Support, B: Support>(
    diff: &MinkowskiDiff<A, B>,
    simplex: &Simplex,
    scratch: &mut Scratch,
) -> Option<Real> {
    let verts = &mut scratch.verts;
    verts.clear();
    for i in 0..simplex.len {
        verts.push(Vertex {
            w: simplex.w[i],
            a: simplex.a[i],
            b: simplex.b[i],
        });
    }
    let mut scale = verts.iter().map(|v| v.w.length()).fold(0.0, Real::max);
    let push = |verts: &mut Vec<Vertex>, d: Vec3| {
        let (w, pa, pb) = diff.support_pair(d);
        verts.push(Vertex { w, a: pa, b: pb });
    };
    if verts.is_empty() {
        push(verts, Vec3::X);
    }
    let tol = 64.0 * EPSILON;
    // Grow to a segment.
    if verts.len() == 1 {
        for d in sample_directions() {
            push(verts, d);
            let len = (verts[1].w - verts[0].w).length();
            scale = scale.max(verts[1].w.length());
            if len > tol * scale.max(len) {
                break;
            }
            verts.pop();
        }
    }
    // Grow to a triangle: search around the segment.
    if verts.len() == 2 {
        let d = (verts[1].w - verts[0].w).normalize_or_zero();
        let (e1, e2) = crate::math::orthonormal_basis(d);
        for k in 0..6 {
            let ang = k as Real * (crate::math::consts::PI / 3.0);
            push(verts, e1 * ang.cos() + e2 * ang.sin());
            let off = (verts[2].w - verts[0].w).cross(d).length();
            scale = scale.max(verts[2].w.length());
            if off > tol * scale {
                break;
            }
            verts.pop();
        }
    }
    // Grow to a tetrahedron: an apex on the origin's side of the triangle first. (A
    // bipyramid would not be convex in general; EPA adds the other side itself.)
    if verts.len() == 3 {
        let n = (verts[1].w - verts[0].w)
            .cross(verts[2].w - verts[0].w)
            .normalize_or_zero();
        let first = if n.dot(verts[0].w) > 0.0 { -n } else { n };
        for dir in [first, -first] {
            push(verts, dir);
            let h = (verts[3].w - verts[0].w).dot(n).abs();
            scale = scale.max(verts[3].w.length());
            if n != Vec3::ZERO && h > tol * scale {
                break;
            }
            verts.pop();
        }
    }
    if verts.len() != 4 {
        return None;
    }
    let faces = &mut scratch.faces;
    faces.clear();
    let centroid = verts.iter().fold(Vec3::ZERO, |acc, v| acc + v.w) * 0.25;
    for t in [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]] {
        let mut f = make_face(verts, t, tol)?;
        if f.normal.dot(centroid - verts[t[0] as usize].w) > 0.0 {
            // The reversed triangle: `make_face(verts, [t[0], t[2], t[1]], tol)` would give
            // the cross product's exact negation (each product is the same, the difference
            // changes sign), the same length and edges, so the negated normal and distance
            // bit for bit, without computing them again.
            f.idx = [t[0], t[2], t[1]];
            f.normal = -f.normal;
            f.dist = -f.dist;
        }
        faces.push(f);
    }
    // Adjacency of the tetrahedron: the face holding the reversed directed edge.
    for fi in 0..4 {
        for e in 0..3 {
            let (i, j) = (faces[fi].idx[e], faces[fi].idx[(e + 1) % 3]);
            faces[fi].adj[e] = (0..4)
                .find(|&g| g != fi && edge_index(&faces[g], j, i).is_some())
                .map_or(NO_FACE, |g| g as u32);
        }
    }
    Some(scale)
}

/// The edge index `e` of `f` with `f.idx[e] == i` and `f.idx[e + 1] == j`.
#[inline]
fn edge_index(f: &Face, i: u32, j: u32) -> Option<usize> {
    (0..3).find(|&e| f.idx[e] == i && f.idx[(e + 1) % 3] == j)
}

/// The penetration of face `f`, with `sol` the closest point to the origin of its triangle
/// (`closest_to_origin` of its three `w`, in index order).
fn result_from_face(verts: &[Vertex], f: &Face, sol: &Barycentric) -> Penetration {
    let v = |k: usize| verts[f.idx[k] as usize];
    let mut pa = Vec3::ZERO;
    let mut pb = Vec3::ZERO;
    for k in 0..3 {
        pa += v(k).a * sol.lambda[k];
        pb += v(k).b * sol.lambda[k];
    }
    let depth = f.dist.max(0.0);
    Penetration {
        depth,
        normal: f.normal,
        point_a: pa,
        point_b: pb,
    }
}

/// Removes the faces that see `w` (a connected region grown from `start` across shared
/// edges, depth first) and records the horizon: the edges between removed and kept faces.
/// Returns `false` when the adjacency is broken (round-off), leaving the polytope as is.
fn carve_horizon(scratch: &mut Scratch, start: u32, w: Vec3, vis_eps: Real) -> bool {
    let Scratch {
        verts,
        faces,
        horizon,
        stack,
        carved,
        ..
    } = scratch;
    let sees = |f: &Face| f.normal.dot(w - verts[f.idx[0] as usize].w) > vis_eps;
    horizon.clear();
    stack.clear();
    carved.clear();
    faces[start as usize].removed = true;
    carved.push(start);
    stack.push((start, 0));
    while let Some(top) = stack.last_mut() {
        let (fi, e) = *top;
        if e == 3 {
            stack.pop();
            continue;
        }
        top.1 += 1;
        let f = faces[fi as usize];
        let g = f.adj[e as usize];
        if g == NO_FACE {
            return false;
        }
        if faces[g as usize].removed {
            continue;
        }
        if sees(&faces[g as usize]) {
            faces[g as usize].removed = true;
            carved.push(g);
            stack.push((g, 0));
        } else {
            horizon.push(HorizonEdge {
                i: f.idx[e as usize],
                j: f.idx[(e as usize + 1) % 3],
                outer: g,
            });
        }
    }
    !horizon.is_empty()
}

fn expand<A: Support, B: Support>(
    diff: &MinkowskiDiff<A, B>,
    scratch: &mut Scratch,
    mut scale: Real,
) -> Penetration {
    let tol = 64.0 * EPSILON;
    let mut best_i = 0u32;
    for _ in 0..EPA_MAX_ITERATIONS {
        best_i = closest_face(&scratch.faces);
        let best = scratch.faces[best_i as usize];
        let (w, pa, pb) = diff.support_pair(best.normal);
        if !w.is_finite() {
            break;
        }
        scale = scale.max(w.length());
        let gap = best.normal.dot(w) - best.dist;
        if gap <= EPA_REL_TOL * scale.max(EPSILON) {
            break;
        }
        let vis_eps = EPSILON * scale;
        let saved_faces = scratch.faces.len();
        if !carve_horizon(scratch, best_i, w, vis_eps) {
            restore(scratch, saved_faces);
            break;
        }
        let k = scratch.verts.len() as u32;
        scratch.verts.push(Vertex { w, a: pa, b: pb });
        if !stitch(scratch, k, best.dist - EPA_REL_TOL * scale - vis_eps, tol) {
            // EPA's lower bound never decreases and every horizon vertex starts one edge;
            // otherwise round-off has broken convexity: stop with the best face so far.
            scratch.verts.pop();
            restore(scratch, saved_faces);
            break;
        }
    }
    // Coplanar faces tie on distance; the origin's projection lies inside only one of them.
    // Among the faces within tolerance of the best *and parallel to it*, take the one whose
    // triangle is truly closest to the origin, so the witnesses satisfy
    // `a - b = depth * normal`. The parallel test matters when the shapes merely touch: the
    // polytope is then a thin slab through the origin, and its opposite face (normal
    // reversed, as close to the origin) would otherwise win the tie and flip the normal
    // (a box resting on a large ground box got the ground's bottom face, 102 m deep).
    let (verts, faces) = (&scratch.verts, &scratch.faces);
    let best = faces[best_i as usize];
    let slack = EPA_REL_TOL * scale.max(EPSILON) * 4.0;
    let tri_of = |f: &Face| {
        [
            verts[f.idx[0] as usize].w,
            verts[f.idx[1] as usize].w,
            verts[f.idx[2] as usize].w,
        ]
    };
    let mut pick = best;
    let mut pick_sol = None;
    let mut pick_d = Real::INFINITY;
    for f in faces.iter().filter(|f| {
        !f.removed && f.dist <= best.dist + slack && f.normal.dot(best.normal) >= COPLANAR_COS
    }) {
        let tri = tri_of(f);
        let sol = closest_to_origin(&tri);
        let d = sol.point(&tri).length_squared();
        if d < pick_d {
            pick_d = d;
            pick = *f;
            pick_sol = Some(sol);
        }
    }
    // The winner's barycentric solution is reused for its witnesses (the same call on the
    // same triangle); it is recomputed only when no face won (NaN distances).
    let sol = pick_sol.unwrap_or_else(|| closest_to_origin(&tri_of(&pick)));
    result_from_face(verts, &pick, &sol)
}

/// The live face closest to the origin (first on ties, so the result is deterministic).
fn closest_face(faces: &[Face]) -> u32 {
    let mut best = (Real::INFINITY, 0u32);
    for (i, f) in faces.iter().enumerate() {
        if !f.removed && f.dist < best.0 {
            best = (f.dist, i as u32);
        }
    }
    best.1
}

/// Connects the new vertex `k` to every horizon edge, linking the new faces to the kept
/// ones and to each other. `false` (nothing linked) when a new face is degenerate, closer
/// than `min_dist`, or the horizon is not one simple loop.
fn stitch(scratch: &mut Scratch, k: u32, min_dist: Real, tol: Real) -> bool {
    scratch.stamp = scratch.stamp.wrapping_add(1);
    if scratch.stamp == u32::MAX {
        scratch.stamp = 0;
        scratch.start_of.clear();
    }
    let stamp = scratch.stamp;
    let Scratch {
        verts,
        faces,
        horizon,
        start_of,
        ..
    } = scratch;
    if start_of.len() < verts.len() {
        start_of.resize(verts.len(), (u32::MAX, NO_FACE));
    }
    let first_new = faces.len() as u32;
    for (n, h) in horizon.iter().enumerate() {
        match make_face(verts, [h.i, h.j, k], tol) {
            Some(f) if f.dist >= min_dist => faces.push(f),
            _ => return false,
        }
        if start_of[h.i as usize].0 == stamp {
            return false;
        }
        start_of[h.i as usize] = (stamp, first_new + n as u32);
    }
    // Check everything before changing any kept face.
    for h in horizon.iter() {
        if start_of[h.j as usize].0 != stamp
            || edge_index(&faces[h.outer as usize], h.j, h.i).is_none()
        {
            return false;
        }
    }
    for (n, h) in horizon.iter().enumerate() {
        let fi = first_new + n as u32;
        let next = start_of[h.j as usize].1;
        let e_outer = edge_index(&faces[h.outer as usize], h.j, h.i).unwrap_or(0);
        faces[fi as usize].adj = [h.outer, next, NO_FACE];
        faces[h.outer as usize].adj[e_outer] = fi;
    }
    for n in 0..horizon.len() {
        let fi = first_new + n as u32;
        let next = faces[fi as usize].adj[1];
        faces[next as usize].adj[2] = fi;
    }
    true
}

/// Undoes a failed expansion step: drops the faces added after `len` and revives the faces
/// carved for it (`stitch` changes no kept face before all its checks have passed).
fn restore(scratch: &mut Scratch, len: usize) {
    scratch.faces.truncate(len);
    for &fi in &scratch.carved {
        scratch.faces[fi as usize].removed = false;
    }
}

/// Sampled penetration depth: the smallest support extent of `A - B` over fixed directions
/// (and the GJK direction). Used only when no 3D polytope can be built.
fn sampled<A: Support, B: Support>(diff: &MinkowskiDiff<A, B>, simplex: &Simplex) -> Penetration {
    let hint = simplex.closest().try_normalize();
    let mut best: Option<(Real, Vec3, Vec3)> = None;
    for d in hint.into_iter().map(|h| -h).chain(sample_directions()) {
        let (w, pa, _) = diff.support_pair(d);
        let h = d.dot(w);
        if best.is_none_or(|(bh, _, _)| h < bh) {
            best = Some((h, d, pa));
        }
    }
    let (h, normal, point_a) = best.expect("directions are non-empty");
    let depth = if h.is_finite() { h.max(0.0) } else { 0.0 };
    Penetration {
        depth,
        normal,
        point_a,
        point_b: point_a - normal * depth,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::query::gjk::{gjk, GjkResult};
    use crate::query::support_adapters::{PointSupport, PolytopeSupport};

    fn cube(h: Vec3, c: Vec3) -> Vec<Vec3> {
        (0..8)
            .map(|i| {
                c + Vec3::new(
                    if i & 1 != 0 { h.x } else { -h.x },
                    if i & 2 != 0 { h.y } else { -h.y },
                    if i & 4 != 0 { h.z } else { -h.z },
                )
            })
            .collect()
    }

    #[test]
    fn boxes_overlapping_along_each_axis() {
        let a = cube(Vec3::new(1.0, 2.0, 3.0), Vec3::ZERO);
        for (off, depth, n) in [
            (Vec3::new(1.5, 0.1, 0.2), 0.5, Vec3::X),
            (Vec3::new(0.1, -2.2, 0.2), 0.8, -Vec3::Y),
            (Vec3::new(0.0, 0.0, 3.5), 0.5, Vec3::Z),
            (Vec3::new(0.0, 0.0, 4.0), 0.0, Vec3::Z),
        ] {
            let b = cube(Vec3::splat(1.0), off);
            let (sa, sb) = (PolytopeSupport(&a), PolytopeSupport(&b));
            let r = gjk(&sa, &sb, off, Real::INFINITY);
            let GjkResult::Overlapping(s) = r else {
                panic!("should overlap: {r:?}")
            };
            let p = epa(&sa, &sb, &s);
            assert!((p.depth - depth).abs() < 1e-4, "{p:?}");
            assert!((p.normal - n).length() < 1e-4, "{p:?}");
            assert!((p.point_a - p.point_b - p.normal * p.depth).length() < 1e-4);
        }
    }

    /// `make_face`'s one square root of the largest squared edge equals the largest of the
    /// three edge lengths bit for bit (the old code), on random, degenerate (zero-size,
    /// collinear, repeated), huge, tiny, far-from-origin and non-finite triangles.
    #[test]
    fn one_square_root_edge_matches_three() {
        let old = |p: Vec3, q: Vec3, r: Vec3| {
            (q - p).length().max((r - p).length()).max((r - q).length())
        };
        let new = |p: Vec3, q: Vec3, r: Vec3| {
            (q - p)
                .length_squared()
                .max((r - p).length_squared())
                .max((r - q).length_squared())
                .sqrt()
        };
        let mut seed = 0x9E37_79B9_7F4A_7C15_u64;
        let mut rnd = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as Real / (1u64 << 53) as Real * 2.0 - 1.0
        };
        let mut tris = Vec::new();
        for k in 0..20_000 {
            let scale = [1.0e-20, 1.0e-3, 1.0, 1.0e3, 1.0e15][k % 5];
            let far = Vec3::splat([0.0, 1.0e4, -3.0e6][k % 3]);
            let mut v = || Vec3::new(rnd(), rnd(), rnd()) * scale + far;
            let (p, q, r) = (v(), v(), v());
            tris.push((p, q, r));
            tris.push((p, p, r)); // repeated vertex
            tris.push((p, q, p + (q - p) * 0.5)); // collinear
            tris.push((p, q, q + (q - p) * 1.0e-3)); // nearly collinear, two equal edges
        }
        let x = Vec3::new(1.0, 2.0, 3.0);
        tris.push((x, x, x)); // zero size
        tris.push((x, Vec3::splat(Real::NAN), Vec3::ZERO));
        tris.push((x, Vec3::splat(Real::INFINITY), Vec3::ZERO));
        tris.push((Vec3::splat(Real::MAX), -Vec3::splat(Real::MAX), Vec3::ZERO));
        for (p, q, r) in tris {
            let (a, b) = (old(p, q, r), new(p, q, r));
            assert!(
                a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()),
                "{p} {q} {r}: {a} vs {b}"
            );
        }
    }

    #[test]
    fn degenerate_starts_and_flat_differences_are_finite() {
        let a = cube(Vec3::splat(1.0), Vec3::ZERO);
        // Point at the centre, starting from a one-point simplex (a support point).
        let p = PointSupport(Vec3::ZERO);
        let sa = PolytopeSupport(&a);
        let mut s = Simplex::default();
        s.w[0] = Vec3::ONE;
        s.a[0] = Vec3::ONE;
        s.len = 1;
        s.lambda[0] = 1.0;
        let pen = epa(&sa, &p, &s);
        assert!((pen.depth - 1.0).abs() < 1e-4, "{pen:?}");
        let GjkResult::Overlapping(s2) = gjk(&sa, &p, Vec3::X, Real::INFINITY) else {
            panic!("centre is inside")
        };
        assert!((epa(&sa, &p, &s2).depth - 1.0).abs() < 1e-4);
        // Flat: two coplanar squares.
        let sq1 = [Vec3::ZERO, Vec3::X, Vec3::Z, Vec3::X + Vec3::Z];
        let sq2: Vec<Vec3> = sq1.iter().map(|v| *v + Vec3::new(0.5, 0.0, 0.5)).collect();
        let pen = epa(&PolytopeSupport(&sq1), &PolytopeSupport(&sq2), &s);
        assert!(pen.depth.is_finite() && pen.depth.abs() < 1e-4);
        assert!(pen.normal.is_finite() && pen.point_a.is_finite());
    }
}
