//! Uniform grid broadphase, unbounded by hashing the cell coordinates (the talk's "use modulo
//! to make the grid unbounded"; Teschner et al., "Optimized Spatial Hashing for Collision
//! Detection of Deformable Objects", VMV 2003; Le Grand, GPU Gems 3 ch. 32).
//!
//! Each update (from scratch, GPU-style): every box is entered in every cell it overlaps as a
//! `(hash(cell) mod 2³², id)` key; the keys are radix-sorted so each bucket is a run; boxes in
//! the same *cell* of a run are tested. A pair that shares several cells is reported only by
//! the cell that holds the min corner of the intersection of the two boxes, so no
//! de-duplication pass is needed. Boxes spanning too many cells go to an "oversize" list
//! tested against everything. [`GridLevel`] is shared with the hierarchical grid.

use super::impl_rebuilt_proxies;
use super::radix::radix_sort_by_key;
use super::{impl_common_broadphase, pair_key, BroadPhase, PairCache, PairChanges, ProxyStore};
use crate::math::{Aabb, Real, Vec3};

/// Boxes covering more cells than this are handled by the oversize list.
pub const MAX_CELLS_PER_BOX: i64 = 64;

/// Integer cell coordinates.
pub type Cell = [i32; 3];

/// The cell of point `p` for cells of size `1 / inv` (clamped to the `i32` range, which only
/// merges very distant cells: still conservative).
#[inline]
pub fn cell_of(p: Vec3, inv: Real) -> Cell {
    // Inline floor (no libm call): truncate, then step down for negative non-integers.
    let c = |x: Real| {
        let v = (x * inv).clamp(i32::MIN as Real, i32::MAX as Real);
        let t = v as i32;
        if (t as Real) > v {
            t - 1
        } else {
            t
        }
    };
    [c(p.x), c(p.y), c(p.z)]
}

/// Spatial hash of a cell (Teschner et al.'s three large primes, mixed to 32 bits).
#[inline]
pub fn hash_cell(c: Cell) -> u32 {
    let h = (c[0] as u32 as u64).wrapping_mul(73_856_093)
        ^ (c[1] as u32 as u64).wrapping_mul(19_349_663)
        ^ (c[2] as u32 as u64).wrapping_mul(83_492_791);
    let h = (h ^ (h >> 31)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    (h >> 32) as u32
}

/// One entry of a grid level: a box in one cell.
#[derive(Debug, Clone, Copy)]
pub struct CellEntry {
    /// `(hash << 32) | id`: the sort key.
    pub key: u64,
    /// The cell.
    pub cell: Cell,
    /// True when the box lies in this one cell only: a pair with such a box can only be
    /// found here, so the lowest-common-cell test is skipped.
    pub single: bool,
}

impl CellEntry {
    #[inline]
    fn id(&self) -> u32 {
        self.key as u32
    }
}

/// One level of a (hierarchical) hashed grid: sorted cell entries. Rebuilt in place at
/// every update ([`GridLevel::rebuild`]), so its buffers are reused.
#[derive(Debug, Clone, Default)]
pub struct GridLevel {
    /// Inverse cell size.
    pub inv: Real,
    /// Entries sorted by key.
    pub entries: Vec<CellEntry>,
    /// Group boundaries and per-group pair buffers of [`GridLevel::self_pairs`].
    cuts: Vec<usize>,
    parts: Vec<Vec<u64>>,
}

impl GridLevel {
    /// Builds the level for boxes `ids` (each must span at most [`MAX_CELLS_PER_BOX`] cells).
    pub fn build(
        boxes: &[Aabb],
        ids: &[u32],
        cell_size: Real,
        scratch: &mut Vec<CellEntry>,
    ) -> Self {
        let mut level = GridLevel::default();
        level.rebuild(boxes, ids, cell_size, scratch);
        level
    }

    /// [`GridLevel::build`] into this level, reusing its buffers (no allocation once they
    /// have grown).
    pub fn rebuild(
        &mut self,
        boxes: &[Aabb],
        ids: &[u32],
        cell_size: Real,
        scratch: &mut Vec<CellEntry>,
    ) {
        let inv = 1.0 / cell_size;
        self.inv = inv;
        let entries = &mut self.entries;
        entries.clear();
        for &id in ids {
            let b = &boxes[id as usize];
            let (lo, hi) = (cell_of(b.min, inv), cell_of(b.max, inv));
            let single = lo == hi;
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        let cell = [x, y, z];
                        entries.push(CellEntry {
                            key: ((hash_cell(cell) as u64) << 32) | id as u64,
                            cell,
                            single,
                        });
                    }
                }
            }
        }
        // Entries were pushed in id order and the radix sort is stable: sorting on the hash
        // alone leaves each bucket in id order (3 passes instead of 5).
        radix_sort_by_key(entries, scratch, |e| e.key >> 32);
    }

    /// Pairs among the boxes of this level, each reported once (in its lowest common cell).
    /// Buckets are processed in parallel in fixed-size groups, whose results are appended
    /// in group order (the output does not depend on the thread count; it is sorted later).
    pub fn self_pairs(&mut self, boxes: &[Aabb], out: &mut Vec<u64>) {
        // Bucket boundaries, then groups of about PAIR_CHUNK entries cut at boundaries.
        const PAIR_CHUNK: usize = 4096;
        let e = &self.entries;
        let cuts = &mut self.cuts;
        cuts.clear();
        cuts.push(0);
        let mut i = 0;
        while i < e.len() {
            let h = e[i].key >> 32;
            i += 1;
            while i < e.len() && e[i].key >> 32 == h {
                i += 1;
            }
            if i - cuts[cuts.len() - 1] >= PAIR_CHUNK || i == e.len() {
                cuts.push(i);
            }
        }
        let groups = cuts.len() - 1;
        if self.parts.len() < groups {
            self.parts.resize_with(groups, Vec::new);
        }
        let inv = self.inv;
        let run = |w: &[usize], part: &mut Vec<u64>| {
            part.clear();
            pairs_in(e, inv, boxes, w[0], w[1], part);
        };
        let parts = &mut self.parts[..groups];
        #[cfg(feature = "parallel")]
        {
            use rayon::prelude::*;
            cuts.par_windows(2)
                .zip(parts.par_iter_mut())
                .for_each(|(w, part)| run(w, part));
        }
        #[cfg(not(feature = "parallel"))]
        for (w, part) in cuts.windows(2).zip(parts.iter_mut()) {
            run(w, part);
        }
        for p in parts.iter() {
            out.extend_from_slice(p);
        }
    }

    /// Pairs between box `a` (not in this level, no larger than a cell) and this level's
    /// boxes, each reported once.
    pub fn query(&self, boxes: &[Aabb], a: u32, out: &mut Vec<u64>) {
        let ba = &boxes[a as usize];
        let (lo, hi) = (cell_of(ba.min, self.inv), cell_of(ba.max, self.inv));
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    let cell = [x, y, z];
                    let h = (hash_cell(cell) as u64) << 32;
                    let mut i = self.entries.partition_point(|e| e.key < h);
                    while i < self.entries.len() && self.entries[i].key >> 32 == h >> 32 {
                        let e = self.entries[i];
                        i += 1;
                        if e.cell != cell {
                            continue;
                        }
                        let bb = &boxes[e.id() as usize];
                        if ba.intersects(bb) && cell_of(ba.min.max(bb.min), self.inv) == cell {
                            out.push(pair_key(a, e.id()));
                        }
                    }
                }
            }
        }
    }
}

/// Pairs within the buckets that make up `entries[lo..hi]` of a level with inverse cell
/// size `inv`.
fn pairs_in(
    entries: &[CellEntry],
    inv: Real,
    boxes: &[Aabb],
    lo: usize,
    hi: usize,
    out: &mut Vec<u64>,
) {
    let e = &entries[..hi];
    let mut start = lo;
    while start < hi {
        let h = e[start].key >> 32;
        let mut end = start + 1;
        while end < hi && e[end].key >> 32 == h {
            end += 1;
        }
        for p in start..end {
            let ep = e[p];
            let ba = &boxes[ep.id() as usize];
            for eq in &e[p + 1..end] {
                if ep.cell != eq.cell {
                    continue;
                }
                let b = eq.id();
                let bb = &boxes[b as usize];
                if ba.intersects(bb)
                    && ep.id() != b
                    && (ep.single || eq.single || cell_of(ba.min.max(bb.min), inv) == ep.cell)
                {
                    out.push(pair_key(ep.id(), b));
                }
            }
        }
        start = end;
    }
}

/// Number of cells of size `1/inv` a box covers (saturating).
pub fn cell_count(b: &Aabb, inv: Real) -> i64 {
    let (lo, hi) = (cell_of(b.min, inv), cell_of(b.max, inv));
    (0..3).fold(1i64, |n, k| {
        n.saturating_mul(hi[k] as i64 - lo[k] as i64 + 1)
    })
}

/// Pairs of the oversize boxes `big` with everything (each pair once).
pub fn oversize_pairs(
    boxes: &[Aabb],
    big: &[u32],
    all: &[u32],
    is_big: &[bool],
    out: &mut Vec<u64>,
) {
    for (n, &a) in big.iter().enumerate() {
        for &b in all {
            if !is_big[b as usize] && boxes[a as usize].intersects(&boxes[b as usize]) {
                out.push(pair_key(a, b));
            }
        }
        for &b in &big[n + 1..] {
            if boxes[a as usize].intersects(&boxes[b as usize]) {
                out.push(pair_key(a, b));
            }
        }
    }
}

/// The uniform hashed grid broadphase (see the module docs).
#[derive(Debug, Clone, Default)]
pub struct HashGrid {
    store: ProxyStore,
    cache: PairCache,
    /// Fixed cell size; `None` picks the median largest box extent at each update.
    pub cell_size: Option<Real>,
    scratch: Vec<CellEntry>,
    /// Buffers reused by every update (no allocation in the steady state).
    bufs: GridBuffers,
    level: GridLevel,
}

/// Per-update buffers of the grids, kept between updates.
#[derive(Debug, Clone, Default)]
pub(crate) struct GridBuffers {
    pub live: Vec<u32>,
    pub ext: Vec<Real>,
    pub big: Vec<u32>,
    pub small: Vec<u32>,
    pub is_big: Vec<bool>,
    pub keys: Vec<u64>,
}

impl GridBuffers {
    /// Clears the lists and sizes `is_big` to `capacity` slots, all false.
    pub fn reset(&mut self, capacity: usize) {
        self.big.clear();
        self.small.clear();
        self.keys.clear();
        self.is_big.clear();
        self.is_big.resize(capacity, false);
    }
}

impl HashGrid {
    /// An empty grid; `cell_size` `None` adapts to the boxes.
    pub fn new(cell_size: Option<Real>) -> Self {
        HashGrid {
            cell_size: cell_size.filter(|s| s.is_finite() && *s > 0.0),
            ..Self::default()
        }
    }
}

impl BroadPhase for HashGrid {
    fn name(&self) -> &'static str {
        "grid"
    }

    fn update_pairs(&mut self) -> &PairChanges {
        let b = &mut self.bufs;
        self.store.live_indices_into(&mut b.live);
        let boxes = self.store.aabbs();
        let cell = match self.cell_size {
            Some(c) => c,
            None => {
                // The median largest extent: robust to a few huge boxes (planes).
                b.ext.clear();
                b.ext.extend(
                    b.live
                        .iter()
                        .map(|&i| boxes[i as usize].extents().max_element()),
                );
                let m = b.ext.len() / 2;
                let median = if b.ext.is_empty() {
                    0.0
                } else {
                    *b.ext.select_nth_unstable_by(m, |a, b| a.total_cmp(b)).1
                };
                if median > 0.0 && median.is_finite() {
                    median
                } else {
                    1.0
                }
            }
        };
        let inv = 1.0 / cell;
        b.reset(self.store.capacity());
        for &i in &b.live {
            if cell_count(&boxes[i as usize], inv) > MAX_CELLS_PER_BOX {
                b.big.push(i);
                b.is_big[i as usize] = true;
            } else {
                b.small.push(i);
            }
        }
        self.level.rebuild(boxes, &b.small, cell, &mut self.scratch);
        self.level.self_pairs(boxes, &mut b.keys);
        oversize_pairs(boxes, &b.big, &b.live, &b.is_big, &mut b.keys);
        self.cache
            .replace_reusing(&mut self.store, &mut b.keys, false)
    }

    impl_common_broadphase!();
    impl_rebuilt_proxies!();
}
