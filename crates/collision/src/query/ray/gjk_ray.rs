//! GJK ray cast: van den Bergen, "Ray Casting against General Convex Objects with
//! Application to Continuous Collision Detection" (JGT 2004), with the margin variant of
//! his book (§5.5): the ray hits `C ⊕ ball(radius)` where C is given by a support function.
//!
//! The current point `x = origin + λ·dir` only ever advances to a support plane of the
//! rounded set, so `λ` is a lower bound of the hit parameter that increases monotonically;
//! the simplex (stored as points of C, re-expressed relative to the moving `x`) tracks the
//! closest point of C to `x`. Also used by the linear shape cast, where C is the Minkowski
//! difference `A - B` and the witness points come from the same barycentric weights.

use crate::math::{Real, Vec3, EPSILON};
use crate::query::simplex::closest_to_origin;
use crate::query::support_adapters::{MinkowskiDiff, Support};

/// Iteration cap of the GJK ray cast.
pub const GJK_RAY_MAX_ITERATIONS: usize = 64;

/// A support function that also reports the pair of points behind each support point
/// (for a Minkowski difference `A - B`: the points on A and on B).
pub trait SupportPair {
    /// `(point of C, point on A, point on B)` maximising `dir`.
    fn support_pair(&self, dir: Vec3) -> (Vec3, Vec3, Vec3);
}

impl<A: Support, B: Support> SupportPair for MinkowskiDiff<A, B> {
    #[inline]
    fn support_pair(&self, dir: Vec3) -> (Vec3, Vec3, Vec3) {
        MinkowskiDiff::support_pair(self, dir)
    }
}

/// A single set seen as a [`SupportPair`] (the "B" point is zero).
#[derive(Debug, Clone, Copy)]
pub struct Single<S>(pub S);

impl<S: Support> SupportPair for Single<S> {
    #[inline]
    fn support_pair(&self, dir: Vec3) -> (Vec3, Vec3, Vec3) {
        let p = self.0.support(dir);
        (p, p, Vec3::ZERO)
    }
}

/// A GJK ray-cast hit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GjkRayHit {
    /// Ray parameter of the hit (`origin + lambda * dir`).
    pub lambda: Real,
    /// Outward normal of the (rounded) set at the hit (unit), or `-dir` when the origin was
    /// already inside.
    pub normal: Vec3,
    /// True when the origin was inside (`lambda == 0` without advancing).
    pub inside: bool,
    /// Closest point of the core on A (for a single set: the core point).
    pub core_a: Vec3,
    /// Closest point of the core on B (zero for a single set).
    pub core_b: Vec3,
}

/// Casts `origin + λ·dir`, `λ ∈ [0, max_lambda]`, against `C ⊕ ball(radius)`. `dir` need
/// not be unit. Returns `None` on a miss.
pub fn gjk_raycast<S: SupportPair>(
    c: &S,
    radius: Real,
    origin: Vec3,
    dir: Vec3,
    max_lambda: Real,
) -> Option<GjkRayHit> {
    let mut lambda: Real = 0.0;
    let mut x = origin;
    let mut normal = Vec3::ZERO;
    let (p0, a0, b0) = c.support_pair(dir);
    let mut ps = [Vec3::ZERO; 4];
    let mut pa = [Vec3::ZERO; 4];
    let mut pb = [Vec3::ZERO; 4];
    let mut lam = [0.0 as Real; 4];
    let mut n = 0usize;
    let mut v = x - p0;
    let mut scale = p0.abs().max_element().max(origin.abs().max_element());
    // First closest point guess: the single support point (not in the simplex yet).
    let mut single = (p0, a0, b0);
    let mut converged = false;
    for _ in 0..GJK_RAY_MAX_ITERATIONS {
        let vlen = v.length();
        let tol = 64.0 * EPSILON * scale.max(radius).max(EPSILON);
        if vlen - radius <= tol {
            converged = true;
            break;
        }
        let (p, a, b) = c.support_pair(v);
        scale = scale.max(p.abs().max_element());
        let w = x - p;
        let vw = v.dot(w);
        let mut advanced = false;
        if vw > radius * vlen + tol * vlen {
            let vr = v.dot(dir);
            if vr >= 0.0 {
                return None;
            }
            lambda -= (vw - radius * vlen) / vr;
            if lambda > max_lambda || !lambda.is_finite() {
                return None;
            }
            x = origin + dir * lambda;
            normal = v;
            advanced = true;
        }
        if ps[..n].contains(&p) {
            if !advanced {
                // Nothing new and x did not move: v is the exact closest vector.
                converged = true;
                break;
            }
        } else {
            ps[n] = p;
            pa[n] = a;
            pb[n] = b;
            n += 1;
        }
        let ws: [Vec3; 4] = std::array::from_fn(|i| if i < n { x - ps[i] } else { Vec3::ZERO });
        let sol = closest_to_origin(&ws[..n]);
        let mut m = 0;
        for i in 0..n {
            if sol.mask & (1 << i) != 0 {
                ps[m] = ps[i];
                pa[m] = pa[i];
                pb[m] = pb[i];
                lam[m] = sol.lambda[i];
                m += 1;
            }
        }
        n = m;
        v = (0..n).fold(Vec3::ZERO, |acc, i| acc + (x - ps[i]) * lam[i]);
        single = (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO);
        if n == 4 {
            converged = true;
            v = Vec3::ZERO;
            break;
        }
    }
    if !converged && v.length() - radius > 1e-3 * scale.max(radius) {
        return None;
    }
    let (core_a, core_b) = if n == 0 {
        (single.1, single.2)
    } else {
        (0..n).fold((Vec3::ZERO, Vec3::ZERO), |(sa, sb), i| {
            (sa + pa[i] * lam[i], sb + pb[i] * lam[i])
        })
    };
    let inside = lambda == 0.0;
    // With a margin, the final closest vector (length ≈ radius) is the exact normal of the
    // rounded surface at x; without one it vanishes, and the last support plane's normal
    // (the one x was advanced onto) is the surface normal.
    let vlen = v.length();
    let normal = if inside {
        -dir.normalize_or_zero()
    } else if radius > 0.0 && vlen > 0.5 * radius {
        v / vlen
    } else {
        normal.normalize_or_zero()
    };
    Some(GjkRayHit {
        lambda,
        normal,
        inside,
        core_a,
        core_b,
    })
}
