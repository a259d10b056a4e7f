//! The separation certificate of apart box pairs (`ContactManifold::apart`): while it holds,
//! `Dispatcher::update_manifold` skips the pair. Checked against brute force (the boxes'
//! corners projected on the certificate's axis at the new pose), the GJK distance, and fresh
//! generation at every pose of a motion (the persistent manifold must give the same points as
//! a manifold generated from scratch whenever there are any).

mod common;

use carom_collision::math::{Isometry, Quat, Real, Vec3};
use carom_collision::narrowphase::contact_cuboid_cuboid::cuboid_cuboid_manifold_into;
use carom_collision::narrowphase::{ContactManifold, Dispatcher, ManifoldConfig};
use carom_collision::query;
use carom_collision::shape::{Cuboid, Shape};
use common::Rng;

fn corners(h: Vec3, pose: &Isometry) -> Vec<Vec3> {
    (0..8)
        .map(|k| {
            let s = Vec3::new(
                if k & 1 == 0 { -1.0 } else { 1.0 },
                if k & 2 == 0 { -1.0 } else { 1.0 },
                if k & 4 == 0 { -1.0 } else { 1.0 },
            );
            pose.transform_point(h * s)
        })
        .collect()
}

/// Separation of the boxes along `axis` (A's frame), from their corners.
fn brute_separation(ha: Vec3, hb: Vec3, pose_ab: &Isometry, axis: Vec3) -> Real {
    let a_max = corners(ha, &Isometry::IDENTITY)
        .iter()
        .map(|c| c.dot(axis))
        .fold(Real::NEG_INFINITY, Real::max);
    let b_min = corners(hb, pose_ab)
        .iter()
        .map(|c| c.dot(axis))
        .fold(Real::INFINITY, Real::min);
    b_min - a_max
}

fn random_box(rng: &mut Rng) -> Vec3 {
    Vec3::new(
        rng.range(0.05, 1.0),
        rng.range(0.05, 1.0),
        rng.range(0.05, 1.0),
    )
}

#[test]
fn a_holding_certificate_proves_the_gap() {
    let mut rng = Rng::new(7);
    let d = Dispatcher::new(ManifoldConfig::default());
    let (mut made, mut held, mut failed) = (0, 0, 0);
    for k in 0..400 {
        let (ha, hb) = (random_box(&mut rng), random_box(&mut rng));
        let (sa, sb) = (
            Shape::Cuboid(Cuboid::new(ha).unwrap()),
            Shape::Cuboid(Cuboid::new(hb).unwrap()),
        );
        // Near the origin and 1 km from it (the certificate lives in A's frame).
        let origin = if k % 2 == 0 {
            Vec3::ZERO
        } else {
            Vec3::new(1000.0, -700.0, 300.0)
        };
        let pose_a = Isometry::new(
            origin,
            Quat::from_axis_angle(rng.unit(), rng.range(0.0, 3.0)),
        );
        let rot_b = Quat::from_axis_angle(rng.unit(), rng.range(0.0, 3.0));
        let dir = rng.unit();
        // Apart by 0–0.3 beyond contact: place B along `dir` just outside A.
        let mut pose_ab = Isometry::new(dir * 3.0, rot_b);
        let c0 = query::distance(&sa, &Isometry::IDENTITY, &sb, &pose_ab).unwrap();
        pose_ab.translation -= dir * (c0.distance - rng.range(0.0, 0.3));
        let pose_b = pose_a * pose_ab;
        let mut m = ContactManifold::new();
        d.update_manifold(&sa, &pose_a, &sb, &pose_b, &mut m)
            .unwrap();
        let Some(cert) = m.apart else {
            assert!(
                !m.is_empty() || c0.distance >= 0.0,
                "no certificate only for pairs within the prediction"
            );
            continue;
        };
        made += 1;
        assert!(m.is_empty());
        assert!((cert.axis.length() - 1.0).abs() < 1e-4);
        let brute0 = brute_separation(ha, hb, &cert.pose_ab, cert.axis);
        assert!(
            (brute0 - cert.distance).abs() <= 1e-4 * (1.0 + cert.pose_ab.translation.length()),
            "the certificate's separation {} is the boxes' {brute0}",
            cert.distance
        );
        // Random motions of B, small and large, translation and rotation (about B's origin,
        // where the reach matters).
        for j in 0..20 {
            let scale = [0.001, 0.01, 0.05, 0.2][j % 4];
            let moved = Isometry::new(
                pose_ab.translation + rng.unit() * rng.range(0.0, scale),
                Quat::from_axis_angle(rng.unit(), rng.range(0.0, scale)) * pose_ab.rotation,
            );
            let pred = [0.02, 0.05][j % 2];
            if cert.holds(&moved, pred) {
                held += 1;
                let brute = brute_separation(ha, hb, &moved, cert.axis);
                assert!(
                    brute > pred,
                    "the boxes came within {brute} along the axis: k {k} j {j} {cert:?} {moved:?} brute0 {brute0}"
                );
                let gjk = query::distance(&sa, &Isometry::IDENTITY, &sb, &moved).unwrap();
                assert!(gjk.distance > pred, "GJK distance {}", gjk.distance);
                let mut out = Vec::new();
                let (x, y) = (Cuboid::new(ha).unwrap(), Cuboid::new(hb).unwrap());
                cuboid_cuboid_manifold_into(&x, &y, &moved, pred, &mut out);
                assert!(out.is_empty(), "fresh generation found {out:?}");
            } else {
                failed += 1;
            }
        }
    }
    assert!(
        made > 100 && held > 500 && failed > 100,
        "{made} {held} {failed}"
    );
}

/// Two boxes approaching, rotating and passing each other: the persistent manifold (which
/// skips while the certificate holds) equals a fresh generation at every step, and it
/// skipped some steps.
#[test]
fn skipping_gives_the_points_of_fresh_generation() {
    let d = Dispatcher::new(ManifoldConfig::default());
    let a = Shape::Cuboid(Cuboid::new(Vec3::new(1.0, 0.5, 0.5)).unwrap());
    // A long thin box spinning about its centre: the rotation, not the translation, closes
    // the gap.
    let b = Shape::Cuboid(Cuboid::new(Vec3::new(2.0, 0.05, 0.05)).unwrap());
    for origin in [Vec3::ZERO, Vec3::new(-1000.0, 500.0, 1000.0)] {
        let pose_a = Isometry::new(origin, Quat::from_rotation_y(0.2));
        let mut m = ContactManifold::new();
        let mut skipped = 0;
        let mut touching = 0;
        for step in 0..400 {
            let s = step as Real;
            let pose_ab = Isometry::new(
                Vec3::new(0.0, 2.6 - 0.0025 * s, 0.3),
                Quat::from_rotation_z(0.004 * s) * Quat::from_rotation_x(0.3),
            );
            let pose_b = pose_a * pose_ab;
            let had = m.apart;
            d.update_manifold(&a, &pose_a, &b, &pose_b, &mut m).unwrap();
            if had.is_some() && m.apart == had {
                skipped += 1;
            }
            let mut f = ContactManifold::new();
            d.update_manifold(&a, &pose_a, &b, &pose_b, &mut f).unwrap();
            if m.is_empty() || f.is_empty() {
                assert_eq!(m.len(), f.len(), "step {step}: {m:?} vs fresh {f:?}");
                if m.is_empty() {
                    assert!(
                        query::distance(&a, &pose_a, &b, &pose_b).unwrap().distance > 0.0,
                        "step {step}: an empty manifold for touching boxes"
                    );
                }
            } else {
                touching += 1;
            }
            // The first contact of a persistent manifold is a fresh generation.
            if had.is_some() && !m.is_empty() {
                assert_eq!(m.points, f.points, "step {step}");
            }
        }
        assert!(skipped > 50 && touching > 10, "{skipped} {touching}");
    }
}

#[test]
fn non_finite_or_touching_pairs_get_no_certificate() {
    let d = Dispatcher::new(ManifoldConfig::default());
    let a = Shape::Cuboid(Cuboid::new(Vec3::splat(0.5)).unwrap());
    // Touching face to face, and within the prediction: points, no certificate.
    for gap in [0.0, 0.01] {
        let mut m = ContactManifold::new();
        let pose_b = Isometry::from_translation(Vec3::new(0.0, 1.0 + gap, 0.0));
        d.update_manifold(&a, &Isometry::IDENTITY, &a, &pose_b, &mut m)
            .unwrap();
        assert_eq!(m.len(), 4);
        assert!(m.apart.is_none());
    }
    // Apart: a certificate, which a non-finite pose never satisfies; clearing forgets it.
    let mut m = ContactManifold::new();
    let far = Isometry::from_translation(Vec3::new(0.0, 1.5, 0.0));
    d.update_manifold(&a, &Isometry::IDENTITY, &a, &far, &mut m)
        .unwrap();
    let cert = m.apart.expect("a certificate for boxes 0.5 apart");
    assert!((cert.distance - 0.5).abs() < 1e-5);
    assert!(cert.holds(&far, 0.02));
    assert!(!cert.holds(&far, 0.6));
    let bad = Isometry::from_translation(Vec3::new(0.0, Real::NAN, 0.0));
    assert!(!cert.holds(&bad, 0.02));
    m.clear();
    assert!(m.apart.is_none());
}

/// The coherence test's cheap bound must see small rotations in f32 too: a box resting on a
/// box, turned by 4e-4 rad about the vertical (its corners move by about 3e-4, three times
/// `COHERENCE_DISTANCE`), is generated again. Before, `sqrt(1 - (q·q0)²)` rounded to 0 in
/// f32 below about 5e-4 rad and the stale points were kept.
#[test]
fn coherence_sees_small_rotations() {
    use carom_collision::narrowphase::COHERENCE_DISTANCE;
    let d = Dispatcher::new(ManifoldConfig::default());
    let a = Shape::Cuboid(Cuboid::new(Vec3::new(5.0, 0.5, 5.0)).unwrap());
    let b = Shape::Cuboid(Cuboid::new(Vec3::splat(0.5)).unwrap());
    for origin in [Vec3::ZERO, Vec3::new(300.0, 0.0, -200.0)] {
        let pose_a = Isometry::from_translation(origin);
        let at = |angle: Real| {
            Isometry::new(
                origin + Vec3::new(0.0, 0.999, 0.0),
                Quat::from_rotation_y(0.3 + angle),
            )
        };
        let mut m = ContactManifold::new();
        d.update_manifold(&a, &pose_a, &b, &at(0.0), &mut m)
            .unwrap();
        assert_eq!(m.len(), 4);
        let before = m.generated_at;
        // A rotation whose corner motion stays under the tolerance keeps the points...
        let tiny = 0.5 * COHERENCE_DISTANCE / 0.75;
        d.update_manifold(&a, &pose_a, &b, &at(tiny), &mut m)
            .unwrap();
        assert_eq!(m.generated_at, before, "kept at {tiny} rad");
        // ... one that moves the corners by three times the tolerance regenerates them.
        d.update_manifold(&a, &pose_a, &b, &at(4.0e-4), &mut m)
            .unwrap();
        assert_ne!(m.generated_at, before, "regenerated at 4e-4 rad");
        let fresh = {
            let mut f = ContactManifold::new();
            d.update_manifold(&a, &pose_a, &b, &at(4.0e-4), &mut f)
                .unwrap();
            f
        };
        for (p, q) in m.points.iter().zip(&fresh.points) {
            assert!((p.point_b - q.point_b).length() <= COHERENCE_DISTANCE);
        }
    }
}
