//! The distance sub-algorithm of GJK: the point of a simplex (1 to 4 points) closest to the
//! origin, with its barycentric coordinates and the smallest sub-simplex that supports it.
//!
//! This is the signed-volumes method of Montanari, Petrinic and Barbieri, "Improving the GJK
//! algorithm for faster and more reliable distance queries between convex objects" (ACM TOG
//! 2017): instead of Johnson's determinant recursion over all sub-simplices, the origin's
//! projection onto the simplex's affine hull is located by signed volumes (areas, lengths);
//! when a barycentric coordinate is not positive, only the facets opposite those vertices
//! are searched, and the closest candidate wins. Degenerate simplices (coincident, collinear,
//! coplanar points) are detected with scale-relative thresholds and fall back to their facets,
//! so the solver never divides by zero and never returns NaN.

use crate::math::{Real, Vec3, EPSILON};

/// Barycentric solution: `mask` bit `i` set when vertex `i` is in the support set, and
/// `lambda[i]` its weight (zero for vertices outside the set). Weights sum to one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Barycentric {
    /// Support-set bit mask over the input points.
    pub mask: u8,
    /// Barycentric weights.
    pub lambda: [Real; 4],
}

impl Barycentric {
    fn vertex(i: usize) -> Self {
        let mut lambda = [0.0; 4];
        lambda[i] = 1.0;
        Barycentric {
            mask: 1 << i,
            lambda,
        }
    }

    /// The closest point `Σ λᵢ pᵢ`.
    #[inline]
    pub fn point(&self, p: &[Vec3]) -> Vec3 {
        let mut v = Vec3::ZERO;
        for (i, &pi) in p.iter().enumerate() {
            if self.mask & (1 << i) != 0 {
                v += pi * self.lambda[i];
            }
        }
        v
    }
}

/// Relative threshold below which a simplex is considered degenerate.
const DEGENERATE: Real = 64.0 * EPSILON;

/// Closest point to the origin on the simplex `p` (1 to 4 points).
pub fn closest_to_origin(p: &[Vec3]) -> Barycentric {
    match p.len() {
        1 => Barycentric::vertex(0),
        2 => s1d(p, [0, 1]),
        3 => s2d(p, [0, 1, 2]),
        _ => s3d(p),
    }
}

/// Remaps a solution over `idx` to the caller's indices.
fn remap<const N: usize>(idx: [usize; N], lambda: [Real; N]) -> Barycentric {
    let mut out = Barycentric {
        mask: 0,
        lambda: [0.0; 4],
    };
    for k in 0..N {
        if lambda[k] > 0.0 {
            out.mask |= 1 << idx[k];
            out.lambda[idx[k]] = lambda[k];
        }
    }
    if out.mask == 0 {
        return Barycentric::vertex(idx[0]);
    }
    out
}

/// Segment `p[i0], p[i1]`.
fn s1d(p: &[Vec3], idx: [usize; 2]) -> Barycentric {
    let (a, b) = (p[idx[0]], p[idx[1]]);
    let ab = b - a;
    let len_sq = ab.length_squared();
    if len_sq <= (DEGENERATE * a.abs().max(b.abs()).max_element()).powi(2) || len_sq == 0.0 {
        // Coincident points: keep the one closer to the origin (the first on ties).
        return if b.length_squared() < a.length_squared() {
            Barycentric::vertex(idx[1])
        } else {
            Barycentric::vertex(idx[0])
        };
    }
    let t = -a.dot(ab) / len_sq;
    if t <= 0.0 {
        Barycentric::vertex(idx[0])
    } else if t >= 1.0 {
        Barycentric::vertex(idx[1])
    } else {
        remap(idx, [1.0 - t, t])
    }
}

/// The candidate of smallest norm among facet solutions.
fn best_of(p: &[Vec3], candidates: impl Iterator<Item = Barycentric>) -> Barycentric {
    let mut best: Option<(Real, Barycentric)> = None;
    for c in candidates {
        let d = c.point(p).length_squared();
        if best.is_none_or(|(bd, _)| d < bd) {
            best = Some((d, c));
        }
    }
    best.map(|(_, c)| c).unwrap_or(Barycentric::vertex(0))
}

/// Triangle `p[i0], p[i1], p[i2]`.
fn s2d(p: &[Vec3], idx: [usize; 3]) -> Barycentric {
    let (a, b, c) = (p[idx[0]], p[idx[1]], p[idx[2]]);
    let n = (b - a).cross(c - a);
    let nn = n.length_squared();
    let edge_sq = (b - a)
        .length_squared()
        .max((c - a).length_squared())
        .max((c - b).length_squared());
    if nn <= (DEGENERATE * edge_sq).powi(2) || nn == 0.0 {
        let edges = [[idx[0], idx[1]], [idx[1], idx[2]], [idx[0], idx[2]]];
        return best_of(p, edges.into_iter().map(|e| s1d(p, e)));
    }
    // Projection of the origin on the plane; signed areas relative to it are well
    // conditioned because q lies near the triangle when the triangle is near the origin.
    let q = n * (n.dot(a) / nn);
    let la = n.dot((b - q).cross(c - q));
    let lb = n.dot((c - q).cross(a - q));
    let lc = n.dot((a - q).cross(b - q));
    if la > 0.0 && lb > 0.0 && lc > 0.0 {
        let s = la + lb + lc;
        return remap(idx, [la / s, lb / s, lc / s]);
    }
    // Search the edges opposite the vertices with non-positive weights.
    let opposite = [[idx[1], idx[2]], [idx[0], idx[2]], [idx[0], idx[1]]];
    let lam = [la, lb, lc];
    best_of(
        p,
        (0..3)
            .filter(|&k| lam[k] <= 0.0)
            .map(|k| s1d(p, opposite[k])),
    )
}

/// Tetrahedron `p[0..4]`.
fn s3d(p: &[Vec3]) -> Barycentric {
    let (a, b, c, d) = (p[0], p[1], p[2], p[3]);
    let vol = (b - a).dot((c - a).cross(d - a));
    let scale = [b - a, c - a, d - a, c - b, d - b, d - c]
        .iter()
        .map(|e| e.length_squared())
        .fold(0.0, Real::max);
    let faces = [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]];
    if vol.abs() <= DEGENERATE * scale * scale.sqrt() || vol == 0.0 {
        return best_of(p, faces.into_iter().map(|f| s2d(p, f)));
    }
    // Signed volumes with one vertex replaced by the origin (Cramer's rule).
    let c0 = b.dot(c.cross(d));
    let c1 = -a.dot(c.cross(d));
    let c2 = a.dot(b.cross(d));
    let c3 = -a.dot(b.cross(c));
    let cs = [c0, c1, c2, c3];
    let same = |x: Real| x * vol.signum() > 0.0;
    if cs.iter().all(|&x| same(x)) {
        let s = c0 + c1 + c2 + c3;
        return Barycentric {
            mask: 0b1111,
            lambda: [c0 / s, c1 / s, c2 / s, c3 / s],
        };
    }
    best_of(
        p,
        (0..4).filter(|&k| !same(cs[k])).map(|k| s2d(p, faces[k])),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Brute force: closest point over all sub-simplices by dense barycentric sampling is
    /// too slow; instead compare with the exact closest point on each feature computed by
    /// projection and clamping checks.
    #[allow(clippy::needless_range_loop)]
    fn brute(p: &[Vec3]) -> Real {
        let n = p.len();
        let mut best = Real::INFINITY;
        for mask in 1u8..(1 << n) {
            let pts: Vec<Vec3> = (0..n)
                .filter(|i| mask & (1 << i) != 0)
                .map(|i| p[i])
                .collect();
            // Affine projection via least squares on the sub-simplex (Gram matrix).
            let m = pts.len();
            if m == 1 {
                best = best.min(pts[0].length());
                continue;
            }
            let e: Vec<Vec3> = pts[1..].iter().map(|q| *q - pts[0]).collect();
            let mut g = [[0.0 as Real; 3]; 3];
            let mut r = [0.0 as Real; 3];
            for i in 0..m - 1 {
                for j in 0..m - 1 {
                    g[i][j] = e[i].dot(e[j]);
                }
                r[i] = -pts[0].dot(e[i]);
            }
            // Solve with Gaussian elimination (small, well-conditioned in tests).
            let k = m - 1;
            let mut x = [0.0 as Real; 3];
            let mut a = g;
            let mut bvec = r;
            for col in 0..k {
                let piv = a[col][col];
                if piv.abs() < 1e-9 {
                    continue;
                }
                for row in col + 1..k {
                    let f = a[row][col] / piv;
                    for cc in col..k {
                        a[row][cc] -= f * a[col][cc];
                    }
                    bvec[row] -= f * bvec[col];
                }
            }
            for col in (0..k).rev() {
                let mut s = bvec[col];
                for cc in col + 1..k {
                    s -= a[col][cc] * x[cc];
                }
                x[col] = s / a[col][col];
            }
            let l0 = 1.0 - x[..k].iter().sum::<Real>();
            if l0 >= 0.0 && x[..k].iter().all(|&v| v >= 0.0) {
                let mut q = pts[0];
                for i in 0..k {
                    q += e[i] * x[i];
                }
                best = best.min(q.length());
            }
        }
        best
    }

    #[test]
    fn matches_brute_force_on_random_simplices() {
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 33) as f64 / (1u64 << 31) as f64 * 2.0 - 1.0) as Real
        };
        let mut interior = 0;
        for _ in 0..2000 {
            let n = 2 + (rnd().abs() * 2.99) as usize;
            let p: Vec<Vec3> = (0..n)
                .map(|_| Vec3::new(rnd(), rnd(), rnd()) * 2.0 + Vec3::new(0.3, 0.1, -0.2))
                .collect();
            let sol = closest_to_origin(&p);
            let got = sol.point(&p).length();
            let want = brute(&p);
            if sol.mask.count_ones() as usize == n {
                interior += 1;
            }
            assert!((got - want).abs() < 1e-4, "{p:?}: {got} vs {want}");
            let sum: Real = sol.lambda.iter().sum();
            assert!((sum - 1.0).abs() < 1e-4);
        }
        assert!(interior > 50, "interior case too rare: {interior}");
    }

    #[test]
    fn degenerate_simplices_are_finite() {
        let a = Vec3::new(1.0, 1.0, 1.0);
        let cases: Vec<Vec<Vec3>> = vec![
            vec![a, a],
            vec![a, a, a],
            vec![a, a * 2.0, a * 3.0],
            vec![a, a, a, a],
            vec![Vec3::X, Vec3::Y, -Vec3::X - Vec3::Y, Vec3::X + Vec3::Y],
            vec![Vec3::ZERO, Vec3::X, Vec3::X * 2.0, Vec3::X * 3.0],
        ];
        for p in cases {
            let s = closest_to_origin(&p);
            let v = s.point(&p);
            assert!(v.is_finite());
            assert!((v.length() - brute(&p)).abs() < 1e-4, "{p:?}");
        }
    }
}
