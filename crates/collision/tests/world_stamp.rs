//! `CollisionWorld::objects_stamp` names the objects with their shapes and filters: it
//! changes with every added or removed object and every filter change, never with poses,
//! motions, resting hints, exclusions or updates, is unique across worlds (two empty worlds
//! differ), and a clone keeps it. Caches of per-object data (the dynamics world's query
//! tree) rely on exactly this.

use carom_collision::broadphase::{Filter, Method};
use carom_collision::math::{Isometry, Vec3};
use carom_collision::shape::{Shape, Sphere};
use carom_collision::world::CollisionWorld;
use std::collections::HashSet;
use std::sync::Arc;

fn ball() -> Arc<Shape> {
    Arc::new(Shape::Sphere(Sphere::new(0.5).unwrap()))
}

#[test]
fn the_objects_stamp_changes_exactly_with_the_objects_shapes_and_filters() {
    let mut seen = HashSet::new();
    let mut w = CollisionWorld::new(Method::Tree);
    let other = CollisionWorld::new(Method::Tree);
    assert_ne!(
        w.objects_stamp(),
        other.objects_stamp(),
        "two worlds share a stamp"
    );
    seen.insert(other.objects_stamp());
    let mut fresh = |w: &CollisionWorld| assert!(seen.insert(w.objects_stamp()), "stamp reused");
    fresh(&w);
    let a = w
        .add(ball(), Isometry::IDENTITY, Filter::default())
        .unwrap();
    fresh(&w);
    let b = w
        .add(
            ball(),
            Isometry::from_translation(Vec3::X * 0.8),
            Filter::default(),
        )
        .unwrap();
    fresh(&w);
    // Poses, motions, resting hints, exclusions and updates keep it.
    let kept = w.objects_stamp();
    w.set_pose(a, Isometry::from_translation(Vec3::Y)).unwrap();
    w.set_motion(b, Vec3::X).unwrap();
    w.set_resting(a, true).unwrap();
    w.set_pair_excluded(a, b, true).unwrap();
    w.update().unwrap();
    assert_eq!(w.objects_stamp(), kept);
    // A clone keeps it (same objects); changing the clone gives the clone a new one.
    let mut c = w.clone();
    assert_eq!(c.objects_stamp(), kept);
    c.set_filter(b, Filter::new(true)).unwrap();
    fresh(&c);
    assert_eq!(w.objects_stamp(), kept);
    // A filter change, a removal.
    w.set_filter(a, Filter::new(true)).unwrap();
    fresh(&w);
    w.remove(b).unwrap();
    fresh(&w);
    // Errors change nothing.
    assert!(w.remove(b).is_err());
    assert!(w.set_filter(b, Filter::default()).is_err());
    let after_errors = w.objects_stamp();
    assert!(
        !seen.insert(after_errors),
        "a failed call changed the stamp"
    );
}
