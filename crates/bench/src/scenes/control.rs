//! The two-thread control of `carom-bench scenes`: how much a second core speeds up work that
//! has nothing serial in it, measured on the same machine during the same run as the scenes.
//!
//! The two-thread target (1.6x over one thread) assumes a machine that gives a whole
//! second core. A shared VM often gives less, and how much less changes from minute to minute,
//! so the scenes' speed-ups are only readable next to what the machine allowed at the time.
//! The control is an embarrassingly parallel loop (a sum of sines, a few ms on one thread: no
//! allocation, no shared writes, no memory traffic), timed alternately in a one-thread and an
//! `n`-thread pool between the scenes' runs. The report prints the ratio of the median times
//! next to every scene's speed-up. Single pairs are too noisy to use: on the shared 2-core VM
//! they ranged from 0.5x to 2.6x within seconds, and so did the ratio of the best times
//! (2.1x), as the scenes' own runs do, which is why they are compared by medians too (`carom-dynamics`'s `parallel_scaling`
//! example does the same step by step for one scene, with a memory-bound control as well).

use rayon::prelude::*;
use serde::Serialize;
use std::time::Instant;

/// Pairs of timings taken at each sampling point (between two rounds of runs).
const PAIRS_PER_SAMPLE: usize = 9;

/// The control loop: a parallel sum of sines (about 5 ms on one core here).
fn workload() -> f64 {
    (0..1_000_000u32)
        .into_par_iter()
        .with_min_len(4096)
        .map(|i| (f64::from(i) * 1e-3).sin())
        .sum()
}

/// Milliseconds of one control loop in `pool`.
fn time_in(pool: &rayon::ThreadPool) -> f64 {
    let t = Instant::now();
    let s = pool.install(workload);
    std::hint::black_box(s);
    t.elapsed().as_secs_f64() * 1e3
}

/// The control's timings on one thread and on `threads` threads, gathered over a run.
#[derive(Debug, Clone, Serialize)]
pub struct Control {
    /// Threads of the parallel pool.
    pub threads: usize,
    /// Milliseconds per loop on one thread, in the order taken.
    pub one_ms: Vec<f64>,
    /// Milliseconds per loop on `threads` threads, each taken right after the matching
    /// one-thread time.
    pub many_ms: Vec<f64>,
    #[serde(skip)]
    pools: Option<[std::sync::Arc<rayon::ThreadPool>; 2]>,
}

/// Median of a non-empty slice (sorted copy).
fn median(v: &[f64]) -> f64 {
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

impl Control {
    /// A control for `threads` threads (nothing measured yet); `None` for one thread.
    pub fn new(threads: usize) -> Result<Option<Control>, String> {
        if threads < 2 {
            return Ok(None);
        }
        let pool = |n| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build()
                .map(std::sync::Arc::new)
                .map_err(|e| e.to_string())
        };
        Ok(Some(Control {
            threads,
            one_ms: Vec::new(),
            many_ms: Vec::new(),
            pools: Some([pool(1)?, pool(threads)?]),
        }))
    }

    /// Takes [`PAIRS_PER_SAMPLE`] alternating one-thread and `threads`-thread timings, after
    /// one warm-up of each.
    pub fn sample(&mut self) {
        let Some([one, many]) = &self.pools else {
            return;
        };
        time_in(one);
        time_in(many);
        for _ in 0..PAIRS_PER_SAMPLE {
            self.one_ms.push(time_in(one));
            self.many_ms.push(time_in(many));
        }
    }

    /// The speed-up of the median times (`None` before any sample).
    pub fn speedup(&self) -> Option<f64> {
        if self.one_ms.is_empty() || self.many_ms.is_empty() {
            return None;
        }
        Some(median(&self.one_ms) / median(&self.many_ms))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_thread_has_no_control_and_samples_give_finite_speedups() {
        assert!(Control::new(1).unwrap().is_none());
        let mut c = Control::new(2).unwrap().unwrap();
        assert!(c.speedup().is_none());
        c.sample();
        assert_eq!(c.one_ms.len(), PAIRS_PER_SAMPLE);
        assert_eq!(c.many_ms.len(), PAIRS_PER_SAMPLE);
        let s = c.speedup().unwrap();
        assert!(s > 0.0 && s.is_finite());
    }
}
