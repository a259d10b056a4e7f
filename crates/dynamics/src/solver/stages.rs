//! The worker/stage machinery of the parallel soft step, after Box2D v3's `solver.c`
//! (`b2SolverStage`, `b2SolverBlock`, `b2ExecuteMainStage`, `b2SolverTask`, the atomic
//! `syncBits` and `completionCount` and the spin-wait between stages).
//!
//! A step's work is a precomputed list of [`Stage`]s (integrate velocities, warm start
//! colour k, solve colour k, integrate positions, relax colour k, …), each cut into a fixed
//! number of blocks whose work items do not conflict (the constraints of one colour share no
//! dynamic body; bodies are integrated one by one). [`StageList::run`] enters one parallel
//! region for the whole list: every participating thread (the caller included) walks the
//! stages in order, claims blocks of the current stage with an atomic counter, counts the
//! blocks it finished, and waits for the stage's last block with a spin loop (then
//! `yield_now`) before moving on. There is one fork and one join per step instead of one per
//! colour and pass.
//!
//! Differences from Box2D: the stage does not wait for a fixed set of workers. Whoever
//! finds every block of the current stage finished advances the stage index (one
//! compare-and-swap), and a thread that joins late simply starts at the current stage, so no
//! thread ever waits for a thread that has not started (or is busy elsewhere in the pool):
//! with one thread, or when the other workers never arrive, the caller runs every block
//! itself. Threads are forked with `rayon::join` (no allocation, unlike `rayon::scope` or
//! `rayon::broadcast`).
//!
//! Which blocks a thread takes (Box2D's `b2GetWorkerStartIndex` and `b2ExecuteStage`):
//! worker `w` of `n` starts at block `w·blocks/n` of every stage and claims blocks forward
//! (each block has its own claim flag) until it meets a claimed one, then backward from
//! its start until it meets a claimed one. So on two threads worker 0 takes the first half
//! of every colour and body range and worker 1 the second, pass after pass, and the
//! constraints and bodies a core wrote in one stage are mostly the ones it reads in the
//! next (they stay in its own cache); a worker that finishes early steals from the far end
//! of another's range. Every block is still claimed exactly once (a forward sweep only stops
//! at a claimed block, and the backward sweeps close any gap behind a start).
//!
//! Determinism: the block boundaries are fixed when the list is built and never depend on
//! the thread count, and blocks of one stage write disjoint data, so which thread runs a block
//! cannot change a bit of the result.

use std::sync::atomic::{AtomicBool, AtomicU32, AtomicU64, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// Spins before a waiting thread starts yielding its core (Box2D spins, then yields).
const SPINS_BEFORE_YIELD: u32 = 2000;

/// One stage: `blocks` blocks of work of kind `kind`, with the counters of the threads
/// working on it (Box2D's `b2SolverStage`).
#[derive(Debug)]
pub(crate) struct Stage<K> {
    /// What the stage does (the executor's argument).
    pub kind: K,
    /// Number of blocks (at least one).
    pub blocks: u32,
    /// Index of the stage's first claim flag in [`StageList`]'s `claims`.
    first: usize,
    /// Blocks finished.
    done: AtomicU32,
    /// When the stage was found finished, in nanoseconds since the region began.
    end_ns: AtomicU64,
}

impl<K: Clone> Clone for Stage<K> {
    fn clone(&self) -> Self {
        Stage::new(self.kind.clone(), self.blocks, self.first)
    }
}

impl<K> Stage<K> {
    fn new(kind: K, blocks: u32, first: usize) -> Self {
        Stage {
            kind,
            blocks,
            first,
            done: AtomicU32::new(0),
            end_ns: AtomicU64::new(0),
        }
    }

    fn finished(&self) -> bool {
        self.done.load(Ordering::Acquire) >= self.blocks
    }
}

/// A list of stages, reused from step to step (cleared, not freed).
#[derive(Debug)]
pub(crate) struct StageList<K> {
    stages: Vec<Stage<K>>,
    /// Index of the stage being worked on (Box2D's `atomicSyncBits`).
    current: AtomicUsize,
    /// Set when a block panicked: every thread leaves the region so the panic can propagate.
    abort: AtomicBool,
    /// One claim flag per block of every stage (Box2D's `b2SolverBlock::syncIndex`): set by
    /// the thread that runs the block, cleared at the start of each run.
    claims: Vec<AtomicBool>,
}

impl<K> Default for StageList<K> {
    fn default() -> Self {
        StageList {
            stages: Vec::new(),
            current: AtomicUsize::new(0),
            abort: AtomicBool::new(false),
            claims: Vec::new(),
        }
    }
}

impl<K: Clone> Clone for StageList<K> {
    fn clone(&self) -> Self {
        StageList {
            stages: self.stages.clone(),
            claims: self.claims.iter().map(|_| AtomicBool::new(false)).collect(),
            ..Default::default()
        }
    }
}

/// Sets the list's abort flag if a block unwinds (the other threads stop waiting).
struct AbortOnUnwind<'a>(&'a AtomicBool);

impl Drop for AbortOnUnwind<'_> {
    fn drop(&mut self) {
        if std::thread::panicking() {
            self.0.store(true, Ordering::Release);
        }
    }
}

impl<K: Copy + Send + Sync> StageList<K> {
    /// Empties the list (keeps its buffer).
    pub fn clear(&mut self) {
        self.stages.clear();
        self.claims.clear();
    }

    /// Appends a stage of `blocks` blocks; a stage without blocks is left out.
    pub fn push(&mut self, kind: K, blocks: usize) {
        if blocks > 0 {
            let blocks = u32::try_from(blocks).unwrap_or(u32::MAX);
            let first = self.claims.len();
            self.claims
                .extend((0..blocks).map(|_| AtomicBool::new(false)));
            self.stages.push(Stage::new(kind, blocks, first));
        }
    }

    /// The stages, in order.
    #[cfg(test)]
    pub fn stages(&self) -> &[Stage<K>] {
        &self.stages
    }

    /// Runs every block of every stage, stage after stage: `exec(kind, block, blocks)` for blocks
    /// `0..blocks` of each stage. With `threads > 1` (and the `parallel` feature), up to
    /// `threads` threads of the current rayon pool take part (see the module docs); the
    /// blocks of one stage may then run at the same time on different threads, so `exec`
    /// must only be given stages whose blocks do not conflict. Every stage's end time is
    /// recorded ([`StageList::durations`]). No allocation.
    pub fn run<F>(&mut self, threads: usize, exec: F)
    where
        F: Fn(K, usize, usize) + Sync,
    {
        for c in &mut self.claims {
            *c.get_mut() = false;
        }
        for s in &mut self.stages {
            *s.done.get_mut() = 0;
            *s.end_ns.get_mut() = 0;
        }
        *self.current.get_mut() = 0;
        *self.abort.get_mut() = false;
        let base = Instant::now();
        if threads <= 1 || self.stages.is_empty() || !cfg!(feature = "parallel") {
            for s in &self.stages {
                if s.blocks == 1 {
                    single_block(&exec, s.kind);
                } else {
                    for b in 0..s.blocks {
                        exec(s.kind, b as usize, s.blocks as usize);
                    }
                }
                s.end_ns.store(nanos_since(base), Ordering::Relaxed);
            }
            return;
        }
        let this = &*self;
        fan_out(threads, 0, &|worker| {
            this.work(&exec, base, worker, threads)
        });
    }

    /// The wall time of each stage of the last [`StageList::run`] (from the end of the
    /// previous stage, or the start of the run, to the moment its last block was seen
    /// finished).
    pub fn durations(&self) -> impl Iterator<Item = (K, Duration)> + '_ {
        let mut last = 0;
        self.stages.iter().map(move |s| {
            let end = s.end_ns.load(Ordering::Relaxed).max(last);
            let d = Duration::from_nanos(end - last);
            last = end;
            (s.kind, d)
        })
    }

    /// Claims block `b` of `stage` and runs it; false when another thread had claimed it.
    #[inline]
    fn try_run<F>(&self, stage: &Stage<K>, b: u32, exec: &F) -> bool
    where
        F: Fn(K, usize, usize) + Sync,
    {
        if self.claims[stage.first + b as usize].swap(true, Ordering::AcqRel) {
            return false;
        }
        exec(stage.kind, b as usize, stage.blocks as usize);
        // Release: whoever sees the last count sees every block's writes.
        stage.done.fetch_add(1, Ordering::AcqRel);
        true
    }

    /// One thread's walk through the stages (Box2D's `b2SolverTask` and
    /// `b2ExecuteMainStage` in one: every thread may advance the stage), as worker `worker`
    /// of `workers` (which fixes its start block in every stage, see the module docs).
    fn work<F>(&self, exec: &F, base: Instant, worker: usize, workers: usize)
    where
        F: Fn(K, usize, usize) + Sync,
    {
        let n = self.stages.len();
        let _guard = AbortOnUnwind(&self.abort);
        loop {
            let s = self.current.load(Ordering::Acquire);
            if s >= n || self.abort.load(Ordering::Acquire) {
                return;
            }
            let stage = &self.stages[s];
            let blocks = stage.blocks;
            let start = worker_start(worker, workers, blocks);
            // Forward from the start while the blocks are free, then backward from it.
            let mut b = start;
            while self.try_run(stage, b, exec) {
                b = if b + 1 == blocks { 0 } else { b + 1 };
            }
            let mut b = start;
            loop {
                b = if b == 0 { blocks - 1 } else { b - 1 };
                if !self.try_run(stage, b, exec) {
                    break;
                }
            }
            wait_until(|| {
                stage.finished()
                    || self.current.load(Ordering::Acquire) != s
                    || self.abort.load(Ordering::Acquire)
            });
            if stage.finished()
                && self
                    .current
                    .compare_exchange(s, s + 1, Ordering::AcqRel, Ordering::Acquire)
                    .is_ok()
            {
                stage.end_ns.store(nanos_since(base), Ordering::Relaxed);
            }
        }
    }
}

/// Runs the only block of a one-block stage (on one thread). Not inlined, so that a profile
/// of a one-thread step (callgrind) shows apart the work that a one-block stage leaves to a
/// single thread however many take part: part of the step's serial share.
#[inline(never)]
fn single_block<K, F: Fn(K, usize, usize)>(exec: &F, kind: K) {
    exec(kind, 0, 1);
}

/// The first block worker `worker` of `workers` tries in a stage of `blocks` blocks
/// (Box2D's `b2GetWorkerStartIndex`): the workers' starts are spread evenly, so each one
/// takes the same share of every stage.
fn worker_start(worker: usize, workers: usize, blocks: u32) -> u32 {
    let workers = workers.max(1) as u64;
    let w = (worker as u64).min(workers - 1);
    (w * u64::from(blocks) / workers) as u32
}

fn nanos_since(base: Instant) -> u64 {
    u64::try_from(base.elapsed().as_nanos()).unwrap_or(u64::MAX)
}

/// Spins until `done()` holds, then yields the core between checks.
#[inline]
fn wait_until(done: impl Fn() -> bool) {
    let mut spins = 0u32;
    while !done() {
        if spins < SPINS_BEFORE_YIELD {
            std::hint::spin_loop();
            spins += 1;
        } else {
            std::thread::yield_now();
        }
    }
}

/// Runs `f(worker)` on up to `threads` threads of the current rayon pool (the caller is
/// one of them, worker `first`; the others are `first + 1 ..`), forking with `rayon::join`
/// in a binary tree.
#[cfg(feature = "parallel")]
fn fan_out(threads: usize, first: usize, f: &(dyn Fn(usize) + Sync)) {
    if threads <= 1 {
        f(first);
    } else {
        let right = threads / 2;
        let left = threads - right;
        rayon::join(
            || fan_out(left, first, f),
            || fan_out(right, first + left, f),
        );
    }
}

#[cfg(not(feature = "parallel"))]
fn fan_out(_: usize, first: usize, f: &(dyn Fn(usize) + Sync)) {
    f(first);
}

/// Threads the solver may use: the current rayon pool's when `parallel` (and the
/// `parallel` feature is on), else one.
pub(crate) fn thread_count(parallel: bool) -> usize {
    #[cfg(feature = "parallel")]
    if parallel {
        return rayon::current_num_threads();
    }
    let _ = parallel;
    1
}

/// Number of blocks of at most `block` items that `len` items need. Depends only on `len` and
/// `block`.
pub(crate) fn block_count(len: usize, block: usize) -> usize {
    len.div_ceil(block.max(1))
}

/// Items of block `b` when `len` items are cut into `blocks` blocks of nearly equal size
/// (`len·b/blocks ..`). Depends only on `len` and `blocks`; the blocks cover `0..len` in
/// order without overlap.
pub(crate) fn block_range(len: usize, blocks: usize, b: usize) -> std::ops::Range<usize> {
    let blocks = blocks.max(1);
    let at = |k: usize| (len as u128 * k.min(blocks) as u128 / blocks as u128) as usize;
    at(b)..at(b + 1)
}

#[cfg(test)]
#[path = "stages_tests.rs"]
mod tests;
