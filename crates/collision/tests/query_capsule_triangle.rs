//! The closed-form capsule–triangle contact (`contact_capsule_triangle_separated`) against
//! two oracles: GJK/EPA (the general path it replaces) and a brute-force distance (the
//! segment sampled densely against the triangle's closest points). Random configurations,
//! plus touching, parallel (to the plane and to an edge), piercing and far-from-origin ones.

#[path = "query_common/mod.rs"]
mod common;

use carom_collision::math::{Isometry, Real, Vec3};
use carom_collision::query::closest_points::closest_point_triangle;
use carom_collision::query::contact_convex::contact_gjk_epa;
use carom_collision::query::contact_round::contact_capsule_triangle_separated;
use carom_collision::query::{contact_convex, Contact};
use carom_collision::shape::{Capsule, ConvexRef, Triangle};
use common::*;

/// Distance of the segment `p q` to the triangle by sampling the segment (an upper bound
/// within `|q - p| / samples` of the exact one).
fn brute_distance(p: Vec3, q: Vec3, t: [Vec3; 3], samples: usize) -> Real {
    (0..=samples)
        .map(|i| {
            let x = p + (q - p) * (i as Real / samples as Real);
            (closest_point_triangle(x, t[0], t[1], t[2]) - x).length()
        })
        .fold(Real::INFINITY, Real::min)
}

/// Checks the closed form for capsule `cap` against triangle `tri` placed by `pose_ab`
/// (in the capsule's frame); returns whether the closed form decided.
fn check(cap: &Capsule, tri: &Triangle, pose_ab: &Isometry, prediction: Real) -> bool {
    let closed = contact_capsule_triangle_separated(cap, tri, pose_ab, prediction);
    let (a, b) = (ConvexRef::Capsule(cap), ConvexRef::Triangle(tri));
    let Some(closed) = closed else {
        // Undecided: the dispatcher's answer is GJK/EPA's.
        let k = contact_convex(a, b, pose_ab, prediction);
        let g = contact_gjk_epa(a, b, pose_ab, prediction);
        assert_eq!(k.map(|c| c.distance), g.map(|c| c.distance));
        return false;
    };
    let t = tri.vertices().map(|v| pose_ab.transform_point(v));
    let (p, q) = cap.segment();
    let r = cap.radius();
    let scale = 1.0 + pose_ab.translation.abs().max_element() + (q - p).length();
    let eps = tol() * 10.0 * scale;
    let brute = brute_distance(p, q, t, 2000) - r;
    let step = (q - p).length() / 2000.0;
    let g = contact_gjk_epa(a, b, pose_ab, Real::MAX);
    match closed {
        Some(c) => {
            check_contact(&c, p, q, r, t, eps);
            assert!(c.distance <= prediction);
            assert!(c.distance <= brute + eps, "{} vs brute {brute}", c.distance);
            assert!(
                c.distance >= brute - step - eps,
                "{} vs brute {brute}",
                c.distance
            );
            let g = g.expect("GJK finds the pair");
            assert!(
                (c.distance - g.distance).abs() <= eps,
                "closed {} vs GJK {}",
                c.distance,
                g.distance
            );
            let k = contact_convex(ConvexRef::Triangle(tri), a, &pose_ab.inverse(), prediction)
                .expect("the swapped pair agrees");
            assert!((k.distance - c.distance).abs() <= eps);
        }
        None => {
            assert!(brute > prediction - eps, "missed a contact at {brute}");
            if let Some(g) = g {
                assert!(g.distance > prediction - eps);
            }
        }
    }
    true
}

/// The contact's convention and witnesses: on the capsule's surface, on the triangle,
/// `point_b = point_a + normal · distance`.
fn check_contact(c: &Contact, p: Vec3, q: Vec3, r: Real, t: [Vec3; 3], eps: Real) {
    assert!((c.normal.length() - 1.0).abs() <= 1e-4);
    assert!((c.point_b - c.point_a - c.normal * c.distance).length() <= eps);
    let on_tri = closest_point_triangle(c.point_b, t[0], t[1], t[2]);
    assert!((on_tri - c.point_b).length() <= eps);
    let (on_seg, _) =
        carom_collision::query::closest_points::closest_point_segment(c.point_a, p, q);
    assert!(((on_seg - c.point_a).length() - r).abs() <= eps);
}

fn random_triangle(rng: &mut Rng, s: Real) -> Triangle {
    Triangle {
        a: rng.vec(s),
        b: rng.vec(s),
        c: rng.vec(s),
    }
}

#[test]
fn random_capsules_agree_with_gjk_and_brute_force() {
    let mut rng = Rng(7);
    let mut decided = 0;
    for i in 0..3000 {
        let cap = Capsule::new(rng.range(0.05, 0.8), rng.range(0.0, 2.0)).unwrap();
        let size = rng.range(0.3, 3.0);
        let tri = random_triangle(&mut rng, size);
        let far = if i % 3 == 0 { 100.0 } else { 0.0 };
        // The triangle near the capsule (in A's frame), given in B's frame for a random
        // pose, sometimes far from B's origin (large coordinates that cancel).
        let shift = rng.vec(2.0);
        let pose_ab = Isometry::new(rng.vec(far), rng.quat());
        let tri = Triangle {
            a: pose_ab.inverse_transform_point(tri.a + shift),
            b: pose_ab.inverse_transform_point(tri.b + shift),
            c: pose_ab.inverse_transform_point(tri.c + shift),
        };
        decided += check(&cap, &tri, &pose_ab, rng.range(0.0, 0.5)) as usize;
    }
    assert!(decided > 1000, "closed form decided only {decided} cases");
}

#[test]
fn touching_parallel_and_piercing_capsules() {
    let tri = Triangle {
        a: Vec3::new(-2.0, 0.0, -1.0),
        b: Vec3::new(2.0, 0.0, -1.0),
        c: Vec3::new(0.0, 0.0, 2.0),
    };
    let cap = Capsule::new(0.3, 1.0).unwrap();
    // The capsule's axis is its local Y: rotate it flat (along X) or keep it upright.
    let flat = carom_collision::math::Quat::from_rotation_z(std::f64::consts::FRAC_PI_2 as Real);
    for far in [Vec3::ZERO, Vec3::new(300.0, -200.0, 500.0)] {
        let tri = Triangle {
            a: tri.a + far,
            b: tri.b + far,
            c: tri.c + far,
        };
        for h in [0.3, 0.3 + 1e-4, 0.31, 0.5, 0.2, 0.0, -0.2] {
            // Lying flat at height h over the triangle (parallel to its plane; below r it
            // penetrates, at 0 the segment lies in the plane: GJK/EPA).
            let pose_world = Isometry::new(far + Vec3::new(0.0, h, 0.0), flat.inverse());
            let pose_ab = pose_world.inv_mul(&Isometry::IDENTITY);
            check(&cap, &tri, &pose_ab, 0.05);
            // Upright over the interior: endpoint–face.
            let pose_world = Isometry::from_translation(far + Vec3::new(0.1, h + 0.5, 0.0));
            check(&cap, &tri, &pose_world.inv_mul(&Isometry::IDENTITY), 0.05);
            // Parallel to the edge a-b, beside it.
            let pose_world = Isometry::new(far + Vec3::new(0.0, h, -1.0 - 0.2), flat.inverse());
            check(&cap, &tri, &pose_world.inv_mul(&Isometry::IDENTITY), 0.05);
        }
        // Piercing the triangle: undecided, GJK/EPA gives the penetration.
        let pose_world = Isometry::from_translation(far + Vec3::new(0.0, 0.1, 0.0));
        let pose_ab = pose_world.inv_mul(&Isometry::IDENTITY);
        assert!(contact_capsule_triangle_separated(&cap, &tri, &pose_ab, 0.05).is_none());
        check(&cap, &tri, &pose_ab, 0.05);
    }
}

#[test]
fn degenerate_triangles_fall_back_to_gjk() {
    let cap = Capsule::new(0.25, 0.7).unwrap();
    let mut rng = Rng(11);
    let mut fallbacks = 0;
    for far in [Vec3::ZERO, Vec3::new(-400.0, 250.0, 600.0)] {
        for k in 0..200 {
            let (p, d) = (rng.vec(1.5), rng.vec(1.0));
            // A sliver (collinear corners), a needle (two equal corners) and a point.
            let tri = match k % 3 {
                0 => Triangle {
                    a: p,
                    b: p + d,
                    c: p + d * 2.5,
                },
                1 => Triangle {
                    a: p,
                    b: p,
                    c: p + d,
                },
                _ => Triangle { a: p, b: p, c: p },
            };
            let pose_ab = Isometry::new(far + rng.vec(1.0), rng.quat());
            let tri = Triangle {
                a: pose_ab.inverse_transform_point(tri.a),
                b: pose_ab.inverse_transform_point(tri.b),
                c: pose_ab.inverse_transform_point(tri.c),
            };
            // Collinear corners may gain a sliver of area from the pose's round-off: then
            // the closed form may decide, and must agree with the oracles. Repeated corners
            // stay repeated (no area): GJK/EPA always.
            let decided = check(&cap, &tri, &pose_ab, 0.1);
            assert!(!(decided && k % 3 != 0), "case {k}");
            fallbacks += usize::from(!decided);
        }
    }
    assert!(fallbacks > 300, "only {fallbacks} fell back");
}
