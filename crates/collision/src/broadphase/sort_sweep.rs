//! One-axis sort-and-sweep from scratch, in parallel: the talk's "parallel 1 axis sweep and
//! prune" (OPCODE's complete box pruning, Terdiman 2002; Game Physics Pearls ch. 7; Le Grand,
//! GPU Gems 3 ch. 32).
//!
//! Each update: pick the axis along which the box centres vary most (fewest boxes overlap on
//! it), radix-sort the boxes by their min on that axis ([`super::radix::par_sort_u64`]), then
//! for each box scan forward while the next min does not exceed its max, testing the two other
//! axes. The scan is split into fixed-size chunks run in parallel (rayon); chunk boundaries do
//! not depend on the thread count and the pairs are sorted afterwards, so the result is the
//! same on any number of threads. No state is kept between updates but reused buffers, so
//! cost does not depend on how far objects moved, and a steady update allocates nothing (up
//! to `2 × radix::PAR_CHUNK` proxies, past which the parallel sort allocates its merge buffer).

use super::impl_rebuilt_proxies;
use super::radix::par_sort_u64_with;
use super::{impl_common_broadphase, pair_key, BroadPhase, PairCache, PairChanges, ProxyStore};
use crate::math::{ordered_to_real, real_floor_key, Aabb, Real, Vec3};

/// Boxes swept per parallel task.
const SWEEP_CHUNK: usize = 1024;

/// The from-scratch sort-and-sweep broadphase (see the module docs).
#[derive(Debug, Clone, Default)]
pub struct SortSweep {
    store: ProxyStore,
    cache: PairCache,
    /// Axis used by the last update (0, 1 or 2).
    last_axis: usize,
    /// Buffers reused by every update.
    bufs: SweepBuffers,
}

/// Per-update buffers of the sweep, kept between updates: the live proxies, the sort keys
/// and the sort's scratch, the boxes in sweep order, one pair list per chunk and the pair
/// keys handed to the cache (which hands back its previous array).
#[derive(Debug, Clone, Default)]
struct SweepBuffers {
    live: Vec<u32>,
    keys: Vec<u64>,
    scratch: Vec<u64>,
    sorted: Sorted,
    parts: Vec<Vec<u64>>,
    pairs: Vec<u64>,
}

impl SortSweep {
    /// An empty broadphase.
    pub fn new() -> Self {
        Self::default()
    }

    /// The axis the last update swept along.
    pub fn last_axis(&self) -> usize {
        self.last_axis
    }
}

/// The axis of greatest variance of the centres of `boxes` (sums in a fixed order).
pub fn axis_of_greatest_variance(boxes: &[Aabb], ids: &[u32]) -> usize {
    if ids.is_empty() {
        return 0;
    }
    let n = ids.len() as Real;
    let mut sum = Vec3::ZERO;
    let mut sum_sq = Vec3::ZERO;
    for &i in ids {
        let c = boxes[i as usize].center();
        sum += c;
        sum_sq += c * c;
    }
    let var = sum_sq / n - (sum / n) * (sum / n);
    if var.x >= var.y && var.x >= var.z {
        0
    } else if var.y >= var.z {
        1
    } else {
        2
    }
}

/// Sorted sweep data: boxes in sweep order, their rounded-down min on the axis, their ids.
#[derive(Debug, Clone, Default)]
struct Sorted {
    boxes: Vec<Aabb>,
    lo: Vec<Real>,
    ids: Vec<u32>,
}

/// Sweeps the sorted boxes with indices in `range`, pushing pair keys to `out`.
fn sweep_range(s: &Sorted, axis: usize, range: std::ops::Range<usize>, out: &mut Vec<u64>) {
    let (j_ax, k_ax) = ((axis + 1) % 3, (axis + 2) % 3);
    let n = s.boxes.len();
    for i in range {
        let bi = &s.boxes[i];
        let hi = bi.max[axis];
        let mut j = i + 1;
        while j < n && s.lo[j] <= hi {
            let bj = &s.boxes[j];
            if bi.min[j_ax] <= bj.max[j_ax]
                && bj.min[j_ax] <= bi.max[j_ax]
                && bi.min[k_ax] <= bj.max[k_ax]
                && bj.min[k_ax] <= bi.max[k_ax]
                && bi.min[axis] <= bj.max[axis]
                && bj.min[axis] <= bi.max[axis]
            {
                out.push(pair_key(s.ids[i], s.ids[j]));
            }
            j += 1;
        }
    }
}

/// All overlapping pairs among `boxes[ids]` as unsorted pair keys (each pair once), and the
/// axis swept.
pub fn find_pairs(boxes: &[Aabb], ids: &[u32]) -> (Vec<u64>, usize) {
    let mut bufs = SweepBuffers::default();
    let mut out = Vec::new();
    let axis = find_pairs_into(boxes, ids, &mut bufs, &mut out);
    (out, axis)
}

/// [`find_pairs`] into `out` (cleared first) with reused buffers; returns the axis.
fn find_pairs_into(
    boxes: &[Aabb],
    ids: &[u32],
    bufs: &mut SweepBuffers,
    out: &mut Vec<u64>,
) -> usize {
    let axis = axis_of_greatest_variance(boxes, ids);
    let keys = &mut bufs.keys;
    keys.clear();
    keys.extend(
        ids.iter()
            .map(|&i| ((real_floor_key(boxes[i as usize].min[axis]) as u64) << 32) | i as u64),
    );
    par_sort_u64_with(keys, &mut bufs.scratch);
    let s = &mut bufs.sorted;
    s.boxes.clear();
    s.lo.clear();
    s.ids.clear();
    for &k in keys.iter() {
        let id = k as u32;
        s.boxes.push(boxes[id as usize]);
        s.ids.push(id);
        s.lo.push(ordered_to_real((k >> 32) as u32));
    }
    let n = s.boxes.len();
    let chunks = n.div_ceil(SWEEP_CHUNK);
    if bufs.parts.len() < chunks {
        bufs.parts.resize_with(chunks, Vec::new);
    }
    let s = &bufs.sorted;
    let run = |c: usize, part: &mut Vec<u64>| {
        part.clear();
        sweep_range(
            s,
            axis,
            c * SWEEP_CHUNK..((c + 1) * SWEEP_CHUNK).min(n),
            part,
        );
    };
    let parts = &mut bufs.parts[..chunks];
    #[cfg(feature = "parallel")]
    {
        use rayon::prelude::*;
        parts
            .par_iter_mut()
            .enumerate()
            .for_each(|(c, part)| run(c, part));
    }
    #[cfg(not(feature = "parallel"))]
    for (c, part) in parts.iter_mut().enumerate() {
        run(c, part);
    }
    out.clear();
    for p in parts.iter() {
        out.extend_from_slice(p);
    }
    axis
}

impl BroadPhase for SortSweep {
    fn name(&self) -> &'static str {
        "sort_sweep"
    }

    fn update_pairs(&mut self) -> &PairChanges {
        let bufs = &mut self.bufs;
        self.store.live_indices_into(&mut bufs.live);
        let mut pairs = std::mem::take(&mut bufs.pairs);
        let live = std::mem::take(&mut bufs.live);
        self.last_axis = find_pairs_into(self.store.aabbs(), &live, bufs, &mut pairs);
        bufs.live = live;
        let changes = self
            .cache
            .replace_reusing(&mut self.store, &mut pairs, false);
        self.bufs.pairs = pairs;
        changes
    }

    impl_common_broadphase!();
    impl_rebuilt_proxies!();
}
