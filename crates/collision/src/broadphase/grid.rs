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

/// One level of a (hierarchical) hashed grid: sorted cell entries.
#[derive(Debug, Clone, Default)]
pub struct GridLevel {
    /// Inverse cell size.
    pub inv: Real,
    /// Entries sorted by key.
    pub entries: Vec<CellEntry>,
}

impl GridLevel {
    /// Builds the level for boxes `ids` (each must span at most [`MAX_CELLS_PER_BOX`] cells).
    pub fn build(
        boxes: &[Aabb],
        ids: &[u32],
        cell_size: Real,
        scratch: &mut Vec<CellEntry>,
    ) -> Self {
        let inv = 1.0 / cell_size;
        let mut entries = Vec::with_capacity(ids.len() * 2);
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
        radix_sort_by_key(&mut entries, scratch, |e| e.key >> 32);
        GridLevel { inv, entries }
    }

    /// Pairs among the boxes of this level, each reported once (in its lowest common cell).
    /// Buckets are processed in parallel in fixed-size groups (the output is sorted later).
    pub fn self_pairs(&self, boxes: &[Aabb], out: &mut Vec<u64>) {
        // Bucket boundaries, then groups of about PAIR_CHUNK entries cut at boundaries.
        const PAIR_CHUNK: usize = 4096;
        let e = &self.entries;
        let mut cuts = vec![0usize];
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
        let run = |lo: usize, hi: usize| {
            let mut out = Vec::new();
            self.pairs_in(boxes, lo, hi, &mut out);
            out
        };
        #[cfg(feature = "parallel")]
        {
            use rayon::prelude::*;
            let parts: Vec<Vec<u64>> = cuts.par_windows(2).map(|w| run(w[0], w[1])).collect();
            for p in parts {
                out.extend_from_slice(&p);
            }
        }
        #[cfg(not(feature = "parallel"))]
        for w in cuts.windows(2) {
            out.extend_from_slice(&run(w[0], w[1]));
        }
    }

    /// Pairs within the buckets that make up `entries[lo..hi]`.
    fn pairs_in(&self, boxes: &[Aabb], lo: usize, hi: usize, out: &mut Vec<u64>) {
        let e = &self.entries[..hi];
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
                        && (ep.single
                            || eq.single
                            || cell_of(ba.min.max(bb.min), self.inv) == ep.cell)
                    {
                        out.push(pair_key(ep.id(), b));
                    }
                }
            }
            start = end;
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
        let live = self.store.live_indices();
        let boxes = self.store.aabbs();
        let cell = self.cell_size.unwrap_or_else(|| {
            // The median largest extent: robust to a few huge boxes (planes).
            let mut ext: Vec<Real> = live
                .iter()
                .map(|&i| boxes[i as usize].extents().max_element())
                .collect();
            let m = ext.len() / 2;
            let median = if ext.is_empty() {
                0.0
            } else {
                *ext.select_nth_unstable_by(m, |a, b| a.total_cmp(b)).1
            };
            if median > 0.0 && median.is_finite() {
                median
            } else {
                1.0
            }
        });
        let inv = 1.0 / cell;
        let mut is_big = vec![false; self.store.capacity()];
        let (big, small): (Vec<u32>, Vec<u32>) = live
            .iter()
            .partition(|&&i| cell_count(&boxes[i as usize], inv) > MAX_CELLS_PER_BOX);
        for &b in &big {
            is_big[b as usize] = true;
        }
        let level = GridLevel::build(boxes, &small, cell, &mut self.scratch);
        let mut keys = Vec::new();
        level.self_pairs(boxes, &mut keys);
        oversize_pairs(boxes, &big, &live, &is_big, &mut keys);
        self.cache.replace(&mut self.store, keys, false)
    }

    impl_common_broadphase!();
    impl_rebuilt_proxies!();
}
