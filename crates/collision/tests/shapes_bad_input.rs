//! Every constructor rejects bad input with a `CaromError` naming the bad value.

use carom_collision::math::{check_isometry, Isometry, Quat, Real, Vec3};
use carom_collision::shape::*;
use carom_collision::CaromError;
use std::sync::Arc;

const BAD: [Real; 5] = [0.0, -1.0, Real::NAN, Real::INFINITY, Real::NEG_INFINITY];

fn assert_names(r: Result<impl std::fmt::Debug, CaromError>, name: &str) {
    let e = r.expect_err("must be rejected");
    let msg = e.to_string();
    assert!(msg.contains(name), "message {msg:?} does not name {name:?}");
}

#[test]
fn primitives_reject_bad_sizes() {
    for x in BAD {
        assert_names(Sphere::new(x), "radius");
        assert_names(Cuboid::new(Vec3::new(1.0, x, 1.0)), "half_extents");
        assert_names(Capsule::new(x, 1.0), "radius");
        assert_names(Capsule::new(1.0, x), "half_height");
        assert_names(Cylinder::new(x, 1.0), "radius");
        assert_names(Cylinder::new(1.0, x), "half_height");
        assert_names(Cone::new(x, 1.0), "radius");
        assert_names(Cone::new(1.0, x), "half_height");
    }
    // The message carries the value.
    let msg = Sphere::new(-2.5).unwrap_err().to_string();
    assert!(msg.contains("-2.5"), "{msg}");
}

#[test]
fn margins_are_validated() {
    let b = Cuboid::new(Vec3::splat(1.0)).unwrap();
    assert_names(b.with_margin(-0.1), "margin");
    assert_names(b.with_margin(1.0), "margin");
    assert_names(b.with_margin(Real::NAN), "margin");
    assert!(b.with_margin(0.0).is_ok());
    assert_names(Cylinder::new(1.0, 1.0).unwrap().with_margin(2.0), "margin");
    assert_names(Cone::new(1.0, 1.0).unwrap().with_margin(5.0), "margin");
    // Default margins are small and inside the shape.
    let tiny = Cuboid::new(Vec3::splat(0.01)).unwrap();
    assert!(tiny.margin() <= 0.2 * 0.01 + 1e-9);
}

#[test]
fn triangles_planes_and_poses() {
    let nan = Vec3::new(0.0, Real::NAN, 0.0);
    assert_names(Triangle::new(nan, Vec3::X, Vec3::Y), "a");
    assert_names(Triangle::new(Vec3::ZERO, Vec3::X, nan), "c");
    // Degenerate triangles are allowed, and have no normal.
    let flat = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::X * 2.0).unwrap();
    assert!(flat.normal().is_none() && flat.area() == 0.0);
    assert_names(Plane::new(Vec3::ZERO, 1.0), "normal");
    assert_names(Plane::new(nan, 1.0), "normal");
    assert_names(Plane::new(Vec3::Y, Real::NAN), "offset");
    let p = Plane::new(Vec3::new(0.0, 2.0, 0.0), 1.0).unwrap();
    assert_eq!(p.normal(), Vec3::Y);
    let bad_rot = Isometry::new(Vec3::ZERO, Quat::from_xyzw(0.0, 0.0, 0.0, 3.0));
    assert_names(check_isometry("pose", bad_rot), "pose.rotation");
    let bad_pos = Isometry::new(nan, Quat::IDENTITY);
    assert_names(check_isometry("pose", bad_pos), "pose.translation");
}

#[test]
fn hulls_reject_degenerate_clouds() {
    assert_names(ConvexHull::new(&[Vec3::ZERO, Vec3::X, Vec3::Y]), "points");
    assert!(ConvexHull::new(&[]).is_err());
    // Coplanar and collinear clouds have no 3D hull.
    let flat: Vec<Vec3> = (0..20)
        .map(|i| Vec3::new(i as Real, (i * i % 7) as Real, 0.0))
        .collect();
    assert!(matches!(
        ConvexHull::new(&flat),
        Err(CaromError::Degenerate { .. })
    ));
    let line: Vec<Vec3> = (0..10).map(|i| Vec3::splat(i as Real)).collect();
    assert!(ConvexHull::new(&line).is_err());
    let dup = vec![Vec3::ONE; 10];
    assert!(ConvexHull::new(&dup).is_err());
    let mut with_nan = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
    with_nan.push(Vec3::new(Real::NAN, 0.0, 0.0));
    assert_names(ConvexHull::new(&with_nan), "points[4]");
}

#[test]
fn meshes_compounds_and_scaling() {
    let v = vec![Vec3::ZERO, Vec3::X, Vec3::Y];
    assert_names(TriMesh::new(v.clone(), vec![[0, 1, 3]]), "indices[0][2]");
    assert_names(TriMesh::new(v.clone(), vec![]), "indices");
    assert_names(TriMesh::new(vec![], vec![[0, 0, 0]]), "vertices");
    assert_names(
        TriMesh::new(
            vec![Vec3::ZERO, Vec3::X, Vec3::splat(Real::INFINITY)],
            vec![[0, 1, 2]],
        ),
        "vertices[2]",
    );
    assert!(
        TriMesh::new(v, vec![[0, 1, 2], [0, 0, 0]]).is_ok(),
        "degenerate triangles are kept"
    );

    assert_names(Compound::new(vec![]), "children");
    let plane = Arc::new(Shape::from(Plane::new(Vec3::Y, 0.0).unwrap()));
    assert!(matches!(
        Compound::new(vec![(Isometry::IDENTITY, plane.clone())]),
        Err(CaromError::Unsupported(_))
    ));
    let sphere = Arc::new(Shape::from(Sphere::new(1.0).unwrap()));
    let bad_pose = Isometry::new(Vec3::ZERO, Quat::from_xyzw(1.0, 1.0, 0.0, 0.0));
    assert_names(
        Compound::new(vec![(bad_pose, sphere.clone())]),
        "children[0].pose",
    );

    assert_names(
        Scaled::new(sphere.clone(), Vec3::new(1.0, 0.0, 1.0)),
        "scale",
    );
    assert_names(
        Scaled::new(sphere.clone(), Vec3::new(1.0, Real::NAN, 1.0)),
        "scale",
    );
    assert!(matches!(
        Scaled::new(plane, Vec3::ONE),
        Err(CaromError::Unsupported(_))
    ));
    // Scaling a scaled shape multiplies the factors.
    let once = Arc::new(Shape::from(Scaled::new(sphere, Vec3::splat(2.0)).unwrap()));
    let Shape::Scaled(twice) = once.scaled(Vec3::new(1.0, 3.0, 1.0)).unwrap() else {
        panic!()
    };
    assert_eq!(twice.scale(), Vec3::new(2.0, 6.0, 2.0));
    assert!(matches!(**twice.inner(), Shape::Sphere(_)));
}

#[test]
fn mass_properties_reject_bad_density() {
    let s = Shape::from(Sphere::new(1.0).unwrap());
    for x in BAD {
        assert_names(s.checked_mass_properties(x), "density");
    }
}
