//! GJK seeded with a guessed normal (`hull_manifold_or_separation`'s `hint`, the persistent
//! manifold's last normal or separating axis): the manifold must not depend on the seed
//! beyond round-off. For hull–hull, box–hull and hull–box pairs (random, touching, face on
//! face with coplanar faces, parallel edges; near the origin and 1 km from it), the manifold
//! for every seed — none, the true normal, its opposite, a random direction, a zero and a
//! NaN vector — is checked against the exact intersection polytope (`polytope_common`'s
//! f64 oracle), and its depth against the unseeded manifold's; apart pairs get no point
//! whatever the seed. Also the Taru hull (scenes 4 and 6) face on face and stacked.

mod polytope_common;

use carom_collision::math::{Isometry, Quat, Real, Vec3};
use carom_collision::narrowphase::polyhedron_guided::hull_manifold_or_separation;
use carom_collision::query::Contact;
use carom_collision::shape::{ConvexHull, Shape};
use polytope_common::common::{taru_points, Rng};
use polytope_common::*;
use proptest::prelude::*;

/// The manifold of `a` at `pose_a` and `b` at `pose_b` (world frame, query convention) with
/// GJK seeded by `hint` (A's frame).
fn manifold(
    a: &Shape,
    pose_a: &Isometry,
    b: &Shape,
    pose_b: &Isometry,
    prediction: Real,
    hint: Option<Vec3>,
) -> Vec<Contact> {
    let pose_ab = pose_a.inv_mul(pose_b);
    let mut out = Vec::new();
    hull_manifold_or_separation(a, b, &pose_ab, prediction, hint, &mut out);
    out.into_iter()
        .map(|(c, _)| c.transformed(pose_a))
        .collect()
}

/// The seeds tried: none, the unseeded answer's normal (A's frame) and its opposite, a
/// fixed oblique direction, zero and NaN.
fn hints(normal: Option<Vec3>) -> Vec<Option<Vec3>> {
    let mut h = vec![
        None,
        Some(Vec3::new(0.3, -0.8, 0.52)),
        Some(Vec3::ZERO),
        Some(Vec3::splat(Real::NAN)),
    ];
    if let Some(n) = normal {
        h.push(Some(n));
        h.push(Some(-n));
    }
    h
}

fn check_hints(a: &Shape, b: &Shape, pr: &Params) -> Result<(), TestCaseError> {
    let Some((pose_a, pose_b)) = configure(a, b, pr) else {
        return Ok(());
    };
    let tol = tolerance(pr.far);
    let prediction = if matches!(pr.kind, Kind::Touching) {
        tol as Real
    } else {
        0.0
    };
    let base = manifold(a, &pose_a, b, &pose_b, prediction, None);
    let normal = base
        .first()
        .map(|c| pose_a.inverse_transform_vector(c.normal));
    for hint in hints(normal) {
        let got = manifold(a, &pose_a, b, &pose_b, prediction, hint);
        check_against_polytope(a, &pose_a, b, &pose_b, &got, pr.kind, tol + r(prediction))
            .map_err(|e| {
                TestCaseError::fail(format!(
                    "hint {hint:?}, {} against {}: {e}\n{got:?}",
                    a.kind_name(),
                    b.kind_name()
                ))
            })?;
        check_same_depth(&base, &got, tol, &format!("hint {hint:?} against unseeded"))?;
    }
    Ok(())
}

hull_pair_cases!(
    check_hints,
    0x6869_6e74_0009,
    hull_hull_manifolds_do_not_depend_on_the_seed,
    box_hull_manifolds_do_not_depend_on_the_seed
);

/// Apart pairs beyond the prediction: no point whatever the seed, also with the seed
/// pointing away from B.
#[test]
fn apart_pairs_have_no_point_whatever_the_seed() {
    let taru = Shape::ConvexHull(ConvexHull::new(&taru_points()).unwrap());
    let mut rng = Rng::new(9);
    for k in 0..200 {
        let far = if k % 2 == 0 {
            Vec3::ZERO
        } else {
            Vec3::new(1.0e3, -2.0e2, 7.0e2)
        };
        let rot = Quat::from_axis_angle(rng.unit(), rng.range(-3.0, 3.0));
        let dir = rng.unit();
        // The Taru hull's radius is under 2.7: 5.5 apart leaves a gap.
        let pose_a = Isometry::new(far, Quat::IDENTITY);
        let pose_b = Isometry::new(far + dir * 5.5, rot);
        for hint in hints(Some(dir)) {
            let got = manifold(&taru, &pose_a, &taru, &pose_b, 0.02, hint);
            assert!(got.is_empty(), "hint {hint:?}: {got:?}");
        }
    }
}

/// Taru barrels standing on each other (the stacks of "1000 convex") and lying side by
/// side, touching and 1 mm deep, with small tilts, near the origin and 1 km out: the same
/// depth for every seed, and the unseeded depth against the oracle.
#[test]
fn taru_stacks_give_the_same_depth_for_every_seed() {
    let taru = Shape::ConvexHull(ConvexHull::new(&taru_points()).unwrap());
    let Shape::ConvexHull(h) = &taru else {
        unreachable!()
    };
    let top = h.vertices().iter().map(|v| v.y).fold(Real::MIN, Real::max);
    let bottom = h.vertices().iter().map(|v| v.y).fold(Real::MAX, Real::min);
    let mut rng = Rng::new(4);
    for k in 0..120 {
        let far = if k % 2 == 0 {
            Vec3::ZERO
        } else {
            Vec3::new(-6.0e2, 3.0e2, 8.0e2)
        };
        let depth = [0.0, 1.0e-3, 1.0e-5][k % 3];
        let tilt = Quat::from_axis_angle(rng.unit(), rng.range(0.0, 2.0e-3));
        let spin = Quat::from_rotation_y(rng.range(-3.2, 3.2));
        let side = Vec3::new(rng.range(-0.3, 0.3), 0.0, rng.range(-0.3, 0.3));
        let pose_a = Isometry::new(far, Quat::IDENTITY);
        let pose_b = Isometry::new(
            far + Vec3::Y * (top - bottom - depth) + side,
            (tilt * spin).normalize(),
        );
        let tol = tolerance(far);
        let base = manifold(&taru, &pose_a, &taru, &pose_b, 0.02, None);
        let d0 = deepest(&base).expect("stacked barrels touch");
        for hint in hints(Some(Vec3::Y)) {
            let got = manifold(&taru, &pose_a, &taru, &pose_b, 0.02, hint);
            let d1 = deepest(&got).expect("stacked barrels touch");
            assert!(
                r(d0 - d1).abs() <= tol + 2.0e-3 * (1.0 + r(d0).abs()),
                "case {k}, hint {hint:?}: {d1} against {d0}"
            );
            for c in &got {
                assert!(c.normal.is_finite() && c.distance.is_finite(), "{c:?}");
            }
        }
        check_against_polytope(
            &taru,
            &pose_a,
            &taru,
            &pose_b,
            &base,
            Kind::Random,
            tol + 0.02,
        )
        .unwrap_or_else(|e| panic!("case {k}: {e}"));
    }
}
