//! Closest points between elementary features: point–segment, segment–segment and
//! point–triangle, after Ericson, "Real-Time Collision Detection" (2005), §5.1.

use crate::math::{Real, Vec3, EPSILON};

/// Closest point to `p` on the segment `[a, b]`, and its parameter in `[0, 1]`.
#[inline]
pub fn closest_point_segment(p: Vec3, a: Vec3, b: Vec3) -> (Vec3, Real) {
    let ab = b - a;
    let len_sq = ab.length_squared();
    if len_sq <= 0.0 {
        return (a, 0.0);
    }
    let t = ((p - a).dot(ab) / len_sq).clamp(0.0, 1.0);
    (a + ab * t, t)
}

/// Closest points of the segments `[p1, q1]` and `[p2, q2]` (Ericson §5.1.9): returns
/// `(c1, c2)`. Parallel segments give one of the closest pairs (deterministically), and
/// degenerate segments (points) are handled.
pub fn closest_points_segment_segment(p1: Vec3, q1: Vec3, p2: Vec3, q2: Vec3) -> (Vec3, Vec3) {
    let d1 = q1 - p1;
    let d2 = q2 - p2;
    let r = p1 - p2;
    let a = d1.length_squared();
    let e = d2.length_squared();
    let f = d2.dot(r);
    let tiny = EPSILON * EPSILON;
    let (s, t);
    if a <= tiny && e <= tiny {
        return (p1, p2);
    }
    if a <= tiny {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = d1.dot(r);
        if e <= tiny {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            // Non-parallel: closest point on line 1 to line 2, clamped. Parallel: s = 0.
            let mut s0 = if denom > EPSILON * a * e {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t0 = (b * s0 + f) / e;
            if t0 < 0.0 {
                t0 = 0.0;
                s0 = (-c / a).clamp(0.0, 1.0);
            } else if t0 > 1.0 {
                t0 = 1.0;
                s0 = ((b - c) / a).clamp(0.0, 1.0);
            }
            s = s0;
            t = t0;
        }
    }
    (p1 + d1 * s, p2 + d2 * t)
}

/// Closest point to `p` on the triangle `(a, b, c)` (Ericson §5.1.5, Voronoi regions).
/// Degenerate triangles give the closest point on their edges.
pub fn closest_point_triangle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    let ab = b - a;
    let ac = c - a;
    if a == b || a == c || b == c {
        // A repeated corner: the edge regions below would divide 0 by 0.
        return closest_point_on_edges(p, a, b, c);
    }
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return a + ab * v;
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return a + ac * w;
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return b + (c - b) * w;
    }
    let sum = va + vb + vc;
    if sum == 0.0 || !sum.is_finite() {
        // Degenerate (zero-area) triangle: best of the edges.
        return closest_point_on_edges(p, a, b, c);
    }
    let denom = 1.0 / sum;
    let v = vb * denom;
    let w = vc * denom;
    a + ab * v + ac * w
}

/// The closest point to `p` on the edges of the triangle `(a, b, c)`: the answer for a
/// triangle without area (a segment or a point).
fn closest_point_on_edges(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    let cands = [
        closest_point_segment(p, a, b).0,
        closest_point_segment(p, b, c).0,
        closest_point_segment(p, a, c).0,
    ];
    cands
        .into_iter()
        .min_by(|x, y| {
            (*x - p)
                .length_squared()
                .total_cmp(&(*y - p).length_squared())
        })
        .expect("three candidates")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rnd(seed: &mut u64) -> Real {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((*seed >> 33) as f64 / (1u64 << 31) as f64 * 2.0 - 1.0) as Real
    }

    #[test]
    fn segment_segment_matches_dense_sampling() {
        let mut seed = 7;
        for _ in 0..200 {
            let mut v = || Vec3::new(rnd(&mut seed), rnd(&mut seed), rnd(&mut seed));
            let (p1, q1, p2, q2) = (v(), v(), v(), v());
            let (c1, c2) = closest_points_segment_segment(p1, q1, p2, q2);
            let got = (c1 - c2).length();
            let mut best = Real::INFINITY;
            let n = 200;
            for i in 0..=n {
                let a = p1 + (q1 - p1) * (i as Real / n as Real);
                best = best.min((closest_point_segment(a, p2, q2).0 - a).length());
            }
            assert!(got <= best + 1e-5 && got >= best - 2e-2, "{got} vs {best}");
        }
    }

    #[test]
    fn parallel_and_degenerate_segments() {
        let (c1, c2) = closest_points_segment_segment(
            Vec3::ZERO,
            Vec3::X,
            Vec3::new(0.5, 1.0, 0.0),
            Vec3::new(2.0, 1.0, 0.0),
        );
        assert!(((c1 - c2).length() - 1.0).abs() < 1e-6);
        let (c1, c2) = closest_points_segment_segment(Vec3::ZERO, Vec3::ZERO, Vec3::Y, Vec3::Y);
        assert_eq!((c1, c2), (Vec3::ZERO, Vec3::Y));
    }

    #[test]
    fn triangle_matches_dense_sampling() {
        let mut seed = 99;
        for _ in 0..200 {
            let mut v = || Vec3::new(rnd(&mut seed), rnd(&mut seed), rnd(&mut seed));
            let (p, a, b, c) = (v() * 2.0, v(), v(), v());
            let q = closest_point_triangle(p, a, b, c);
            let got = (q - p).length();
            let n = 60;
            let mut best = Real::INFINITY;
            for i in 0..=n {
                for j in 0..=(n - i) {
                    let (u, w) = (i as Real / n as Real, j as Real / n as Real);
                    best = best.min((a + (b - a) * u + (c - a) * w - p).length());
                }
            }
            assert!(got <= best + 1e-5 && got >= best - 5e-2, "{got} vs {best}");
        }
        // Degenerate triangle.
        let q = closest_point_triangle(Vec3::Y, Vec3::ZERO, Vec3::X, Vec3::X * 2.0);
        assert!(q.is_finite() && (q - Vec3::ZERO).length() < 1e-6);
        // Repeated corners (a segment, a point): every order of the corners, and points in
        // every region (session 27: `a == b` divided 0 by 0 and returned NaN).
        let (s, t) = (Vec3::new(1.0, 0.0, 0.0), Vec3::new(3.0, 0.0, 0.0));
        for p in [
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(2.0, 1.0, 0.5),
            Vec3::new(4.0, -1.0, 0.0),
        ] {
            let want = closest_point_segment(p, s, t).0;
            for (a, b, c) in [(s, s, t), (s, t, s), (t, s, s), (s, t, t)] {
                let q = closest_point_triangle(p, a, b, c);
                assert!((q - want).length() < 1e-6, "{p} on {a} {b} {c}: {q}");
            }
            assert_eq!(closest_point_triangle(p, s, s, s), s);
        }
    }
}
