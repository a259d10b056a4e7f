//! `CollisionWorld::sync_objects` (the pipeline's batched sync: boxes and fat-box tests
//! first, in parallel, then the writes) against its oracle, `sync_object` called once per
//! entry: the same objects, boxes, pairs and pair changes every frame, for every broadphase
//! method, on 1, 2 and 8 threads; near and far from the origin, with zero margins and
//! motions, touching boxes and zero-size (point) boxes; unsorted and repeated handles; and
//! the same error, with the same entries applied, when an entry is bad or stale.

mod broadphase_common;

use broadphase_common::Rng;
use carom_collision::broadphase::{Filter, Method};
use carom_collision::math::{Isometry, Quat, Real, Vec3};
use carom_collision::shape::{Cuboid, Shape, Sphere};
use carom_collision::world::{CollisionWorld, ObjectHandle, ObjectSync};
use carom_collision::CaromError;
use std::sync::Arc;

/// Unit cubes on a lattice of pitch 2 (neighbours' boxes touch), spheres of radius 0 are
/// not allowed, so tiny spheres stand for near-point boxes, plus a static ground cube.
fn world(m: Method, n: usize, far: Vec3) -> (CollisionWorld, Vec<ObjectHandle>) {
    let cube: Arc<Shape> = Arc::new(Cuboid::new(Vec3::ONE).unwrap().into());
    let dot: Arc<Shape> = Arc::new(Sphere::new(1.0e-6).unwrap().into());
    let ground: Arc<Shape> = Arc::new(Cuboid::new(Vec3::new(200.0, 1.0, 200.0)).unwrap().into());
    let mut w = CollisionWorld::new(m);
    let mut hs = Vec::new();
    w.add(
        ground,
        Isometry::from_translation(far - Vec3::Y * 1.0),
        Filter::new(true),
    )
    .unwrap();
    for k in 0..n {
        let p = Vec3::new(
            (k % 16) as Real,
            (k / 256) as Real + 1.0,
            ((k / 16) % 16) as Real,
        );
        let shape = if k % 9 == 4 {
            dot.clone()
        } else {
            cube.clone()
        };
        let pose = Isometry::from_translation(far + p * 2.0);
        hs.push(w.add(shape, pose, Filter::default()).unwrap());
    }
    (w, hs)
}

/// One frame's entries: most objects, in ascending order; small moves that stay inside the
/// fat boxes, some jumps, zero margins and motions, exact lattice positions (touching).
fn frame(rng: &mut Rng, w: &CollisionWorld, hs: &[ObjectHandle], far: Vec3) -> Vec<ObjectSync> {
    let mut items = Vec::new();
    for (k, &h) in hs.iter().enumerate() {
        if rng.below(5) == 0 {
            continue;
        }
        let p = w.get(h).unwrap().pose;
        let pose = match rng.below(6) {
            0 => Isometry::new(
                far + rng.vec(0.0, 32.0),
                Quat::from_axis_angle(Vec3::Y, rng.range(0.0, 3.0)),
            ),
            1 => Isometry::from_translation(
                far + Vec3::new((k % 16) as Real, 1.0, ((k / 16) % 16) as Real) * 2.0,
            ),
            _ => Isometry::new(p.translation + rng.vec(-0.02, 0.02), p.rotation),
        };
        let (margin, motion) = if k % 4 == 0 {
            (0.0, Vec3::ZERO)
        } else {
            let motion = rng.vec(-0.1, 0.1);
            (motion.length() + rng.range(0.0, 0.05), motion)
        };
        items.push(ObjectSync {
            handle: h,
            pose,
            margin,
            motion,
        });
    }
    items
}

fn assert_same(a: &CollisionWorld, b: &CollisionWorld, what: &str) {
    assert_eq!(a.pairs(), b.pairs(), "{what}: pairs");
    for ((ha, oa), (hb, ob)) in a.iter().zip(b.iter()) {
        assert_eq!(ha, hb);
        assert_eq!(oa.pose, ob.pose, "{what}: pose of {ha:?}");
        assert_eq!(oa.aabb, ob.aabb, "{what}: box of {ha:?}");
        assert_eq!((oa.margin, oa.motion), (ob.margin, ob.motion), "{what}");
    }
}

fn pools() -> Vec<rayon::ThreadPool> {
    [1, 2, 8]
        .map(|n| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .unwrap()
        })
        .into()
}

#[test]
fn batch_equals_one_by_one_on_any_thread_count() {
    let pools = pools();
    for far in [Vec3::ZERO, Vec3::new(3.0e4, -1.0e4, 2.0e4)] {
        for m in Method::ALL {
            // Above two chunks of the parallel pass for the tree; fewer for the slow methods.
            let n = if m == Method::BruteForce { 300 } else { 1300 };
            let (mut oracle, hs) = world(m, n, far);
            let mut batched: Vec<CollisionWorld> =
                pools.iter().map(|_| world(m, n, far).0).collect();
            let mut rng = Rng(0x5eed ^ n as u64);
            for f in 0..6 {
                let items = frame(&mut rng, &oracle, &hs, far);
                for s in &items {
                    oracle
                        .sync_object(s.handle, s.pose, s.margin, s.motion)
                        .unwrap();
                }
                let expected = oracle.update().unwrap().clone();
                for (w, pool) in batched.iter_mut().zip(&pools) {
                    pool.install(|| w.sync_objects(&items)).unwrap();
                    let got = pool.install(|| w.update().unwrap().clone());
                    let what = format!(
                        "{m:?} far {far} frame {f} {} threads",
                        pool.current_num_threads()
                    );
                    assert_eq!(got, expected, "{what}: pair changes");
                    assert_same(w, &oracle, &what);
                }
            }
        }
    }
}

#[test]
fn unsorted_and_repeated_handles_take_the_sequential_path() {
    let (mut oracle, hs) = world(Method::Tree, 200, Vec3::ZERO);
    let (mut w, _) = world(Method::Tree, 200, Vec3::ZERO);
    let mut rng = Rng(3);
    for f in 0..4 {
        let mut items = frame(&mut rng, &oracle, &hs, Vec3::ZERO);
        if f % 2 == 0 {
            items.reverse();
        } else {
            // The same object twice: the second entry must see the first one's pose.
            let mut again = items[3];
            again.pose.translation += Vec3::X * 0.5;
            items.insert(4, again);
        }
        for s in &items {
            oracle
                .sync_object(s.handle, s.pose, s.margin, s.motion)
                .unwrap();
        }
        w.sync_objects(&items).unwrap();
        assert_eq!(w.update().unwrap(), oracle.update().unwrap(), "frame {f}");
        assert_same(&w, &oracle, &format!("frame {f}"));
    }
}

#[test]
fn a_bad_entry_gives_the_same_error_after_the_same_entries() {
    let bad_rot = Isometry::new(Vec3::ZERO, Quat::from_xyzw(0.0, 0.0, 0.0, 2.0));
    let nan = Isometry::from_translation(Vec3::new(Real::NAN, 0.0, 0.0));
    let huge = Isometry::from_translation(Vec3::splat(Real::MAX));
    let ok = Isometry::from_translation(Vec3::new(3.0, 4.0, 5.0));
    let cases: [(Isometry, Real, Vec3); 6] = [
        (nan, 0.1, Vec3::ZERO),
        (bad_rot, 0.1, Vec3::ZERO),
        (ok, -0.1, Vec3::ZERO),
        (ok, Real::INFINITY, Vec3::ZERO),
        (ok, 0.1, Vec3::new(0.0, Real::NAN, 0.0)),
        (huge, Real::MAX, Vec3::ZERO),
    ];
    for (c, &(pose, margin, motion)) in cases.iter().enumerate() {
        for at in [0, 700, 1199] {
            let (mut oracle, hs) = world(Method::Tree, 1200, Vec3::ZERO);
            let (mut w, _) = world(Method::Tree, 1200, Vec3::ZERO);
            let mut rng = Rng(c as u64);
            let mut items = frame(&mut rng, &oracle, &hs, Vec3::ZERO);
            let at = at.min(items.len() - 1);
            items[at].pose = pose;
            items[at].margin = margin;
            items[at].motion = motion;
            let mut expected = Ok(());
            for s in &items {
                if let Err(e) = oracle.sync_object(s.handle, s.pose, s.margin, s.motion) {
                    expected = Err(e);
                    break;
                }
            }
            let got = w.sync_objects(&items);
            match (&got, &expected) {
                (
                    Err(CaromError::InvalidValue { name: a, .. }),
                    Err(CaromError::InvalidValue { name: b, .. }),
                ) => assert_eq!(a, b, "case {c} at {at}"),
                _ => panic!("case {c} at {at}: {got:?} vs {expected:?}"),
            }
            assert_eq!(w.update().unwrap(), oracle.update().unwrap());
            assert_same(&w, &oracle, &format!("case {c} at {at}"));
        }
    }
    // A stale handle in the batch: unknown, after the entries before it.
    let (mut oracle, hs) = world(Method::Tree, 1200, Vec3::ZERO);
    let (mut w, _) = world(Method::Tree, 1200, Vec3::ZERO);
    oracle.remove(hs[600]).unwrap();
    w.remove(hs[600]).unwrap();
    let mut rng = Rng(99);
    let mut items = frame(&mut rng, &oracle, &hs[..600], Vec3::ZERO);
    let tail = frame(&mut rng, &oracle, &hs[601..], Vec3::ZERO);
    items.push(ObjectSync {
        handle: hs[600],
        pose: ok,
        margin: 0.0,
        motion: Vec3::ZERO,
    });
    items.extend(tail);
    for s in &items[..items.len() - 1] {
        if s.handle == hs[600] {
            break;
        }
        oracle
            .sync_object(s.handle, s.pose, s.margin, s.motion)
            .unwrap();
    }
    assert!(matches!(
        w.sync_objects(&items),
        Err(CaromError::UnknownHandle(_))
    ));
    assert_eq!(w.update().unwrap(), oracle.update().unwrap());
    assert_same(&w, &oracle, "stale handle");
}
