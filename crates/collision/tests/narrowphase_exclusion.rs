//! Excluded object pairs (`CollisionWorld::set_pair_excluded`): the broadphase still pairs
//! them, the narrowphase keeps them empty and silent, whether the exclusion comes before or
//! after the pair, and lifting it generates the pair afresh.

use carom_collision::broadphase::{Filter, Method};
use carom_collision::math::{Isometry, Real, Vec3};
use carom_collision::narrowphase::ContactEventKind as K;
use carom_collision::shape::{Cuboid, Shape};
use carom_collision::world::{CollisionWorld, ObjectHandle};
use std::sync::Arc;

fn cuboid(h: Real) -> Arc<Shape> {
    Arc::new(Shape::Cuboid(Cuboid::new(Vec3::splat(h)).unwrap()))
}

fn at(x: Real) -> Isometry {
    Isometry::from_translation(Vec3::new(x, 0.0, 0.0))
}

fn kinds(w: &CollisionWorld, a: ObjectHandle, b: ObjectHandle) -> Vec<K> {
    w.narrowphase()
        .events()
        .iter()
        .filter(|e| (e.a, e.b) == (a.min(b), a.max(b)))
        .map(|e| e.kind)
        .collect()
}

fn points(w: &CollisionWorld, a: ObjectHandle, b: ObjectHandle) -> Option<usize> {
    let p = w.narrowphase().get(a.min(b), a.max(b))?;
    Some(p.manifold.len())
}

#[test]
fn excluded_pairs_get_no_points_and_no_events() {
    for method in [Method::Tree, Method::Sap, Method::BruteForce] {
        let mut w = CollisionWorld::new(method);
        let a = w.add(cuboid(0.5), at(0.0), Filter::default()).unwrap();
        let b = w.add(cuboid(0.5), at(0.9), Filter::default()).unwrap();
        // A third box far away: excluded before its pair with A exists.
        let c = w.add(cuboid(0.5), at(5.0), Filter::default()).unwrap();
        w.set_pair_excluded(b, a, true).unwrap();
        w.set_pair_excluded(a, c, true).unwrap();
        assert!(w.narrowphase().is_excluded(a, b) && w.narrowphase().is_excluded(c, a));
        w.update().unwrap();
        // The broadphase pair exists, excluded and empty.
        let p = w.narrowphase().get(a, b).unwrap();
        assert!(p.excluded && p.manifold.is_empty() && !p.touching);
        assert!(w.narrowphase().events().is_empty());
        assert_eq!(w.narrowphase().manifolds().count(), 0);

        // C moves onto A: the new pair is born excluded.
        w.set_pose(c, at(-0.9)).unwrap();
        w.update().unwrap();
        assert!(w.narrowphase().get(a, c).unwrap().excluded);
        assert_eq!(points(&w, a, c), Some(0));
        assert!(w.narrowphase().events().is_empty());

        // Lifted: generated at the next update, with a Begin.
        w.set_pair_excluded(a, b, false).unwrap();
        assert!(!w.narrowphase().is_excluded(a, b));
        w.update().unwrap();
        assert_eq!(points(&w, a, b), Some(4));
        assert_eq!(kinds(&w, a, b), [K::Begin]);

        // Excluded while touching: emptied at once, End at the next update, then silence.
        w.set_pair_excluded(a, b, true).unwrap();
        assert_eq!(points(&w, a, b), Some(0));
        w.update().unwrap();
        assert_eq!(kinds(&w, a, b), [K::End]);
        w.update().unwrap();
        assert!(kinds(&w, a, b).is_empty());
        // Excluding twice and lifting once lifts it (no count is kept).
        w.set_pair_excluded(a, b, true).unwrap();
        w.set_pair_excluded(a, b, false).unwrap();
        w.update().unwrap();
        assert_eq!(points(&w, a, b), Some(4));

        // Removing an object lifts its exclusions; dead handles are rejected.
        w.remove(c).unwrap();
        assert!(!w.narrowphase().is_excluded(a, c));
        assert!(w.set_pair_excluded(a, c, true).is_err());
        w.update().unwrap();
        let d = w.add(cuboid(0.5), at(-0.9), Filter::default()).unwrap();
        w.update().unwrap();
        assert_eq!(points(&w, a, d), Some(4), "the reused slot is not excluded");
    }
}

#[test]
fn exclusion_applies_to_pairs_added_through_the_narrowphase_alone() {
    use carom_collision::narrowphase::{NarrowObject, NarrowPhase};
    let shape = cuboid(0.5);
    let poses = [at(0.0), at(0.9)];
    let mut np: NarrowPhase<u32> = NarrowPhase::default();
    np.set_excluded(1, 0, true);
    np.add_pair(0, 1);
    let lookup = |h: u32| Some(NarrowObject::new(&shape, poses[h as usize]));
    np.step(&[], &[], lookup).unwrap();
    assert!(np.get(0, 1).unwrap().excluded);
    assert_eq!(np.manifolds().count(), 0);
    np.set_excluded(0, 1, false);
    np.step(&[], &[], lookup).unwrap();
    assert_eq!(np.manifolds().count(), 1);
}
