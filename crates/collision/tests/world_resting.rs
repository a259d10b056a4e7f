//! A world whose objects all rest (or are static) skips the narrowphase's shape tests and
//! the broadphase's pass over its candidates: the pairs, manifolds and events must be those
//! of the same world with one far, unrelated object still active (which takes the full
//! path), including an exclusion set and lifted while everything rests. Quiet updates in a
//! row hand back the last events without rebuilding them (the narrowphase's settled state),
//! so rounds 1, 3 and 5 check that path and rounds 2 and 4 that an exclusion leaves it.

use carom_collision::broadphase::{Filter, Method};
use carom_collision::math::{Isometry, Real, Vec3};
use carom_collision::narrowphase::ContactEventKind as K;
use carom_collision::shape::{Cuboid, Shape};
use carom_collision::world::{CollisionWorld, ObjectHandle};
use std::sync::Arc;

fn cuboid(h: Real) -> Arc<Shape> {
    Arc::new(Shape::Cuboid(Cuboid::new(Vec3::splat(h)).unwrap()))
}

fn at(x: Real, y: Real) -> Isometry {
    Isometry::from_translation(Vec3::new(x, y, 0.0))
}

/// Events (slots and kind) and manifold points (distances) of the pairs among `objs`.
type State = (Vec<(u32, u32, K)>, Vec<Vec<Real>>);

fn state(w: &CollisionWorld, objs: &[ObjectHandle]) -> State {
    let inside = |h: ObjectHandle| objs.contains(&h);
    let events = w
        .narrowphase()
        .events()
        .iter()
        .filter(|e| inside(e.a) && inside(e.b))
        .map(|e| (e.a.index, e.b.index, e.kind))
        .collect();
    let mut points = Vec::new();
    for (i, &a) in objs.iter().enumerate() {
        for &b in &objs[i + 1..] {
            if let Some(p) = w.narrowphase().get(a.min(b), a.max(b)) {
                points.push(p.manifold.points.iter().map(|q| q.distance).collect());
            }
        }
    }
    (events, points)
}

#[test]
fn a_resting_world_keeps_its_pairs_manifolds_and_events() {
    for method in [Method::Tree, Method::Sap, Method::BruteForce] {
        // Two worlds: the same stack on a static ground, and in `busy` a far box that stays
        // active (so its updates take the full path).
        let mut worlds = Vec::new();
        for busy in [false, true] {
            let mut w = CollisionWorld::new(method);
            let ground = w
                .add(cuboid(5.0), at(0.0, -5.0), Filter::new(true))
                .unwrap();
            let a = w
                .add(cuboid(0.5), at(0.0, 0.49), Filter::default())
                .unwrap();
            let b = w
                .add(cuboid(0.5), at(0.1, 1.47), Filter::default())
                .unwrap();
            if busy {
                w.add(cuboid(0.5), at(100.0, 50.0), Filter::default())
                    .unwrap();
            }
            w.update().unwrap();
            worlds.push((w, [ground, a, b]));
        }
        let objs = worlds[0].1;
        assert_eq!(objs, worlds[1].1);
        let touching = state(&worlds[0].0, &objs);
        assert_eq!(touching, state(&worlds[1].0, &objs));
        assert_eq!(
            touching.0.iter().filter(|e| e.2 == K::Begin).count(),
            2,
            "{method:?}"
        );
        for (w, o) in &mut worlds {
            w.set_resting(o[1], true).unwrap();
            w.set_resting(o[2], true).unwrap();
        }
        for round in 0..6 {
            if round == 2 || round == 4 {
                // Excluded while everything rests: emptied, and an End at the next update.
                // Lifted while everything rests: nothing is generated until a box moves.
                for (w, o) in &mut worlds {
                    w.set_pair_excluded(o[1], o[2], round == 2).unwrap();
                }
            }
            for (w, _) in &mut worlds {
                w.update().unwrap();
            }
            let (quiet, busy) = (state(&worlds[0].0, &objs), state(&worlds[1].0, &objs));
            assert_eq!(quiet, busy, "{method:?}, round {round}");
            assert_eq!(
                worlds[0].0.pairs(),
                worlds[1].0.pairs()[..worlds[0].0.pairs().len()],
                "{method:?}"
            );
            let persist = quiet.0.iter().filter(|e| e.2 == K::Persist).count();
            let end = quiet.0.iter().filter(|e| e.2 == K::End).count();
            match round {
                0 | 1 => assert_eq!((persist, end), (2, 0), "{method:?}, round {round}"),
                2 => assert_eq!((persist, end), (1, 1), "{method:?}, round {round}"),
                _ => assert_eq!((persist, end), (1, 0), "{method:?}, round {round}"),
            }
        }
        // Woken: the full path again, the same as the busy world.
        for (w, o) in &mut worlds {
            w.set_resting(o[2], false).unwrap();
            w.set_pose(o[2], at(0.1, 1.45)).unwrap();
            w.update().unwrap();
        }
        assert_eq!(state(&worlds[0].0, &objs), state(&worlds[1].0, &objs));
    }
}
