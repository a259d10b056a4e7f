//! The persistent contact manifold: Bullet's `btPersistentManifold` (Coumans, "Contact
//! Generation", GDC 2010, "Persistent contact caching"), with points stored in each body's
//! local frame, refreshed from the current poses, matched by feature id or distance so that
//! accumulated impulses survive, and reduced to four points (deepest kept, area maximised,
//! as in Box3D's and Jolt's manifold reduction).

use super::contact::{ContactPoint, NO_FEATURE};
use crate::math::{Isometry, Mat3, Real, Vec3, Vec3A};
use crate::query::gjk::WarmSimplex;
use serde::{Deserialize, Serialize};

/// Maximum number of points a manifold keeps after reduction.
pub const MAX_MANIFOLD_POINTS: usize = 4;

/// Tuning of contact generation and caching, in length units.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ManifoldConfig {
    /// Speculative margin: points are generated while the shapes are at most this far apart.
    pub prediction: Real,
    /// A cached point is dropped when its distance grows beyond this (Bullet's contact
    /// breaking threshold) or when its two witness points drift tangentially further apart.
    pub breaking_threshold: Real,
    /// A new point closer than this to a cached one (on B) replaces it.
    pub merge_distance: Real,
    /// Perturbation angle (radians) for multi-point generation on general convex shapes;
    /// clamped to a small value per the talk.
    pub perturbation_angle: Real,
    /// Number of perturbed queries (0 disables perturbation).
    pub perturbation_iterations: u32,
}

impl Default for ManifoldConfig {
    fn default() -> Self {
        ManifoldConfig {
            prediction: 0.02,
            breaking_threshold: 0.02,
            merge_distance: 0.02,
            perturbation_angle: 0.05,
            perturbation_iterations: 4,
        }
    }
}

/// Up to [`MAX_MANIFOLD_POINTS`] contact points between bodies A and B (see [`ContactPoint`]
/// for the conventions).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct ContactManifold {
    /// The points, in insertion order (stable across steps while they persist).
    pub points: Vec<ContactPoint>,
    /// The relative pose (B in A's frame) at which the points were last generated as a full
    /// one-shot manifold, or `None` (incremental points, or never): while the pose stays
    /// within [`COHERENCE_ANGLE`] and [`COHERENCE_DISTANCE`] of it, the refreshed points are
    /// kept without running contact generation again (spatial coherence, as Bullet's contact
    /// caching and parry's `try_update_contacts`).
    #[serde(default)]
    pub generated_at: Option<Isometry>,
    /// For an empty manifold: a certificate that the shapes were apart by more than the
    /// prediction at the last generation, or `None`. While [`Separation::holds`] for the
    /// current relative pose, generating again cannot find a point, and the update skips it.
    #[serde(default)]
    pub apart: Option<Separation>,
    /// The last GJK simplex of a hull pair's contact query (`len == 0` when there is none),
    /// from which the next query starts (see [`WarmSimplex`]).
    #[serde(default)]
    pub warm: WarmSimplex,
}

/// A separating axis of an apart pair and what it proves (Bullet's
/// `btConvexSeparatingDistanceUtil`, which bounds how fast a separating distance can shrink
/// under the bodies' motion; Box2D's and Rapier's broadphases use the same conservative
/// bound for their fat boxes).
///
/// At the relative pose `pose_ab` (B in A's frame), every point of B was at least `distance`
/// beyond A along the unit `axis` (in A's frame, from A towards B), and every point of B lies
/// within `reach` of B's origin. After B moves to a relative pose whose translation differs
/// by `Δt` and whose rotation differs by an angle `θ`, each point of B has moved by at most
/// `|Δt| + 2 sin(θ/2) reach` (A does not move in its own frame), so the separation along the
/// same axis is at least `distance` minus that: a lower bound of the shapes' distance.
/// (The test bounds `2 sin(θ/2)` by twice the quaternions' chord, which stays accurate for
/// tiny angles in f32.)
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Separation {
    /// The relative pose (B in A's frame) at which the separation was measured.
    pub pose_ab: Isometry,
    /// Unit separating axis in A's frame, pointing from A towards B.
    pub axis: Vec3,
    /// Separation of the shapes along `axis` at `pose_ab` (a lower bound of their distance).
    pub distance: Real,
    /// Radius about B's origin of a ball holding B.
    pub reach: Real,
}

impl Separation {
    /// True when, at the relative pose `pose_ab`, the shapes are still certainly more than
    /// `prediction` apart (see the type's docs). False for non-finite values.
    pub fn holds(&self, pose_ab: &Isometry, prediction: Real) -> bool {
        let p0 = &self.pose_ab;
        let moved = crate::math::motion_bound(
            p0.translation,
            p0.rotation,
            pose_ab.translation,
            pose_ab.rotation,
            self.reach,
        );
        // Round-off of the separation, measured at p0: relative to the sizes involved.
        let slack = 1.0e-5 * (p0.translation.length() + self.reach);
        self.distance - moved - slack > prediction
    }
}

/// Relative rotation (radians) under which a manifold's points are reused unchanged.
pub const COHERENCE_ANGLE: Real = 0.1 * crate::math::consts::PI / 180.0;

/// Relative displacement (length units) of every contact point under which a manifold's
/// points are reused unchanged.
pub const COHERENCE_DISTANCE: Real = 1.0e-4;

impl ContactManifold {
    /// An empty manifold.
    pub fn new() -> Self {
        Self::default()
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// True when there is no point.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Removes every point.
    pub fn clear(&mut self) {
        self.points.clear();
        self.generated_at = None;
        self.apart = None;
    }

    /// True when the manifold holds a full manifold generated at a relative pose within
    /// [`COHERENCE_ANGLE`] of `pose_ab`'s rotation and whose points moved less than
    /// [`COHERENCE_DISTANCE`] since (so generating again would give the same points).
    pub fn is_coherent(&self, pose_ab: &Isometry) -> bool {
        let Some(p0) = self.generated_at else {
            return false;
        };
        if self.points.is_empty() {
            return false;
        }
        // cos(COHERENCE_ANGLE / 2), the bound on |q0 · q| (the relative rotation's half angle).
        let cos_half = (0.5 * COHERENCE_ANGLE).cos();
        let c = p0.rotation.dot(pose_ab.rotation).abs();
        if c < cos_half {
            return false;
        }
        // Cheap sufficient test first: a point x moves by at most |Δt| + 2 sin(θ/2) |x|
        // (θ the relative rotation angle), so no per-point transform is needed while the
        // pose has (nearly) not changed, the common case of resting contacts. sin(θ/2) is
        // bounded by the quaternions' chord |q - q0| = 2 sin(θ/4) (see `Separation::holds`):
        // `sqrt(1 - c²)` rounded to 0 in f32 below about 5e-4 rad, and points that had moved
        // three times the tolerance were kept.
        let q0 = if p0.rotation.dot(pose_ab.rotation) < 0.0 {
            -p0.rotation
        } else {
            p0.rotation
        };
        let dt = (pose_ab.translation - p0.translation).length();
        // The bound is at least `dt`: when the translation alone moved further, it cannot
        // hold, and its chord and reach are not formed (the same decision, cheaper).
        if dt <= COHERENCE_DISTANCE {
            let sin_half = (pose_ab.rotation - q0).length();
            let reach = self
                .points
                .iter()
                .map(|p| p.local_b.length_squared())
                .fold(0.0, Real::max)
                .sqrt();
            if dt + 2.0 * sin_half * reach <= COHERENCE_DISTANCE {
                return true;
            }
        }
        // Each point's own displacement `(R - R0) x + Δt`, with the difference of the two
        // rotation matrices formed once (two quaternion rotations per point before).
        let tol2 = COHERENCE_DISTANCE * COHERENCE_DISTANCE;
        let dr = Mat3::from_quat(pose_ab.rotation) - Mat3::from_quat(p0.rotation);
        let dt = pose_ab.translation - p0.translation;
        self.points
            .iter()
            .all(|p| (dr * p.local_b + dt).length_squared() <= tol2)
    }

    /// The deepest (smallest) distance, or `None` when empty.
    pub fn min_distance(&self) -> Option<Real> {
        self.points.iter().map(|p| p.distance).reduce(Real::min)
    }

    /// Recomputes every point's world data and distance from the bodies' current poses
    /// (`distance = (a - b) · n`, the talk's "update contact distance") and drops the points
    /// whose distance exceeds `breaking_threshold` or whose witness points drifted
    /// tangentially by more than `breaking_threshold`.
    pub fn refresh(&mut self, pose_a: &Isometry, pose_b: &Isometry, breaking_threshold: Real) {
        if self.points.is_empty() {
            return;
        }
        let (ra, rb) = (pose_a.rotation_matrix(), pose_b.rotation_matrix());
        self.refresh_with(
            &ra,
            pose_a.translation,
            &rb,
            pose_b.translation,
            breaking_threshold,
        );
    }

    /// [`ContactManifold::refresh`] with the bodies' rotation matrices `ra`, `rb` (their
    /// quaternions' `Mat3::from_quat`) and translations `ta`, `tb` already at hand: the
    /// dispatcher computes the matrices once per pair and shares them with the conversion
    /// of newly generated points.
    pub(crate) fn refresh_with(
        &mut self,
        ra: &Mat3,
        ta: Vec3,
        rb: &Mat3,
        tb: Vec3,
        breaking_threshold: Real,
    ) {
        if self.points.is_empty() {
            return;
        }
        if self.points.len() <= 2 {
            // One or two points: the scalar matrices, without the SIMD columns' set-up, which
            // costs more than it saves here (persistent capsule–box in the contacts bench:
            // 2.75 → 2.58 µs per 64 pairs). Same bits as the column path below.
            self.points.retain_mut(|p| {
                let a = *ra * p.local_a + ta;
                let b = *rb * p.local_b + tb;
                let n = *rb * p.local_normal_b;
                let d = (a - b).dot(n);
                if d.is_nan() || d > breaking_threshold {
                    return false;
                }
                let drift = (a - n * d) - b;
                if drift.length_squared() > breaking_threshold * breaking_threshold {
                    return false;
                }
                p.distance = d;
                p.normal = n;
                p.point_b = b;
                p.lifetime = p.lifetime.saturating_add(1);
                true
            });
            return;
        }
        // Rotation matrices as SIMD columns (`Vec3A`): three matrix–vector products per
        // point, each three lane multiplies and two adds, summed in `Mat3 * Vec3`'s order
        // (column by column, nothing fused), so every value has the scalar product's bits
        // (the dot products too: `(x + y) + z` in both). In f64 `Vec3A` is `Vec3` and this
        // is the scalar code.
        let cols = |m: &Mat3| [m.x_axis, m.y_axis, m.z_axis].map(Vec3A::from);
        let (ra, rb) = (cols(ra), cols(rb));
        let (ta, tb) = (Vec3A::from(ta), Vec3A::from(tb));
        let mul = |m: &[Vec3A; 3], v: Vec3| m[0] * v.x + m[1] * v.y + m[2] * v.z;
        let limit2 = breaking_threshold * breaking_threshold;
        // In-place compaction, in order (what `retain_mut` did, without its per-point
        // closure call); a kept point's four changed fields are written where it lands,
        // not the whole point copied out and back.
        let mut kept = 0;
        for i in 0..self.points.len() {
            let p = &self.points[i];
            let a = mul(&ra, p.local_a) + ta;
            let b = mul(&rb, p.local_b) + tb;
            let n = mul(&rb, p.local_normal_b);
            let d = (a - b).dot(n);
            if d.is_nan() || d > breaking_threshold {
                continue;
            }
            let drift = (a - n * d) - b;
            if drift.length_squared() > limit2 {
                continue;
            }
            if kept != i {
                self.points[kept] = self.points[i];
            }
            let p = &mut self.points[kept];
            p.distance = d;
            p.normal = to_vec3(n);
            p.point_b = to_vec3(b);
            p.lifetime = p.lifetime.saturating_add(1);
            kept += 1;
        }
        self.points.truncate(kept);
    }

    /// The index of the cached point the new point `p` duplicates: the same feature id, or
    /// else the closest point on B within `merge_distance` (without a feature match).
    pub fn find_match(&self, p: &ContactPoint, merge_distance: Real) -> Option<usize> {
        if p.feature != NO_FEATURE {
            if let Some(i) = self.points.iter().position(|q| q.feature == p.feature) {
                return Some(i);
            }
        }
        let mut best = None;
        let mut best_d2 = merge_distance * merge_distance;
        for (i, q) in self.points.iter().enumerate() {
            let d2 = (q.local_b - p.local_b).length_squared();
            if d2 <= best_d2 {
                best_d2 = d2;
                best = Some(i);
            }
        }
        best
    }

    /// Adds one point (the incremental half of the hybrid method): a duplicate replaces the
    /// cached point and inherits its impulses and lifetime; beyond four points the manifold
    /// is reduced. Non-finite points are ignored.
    pub fn add_point(&mut self, mut p: ContactPoint, merge_distance: Real) {
        if !p.is_finite() {
            return;
        }
        if let Some(i) = self.find_match(&p, merge_distance) {
            let old = &self.points[i];
            p.normal_impulse = old.normal_impulse;
            p.tangent_impulse = old.tangent_impulse;
            p.lifetime = old.lifetime;
            self.points[i] = p;
            return;
        }
        self.points.push(p);
        if self.points.len() > MAX_MANIFOLD_POINTS {
            self.reduce();
        }
    }

    /// Replaces the whole manifold by a freshly generated full one (the one-shot half of the
    /// hybrid method), carrying impulses and lifetimes over from matching cached points.
    pub fn replace_all(&mut self, mut new_points: Vec<ContactPoint>, merge_distance: Real) {
        self.replace_with(&mut new_points, merge_distance);
    }

    /// [`ContactManifold::replace_all`] without allocating once the manifold has held
    /// points: `new_points` is reduced to four in place, matched, copied into the manifold's
    /// own buffer (sized for [`MAX_MANIFOLD_POINTS`] once) and left empty for reuse. (Swapping
    /// the two buffers instead handed small or empty buffers around, which then grew again.)
    pub fn replace_with(&mut self, new_points: &mut Vec<ContactPoint>, merge_distance: Real) {
        // The usual case, every point finite, is told by one cheap test per point (see
        // `finite_point`); `retain` runs only when one is not.
        if !new_points.iter().all(finite_point) {
            new_points.retain(|p| p.is_finite());
        }
        // Reducing before matching keeps the same points as matching first: the reduction
        // looks at positions and depths only. (Most generations have at most four points:
        // the test is made here, without the call.)
        if new_points.len() > MAX_MANIFOLD_POINTS {
            reduce_points(new_points);
        }
        for p in new_points.iter_mut() {
            if let Some(i) = self.find_match(p, merge_distance) {
                let old = &self.points[i];
                p.normal_impulse = old.normal_impulse;
                p.tangent_impulse = old.tangent_impulse;
                p.lifetime = old.lifetime;
            }
        }
        self.points.clear();
        if self.points.capacity() < MAX_MANIFOLD_POINTS {
            self.points.reserve_exact(MAX_MANIFOLD_POINTS);
        }
        self.points.extend_from_slice(new_points);
        new_points.clear();
    }

    /// Reduces to at most four points: keeps the deepest, then the point farthest from it,
    /// then the one making the largest triangle with those two, then the one adding the most
    /// area outside that triangle (all measured in the plane orthogonal to the deepest
    /// point's normal). Ties keep the earliest point, so the result is deterministic.
    pub fn reduce(&mut self) {
        reduce_points(&mut self.points);
    }
}

/// A SIMD vector back to [`Vec3`] (the identity in f64, where `Vec3A` is `Vec3`).
#[inline(always)]
#[allow(clippy::useless_conversion)]
pub(crate) fn to_vec3(v: Vec3A) -> Vec3 {
    v.into()
}

/// A [`Vec3`] as a SIMD vector (the identity in f64).
#[inline(always)]
#[allow(clippy::useless_conversion)]
pub(crate) fn to_vec3a(v: Vec3) -> Vec3A {
    v.into()
}

/// [`ContactPoint::is_finite`] without a branch per value: `x · 0` is `±0` for a finite `x`
/// and NaN for an infinity or a NaN, and a sum of `±0`s is `±0` while a sum with a NaN is
/// NaN, so the sum of the thirteen values times zero is zero exactly when all are finite.
/// The vectors' products and sums run on SIMD lanes (`Vec3A`; plain `Vec3` in f64).
#[inline]
fn finite_point(p: &ContactPoint) -> bool {
    let z = |v: Vec3| to_vec3a(v) * 0.0;
    let sum = z(p.normal) + z(p.point_b) + z(p.local_a) + z(p.local_b);
    sum.cmpeq(Vec3A::ZERO).all() && p.distance * 0.0 == 0.0
}

/// The first `i < len` with the largest `f(i)` (0 when every value is `-inf` or NaN).
/// Generic, so that each criterion of [`reduce_points`] is inlined into its loop (a `&dyn
/// Fn` made every point an indirect call).
#[inline]
fn argmax(len: usize, f: impl Fn(usize) -> Real) -> usize {
    let mut best = 0;
    let mut best_v = Real::NEG_INFINITY;
    for i in 0..len {
        let v = f(i);
        if v > best_v {
            best_v = v;
            best = i;
        }
    }
    best
}

/// [`ContactManifold::reduce`] on a list of points, in place.
fn reduce_points(points: &mut Vec<ContactPoint>) {
    let pts = &*points;
    if pts.len() <= MAX_MANIFOLD_POINTS {
        return;
    }
    let mut i0 = 0;
    for (i, p) in pts.iter().enumerate() {
        if p.distance < pts[i0].distance {
            i0 = i;
        }
    }
    let n = pts[i0].normal;
    let proj = |v: Vec3| v - n * v.dot(n);
    let q: smallvec::SmallVec<[Vec3; 16]> = pts.iter().map(|p| proj(p.point_b)).collect();
    let len = q.len();
    let i1 = argmax(len, |i| {
        if i == i0 {
            return Real::NEG_INFINITY;
        }
        (q[i] - q[i0]).length_squared()
    });
    let i2 = argmax(len, |i| {
        if i == i0 || i == i1 {
            return Real::NEG_INFINITY;
        }
        (q[i1] - q[i0]).cross(q[i] - q[i0]).dot(n).abs()
    });
    let (i1, i2) = if (q[i1] - q[i0]).cross(q[i2] - q[i0]).dot(n) < 0.0 {
        (i2, i1)
    } else {
        (i1, i2)
    };
    // The point most outside the triangle (i0, i1, i2): most negative signed area
    // against one of its edges.
    let i3 = argmax(len, |i| {
        if i == i0 || i == i1 || i == i2 {
            return Real::NEG_INFINITY;
        }
        let e = [(i0, i1), (i1, i2), (i2, i0)];
        e.iter()
            .map(|&(u, v)| -(q[v] - q[u]).cross(q[i] - q[u]).dot(n))
            .fold(Real::NEG_INFINITY, Real::max)
    });
    let mut keep = [i0, i1, i2, i3];
    keep.sort_unstable();
    let mut kept = [pts[0]; MAX_MANIFOLD_POINTS];
    let mut n = 0;
    for (k, &i) in keep.iter().enumerate() {
        if k == 0 || keep[k - 1] != i {
            kept[n] = pts[i];
            n += 1;
        }
    }
    points.clear();
    points.extend_from_slice(&kept[..n]);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Quat;

    /// The branch-free finiteness test agrees with `ContactPoint::is_finite` on every
    /// field holding a finite value, zero of either sign, the largest finite value, an
    /// infinity or a NaN.
    #[test]
    fn finite_point_matches_is_finite() {
        let specials = [
            0.0,
            -0.0,
            1.5,
            -3.0e7,
            Real::MAX,
            Real::MIN,
            Real::MIN_POSITIVE,
            Real::INFINITY,
            Real::NEG_INFINITY,
            Real::NAN,
        ];
        let base = ContactPoint {
            distance: 0.01,
            normal: Vec3::Y,
            point_b: Vec3::new(1.0, 2.0, 3.0),
            local_a: Vec3::new(-1.0, 0.5, 3.0),
            local_b: Vec3::new(0.25, -2.0, 1.0e3),
            local_normal_b: Vec3::Z,
            feature: 0,
            normal_impulse: 0.0,
            tangent_impulse: [0.0; 2],
            lifetime: 0,
        };
        let (mut finite, mut not) = (0, 0);
        for field in 0..13 {
            for &x in &specials {
                for &y in &specials[..4] {
                    let mut p = base;
                    let mut set = |i: usize, x: Real| match i {
                        0 => p.distance = x,
                        1..=3 => p.normal[i - 1] = x,
                        4..=6 => p.point_b[i - 4] = x,
                        7..=9 => p.local_a[i - 7] = x,
                        _ => p.local_b[i - 10] = x,
                    };
                    set(field, x);
                    set((field + 5) % 13, y);
                    assert_eq!(finite_point(&p), p.is_finite(), "{field} {x} {y}");
                    if p.is_finite() {
                        finite += 1;
                    } else {
                        not += 1;
                    }
                }
            }
        }
        assert!(finite > 100 && not > 100, "{finite} {not}");
    }

    /// `is_coherent` as it was, forming the chord and the reach before the bound whatever
    /// the translation: the oracle of the early exit on the translation alone.
    fn coherent_reference(m: &ContactManifold, pose_ab: &Isometry) -> bool {
        let Some(p0) = m.generated_at else {
            return false;
        };
        if m.points.is_empty() {
            return false;
        }
        let cos_half = (0.5 * COHERENCE_ANGLE).cos();
        if p0.rotation.dot(pose_ab.rotation).abs() < cos_half {
            return false;
        }
        let q0 = if p0.rotation.dot(pose_ab.rotation) < 0.0 {
            -p0.rotation
        } else {
            p0.rotation
        };
        let sin_half = (pose_ab.rotation - q0).length();
        let dt = (pose_ab.translation - p0.translation).length();
        let reach = m
            .points
            .iter()
            .map(|p| p.local_b.length_squared())
            .fold(0.0, Real::max)
            .sqrt();
        if dt + 2.0 * sin_half * reach <= COHERENCE_DISTANCE {
            return true;
        }
        let dr = Mat3::from_quat(pose_ab.rotation) - Mat3::from_quat(p0.rotation);
        let dt = pose_ab.translation - p0.translation;
        m.points
            .iter()
            .all(|p| (dr * p.local_b + dt).length_squared() <= COHERENCE_DISTANCE.powi(2))
    }

    /// Same decisions as the reference: translations below, at and above the tolerance,
    /// rotations within and beyond the angle, points near and 1 km from B's origin, and
    /// non-finite poses.
    #[test]
    fn coherence_early_exit_keeps_the_decisions() {
        let mut seed = 0x5851_f42d_4c95_7f2d_u64;
        let mut rnd = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as Real / (1u64 << 53) as Real
        };
        let (mut yes, mut no) = (0, 0);
        for case in 0..40000 {
            let far = if case % 4 == 0 { 1000.0 } else { 1.0 };
            let p0 = Isometry::new(
                Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5) * far,
                Quat::from_rotation_y(rnd() * 6.0),
            );
            let mut m = ContactManifold::new();
            for _ in 0..1 + case % 4 {
                let local_b = Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5);
                m.points.push(ContactPoint {
                    distance: 0.0,
                    normal: Vec3::Y,
                    point_b: local_b,
                    local_a: local_b,
                    local_b,
                    local_normal_b: Vec3::Y,
                    feature: 0,
                    normal_impulse: 0.0,
                    tangent_impulse: [0.0; 2],
                    lifetime: 0,
                });
            }
            m.generated_at = Some(p0);
            let dir = Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5).normalize();
            let shift = dir * COHERENCE_DISTANCE * (2.0 * rnd()) * [0.5, 1.0, 1.5][case % 3];
            let turn = Quat::from_axis_angle(dir, COHERENCE_ANGLE * (rnd() - 0.5) * 0.05);
            let mut pose = Isometry::new(p0.translation + shift, turn * p0.rotation);
            if case % 7 == 0 {
                pose.translation = p0.translation; // rotation only
            }
            if case % 997 == 0 {
                pose.translation.x = Real::NAN;
            }
            let want = coherent_reference(&m, &pose);
            assert_eq!(m.is_coherent(&pose), want, "case {case}");
            if want {
                yes += 1;
            } else {
                no += 1;
            }
        }
        assert!(yes > 5000 && no > 5000, "{yes} {no}");
    }
}
