//! GJK started from a kept simplex (`hull_manifold_or_separation_warm`, the persistent
//! manifold's `warm` field): the manifold must not depend on where GJK starts beyond
//! round-off. For hull–hull, box–hull and hull–box pairs (random, touching, face on face,
//! parallel edges; near the origin and 1 km out), the manifold started from the simplex kept
//! at a nearby pose, at a far pose, and at the same pose, is checked against the exact
//! intersection polytope (`polytope_common`'s f64 oracle) and its depth against the cold
//! manifold's. A simplex kept for other shapes is not used. Also a Taru barrel rocking on
//! another for 300 steps, warm against cold at every step.

mod polytope_common;

use carom_collision::math::{Aabb, Isometry, Quat, Real, Vec3};
use carom_collision::narrowphase::polyhedron_guided::hull_manifold_or_separation_warm;
use carom_collision::query::gjk::WarmSimplex;
use carom_collision::query::Contact;
use carom_collision::shape::{ConvexHull, Shape};
use polytope_common::common::{taru_points, Rng};
use polytope_common::*;
use proptest::prelude::*;

/// The manifold of `a` at `pose_a` and `b` at `pose_b` (world frame, query convention),
/// GJK started from `warm` (updated in place) or cold.
fn manifold(
    a: &Shape,
    pose_a: &Isometry,
    b: &Shape,
    pose_b: &Isometry,
    prediction: Real,
    warm: Option<&mut WarmSimplex>,
) -> Vec<Contact> {
    let pose_ab = pose_a.inv_mul(pose_b);
    let mut out = Vec::new();
    hull_manifold_or_separation_warm(a, b, &pose_ab, prediction, None, warm, &mut out);
    out.into_iter()
        .map(|(c, _)| c.transformed(pose_a))
        .collect()
}

/// `pose` moved by `dt` and turned by `angle` about `axis`.
fn nudged(pose: &Isometry, dt: Vec3, axis: Vec3, angle: Real) -> Isometry {
    Isometry::new(
        pose.translation + dt,
        (Quat::from_axis_angle(axis, angle) * pose.rotation).normalize(),
    )
}

fn check_warm(a: &Shape, b: &Shape, pr: &Params) -> Result<(), TestCaseError> {
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
    // Simplices kept at a nearby pose (one step of a resting pair), a far one (B turned
    // half round and moved by its size), and this very pose.
    let near = nudged(
        &pose_b,
        Vec3::new(1e-3, -2e-3, 5e-4),
        Vec3::new(0.3, 0.9, 0.1),
        2e-3,
    );
    let far = nudged(
        &pose_b,
        Vec3::new(0.7, 0.4, -0.5),
        Vec3::new(-0.5, 0.2, 0.8),
        3.0,
    );
    for (name, keep_at) in [("near", near), ("far", far), ("same", pose_b)] {
        let mut warm = WarmSimplex::default();
        manifold(a, &pose_a, b, &keep_at, prediction, Some(&mut warm));
        let got = manifold(a, &pose_a, b, &pose_b, prediction, Some(&mut warm));
        check_against_polytope(a, &pose_a, b, &pose_b, &got, pr.kind, tol + r(prediction))
            .map_err(|e| {
                TestCaseError::fail(format!(
                    "{name} simplex, {} against {}: {e}\n{got:?}",
                    a.kind_name(),
                    b.kind_name()
                ))
            })?;
        // A contact only one of them reports must lie at the prediction, within round-off.
        for (only, other) in [(&base, &got), (&got, &base)] {
            if let (Some(d), None) = (deepest(only), deepest(other)) {
                prop_assert!(
                    r(d) >= r(prediction) - tol,
                    "{name} simplex: one manifold empty, the other {d} deep ({:?})",
                    pr.kind
                );
            }
        }
        check_same_depth(&base, &got, tol, &format!("{name} simplex against cold"))?;
    }
    Ok(())
}

hull_pair_cases!(
    check_warm,
    0x7761_726d_0021,
    hull_hull_manifolds_do_not_depend_on_the_kept_simplex,
    box_hull_manifolds_do_not_depend_on_the_kept_simplex
);

/// A simplex is kept with its points in each shape's own frame, and one whose points do not
/// lie in the shapes' boxes (kept for other shapes) is not used.
#[test]
fn a_kept_simplex_fits_only_its_own_shapes() {
    let taru = Shape::ConvexHull(ConvexHull::new(&taru_points()).unwrap());
    let small = Shape::ConvexHull(
        ConvexHull::new(&taru_points().iter().map(|p| *p * 0.1).collect::<Vec<_>>()).unwrap(),
    );
    let (pose_a, pose_b) = (
        Isometry::new(Vec3::new(3.0, -1.0, 2.0), Quat::from_rotation_x(0.4)),
        Isometry::new(Vec3::new(3.5, 1.2, 2.1), Quat::from_rotation_z(-0.7)),
    );
    let mut warm = WarmSimplex::default();
    manifold(&taru, &pose_a, &taru, &pose_b, 0.02, Some(&mut warm));
    assert!(warm.len > 0);
    let boxes = |s: &Shape| s.as_convex().unwrap().local_aabb();
    assert!(warm.fits(boxes(&taru), boxes(&taru)));
    assert!(!warm.fits(boxes(&small), boxes(&small)));
    assert!(!warm.fits(Aabb::new(Vec3::ZERO, Vec3::ZERO), boxes(&taru)));
    // The small pair's contact from the big pair's simplex equals its cold contact.
    let cold = manifold(&small, &pose_a, &small, &pose_b, 0.02, None);
    let got = manifold(&small, &pose_a, &small, &pose_b, 0.02, Some(&mut warm));
    assert_eq!(cold, got);
}

/// A Taru barrel resting on another and rocking (a small tilt and slide every step, as in
/// "1000 convex"), 1 km out on odd runs: at every step the manifold started from the last
/// step's simplex has the cold manifold's depth and normal within round-off, and the kept
/// simplex saves the search its support queries (its depth then equals the oracle's).
#[test]
fn a_rocking_barrel_gives_the_cold_depth_at_every_step() {
    let taru = Shape::ConvexHull(ConvexHull::new(&taru_points()).unwrap());
    let Shape::ConvexHull(h) = &taru else {
        unreachable!()
    };
    let top = h.vertices().iter().map(|v| v.y).fold(Real::MIN, Real::max);
    let bottom = h.vertices().iter().map(|v| v.y).fold(Real::MAX, Real::min);
    let mut rng = Rng::new(21);
    for run in 0..4 {
        let far = if run % 2 == 0 {
            Vec3::ZERO
        } else {
            Vec3::new(-6.0e2, 3.0e2, 8.0e2)
        };
        let tol = tolerance(far);
        let pose_a = Isometry::new(far, Quat::IDENTITY);
        let mut warm = WarmSimplex::default();
        for step in 0..300 {
            let t = step as Real / 60.0;
            let tilt =
                Quat::from_axis_angle(Vec3::new(1.0, 0.0, 0.3).normalize(), 0.02 * (5.0 * t).sin());
            let depth = 1.0e-3 * (1.0 + (3.0 * t).cos()) + rng.range(-1e-5, 1e-5);
            let pose_b = Isometry::new(
                far + Vec3::Y * (top - bottom - depth) + Vec3::new(0.1 * t.sin(), 0.0, 0.0),
                (tilt * Quat::from_rotation_y(0.3 * t)).normalize(),
            );
            let cold = manifold(&taru, &pose_a, &taru, &pose_b, 0.02, None);
            let got = manifold(&taru, &pose_a, &taru, &pose_b, 0.02, Some(&mut warm));
            let (d0, d1) = (deepest(&cold), deepest(&got));
            assert_eq!(d0.is_some(), d1.is_some(), "run {run} step {step}");
            if let (Some(d0), Some(d1)) = (d0, d1) {
                assert!(
                    r(d0 - d1).abs() <= tol + 2.0e-3 * (1.0 + r(d0).abs()),
                    "run {run} step {step}: {d1} against {d0}"
                );
                let (n0, n1) = (cold[0].normal, got[0].normal);
                assert!(
                    n0.dot(n1) > 0.99,
                    "run {run} step {step}: {n1} against {n0}"
                );
            }
            if step % 50 == 0 {
                check_against_polytope(
                    &taru,
                    &pose_a,
                    &taru,
                    &pose_b,
                    &got,
                    Kind::Random,
                    tol + 0.02,
                )
                .unwrap_or_else(|e| panic!("run {run} step {step}: {e}"));
            }
        }
    }
}
