//! The one check of a penetration answer (EPA's), shared by [`crate::query::contact()`] and
//! the narrowphase, and its bounded fallback.
//!
//! EPA on shapes that touch within round-off (or on a Minkowski difference much larger than
//! the contact, as for a small box on a huge ground box in f32) can return a depth or a
//! normal that is wrong by the size of the shapes. Every answer is therefore checked
//! against the shapes' support functions along its own normal `n` (the same idea as the
//! check after EPA in Jolt's `PenetrationDepth` and Bullet's `btGjkEpaPenetrationDepthSolver`
//! fallback to sampled directions): the separation `h_B(-n) - h_A(n)` must equal the
//! reported distance, and both witnesses must lie on their shapes' supporting planes, within
//! an absolute plus relative tolerance sized to the smaller shape. A failed answer is
//! replaced: by the exact polytope separating-axis test when both shapes are polyhedra,
//! otherwise by the best of a fixed set of sampled directions (EPA's own normal, the axes,
//! the diagonals, the centre line), each measured exactly by the support functions, so the
//! result is never worse than EPA's own normal re-measured.

use crate::math::{orthonormal_basis, Isometry, Real, Vec3, EPSILON};
use crate::narrowphase::dispatcher::as_polyhedron;
use crate::narrowphase::polyhedron::polyhedron_manifold_into;
use crate::query::Contact;
use crate::shape::{ConvexRef, SupportMap};

/// Relative tolerance of the check, applied to the smaller shape's size.
pub const GUARD_REL_TOL: Real = 2.0e-5;

/// Separated answers farther apart than this fraction of the smaller shape's size are not
/// checked by [`guarded_separated`].
pub const SEPARATED_CHECK_FRAC: Real = 0.05;

/// Smallest half-diagonal of the two shapes' local boxes (the "small size" of the pair).
fn small_size(a: ConvexRef<'_>, b: ConvexRef<'_>) -> Real {
    let sa = a.local_aabb().half_extents().length();
    let sb = b.local_aabb().half_extents().length();
    sa.min(sb)
}

/// The tolerance of the check: `GUARD_REL_TOL` of the smaller shape plus a few ulps of the
/// coordinates involved (support heights and the distance), so that f32 round-off at large
/// coordinates is not mistaken for a wrong answer. Relative throughout: the ulps' floor is
/// the smaller shape's size, not 1 (an absolute 0.5 µm in f32, which let answers 0.3 % off
/// pass for 0.1 mm shapes).
fn tolerance(a: ConvexRef<'_>, b: ConvexRef<'_>, ha: Real, hb: Real, d: Real) -> Real {
    let small = small_size(a, b);
    GUARD_REL_TOL * small + 4.0 * EPSILON * (small + ha.abs() + hb.abs() + d.abs())
}

/// Support heights of A along `n` and of B (at `pose_ab`) along `-n`, as `(h_A(n), -h_B(-n))`
/// i.e. the positions of the two supporting planes along `n`.
fn planes(a: ConvexRef<'_>, b: ConvexRef<'_>, pose_ab: &Isometry, n: Vec3) -> (Real, Real) {
    let ha = n.dot(a.support(n));
    let hb = n.dot(pose_ab.transform_point(b.support(pose_ab.inverse_transform_vector(-n))));
    (ha, hb)
}

/// True when `c` (a contact of A and B in A's frame) agrees with the shapes' support
/// functions along its normal: unit finite normal, `distance = h_B(-n) - h_A(n)`, and each
/// witness on its shape's supporting plane, within the pair's tolerance.
pub fn contact_is_consistent(
    a: ConvexRef<'_>,
    b: ConvexRef<'_>,
    pose_ab: &Isometry,
    c: &Contact,
) -> bool {
    let n = c.normal;
    if !n.is_finite() || !c.distance.is_finite() || (n.length() - 1.0).abs() > 1.0e-3 {
        return false;
    }
    let (ha, hb) = planes(a, b, pose_ab, n);
    let tol = tolerance(a, b, ha, hb, c.distance);
    ((hb - ha) - c.distance).abs() <= tol
        && (n.dot(c.point_a) - ha).abs() <= tol
        && (n.dot(c.point_b) - hb).abs() <= tol
}

/// `c` re-measured exactly along its own normal (`contact_along`) when that exact
/// separation is within `slack` times the guard's tolerance of `c.distance` (a looser form of
/// [`contact_is_consistent`] that drops the witnesses' check and replaces them); `None`
/// otherwise. For polyhedra touching within round-off, where EPA's polytope is degenerate
/// and its depth (not its normal) is slightly off.
pub fn remeasured_near(
    a: ConvexRef<'_>,
    b: ConvexRef<'_>,
    pose_ab: &Isometry,
    c: &Contact,
    slack: Real,
) -> Option<Contact> {
    let n = c.normal;
    if !n.is_finite() || !c.distance.is_finite() || (n.length() - 1.0).abs() > 1.0e-3 {
        return None;
    }
    let k = contact_along(a, b, pose_ab, n)?;
    let ha = k.normal.dot(k.point_a);
    let tol = tolerance(a, b, ha, ha + k.distance, c.distance);
    ((k.distance - c.distance).abs() <= slack * tol).then_some(k)
}

/// The contact along direction `n`, measured exactly: distance `h_B(-n) - h_A(n)`, A's
/// support point as `point_a`. `None` for a non-finite direction.
fn contact_along(
    a: ConvexRef<'_>,
    b: ConvexRef<'_>,
    pose_ab: &Isometry,
    n: Vec3,
) -> Option<Contact> {
    let n = n.normalize_or_zero();
    if n == Vec3::ZERO || !n.is_finite() {
        return None;
    }
    let point_a = a.support(n);
    let support_b = pose_ab.transform_point(b.support(pose_ab.inverse_transform_vector(-n)));
    let distance = n.dot(support_b) - n.dot(point_a);
    // `point_b` keeps the contact convention `point_b = point_a + n · distance`: it lies on
    // B's supporting plane, level with A's support point.
    distance.is_finite().then_some(Contact {
        distance,
        point_a,
        point_b: point_a + n * distance,
        normal: n,
    })
}

/// The bounded fallback for a contact that failed [`contact_is_consistent`] (`c`, possibly
/// `None` when EPA gave nothing): the polytope separating-axis test when both shapes are
/// polyhedra; otherwise the sampled direction of largest exact separation (EPA's normal,
/// the 26 axis/edge/corner directions of A's frame and the centre line). The answer's
/// distance is always at least that of `c`'s normal re-measured.
pub fn fallback_contact(
    a: ConvexRef<'_>,
    b: ConvexRef<'_>,
    pose_ab: &Isometry,
    c: Option<&Contact>,
) -> Option<Contact> {
    if let (Some(pa), Some(pb)) = (as_polyhedron(a), as_polyhedron(b)) {
        let mut out = Vec::new();
        polyhedron_manifold_into(&pa, &pb, pose_ab, Real::INFINITY, &mut out);
        let best = out
            .into_iter()
            .map(|(k, _)| k)
            // A triangle without area has a zero face normal, which the separating-axis
            // test may pick as a face (at separation 0); such answers are dropped for the
            // sampled directions below.
            .filter(|k| {
                k.distance.is_finite()
                    && k.normal.is_finite()
                    && (k.normal.length() - 1.0).abs() <= 1.0e-3
            })
            .min_by(|x, y| x.distance.total_cmp(&y.distance));
        if best.is_some() {
            return best;
        }
    }
    let mut best = c.and_then(|c| contact_along(a, b, pose_ab, c.normal));
    let mut consider = |n: Vec3| {
        if let Some(k) = contact_along(a, b, pose_ab, n) {
            if best.as_ref().is_none_or(|b| k.distance > b.distance) {
                best = Some(k);
            }
        }
    };
    consider(pose_ab.translation);
    for x in -1i8..=1 {
        for y in -1i8..=1 {
            for z in -1i8..=1 {
                if (x, y, z) != (0, 0, 0) {
                    consider(Vec3::new(x as Real, y as Real, z as Real));
                }
            }
        }
    }
    best.map(|c| refine(a, b, pose_ab, c))
}

/// Hill climbing on the exact separation `h_B(-n) - h_A(n)` (its maximum over unit `n` is the
/// signed distance): tilts the normal by a shrinking angle towards four tangent directions
/// and keeps any improvement, for at most `REFINE_STEPS` rounds. Monotone: never
/// returns a contact with a smaller distance than `c`.
fn refine(a: ConvexRef<'_>, b: ConvexRef<'_>, pose_ab: &Isometry, mut c: Contact) -> Contact {
    const REFINE_STEPS: usize = 64;
    let mut step: Real = 0.1;
    for _ in 0..REFINE_STEPS {
        if step < 8.0 * EPSILON {
            break;
        }
        let (t0, t1) = orthonormal_basis(c.normal);
        let mut improved = false;
        for t in [t0, -t0, t1, -t1] {
            if let Some(k) = contact_along(a, b, pose_ab, c.normal + t * step) {
                if k.distance > c.distance {
                    c = k;
                    improved = true;
                }
            }
        }
        if !improved {
            step *= 0.5;
        }
    }
    c
}

/// Returns `c` when it passes [`contact_is_consistent`], else the [`fallback_contact`].
pub fn guarded_contact(
    a: ConvexRef<'_>,
    b: ConvexRef<'_>,
    pose_ab: &Isometry,
    c: Option<Contact>,
) -> Option<Contact> {
    match c {
        Some(c) if contact_is_consistent(a, b, pose_ab, &c) => Some(c),
        c => fallback_contact(a, b, pose_ab, c.as_ref()),
    }
}

/// The guard for a separated answer (GJK's): `c` when farther than
/// [`SEPARATED_CHECK_FRAC`] of the smaller shape or consistent, else the fallback when
/// both shapes are polyhedra (the separating-axis answer) or when the fallback's distance
/// exceeds `c`'s (a separation measured exactly along a direction is a lower bound of the
/// true distance, so `c` was too short), else `c`.
pub fn guarded_separated(
    a: ConvexRef<'_>,
    b: ConvexRef<'_>,
    pose_ab: &Isometry,
    c: Contact,
) -> Contact {
    // Only near contact (within 5 % of the smaller shape) is GJK's answer checked: that is
    // where its scale-relative tolerances bite, and farther pairs keep GJK's cost.
    if c.distance > SEPARATED_CHECK_FRAC * small_size(a, b)
        || contact_is_consistent(a, b, pose_ab, &c)
    {
        return c;
    }
    match fallback_contact(a, b, pose_ab, Some(&c)) {
        Some(f) if polyhedral(a, b) || f.distance > c.distance => f,
        _ => c,
    }
}

fn polyhedral(a: ConvexRef<'_>, b: ConvexRef<'_>) -> bool {
    as_polyhedron(a).is_some() && as_polyhedron(b).is_some()
}
