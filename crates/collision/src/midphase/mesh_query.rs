//! Triangle-mesh queries over a [`Bvh`]: box overlap (the midphase of convex-vs-mesh), rays
//! (closest, any, all hits), closest point within a bound, and mesh-vs-mesh triangle pairs.
//!
//! Every query has a brute-force twin in [`brute_force`] that tests all triangles with the
//! same exact leaf test; the BVH versions return identical results (ties on distance are
//! broken by the smaller triangle index, so results do not depend on the visit order).

use super::triangle_query::{closest_point_on_triangle, TriangleRayHit, WatertightRay};
use crate::bvh::Bvh;
use crate::math::{Aabb, Isometry, Real, Vec3, EPSILON};

/// A ray hit on a mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshRayHit {
    /// Index of the triangle hit.
    pub triangle: u32,
    /// Ray parameter: the hit point is `origin + t · dir` (the distance when `dir` is unit).
    pub t: Real,
    /// Barycentric weights of the triangle's corners at the hit.
    pub barycentric: [Real; 3],
    /// Hit point.
    pub point: Vec3,
    /// Unit face normal of the triangle (counter-clockwise front), not flipped toward the
    /// ray. A degenerate triangle that is hit reports `-dir` normalised.
    pub normal: Vec3,
}

/// The closest point of a mesh to a query point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshPointProjection {
    /// Index of the triangle holding the closest point.
    pub triangle: u32,
    /// The closest point.
    pub point: Vec3,
    /// Distance from the query point.
    pub distance: Real,
    /// Barycentric weights of the triangle's corners at the closest point.
    pub barycentric: [Real; 3],
}

/// A borrowed triangle mesh with its BVH; the queries of this module live on it.
#[derive(Debug, Clone, Copy)]
pub struct MeshView<'a> {
    /// Hierarchy over the triangles (primitive `i` is triangle `i`).
    pub bvh: &'a Bvh,
    /// Vertices.
    pub vertices: &'a [Vec3],
    /// Triangles as vertex index triples.
    pub indices: &'a [[u32; 3]],
}

/// Factor admitting candidates tied with the best hit so far (see `ray_closest`).
pub(crate) const TIE_SLACK: Real = 1.0 + 8.0 * EPSILON;

/// The prepared ray, or `None` for an invalid ray (non-finite, zero direction, NaN or
/// negative `max_t`).
#[inline]
fn prepared(origin: Vec3, dir: Vec3, max_t: Real) -> Option<WatertightRay> {
    if max_t >= 0.0 {
        WatertightRay::new(origin, dir)
    } else {
        None
    }
}

/// Leaf ray test shared by the BVH and brute-force paths.
#[inline]
fn ray_hit(
    ray: &WatertightRay,
    tri: &[Vec3; 3],
    index: u32,
    origin: Vec3,
    dir: Vec3,
    max_t: Real,
) -> Option<MeshRayHit> {
    Some(complete_hit(
        tri,
        index,
        origin,
        dir,
        ray.intersect(tri, max_t)?,
    ))
}

/// A mesh hit from a triangle hit: point and unit face normal.
#[inline]
fn complete_hit(
    tri: &[Vec3; 3],
    index: u32,
    origin: Vec3,
    dir: Vec3,
    h: TriangleRayHit,
) -> MeshRayHit {
    let normal = (tri[1] - tri[0])
        .cross(tri[2] - tri[0])
        .try_normalize()
        .unwrap_or_else(|| -dir.normalize_or_zero());
    MeshRayHit {
        triangle: index,
        t: h.t,
        barycentric: h.barycentric,
        point: origin + dir * h.t,
        normal,
    }
}

/// The projection from the best `(squared distance, triangle, point, barycentric)`.
#[inline]
pub(crate) fn projection(
    best: Option<(Real, u32, Vec3, [Real; 3])>,
) -> Option<MeshPointProjection> {
    best.map(|(d, i, q, w)| MeshPointProjection {
        triangle: i,
        point: q,
        distance: d.sqrt(),
        barycentric: w,
    })
}

/// The closest point of the triangles `0..n` (corners from `tri`) to `point` within
/// `max_dist`, testing every one (ties to the smaller index): the brute-force oracle.
pub(crate) fn brute_force_closest(
    n: usize,
    tri: impl Fn(u32) -> [Vec3; 3],
    point: Vec3,
    max_dist: Real,
) -> Option<MeshPointProjection> {
    let mut best: Option<(Real, u32, Vec3, [Real; 3])> = None;
    for i in 0..n as u32 {
        let (q, w) = closest_point_on_triangle(point, &tri(i));
        let d = (q - point).length_squared();
        if d <= max_dist * max_dist && better(d, i, best.map(|b| (b.0, b.1))) {
            best = Some((d, i, q, w));
        }
    }
    projection(best)
}

/// True when `(t, i)` orders before `best` (ties broken by the smaller index).
#[inline]
fn better(t: Real, i: u32, best: Option<(Real, u32)>) -> bool {
    match best {
        None => true,
        Some((bt, bi)) => t < bt || (t == bt && i < bi),
    }
}

impl<'a> MeshView<'a> {
    /// The corners of triangle `i`.
    #[inline]
    pub fn triangle(&self, i: u32) -> [Vec3; 3] {
        let t = self.indices[i as usize];
        [
            self.vertices[t[0] as usize],
            self.vertices[t[1] as usize],
            self.vertices[t[2] as usize],
        ]
    }

    /// Calls `f(triangle)` for every triangle whose bounding box overlaps `aabb` (touching
    /// counts); `f` returns `false` to stop.
    pub fn for_each_triangle_in_aabb(&self, aabb: &Aabb, mut f: impl FnMut(u32) -> bool) {
        self.bvh.for_each_candidate_in_aabb(aabb, |i| {
            let t = self.triangle(i);
            if Aabb::from_points(t).intersects(aabb) {
                f(i)
            } else {
                true
            }
        });
    }

    /// Triangles whose bounding boxes overlap `aabb`, appended to `out` in ascending order.
    pub fn triangles_in_aabb(&self, aabb: &Aabb, out: &mut Vec<u32>) {
        let start = out.len();
        self.for_each_triangle_in_aabb(aabb, |i| {
            out.push(i);
            true
        });
        out[start..].sort_unstable();
    }

    /// The closest hit of the ray `origin + t·dir`, `t ∈ [0, max_t]`.
    pub fn ray_closest(&self, origin: Vec3, dir: Vec3, max_t: Real) -> Option<MeshRayHit> {
        self.ray_closest_walk(origin, dir, max_t, true)
    }

    /// [`MeshView::ray_closest`] with the stackless escape-index walk instead of the
    /// ordered (near child first) walk: the same result, kept to measure the two
    /// (`carom-bench midphase`).
    pub fn ray_closest_stackless(
        &self,
        origin: Vec3,
        dir: Vec3,
        max_t: Real,
    ) -> Option<MeshRayHit> {
        self.ray_closest_walk(origin, dir, max_t, false)
    }

    /// The closest hit through the ordered or the stackless walk.
    #[inline(always)]
    fn ray_closest_walk(
        &self,
        origin: Vec3,
        dir: Vec3,
        max_t: Real,
        ordered: bool,
    ) -> Option<MeshRayHit> {
        let ray = prepared(origin, dir, max_t)?;
        // Keep (t, triangle) only; the hit is completed once, at the end.
        let mut best: Option<(Real, u32)> = None;
        let mut best_hit = None;
        let mut visit = |i: u32, limit: &mut Real| {
            // Once a hit is known, admit exact ties (the range check before the division
            // can round a tied `t` just above the limit); `better` decides exactly.
            let lim = if best.is_some() {
                *limit * TIE_SLACK
            } else {
                *limit
            };
            if let Some(h) = ray.intersect(&self.triangle(i), lim) {
                if better(h.t, i, best) {
                    *limit = h.t;
                    best = Some((h.t, i));
                    best_hit = Some(h);
                }
            }
            true
        };
        if ordered {
            self.bvh
                .for_each_candidate_on_ray_ordered(origin, dir, max_t, &mut visit);
        } else {
            self.bvh
                .for_each_candidate_on_ray(origin, dir, max_t, &mut visit);
        }
        let (_, i) = best?;
        Some(complete_hit(&self.triangle(i), i, origin, dir, best_hit?))
    }

    /// Some hit of the ray (the first found), for occlusion tests.
    pub fn ray_any(&self, origin: Vec3, dir: Vec3, max_t: Real) -> Option<MeshRayHit> {
        let ray = prepared(origin, dir, max_t)?;
        let mut found = None;
        self.bvh
            .for_each_candidate_on_ray(origin, dir, max_t, |i, limit| {
                found = ray_hit(&ray, &self.triangle(i), i, origin, dir, *limit);
                found.is_none()
            });
        found
    }

    /// Every hit of the ray, appended to `out` sorted by `(t, triangle)`.
    pub fn ray_all(&self, origin: Vec3, dir: Vec3, max_t: Real, out: &mut Vec<MeshRayHit>) {
        let Some(ray) = prepared(origin, dir, max_t) else {
            return;
        };
        let start = out.len();
        self.bvh
            .for_each_candidate_on_ray(origin, dir, max_t, |i, limit| {
                if let Some(h) = ray_hit(&ray, &self.triangle(i), i, origin, dir, *limit) {
                    out.push(h);
                }
                true
            });
        sort_hits(&mut out[start..]);
    }

    /// The closest point of the mesh to `point` if it lies within `max_dist`.
    pub fn closest_point(&self, point: Vec3, max_dist: Real) -> Option<MeshPointProjection> {
        if !point.is_finite() || max_dist.is_nan() || max_dist < 0.0 {
            return None;
        }
        let mut best: Option<(Real, u32, Vec3, [Real; 3])> = None;
        self.bvh
            .for_each_candidate_near_point(point, max_dist * max_dist, |i, bound| {
                let (q, w) = closest_point_on_triangle(point, &self.triangle(i));
                let d = (q - point).length_squared();
                if d <= *bound && better(d, i, best.map(|b| (b.0, b.1))) {
                    *bound = d;
                    best = Some((d, i, q, w));
                }
                true
            });
        projection(best)
    }

    /// Triangle pairs `(a, b)`, `a` of `self` and `b` of `other` placed at `pose_ab` (B's pose
    /// in A's frame), whose bounding boxes overlap in A's frame (B's triangle boxed after
    /// moving its corners). Appended to `out` sorted.
    pub fn triangle_pairs(&self, other: &MeshView, pose_ab: &Isometry, out: &mut Vec<(u32, u32)>) {
        let start = out.len();
        self.bvh
            .for_each_candidate_pair(other.bvh, pose_ab, |a, b| {
                if pair_overlaps(self, other, pose_ab, a, b) {
                    out.push((a, b));
                }
            });
        out[start..].sort_unstable();
    }
}

/// Exact pair test of [`MeshView::triangle_pairs`].
#[inline]
fn pair_overlaps(a: &MeshView, b: &MeshView, pose_ab: &Isometry, ia: u32, ib: u32) -> bool {
    let box_a = Aabb::from_points(a.triangle(ia));
    let tb = b.triangle(ib).map(|p| pose_ab.transform_point(p));
    box_a.intersects(&Aabb::from_points(tb))
}

fn sort_hits(hits: &mut [MeshRayHit]) {
    hits.sort_unstable_by(|x, y| x.t.total_cmp(&y.t).then(x.triangle.cmp(&y.triangle)));
}

/// Brute-force references of every [`MeshView`] query: the same exact leaf tests over all
/// triangles, without the BVH. Used as oracles by the tests and benchmarks.
pub mod brute_force {
    use super::*;

    /// All triangles whose boxes overlap `aabb`, ascending.
    pub fn triangles_in_aabb(m: &MeshView, aabb: &Aabb) -> Vec<u32> {
        (0..m.indices.len() as u32)
            .filter(|&i| Aabb::from_points(m.triangle(i)).intersects(aabb))
            .collect()
    }

    /// Every hit, sorted by `(t, triangle)`.
    pub fn ray_all(m: &MeshView, origin: Vec3, dir: Vec3, max_t: Real) -> Vec<MeshRayHit> {
        let Some(ray) = prepared(origin, dir, max_t) else {
            return Vec::new();
        };
        let mut hits: Vec<MeshRayHit> = (0..m.indices.len() as u32)
            .filter_map(|i| ray_hit(&ray, &m.triangle(i), i, origin, dir, max_t))
            .collect();
        sort_hits(&mut hits);
        hits
    }

    /// The closest hit (smallest `(t, triangle)`).
    pub fn ray_closest(m: &MeshView, origin: Vec3, dir: Vec3, max_t: Real) -> Option<MeshRayHit> {
        ray_all(m, origin, dir, max_t).first().copied()
    }

    /// The closest point within `max_dist` (ties to the smaller triangle index).
    pub fn closest_point(m: &MeshView, point: Vec3, max_dist: Real) -> Option<MeshPointProjection> {
        brute_force_closest(m.indices.len(), |i| m.triangle(i), point, max_dist)
    }

    /// All overlapping triangle pairs, sorted.
    pub fn triangle_pairs(a: &MeshView, b: &MeshView, pose_ab: &Isometry) -> Vec<(u32, u32)> {
        let mut out = Vec::new();
        for ia in 0..a.indices.len() as u32 {
            for ib in 0..b.indices.len() as u32 {
                if pair_overlaps(a, b, pose_ab, ia, ib) {
                    out.push((ia, ib));
                }
            }
        }
        out
    }
}
