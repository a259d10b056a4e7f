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
use super::simplex::closest_to_origin;
use super::support_adapters::{MinkowskiDiff, Support};
use crate::math::{Real, Vec3, EPSILON};

/// Iteration cap of EPA.
pub const EPA_MAX_ITERATIONS: usize = 128;

/// Relative tolerance on the gap between a face and the support point along its normal.
pub const EPA_REL_TOL: Real = 64.0 * EPSILON;

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

#[derive(Debug, Clone, Copy)]
struct Face {
    idx: [usize; 3],
    normal: Vec3,
    dist: Real,
}

struct Vertex {
    w: Vec3,
    a: Vec3,
    b: Vec3,
}

fn make_face(verts: &[Vertex], idx: [usize; 3], tol: Real) -> Option<Face> {
    let (p, q, r) = (verts[idx[0]].w, verts[idx[1]].w, verts[idx[2]].w);
    let n = (q - p).cross(r - p);
    let len = n.length();
    let edge = (q - p).length().max((r - p).length()).max((r - q).length());
    if len.is_nan() || len <= tol * edge {
        return None;
    }
    let normal = n / len;
    Some(Face {
        idx,
        normal,
        dist: normal.dot(p),
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
    let diff = MinkowskiDiff { a, b };
    let mut verts: Vec<Vertex> = Vec::with_capacity(EPA_MAX_ITERATIONS + 8);
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
        push(&mut verts, Vec3::X);
    }
    let tol = 64.0 * EPSILON;
    // Grow to a segment.
    if verts.len() == 1 {
        for d in sample_directions() {
            push(&mut verts, d);
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
            push(&mut verts, e1 * ang.cos() + e2 * ang.sin());
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
    let mut faces: Vec<Face> = Vec::new();
    if verts.len() == 3 {
        let n = (verts[1].w - verts[0].w)
            .cross(verts[2].w - verts[0].w)
            .normalize_or_zero();
        let first = if n.dot(verts[0].w) > 0.0 { -n } else { n };
        for dir in [first, -first] {
            push(&mut verts, dir);
            let h = (verts[3].w - verts[0].w).dot(n).abs();
            scale = scale.max(verts[3].w.length());
            if n != Vec3::ZERO && h > tol * scale {
                break;
            }
            verts.pop();
        }
    }
    if verts.len() == 4 {
        build_faces(
            &verts,
            &[[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]],
            &mut faces,
            tol,
        );
    }
    if faces.is_empty() {
        return None;
    }
    Some(expand(&diff, verts, faces, scale))
}

/// Adds the faces `tris`, oriented away from the polytope's centroid; clears `faces` if any
/// face is degenerate.
fn build_faces(verts: &[Vertex], tris: &[[usize; 3]], faces: &mut Vec<Face>, tol: Real) {
    let n = tris.iter().flatten().max().map_or(0, |m| m + 1);
    let centroid = verts[..n].iter().fold(Vec3::ZERO, |acc, v| acc + v.w) / n.max(1) as Real;
    for &t in tris {
        let Some(mut f) = make_face(verts, t, tol) else {
            faces.clear();
            return;
        };
        if f.normal.dot(centroid - verts[t[0]].w) > 0.0 {
            f = make_face(verts, [t[0], t[2], t[1]], tol).expect("same triangle");
        }
        faces.push(f);
    }
}

fn result_from_face(verts: &[Vertex], f: &Face) -> Penetration {
    let tri = [verts[f.idx[0]].w, verts[f.idx[1]].w, verts[f.idx[2]].w];
    let sol = closest_to_origin(&tri);
    let mut pa = Vec3::ZERO;
    let mut pb = Vec3::ZERO;
    for k in 0..3 {
        pa += verts[f.idx[k]].a * sol.lambda[k];
        pb += verts[f.idx[k]].b * sol.lambda[k];
    }
    let depth = f.dist.max(0.0);
    Penetration {
        depth,
        normal: f.normal,
        point_a: pa,
        point_b: pb,
    }
}

fn expand<A: Support, B: Support>(
    diff: &MinkowskiDiff<A, B>,
    mut verts: Vec<Vertex>,
    mut faces: Vec<Face>,
    mut scale: Real,
) -> Penetration {
    let tol = 64.0 * EPSILON;
    let mut best = faces[0];
    let mut edges: Vec<(usize, usize)> = Vec::new();
    let mut new_faces: Vec<Face> = Vec::new();
    let mut visible: Vec<bool> = Vec::new();
    let mut stack: Vec<usize> = Vec::new();
    for _ in 0..EPA_MAX_ITERATIONS {
        best = *faces
            .iter()
            .min_by(|x, y| x.dist.total_cmp(&y.dist))
            .expect("non-empty polytope");
        let (w, pa, pb) = diff.support_pair(best.normal);
        if !w.is_finite() {
            break;
        }
        scale = scale.max(w.length());
        let gap = best.normal.dot(w) - best.dist;
        if gap <= EPA_REL_TOL * scale.max(EPSILON) {
            break;
        }
        let k = verts.len();
        verts.push(Vertex { w, a: pa, b: pb });
        // Faces that see w, by flood fill from the best face across shared edges, so the
        // removed region is connected and its boundary is one horizon loop.
        let vis_eps = EPSILON * scale;
        let sees = |f: &Face| f.normal.dot(w - verts[f.idx[0]].w) > vis_eps;
        visible.clear();
        visible.resize(faces.len(), false);
        let start = faces
            .iter()
            .position(|f| f.idx == best.idx)
            .expect("best is a face");
        visible[start] = true;
        stack.clear();
        stack.push(start);
        edges.clear();
        while let Some(fi) = stack.pop() {
            let f = faces[fi];
            for e in 0..3 {
                let (i, j) = (f.idx[e], f.idx[(e + 1) % 3]);
                let neighbour = faces.iter().position(|g| {
                    (g.idx[0] == j && g.idx[1] == i)
                        || (g.idx[1] == j && g.idx[2] == i)
                        || (g.idx[2] == j && g.idx[0] == i)
                });
                match neighbour {
                    Some(g) if visible[g] => {}
                    Some(g) if sees(&faces[g]) => {
                        visible[g] = true;
                        stack.push(g);
                    }
                    _ => edges.push((i, j)),
                }
            }
        }
        // Horizon edges whose far side turned visible later are interior after all.
        let horizon: Vec<(usize, usize)> = edges
            .iter()
            .copied()
            .filter(|&(i, j)| {
                !faces.iter().enumerate().any(|(g, f)| {
                    visible[g]
                        && ((f.idx[0] == j && f.idx[1] == i)
                            || (f.idx[1] == j && f.idx[2] == i)
                            || (f.idx[2] == j && f.idx[0] == i))
                })
            })
            .collect();
        new_faces.clear();
        let mut ok = !horizon.is_empty();
        for &(i, j) in &horizon {
            match make_face(&verts, [i, j, k], tol) {
                // EPA's lower bound never decreases; a closer new face means round-off
                // has broken convexity: stop with the best face so far.
                Some(f) if f.dist >= best.dist - EPA_REL_TOL * scale - vis_eps => new_faces.push(f),
                _ => {
                    ok = false;
                    break;
                }
            }
        }
        if !ok {
            break;
        }
        let mut g = 0;
        faces.retain(|_| {
            g += 1;
            !visible[g - 1]
        });
        faces.append(&mut new_faces);
    }
    // Coplanar faces tie on distance; the origin's projection lies inside only one of them.
    // Among the faces within tolerance of the best, take the one whose triangle is truly
    // closest to the origin, so the witnesses satisfy `a - b = depth * normal`.
    let slack = EPA_REL_TOL * scale.max(EPSILON) * 4.0;
    let mut pick = best;
    let mut pick_d = Real::INFINITY;
    for f in faces.iter().filter(|f| f.dist <= best.dist + slack) {
        let tri = [verts[f.idx[0]].w, verts[f.idx[1]].w, verts[f.idx[2]].w];
        let d = closest_to_origin(&tri).point(&tri).length_squared();
        if d < pick_d {
            pick_d = d;
            pick = *f;
        }
    }
    result_from_face(&verts, &pick)
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
