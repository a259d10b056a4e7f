//! Compound child queries (static BVH over child boxes) against brute force.

mod midphase_common;

use carom_collision::math::{Aabb, Isometry, Quat, Real, Vec3};
use carom_collision::midphase::child_pair_overlaps;
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
