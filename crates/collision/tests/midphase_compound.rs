//! Compound child queries (static BVH over child boxes) against brute force.

mod midphase_common;

use carom_collision::math::{Aabb, Isometry, Quat, Real, Vec3};
use carom_collision::midphase::{
    brute_force_child_pairs, brute_force_children_in_aabb, child_pair_overlaps,
};
use carom_collision::shape::{Compound, Cuboid, Shape, Sphere};
use midphase_common::Rng;
use std::sync::Arc;

fn compound(rng: &mut Rng, n: usize, spread: Real) -> Compound {
    let children = (0..n)
        .map(|k| {
            let pose = Isometry::new(
                rng.vec(-spread, spread),
                Quat::from_axis_angle(rng.unit(), rng.range(0.0, 3.0)),
            );
            let shape: Shape = if k % 2 == 0 {
                Sphere::new(rng.range(0.1, 0.6)).unwrap().into()
            } else {
                Cuboid::new(rng.vec(0.1, 0.7)).unwrap().into()
            };
            (pose, Arc::new(shape))
        })
        .collect();
    Compound::new(children).unwrap()
}

#[test]
fn children_in_aabb_match_brute_force() {
    let mut rng = Rng(31);
    let c = compound(&mut rng, 200, 6.0);
    let b = c.local_aabb();
    let mut nonempty = 0;
    for _ in 0..300 {
        let center = b.min + b.extents() * Vec3::new(rng.f(), rng.f(), rng.f());
        let q = Aabb::from_center_half_extents(center, rng.vec(0.0, 1.0));
        let want: Vec<u32> = (0..c.children().len() as u32)
            .filter(|&i| c.child_aabbs()[i as usize].intersects(&q))
            .collect();
        assert_eq!(c.children_in_aabb(&q), want);
        nonempty += !want.is_empty() as usize;
    }
    assert!((60..290).contains(&nonempty), "{nonempty}");
    // Child boxes contain the children's own world boxes.
    for (i, (pose, s)) in c.children().iter().enumerate() {
        assert_eq!(c.child_aabbs()[i], s.aabb(pose));
    }
}

#[test]
fn child_pairs_match_brute_force_and_nest() {
    let mut rng = Rng(32);
    let a = compound(&mut rng, 80, 4.0);
    let b = compound(&mut rng, 60, 4.0);
    let mut total = 0;
    for _ in 0..10 {
        let pose = Isometry::new(
            rng.vec(-3.0, 3.0),
            Quat::from_axis_angle(rng.unit(), rng.range(0.0, 3.0)),
        );
        let mut want = Vec::new();
        for ia in 0..a.children().len() as u32 {
            for ib in 0..b.children().len() as u32 {
                if child_pair_overlaps(&a, &b, &pose, ia, ib) {
                    want.push((ia, ib));
                }
            }
        }
        assert_eq!(a.child_pairs(&b, &pose), want);
        total += want.len();
    }
    assert!(total > 50, "{total}");
    // A compound of compounds: its children's boxes are the inner compounds' boxes.
    let outer = Compound::new(vec![
        (Isometry::IDENTITY, Arc::new(Shape::from(a.clone()))),
        (
            Isometry::from_translation(Vec3::X * 20.0),
            Arc::new(Shape::from(b)),
        ),
    ])
    .unwrap();
    assert_eq!(outer.children_in_aabb(&a.local_aabb()), vec![0]);
}

fn random_pose(rng: &mut Rng, spread: Real) -> Isometry {
    Isometry::new(
        rng.vec(-spread, spread),
        Quat::from_axis_angle(rng.unit(), rng.range(0.0, 3.0)),
    )
}

/// Checks every cached quantity and both queries of `c` against brute force.
fn check_against_brute_force(rng: &mut Rng, c: &Compound, other: &Compound) {
    c.tree().validate().unwrap();
    assert_eq!(c.tree().len(), c.children().len());
    let mut bounds = c.child_aabbs()[0];
    for (i, (pose, s)) in c.children().iter().enumerate() {
        assert_eq!(c.child_aabbs()[i], s.aabb(pose));
        bounds = bounds.merge(&c.child_aabbs()[i]);
    }
    assert_eq!(c.local_aabb(), bounds);
    for _ in 0..20 {
        let center = bounds.min + bounds.extents() * Vec3::new(rng.f(), rng.f(), rng.f());
        let q = Aabb::from_center_half_extents(center, rng.vec(0.0, 1.5));
        assert_eq!(c.children_in_aabb(&q), brute_force_children_in_aabb(c, &q));
    }
    let pose = random_pose(rng, 3.0);
    assert_eq!(
        c.child_pairs(other, &pose),
        brute_force_child_pairs(c, other, &pose)
    );
}

#[test]
fn edits_keep_queries_equal_to_brute_force() {
    let mut rng = Rng(33);
    let mut c = compound(&mut rng, 30, 4.0);
    let other = compound(&mut rng, 40, 4.0);
    for step in 0..120 {
        let n = c.children().len() as u32;
        match rng.next_u32() % 3 {
            0 => {
                let shape = Arc::new(Shape::from(Sphere::new(rng.range(0.1, 0.8)).unwrap()));
                let pose = random_pose(&mut rng, 5.0);
                assert_eq!(c.add_child(pose, shape.clone()).unwrap(), n);
                assert_eq!(c.children()[n as usize].0.translation, pose.translation);
            }
            1 if n > 1 => {
                let i = rng.next_u32() % n;
                let last = c.children()[n as usize - 1].clone();
                c.remove_child(i).unwrap();
                // The last child took the removed one's index.
                if i != n - 1 {
                    assert!(Arc::ptr_eq(&c.children()[i as usize].1, &last.1));
                }
            }
            _ => {
                let i = rng.next_u32() % n;
                c.set_child_pose(i, random_pose(&mut rng, 5.0)).unwrap();
            }
        }
        if step % 4 == 0 {
            check_against_brute_force(&mut rng, &c, &other);
        }
    }
    check_against_brute_force(&mut rng, &c, &other);
}

#[test]
fn bad_edits_are_errors_and_change_nothing() {
    let mut rng = Rng(34);
    let mut c = compound(&mut rng, 3, 2.0);
    let before = c.clone();
    let sphere = Arc::new(Shape::from(Sphere::new(0.5).unwrap()));
    let plane: Arc<Shape> = Arc::new(
        carom_collision::shape::Plane::new(Vec3::Y, 0.0)
            .unwrap()
            .into(),
    );
    assert!(c.remove_child(3).is_err());
    assert!(c.set_child_pose(7, Isometry::IDENTITY).is_err());
    let nan_pose = Isometry::from_translation(Vec3::new(Real::NAN, 0.0, 0.0));
    assert!(c.set_child_pose(0, nan_pose).is_err());
    assert!(c.add_child(nan_pose, sphere.clone()).is_err());
    assert!(c.add_child(Isometry::IDENTITY, plane).is_err());
    assert_eq!(c, before);
    assert_eq!(c.local_aabb(), before.local_aabb());
    // The last child cannot be removed.
    let mut single = Compound::new(vec![(Isometry::IDENTITY, sphere)]).unwrap();
    assert!(single.remove_child(0).is_err());
    assert_eq!(single.children().len(), 1);
    // Serialisation keeps the children and rebuilds the tree.
    let bytes = postcard::to_allocvec(&c).unwrap();
    let back: Compound = postcard::from_bytes(&bytes).unwrap();
    assert_eq!(back, c);
    assert_eq!(back.tree().len(), 3);
}
