//! CollisionWorld with the narrowphase: manifolds per pair, begin/persist/end events,
//! sensors, unsupported pairs rejected at `add`, and the same result on 1 and 2 threads.

use carom_collision::broadphase::{Filter, Method};
use carom_collision::math::{Isometry, Quat, Real, Vec3};
use carom_collision::narrowphase::ContactEventKind as K;
use carom_collision::shape::{Cuboid, Plane, Shape, Sphere};
use carom_collision::world::CollisionWorld;
use std::sync::Arc;

fn cuboid(h: Real) -> Arc<Shape> {
    Arc::new(Shape::Cuboid(Cuboid::new(Vec3::splat(h)).unwrap()))
}

#[test]
fn box_landing_and_leaving_gives_begin_persist_end() {
    let mut w = CollisionWorld::new(Method::Tree);
    let ground = w
        .add(
            Arc::new(Shape::Cuboid(
                Cuboid::new(Vec3::new(5.0, 0.5, 5.0)).unwrap(),
            )),
            Isometry::IDENTITY,
            Filter::new(true),
        )
        .unwrap();
    let b = w
        .add(
            cuboid(0.5),
            Isometry::from_translation(Vec3::new(0.0, 3.0, 0.0)),
            Filter::default(),
        )
        .unwrap();
    w.update().unwrap();
    assert!(w.narrowphase().events().is_empty());
    let heights = [0.99, 0.99, 3.0];
    let expected = [K::Begin, K::Persist, K::End];
    for (y, kind) in heights.iter().zip(expected) {
        w.set_pose(b, Isometry::from_translation(Vec3::new(0.0, *y, 0.0)))
            .unwrap();
        w.update().unwrap();
        let ev = w.narrowphase().events();
        assert_eq!(ev.len(), 1, "{ev:?}");
        assert_eq!(ev[0].kind, kind);
        let (lo, hi) = if ground < b { (ground, b) } else { (b, ground) };
        assert_eq!((ev[0].a, ev[0].b), (lo, hi));
        if kind != K::End {
            let m = &w.narrowphase().manifolds().next().unwrap().manifold;
            assert_eq!(m.len(), 4);
        } else {
            assert_eq!(w.narrowphase().manifolds().count(), 0);
        }
    }
}

#[test]
fn sensors_report_overlap_without_points() {
    let mut w = CollisionWorld::new(Method::Sap);
    let s = w
        .add(
            Arc::new(Shape::Sphere(Sphere::new(1.0).unwrap())),
            Isometry::IDENTITY,
            Filter::default(),
        )
        .unwrap();
    w.narrowphase_mut().set_sensor(s, true);
    w.add(
        cuboid(0.5),
        Isometry::from_translation(Vec3::new(1.2, 0.0, 0.0)),
        Filter::default(),
    )
    .unwrap();
    w.update().unwrap();
    let ev = w.narrowphase().events();
    assert_eq!(ev.len(), 1);
    assert!(ev[0].sensor && ev[0].kind == K::Begin);
    assert_eq!(w.narrowphase().manifolds().count(), 0);
}

#[test]
fn unsupported_pair_is_rejected_when_added() {
    let mut w = CollisionWorld::new(Method::Tree);
    let plane = Arc::new(Shape::Plane(Plane::new(Vec3::Y, 0.0).unwrap()));
    w.add(plane.clone(), Isometry::IDENTITY, Filter::new(true))
        .unwrap();
    // A movable plane could meet the static one: no algorithm, an error naming it.
    let err = w
        .add(plane.clone(), Isometry::IDENTITY, Filter::default())
        .unwrap_err();
    assert!(err.to_string().contains("plane"), "{err}");
    assert_eq!(w.len(), 1);
    // Two static objects never pair: accepted.
    w.add(plane, Isometry::IDENTITY, Filter::new(true)).unwrap();
    assert_eq!(w.len(), 2);
}

fn pile(threads: usize) -> Vec<(u32, u32, Vec<[Real; 4]>)> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut w = CollisionWorld::new(Method::Tree);
        w.add(
            Arc::new(Shape::Plane(Plane::new(Vec3::Y, 0.0).unwrap())),
            Isometry::IDENTITY,
            Filter::new(true),
        )
        .unwrap();
        for i in 0..27 {
            let p = Vec3::new(
                (i % 3) as Real * 0.9,
                0.45 + (i / 9) as Real * 0.9,
                ((i / 3) % 3) as Real * 0.9,
            );
            w.add(
                cuboid(0.5),
                Isometry::new(p, Quat::from_rotation_y(0.1 * i as Real)),
                Filter::default(),
            )
            .unwrap();
        }
        w.update().unwrap();
        w.update().unwrap();
        w.narrowphase()
            .manifolds()
            .map(|p| {
                let pts = p
                    .manifold
                    .points
                    .iter()
                    .map(|q| [q.distance, q.point_b.x, q.point_b.y, q.point_b.z])
                    .collect();
                (p.a.index, p.b.index, pts)
            })
            .collect()
    })
}

#[test]
fn one_and_two_threads_agree() {
    let (one, two) = (pile(1), pile(2));
    assert!(one.len() > 20);
    assert_eq!(one, two);
}
