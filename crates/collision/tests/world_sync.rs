//! `CollisionWorld::sync_object` (the pipeline's per-step pose, margin and motion update,
//! with the box and proxy updated at once) against the deferred path it replaces
//! (`set_pose_with_margin` + `set_motion`, boxes at `update`): the same boxes, the same pair
//! changes every frame for every broadphase method, and bad input rejected before anything
//! changes.

mod broadphase_common;

use broadphase_common::Rng;
use carom_collision::broadphase::{Filter, Method};
use carom_collision::math::{Isometry, Quat, Real, Vec3};
use carom_collision::shape::{Cone, Cuboid, Cylinder, Plane, Shape, Sphere};
use carom_collision::world::{CollisionWorld, ObjectHandle};
use carom_collision::CaromError;
use std::sync::Arc;

fn random_pose(rng: &mut Rng, far: Vec3) -> Isometry {
    let axis = rng.vec(-1.0, 1.0).try_normalize().unwrap_or(Vec3::Y);
    Isometry::new(
        far + rng.vec(-8.0, 8.0),
        Quat::from_axis_angle(axis, rng.range(0.0, 3.0)),
    )
}

fn shapes() -> Vec<Arc<Shape>> {
    vec![
        Arc::new(Sphere::new(0.7).unwrap().into()),
        Arc::new(Cuboid::new(Vec3::new(1.0, 0.4, 0.6)).unwrap().into()),
        Arc::new(Cylinder::new(0.5, 0.8).unwrap().into()),
        Arc::new(Cone::new(0.6, 0.5).unwrap().into()),
        Arc::new(Plane::new(Vec3::Y, -6.0).unwrap().into()),
    ]
}

#[test]
fn sync_object_equals_the_deferred_updates_for_every_method() {
    for far in [Vec3::ZERO, Vec3::new(1.0e4, -3.0e3, 2.0e4)] {
        for m in Method::ALL {
            let mut rng = Rng(17);
            let shapes = shapes();
            let mut a = CollisionWorld::new(m);
            let mut b = CollisionWorld::new(m);
            let mut hs: Vec<ObjectHandle> = Vec::new();
            for k in 0..90 {
                let s = if k == 0 { 4 } else { k % 4 };
                let pose = random_pose(&mut rng, far);
                let f = Filter::new(s == 4);
                let ha = a.add(shapes[s].clone(), pose, f).unwrap();
                let hb = b.add(shapes[s].clone(), pose, f).unwrap();
                assert_eq!(ha, hb);
                hs.push(ha);
            }
            for frame in 0..10 {
                for (k, &h) in hs.iter().enumerate().skip(1) {
                    if rng.below(3) == 0 {
                        continue; // not moved this frame
                    }
                    // Small moves (refits inside the fat boxes) and jumps (re-insertions).
                    let pose = if rng.below(4) == 0 {
                        random_pose(&mut rng, far)
                    } else {
                        let p = a.get(h).unwrap().pose;
                        Isometry::new(p.translation + rng.vec(-0.05, 0.05), p.rotation)
                    };
                    let margin = if k % 5 == 0 { 0.0 } else { rng.range(0.0, 0.3) };
                    let motion = rng.vec(-0.2, 0.2);
                    if frame % 3 == 1 && k % 7 == 0 {
                        // A pending `set_pose` overridden by the sync in the same frame.
                        a.set_pose(h, random_pose(&mut rng, far)).unwrap();
                    }
                    a.sync_object(h, pose, margin, motion, false).unwrap();
                    b.set_pose_with_margin(h, pose, margin).unwrap();
                    b.set_motion(h, motion).unwrap();
                }
                let ca = a.update().unwrap().clone();
                let cb = b.update().unwrap().clone();
                assert_eq!(ca, cb, "{m:?} frame {frame}: pair changes");
                assert_eq!(a.pairs(), b.pairs(), "{m:?} frame {frame}: pairs");
                for &h in &hs {
                    let (oa, ob) = (a.get(h).unwrap(), b.get(h).unwrap());
                    assert_eq!(oa.aabb, ob.aabb, "{m:?} frame {frame}: box of {h:?}");
                    assert_eq!(oa.pose, ob.pose);
                    assert_eq!((oa.margin, oa.motion), (ob.margin, ob.motion));
                }
            }
        }
    }
}

#[test]
fn sync_object_rejects_bad_input_and_changes_nothing() {
    let mut w = CollisionWorld::new(Method::Tree);
    let shape: Arc<Shape> = Arc::new(Sphere::new(0.5).unwrap().into());
    let h = w
        .add(shape.clone(), Isometry::IDENTITY, Filter::default())
        .unwrap();
    let other = w
        .add(
            shape,
            Isometry::from_translation(Vec3::X * 0.8),
            Filter::default(),
        )
        .unwrap();
    w.update().unwrap();
    let before = w.get(h).unwrap().clone();
    let pairs = w.pairs();
    let ok = Isometry::from_translation(Vec3::Y);
    let bad_rot = Isometry::new(Vec3::ZERO, Quat::from_xyzw(0.0, 0.0, 0.0, 2.0));
    let nan = Isometry::from_translation(Vec3::new(Real::NAN, 0.0, 0.0));
    let huge = Isometry::from_translation(Vec3::splat(Real::MAX));
    let cases: [(Isometry, Real, Vec3, &str); 6] = [
        (nan, 0.1, Vec3::ZERO, "pose.translation"),
        (bad_rot, 0.1, Vec3::ZERO, "pose.rotation"),
        (ok, -0.1, Vec3::ZERO, "margin"),
        (ok, Real::INFINITY, Vec3::ZERO, "margin"),
        (ok, 0.1, Vec3::new(0.0, Real::NAN, 0.0), "motion"),
        (huge, Real::MAX, Vec3::ZERO, "aabb"),
    ];
    for (pose, margin, motion, name) in cases {
        match w.sync_object(h, pose, margin, motion, false) {
            Err(CaromError::InvalidValue { name: n, .. }) => assert_eq!(n, name),
            r => panic!("{name}: {r:?}"),
        }
        let now = w.get(h).unwrap();
        assert_eq!(now.pose, before.pose, "{name}");
        assert_eq!(now.aabb, before.aabb, "{name}");
        assert_eq!((now.margin, now.motion), (before.margin, before.motion));
    }
    w.update().unwrap();
    assert_eq!(w.pairs(), pairs);
    // A removed object's handle is unknown.
    w.remove(other).unwrap();
    assert!(matches!(
        w.sync_object(other, ok, 0.0, Vec3::ZERO, false),
        Err(CaromError::UnknownHandle(_))
    ));
    // A rotation off unit length by more than round-off is renormalised, as `set_pose` does.
    let q = Quat::from_xyzw(0.0, 0.0, 0.0, 1.0005);
    w.sync_object(h, Isometry::new(Vec3::ZERO, q), 0.0, Vec3::ZERO, false)
        .unwrap();
    assert!((w.get(h).unwrap().pose.rotation.length() - 1.0).abs() <= 4.0 * Real::EPSILON);
}

/// Valid values whose sum overflows (the fast path's single finiteness test fails) are
/// accepted by the named checks, and give the deferred path's box.
#[test]
fn sync_object_accepts_finite_values_whose_sum_overflows() {
    let big = 0.6 * Real::MAX;
    let shape: Arc<Shape> = Arc::new(Sphere::new(0.5).unwrap().into());
    let mut a = CollisionWorld::new(Method::Tree);
    let mut b = CollisionWorld::new(Method::Tree);
    let ha = a
        .add(shape.clone(), Isometry::IDENTITY, Filter::default())
        .unwrap();
    let hb = b.add(shape, Isometry::IDENTITY, Filter::default()).unwrap();
    for (x, margin, motion) in [
        (big, 0.0, Vec3::ZERO),
        (0.9 * big, 0.25, Vec3::new(0.0, 0.1, 0.0)),
        (0.0, 0.0, Vec3::ZERO), // back to the origin: touching zero margin
    ] {
        let pose = Isometry::from_translation(Vec3::new(x, x, 1.0));
        a.sync_object(ha, pose, margin, motion, false).unwrap();
        b.set_pose_with_margin(hb, pose, margin).unwrap();
        b.set_motion(hb, motion).unwrap();
        b.update().unwrap();
        let (oa, ob) = (a.get(ha).unwrap(), b.get(hb).unwrap());
        assert_eq!((oa.pose, oa.aabb), (ob.pose, ob.aabb), "x = {x}");
        assert!(oa.aabb.min.is_finite() && oa.aabb.max.is_finite());
    }
}
