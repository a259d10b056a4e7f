//! Convex against triangle meshes: internal-edge correction on a flat tessellated plane
//! (normals stay within 1° of the face normal) and on a real cliff (the normal turns);
//! dispatcher errors and overrides; no NaN under extreme poses.

mod common;

use carom_collision::math::{Isometry, Quat, Real, Vec3};
use carom_collision::narrowphase::{ContactManifold, Dispatcher, Generated};
use carom_collision::shape::{
    Capsule, Cone, Cuboid, Cylinder, Plane, Shape, ShapeKind, Sphere, TriMesh,
};
use common::Rng;
use std::sync::Arc;

fn grid(n: usize) -> TriMesh {
    let mut v = Vec::new();
    let mut t = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            v.push(Vec3::new(
                i as Real - n as Real / 2.0,
                0.0,
                j as Real - n as Real / 2.0,
            ));
        }
    }
    let w = (n + 1) as u32;
    for j in 0..n as u32 {
        for i in 0..n as u32 {
            let a = j * w + i;
            t.push([a, a + w, a + w + 1]);
            t.push([a, a + w + 1, a + 1]);
        }
    }
    TriMesh::new(v, t).unwrap()
}

#[test]
fn flat_mesh_normals_stay_within_one_degree() {
    let d = Dispatcher::default();
    let mesh = Shape::TriMesh(grid(6));
    let cos1 = (1.0 as Real).to_radians().cos();
    let shapes = [
        (Shape::Sphere(Sphere::new(0.4).unwrap()), 0.4),
        (Shape::Cuboid(Cuboid::new(Vec3::splat(0.3)).unwrap()), 0.3),
    ];
    let mut count = 0;
    for (s, h) in &shapes {
        let mut m = ContactManifold::new();
        for k in 0..120 {
            let x = -2.0 + 0.033 * k as Real;
            let pose = Isometry::new(
                Vec3::new(x, h - 0.01, 0.37 + 0.01 * k as Real),
                Quat::from_rotation_y(0.4),
            );
            d.update_manifold(&mesh, &Isometry::IDENTITY, s, &pose, &mut m)
                .unwrap();
            assert!(!m.is_empty());
            for p in &m.points {
                count += 1;
                assert!(
                    (-p.normal).dot(Vec3::Y) >= cos1,
                    "normal {:?} at x={x}",
                    p.normal
                );
            }
        }
    }
    assert!(count > 100);
}

#[test]
fn cliff_edge_still_turns_the_normal() {
    let v = vec![
        Vec3::new(-2.0, 0.0, -1.0),
        Vec3::new(-2.0, 0.0, 1.0),
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(0.0, 0.0, -1.0),
        Vec3::new(0.0, -2.0, 1.0),
        Vec3::new(0.0, -2.0, -1.0),
    ];
    let t = vec![[0, 1, 2], [0, 2, 3], [3, 2, 4], [3, 4, 5]];
    let mesh = Shape::TriMesh(TriMesh::new(v, t).unwrap());
    let sphere = Shape::Sphere(Sphere::new(0.5).unwrap());
    let d = Dispatcher::default();
    let mut m = ContactManifold::new();
    let pose = Isometry::from_translation(Vec3::new(0.3, 0.3, 0.0));
    d.update_manifold(&mesh, &Isometry::IDENTITY, &sphere, &pose, &mut m)
        .unwrap();
    assert!(!m.is_empty());
    let expected = Vec3::new(1.0, 1.0, 0.0).normalize();
    for p in &m.points {
        assert!((-p.normal).dot(expected) > 0.999, "normal {:?}", p.normal);
        let depth = 0.5 - (0.3 as Real * 0.3 * 2.0).sqrt();
        assert!((p.distance + depth).abs() < 1e-3);
    }
}

#[test]
fn unsupported_pairs_are_errors_and_user_algorithms_override() {
    let mut d = Dispatcher::default();
    let plane = Shape::Plane(Plane::new(Vec3::Y, 0.0).unwrap());
    let mesh = Shape::TriMesh(grid(1));
    assert!(d.check_pair(&plane, &plane).is_err());
    assert!(d.check_pair(&mesh, &plane).is_err());
    assert!(d.check_pair(&mesh, &mesh).is_err());
    let sphere = Shape::Sphere(Sphere::new(1.0).unwrap());
    assert!(d.check_pair(&plane, &sphere).is_ok());
    d.register(
        ShapeKind::Plane,
        ShapeKind::Plane,
        Arc::new(|_, _, _, _, _| Generated::default()),
    );
    assert!(d.check_pair(&plane, &plane).is_ok());
    let mut m = ContactManifold::new();
    d.update_manifold(
        &plane,
        &Isometry::IDENTITY,
        &plane,
        &Isometry::IDENTITY,
        &mut m,
    )
    .unwrap();
    assert!(m.is_empty());
}

#[test]
fn extreme_poses_never_produce_nan() {
    let mut rng = Rng::new(11);
    let d = Dispatcher::default();
    let shapes = [
        Shape::Sphere(Sphere::new(0.5).unwrap()),
        Shape::Cuboid(Cuboid::new(Vec3::new(0.5, 0.2, 1.0)).unwrap()),
        Shape::Capsule(Capsule::new(0.3, 0.5).unwrap()),
        Shape::Cylinder(Cylinder::new(0.4, 0.5).unwrap()),
        Shape::Cone(Cone::new(0.4, 0.5).unwrap()),
        Shape::Plane(Plane::new(Vec3::Y, 0.0).unwrap()),
        Shape::TriMesh(grid(2)),
    ];
    for _ in 0..150 {
        let i = (rng.uniform() * shapes.len() as Real) as usize % shapes.len();
        let j = (rng.uniform() * shapes.len() as Real) as usize % shapes.len();
        let (a, b) = (&shapes[i], &shapes[j]);
        if d.check_pair(a, b).is_err() {
            continue;
        }
        let far = if rng.uniform() < 0.3 { 1.0e4 } else { 0.0 };
        let base = rng.unit() * far;
        let pa = Isometry::new(base, Quat::from_axis_angle(rng.unit(), rng.range(0.0, 6.3)));
        let off = match rng.uniform() {
            u if u < 0.3 => Vec3::ZERO,
            u if u < 0.5 => Vec3::new(0.0, 1.0e-7, 0.0),
            _ => rng.unit() * rng.range(0.0, 1.2),
        };
        let pb = Isometry::new(
            base + off,
            Quat::from_axis_angle(rng.unit(), rng.range(0.0, 6.3)),
        );
        let mut m = ContactManifold::new();
        for _ in 0..2 {
            d.update_manifold(a, &pa, b, &pb, &mut m).unwrap();
            assert!(m.len() <= 4);
            for p in &m.points {
                assert!(p.is_finite(), "{:?} vs {:?}: {:?}", a.kind(), b.kind(), p);
            }
        }
    }
}

#[test]
fn box_on_flat_mesh_gets_four_points_at_the_right_depth() {
    let d = Dispatcher::default();
    let mesh = Shape::TriMesh(grid(4));
    let b = Shape::Cuboid(Cuboid::new(Vec3::splat(0.5)).unwrap());
    let pose = Isometry::new(Vec3::new(0.2, 0.5 - 0.01, 0.1), Quat::from_rotation_y(0.5));
    let mut m = ContactManifold::new();
    d.update_manifold(&mesh, &Isometry::IDENTITY, &b, &pose, &mut m)
        .unwrap();
    assert_eq!(m.len(), 4);
    // Oracle: the bottom corners of the box.
    let corners: Vec<Vec3> = [(-1.0, -1.0), (-1.0, 1.0), (1.0, -1.0), (1.0, 1.0)]
        .iter()
        .map(|&(x, z)| pose.transform_point(Vec3::new(0.5 * x, -0.5, 0.5 * z)))
        .collect();
    for p in &m.points {
        assert!((p.distance + 0.01).abs() < 1e-4);
        assert!(
            corners.iter().any(|c| (*c - p.point_b).length() < 1e-3),
            "{:?}",
            p.point_b
        );
    }
}

#[test]
fn compound_children_merge_into_one_reduced_manifold() {
    use carom_collision::shape::Compound;
    let child = Arc::new(Shape::Cuboid(Cuboid::new(Vec3::splat(0.5)).unwrap()));
    let comp = Shape::Compound(
        Compound::new(vec![
            (
                Isometry::from_translation(Vec3::new(-1.0, 0.0, 0.0)),
                child.clone(),
            ),
            (Isometry::from_translation(Vec3::new(1.0, 0.0, 0.0)), child),
        ])
        .unwrap(),
    );
    let ground = Shape::Plane(Plane::new(Vec3::Y, 0.0).unwrap());
    let d = Dispatcher::default();
    let pose = Isometry::from_translation(Vec3::new(0.0, 0.49, 0.0));
    for (a, pa, b, pb) in [
        (&comp, pose, &ground, Isometry::IDENTITY),
        (&ground, Isometry::IDENTITY, &comp, pose),
    ] {
        let mut m = ContactManifold::new();
        d.update_manifold(a, &pa, b, &pb, &mut m).unwrap();
        assert_eq!(m.len(), 4);
        let mut xs: Vec<Real> = m
            .points
            .iter()
            .map(|p| p.point_b.x.min(p.point_a().x))
            .collect();
        xs.sort_by(|a, b| a.partial_cmp(b).unwrap());
        // Reduction keeps the outer corners: the widest footprint, x = ±1.5.
        assert!(
            (xs[0] + 1.5).abs() < 1e-3 && (xs[3] - 1.5).abs() < 1e-3,
            "{xs:?}"
        );
        for p in &m.points {
            assert!((p.distance + 0.01).abs() < 1e-4);
        }
    }
}

#[test]
fn cylinder_standing_on_a_mesh_gets_three_points_by_caching() {
    let d = Dispatcher::default();
    let mesh = Shape::TriMesh(grid(4));
    let cyl = Shape::Cylinder(Cylinder::new(0.5, 0.5).unwrap());
    let pose = Isometry::from_translation(Vec3::new(0.3, 0.5 - 0.002, 0.2));
    let mut m = ContactManifold::new();
    for _ in 0..3 {
        d.update_manifold(&mesh, &Isometry::IDENTITY, &cyl, &pose, &mut m)
            .unwrap();
    }
    assert!(m.len() >= 3, "{} points", m.len());
    for p in &m.points {
        // Oracle: points on the bottom disc, 0.002 below the mesh plane y = 0.
        let r = Vec3::new(p.point_b.x - 0.3, 0.0, p.point_b.z - 0.2).length();
        assert!(r < 0.5 + 2e-3, "radius {r}");
        assert!((p.point_b.y + 0.002).abs() < 2e-3, "{:?}", p.point_b);
        assert!((p.distance + 0.002).abs() < 2e-3, "distance {}", p.distance);
        assert!((-p.normal).dot(Vec3::Y) > 0.9998);
    }
    // A stable support: the points span a triangle of real area.
    let q: Vec<Vec3> = m.points.iter().map(|p| p.point_b).collect();
    let mut best: Real = 0.0;
    for i in 0..q.len() {
        for j in i + 1..q.len() {
            for k in j + 1..q.len() {
                best = best.max(0.5 * (q[j] - q[i]).cross(q[k] - q[i]).length());
            }
        }
    }
    assert!(best > 0.01, "footprint area {best}");
}

#[test]
fn registered_user_algorithm_produces_the_points_in_both_orders() {
    use carom_collision::query::Contact;
    let mut d = Dispatcher::default();
    // A user algorithm for sphere–box: one point at B's origin, 5 mm deep, normal +Y (A's
    // frame, from A to B), with a recognisable feature id.
    d.register(
        ShapeKind::Sphere,
        ShapeKind::Cuboid,
        Arc::new(|_, _, pose_ab, _, _| Generated {
            contacts: vec![(
                Contact {
                    distance: -0.005,
                    point_a: pose_ab.translation + Vec3::Y * 0.005,
                    point_b: pose_ab.translation,
                    normal: Vec3::Y,
                },
                77,
            )],
            full: true,
        }),
    );
    let sphere = Shape::Sphere(Sphere::new(0.5).unwrap());
    let cube = Shape::Cuboid(Cuboid::new(Vec3::splat(0.5)).unwrap());
    let far = Isometry::from_translation(Vec3::new(10.0, 0.0, 0.0));
    let mut m = ContactManifold::new();
    d.update_manifold(&sphere, &Isometry::IDENTITY, &cube, &far, &mut m)
        .unwrap();
    assert_eq!(
        m.len(),
        1,
        "the user algorithm runs even though the shapes are apart"
    );
    assert_eq!(m.points[0].feature, 77);
    assert!((m.points[0].point_b - far.translation).length() < 1e-6);
    assert!(
        (m.points[0].normal + Vec3::Y).length() < 1e-6,
        "normal on B, from B to A"
    );
    // Reversed pair: through the swap adapter, the same contact seen from the box.
    let mut r = ContactManifold::new();
    d.update_manifold(&cube, &far, &sphere, &Isometry::IDENTITY, &mut r)
        .unwrap();
    assert_eq!(r.len(), 1);
    assert_eq!(r.points[0].feature, 77);
    assert!((r.points[0].distance + 0.005).abs() < 1e-6);
    assert!((r.points[0].point_a() - far.translation).length() < 1e-5);
    assert!((r.points[0].normal - Vec3::Y).length() < 1e-6);
}

/// A sphere resting against the middle of a boundary edge of a lone triangle (its centre
/// beside the triangle's plane, 45° down from the edge) touches the edge, not the face: the
/// internal-edge correction must keep the edge normal there. (It used to compare the
/// closest point's segment parameter with the distance tolerance, so only contacts near an
/// edge's first vertex counted as on the edge and this one was forced to the face normal.)
#[test]
fn boundary_edge_keeps_its_normal_along_the_whole_edge() {
    let v = vec![
        Vec3::new(0.0, 0.0, -1.0),
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(-2.0, 0.0, 0.0),
    ];
    for t in [vec![[0, 1, 2]], vec![[0, 2, 1]]] {
        let mesh = Shape::TriMesh(TriMesh::new(v.clone(), t).unwrap());
        let d = Dispatcher::default();
        for z in [-0.6 as Real, -0.2, 0.0, 0.3, 0.7] {
            for s in [
                Shape::Sphere(Sphere::new(0.5).unwrap()),
                Shape::Capsule(Capsule::new(0.5, 0.3).unwrap()),
            ] {
                // Centre 0.49 from the edge point (0, 0, z), along (1, 1, 0)/√2 or
                // (1, -1, 0)/√2 (below the triangle, which is two-sided).
                for sy in [1.0 as Real, -1.0] {
                    let dir = Vec3::new(1.0, sy, 0.0).normalize();
                    let r = 0.5 - 0.01;
                    let pose = Isometry::new(
                        Vec3::new(0.0, 0.0, z) + dir * r,
                        Quat::from_rotation_x(std::f64::consts::FRAC_PI_2 as Real),
                    );
                    let mut m = ContactManifold::new();
                    d.update_manifold(&mesh, &Isometry::IDENTITY, &s, &pose, &mut m)
                        .unwrap();
                    assert!(!m.is_empty(), "z {z} side {sy}");
                    for p in &m.points {
                        assert!(
                            (-p.normal).dot(dir) > 0.999,
                            "z {z} side {sy} shape {:?}: normal {:?}, expected {:?}",
                            s.kind(),
                            p.normal,
                            -dir
                        );
                        assert!((p.distance + 0.01).abs() < 1e-3, "distance {}", p.distance);
                    }
                }
            }
        }
    }
}
