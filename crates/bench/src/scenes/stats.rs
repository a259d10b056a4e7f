//! Summaries of repeated runs ([`Summary`]): ms/step median and min–max over runs (each run's
//! mean), the mean over the first 200 steps (Bullet's own harness metric), the settled-phase
//! median (steps 300–600), the mean stage split per step, and the ray batch's median.

use super::record::RunRecord;
use super::sanity::Sanity;
use serde::Serialize;

/// Steps averaged by Bullet's console harness.
pub const FIRST_STEPS: usize = 200;
/// First step of the settled phase.
pub const SETTLED_FROM: usize = 300;

/// Median of a slice (mean of the two middle values for even lengths); NaN when empty.
pub fn median(xs: &[f64]) -> f64 {
    if xs.is_empty() {
        return f64::NAN;
    }
    let mut v = xs.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn mean(xs: &[f64]) -> f64 {
    if xs.is_empty() {
        f64::NAN
    } else {
        xs.iter().sum::<f64>() / xs.len() as f64
    }
}

/// The summary of the runs of one (scene, engine, threads, sleeping) configuration.
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    /// Scene name.
    pub scene: String,
    /// Engine name.
    pub engine: String,
    /// Worker threads.
    pub threads: usize,
    /// Sleeping on or off.
    pub sleeping: bool,
    /// Runs summarised.
    pub runs: usize,
    /// Steps per run.
    pub steps: usize,
    /// Median over runs of the mean frame time (step + rays), ms.
    pub ms_median: f64,
    /// Smallest run mean, ms.
    pub ms_min: f64,
    /// Largest run mean, ms.
    pub ms_max: f64,
    /// Median over runs of the mean over the first 200 steps, ms.
    pub first200_mean: f64,
    /// Median over runs of the median of steps 300–600, ms (NaN for shorter runs).
    pub settled_median: f64,
    /// Mean stage split per step (median run), ms; `None` where the engine has no timer.
    pub broadphase_ms: Option<f64>,
    /// Midphase + narrowphase, ms per step.
    pub narrowphase_ms: Option<f64>,
    /// Solver, ms per step.
    pub solver_ms: Option<f64>,
    /// Integration, ms per step.
    pub integration_ms: Option<f64>,
    /// Median over all runs and steps of the ray batch time, ms (`None` without rays).
    pub rays_ms: Option<f64>,
    /// Rays hit in the last batch of the last run.
    pub ray_hits: usize,
    /// Sanity figures of the last run.
    pub sanity: Sanity,
}

/// Summarises runs of one configuration (all records must share scene, engine, threads and
/// sleeping; at least one record).
pub fn summarize(records: &[RunRecord]) -> Summary {
    let first = &records[0];
    let frames: Vec<Vec<f64>> = records.iter().map(RunRecord::frame_ms).collect();
    let means: Vec<f64> = frames.iter().map(|f| mean(f)).collect();
    let per_run =
        |f: &dyn Fn(&[f64]) -> f64| median(&frames.iter().map(|x| f(x)).collect::<Vec<_>>());
    let first200 = per_run(&|x| mean(&x[..x.len().min(FIRST_STEPS)]));
    let settled = per_run(&|x| {
        if x.len() > SETTLED_FROM {
            median(&x[SETTLED_FROM..])
        } else {
            f64::NAN
        }
    });
    // Stage split of the run whose mean is the median (or closest to it).
    let m = median(&means);
    let pick = (0..records.len())
        .min_by(|&a, &b| (means[a] - m).abs().total_cmp(&(means[b] - m).abs()))
        .unwrap_or(0);
    let steps = first.step_ms.len().max(1);
    let stages = records[pick].stages.scaled(1.0 / steps as f64);
    let rays: Vec<f64> = records
        .iter()
        .flat_map(|r| r.ray_ms.iter().copied())
        .collect();
    let last = &records[records.len() - 1];
    Summary {
        scene: first.scene.clone(),
        engine: first.engine.clone(),
        threads: first.threads,
        sleeping: first.sleeping,
        runs: records.len(),
        steps: first.step_ms.len(),
        ms_median: m,
        ms_min: means.iter().copied().fold(f64::INFINITY, f64::min),
        ms_max: means.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        first200_mean: first200,
        settled_median: settled,
        broadphase_ms: stages.broadphase,
        narrowphase_ms: stages.narrowphase,
        solver_ms: stages.solver,
        integration_ms: stages.integration,
        rays_ms: (!rays.is_empty()).then(|| median(&rays)),
        ray_hits: last.hits,
        sanity: last.sanity,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenes::engine::StageTimes;
    use crate::scenes::sanity::Sanity;

    fn rec(step: Vec<f64>) -> RunRecord {
        RunRecord {
            scene: "s".into(),
            engine: "e".into(),
            threads: 1,
            sleeping: false,
            step_ms: step,
            ray_ms: vec![],
            stages: StageTimes::default(),
            hits: 0,
            sanity: Sanity::default(),
        }
    }

    #[test]
    fn summary_matches_brute_force() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), 2.5);
        // Run k: 200 steps of 2k ms, then 400 steps of k ms.
        let runs: Vec<RunRecord> = (1..=3)
            .map(|k| {
                let k = k as f64;
                let mut v = vec![2.0 * k; 200];
                v.extend(vec![k; 400]);
                rec(v)
            })
            .collect();
        let s = summarize(&runs);
        let run_mean = |k: f64| (200.0 * 2.0 * k + 400.0 * k) / 600.0;
        assert!((s.ms_median - run_mean(2.0)).abs() < 1e-12);
        assert!((s.ms_min - run_mean(1.0)).abs() < 1e-12);
        assert!((s.ms_max - run_mean(3.0)).abs() < 1e-12);
        assert!((s.first200_mean - 4.0).abs() < 1e-12);
        assert!((s.settled_median - 2.0).abs() < 1e-12);
        assert!(s.rays_ms.is_none() && s.broadphase_ms.is_none());
    }
}
