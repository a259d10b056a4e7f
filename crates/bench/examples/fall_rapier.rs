//! The peer run of `make demo`'s simulation: Bullet's "3000 fall" scene (from carom-scenes)
//! in rapier3d, with the same report (ms/step, sleeping bodies, final heights).
//! `cargo run --release -p carom-bench --example fall_rapier` (`CAROM_DEMO_STEPS`, default 300).

use carom_collision::shape::Shape;
use carom_scenes::bullet;
use rapier3d::prelude::*;
use std::time::Instant;

type R = rapier3d::math::Real;

fn main() {
    let steps: usize = std::env::var("CAROM_DEMO_STEPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(300);
    let scene = bullet::falling_boxes();
    let mut world = PhysicsWorld::new();
    world.gravity = Vector::new(
        scene.gravity.x as R,
        scene.gravity.y as R,
        scene.gravity.z as R,
    );
    world.integration_parameters.dt = scene.dt as R;
    let mut dynamic = Vec::new();
    for b in &scene.bodies {
        let Shape::Cuboid(c) = &*b.shape else {
            panic!("the falling-boxes scene holds boxes only");
        };
        let h = c.half_extents();
        let t = b.pose.translation;
        let collider = ColliderBuilder::cuboid(h.x as R, h.y as R, h.z as R)
            .friction(b.friction as R)
            .restitution(b.restitution as R);
        let at = Vector::new(t.x as R, t.y as R, t.z as R);
        if b.is_static() {
            world.insert_collider(collider.translation(at), None);
        } else {
            let (h, _) = world.insert(
                RigidBodyBuilder::dynamic().translation(at),
                collider.mass(b.mass as R),
            );
            dynamic.push(h);
        }
    }
    let mut per_step = Vec::with_capacity(steps);
    for _ in 0..steps {
        let t = Instant::now();
        world.step();
        per_step.push(t.elapsed().as_secs_f64() * 1e3);
    }
    let mean = per_step.iter().sum::<f64>() / steps.max(1) as f64;
    per_step.sort_by(f64::total_cmp);
    let median = per_step.get(per_step.len() / 2).copied().unwrap_or(0.0);
    let heights: Vec<R> = dynamic
        .iter()
        .map(|&h| world.bodies[h].translation().y)
        .collect();
    let sleeping = dynamic
        .iter()
        .filter(|&&h| world.bodies[h].is_sleeping())
        .count();
    let min = heights.iter().copied().fold(R::INFINITY, R::min);
    let mean_h = heights.iter().sum::<R>() / heights.len().max(1) as R;
    println!(
        "rapier3d 0.36.1, \"{}\" ({} boxes, {} threads): {steps} steps, ms/step mean {mean:.2}, median {median:.2}; asleep {sleeping}; heights min {min:.3} mean {mean_h:.3}; below ground {}",
        scene.name,
        dynamic.len(),
        rayon::current_num_threads(),
        heights.iter().filter(|&&y| y < 0.0).count()
    );
}
