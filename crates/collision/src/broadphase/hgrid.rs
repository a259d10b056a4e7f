//! Hierarchical hashed grid for mixed object sizes (the talk's "use a hierarchy of grids to
//! allow varying sizes"; Ericson, Real-Time Collision Detection §7.2; Mirtich's hierarchical
//! hash tables).
//!
//! Level `l` has cells of size `s₀·2ˡ`; a box goes to the smallest level whose cells are at
//! least as large as its largest extent, so it covers at most 2×2×2 cells there. Pairs are
//! found within each level ([`GridLevel::self_pairs`]) and by querying every box against the
//! occupied coarser levels ([`GridLevel::query`]); each pair is reported once, by its smaller
//! box, in the lowest common cell.

use super::grid::{oversize_pairs, CellEntry, GridBuffers, GridLevel};
use super::impl_rebuilt_proxies;
use super::{impl_common_broadphase, BroadPhase, PairCache, PairChanges, ProxyStore};
use crate::math::Real;

/// At most this many levels (sizes spanning a factor 2³¹ above the smallest).
const MAX_LEVELS: usize = 32;

/// The hierarchical grid broadphase (see the module docs).
#[derive(Debug, Clone)]
pub struct HierarchicalGrid {
    store: ProxyStore,
    cache: PairCache,
    scratch: Vec<CellEntry>,
    levels_used: usize,
    /// Buffers reused by every update (no allocation in the steady state): the boxes of
    /// each level, the levels (rebuilt in place) and the occupied level indices.
    bufs: GridBuffers,
    by_level: Vec<Vec<u32>>,
    levels: Vec<GridLevel>,
    used: Vec<usize>,
}

impl Default for HierarchicalGrid {
    fn default() -> Self {
        HierarchicalGrid {
            store: ProxyStore::default(),
            cache: PairCache::default(),
            scratch: Vec::new(),
            levels_used: 0,
            bufs: GridBuffers::default(),
            by_level: vec![Vec::new(); MAX_LEVELS],
            levels: vec![GridLevel::default(); MAX_LEVELS],
            used: Vec::with_capacity(MAX_LEVELS),
        }
    }
}

impl HierarchicalGrid {
    /// An empty grid (cell sizes adapt to the boxes at each update).
    pub fn new() -> Self {
        Self::default()
    }

    /// Number of occupied levels at the last update.
    pub fn levels_used(&self) -> usize {
        self.levels_used
    }
}

impl BroadPhase for HierarchicalGrid {
    fn name(&self) -> &'static str {
        "hgrid"
    }

    fn update_pairs(&mut self) -> &PairChanges {
        let b = &mut self.bufs;
        self.store.live_indices_into(&mut b.live);
        let boxes = self.store.aabbs();
        let ext = |i: u32| boxes[i as usize].extents().max_element();
        let smallest = b
            .live
            .iter()
            .map(|&i| ext(i))
            .filter(|&e| e > 0.0)
            .fold(Real::INFINITY, Real::min);
        // Base cell size: the smallest positive extent. Boxes too large for the top level
        // (e.g. planes' huge boxes) go to the oversize list.
        let base = if smallest.is_finite() { smallest } else { 1.0 };
        let top = base * (2.0 as Real).powi(MAX_LEVELS as i32 - 1);
        b.reset(self.store.capacity());
        for l in &mut self.by_level {
            l.clear();
        }
        for &i in &b.live {
            let e = ext(i);
            if e > top || !top.is_finite() {
                b.big.push(i);
                b.is_big[i as usize] = true;
                continue;
            }
            let mut l = 0;
            let mut size = base;
            while size < e && l + 1 < MAX_LEVELS {
                size *= 2.0;
                l += 1;
            }
            self.by_level[l].push(i);
        }
        self.used.clear();
        for (l, ids) in self.by_level.iter().enumerate() {
            if !ids.is_empty() {
                let size = base * (2.0 as Real).powi(l as i32);
                self.levels[l].rebuild(boxes, ids, size, &mut self.scratch);
                self.used.push(l);
            }
        }
        self.levels_used = self.used.len();
        for (n, &l) in self.used.iter().enumerate() {
            self.levels[l].self_pairs(boxes, &mut b.keys);
            for &a in &self.by_level[l] {
                for &c in &self.used[n + 1..] {
                    self.levels[c].query(boxes, a, &mut b.keys);
                }
            }
        }
        oversize_pairs(boxes, &b.big, &b.live, &b.is_big, &mut b.keys);
        self.cache
            .replace_reusing(&mut self.store, &mut b.keys, false)
    }

    impl_common_broadphase!();
    impl_rebuilt_proxies!();
}
