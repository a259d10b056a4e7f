//! The collision world skeleton: boxes from shapes and poses, pairs against brute force on
//! `Shape::aabb`, every method agreeing, handles checked.

mod broadphase_common;

use broadphase_common::Rng;
use carom_collision::broadphase::{Filter, Method};
use carom_collision::math::{Isometry, Quat, Vec3};
use carom_collision::shape::{Cuboid, Plane, Shape, Sphere};
use carom_collision::world::{CollisionWorld, ObjectHandle};
use std::collections::BTreeMap;
use std::sync::Arc;

fn random_pose(rng: &mut Rng) -> Isometry {
    let axis = rng.vec(-1.0, 1.0).try_normalize().unwrap_or(Vec3::Y);
    Isometry::new(
        rng.vec(-8.0, 8.0),
        Quat::from_axis_angle(axis, rng.range(0.0, 3.0)),
    )
}

#[test]
fn world_pairs_match_brute_force_for_every_method() {
    let shapes = [
        Arc::new(Shape::Sphere(Sphere::new(0.7).unwrap())),
        Arc::new(Shape::Cuboid(
            Cuboid::new(Vec3::new(1.0, 0.4, 0.6)).unwrap(),
        )),
        Arc::new(Shape::Plane(Plane::new(Vec3::Y, -6.0).unwrap())),
    ];
    for m in Method::ALL {
        let mut rng = Rng(31);
        let mut world = CollisionWorld::new(m);
        let mut objs: BTreeMap<ObjectHandle, usize> = BTreeMap::new();
        for k in 0..120 {
            let s = if k == 0 { 2 } else { k % 2 };
            let f = Filter::new(s == 2);
            let h = world
                .add(shapes[s].clone(), random_pose(&mut rng), f)
                .unwrap();
            objs.insert(h, s);
        }
        let mut prev: Vec<(ObjectHandle, ObjectHandle)> = Vec::new();
        for frame in 0..8 {
            let hs: Vec<ObjectHandle> = objs.keys().copied().collect();
            for &h in &hs {
                match rng.below(10) {
                    0..=3 if objs[&h] != 2 => world.set_pose(h, random_pose(&mut rng)).unwrap(),
                    4 if frame > 0 && objs[&h] != 2 => {
                        world.remove(h).unwrap();
                        assert!(world.remove(h).is_err());
                        assert!(world.set_pose(h, Isometry::IDENTITY).is_err());
                        objs.remove(&h);
                    }
                    _ => {}
                }
            }
            let ch = world.update().unwrap().clone();
            let pairs = world.pairs();
            let items: Vec<_> = world
                .iter()
                .map(|(h, o)| (h, o.shape.aabb(&o.pose), o.filter))
                .collect();
            assert_eq!(items.len(), objs.len());
            let mut expect = Vec::new();
            for (i, a) in items.iter().enumerate() {
                for b in &items[i + 1..] {
                    if a.1.intersects(&b.1) && a.2.can_pair(&b.2) {
                        expect.push((a.0.min(b.0), a.0.max(b.0)));
                    }
                }
            }
            expect.sort_unstable();
            assert_eq!(pairs, expect, "{m:?} frame {frame}");
            assert!(
                pairs.iter().any(|p| objs[&p.0] == 2 || objs[&p.1] == 2),
                "plane pairs"
            );
            for p in &ch.added {
                assert!(!prev.contains(p) && pairs.contains(p));
            }
            for p in &ch.removed {
                assert!(prev.contains(p) && !pairs.contains(p));
            }
            prev = pairs;
        }
    }
}

#[test]
fn world_rejects_bad_poses_and_handles() {
    let mut world = CollisionWorld::new(Method::Tree);
    let s = Arc::new(Shape::Sphere(Sphere::new(1.0).unwrap()));
    let bad = Isometry::new(Vec3::new(Real::NAN, 0.0, 0.0), Quat::IDENTITY);
    assert!(world.add(s.clone(), bad, Filter::default()).is_err());
    let h = world
        .add(s.clone(), Isometry::IDENTITY, Filter::default())
        .unwrap();
    assert!(world.set_pose(h, bad).is_err());
    let stale = ObjectHandle {
        index: h.index,
        generation: h.generation + 1,
    };
    assert!(world.get(stale).is_err());
    assert!(world.set_resting(stale, true).is_err());
    let h2 = world
        .add(s, Isometry::from_translation(Vec3::X), Filter::default())
        .unwrap();
    assert_eq!(world.update().unwrap().added, vec![(h, h2)]);
    world.set_user_filter(Some(Arc::new(|_, _| false)));
    assert_eq!(world.update().unwrap().removed, vec![(h, h2)]);
    assert_eq!(world.len(), 2);
}

use carom_collision::math::Real;
