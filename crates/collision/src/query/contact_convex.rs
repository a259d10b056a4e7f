//! Contact between two convex shapes in A's frame (B placed by `pose_ab`): the dispatcher
//! that picks an exact special case by shape kinds, and the general GJK + EPA path.
//!
//! The general path follows the talk's margins: GJK runs on the *cores* (a sphere's centre,
//! a capsule's segment, every other shape exactly) and the radii are added back, which is
//! exact for the user's shape; when the cores themselves overlap, EPA runs on the cores
//! (the Minkowski difference of two rounded shapes is the cores' difference rounded by
//! `ra + rb`, so the depth is the cores' depth plus `ra + rb`, still exact). If the cores'
//! difference is flat (segment against segment), EPA runs on the full shapes.

use super::contact_capsule_cuboid::contact_capsule_cuboid;
use super::contact_cuboid_cuboid::contact_cuboid_cuboid;
use super::contact_round::{
    contact_capsule_capsule, contact_capsule_triangle_separated, contact_sphere_capsule,
    contact_sphere_cuboid, contact_sphere_sphere, contact_sphere_triangle,
};
use super::epa::{epa, epa_polytope};
use super::gjk::{gjk, gjk_intersects, gjk_warm, GjkResult, Simplex, WarmSimplex};
use super::guard::{guarded_contact, guarded_separated};
use super::result::Contact;
use super::support_adapters::{core_radius, AddRadius, Core, Transformed};
use crate::math::{Isometry, Real, Vec3};
use crate::shape::ConvexRef;

/// Runs `f` with A and B exchanged (`f` receives `pose_ba`) and maps its answer back to A's
/// frame: the one generic adapter that serves every reversed pair.
#[inline]
pub fn swap_contact(
    pose_ab: &Isometry,
    f: impl FnOnce(&Isometry) -> Option<Contact>,
) -> Option<Contact> {
    let pose_ba = pose_ab.inverse();
    f(&pose_ba).map(|c| c.swapped().transformed(pose_ab))
}

/// Contact of two convex shapes in A's frame, or `None` when they are further apart than
/// `prediction`. Dispatches to an exact special case when one exists (sphere–sphere,
/// sphere–box, sphere–capsule, sphere–triangle, capsule–capsule, capsule–triangle (while
/// apart), capsule–box, box–box) and to
/// [`contact_gjk_epa`] otherwise.
pub fn contact_convex(
    a: ConvexRef<'_>,
    b: ConvexRef<'_>,
    pose_ab: &Isometry,
    prediction: Real,
) -> Option<Contact> {
    use ConvexRef as C;
    match (a, b) {
        (C::Sphere(a), C::Sphere(b)) => contact_sphere_sphere(a, b, pose_ab, prediction),
        (C::Sphere(a), C::Cuboid(b)) => contact_sphere_cuboid(a, b, pose_ab, prediction),
        (C::Cuboid(a), C::Sphere(b)) => {
            swap_contact(pose_ab, |p| contact_sphere_cuboid(b, a, p, prediction))
        }
        (C::Sphere(a), C::Capsule(b)) => contact_sphere_capsule(a, b, pose_ab, prediction),
        (C::Capsule(a), C::Sphere(b)) => {
            swap_contact(pose_ab, |p| contact_sphere_capsule(b, a, p, prediction))
        }
        (C::Sphere(a), C::Triangle(b)) => contact_sphere_triangle(a, b, pose_ab, prediction),
        (C::Triangle(a), C::Sphere(b)) => {
            swap_contact(pose_ab, |p| contact_sphere_triangle(b, a, p, prediction))
        }
        (C::Capsule(a), C::Capsule(b)) => contact_capsule_capsule(a, b, pose_ab, prediction),
        (C::Capsule(x), C::Triangle(y)) => {
            contact_capsule_triangle_separated(x, y, pose_ab, prediction)
                .unwrap_or_else(|| contact_gjk_epa(a, b, pose_ab, prediction))
        }
        (C::Triangle(x), C::Capsule(y)) => swap_contact(pose_ab, |p| {
            contact_capsule_triangle_separated(y, x, p, prediction)
                .unwrap_or_else(|| contact_gjk_epa(b, a, p, prediction))
        }),
        (C::Capsule(a), C::Cuboid(b)) => contact_capsule_cuboid(a, b, pose_ab, prediction),
        (C::Cuboid(a), C::Capsule(b)) => {
            swap_contact(pose_ab, |p| contact_capsule_cuboid(b, a, p, prediction))
        }
        (C::Cuboid(a), C::Cuboid(b)) => contact_cuboid_cuboid(a, b, pose_ab, prediction),
        _ => contact_gjk_epa(a, b, pose_ab, prediction),
    }
}

/// The general path: GJK on cores plus radii, EPA when the cores overlap, each answer checked
/// by the guard ([`super::guard`]). Works for every pair of convex shapes; `None` when
/// further apart than `prediction`.
pub fn contact_gjk_epa(
    a: ConvexRef<'_>,
    b: ConvexRef<'_>,
    pose_ab: &Isometry,
    prediction: Real,
) -> Option<Contact> {
    match contact_gjk_epa_unguarded(a, b, pose_ab, prediction) {
        GjkEpa::Beyond => None,
        GjkEpa::Separated(c) => {
            Some(guarded_separated(a, b, pose_ab, c)).filter(|c| c.distance <= prediction)
        }
        // EPA is checked against the support functions and replaced when wrong.
        GjkEpa::Penetrating(c) => {
            guarded_contact(a, b, pose_ab, Some(c)).filter(|c| c.distance <= prediction)
        }
    }
}

/// The raw answer of GJK/EPA, before the guard: callers that have a better fallback than
/// the guard's (the polyhedron narrowphase runs the full separating-axis test) check it
/// themselves with [`super::guard::contact_is_consistent`].
#[derive(Debug, Clone, Copy)]
pub enum GjkEpa {
    /// Further apart than the prediction distance.
    Beyond,
    /// GJK's closest points, within the prediction distance.
    Separated(Contact),
    /// EPA's penetration (negative distance).
    Penetrating(Contact),
}

/// GJK on cores plus radii, EPA when the cores overlap, unchecked (see [`GjkEpa`];
/// [`contact_gjk_epa`] adds the guard).
#[inline]
pub fn contact_gjk_epa_unguarded(
    a: ConvexRef<'_>,
    b: ConvexRef<'_>,
    pose_ab: &Isometry,
    prediction: Real,
) -> GjkEpa {
    contact_gjk_epa_unguarded_axis(a, b, pose_ab, prediction).0
}

/// [`contact_gjk_epa_unguarded`], also returning, for [`GjkEpa::Beyond`], the direction
/// (A's frame, from A towards B, not normalised) along which GJK found the shapes farther
/// apart than the prediction; zero otherwise. A caller keeping it as a separating axis must
/// measure the separation along it itself.
#[inline]
pub fn contact_gjk_epa_unguarded_axis(
    a: ConvexRef<'_>,
    b: ConvexRef<'_>,
    pose_ab: &Isometry,
    prediction: Real,
) -> (GjkEpa, Vec3) {
    contact_gjk_epa_unguarded_hinted(a, b, pose_ab, prediction, None)
}

/// [`contact_gjk_epa_unguarded_axis`] with GJK seeded by `hint`, a guess of the contact
/// normal (A's frame, from A towards B; a persistent manifold's last normal), instead of
/// the line between the origins: the first support points then lie on the features that
/// touched at the last step, which saves GJK iterations on coherent pairs (parry's
/// `contact_manifolds_pfm_pfm` seeds GJK with the manifold's last normal the same way).
/// The answer is GJK/EPA's for any seed; only round-off differs. A zero or non-finite
/// hint falls back to the origins' line.
#[inline]
pub fn contact_gjk_epa_unguarded_hinted(
    a: ConvexRef<'_>,
    b: ConvexRef<'_>,
    pose_ab: &Isometry,
    prediction: Real,
    hint: Option<Vec3>,
) -> (GjkEpa, Vec3) {
    contact_gjk_epa_unguarded_warm(a, b, pose_ab, prediction, hint, None)
}

/// [`contact_gjk_epa_unguarded_hinted`] with GJK started from `warm`'s simplex when it holds
/// one (a pair's simplex from its last query, see [`gjk_warm`]), and `warm` then replaced by
/// this query's final simplex. On a resting pair the kept simplex is nearly the answer, so
/// GJK ends in one or two iterations instead of four or five; a kept tetrahedron that still
/// holds the origin goes to EPA with no support query at all. The answer is GJK/EPA's from
/// any start; only round-off differs.
pub fn contact_gjk_epa_unguarded_warm(
    a: ConvexRef<'_>,
    b: ConvexRef<'_>,
    pose_ab: &Isometry,
    prediction: Real,
    hint: Option<Vec3>,
    warm: Option<&mut WarmSimplex>,
) -> (GjkEpa, Vec3) {
    let (ra, rb) = (core_radius(a), core_radius(b));
    let radius = ra + rb;
    let core_a = Core(a);
    let core_b = Transformed::new(Core(b), pose_ab);
    let dir = match hint {
        // GJK's direction is its guess of the closest point of A - B, which lies along
        // -normal.
        Some(n) if n.is_finite() && n.length_squared() > 0.0 => -n,
        _ => -pose_ab.translation,
    };
    // A kept simplex whose points do not lie in the shapes' boxes belongs to other shapes
    // (a manifold reused for another pair): start afresh rather than from wrong points.
    let start = match warm.as_deref() {
        Some(w) if w.fits(a.local_aabb(), b.local_aabb()) => w.placed(pose_ab),
        _ => Simplex::default(),
    };
    let (result, v, last) = gjk_warm(&core_a, &core_b, &start, dir, prediction + radius);
    if let Some(w) = warm {
        *w = WarmSimplex::keep(&last, pose_ab);
    }
    let c = match result {
        GjkResult::BeyondMaxDistance => return (GjkEpa::Beyond, -v),
        GjkResult::Separated {
            distance,
            point_a,
            point_b,
        } => {
            let signed = distance - radius;
            if signed > prediction {
                return (GjkEpa::Beyond, point_b - point_a);
            }
            let mut n = (point_b - point_a) / distance;
            if (n.length_squared() - 1.0).abs() > 1.0e-3 {
                // The witnesses lost the gap to round-off (coordinates far larger than the
                // distance, e.g. 1e5 against 5e-5 in f32): GJK's own direction is unit.
                n = (-v)
                    .try_normalize()
                    .or_else(|| (point_b - point_a).try_normalize())
                    .unwrap_or(Vec3::Y);
            }
            GjkEpa::Separated(Contact {
                distance: signed,
                point_a: point_a + n * ra,
                point_b: point_b - n * rb,
                normal: n,
            })
        }
        GjkResult::Overlapping(simplex) => {
            let (pen, ra, rb) = if radius > 0.0 {
                match epa_polytope(&core_a, &core_b, &simplex) {
                    Some(p) => (p, ra, rb),
                    None => {
                        // Full shapes: exact support including the radius.
                        let full_a = AddRadius {
                            inner: core_a,
                            radius: ra,
                        };
                        let full_b = Transformed::new(
                            AddRadius {
                                inner: Core(b),
                                radius: rb,
                            },
                            pose_ab,
                        );
                        let p = match gjk(&full_a, &full_b, dir, Real::INFINITY) {
                            GjkResult::Overlapping(s) => epa(&full_a, &full_b, &s),
                            _ => epa(&full_a, &full_b, &simplex),
                        };
                        (p, 0.0, 0.0)
                    }
                }
            } else {
                // No radius: the cores are the shapes, and GJK's simplex is already the one
                // on the full shapes (a second GJK would repeat the same iterations).
                (epa(&core_a, &core_b, &simplex), 0.0, 0.0)
            };
            let depth = pen.depth + ra + rb;
            let n = pen.normal;
            GjkEpa::Penetrating(Contact {
                distance: -depth,
                point_a: pen.point_a + n * ra,
                point_b: pen.point_b - n * rb,
                normal: n,
            })
        }
    };
    (c, Vec3::ZERO)
}

/// Signed distance of two convex shapes in A's frame (always a result).
pub fn distance_convex(a: ConvexRef<'_>, b: ConvexRef<'_>, pose_ab: &Isometry) -> Contact {
    contact_convex(a, b, pose_ab, Real::INFINITY).unwrap_or(Contact {
        // Unreachable with an infinite prediction; kept total and finite.
        distance: Real::MAX,
        point_a: Vec3::ZERO,
        point_b: pose_ab.translation,
        normal: Vec3::Y,
    })
}

/// True when two convex shapes touch or overlap. GJK on the cores with an early exit on the
/// first separating axis (no EPA, no witness points).
pub fn intersects_convex(a: ConvexRef<'_>, b: ConvexRef<'_>, pose_ab: &Isometry) -> bool {
    use ConvexRef as C;
    match (a, b) {
        (C::Sphere(a), C::Sphere(b)) => {
            let r = a.radius() + b.radius();
            pose_ab.translation.length_squared() <= r * r
        }
        _ => {
            let radius = core_radius(a) + core_radius(b);
            gjk_intersects(
                &Core(a),
                &Transformed::new(Core(b), pose_ab),
                -pose_ab.translation,
                radius,
            )
        }
    }
}
