//! The parallel candidate search of [`TreeBroadPhase`]: the incremental search over many
//! moved proxies cut into chunks, and the full search's descents cut into node-pair tasks
//! (Box2D v3's `b2UpdateBroadPhasePairs` splits its move buffer the same way). Each chunk or
//! task writes into its own reused buffers, appended in a fixed order, so the keys do not
//! depend on the thread count.

use super::pair_key;
use super::tree_broadphase::{PairView, MOVING, RESTING};
use super::TreeBroadPhase;

impl TreeBroadPhase {
    /// The incremental candidate search over many moved proxies: `moved` (ascending) is cut
    /// into chunks of [`MOVED_CHUNK`] (bounds that depend only on the count), each queried
    /// into its own reused buffer, in parallel with the `parallel` feature; the buffers are
    /// appended to `out` in chunk order, so `out` holds the keys of the serial loop in the
    /// serial order. (Box2D v3 splits its move buffer into tasks the same way,
    /// `b2UpdateBroadPhasePairs`.)
    pub(super) fn query_moved_chunked(&mut self, moved: &[u32], out: &mut Vec<u64>) {
        let chunks = moved.len().div_ceil(MOVED_CHUNK);
        let mut parts = std::mem::take(&mut self.parts);
        if parts.len() < chunks {
            parts.resize_with(chunks, Part::default);
        }
        let cap = self.part_capacity;
        let this = &*self;
        let run = |c: usize, part: &mut Part| {
            part.prepare(cap);
            let lo = c * MOVED_CHUNK;
            let hi = (lo + MOVED_CHUNK).min(moved.len());
            for &m in &moved[lo..hi] {
                this.query_moved(m, MOVING, &mut part.stack, &mut part.keys);
                this.query_moved(m, RESTING, &mut part.stack, &mut part.keys);
            }
        };
        self.part_capacity = Part::run_all(&mut parts[..chunks], cap, run, out);
        self.parts = parts;
    }

    /// The full candidate search's descents (self-pairs of the moving tree, moving ×
    /// resting), split at the top levels of the trees into a fixed list of node-pair tasks
    /// ([`DynamicTree::self_pair_tasks`], [`DynamicTree::tree_pair_tasks`]: the list depends
    /// only on the trees), run in parallel with the `parallel` feature, each into its own
    /// reused buffer; the buffers are appended to `out` in task order. The keys are sorted
    /// afterwards, so the candidates do not depend on the thread count.
    pub(super) fn descend_split(&mut self, out: &mut Vec<u64>) {
        let mut tasks = std::mem::take(&mut self.tasks);
        let mut scratch = std::mem::take(&mut self.task_scratch);
        let mut parts = std::mem::take(&mut self.parts);
        tasks.reserve(5 * DESCENT_TASKS);
        scratch.reserve(3 * DESCENT_TASKS);
        self.cross_tasks.reserve(2 * DESCENT_TASKS);
        let [moving, resting] = &self.trees;
        moving.self_pair_tasks(DESCENT_TASKS, &mut tasks, &mut scratch);
        let self_tasks = tasks.len();
        // The moving × resting tasks follow the self-pair tasks in the same list.
        scratch.clear();
        let cross = &mut self.cross_tasks;
        moving.tree_pair_tasks(resting, DESCENT_TASKS, cross, &mut scratch);
        tasks.extend_from_slice(cross);
        let n = tasks.len();
        // At most 3 (self) and 2 (cross) node pairs per task of the last round, which
        // started below DESCENT_TASKS: so the lists stop growing at once.
        if parts.len() < 5 * DESCENT_TASKS {
            parts.resize_with(5 * DESCENT_TASKS, Part::default);
        }
        if parts.len() < n {
            parts.resize_with(n, Part::default);
        }
        let cap = self.part_capacity;
        let run = |t: usize, part: &mut Part| {
            part.prepare(cap);
            let keys = &mut part.keys;
            if t < self_tasks {
                moving.self_pairs_from(tasks[t], &mut part.pair_stack, |a, b| {
                    keys.push(pair_key(a, b))
                });
            } else {
                moving.query_tree_from(resting, tasks[t], &mut part.pair_stack, |a, b| {
                    keys.push(pair_key(a, b))
                });
            }
        };
        self.part_capacity = Part::run_all(&mut parts[..n], cap, run, out);
        self.tasks = tasks;
        self.task_scratch = scratch;
        self.parts = parts;
    }
}

/// Moved proxies per chunk of the parallel incremental search; the chunked path is taken
/// from two chunks up (fewer moved proxies do not pay a fork).
pub(super) const MOVED_CHUNK: usize = 64;

/// The full search is split into parallel tasks from this many leaves of the moving tree.
pub(super) const PARALLEL_MIN_LEAVES: usize = 512;

/// The split descents are cut into at least this many node-pair tasks each (when the trees
/// are deep enough).
const DESCENT_TASKS: usize = 32;

/// One task's or chunk's reused buffers in the parallel candidate search.
#[derive(Debug, Clone, Default)]
pub(super) struct Part {
    keys: Vec<u64>,
    stack: Vec<u32>,
    pair_stack: Vec<(u32, u32)>,
}

impl Part {
    /// Runs `run(i, part)` for every part (one rayon task each with the `parallel`
    /// feature), appends the parts' keys to `out` in part order, and returns the buffer
    /// capacities to ask of the next search (see [`Part::capacities`]).
    fn run_all<F>(parts: &mut [Part], cap: [usize; 3], run: F, out: &mut Vec<u64>) -> [usize; 3]
    where
        F: Fn(usize, &mut Part) + Sync + Send,
    {
        #[cfg(feature = "parallel")]
        {
            use rayon::prelude::*;
            parts
                .par_iter_mut()
                .enumerate()
                .with_max_len(1)
                .for_each(|(i, part)| run(i, part));
        }
        #[cfg(not(feature = "parallel"))]
        for (i, part) in parts.iter_mut().enumerate() {
            run(i, part);
        }
        for p in parts.iter() {
            out.extend_from_slice(&p.keys);
        }
        Part::capacities(parts, cap)
    }

    /// Clears the keys and grows every buffer to the capacities `cap` (keys, stack, pair
    /// stack) if it has less.
    fn prepare(&mut self, cap: [usize; 3]) {
        self.keys.clear();
        self.stack.clear();
        self.pair_stack.clear();
        self.keys.reserve(cap[0]);
        self.stack.reserve(cap[1]);
        self.pair_stack.reserve(cap[2]);
    }

    /// The largest capacities among `parts` and `cap`.
    fn capacities(parts: &[Part], cap: [usize; 3]) -> [usize; 3] {
        parts.iter().fold(cap, |c, p| {
            [
                c[0].max(p.keys.capacity()),
                c[1].max(p.stack.capacity()),
                c[2].max(p.pair_stack.capacity()),
            ]
        })
    }
}

/// Surviving candidates per chunk of the parallel candidate merge; the merge is split from
/// two chunks up.
#[cfg(feature = "parallel")]
const MERGE_CHUNK: usize = 2048;

/// One chunk's reused buffers in the parallel candidate merge.
#[derive(Debug, Clone, Default)]
#[cfg_attr(not(feature = "parallel"), allow(dead_code))]
pub(super) struct MergePart {
    next: Vec<u64>,
    exact: Vec<u64>,
}

/// Merges the sorted surviving candidates `old` with the sorted, deduplicated new candidates
/// `new` into `next`, dropping a surviving candidate that is not
/// [`PairView::unchanged`] and not found again, and pushes the candidates whose exact boxes
/// overlap and whose filters accept to `exact` ([`PairView::emit`]); both outputs sorted.
///
/// From two chunks of `MERGE_CHUNK` (2048) surviving candidates up and on more than one thread
/// (with the `parallel` feature), `old` is cut at fixed
/// positions and `new` at the first key of each chunk (a binary search), so each chunk
/// holds every key of its key range; the chunks are merged in parallel with the `parallel`
/// feature, each into its own reused buffers (`parts`), which are appended in chunk order:
/// the output is the serial merge's, on any thread count. `capacity` keeps the largest
/// buffer sizes seen, to which every part is grown (no allocation once the largest chunk
/// has been seen).
pub(super) fn merge_candidates(
    view: &PairView<'_>,
    old: &[u64],
    new: &[u64],
    next: &mut Vec<u64>,
    exact: &mut Vec<u64>,
    parts: &mut Vec<MergePart>,
    capacity: &mut [usize; 2],
) {
    #[cfg(feature = "parallel")]
    if old.len() > MERGE_CHUNK && rayon::current_num_threads() > 1 {
        merge_split(view, old, new, next, exact, parts, capacity);
        return;
    }
    #[cfg(not(feature = "parallel"))]
    let _ = (parts, capacity);
    merge_range(view, old, new, next, exact);
}

/// The split merge of [`merge_candidates`].
#[cfg(feature = "parallel")]
fn merge_split(
    view: &PairView<'_>,
    old: &[u64],
    new: &[u64],
    next: &mut Vec<u64>,
    exact: &mut Vec<u64>,
    parts: &mut Vec<MergePart>,
    capacity: &mut [usize; 2],
) {
    use rayon::prelude::*;
    let chunks = old.len().div_ceil(MERGE_CHUNK);
    if parts.len() < chunks {
        parts.resize_with(chunks, MergePart::default);
    }
    // The start of chunk `c` in `new`: its first key not below the chunk's first key.
    let new_start = |c: usize| -> usize {
        if c == 0 {
            0
        } else if c == chunks {
            new.len()
        } else {
            new.partition_point(|&k| k < old[c * MERGE_CHUNK])
        }
    };
    let cap = *capacity;
    let run = |c: usize, part: &mut MergePart| {
        part.next.clear();
        part.exact.clear();
        part.next.reserve(cap[0]);
        part.exact.reserve(cap[1]);
        let lo = c * MERGE_CHUNK;
        let hi = (lo + MERGE_CHUNK).min(old.len());
        let (nlo, nhi) = (new_start(c), new_start(c + 1));
        merge_range(
            view,
            &old[lo..hi],
            &new[nlo..nhi],
            &mut part.next,
            &mut part.exact,
        );
    };
    parts[..chunks]
        .par_iter_mut()
        .enumerate()
        .with_max_len(1)
        .for_each(|(c, part)| run(c, part));
    for p in &parts[..chunks] {
        next.extend_from_slice(&p.next);
        exact.extend_from_slice(&p.exact);
        capacity[0] = capacity[0].max(p.next.capacity());
        capacity[1] = capacity[1].max(p.exact.capacity());
    }
}

/// The serial merge of [`merge_candidates`] over one key range.
fn merge_range(
    view: &PairView<'_>,
    old: &[u64],
    new: &[u64],
    next: &mut Vec<u64>,
    exact: &mut Vec<u64>,
) {
    // Per new key: first the run of surviving candidates below it (most of the work, in
    // a loop with one comparison per key), then the new key itself (dropping its old copy).
    let mut i = 0;
    for &n in new {
        while let Some(&o) = old.get(i) {
            if o >= n {
                i += (o == n) as usize;
                break;
            }
            i += 1;
            if view.unchanged(o) {
                next.push(o);
                view.emit(o, exact);
            }
        }
        next.push(n);
        view.emit(n, exact);
    }
    for &o in &old[i..] {
        if view.unchanged(o) {
            next.push(o);
            view.emit(o, exact);
        }
    }
}
