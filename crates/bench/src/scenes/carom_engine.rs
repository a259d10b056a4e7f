//! The Carom engine of `carom-bench scenes`: `carom_dynamics::World::from_scene_with` (the
//! scene's bodies, joints, gravity and iterations), stepped with `World::step(dt)`; its
//! `PipelineTimings` give the stage split (broadphase = sync + broadphase; mid+narrow =
//! narrowphase + contact adaptation; solver = solver + islands; integration = integrate).
//! Sleeping follows the config; threads run the step inside a rayon pool of that size.
//!
//! Environment switches for measurements: `CAROM_SOLVER_SIMD=off` (scalar contact solve),
//! `CAROM_BROADPHASE=<method>` (broadphase other than the default two-tree one) and
//! `CAROM_PARALLEL_MIN_BATCH=<n>` (smallest colour solved in parallel).
//!
//! Rays: each batch builds the world's query structure (`World::query`: a BVH over the
//! bodies' current boxes, counted in the ray time) and casts every ray closest-first through
//! it; the batch runs in chunks of 20 rays on the pool (Bullet's `btParallelFor` grain).

use super::engine::{BodyState, Engine, EngineConfig, StageTimes};
use carom_collision::math::{Real, Vec3};
use carom_dynamics::{BodyHandle, PipelineParams, World};
use carom_scenes::Scene;
use rayon::prelude::*;

const RAY_GRAIN: usize = 20;

/// Carom's world for one scene.
pub struct CaromEngine {
    world: World,
    dynamic: Vec<BodyHandle>,
    dt: Real,
    rays: Vec<(Vec3, Vec3)>,
    pool: rayon::ThreadPool,
}

/// Builds `scene` in Carom.
pub fn build(scene: &Scene, config: EngineConfig) -> Result<Box<dyn Engine>, String> {
    let mut params = PipelineParams::default();
    params.dynamics.sleep.enabled = config.sleeping;
    params.dynamics.parallel = config.threads > 1;
    // `CAROM_SOLVER_SIMD=off` selects the scalar contact solve (to measure the SIMD one).
    params.dynamics.solver.simd = std::env::var("CAROM_SOLVER_SIMD").map_or(true, |v| v != "off");
    // `CAROM_BROADPHASE=<method>` selects another broadphase method (to compare them).
    if let Ok(name) = std::env::var("CAROM_BROADPHASE") {
        params.broadphase = name
            .parse()
            .map_err(|e: carom_collision::CaromError| e.to_string())?;
    }
    // `CAROM_PARALLEL_MIN_BATCH=n` sets the smallest colour solved in parallel (to measure it).
    if let Some(n) = std::env::var("CAROM_PARALLEL_MIN_BATCH")
        .ok()
        .and_then(|v| v.parse().ok())
    {
        params.dynamics.solver.parallel_min_batch = n;
    }
    let world = World::from_scene_with(scene, params).map_err(|e| e.to_string())?;
    let handles = world.handles();
    let dynamic = scene
        .bodies
        .iter()
        .zip(&handles)
        .filter(|(b, _)| !b.is_static())
        .map(|(_, &h)| h)
        .collect();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(config.threads.max(1))
        .build()
        .map_err(|e| e.to_string())?;
    Ok(Box::new(CaromEngine {
        world,
        dynamic,
        dt: scene.dt,
        rays: scene.rays.clone(),
        pool,
    }))
}

fn ms(d: std::time::Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

impl Engine for CaromEngine {
    fn name(&self) -> &'static str {
        "carom"
    }

    fn step(&mut self) -> StageTimes {
        let (world, dt) = (&mut self.world, self.dt);
        let t = self.pool.install(|| {
            world
                .step(dt)
                .map(|r| r.timings)
                .expect("a valid scene steps without error")
        });
        StageTimes {
            // The query tree's refresh is the broadphase tree upkeep the peers' ray casts rely on.
            broadphase: Some(ms(t.sync) + ms(t.broadphase) + ms(t.query_tree)),
            narrowphase: Some(ms(t.narrowphase) + ms(t.contacts)),
            solver: Some(ms(t.solver) + ms(t.islands)),
            integration: Some(ms(t.integrate)),
        }
    }

    fn cast_rays(&mut self) -> usize {
        if self.rays.is_empty() {
            return 0;
        }
        let Ok(query) = self.world.query() else {
            return 0;
        };
        let cast = |&(from, to): &(Vec3, Vec3)| {
            let d = to - from;
            let len = d.length();
            matches!(query.raycast(from, d, len, u32::MAX), Ok(Some(_)))
        };
        if self.pool.current_num_threads() == 1 {
            return self.rays.iter().filter(|r| cast(r)).count();
        }
        let rays = &self.rays;
        self.pool.install(|| {
            rays.par_chunks(RAY_GRAIN)
                .map(|c| c.iter().filter(|r| cast(r)).count())
                .sum()
        })
    }

    fn bodies(&self) -> Vec<BodyState> {
        let set = self.world.bodies();
        self.dynamic
            .iter()
            .map(|&h| {
                let p = set.pose(h).map(|p| p.translation).unwrap_or(Vec3::NAN);
                let v = set.linear_velocity(h).unwrap_or(Vec3::NAN);
                BodyState {
                    position: [p.x as f64, p.y as f64, p.z as f64],
                    velocity: [v.x as f64, v.y as f64, v.z as f64],
                }
            })
            .collect()
    }
}
