//! The two-tree broadphase of the talk: moving proxies in one [`DynamicTree`], resting and
//! static ones in another; pairs come from moving × moving and moving × resting (Bullet's
//! `btDbvtBroadphase` with its `m_sets[0]`/`m_sets[1]`; Box2D v3 `b2BroadPhase` with one tree
//! per body type and a move buffer).
//!
//! Candidate pairs are the pairs whose *fat* boxes overlap. A pair can only start to overlap
//! when one of its fat boxes changes, so each update only queries the proxies whose fat box
//! changed (the move buffer) against both trees; when most proxies moved, a simultaneous
//! descent (self-pairs of the moving tree, moving × resting) is cheaper and used instead.
//! Candidates are kept sorted; each update drops those whose fat boxes separated and reports
//! those whose exact boxes overlap.

use super::{pair_key, unpack_pair, BroadPhase, Filter, InsertStrategy};
use super::{PairCache, PairChanges, ProxyHandle, ProxyStore, TreeProxy};
use crate::bvh::DynamicTree;
use crate::error::Result;
use crate::math::{Aabb, Real, Vec3};

const MOVING: usize = 0;
const RESTING: usize = 1;

/// Two dynamic AABB trees (moving, resting/static) with a move buffer and a sorted candidate
/// pair set. See the module docs.
#[derive(Debug, Clone)]
pub struct TreeBroadPhase {
    store: ProxyStore,
    cache: PairCache,
    trees: [DynamicTree; 2],
    /// Per slot: which tree and which leaf.
    leaves: Vec<(usize, TreeProxy)>,
    /// Per slot: the fat box (a copy of the leaf's, for the candidate pass).
    fat: Vec<Aabb>,
    moved: Vec<u32>,
    moved_flag: Vec<bool>,
    candidates: Vec<u64>,
    /// Leaves re-inserted per update and tree by the incremental optimisation.
    pub optimize_per_update: usize,
    /// Fraction of moved proxies above which pairs are found by tree descent, not queries.
    pub full_sweep_fraction: Real,
}

impl Default for TreeBroadPhase {
    fn default() -> Self {
        Self::new(InsertStrategy::default(), 0.1)
    }
}

impl TreeBroadPhase {
    /// An empty broadphase whose trees use `strategy` and the fat-box `margin`.
    pub fn new(strategy: InsertStrategy, margin: Real) -> Self {
        TreeBroadPhase {
            store: ProxyStore::new(),
            cache: PairCache::new(),
            trees: [
                DynamicTree::new(strategy, margin),
                DynamicTree::new(strategy, margin),
            ],
            leaves: Vec::new(),
            fat: Vec::new(),
            moved: Vec::new(),
            moved_flag: Vec::new(),
            candidates: Vec::new(),
            optimize_per_update: 4,
            full_sweep_fraction: 0.5,
        }
    }

    /// Sets how many times the predicted displacement the fat boxes are swept by (both
    /// trees; see [`DynamicTree::set_motion_scale`]).
    pub fn set_motion_scale(&mut self, scale: Real) {
        for t in &mut self.trees {
            t.set_motion_scale(scale);
        }
    }

    /// Number of candidate pairs (fat boxes overlapping) after the last update.
    pub fn candidate_count(&self) -> usize {
        self.candidates.len()
    }

    /// The moving tree (index 0) or the resting tree (index 1).
    pub fn tree(&self, which: usize) -> &DynamicTree {
        &self.trees[which.min(1)]
    }

    /// True when the proxy lives in the resting tree.
    pub fn is_resting(&self, proxy: ProxyHandle) -> Result<bool> {
        let i = self.store.check(proxy)?;
        Ok(self.leaves[i].0 == RESTING)
    }

    fn mark_moved(&mut self, i: u32) {
        if !self.moved_flag[i as usize] {
            self.moved_flag[i as usize] = true;
            self.moved.push(i);
        }
    }

    /// Moves slot `i`'s leaf to tree `to` (keeping its fat box).
    fn migrate(&mut self, i: usize, to: usize) {
        let (from, leaf) = self.leaves[i];
        if from == to {
            return;
        }
        // The leaf is live (checked by the caller), so destroying cannot fail.
        let _ = self.trees[from].destroy_proxy(leaf);
        let new_leaf = self.trees[to].create_proxy_fat(self.fat[i], i as u32);
        self.leaves[i] = (to, new_leaf);
    }

    /// Adds to `out` the candidate keys of moved proxy `m` against tree `t`.
    fn query_moved(&self, m: u32, t: usize, out: &mut Vec<u64>) {
        let fat = self.fat[m as usize];
        self.trees[t].query_aabb(&fat, |_, other| {
            if other != m {
                out.push(pair_key(m, other));
            }
            true
        });
    }
}

impl BroadPhase for TreeBroadPhase {
    fn name(&self) -> &'static str {
        "tree"
    }

    fn create_proxy(&mut self, aabb: Aabb, filter: Filter) -> Result<ProxyHandle> {
        let h = self.store.create(aabb, filter)?;
        let i = h.index as usize;
        let t = if filter.is_static { RESTING } else { MOVING };
        let fat = self.trees[t].fat_aabb(&aabb, Vec3::ZERO);
        let leaf = self.trees[t].create_proxy_fat(fat, h.index);
        if i == self.leaves.len() {
            self.leaves.push((t, leaf));
            self.fat.push(fat);
            self.moved_flag.push(false);
        } else {
            self.leaves[i] = (t, leaf);
            self.fat[i] = fat;
            self.moved_flag[i] = false;
        }
        self.mark_moved(h.index);
        Ok(h)
    }

    fn update_proxy(&mut self, proxy: ProxyHandle, aabb: Aabb, displacement: Vec3) -> Result<()> {
        let i = self.store.check(proxy)?;
        if !displacement.is_finite() {
            return Err(crate::CaromError::invalid(
                "displacement",
                displacement,
                "must be finite",
            ));
        }
        self.store.set_aabb(proxy, aabb)?;
        let (t, leaf) = self.leaves[i];
        if self.trees[t].move_proxy(leaf, aabb, displacement)? {
            self.fat[i] = self.trees[t].fat_aabb_of(leaf)?;
            self.mark_moved(i as u32);
        }
        Ok(())
    }

    fn remove_proxy(&mut self, proxy: ProxyHandle) -> Result<()> {
        let i = self.store.remove(proxy)?;
        let (t, leaf) = self.leaves[i];
        self.trees[t].destroy_proxy(leaf)?;
        Ok(())
    }

    fn set_filter(&mut self, proxy: ProxyHandle, filter: Filter) -> Result<()> {
        let i = self.store.check(proxy)?;
        let was_static = self.store.filters()[i].is_static;
        self.store.set_filter(proxy, filter)?;
        if filter.is_static && !was_static {
            self.migrate(i, RESTING);
        } else if !filter.is_static && was_static {
            self.migrate(i, MOVING);
            // Pairs with other static proxies were never searched for.
            self.mark_moved(i as u32);
        }
        Ok(())
    }

    fn set_resting(&mut self, proxy: ProxyHandle, resting: bool) -> Result<()> {
        let i = self.store.check(proxy)?;
        if self.store.filters()[i].is_static {
            return Ok(());
        }
        self.migrate(i, if resting { RESTING } else { MOVING });
        Ok(())
    }

    fn set_user_filter(&mut self, filter: Option<super::UserFilter>) {
        self.cache.set_user_filter(filter);
    }

    fn update_pairs(&mut self) -> &PairChanges {
        let mut moved = std::mem::take(&mut self.moved);
        moved.retain(|&m| self.store.is_alive(m as usize));
        moved.sort_unstable();
        let live = self.store.len().max(1);
        let mut new_keys = Vec::new();
        let full = moved.len() as Real > self.full_sweep_fraction * live as Real;
        if full {
            // Rebuild the candidates of every pair with a moving proxy by tree descent; keep
            // the resting × resting ones, and query the moved resting proxies.
            self.trees[MOVING].self_pairs(|a, b| new_keys.push(pair_key(a, b)));
            self.trees[MOVING]
                .query_tree(&self.trees[RESTING], |a, b| new_keys.push(pair_key(a, b)));
            for &m in &moved {
                if self.leaves[m as usize].0 == RESTING {
                    self.query_moved(m, RESTING, &mut new_keys);
                }
            }
            let leaves = &self.leaves;
            self.candidates.retain(|&k| {
                let (a, b) = unpack_pair(k);
                leaves[a as usize].0 == RESTING && leaves[b as usize].0 == RESTING
            });
        } else {
            for &m in &moved {
                self.query_moved(m, MOVING, &mut new_keys);
                self.query_moved(m, RESTING, &mut new_keys);
            }
        }
        for &m in &moved {
            self.moved_flag[m as usize] = false;
        }
        moved.clear();
        self.moved = moved;
        super::radix::par_sort_u64(&mut new_keys);
        new_keys.dedup();
        // Merge with the surviving candidates, dropping dead and separated pairs.
        let old = std::mem::take(&mut self.candidates);
        let mut merged = vec![0u64; old.len() + new_keys.len()];
        super::radix::merge(&old, &new_keys, &mut merged);
        merged.dedup();
        let alive = self.store.alive();
        let fat = &self.fat;
        merged.retain(|&k| {
            let (a, b) = unpack_pair(k);
            alive[a as usize] && alive[b as usize] && fat[a as usize].intersects(&fat[b as usize])
        });
        let boxes = self.store.aabbs();
        let exact: Vec<u64> = merged
            .iter()
            .copied()
            .filter(|&k| {
                let (a, b) = unpack_pair(k);
                boxes[a as usize].intersects(&boxes[b as usize])
            })
            .collect();
        self.candidates = merged;
        for t in &mut self.trees {
            t.optimize_incremental(self.optimize_per_update);
        }
        self.cache.replace(&mut self.store, exact, true)
    }

    fn pairs(&self) -> Vec<(ProxyHandle, ProxyHandle)> {
        self.cache.pairs(&self.store)
    }

    fn pair_count(&self) -> usize {
        self.cache.len()
    }

    fn aabb(&self, proxy: ProxyHandle) -> Result<Aabb> {
        self.store.aabb(proxy)
    }

    fn len(&self) -> usize {
        self.store.len()
    }
}
