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

use super::pair_keys::sort_dedup_pair_keys;
use super::tree_search::{merge_candidates, MergePart, Part, MOVED_CHUNK, PARALLEL_MIN_LEAVES};
use super::{pair_key, unpack_pair, BroadPhase, Filter, InsertStrategy};
use super::{PairCache, PairChanges, ProxyHandle, ProxyStore, TreeProxy};
use crate::bvh::{DynamicTree, WideTree};
use crate::error::Result;
use crate::math::{Aabb, Real, Vec3};

pub(super) const MOVING: usize = 0;
pub(super) const RESTING: usize = 1;

/// Two dynamic AABB trees (moving, resting/static) with a move buffer and a sorted candidate
/// pair set. See the module docs.
#[derive(Debug, Clone)]
pub struct TreeBroadPhase {
    store: ProxyStore,
    cache: PairCache,
    pub(super) trees: [DynamicTree; 2],
    /// The 4-wide copy of the moving tree the moved proxies query in this update, when
    /// `wide_ready` (see [`TreeBroadPhase::wide_query_keys`]).
    wide: WideTree,
    wide_ready: bool,
    /// Candidate keys per moved proxy found by the last incremental search (before the
    /// sort): how dense the queries are, which decides whether the wide copy pays.
    keys_per_query: Real,
    /// Per slot: which tree and which leaf.
    leaves: Vec<(usize, TreeProxy)>,
    /// Per slot: the fat box (a copy of the leaf's, for the candidate pass).
    fat: Vec<Aabb>,
    moved: Vec<u32>,
    moved_flag: Vec<bool>,
    candidates: Vec<u64>,
    /// Reused buffers: new candidate keys, the next candidate set, the next exact pairs,
    /// and the traversal stacks (no allocation per update in the steady state).
    new_keys: Vec<u64>,
    next_candidates: Vec<u64>,
    exact: Vec<u64>,
    /// Reused buffers of [`sort_dedup_pair_keys`]: the scattered keys and the bucket counts.
    key_scratch: Vec<u64>,
    key_counts: Vec<u32>,
    stack: Vec<u32>,
    pair_stack: Vec<(u32, u32)>,
    /// Reused buffers of the parallel candidate search: the node-pair tasks of the split
    /// descent (and their expansion scratch), and per task or chunk of moved proxies its
    /// keys and traversal stacks.
    pub(super) tasks: Vec<(u32, u32)>,
    pub(super) cross_tasks: Vec<(u32, u32)>,
    pub(super) task_scratch: Vec<(u32, u32)>,
    pub(super) parts: Vec<Part>,
    /// The largest capacities any part's buffers reached (keys, stack, pair stack): every
    /// part is grown to them, so that tasks whose work shifts from update to update stop
    /// allocating once the largest has been seen.
    pub(super) part_capacity: [usize; 3],
    /// Reused buffers of the parallel candidate merge ([`merge_candidates`]) and the
    /// largest capacities they reached (surviving candidates, exact pairs).
    merge_parts: Vec<MergePart>,
    merge_capacity: [usize; 2],
    /// A proxy was removed since the last update (its candidate pairs must be dropped).
    removed_since_update: bool,
    /// A box or a filter changed since the last update (`update_proxy`, `set_filter`,
    /// `set_user_filter`): a box may move inside its fat box without marking its proxy moved,
    /// and its exact pairs must still be tested again.
    changed: bool,
    /// Leaves re-inserted per update and tree by the incremental optimisation.
    pub optimize_per_update: usize,
    /// Fraction of moved proxies above which pairs are found by tree descent, not queries.
    pub full_sweep_fraction: Real,
    /// The moved proxies' queries of an incremental update run on a 4-wide copy of the
    /// moving tree rebuilt for the update ([`WideTree`], four child boxes tested per step)
    /// when the keys they are expected to find (moved proxies times the keys per query of
    /// the last incremental search) exceed this many per leaf of the moving tree. The
    /// rebuild costs about as much per leaf as the copy saves per key found (measured on
    /// "3000 fall": ~85 instructions per leaf against ~150 per key), so sparse or few
    /// queries keep the binary tree. Same pairs either way (0 always takes the copy once
    /// keys were found; infinity never).
    pub wide_query_keys: Real,
    /// When true (the default), a moving proxy whose box left its fat box keeps its place
    /// in the moving tree and only its ancestors are refitted
    /// ([`DynamicTree::refit_proxy`]); when false it is removed and re-inserted by the
    /// tree's strategy ([`DynamicTree::move_proxy`]). Resting and static proxies are always
    /// re-inserted.
    pub refit_moving: bool,
}

impl Default for TreeBroadPhase {
    fn default() -> Self {
        Self::new(InsertStrategy::default(), Self::DEFAULT_MARGIN)
    }
}

impl TreeBroadPhase {
    /// The default fat-box margin (length units).
    ///
    /// With [`TreeBroadPhase::DEFAULT_MOTION_SCALE`] it was chosen on the pipeline's
    /// recorded boxes (`examples/broadphase_replay.rs`, 300 steps, instructions per step on
    /// "3000 fall"): margin 0.1 / scale 2 7.08M, 0.05 / 4 5.98M, 0.05 / 6 5.76M, 0.02 / 4
    /// 6.37M, 0.2 / 2 7.58M; "1000 stack" and "1000 convex" did not get worse (0.85M and
    /// 1.02M vs 0.85M and 1.15M). The pipeline's boxes already carry a speculative margin
    /// that grows with the speed, so a small fixed margin suffices; sweeping along the
    /// motion saves the re-fits of falling bodies.
    pub const DEFAULT_MARGIN: Real = 0.05;

    /// The default multiple of the predicted displacement the fat boxes are swept by.
    pub const DEFAULT_MOTION_SCALE: Real = 4.0;

    /// An empty broadphase whose trees use `strategy` and the fat-box `margin`, with fat
    /// boxes swept by [`TreeBroadPhase::DEFAULT_MOTION_SCALE`] times the displacement.
    pub fn new(strategy: InsertStrategy, margin: Real) -> Self {
        let mut tree = DynamicTree::new(strategy, margin);
        tree.set_motion_scale(Self::DEFAULT_MOTION_SCALE);
        TreeBroadPhase {
            store: ProxyStore::new(),
            cache: PairCache::new(),
            trees: [tree.clone(), tree],
            wide: WideTree::new(),
            wide_ready: false,
            keys_per_query: 0.0,
            leaves: Vec::new(),
            fat: Vec::new(),
            moved: Vec::new(),
            moved_flag: Vec::new(),
            candidates: Vec::new(),
            new_keys: Vec::new(),
            next_candidates: Vec::new(),
            exact: Vec::new(),
            key_scratch: Vec::new(),
            key_counts: Vec::new(),
            stack: Vec::new(),
            pair_stack: Vec::new(),
            tasks: Vec::new(),
            cross_tasks: Vec::new(),
            task_scratch: Vec::new(),
            parts: Vec::new(),
            part_capacity: [0; 3],
            merge_parts: Vec::new(),
            merge_capacity: [0; 2],
            removed_since_update: false,
            changed: false,
            optimize_per_update: 4,
            full_sweep_fraction: 0.5,
            wide_query_keys: 1.0,
            refit_moving: true,
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

    /// [`BroadPhase::update_proxy`] without the checks, for a caller that has checked the
    /// handle (slot `i` is live), the box (finite, `min <= max`) and the displacement
    /// (finite): the collision world's per-step sync, where the checks were a third of the
    /// update's instructions.
    ///
    /// The usual case (the box still inside its fat box, which is not too large) is inline
    /// and touches the tree only to read the leaf's fat box; a new fat box is set out of
    /// line ([`TreeBroadPhase::set_new_fat`]), so the common path pays no large frame.
    #[inline]
    pub(crate) fn update_slot(&mut self, i: usize, aabb: &Aabb, displacement: Vec3) {
        self.store.set_aabb_trusted(i, *aabb);
        self.changed = true;
        let (t, leaf) = self.leaves[i];
        if self.trees[t].needs_new_fat(leaf.index as usize, aabb, displacement) {
            self.set_new_fat(i, aabb, displacement);
        }
    }

    /// Gives slot `i`'s leaf a new fat box for `aabb` moving by `displacement` (refitted in
    /// place in the moving tree, re-inserted otherwise) and marks it moved.
    #[inline(never)]
    fn set_new_fat(&mut self, i: usize, aabb: &Aabb, displacement: Vec3) {
        let (t, leaf) = self.leaves[i];
        let tree = &mut self.trees[t];
        if t == MOVING && self.refit_moving {
            tree.refit_fat(leaf.index, aabb, displacement);
        } else {
            let fat = tree.fat_aabb(aabb, displacement);
            tree.move_proxy_fat(leaf.index, fat);
        }
        self.fat[i] = self.trees[t].leaf_fat(leaf.index);
        self.mark_moved(i as u32);
    }

    /// Adds to `out` the candidate keys of moved proxy `m` against tree `t`. A pair of two
    /// moved proxies is reported only by the lower one (when both query, as Box2D v3's
    /// `b2PairQueryCallback`), so fewer duplicate keys reach the sort.
    #[inline]
    pub(super) fn query_moved(&self, m: u32, t: usize, stack: &mut Vec<u32>, out: &mut Vec<u64>) {
        if t == MOVING && self.wide_ready {
            self.query_moved_wide(m, stack, out);
            return;
        }
        let fat = self.fat[m as usize];
        let moved = &self.moved_flag;
        self.trees[t].overlapping_leaves(&fat, stack, |other| {
            if other != m && !(other < m && moved[other as usize]) {
                out.push(pair_key(m, other));
            }
        });
    }

    /// [`TreeBroadPhase::query_moved`] against the moving tree's 4-wide copy (the same
    /// keys); kept out of line so that the binary query stays small enough to inline.
    #[inline(never)]
    fn query_moved_wide(&self, m: u32, stack: &mut Vec<u32>, out: &mut Vec<u64>) {
        let fat = self.fat[m as usize];
        let moved = &self.moved_flag;
        self.wide.overlapping_leaves(&fat, stack, |other| {
            if other != m && !(other < m && moved[other as usize]) {
                out.push(pair_key(m, other));
            }
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
        // Validates the box; the leaf is ours and live, so the tree skips its own checks.
        self.store.set_aabb(proxy, aabb)?;
        self.update_slot(i, &aabb, displacement);
        Ok(())
    }

    fn remove_proxy(&mut self, proxy: ProxyHandle) -> Result<()> {
        let i = self.store.remove(proxy)?;
        let (t, leaf) = self.leaves[i];
        self.trees[t].destroy_proxy(leaf)?;
        self.removed_since_update = true;
        Ok(())
    }

    fn set_filter(&mut self, proxy: ProxyHandle, filter: Filter) -> Result<()> {
        let i = self.store.check(proxy)?;
        let was_static = self.store.filters()[i].is_static;
        self.store.set_filter(proxy, filter)?;
        self.changed = true;
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
        self.changed = true;
    }

    fn update_pairs(&mut self) -> &PairChanges {
        // No box, filter or proxy changed (and no user filter, which may answer differently
        // from one update to the next): every candidate keeps its boxes and filters, so the
        // pairs are the last update's (a world whose bodies all sleep). The trees are not
        // re-optimised either: nothing degraded them and nothing queries them until a leaf
        // moves again, and then the incremental optimisation resumes. (Re-inserting four
        // leaves of each tree was 78 k of the 113 k instructions of an idle step of
        // "1000 stack".)
        if self.moved.is_empty()
            && !self.removed_since_update
            && !self.changed
            && !self.cache.has_user_filter()
        {
            return self.cache.keep_all();
        }
        self.changed = false;
        let mut moved = std::mem::take(&mut self.moved);
        moved.retain(|&m| self.store.is_alive(m as usize));
        moved.sort_unstable();
        let mut new_keys = std::mem::take(&mut self.new_keys);
        let mut stack = std::mem::take(&mut self.stack);
        let mut pair_stack = std::mem::take(&mut self.pair_stack);
        new_keys.clear();
        let live = self.store.len().max(1);
        let full = moved.len() as Real > self.full_sweep_fraction * live as Real;
        if full {
            // Rebuild the candidates of every pair with a moving proxy by tree descent; keep
            // the resting × resting ones, and query the moved resting proxies.
            if self.trees[MOVING].len() >= PARALLEL_MIN_LEAVES {
                self.descend_split(&mut new_keys);
            } else {
                self.trees[MOVING]
                    .self_pairs_with(&mut pair_stack, |a, b| new_keys.push(pair_key(a, b)));
                self.trees[MOVING].query_tree_with(
                    &self.trees[RESTING],
                    &mut pair_stack,
                    |a, b| new_keys.push(pair_key(a, b)),
                );
            }
            for &m in &moved {
                if self.leaves[m as usize].0 == RESTING {
                    self.query_moved(m, RESTING, &mut stack, &mut new_keys);
                }
            }
            let leaves = &self.leaves;
            self.candidates.retain(|&k| {
                let (a, b) = unpack_pair(k);
                leaves[a as usize].0 == RESTING && leaves[b as usize].0 == RESTING
            });
        } else {
            // Enough keys expected from the moving tree to pay for its 4-wide copy? (The
            // estimate depends only on past keys, never on the thread count.)
            let expected = moved.len() as Real * self.keys_per_query;
            self.wide_ready = expected > self.wide_query_keys * self.trees[MOVING].len() as Real;
            if self.wide_ready {
                self.wide.rebuild(&self.trees[MOVING]);
            }
            if moved.len() >= 2 * MOVED_CHUNK {
                self.query_moved_chunked(&moved, &mut new_keys);
            } else {
                for &m in &moved {
                    self.query_moved(m, MOVING, &mut stack, &mut new_keys);
                    self.query_moved(m, RESTING, &mut stack, &mut new_keys);
                }
            }
            self.wide_ready = false;
            if !moved.is_empty() {
                self.keys_per_query = new_keys.len() as Real / moved.len() as Real;
            }
        }
        self.stack = stack;
        self.pair_stack = pair_stack;
        sort_dedup_pair_keys(
            &mut new_keys,
            &mut self.key_scratch,
            &mut self.key_counts,
            self.leaves.len(),
        );
        // One pass over the union of the surviving and the new candidates (both sorted).
        // Every pair whose fat boxes overlap and that has a moved proxy was found again by
        // the queries above (or the descent), and a pair of two unmoved proxies keeps its fat
        // boxes; so a surviving candidate is dropped exactly when it has a moved or removed
        // proxy and was not found again, and no fat boxes need testing. The pairs whose
        // exact boxes overlap and whose filters accept each other are this update's pairs,
        // already sorted.
        let mut exact = std::mem::take(&mut self.exact);
        exact.clear();
        {
            let view = PairView {
                alive: self.store.alive(),
                boxes: self.store.aabbs(),
                filters: self.store.filters(),
                moved: &self.moved_flag,
                removals: self.removed_since_update,
            };
            if new_keys.is_empty() {
                // The steady state: filter the candidates in place.
                let cands = &mut self.candidates;
                let mut w = 0;
                for r in 0..cands.len() {
                    let k = cands[r];
                    if view.unchanged(k) {
                        cands[w] = k;
                        w += 1;
                        view.emit(k, &mut exact);
                    }
                }
                cands.truncate(w);
            } else {
                let mut next = std::mem::take(&mut self.next_candidates);
                next.clear();
                merge_candidates(
                    &view,
                    &self.candidates,
                    &new_keys,
                    &mut next,
                    &mut exact,
                    &mut self.merge_parts,
                    &mut self.merge_capacity,
                );
                self.next_candidates = std::mem::replace(&mut self.candidates, next);
            }
        }
        for &m in &moved {
            self.moved_flag[m as usize] = false;
        }
        moved.clear();
        self.moved = moved;
        self.removed_since_update = false;
        self.new_keys = new_keys;
        for t in &mut self.trees {
            t.optimize_incremental(self.optimize_per_update);
        }
        self.cache.replace_accepted(&mut self.store, &mut exact);
        self.exact = exact;
        self.cache.changes()
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

/// What the candidate pass of [`TreeBroadPhase::update_pairs`] reads, per slot.
pub(super) struct PairView<'a> {
    alive: &'a [bool],
    boxes: &'a [Aabb],
    filters: &'a [Filter],
    moved: &'a [bool],
    removals: bool,
}

impl PairView<'_> {
    /// True when a surviving candidate stays one without a test: neither proxy moved (so
    /// their fat boxes still overlap) nor was removed.
    #[inline(always)]
    pub(super) fn unchanged(&self, k: u64) -> bool {
        let (a, b) = unpack_pair(k);
        let (a, b) = (a as usize, b as usize);
        !(self.moved[a] || self.moved[b] || (self.removals && !(self.alive[a] && self.alive[b])))
    }

    /// Pushes candidate `k` to `exact` when the exact boxes overlap and the filters accept.
    #[inline(always)]
    pub(super) fn emit(&self, k: u64, exact: &mut Vec<u64>) {
        let (a, b) = unpack_pair(k);
        let (a, b) = (a as usize, b as usize);
        if self.boxes[a].intersects(&self.boxes[b]) && self.filters[a].can_pair(&self.filters[b]) {
            exact.push(k);
        }
    }
}
