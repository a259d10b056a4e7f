//! Deepest box–box penetration in a falling pile of the "3000 fall" kind, Carom beside
//! rapier3d, measured with one oracle for both: Carom's exact box–box query (SAT) on each
//! engine's poses, every `EVERY` steps (issue 7). The pile: `LAYERS` layers of `COLS` × `COLS`
//! 2 m cubes of 2 kg, 3 m apart, each layer shifted by 0.35 m, on the scene's ground box;
//! sleeping off. `LAYERS=47 COLS=8` is the whole scene.
//! `LAYERS=30 COLS=3 STEPS=300 EVERY=5 cargo run --release -p carom-bench --example pile_depth`
//! (`HZ`, `SUB`: Carom's contact hertz and substeps; `RSUB`: rapier's substeps, default 5 as
//! in the scene).
use carom_collision::math::{Isometry, Quat, Real, Vec3};
use carom_collision::query;
use carom_collision::shape::{Cuboid, Shape};
use carom_dynamics::{BodyDesc, MassSpec, PipelineParams, World};
use rapier3d::prelude::*;
use std::sync::Arc;

type R = rapier3d::math::Real;

fn env<T: std::str::FromStr>(k: &str, d: T) -> T {
    std::env::var(k)
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(d)
}

fn deepest(poses: &[Isometry], cube: &Shape) -> Real {
    let mut worst: Real = 0.0;
    for i in 0..poses.len() {
        for j in i + 1..poses.len() {
            if (poses[i].translation - poses[j].translation).length_squared() > 12.0 {
                continue;
            }
            if let Ok(Some(c)) = query::contact(cube, &poses[i], cube, &poses[j], 0.0) {
                worst = worst.min(c.distance);
            }
        }
    }
    -worst
}

fn main() {
    let layers: usize = env("LAYERS", 30);
    let cols: usize = env("COLS", 3);
    let steps: usize = env("STEPS", 300);
    let every: usize = env("EVERY", 5);
    let mut starts = Vec::new();
    let mut offset: Real = 0.0;
    for k in 0..layers {
        for i in 0..cols {
            for j in 0..cols {
                starts.push(Vec3::new(
                    offset + 3.0 * i as Real,
                    2.0 + 3.0 * k as Real,
                    offset + 3.0 * j as Real,
                ));
            }
        }
        offset -= 0.35;
    }
    let cube: Arc<Shape> = Arc::new(Cuboid::new(Vec3::ONE).unwrap().into());
    // Carom
    let mut p = PipelineParams::default();
    p.dynamics.gravity = Vec3::new(0.0, -10.0, 0.0);
    p.dynamics.sleep.enabled = false;
    p.dynamics.solver.contact_hertz = env("HZ", p.dynamics.solver.contact_hertz);
    p.dynamics.solver.substeps = env("SUB", p.dynamics.solver.substeps);
    let mut w = World::new(p).unwrap();
    let ground: Arc<Shape> = Arc::new(Cuboid::new(Vec3::new(250.0, 50.0, 250.0)).unwrap().into());
    w.add_body(&BodyDesc::fixed(
        ground,
        Isometry::from_translation(Vec3::new(0.0, -50.0, 0.0)),
    ))
    .unwrap();
    let mut handles = Vec::new();
    for s in &starts {
        let mut d = BodyDesc::dynamic(cube.clone(), Isometry::from_translation(*s), 1.0);
        d.mass = MassSpec::Mass(2.0);
        handles.push(w.add_body(&d).unwrap());
    }
    // rapier
    let mut rw = PhysicsWorld::new();
    rw.gravity = Vector::new(0.0, -10.0, 0.0);
    rw.integration_parameters.dt = 1.0 / 60.0;
    rw.integration_parameters.num_solver_iterations = env("RSUB", 5);
    rw.insert_collider(
        ColliderBuilder::cuboid(250.0, 50.0, 250.0)
            .friction(0.5)
            .translation(Vector::new(0.0, -50.0, 0.0)),
        None,
    );
    let mut rh = Vec::new();
    for s in &starts {
        let (h, _) = rw.insert(
            RigidBodyBuilder::dynamic()
                .translation(Vector::new(s.x as R, s.y as R, s.z as R))
                .can_sleep(false),
            ColliderBuilder::cuboid(1.0, 1.0, 1.0)
                .friction(0.5)
                .mass(2.0),
        );
        rh.push(h);
    }
    let (mut wc, mut wr, mut sc, mut sr, mut n) =
        (0.0 as Real, 0.0 as Real, 0.0 as Real, 0.0 as Real, 0);
    for s in 0..steps {
        w.step(1.0 / 60.0).unwrap();
        rw.step();
        if (s + 1) % every != 0 {
            continue;
        }
        let pc: Vec<Isometry> = handles
            .iter()
            .map(|&h| w.bodies().pose(h).unwrap())
            .collect();
        let pr: Vec<Isometry> = rh
            .iter()
            .map(|&h| {
                let b = &rw.bodies[h];
                let t = b.translation();
                let q = b.rotation();
                Isometry::new(
                    Vec3::new(t.x as Real, t.y as Real, t.z as Real),
                    Quat::from_xyzw(q.x as Real, q.y as Real, q.z as Real, q.w as Real),
                )
            })
            .collect();
        let (dc, dr) = (deepest(&pc, &cube), deepest(&pr, &cube));
        let mh = |v: &[Isometry]| v.iter().map(|p| p.translation.y).sum::<Real>() / v.len() as Real;
        wc = wc.max(dc);
        wr = wr.max(dr);
        sc += dc;
        sr += dr;
        n += 1;
        if (s + 1) % (every * 10) == 0 {
            println!(
                "step {:4}: deepest carom {:.3} rapier {:.3}; mean h carom {:.2} rapier {:.2}",
                s + 1,
                dc,
                dr,
                mh(&pc),
                mh(&pr)
            );
        }
    }
    println!(
        "worst carom {wc:.3} rapier {wr:.3}; mean of sampled deepest carom {:.4} rapier {:.4}",
        sc / n as Real,
        sr / n as Real
    );
}
