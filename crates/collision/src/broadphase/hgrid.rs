//! Hierarchical hashed grid for mixed object sizes (the talk's "use a hierarchy of grids to
//! allow varying sizes"; Ericson, Real-Time Collision Detection §7.2; Mirtich's hierarchical
//! hash tables).
//!
//! Level `l` has cells of size `s₀·2ˡ`; a box goes to the smallest level whose cells are at
//! least as large as its largest extent, so it covers at most 2×2×2 cells there. Pairs are
//! found within each level ([`GridLevel::self_pairs`]) and by querying every box against the
//! occupied coarser levels ([`GridLevel::query`]); each pair is reported once, by its smaller
//! box, in the lowest common cell.

use super::grid::{oversize_pairs, CellEntry, GridLevel};
use super::impl_rebuilt_proxies;
use super::{impl_common_broadphase, BroadPhase, PairCache, PairChanges, ProxyStore};
use crate::math::Real;

/// At most this many levels (sizes spanning a factor 2³¹ above the smallest).
const MAX_LEVELS: usize = 32;

/// The hierarchical grid broadphase (see the module docs).
#[derive(Debug, Clone, Default)]
pub struct HierarchicalGrid {
    store: ProxyStore,
    cache: PairCache,
    scratch: Vec<CellEntry>,
    levels_used: usize,
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
        let live = self.store.live_indices();
        let boxes = self.store.aabbs();
        let ext = |i: u32| boxes[i as usize].extents().max_element();
        let smallest = live
            .iter()
            .map(|&i| ext(i))
            .filter(|&e| e > 0.0)
            .fold(Real::INFINITY, Real::min);
        // Base cell size: the smallest positive extent. Boxes too large for the top level
        // (e.g. planes' huge boxes) go to the oversize list.
        let base = if smallest.is_finite() { smallest } else { 1.0 };
        let top = base * (2.0 as Real).powi(MAX_LEVELS as i32 - 1);
        let mut by_level: Vec<Vec<u32>> = vec![Vec::new(); MAX_LEVELS];
        let mut big = Vec::new();
        let mut is_big = vec![false; self.store.capacity()];
        for &i in &live {
            let e = ext(i);
            if e > top || !top.is_finite() {
                big.push(i);
                is_big[i as usize] = true;
                continue;
            }
            let mut l = 0;
            let mut size = base;
            while size < e && l + 1 < MAX_LEVELS {
                size *= 2.0;
                l += 1;
            }
            by_level[l].push(i);
        }
        let mut levels: Vec<(usize, GridLevel)> = Vec::new();
        for (l, ids) in by_level.iter().enumerate() {
            if !ids.is_empty() {
                let size = base * (2.0 as Real).powi(l as i32);
                levels.push((l, GridLevel::build(boxes, ids, size, &mut self.scratch)));
            }
        }
        self.levels_used = levels.len();
        let mut keys = Vec::new();
        for (n, (l, level)) in levels.iter().enumerate() {
            level.self_pairs(boxes, &mut keys);
            for &a in &by_level[*l] {
                for (_, coarser) in &levels[n + 1..] {
                    coarser.query(boxes, a, &mut keys);
                }
            }
        }
        oversize_pairs(boxes, &big, &live, &is_big, &mut keys);
        self.cache.replace(&mut self.store, keys, false)
    }

    impl_common_broadphase!();
    impl_rebuilt_proxies!();
}
