//! GJK: closest points between two convex sets given by support functions.
//!
//! Gilbert, Johnson and Keerthi (1988), in the form of van den Bergen, "Collision Detection
//! in Interactive 3D Environments" (2003), with the signed-volumes sub-algorithm and the
//! termination criteria of Montanari et al. (2017) (see [`super::simplex`]):
//!
//! 1. `v` is the current closest point of the simplex to the origin (a point of `A - B`).
//! 2. `w = s_{A-B}(-v)`; `v·w / |v|` is a lower bound of the distance, `|v|` an upper bound.
//! 3. Stop when the bounds meet within a relative tolerance, when `w` is already in the
//!    simplex, when `|v|` stops decreasing (round-off), or after [`GJK_MAX_ITERATIONS`].
//! 4. The origin is inside (the sets overlap) when the simplex becomes a tetrahedron that
//!    contains it, or when `|v|` falls below a scale-relative tolerance.
//!
//! Witness points come from the same barycentric weights applied to the support points on
//! A and on B. Everything here is in A's frame; callers place B with a
//! [`super::support_adapters::Transformed`] adapter.

use super::simplex::closest_to_origin;
use super::support_adapters::{MinkowskiDiff, Support};
use crate::math::{Aabb, Isometry, Real, Vec3, EPSILON};
use serde::{Deserialize, Serialize};

/// Iteration cap of GJK (a polytope pair converges in far fewer; smooth shapes stop on the
/// relative tolerance long before).
pub const GJK_MAX_ITERATIONS: usize = 64;

/// Relative tolerance on the duality gap `|v|² - v·w <= GJK_REL_TOL · |v|²`.
pub const GJK_REL_TOL: Real = 16.0 * EPSILON;

/// Scale-relative tolerance below which `|v|` counts as zero (the sets touch or overlap).
pub const GJK_ZERO_TOL: Real = 32.0 * EPSILON;

/// The GJK simplex: up to four points of `A - B` with their support points on A and B.
#[derive(Debug, Clone, Copy, Default)]
pub struct Simplex {
    /// Points of the Minkowski difference.
    pub w: [Vec3; 4],
    /// Support points on A.
    pub a: [Vec3; 4],
    /// Support points on B.
    pub b: [Vec3; 4],
    /// Barycentric weights of the closest point.
    pub lambda: [Real; 4],
    /// Number of points in use.
    pub len: usize,
}

impl Simplex {
    fn push(&mut self, w: Vec3, a: Vec3, b: Vec3) {
        self.w[self.len] = w;
        self.a[self.len] = a;
        self.b[self.len] = b;
        self.lambda[self.len] = 0.0;
        self.len += 1;
    }

    /// Reduces to the support set of the closest point and returns that point.
    fn solve(&mut self) -> Vec3 {
        let sol = closest_to_origin(&self.w[..self.len]);
        // Compacted in place (the kept points keep their order; slot `k <= i`), instead of
        // building a fresh simplex and copying it over this one.
        let mut k = 0;
        for i in 0..self.len {
            if sol.mask & (1 << i) != 0 {
                self.w[k] = self.w[i];
                self.a[k] = self.a[i];
                self.b[k] = self.b[i];
                self.lambda[k] = sol.lambda[i];
                k += 1;
            }
        }
        for i in k..self.len {
            self.w[i] = Vec3::ZERO;
            self.a[i] = Vec3::ZERO;
            self.b[i] = Vec3::ZERO;
            self.lambda[i] = 0.0;
        }
        self.len = k;
        self.closest()
    }

    /// The closest point `Σ λᵢ wᵢ`.
    pub fn closest(&self) -> Vec3 {
        (0..self.len).fold(Vec3::ZERO, |acc, i| acc + self.w[i] * self.lambda[i])
    }

    /// Witness points `(Σ λᵢ aᵢ, Σ λᵢ bᵢ)`.
    pub fn witnesses(&self) -> (Vec3, Vec3) {
        let mut pa = Vec3::ZERO;
        let mut pb = Vec3::ZERO;
        for i in 0..self.len {
            pa += self.a[i] * self.lambda[i];
            pb += self.b[i] * self.lambda[i];
        }
        (pa, pb)
    }

    fn contains(&self, w: Vec3) -> bool {
        self.w[..self.len].contains(&w)
    }

    fn max_norm_sq(&self) -> Real {
        self.w[..self.len]
            .iter()
            .map(|w| w.length_squared())
            .fold(0.0, Real::max)
    }
}

/// A GJK simplex kept between queries of one pair (see [`gjk_warm`]): its support points on A
/// in A's frame and on B in B's own frame, so that it can be placed at the pair's next
/// relative pose. Any points of the two shapes are a valid start; points that lie off them
/// (a cache kept for other shapes) are not, so a cache belongs to one pair of shapes
/// ([`WarmSimplex::fits`] rejects one that is plainly foreign). Round-off from the frame
/// changes only costs iterations.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct WarmSimplex {
    /// Number of points in use (at most 4).
    pub len: u8,
    /// Points of A, in A's frame.
    pub a: [Vec3; 4],
    /// Points of B, in B's frame.
    pub b: [Vec3; 4],
}

impl WarmSimplex {
    /// The points of `simplex` (A's frame, B at `pose_ab`), B's taken back to B's frame.
    pub fn keep(simplex: &Simplex, pose_ab: &Isometry) -> Self {
        let mut out = WarmSimplex {
            len: simplex.len.min(4) as u8,
            ..Default::default()
        };
        for i in 0..out.len as usize {
            out.a[i] = simplex.a[i];
            out.b[i] = pose_ab.inverse_transform_point(simplex.b[i]);
        }
        out
    }

    /// True when every point of A lies in `box_a` and every point of B in `box_b` (the
    /// shapes' local boxes, grown by a relative 1e-4 for the round-off of [`Self::keep`]):
    /// a cheap check that the simplex was kept for these shapes.
    pub fn fits(&self, box_a: Aabb, box_b: Aabb) -> bool {
        let inside = |bx: Aabb, p: Vec3| {
            let slack = 1e-4 * (1.0 + bx.half_extents().max_element() + p.abs().max_element());
            p.cmpge(bx.min - Vec3::splat(slack)).all() && p.cmple(bx.max + Vec3::splat(slack)).all()
        };
        let n = (self.len as usize).min(4);
        (0..n).all(|i| inside(box_a, self.a[i]) && inside(box_b, self.b[i]))
    }

    /// The points placed with B at `pose_ab`, as a simplex for [`gjk_warm`].
    pub fn placed(&self, pose_ab: &Isometry) -> Simplex {
        let mut out = Simplex::default();
        for i in 0..(self.len as usize).min(4) {
            out.a[i] = self.a[i];
            out.b[i] = pose_ab.transform_point(self.b[i]);
            out.w[i] = out.a[i] - out.b[i];
        }
        out.len = (self.len as usize).min(4);
        out
    }
}

/// Outcome of [`gjk`].
#[derive(Debug, Clone, Copy)]
#[allow(clippy::large_enum_variant)] // returned by value once per query; boxing would allocate
pub enum GjkResult {
    /// The sets are apart: closest points on A and B (A's frame) and their distance.
    Separated {
        /// Distance between the sets (`|point_b - point_a|`).
        distance: Real,
        /// Closest point on A.
        point_a: Vec3,
        /// Closest point on B.
        point_b: Vec3,
    },
    /// The lower bound proved the distance larger than the requested `max_distance`.
    BeyondMaxDistance,
    /// The sets touch or overlap; the simplex is the starting point for EPA.
    Overlapping(Simplex),
}

/// GJK closest points between `a` and `b` (both in the same frame).
///
/// `initial_dir` seeds the search (e.g. the vector between the centres). When
/// `max_distance` is finite, the search stops as soon as the lower bound exceeds it.
pub fn gjk<A: Support, B: Support>(
    a: &A,
    b: &B,
    initial_dir: Vec3,
    max_distance: Real,
) -> GjkResult {
    gjk_with_direction(a, b, initial_dir, max_distance).0
}

/// [`gjk`], also returning its last direction `v` (the closest point of the simplex in
/// `A - B` to the origin): for [`GjkResult::BeyondMaxDistance`], `-v` is an axis along which
/// B lies beyond A by more than `max_distance` (`v · w > |v| max_distance` for the support
/// point `w` of `A - B` along `-v`), which callers may keep as a separating axis.
pub fn gjk_with_direction<A: Support, B: Support>(
    a: &A,
    b: &B,
    initial_dir: Vec3,
    max_distance: Real,
) -> (GjkResult, Vec3) {
    let (result, v, _) = gjk_warm(a, b, &Simplex::default(), initial_dir, max_distance);
    (result, v)
}

/// [`gjk_with_direction`] started from the points of `warm` (A's frame; their `w` is
/// recomputed as `a - b` and `lambda` ignored), e.g. the last simplex of the same pair a step
/// ago placed at the new relative pose, instead of from one support point: Box2D's
/// `b2SimplexCache` and Bullet's cached separating vector. Any points of A and of B make a
/// valid start (they are points of `A - B`), so only the number of iterations depends on
/// it. Also returns the final simplex (a tetrahedron holding the origin when overlapping).
/// An empty or unusable `warm` gives exactly [`gjk_with_direction`]'s search.
pub fn gjk_warm<A: Support, B: Support>(
    a: &A,
    b: &B,
    warm: &Simplex,
    initial_dir: Vec3,
    max_distance: Real,
) -> (GjkResult, Vec3, Simplex) {
    let diff = MinkowskiDiff { a, b };
    let mut simplex = Simplex::default();
    for i in 0..warm.len.min(4) {
        let (pa, pb) = (warm.a[i], warm.b[i]);
        let w = pa - pb;
        if w.is_finite() && !simplex.contains(w) {
            simplex.push(w, pa, pb);
        }
    }
    let mut v = Vec3::ZERO;
    if simplex.len > 0 {
        v = simplex.solve();
        if simplex.len == 4 {
            return (GjkResult::Overlapping(simplex), v, simplex);
        }
        if !v.is_finite() {
            simplex = Simplex::default();
        }
    }
    if simplex.len == 0 {
        let d0 = if initial_dir.length_squared() > 0.0 && initial_dir.is_finite() {
            initial_dir
        } else {
            Vec3::X
        };
        let (w, pa, pb) = diff.support_pair(-d0);
        simplex.push(w, pa, pb);
        simplex.lambda[0] = 1.0;
        v = w;
    }
    let mut prev;
    let mut scale_sq = simplex.max_norm_sq();
    for _ in 0..GJK_MAX_ITERATIONS {
        let vv = v.length_squared();
        if vv <= GJK_ZERO_TOL * GJK_ZERO_TOL * scale_sq || !vv.is_finite() {
            return (GjkResult::Overlapping(simplex), v, simplex);
        }
        let (w, pa, pb) = diff.support_pair(-v);
        scale_sq = scale_sq.max(w.length_squared());
        let vw = v.dot(w);
        if max_distance.is_finite() && vw > 0.0 && vw * vw > vv * max_distance * max_distance {
            return (GjkResult::BeyondMaxDistance, v, simplex);
        }
        if vv - vw <= GJK_REL_TOL * vv || simplex.contains(w) {
            break;
        }
        prev = simplex;
        simplex.push(w, pa, pb);
        let new_v = simplex.solve();
        if simplex.len == 4 {
            return (GjkResult::Overlapping(simplex), v, simplex);
        }
        let new_vv = new_v.length_squared();
        if new_vv >= vv {
            // No progress: round-off. Keep the previous, better simplex.
            simplex = prev;
            break;
        }
        scale_sq = scale_sq.max(simplex.max_norm_sq());
        v = new_v;
    }
    let vv = v.length_squared();
    if vv <= GJK_ZERO_TOL * GJK_ZERO_TOL * scale_sq {
        return (GjkResult::Overlapping(simplex), v, simplex);
    }
    let (point_a, point_b) = simplex.witnesses();
    (
        GjkResult::Separated {
            distance: vv.sqrt(),
            point_a,
            point_b,
        },
        v,
        simplex,
    )
}

/// Boolean GJK: true when the sets, each swept by the given radius sum `radius`, intersect
/// (distance <= `radius`). Exits as soon as a separating axis is found (`v·w > radius |v|`).
pub fn gjk_intersects<A: Support, B: Support>(
    a: &A,
    b: &B,
    initial_dir: Vec3,
    radius: Real,
) -> bool {
    let diff = MinkowskiDiff { a, b };
    let d0 = if initial_dir.length_squared() > 0.0 && initial_dir.is_finite() {
        initial_dir
    } else {
        Vec3::X
    };
    let mut simplex = Simplex::default();
    let (w, pa, pb) = diff.support_pair(-d0);
    simplex.push(w, pa, pb);
    simplex.lambda[0] = 1.0;
    let mut v = w;
    let mut scale_sq = w.length_squared();
    for _ in 0..GJK_MAX_ITERATIONS {
        let vv = v.length_squared();
        if vv <= radius * radius || vv <= GJK_ZERO_TOL * GJK_ZERO_TOL * scale_sq {
            return true;
        }
        let (w, pa, pb) = diff.support_pair(-v);
        scale_sq = scale_sq.max(w.length_squared());
        let vw = v.dot(w);
        if vw > 0.0 && vw * vw > vv * radius * radius {
            return false; // separating axis
        }
        if vv - vw <= GJK_REL_TOL * vv || simplex.contains(w) {
            // Converged: the distance is |v|.
            return vv <= radius * radius * (1.0 + GJK_REL_TOL);
        }
        let prev_v = v;
        simplex.push(w, pa, pb);
        v = simplex.solve();
        if simplex.len == 4 {
            return true;
        }
        if v.length_squared() >= prev_v.length_squared() {
            return prev_v.length_squared() <= radius * radius;
        }
    }
    v.length_squared() <= radius * radius
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::query::support_adapters::{PointSupport, PolytopeSupport, SegmentSupport};

    #[test]
    fn point_to_segment_and_box() {
        let seg = SegmentSupport(Vec3::new(-1.0, 2.0, 0.0), Vec3::new(1.0, 2.0, 0.0));
        match gjk(&PointSupport(Vec3::ZERO), &seg, Vec3::Y, Real::INFINITY) {
            GjkResult::Separated {
                distance, point_b, ..
            } => {
                assert!((distance - 2.0).abs() < 1e-5);
                assert!((point_b - Vec3::new(0.0, 2.0, 0.0)).length() < 1e-5);
            }
            r => panic!("{r:?}"),
        }
        let cube: Vec<Vec3> = (0..8)
            .map(|i| {
                Vec3::new(
                    if i & 1 != 0 { 1.0 } else { -1.0 },
                    if i & 2 != 0 { 1.0 } else { -1.0 },
                    if i & 4 != 0 { 1.0 } else { -1.0 },
                )
            })
            .collect();
        let c = PolytopeSupport(&cube);
        assert!(matches!(
            gjk(
                &PointSupport(Vec3::new(0.5, 0.2, 0.1)),
                &c,
                Vec3::X,
                Real::INFINITY
            ),
            GjkResult::Overlapping(_)
        ));
        match gjk(
            &PointSupport(Vec3::new(3.0, 4.0, 0.5)),
            &c,
            Vec3::X,
            Real::INFINITY,
        ) {
            GjkResult::Separated { distance, .. } => {
                assert!((distance - (13.0 as Real).sqrt()).abs() < 1e-5)
            }
            r => panic!("{r:?}"),
        }
        assert!(!gjk_intersects(
            &PointSupport(Vec3::new(3.0, 0.0, 0.0)),
            &c,
            Vec3::X,
            1.5
        ));
        assert!(gjk_intersects(
            &PointSupport(Vec3::new(3.0, 0.0, 0.0)),
            &c,
            Vec3::X,
            2.5
        ));
    }
}
