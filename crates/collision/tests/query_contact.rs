//! Contact, distance and penetration against independent oracles: brute-force feature
//! enumeration and SAT for hulls, analytic answers for spheres, capsules and boxes, and
//! invariants (swap, rigid motion, witnesses on the shapes).

#[path = "query_common/mod.rs"]
mod common;

use carom_collision::math::{Isometry, Quat, Real, Vec3};
use carom_collision::query::contact_convex::contact_gjk_epa;
use carom_collision::query::{contact, distance, intersects, Contact};
use carom_collision::shape::{Capsule, Cone, Cuboid, Cylinder, Shape, Sphere};
use common::*;
use std::sync::Arc;

fn check_convention(c: &Contact) {
    check_convention_tol(c, tol() * 10.0);
}

fn check_convention_tol(c: &Contact, eps: Real) {
    assert!(c.distance.is_finite() && c.point_a.is_finite() && c.point_b.is_finite());
    assert!((c.normal.length() - 1.0).abs() < 1e-4, "{c:?}");
    let scale = 1.0 + c.point_a.abs().max_element();
    assert!(
        (c.point_a + c.normal * c.distance - c.point_b).length() < eps * scale,
        "{c:?}"
    );
}

#[test]
fn hull_hull_distance_matches_feature_enumeration() {
    let mut rng = Rng(1);
    let mut separated = 0;
    let mut worst: Real = 0.0;
    for i in 0..150 {
        let n = [8, 12, 32][i % 3];
        let a = random_hull(&mut rng, n, 1.0);
        let b = random_hull(&mut rng, n, 0.7);
        let pa = rng.pose(0.5);
        let pb = Isometry::new(
            pa.translation + rng.unit() * rng.range(1.6, 3.0),
            rng.quat(),
        );
        let (sa, sb) = (Shape::ConvexHull(a.clone()), Shape::ConvexHull(b.clone()));
        let c = distance(&sa, &pa, &sb, &pb).unwrap();
        check_convention(&c);
        if c.distance <= 0.0 {
            continue;
        }
        separated += 1;
        let want = brute_hull_distance(&a, &pa, &b, &pb);
        let err = (c.distance - want).abs() / want.max(1e-3);
        worst = worst.max(err);
        assert!(err < tol(), "{} vs {want}", c.distance);
        // Witnesses on the shapes' boundaries.
        assert!(hull_plane_distance(&a, &pa, c.point_a).abs() < tol() * 10.0);
        assert!(hull_plane_distance(&b, &pb, c.point_b).abs() < tol() * 10.0);
        assert!(((c.point_b - c.point_a).length() - c.distance).abs() < tol() * 10.0);
    }
    assert!(separated > 100, "too few separated cases: {separated}");
    eprintln!("hull-hull distance: worst relative error {worst:e}");
}

#[test]
fn hull_hull_penetration_matches_sat_oracle() {
    let mut rng = Rng(2);
    let mut deep = 0;
    let mut worst: Real = 0.0;
    for i in 0..150 {
        let n = [8, 16, 32][i % 3];
        let a = random_hull(&mut rng, n, 1.0);
        let b = random_hull(&mut rng, n, 0.8);
        let pa = rng.pose(0.5);
        let pb = Isometry::new(
            pa.translation + rng.unit() * rng.range(0.0, 1.2),
            rng.quat(),
        );
        let (sa, sb) = (Shape::ConvexHull(a.clone()), Shape::ConvexHull(b.clone()));
        let c = distance(&sa, &pa, &sb, &pb).unwrap();
        let want = brute_hull_depth(&a, &pa, &b, &pb);
        check_convention(&c);
        if want <= 0.0 {
            continue;
        }
        deep += 1;
        let err = (-c.distance - want).abs();
        worst = worst.max(err);
        assert!(err < tol() * 10.0, "EPA {} vs SAT {want}", -c.distance);
        // Moving B by the MTD makes them touch.
        let moved = Isometry::new(pb.translation - c.normal * c.distance, pb.rotation);
        let after = distance(&sa, &pa, &sb, &moved).unwrap();
        assert!(after.distance.abs() < tol() * 20.0, "{after:?}");
    }
    assert!(deep > 100, "too few overlapping cases: {deep}");
    eprintln!("hull-hull penetration: worst absolute error {worst:e}");
}

#[test]
fn box_box_sat_agrees_with_gjk_epa_and_sat_oracle() {
    let mut rng = Rng(3);
    let mut overlaps = 0;
    for _ in 0..300 {
        let ha = Vec3::new(
            rng.range(0.2, 1.5),
            rng.range(0.2, 1.5),
            rng.range(0.2, 1.5),
        );
        let hb = Vec3::new(
            rng.range(0.2, 1.5),
            rng.range(0.2, 1.5),
            rng.range(0.2, 1.5),
        );
        let (a, b) = (Cuboid::new(ha).unwrap(), Cuboid::new(hb).unwrap());
        let pose_ab = Isometry::new(rng.vec(2.0), rng.quat());
        let fast = carom_collision::query::contact_convex(
            carom_collision::shape::ConvexRef::Cuboid(&a),
            carom_collision::shape::ConvexRef::Cuboid(&b),
            &pose_ab,
            Real::INFINITY,
        )
        .unwrap();
        let general = contact_gjk_epa(
            carom_collision::shape::ConvexRef::Cuboid(&a),
            carom_collision::shape::ConvexRef::Cuboid(&b),
            &pose_ab,
            Real::INFINITY,
        )
        .unwrap();
        check_convention(&fast);
        assert!(
            (fast.distance - general.distance).abs() < tol() * 10.0,
            "{fast:?} {general:?}"
        );
        let hull = |h: Vec3| {
            carom_collision::shape::ConvexHull::new(&Cuboid::new(h).unwrap().vertices()).unwrap()
        };
        if fast.distance < 0.0 {
            overlaps += 1;
            let want = brute_hull_depth(&hull(ha), &Isometry::IDENTITY, &hull(hb), &pose_ab);
            assert!((-fast.distance - want).abs() < tol() * 10.0);
            // Witnesses lie in the boxes (within tolerance).
            let pa = fast.point_a;
            assert!((pa.abs() - ha).max_element() < tol() * 10.0, "{fast:?}");
            let pb = pose_ab.inverse_transform_point(fast.point_b);
            assert!((pb.abs() - hb).max_element() < tol() * 10.0, "{fast:?}");
        }
    }
    assert!(overlaps > 60 && overlaps < 280, "{overlaps}");
}

#[test]
fn analytic_spheres_capsules_and_boxes() {
    let mut rng = Rng(4);
    for _ in 0..200 {
        let (ra, rb) = (rng.range(0.1, 1.0), rng.range(0.1, 1.0));
        let pa = rng.pose(3.0);
        let pb = rng.pose(3.0);
        let sa = Shape::Sphere(Sphere::new(ra).unwrap());
        let sb = Shape::Sphere(Sphere::new(rb).unwrap());
        let want = (pb.translation - pa.translation).length() - ra - rb;
        let c = distance(&sa, &pa, &sb, &pb).unwrap();
        check_convention(&c);
        assert!((c.distance - want).abs() < tol());
        assert_eq!(intersects(&sa, &pa, &sb, &pb).unwrap(), want <= 0.0);

        // Capsule vs sphere: the distance from the sphere centre to the segment.
        let (hh, rc) = (rng.range(0.1, 1.0), rng.range(0.1, 0.5));
        let cap = Shape::Capsule(Capsule::new(rc, hh).unwrap());
        let p0 = pa.transform_point(Vec3::new(0.0, -hh, 0.0));
        let p1 = pa.transform_point(Vec3::new(0.0, hh, 0.0));
        let (q, _) =
            carom_collision::query::closest_points::closest_point_segment(pb.translation, p0, p1);
        let want = (q - pb.translation).length() - rc - rb;
        let c = distance(&cap, &pa, &sb, &pb).unwrap();
        check_convention(&c);
        assert!((c.distance - want).abs() < tol(), "{c:?} vs {want}");
        // The general GJK/EPA path agrees with the special case (exact through cores).
        let pose_ab = pa.inv_mul(&pb);
        let g = contact_gjk_epa(
            cap.as_convex().unwrap(),
            sb.as_convex().unwrap(),
            &pose_ab,
            Real::INFINITY,
        )
        .unwrap();
        assert!((g.distance - want).abs() < tol() * 10.0, "{g:?} vs {want}");

        // Box vs sphere against the clamp oracle.
        let h = Vec3::new(
            rng.range(0.2, 1.0),
            rng.range(0.2, 1.0),
            rng.range(0.2, 1.0),
        );
        let bx = Shape::Cuboid(Cuboid::new(h).unwrap());
        let local = pa.inverse_transform_point(pb.translation);
        let outside = (local.abs() - h).max(Vec3::ZERO).length();
        let inside = (local.abs() - h).max_element().min(0.0);
        let want = outside + inside - rb;
        let c = distance(&bx, &pa, &sb, &pb).unwrap();
        check_convention(&c);
        assert!((c.distance - want).abs() < tol(), "{c:?} vs {want}");
        let g = contact_gjk_epa(
            bx.as_convex().unwrap(),
            sb.as_convex().unwrap(),
            &pose_ab,
            Real::INFINITY,
        )
        .unwrap();
        assert!((g.distance - want).abs() < tol() * 10.0, "{g:?} vs {want}");
    }
}

#[test]
fn capsule_capsule_matches_segment_oracle_and_general_path() {
    let mut rng = Rng(5);
    for _ in 0..200 {
        let a = Capsule::new(rng.range(0.05, 0.5), rng.range(0.1, 1.0)).unwrap();
        let b = Capsule::new(rng.range(0.05, 0.5), rng.range(0.1, 1.0)).unwrap();
        let pose_ab = Isometry::new(rng.vec(1.5), rng.quat());
        let (p2, q2) = b.segment();
        let (c1, c2) = carom_collision::query::closest_points::closest_points_segment_segment(
            a.segment().0,
            a.segment().1,
            pose_ab.transform_point(p2),
            pose_ab.transform_point(q2),
        );
        let want = (c1 - c2).length() - a.radius() - b.radius();
        let ca = carom_collision::shape::ConvexRef::Capsule(&a);
        let cb = carom_collision::shape::ConvexRef::Capsule(&b);
        let fast =
            carom_collision::query::contact_convex(ca, cb, &pose_ab, Real::INFINITY).unwrap();
        check_convention(&fast);
        assert!((fast.distance - want).abs() < tol());
        let g = contact_gjk_epa(ca, cb, &pose_ab, Real::INFINITY).unwrap();
        assert!((g.distance - want).abs() < tol() * 10.0, "{g:?} vs {want}");
    }
}

#[test]
fn invariants_swap_and_rigid_motion() {
    let mut rng = Rng(6);
    let shapes: Vec<Shape> = vec![
        Shape::Sphere(Sphere::new(0.5).unwrap()),
        Shape::Cuboid(Cuboid::new(Vec3::new(0.5, 0.3, 0.8)).unwrap()),
        Shape::Capsule(Capsule::new(0.3, 0.6).unwrap()),
        Shape::Cylinder(Cylinder::new(0.4, 0.5).unwrap()),
        Shape::Cone(Cone::new(0.5, 0.6).unwrap()),
        Shape::ConvexHull(random_hull(&mut rng, 20, 0.7)),
        Shape::Triangle(
            carom_collision::shape::Triangle::new(Vec3::ZERO, Vec3::X, Vec3::Y).unwrap(),
        ),
    ];
    let scaled = Arc::new(shapes[1].clone())
        .scaled(Vec3::new(1.5, 0.5, 1.0))
        .unwrap();
    let mut all = shapes.clone();
    all.push(scaled);
    for a in &all {
        for b in &all {
            for _ in 0..6 {
                let pa = rng.pose(1.0);
                let pb = rng.pose(1.0);
                let c = distance(a, &pa, b, &pb).unwrap();
                check_convention_tol(&c, if c.distance < 0.0 { 1e-3 } else { tol() * 10.0 });
                let s = distance(b, &pb, a, &pa).unwrap();
                let loose = if c.distance < 0.0 { 1e-4 } else { tol() * 10.0 };
                assert!(
                    (c.distance - s.distance).abs() < loose,
                    "{} {}: {c:?} {s:?}",
                    a.kind_name(),
                    b.kind_name()
                );
                let m = rng.pose(5.0);
                let moved = distance(a, &m.mul(&pa), b, &m.mul(&pb)).unwrap();
                assert!(
                    (moved.distance - c.distance).abs() < loose.max(tol() * 50.0),
                    "{moved:?} {c:?}"
                );
                assert_eq!(
                    intersects(a, &pa, b, &pb).unwrap(),
                    c.distance <= 0.0 || c.distance.abs() < tol(),
                    "{} {} {c:?}",
                    a.kind_name(),
                    b.kind_name()
                );
            }
        }
    }
}

#[test]
fn far_from_origin_and_scales() {
    let far: Real = if std::mem::size_of::<Real>() == 8 {
        1e8
    } else {
        1e4
    };
    let mut rng = Rng(7);
    for scale in [1e-3 as Real, 1.0, 1e3] {
        for _ in 0..20 {
            let a = random_hull(&mut rng, 16, scale);
            let b = random_hull(&mut rng, 16, scale);
            let base = Vec3::new(far, -far, far * 0.5);
            let pa = Isometry::new(base + rng.vec(scale), rng.quat());
            let pb = Isometry::new(pa.translation + rng.unit() * 3.0 * scale, rng.quat());
            let (sa, sb) = (Shape::ConvexHull(a.clone()), Shape::ConvexHull(b.clone()));
            let c = distance(&sa, &pa, &sb, &pb).unwrap();
            assert!(c.distance.is_finite() && c.normal.is_finite());
            if c.distance > 0.0 {
                // Compare with the same configuration at the origin.
                let shift = |p: &Isometry| Isometry::new(p.translation - base, p.rotation);
                let want = brute_hull_distance(&a, &shift(&pa), &b, &shift(&pb));
                // Translation by `base` rounds positions to ~eps * far.
                let allowed = tol() * scale + far * Real::EPSILON * 8.0;
                assert!(
                    (c.distance - want).abs() < allowed,
                    "{} vs {want}",
                    c.distance
                );
            }
        }
    }
}

#[test]
fn touching_face_to_face_and_parallel_edges() {
    let b = Shape::Cuboid(Cuboid::new(Vec3::splat(0.5)).unwrap());
    // Face to face, exactly touching.
    let c = distance(
        &b,
        &Isometry::IDENTITY,
        &b,
        &Isometry::from_translation(Vec3::X),
    )
    .unwrap();
    assert!(c.distance.abs() < tol(), "{c:?}");
    assert!((c.normal - Vec3::X).length() < 1e-3);
    // Face to face, slightly apart and slightly overlapping.
    for d in [1e-3 as Real, -1e-3] {
        let c = distance(
            &b,
            &Isometry::IDENTITY,
            &b,
            &Isometry::from_translation(Vec3::X * (1.0 + d)),
        )
        .unwrap();
        assert!((c.distance - d).abs() < tol(), "{c:?}");
    }
    // Parallel edges: boxes rotated 45° about Z, edge on edge.
    let q = Quat::from_rotation_z(crate_pi() / 4.0);
    let s2 = (2.0 as Real).sqrt();
    let pa = Isometry::from_rotation(q);
    let pb = Isometry::new(
        Vec3::new(s2 + 0.1, 0.0, 0.3),
        q * Quat::from_rotation_z(crate_pi() / 2.0),
    );
    let c = distance(&b, &pa, &b, &pb).unwrap();
    assert!((c.distance - 0.1).abs() < tol(), "{c:?}");
}

fn crate_pi() -> Real {
    carom_collision::math::consts::PI
}

#[test]
fn bad_input_is_an_error_and_extreme_values_stay_finite() {
    let s = Shape::Sphere(Sphere::new(1.0).unwrap());
    let nan = Isometry::from_translation(Vec3::new(Real::NAN, 0.0, 0.0));
    assert!(distance(&s, &nan, &s, &Isometry::IDENTITY).is_err());
    let bad_q = Isometry::new(Vec3::ZERO, Quat::from_xyzw(0.0, 0.0, 0.0, 2.0));
    assert!(contact(&s, &Isometry::IDENTITY, &s, &bad_q, 0.0).is_err());
    assert!(contact(&s, &Isometry::IDENTITY, &s, &Isometry::IDENTITY, Real::NAN).is_err());
    let mut rng = Rng(8);
    let shapes = [
        Shape::Cuboid(Cuboid::new(Vec3::new(1e-4, 1e3, 1.0)).unwrap()),
        Shape::ConvexHull(random_hull(&mut rng, 8, 1e-3)),
        Shape::Cylinder(Cylinder::new(1e3, 1e-3).unwrap()),
        Shape::Capsule(Capsule::new(1e-4, 1e2).unwrap()),
    ];
    for a in &shapes {
        for b in &shapes {
            for t in [0.0 as Real, 1e-6, 1e-3, 1.0, 1e3, 1e6] {
                let pb = Isometry::new(rng.unit() * t, rng.quat());
                let c = distance(a, &Isometry::IDENTITY, b, &pb).unwrap();
                assert!(
                    c.distance.is_finite()
                        && c.point_a.is_finite()
                        && c.point_b.is_finite()
                        && c.normal.is_finite(),
                    "{} {} {c:?}",
                    a.kind_name(),
                    b.kind_name()
                );
            }
        }
    }
}
