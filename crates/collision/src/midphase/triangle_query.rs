//! Exact per-triangle tests used at the leaves: watertight ray–triangle intersection and the
//! closest point of a triangle to a point. Both are total: degenerate (zero-area) triangles
//! give a miss or a finite answer, never NaN.

use crate::math::{Real, Vec3};

/// A ray hit on one triangle: parameter and barycentric weights of the three corners.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriangleRayHit {
    /// Ray parameter: the hit point is `origin + t · dir`.
    pub t: Real,
    /// Weights of the corners `a, b, c` (non-negative, sum 1).
    pub barycentric: [Real; 3],
}

/// Watertight ray–triangle intersection of Woop, Benthin and Wald, "Watertight
/// Ray/Triangle Intersection" (JCGT 2013), two-sided. The vertices are sheared into a frame
/// where the ray is the +z axis and the three 2D edge functions decide the hit; an edge shared
/// by two triangles gives exactly opposite edge functions in both, so a ray through a shared
/// edge or vertex never slips between them. Rays lying in the triangle's plane miss, as do
/// degenerate triangles seen edge-on. Returns hits with `t ∈ [0, max_t]`.
#[inline]
pub fn ray_triangle(
    origin: Vec3,
    dir: Vec3,
    max_t: Real,
    tri: &[Vec3; 3],
) -> Option<TriangleRayHit> {
    WatertightRay::new(origin, dir)?.intersect(tri, max_t)
}

/// A ray prepared once for [`ray_triangle`]'s test against many triangles: the permuted
/// axes and the shear constants.
#[derive(Debug, Clone, Copy)]
pub struct WatertightRay {
    origin: Vec3,
    k: [usize; 3],
    shear: Vec3,
}

impl WatertightRay {
    /// Prepares the ray; `None` for a zero or non-finite direction.
    #[inline]
    pub fn new(origin: Vec3, dir: Vec3) -> Option<Self> {
        // Axis of the largest direction component becomes z; swap x, y to keep winding.
        let ad = dir.abs();
        let kz = if ad.x >= ad.y && ad.x >= ad.z {
            0
        } else if ad.y >= ad.z {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        if dir[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let dz = dir[kz];
        if dz == 0.0 || !dir.is_finite() || !origin.is_finite() {
            return None;
        }
        Some(WatertightRay {
            origin,
            k: [kx, ky, kz],
            shear: Vec3::new(dir[kx] / dz, dir[ky] / dz, 1.0 / dz),
        })
    }

    /// The hit on `tri` with `t ∈ [0, max_t]`, if any. The axis permutation is one of six;
    /// each gets its own copy of the test with fixed components (a predictable branch per
    /// triangle instead of three indexed loads per corner, which made the test about a
    /// hundred instructions longer in the raytests batch). Same arithmetic, same bits.
    #[inline(always)]
    pub fn intersect(&self, tri: &[Vec3; 3], max_t: Real) -> Option<TriangleRayHit> {
        match self.k {
            [1, 2, 0] => self.intersect_in(tri, max_t, |v| [v.y, v.z, v.x]),
            [2, 1, 0] => self.intersect_in(tri, max_t, |v| [v.z, v.y, v.x]),
            [2, 0, 1] => self.intersect_in(tri, max_t, |v| [v.z, v.x, v.y]),
            [0, 2, 1] => self.intersect_in(tri, max_t, |v| [v.x, v.z, v.y]),
            [0, 1, 2] => self.intersect_in(tri, max_t, |v| [v.x, v.y, v.z]),
            [1, 0, 2] => self.intersect_in(tri, max_t, |v| [v.y, v.x, v.z]),
            // `new` makes no other permutation.
            [kx, ky, kz] => self.intersect_in(tri, max_t, |v| [v[kx], v[ky], v[kz]]),
        }
    }

    /// [`WatertightRay::intersect`] with the permutation `perm` (`[v[kx], v[ky], v[kz]]`).
    #[inline(always)]
    fn intersect_in(
        &self,
        tri: &[Vec3; 3],
        max_t: Real,
        perm: impl Fn(Vec3) -> [Real; 3],
    ) -> Option<TriangleRayHit> {
        let (sx, sy, sz) = (self.shear.x, self.shear.y, self.shear.z);
        let a = perm(tri[0] - self.origin);
        let b = perm(tri[1] - self.origin);
        let c = perm(tri[2] - self.origin);
        let (ax, ay) = (a[0] - sx * a[2], a[1] - sy * a[2]);
        let (bx, by) = (b[0] - sx * b[2], b[1] - sy * b[2]);
        let (cx, cy) = (c[0] - sx * c[2], c[1] - sy * c[2]);
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 || !det.is_finite() {
            return None;
        }
        let t_scaled = u * (sz * a[2]) + v * (sz * b[2]) + w * (sz * c[2]);
        // Range check before dividing, with det's sign folded in.
        let (ts, ds) = if det < 0.0 {
            (-t_scaled, -det)
        } else {
            (t_scaled, det)
        };
        if ts < 0.0 || ts > max_t * ds {
            return None;
        }
        let inv = 1.0 / det;
        let t = t_scaled * inv;
        let bary = [u * inv, v * inv, w * inv];
        if !(t.is_finite() && bary.iter().all(|x| x.is_finite())) || t > max_t {
            return None;
        }
        Some(TriangleRayHit {
            t,
            barycentric: bary,
        })
    }
}

/// Closest point of the segment `[a, b]` to `p` and its parameter (0 for a zero-length
/// segment).
#[inline]
fn closest_on_segment(p: Vec3, a: Vec3, b: Vec3) -> (Vec3, Real) {
    let ab = b - a;
    let len_sq = ab.length_squared();
    let t = if len_sq > 0.0 {
        ((p - a).dot(ab) / len_sq).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + ab * t, t)
}

/// Closest point of a degenerate triangle: the best of its three edges.
fn closest_on_edges(p: Vec3, tri: &[Vec3; 3]) -> (Vec3, [Real; 3]) {
    let mut best = (tri[0], [1.0, 0.0, 0.0]);
    let mut best_d = Real::INFINITY;
    for k in 0..3 {
        let (i, j) = (k, (k + 1) % 3);
        let (q, t) = closest_on_segment(p, tri[i], tri[j]);
        let d = (q - p).length_squared();
        if d < best_d {
            let mut w = [0.0; 3];
            w[i] = 1.0 - t;
            w[j] = t;
            best = (q, w);
            best_d = d;
        }
    }
    best
}

/// Closest point of the triangle to `p` and its barycentric weights: Ericson, "Real-Time
/// Collision Detection" §5.1.5 (`ClosestPtPointTriangle`), the Voronoi-region walk. Degenerate
/// triangles (any denominator not positive) fall back to the closest point of the edges.
pub fn closest_point_on_triangle(p: Vec3, tri: &[Vec3; 3]) -> (Vec3, [Real; 3]) {
    let [a, b, c] = *tri;
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, [1.0, 0.0, 0.0]);
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return (b, [0.0, 1.0, 0.0]);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let den = d1 - d3;
        if den <= 0.0 {
            return closest_on_edges(p, tri);
        }
        let v = (d1 / den).clamp(0.0, 1.0);
        return (a + ab * v, [1.0 - v, v, 0.0]);
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return (c, [0.0, 0.0, 1.0]);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let den = d2 - d6;
        if den <= 0.0 {
            return closest_on_edges(p, tri);
        }
        let w = (d2 / den).clamp(0.0, 1.0);
        return (a + ac * w, [1.0 - w, 0.0, w]);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let den = (d4 - d3) + (d5 - d6);
        if den <= 0.0 {
            return closest_on_edges(p, tri);
        }
        let w = ((d4 - d3) / den).clamp(0.0, 1.0);
        return (b + (c - b) * w, [0.0, 1.0 - w, w]);
    }
    let den = va + vb + vc;
    if den <= 0.0 || !den.is_finite() {
        return closest_on_edges(p, tri);
    }
    let v = vb / den;
    let w = vc / den;
    let q = a + ab * v + ac * w;
    if !q.is_finite() {
        return closest_on_edges(p, tri);
    }
    (q, [1.0 - v - w, v, w])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri() -> [Vec3; 3] {
        [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ]
    }

    #[test]
    fn ray_hits_interior_both_sides() {
        let t = tri();
        let h = ray_triangle(Vec3::new(0.25, 0.25, 2.0), -Vec3::Z, 10.0, &t).unwrap();
        assert!((h.t - 2.0).abs() < 1e-6);
        let p = t[0] * h.barycentric[0] + t[1] * h.barycentric[1] + t[2] * h.barycentric[2];
        assert!((p - Vec3::new(0.25, 0.25, 0.0)).length() < 1e-6);
        assert!(ray_triangle(Vec3::new(0.25, 0.25, -2.0), Vec3::Z, 10.0, &t).is_some());
        assert!(ray_triangle(Vec3::new(0.25, 0.25, 2.0), -Vec3::Z, 1.0, &t).is_none());
        assert!(ray_triangle(Vec3::new(0.25, 0.25, 2.0), Vec3::Z, 10.0, &t).is_none());
        assert!(ray_triangle(Vec3::new(0.8, 0.8, 2.0), -Vec3::Z, 10.0, &t).is_none());
    }

    #[test]
    fn ray_in_plane_and_degenerate_never_nan() {
        let t = tri();
        assert!(ray_triangle(Vec3::new(-1.0, 0.25, 0.0), Vec3::X, 10.0, &t).is_none());
        let flat = [Vec3::ZERO, Vec3::X, Vec3::X * 2.0];
        assert!(ray_triangle(Vec3::new(0.5, 0.0, 1.0), -Vec3::Z, 10.0, &flat).is_none());
        let point = [Vec3::ONE; 3];
        assert!(ray_triangle(Vec3::new(1.0, 1.0, 3.0), -Vec3::Z, 10.0, &point).is_none());
        assert!(ray_triangle(Vec3::ZERO, Vec3::ZERO, 10.0, &t).is_none());
    }

    #[test]
    fn closest_point_regions_and_degenerate() {
        let t = tri();
        let cases = [
            (Vec3::new(0.2, 0.2, 1.0), Vec3::new(0.2, 0.2, 0.0)),
            (Vec3::new(-1.0, -1.0, 0.0), t[0]),
            (Vec3::new(2.0, -0.5, 0.0), t[1]),
            (Vec3::new(0.5, -1.0, 3.0), Vec3::new(0.5, 0.0, 0.0)),
            (Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.5, 0.5, 0.0)),
        ];
        for (p, want) in cases {
            let (q, w) = closest_point_on_triangle(p, &t);
            assert!((q - want).length() < 1e-6, "{p} -> {q}, want {want}");
            assert!((w.iter().sum::<Real>() - 1.0).abs() < 1e-6);
        }
        for degenerate in [
            [Vec3::ONE; 3],
            [Vec3::ZERO, Vec3::ZERO, Vec3::X],
            [Vec3::ZERO, Vec3::X, Vec3::X * 3.0],
        ] {
            for p in [
                Vec3::new(0.5, 2.0, 0.0),
                Vec3::new(-1.0, 0.0, 0.0),
                Vec3::ONE,
            ] {
                let (q, w) = closest_point_on_triangle(p, &degenerate);
                assert!(q.is_finite() && w.iter().all(|x| x.is_finite()));
                let (best, _) = closest_on_edges(p, &degenerate);
                assert!(((q - p).length() - (best - p).length()).abs() < 1e-5);
            }
        }
    }
}
