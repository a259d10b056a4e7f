//! Convex against heightfields: the same contacts (points, normals, depths, feature ids) as
//! against the triangle mesh built from the same heights, on bumpy and flat terrain,
//! including internal-edge correction; heightfields in the collision world; unsupported
//! heightfield pairs are errors.

mod common;

use carom_collision::broadphase::{Filter, Method};
use carom_collision::math::{Isometry, Quat, Real, Vec3};
use carom_collision::narrowphase::{ContactManifold, Dispatcher};
use carom_collision::query::Contact;
use carom_collision::shape::{
    Capsule, ConvexHull, Cuboid, Cylinder, HeightField, Shape, Sphere, TriMesh,
};
use carom_collision::world::CollisionWorld;
use common::Rng;
use std::sync::Arc;

/// The heightfield and the mesh of the same triangles, numbered alike.
fn terrain(rows: usize, cols: usize, heights: Vec<Real>) -> (Shape, Shape) {
    let hf = HeightField::new(rows, cols, heights, 1.0, 0.8).unwrap();
    let mut v = Vec::new();
    for r in 0..rows {
        for c in 0..cols {
            v.push(hf.point(r, c));
        }
    }
    let idx = |r: usize, c: usize| (r * cols + c) as u32;
    let mut t = Vec::new();
    for r in 0..rows - 1 {
        for c in 0..cols - 1 {
            t.push([idx(r, c), idx(r + 1, c), idx(r, c + 1)]);
            t.push([idx(r, c + 1), idx(r + 1, c), idx(r + 1, c + 1)]);
        }
    }
    for (i, tri) in t.iter().enumerate() {
        assert_eq!(tri.map(|k| v[k as usize]), hf.triangle(i));
    }
    let mesh = TriMesh::new(v, t).unwrap();
    (Shape::HeightField(hf), Shape::TriMesh(mesh))
}

fn sorted(mut v: Vec<(Contact, u32)>) -> Vec<(Contact, u32)> {
    v.sort_by(|x, y| {
        (x.1, x.0.distance, x.0.point_b.x, x.0.point_b.z)
            .partial_cmp(&(y.1, y.0.distance, y.0.point_b.x, y.0.point_b.z))
            .unwrap()
    });
    v
}

fn shapes(rng: &mut Rng) -> Vec<Shape> {
    let pts: Vec<Vec3> = (0..8).map(|_| rng.unit() * rng.range(0.3, 0.6)).collect();
    vec![
        Shape::Sphere(Sphere::new(0.45).unwrap()),
        Shape::Cuboid(Cuboid::new(Vec3::new(0.5, 0.3, 0.4)).unwrap()),
        Shape::Capsule(Capsule::new(0.25, 0.6).unwrap()),
        Shape::ConvexHull(ConvexHull::new(&pts).unwrap()),
        Shape::Cylinder(Cylinder::new(0.3, 0.4).unwrap()),
    ]
}

fn compare(hf: &Shape, mesh: &Shape, rng: &mut Rng, tilt: Real) -> usize {
    let d = Dispatcher::default();
    let mut nonempty = 0;
    for s in shapes(rng) {
        for _ in 0..12 {
            let pose = Isometry::new(
                Vec3::new(
                    rng.range(-2.0, 2.0),
                    rng.range(0.0, 0.6),
                    rng.range(-1.5, 1.5),
                ),
                Quat::from_axis_angle(rng.unit(), rng.range(0.0, tilt)),
            );
            for want_full in [true, false] {
                let g1 = d.generate(hf, &s, &pose, want_full).unwrap();
                let g2 = d.generate(mesh, &s, &pose, want_full).unwrap();
                assert_eq!(g1.full, g2.full);
                assert_eq!(g1.contacts.len(), g2.contacts.len(), "{s:?} at {pose:?}");
                for ((c1, f1), (c2, f2)) in
                    sorted(g1.contacts).iter().zip(&sorted(g2.contacts.clone()))
                {
                    assert_eq!(f1, f2);
                    assert!((c1.distance - c2.distance).abs() < 1e-4);
                    assert!((c1.normal - c2.normal).length() < 1e-4);
                    assert!((c1.point_a - c2.point_a).length() < 1e-4);
                    assert!((c1.point_b - c2.point_b).length() < 1e-4);
                    assert!(c1.distance.is_finite() && c1.normal.is_finite());
                }
                if want_full {
                    // Swapped order agrees too (the swap adapter).
                    let g3 = d.generate(&s, hf, &pose.inverse(), true).unwrap();
                    assert_eq!(g3.contacts.len(), g2.contacts.len());
                }
            }
            let mut m = ContactManifold::new();
            d.update_manifold(hf, &Isometry::IDENTITY, &s, &pose, &mut m)
                .unwrap();
            nonempty += usize::from(!m.is_empty());
            // The reduced manifolds agree too (triangles are visited in index order).
            let mut m2 = ContactManifold::new();
            d.update_manifold(mesh, &Isometry::IDENTITY, &s, &pose, &mut m2)
                .unwrap();
            let ids = |m: &ContactManifold| m.points.iter().map(|p| p.feature).collect::<Vec<_>>();
            assert_eq!(ids(&m), ids(&m2));
        }
    }
    nonempty
}

#[test]
fn bumpy_heightfield_matches_the_equivalent_mesh() {
    let mut rng = Rng::new(11);
    let (rows, cols) = (6, 7);
    let heights = (0..rows * cols).map(|_| rng.range(0.0, 0.4)).collect();
    let (hf, mesh) = terrain(rows, cols, heights);
    let n = compare(&hf, &mesh, &mut rng, 3.0);
    assert!(n > 20, "only {n} touching cases");
}

#[test]
fn flat_heightfield_matches_the_mesh_and_keeps_face_normals() {
    let mut rng = Rng::new(12);
    let (hf, mesh) = terrain(5, 6, vec![0.1; 30]);
    let n = compare(&hf, &mesh, &mut rng, 0.5);
    assert!(n > 20, "only {n} touching cases");
    // A box pushed across the flat, tessellated heightfield: normals within 1 degree of +Y.
    let d = Dispatcher::default();
    let b = Shape::Cuboid(Cuboid::new(Vec3::splat(0.3)).unwrap());
    let mut m = ContactManifold::new();
    let cos1 = (1.0 as Real).to_radians().cos();
    for k in 0..60 {
        let pose = Isometry::new(
            Vec3::new(-1.5 + 0.05 * k as Real, 0.39, 0.1 + 0.01 * k as Real),
            Quat::from_rotation_y(0.3),
        );
        d.update_manifold(&hf, &Isometry::IDENTITY, &b, &pose, &mut m)
            .unwrap();
        assert_eq!(m.len(), 4, "at step {k}");
        for p in &m.points {
            assert!((-p.normal).dot(Vec3::Y) >= cos1, "{:?}", p.normal);
            assert!((p.distance + 0.01).abs() < 1e-3, "{}", p.distance);
        }
    }
}

#[test]
fn heightfields_in_the_world_and_unsupported_pairs() {
    let (hf, mesh) = terrain(4, 4, vec![0.0; 16]);
    let mut w = CollisionWorld::new(Method::Tree);
    let ground = w
        .add(Arc::new(hf.clone()), Isometry::IDENTITY, Filter::new(true))
        .unwrap();
    let ball = w
        .add(
            Arc::new(Shape::Sphere(Sphere::new(0.5).unwrap())),
            Isometry::from_translation(Vec3::new(0.2, 0.45, 0.1)),
            Filter::default(),
        )
        .unwrap();
    w.update().unwrap();
    let p = w.narrowphase().get(ground, ball).expect("pair");
    assert!(p.touching);
    assert!((p.manifold.min_distance().unwrap() + 0.05).abs() < 1e-3);
    for other in [hf, mesh] {
        // A movable one could meet the ground: no algorithm, so an error naming it.
        let err = w
            .add(
                Arc::new(other.clone()),
                Isometry::IDENTITY,
                Filter::default(),
            )
            .unwrap_err();
        assert!(err.to_string().contains("heightfield"), "{err}");
        // Two static objects never pair, so a static one is accepted.
        w.add(Arc::new(other), Isometry::IDENTITY, Filter::new(true))
            .unwrap();
    }
}
