//! How much contact work each engine does on the same scene: broadphase pairs, manifolds
//! with points and contact points, Carom against rapier3d, every 50 steps.
//! `cargo run --release -p carom-bench --example pair_counts [scene number, default 1]`
//! (`CAROM_DEMO_STEPS`, default 300).
//!
//! Carom's pairs are its narrowphase pairs (broadphase boxes expanded by each body's
//! speculative margin, `prediction/2 + (|v| + |ω| r) dt`); its manifolds are those handed to
//! the solver (at most 4 points each). Rapier's are its narrow phase's contact pairs, the
//! contact manifolds with points, and the solver contacts (its prediction distance is its
//! default, 2 mm; no speculative margin from the motion without CCD).

use carom_collision::shape::Shape;
use carom_dynamics::World;
use rapier3d::prelude::*;

type R = rapier3d::math::Real;

fn rapier_world(scene: &carom_scenes::Scene) -> PhysicsWorld {
    let mut world = PhysicsWorld::new();
    world.gravity = Vector::new(
        scene.gravity.x as R,
        scene.gravity.y as R,
        scene.gravity.z as R,
    );
    world.integration_parameters.dt = scene.dt as R;
    world.integration_parameters.num_solver_iterations = scene.solver.iterations.max(1) as usize;
    for b in &scene.bodies {
        let Shape::Cuboid(c) = &*b.shape else {
            panic!("pair_counts compares box scenes only (1 and 2)");
        };
        let h = c.half_extents();
        let t = b.pose.translation;
        let q = b.pose.rotation;
        let collider = ColliderBuilder::cuboid(h.x as R, h.y as R, h.z as R)
            .friction(b.friction as R)
            .restitution(b.restitution as R);
        let pose = Pose::from_parts(
            Vector::new(t.x as R, t.y as R, t.z as R),
            Rotation::from_xyzw(q.x as R, q.y as R, q.z as R, q.w as R),
        );
        if b.is_static() {
            world.insert_collider(collider.position(pose), None);
        } else {
            world.insert(
                RigidBodyBuilder::dynamic().pose(pose).can_sleep(false),
                collider.mass(b.mass as R),
            );
        }
    }
    world
}

fn main() {
    let steps: usize = std::env::var("CAROM_DEMO_STEPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(300);
    let which: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let scene = carom_scenes::bullet::scene(which).expect("a scene number 1..=8");
    let mut params = carom_dynamics::PipelineParams::default();
    params.dynamics.sleep.enabled = false;
    let mut carom = World::from_scene_with(&scene, params).expect("the scene builds");
    let mut rapier = rapier_world(&scene);
    println!(
        "{}: step | carom pairs, manifolds, points | rapier pairs, manifolds, points, solver contacts",
        scene.name
    );
    for step in 1..=steps {
        carom.step(scene.dt).expect("step");
        rapier.step();
        if step % 50 != 0 {
            continue;
        }
        let r = carom.last_report();
        let (mut pairs, mut manifolds, mut points, mut solver) = (0, 0, 0, 0);
        for p in rapier.narrow_phase.contact_pairs() {
            pairs += 1;
            for m in p.manifolds() {
                if !m.points.is_empty() {
                    manifolds += 1;
                    points += m.points.len();
                }
            }
            for m in p.solver_manifolds() {
                solver += m.data.solver_contacts.len();
            }
        }
        println!(
            "{step:5} | {:6} {:6} {:6} | {pairs:6} {manifolds:6} {points:6} {solver:6}",
            r.pairs, r.manifolds, r.contact_points
        );
    }
}
