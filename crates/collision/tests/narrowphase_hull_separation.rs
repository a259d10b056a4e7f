//! The separation certificate of apart hull–hull and hull–box pairs (`ContactManifold::apart`,
//! kept from GJK's last direction by `polyhedron_manifold_or_separation`): while it holds,
//! `Dispatcher::update_manifold` skips the pair. Checked against brute force (the vertices
//! projected on the certificate's axis at the new pose), the GJK distance and fresh
//! generation, near the origin and 1 km from it, in both orders; and along a motion, the
//! persistent manifold against one generated from scratch at every step.

mod common;

use carom_collision::math::{Isometry, Quat, Real, Vec3};
use carom_collision::narrowphase::{ContactManifold, Dispatcher, ManifoldConfig};
use carom_collision::query;
use carom_collision::shape::{ConvexHull, Cuboid, Shape};
use common::Rng;

fn random_hull(rng: &mut Rng) -> Shape {
    loop {
        let n = 6 + (rng.range(0.0, 20.0) as usize);
        let pts: Vec<Vec3> = (0..n).map(|_| rng.unit() * rng.range(0.3, 1.0)).collect();
        if let Ok(h) = ConvexHull::new(&pts) {
            if h.volume() > 0.05 {
                return Shape::ConvexHull(h);
            }
        }
    }
}

fn random_shape(rng: &mut Rng, k: usize) -> Shape {
    if k % 3 == 2 {
        Shape::Cuboid(
            Cuboid::new(Vec3::new(
                rng.range(0.05, 1.0),
                rng.range(0.05, 1.0),
                rng.range(0.05, 1.0),
            ))
            .unwrap(),
        )
    } else {
        random_hull(rng)
    }
}

/// The shape's vertices at `pose`.
fn vertices(s: &Shape, pose: &Isometry) -> Vec<Vec3> {
    let local: Vec<Vec3> = match s {
        Shape::ConvexHull(h) => h.vertices().to_vec(),
        Shape::Cuboid(c) => {
            let h = c.half_extents();
            (0..8)
                .map(|k| {
                    h * Vec3::new(
                        if k & 1 == 0 { -1.0 } else { 1.0 },
                        if k & 2 == 0 { -1.0 } else { 1.0 },
                        if k & 4 == 0 { -1.0 } else { 1.0 },
                    )
                })
                .collect()
        }
        _ => unreachable!(),
    };
    local.iter().map(|v| pose.transform_point(*v)).collect()
}

/// Separation of the shapes along `axis` (A's frame), from their vertices.
fn brute_separation(a: &Shape, b: &Shape, pose_ab: &Isometry, axis: Vec3) -> Real {
    let a_max = vertices(a, &Isometry::IDENTITY)
        .iter()
        .map(|c| c.dot(axis))
        .fold(Real::NEG_INFINITY, Real::max);
    let b_min = vertices(b, pose_ab)
        .iter()
        .map(|c| c.dot(axis))
        .fold(Real::INFINITY, Real::min);
    b_min - a_max
}

#[test]
fn a_holding_hull_certificate_proves_the_gap() {
    let mut rng = Rng::new(11);
    let d = Dispatcher::new(ManifoldConfig::default());
    let (mut made, mut held, mut failed, mut none) = (0, 0, 0, 0);
    for k in 0..300 {
        let (sa, sb) = (random_shape(&mut rng, k), random_hull(&mut rng));
        // Hull first at times (the box is always one of the two when there is one).
        let (sa, sb) = if k % 2 == 1 { (sb, sa) } else { (sa, sb) };
        let origin = if k % 4 < 2 {
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
        // Apart by -0.01–0.3 beyond contact (touching and within the prediction too).
        let mut pose_ab = Isometry::new(dir * 4.0, rot_b);
        let c0 = query::distance(&sa, &Isometry::IDENTITY, &sb, &pose_ab).unwrap();
        let gap = [0.0, 0.01, rng.range(0.0, 0.3), rng.range(0.02, 0.3)][k % 4];
        pose_ab.translation -= c0.normal * (c0.distance - gap);
        let pose_b = pose_a * pose_ab;
        let mut m = ContactManifold::new();
        d.update_manifold(&sa, &pose_a, &sb, &pose_b, &mut m)
            .unwrap();
        let Some(cert) = m.apart else {
            none += 1;
            continue;
        };
        made += 1;
        assert!(m.is_empty(), "a certificate only for a pair without points");
        let now = query::distance(&sa, &Isometry::IDENTITY, &sb, &pose_ab).unwrap();
        assert!(
            now.distance > 0.02 - 1e-4,
            "a certificate within the prediction: gap {gap}, distance {} (was {}), {cert:?} brute {}",
            now.distance,
            c0.distance,
            brute_separation(&sa, &sb, &cert.pose_ab, cert.axis)
        );
        assert!((cert.axis.length() - 1.0).abs() < 1e-4);
        let brute0 = brute_separation(&sa, &sb, &cert.pose_ab, cert.axis);
        assert!(
            (brute0 - cert.distance).abs() <= 1e-4 * (1.0 + cert.pose_ab.translation.length()),
            "the certificate's separation {} is the shapes' {brute0}",
            cert.distance
        );
        for j in 0..20 {
            let scale = [0.001, 0.01, 0.05, 0.2][j % 4];
            let moved = Isometry::new(
                pose_ab.translation + rng.unit() * rng.range(0.0, scale),
                Quat::from_axis_angle(rng.unit(), rng.range(0.0, scale)) * pose_ab.rotation,
            );
            let pred = [0.02, 0.05][j % 2];
            if cert.holds(&moved, pred) {
                held += 1;
                let brute = brute_separation(&sa, &sb, &moved, cert.axis);
                assert!(brute > pred, "within {brute} along the axis: k {k} j {j}");
                let gjk = query::distance(&sa, &Isometry::IDENTITY, &sb, &moved).unwrap();
                assert!(gjk.distance > pred, "GJK distance {}", gjk.distance);
                let fresh = Dispatcher::new(ManifoldConfig {
                    prediction: pred,
                    ..Default::default()
                });
                let g = fresh.generate(&sa, &sb, &moved, true).unwrap().contacts;
                assert!(g.is_empty(), "fresh generation found {g:?}");
            } else {
                failed += 1;
            }
        }
        // A non-finite pose never satisfies a certificate.
        let bad = Isometry::new(Vec3::new(Real::NAN, 0.0, 0.0), pose_ab.rotation);
        assert!(!cert.holds(&bad, 0.02));
    }
    assert!(
        made > 80 && held > 400 && failed > 100 && none > 40,
        "{made} {held} {failed} {none}"
    );
}

/// Two hulls approaching and turning: at every step the persistent manifold (skipping the
/// pair while its certificate holds) has the points of a manifold generated from scratch.
#[test]
fn approaching_hulls_match_fresh_generation() {
    let mut rng = Rng::new(5);
    let d = Dispatcher::new(ManifoldConfig::default());
    let mut skipped = 0;
    for round in 0..6 {
        let (sa, sb) = (random_hull(&mut rng), random_shape(&mut rng, round));
        let far = if round % 2 == 0 { 0.0 } else { 1000.0 };
        let pose_a = Isometry::new(Vec3::splat(far), Quat::from_rotation_z(0.2));
        let axis = rng.unit();
        let mut m = ContactManifold::new();
        for step in 0..200 {
            let s = step as Real;
            let pose_b = Isometry::new(
                pose_a.translation + Vec3::new(3.0 - 0.012 * s, 0.3, -0.1),
                Quat::from_axis_angle(axis, 0.004 * s),
            );
            let had = m.apart;
            d.update_manifold(&sa, &pose_a, &sb, &pose_b, &mut m)
                .unwrap();
            if had.is_some() && m.apart == had {
                skipped += 1;
            }
            let mut fresh = ContactManifold::new();
            d.update_manifold(&sa, &pose_a, &sb, &pose_b, &mut fresh)
                .unwrap();
            assert_eq!(
                m.is_empty(),
                fresh.is_empty(),
                "round {round} step {step}: persistent {m:?} fresh {fresh:?}"
            );
            if !m.is_empty() {
                break;
            }
        }
    }
    assert!(skipped > 100, "skipped {skipped}");
}
