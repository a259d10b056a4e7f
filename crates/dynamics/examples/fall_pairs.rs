//! What the narrowphase does with the broadphase pairs of one scene (sleeping off): every
//! `every` steps, the pairs split by outcome (points / apart / neither), how many reused their
//! previous result (the apart certificate still held, or the manifold was coherent) and how
//! many ran contact generation, and how many pairs' tight boxes (shape boxes without the
//! speculative margins) overlap.
//!
//! `cargo run --release -p carom-dynamics --example fall_pairs -- [scene 1–8] [steps] [every]`
//!
//! With `every` 0 it only steps (for instruction counts); `CAROM_BROADPHASE=<method>` picks
//! the broadphase (`tree`, `sap`, `sort_sweep`, `grid`, ...), `CAROM_PREDICTION=<m>` the
//! base speculative distance (`manifold.prediction`, 0.02 by default).

use carom_collision::math::{Isometry, Vec3};
use carom_collision::world::ObjectHandle;
use carom_dynamics::{PipelineParams, World};
use std::collections::HashMap;

type Key = (ObjectHandle, ObjectHandle);

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let number: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(1);
    let steps: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(300);
    let every: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(25);
    let scene = carom_scenes::bullet::scene(number).ok_or("scene number must be 1–8")?;
    let mut params = PipelineParams::default();
    params.dynamics.sleep.enabled = false;
    if let Ok(m) = std::env::var("CAROM_BROADPHASE") {
        params.broadphase = m.parse()?;
    }
    if let Ok(p) = std::env::var("CAROM_PREDICTION") {
        params.manifold.prediction = p.parse()?;
    }
    let mut world = World::from_scene_with(&scene, params)?;
    println!(
        "step | pairs | points: kept regen | apart: kept regen | none | new | tight-overlap (of apart) | tight+pred overlap (of apart)"
    );
    let mut totals = [0usize; 7];
    if every == 0 {
        let mut bp = std::time::Duration::ZERO;
        for _ in 0..steps {
            bp += world.step(scene.dt)?.timings.broadphase;
        }
        println!(
            "broadphase {:.3} ms/step",
            bp.as_secs_f64() * 1e3 / steps as f64
        );
        return Ok(());
    }
    for step in 1..=steps {
        // Before the step: each pair's certificate pose and generation pose.
        let before: HashMap<Key, (Option<Isometry>, Option<Isometry>)> = world
            .collision()
            .narrowphase()
            .pairs()
            .map(|p| {
                (
                    (p.a, p.b),
                    (p.manifold.apart.map(|s| s.pose_ab), p.manifold.generated_at),
                )
            })
            .collect();
        world.step(scene.dt)?;
        let c = world.collision();
        let mut n = [0usize; 9];
        for p in c.narrowphase().pairs() {
            let old = before.get(&(p.a, p.b));
            let m = &p.manifold;
            let slot = match (old, m.apart) {
                (None, _) => 5,
                (Some(&(_, gen)), _) if !m.is_empty() => {
                    if m.generated_at.is_some() && m.generated_at == gen {
                        0
                    } else {
                        1
                    }
                }
                (Some(&(cert, _)), Some(s)) => {
                    if Some(s.pose_ab) == cert {
                        2
                    } else {
                        3
                    }
                }
                (Some(_), None) => 4,
            };
            n[slot] += 1;
            if m.is_empty() {
                let (oa, ob) = (c.get(p.a)?, c.get(p.b)?);
                let (ba, bb) = (oa.shape.aabb(&oa.pose), ob.shape.aabb(&ob.pose));
                if ba.intersects(&bb) {
                    n[6] += 1;
                }
                let own = |o: &carom_collision::world::CollisionObject| {
                    (o.margin - o.motion.length()).max(0.0)
                };
                let pred = (own(oa) + own(ob) + (oa.motion - ob.motion).length()).max(0.02);
                let e = Vec3::splat(pred);
                let ba = carom_collision::math::Aabb::new(ba.min - e, ba.max + e);
                if ba.intersects(&bb) {
                    n[7] += 1;
                }
            }
        }
        for k in 0..6 {
            totals[k] += n[k];
        }
        totals[6] += n[6];
        if step % every == 0 {
            let total: usize = n[..6].iter().sum();
            println!(
                "{step:4} | {total:6} | {:6} {:6} | {:6} {:6} | {:5} | {:5} | {:6} | {:6}",
                n[0], n[1], n[2], n[3], n[4], n[5], n[6], n[7]
            );
        }
    }
    println!(
        "all steps: points kept {} regen {} | apart kept {} regen {} | none {} | new {}",
        totals[0], totals[1], totals[2], totals[3], totals[4], totals[5]
    );
    Ok(())
}
