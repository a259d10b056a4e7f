//! One timed run of one scene by one engine ([`RunRecord`]), and the loop that produces it for
//! the in-process engines: build (not timed), then per step time the step and, for the ray
//! scene, the ray batch separately (Bullet's "raytests" bar times its rays apart from the step).

use super::engine::{initial_states, EngineBuilder, EngineConfig, StageTimes};
use super::sanity::{sanity, Sanity};
use carom_scenes::Scene;
use std::time::Instant;

/// Timings and sanity of one run.
#[derive(Debug, Clone)]
pub struct RunRecord {
    /// Scene name.
    pub scene: String,
    /// Engine name.
    pub engine: String,
    /// Worker threads used.
    pub threads: usize,
    /// Sleeping on or off.
    pub sleeping: bool,
    /// Wall time of each step, ms (the physics step only).
    pub step_ms: Vec<f64>,
    /// Wall time of the ray batch after each step, ms (empty for scenes without rays).
    pub ray_ms: Vec<f64>,
    /// Stage times summed over all steps, ms.
    pub stages: StageTimes,
    /// Rays that hit something in the last batch.
    pub hits: usize,
    /// Sanity figures after the last step.
    pub sanity: Sanity,
}

impl RunRecord {
    /// Frame time per step: the step plus the rays cast after it.
    pub fn frame_ms(&self) -> Vec<f64> {
        self.step_ms
            .iter()
            .enumerate()
            .map(|(i, s)| s + self.ray_ms.get(i).copied().unwrap_or(0.0))
            .collect()
    }
}

/// Builds `scene` with `build` and runs it for `steps` steps, calling `tick` after each step.
pub fn run_in_process(
    scene: &Scene,
    build: EngineBuilder,
    config: EngineConfig,
    steps: usize,
    tick: &mut dyn FnMut(),
) -> Result<RunRecord, String> {
    let mut engine = build(scene, config)?;
    let mut step_ms = Vec::with_capacity(steps);
    let mut ray_ms = Vec::new();
    let mut stages = StageTimes::default();
    let mut hits = 0;
    for _ in 0..steps {
        let t0 = Instant::now();
        let st = engine.step();
        step_ms.push(t0.elapsed().as_secs_f64() * 1e3);
        stages.accumulate(&st);
        if !scene.rays.is_empty() {
            let t1 = Instant::now();
            hits = engine.cast_rays();
            ray_ms.push(t1.elapsed().as_secs_f64() * 1e3);
        }
        tick();
    }
    let last = engine.bodies();
    Ok(RunRecord {
        scene: scene.name.to_string(),
        engine: engine.name().to_string(),
        threads: config.threads,
        sleeping: config.sleeping,
        step_ms,
        ray_ms,
        stages,
        hits,
        sanity: sanity(scene, &initial_states(scene), &last),
    })
}
