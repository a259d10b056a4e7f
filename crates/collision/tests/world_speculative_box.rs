//! The broadphase box of a moving object (`CollisionWorld::sync_object` and the deferred
//! `set_pose_with_margin` + `set_motion` path): the shape's box grown by the margin's own part
//! `max(margin - |motion|, 0)` and swept along the motion. Checked against an oracle that
//! moves the grown boxes along their motions in small steps: whenever two of them meet at
//! some time of the step, the world must report the pair (touching included), near the
//! origin and 1 km from it, with zero motions, margins below the motion's length, point-like
//! shapes and exactly touching end boxes.

mod broadphase_common;

use broadphase_common::Rng;
use carom_collision::broadphase::{Filter, Method};
use carom_collision::math::{Aabb, Isometry, Quat, Real, Vec3};
use carom_collision::shape::{Cuboid, Shape, Sphere};
use carom_collision::world::{CollisionWorld, ObjectHandle};
use std::sync::Arc;

/// The shape's box grown by the margin's own part, at the start of the step.
fn own_box(shape: &Shape, pose: &Isometry, margin: Real, motion: Vec3) -> Aabb {
    let own = (margin - motion.length()).max(0.0);
    let b = shape.aabb(pose);
    Aabb::new(b.min - Vec3::splat(own), b.max + Vec3::splat(own))
}

struct Mover {
    h: ObjectHandle,
    start: Aabb,
    motion: Vec3,
}

#[test]
fn swept_boxes_find_every_pair_that_meets_during_the_step() {
    let shapes: Vec<Arc<Shape>> = vec![
        Arc::new(Cuboid::new(Vec3::new(0.5, 0.5, 0.5)).unwrap().into()),
        Arc::new(Cuboid::new(Vec3::new(1.0, 0.1, 0.3)).unwrap().into()),
        Arc::new(Sphere::new(0.3).unwrap().into()),
        Arc::new(Sphere::new(1.0e-6).unwrap().into()),
    ];
    for far in [Vec3::ZERO, Vec3::new(1.0e3, -7.0e2, 4.0e2)] {
        for deferred in [false, true] {
            let mut rng = Rng(29);
            let mut w = CollisionWorld::new(Method::default());
            let mut movers = Vec::new();
            for k in 0..120 {
                let shape = shapes[k % shapes.len()].clone();
                let axis = rng.vec(-1.0, 1.0).try_normalize().unwrap_or(Vec3::Y);
                let pose = Isometry::new(
                    far + rng.vec(-4.0, 4.0),
                    Quat::from_axis_angle(axis, rng.range(0.0, 3.0)),
                );
                let h = w.add(shape.clone(), pose, Filter::new(false)).unwrap();
                let motion = match k % 4 {
                    0 => Vec3::ZERO,
                    _ => rng.vec(-1.5, 1.5),
                };
                // Some margins hold the whole motion and more, some only part of it.
                let margin = match k % 3 {
                    0 => motion.length() + rng.range(0.0, 0.05),
                    1 => motion.length(),
                    _ => rng.range(0.0, 1.0) * motion.length(),
                };
                if deferred {
                    w.set_pose_with_margin(h, pose, margin).unwrap();
                    w.set_motion(h, motion).unwrap();
                } else {
                    w.sync_object(h, pose, margin, motion, false).unwrap();
                }
                let start = own_box(&shape, &pose, margin, motion);
                movers.push(Mover { h, start, motion });
            }
            w.update().unwrap();
            let pairs = w.pairs();
            let mut met = 0;
            for (i, a) in movers.iter().enumerate() {
                // The box is exactly the hull of the grown box at the start and the end.
                let o = w.get(a.h).unwrap();
                let end = Aabb::new(a.start.min + a.motion, a.start.max + a.motion);
                assert_eq!(o.aabb, a.start.merge(&end), "{i}");
                for b in &movers[i + 1..] {
                    let meets = (0..=64).any(|s| {
                        let t = s as Real / 64.0;
                        let (da, db) = (a.motion * t, b.motion * t);
                        let ba = Aabb::new(a.start.min + da, a.start.max + da);
                        let bb = Aabb::new(b.start.min + db, b.start.max + db);
                        ba.intersects(&bb)
                    });
                    if meets {
                        met += 1;
                        let key = if a.h.index < b.h.index {
                            (a.h, b.h)
                        } else {
                            (b.h, a.h)
                        };
                        assert!(pairs.contains(&key), "{far} {deferred}: {i} and {:?}", b.h);
                    }
                }
            }
            assert!(met > 50, "the scene must hold meeting pairs ({met})");
        }
    }
}

#[test]
fn touching_at_the_end_of_the_step_pairs_and_moving_side_by_side_does_not() {
    let cube: Arc<Shape> = Arc::new(Cuboid::new(Vec3::splat(0.5)).unwrap().into());
    for far in [Vec3::ZERO, Vec3::new(1024.0, 512.0, -2048.0)] {
        let mut w = CollisionWorld::new(Method::default());
        let at = |x: Real| Isometry::new(far + Vec3::new(x, 0.0, 0.0), Quat::IDENTITY);
        // A moves 1 m towards B and ends exactly touching it (dyadic coordinates).
        let a = w.add(cube.clone(), at(0.0), Filter::new(false)).unwrap();
        let b = w.add(cube.clone(), at(2.0), Filter::new(false)).unwrap();
        w.sync_object(a, at(0.0), 1.0, Vec3::X, false).unwrap();
        w.sync_object(b, at(2.0), 0.0, Vec3::ZERO, false).unwrap();
        // C and D fall side by side, 0.25 m apart, at 1 m per step, with a 1 cm margin of
        // their own: the whole margin on every side (the old box) would pair them.
        let c = w.add(cube.clone(), at(10.0), Filter::new(false)).unwrap();
        let d = w.add(cube.clone(), at(11.25), Filter::new(false)).unwrap();
        let down = Vec3::new(0.0, -1.0, 0.0);
        w.sync_object(c, at(10.0), 1.01, down, false).unwrap();
        w.sync_object(d, at(11.25), 1.01, down, false).unwrap();
        w.update().unwrap();
        let pairs = w.pairs();
        assert!(pairs.contains(&(a, b)), "{far}: {pairs:?}");
        assert!(!pairs.contains(&(c, d)), "{far}: {pairs:?}");
        // A motion 1 cm short of the contact leaves a 1 cm gap: no pair.
        w.sync_object(a, at(0.0), 0.99, Vec3::new(0.99, 0.0, 0.0), false)
            .unwrap();
        w.update().unwrap();
        assert!(!w.pairs().contains(&(a, b)), "{far}");
    }
}

#[test]
fn a_new_motion_alone_updates_the_box() {
    let cube: Arc<Shape> = Arc::new(Cuboid::new(Vec3::splat(0.5)).unwrap().into());
    let mut w = CollisionWorld::new(Method::default());
    let pose = Isometry::new(Vec3::new(3.0, 1.0, -2.0), Quat::IDENTITY);
    let h = w.add(cube, pose, Filter::new(false)).unwrap();
    w.set_pose_with_margin(h, pose, 1.0).unwrap();
    w.update().unwrap();
    let whole = Aabb::new(Vec3::new(1.5, -0.5, -3.5), Vec3::new(4.5, 2.5, -0.5));
    assert_eq!(w.get(h).unwrap().aabb, whole);
    // The same pose, a motion of the margin's length: the box is the shape's swept by it.
    w.set_motion(h, Vec3::new(0.0, -1.0, 0.0)).unwrap();
    w.update().unwrap();
    let swept = Aabb::new(Vec3::new(2.5, -0.5, -2.5), Vec3::new(3.5, 1.5, -1.5));
    assert_eq!(w.get(h).unwrap().aabb, swept);
    // Back to rest: the whole margin on every side again.
    w.set_motion(h, Vec3::ZERO).unwrap();
    w.update().unwrap();
    assert_eq!(w.get(h).unwrap().aabb, whole);
}

/// `may_stop`: a pair counts the stop of an object that may stop short of its motion. Two
/// cubes fall together at 5 cm a step, 4 cm apart, with a 1 cm margin of their own each: by
/// their relative motion (none) they are 2 cm short of a speculative point. When the lower
/// one may stop (it has just landed on something), the upper one's whole motion counts
/// and their facing faces get points; with the upper one stopping instead, the lower one
/// moves away from it, and its motion counts as well. Near the origin and 1 km from it.
#[test]
fn an_object_that_may_stop_gets_points_against_one_falling_with_it() {
    let cube: Arc<Shape> = Arc::new(Cuboid::new(Vec3::splat(0.5)).unwrap().into());
    for far in [Vec3::ZERO, Vec3::new(1024.0, 512.0, -2048.0)] {
        for (lower_stops, upper_stops, points) in [
            (false, false, false),
            (true, false, true),
            (false, true, true),
            (true, true, true),
        ] {
            let mut w = CollisionWorld::new(Method::default());
            let at = |y: Real| Isometry::new(far + Vec3::new(0.0, y, 0.0), Quat::IDENTITY);
            let low = w.add(cube.clone(), at(0.0), Filter::new(false)).unwrap();
            let up = w.add(cube.clone(), at(1.04), Filter::new(false)).unwrap();
            let down = Vec3::new(0.0, -0.05, 0.0);
            w.sync_object(low, at(0.0), 0.06, down, lower_stops)
                .unwrap();
            w.sync_object(up, at(1.04), 0.06, down, upper_stops)
                .unwrap();
            w.update().unwrap();
            let key = (low.min(up), low.max(up));
            let found = w
                .narrowphase()
                .manifolds()
                .filter(|p| (p.a, p.b) == key)
                .map(|p| p.manifold.points.len())
                .sum::<usize>();
            assert_eq!(
                found > 0,
                points,
                "{far} lower {lower_stops} upper {upper_stops}: {found} points"
            );
            if points {
                assert_eq!(found, 4, "{far}: the facing faces");
            }
        }
    }
}
