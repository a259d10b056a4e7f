//! The persistent manifold's matrix paths against the quaternion forms they replaced:
//! generated points converted with the bodies' rotation matrices
//! (`ContactPoint::from_local_contact_mat`) against `from_local_contact`, and the
//! coherence test's per-point displacement (`(R - R0) x + Δt`) against transforming each
//! point by both poses. Near the origin and 1 km from it, tiny and large rotations,
//! zero-size and thin shapes' points, identical poses.

mod common;

use carom_collision::math::{Isometry, Quat, Real, Vec3};
use carom_collision::narrowphase::{
    ContactManifold, ContactPoint, Dispatcher, COHERENCE_ANGLE, COHERENCE_DISTANCE,
};
use carom_collision::query::Contact;
use carom_collision::shape::{Cuboid, Shape};
use common::Rng;

fn random_pose(rng: &mut Rng, far: Real) -> Isometry {
    Isometry::new(
        rng.unit() * rng.range(0.0, 3.0) + Vec3::new(far, -0.5 * far, 0.25 * far),
        Quat::from_axis_angle(rng.unit(), rng.range(-3.1, 3.1)),
    )
}

fn close(a: Vec3, b: Vec3, tol: Real) -> bool {
    (a - b).length() <= tol
}

#[test]
fn matrix_conversion_matches_the_quaternion_one() {
    let mut rng = Rng::new(0x5eed_0009);
    for k in 0..4000 {
        let far = [0.0, 1000.0, -1000.0, 10.0][k % 4];
        let (pa, pb) = (random_pose(&mut rng, far), random_pose(&mut rng, far));
        // Points in A's frame up to a few metres out (zero-size shapes: the origin).
        let scale = [0.0, 1e-4, 1.0, 5.0][(k / 4) % 4];
        let normal = rng.unit();
        let point_a = rng.unit() * scale;
        let distance = rng.range(-0.1, 0.05);
        let c = Contact {
            distance,
            point_a,
            point_b: point_a + normal * distance,
            normal,
        };
        let id = k as u32;
        let old = ContactPoint::from_local_contact(&c, &pa, &pb, id);
        let (ra, rb) = (pa.rotation_matrix(), pb.rotation_matrix());
        let new = ContactPoint::from_local_contact_mat(
            &c,
            (&ra, pa.translation),
            (&rb.transpose(), pb.translation),
            id,
        );
        // Round-off relative to the coordinates involved (f32: a few ulps of 1 km).
        let big = 1.0 + pa.translation.length() + pb.translation.length() + scale;
        let tol = 16.0 * Real::EPSILON * big;
        assert_eq!(new.distance, old.distance, "case {k}");
        assert_eq!(new.local_a, old.local_a, "case {k}");
        assert_eq!(new.feature, id);
        assert!(
            close(new.point_b, old.point_b, tol),
            "case {k}: {new:?} {old:?}"
        );
        assert!(
            close(new.local_b, old.local_b, tol),
            "case {k}: {new:?} {old:?}"
        );
        assert!(
            close(new.normal, old.normal, 8.0 * Real::EPSILON),
            "case {k}"
        );
        assert!(close(
            new.local_normal_b,
            old.local_normal_b,
            8.0 * Real::EPSILON
        ));
        assert!((new.normal.length() - 1.0).abs() < 8.0 * Real::EPSILON);
        assert_eq!(new.normal_impulse, 0.0);
        assert_eq!(new.lifetime, 0);
    }
}

/// A box resting on a box, generated at one relative pose, then asked whether another pose
/// is coherent: the answer must be what transforming every point by both poses says, except
/// when the largest displacement is within round-off of the tolerance.
#[test]
fn coherence_matches_per_point_transforms() {
    let mut rng = Rng::new(0x5eed_0010);
    let d = Dispatcher::default();
    let (mut yes, mut no) = (0, 0);
    for k in 0..3000 {
        let far = [0.0, 1000.0][k % 2];
        let (ha, hb) = if k % 7 == 0 {
            // Thin boxes: a plate on a plate.
            (Vec3::new(1.0, 0.001, 0.8), Vec3::new(0.5, 0.001, 0.6))
        } else {
            (
                Vec3::new(
                    rng.range(0.1, 2.0),
                    rng.range(0.1, 2.0),
                    rng.range(0.1, 2.0),
                ),
                Vec3::new(
                    rng.range(0.1, 2.0),
                    rng.range(0.1, 2.0),
                    rng.range(0.1, 2.0),
                ),
            )
        };
        let (a, b) = (
            Shape::Cuboid(Cuboid::new(ha).unwrap()),
            Shape::Cuboid(Cuboid::new(hb).unwrap()),
        );
        let spin = Quat::from_rotation_y(rng.range(-3.1, 3.1));
        let pose_a = Isometry::new(Vec3::new(far, 0.0, -far), Quat::IDENTITY);
        let pose_b = Isometry::new(
            Vec3::new(
                far + rng.range(-0.2, 0.2),
                ha.y + hb.y - 0.001,
                -far + rng.range(-0.2, 0.2),
            ),
            spin,
        );
        let mut m = ContactManifold::new();
        d.update_manifold(&a, &pose_a, &b, &pose_b, &mut m).unwrap();
        let Some(p0) = m.generated_at else {
            continue;
        };
        assert!(!m.is_empty());
        // A relative motion around the tolerances: sometimes none at all.
        let scale = [0.0, 0.3, 1.0, 3.0][k % 4];
        let angle = scale * COHERENCE_ANGLE * rng.range(0.0, 1.0);
        let shift = rng.unit() * scale * COHERENCE_DISTANCE * rng.range(0.0, 1.0);
        let pose_ab = Isometry::new(
            p0.translation + shift,
            (Quat::from_axis_angle(rng.unit(), angle) * p0.rotation).normalize(),
        );
        let got = m.is_coherent(&pose_ab);
        let cos_half = (0.5 * COHERENCE_ANGLE).cos();
        let in_angle = p0.rotation.dot(pose_ab.rotation).abs() >= cos_half;
        let worst = m
            .points
            .iter()
            .map(|p| (pose_ab.transform_point(p.local_b) - p0.transform_point(p.local_b)).length())
            .fold(0.0, Real::max);
        let near = (worst - COHERENCE_DISTANCE).abs() <= 1e-3 * COHERENCE_DISTANCE + 1e-6;
        if !near {
            assert_eq!(
                got,
                in_angle && worst <= COHERENCE_DISTANCE,
                "case {k}: worst {worst}, angle {angle}"
            );
        }
        if got {
            yes += 1;
        } else {
            no += 1;
        }
    }
    // Both answers occur (the test can fail either way).
    assert!(yes > 300 && no > 300, "{yes} coherent, {no} not");
}
