//! The pair cache: the current overlapping pairs, and what changed at each update.
//!
//! The talk's "decompose pairs": the narrowphase keeps data per pair (a persistent manifold,
//! warm-starting impulses), so the broadphase reports the pairs newly added, the ones kept
//! and the ones removed. Here the pairs of an update are a sorted array of keys
//! `(min index << 32) | max index`; the changes are found by merging it with the previous
//! array, so they come out in a deterministic order (sorted by (min id, max id)) whatever the
//! method, hash-table layout or thread count (Bullet's `btSortedOverlappingPairCache` does
//! the same by sorting; Box2D v3 orders its move buffer for determinism).

use super::{pair_key, unpack_pair, ProxyHandle, ProxyStore};
use std::sync::Arc;

/// A user pair filter: called with the two handles of a candidate pair that passed the
/// group/mask test; the pair is kept when it returns `true`.
pub type UserFilter = Arc<dyn Fn(ProxyHandle, ProxyHandle) -> bool + Send + Sync>;

/// What an update changed.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct PairChanges {
    /// Pairs that overlap now and did not at the previous update, sorted by (min, max)
    /// index; each pair is `(lower index, higher index)`.
    pub added: Vec<(ProxyHandle, ProxyHandle)>,
    /// Pairs that overlapped at the previous update and do not now (or whose proxy was
    /// removed), sorted the same way.
    pub removed: Vec<(ProxyHandle, ProxyHandle)>,
    /// Number of pairs present at both updates.
    pub kept: usize,
}

/// The sorted set of current pairs, with filtering and change reporting.
#[derive(Clone, Default)]
pub struct PairCache {
    keys: Vec<u64>,
    changes: PairChanges,
    user_filter: Option<UserFilter>,
    /// Radix-sort scratch of [`PairCache::replace_reusing`].
    scratch: Vec<u64>,
}

impl std::fmt::Debug for PairCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PairCache")
            .field("pairs", &self.keys.len())
            .field("changes", &self.changes)
            .field("user_filter", &self.user_filter.is_some())
            .finish()
    }
}

impl PairCache {
    /// An empty cache.
    pub fn new() -> Self {
        Self::default()
    }

    /// Installs or clears the user filter.
    pub fn set_user_filter(&mut self, filter: Option<UserFilter>) {
        self.user_filter = filter;
    }

    /// True when the live proxies in slots `a` and `b` may pair (filter bits, not both
    /// static, user filter). Does not look at the boxes.
    #[inline]
    pub fn accepts(&self, store: &ProxyStore, a: u32, b: u32) -> bool {
        let f = store.filters();
        let ok = store.is_alive(a as usize)
            && store.is_alive(b as usize)
            && f[a as usize].can_pair(&f[b as usize]);
        if !ok {
            return false;
        }
        match &self.user_filter {
            Some(uf) => uf(store.handle(a), store.handle(b)),
            None => true,
        }
    }

    /// Replaces the current pairs with `keys` (pair keys of overlapping proxies, each pair at
    /// most once, in any order unless `sorted`), dropping those the filters reject, and
    /// computes the changes. Then recycles the slots removed during the frame.
    pub fn replace(
        &mut self,
        store: &mut ProxyStore,
        mut keys: Vec<u64>,
        sorted: bool,
    ) -> &PairChanges {
        if !sorted {
            super::radix::par_sort_u64(&mut keys);
        }
        debug_assert!(keys.windows(2).all(|w| w[0] < w[1]), "pairs sorted, unique");
        keys.retain(|&k| {
            let (a, b) = unpack_pair(k);
            self.accepts(store, a, b)
        });
        self.diff(store, keys);
        store.end_frame();
        &self.changes
    }

    /// [`PairCache::replace`] without allocating in the steady state: `keys` is sorted (with
    /// the cache's scratch) and filtered in place, swapped in as the current pairs, and
    /// receives the previous pair array for the caller to reuse as its next key buffer.
    pub fn replace_reusing(
        &mut self,
        store: &mut ProxyStore,
        keys: &mut Vec<u64>,
        sorted: bool,
    ) -> &PairChanges {
        if !sorted {
            super::radix::par_sort_u64_with(keys, &mut self.scratch);
        }
        debug_assert!(keys.windows(2).all(|w| w[0] < w[1]), "pairs sorted, unique");
        keys.retain(|&k| {
            let (a, b) = unpack_pair(k);
            self.accepts(store, a, b)
        });
        std::mem::swap(&mut self.keys, keys);
        Self::diff_into(&mut self.changes, store, keys, &self.keys);
        store.end_frame();
        &self.changes
    }

    /// Like [`PairCache::replace`] for keys that are already sorted, unique and accepted by
    /// the group/mask rule between live proxies (the user filter, if any, is applied here).
    /// The keys are swapped in and `keys` receives the previous pair array, so a caller that
    /// keeps it as its next buffer allocates nothing in the steady state.
    pub fn replace_accepted(
        &mut self,
        store: &mut ProxyStore,
        keys: &mut Vec<u64>,
    ) -> &PairChanges {
        debug_assert!(keys.windows(2).all(|w| w[0] < w[1]), "pairs sorted, unique");
        debug_assert!(keys.iter().all(|&k| {
            let (a, b) = unpack_pair(k);
            let f = store.filters();
            store.is_alive(a as usize)
                && store.is_alive(b as usize)
                && f[a as usize].can_pair(&f[b as usize])
        }));
        if let Some(uf) = &self.user_filter {
            keys.retain(|&k| {
                let (a, b) = unpack_pair(k);
                uf(store.handle(a), store.handle(b))
            });
        }
        std::mem::swap(&mut self.keys, keys);
        Self::diff_into(&mut self.changes, store, keys, &self.keys);
        store.end_frame();
        &self.changes
    }

    /// Merges the previous and the new sorted key arrays into added/removed/kept.
    fn diff(&mut self, store: &ProxyStore, keys: Vec<u64>) {
        let old = std::mem::replace(&mut self.keys, keys);
        Self::diff_into(&mut self.changes, store, &old, &self.keys);
    }

    /// The changes from the sorted pair keys `old` to `new`.
    fn diff_into(ch: &mut PairChanges, store: &ProxyStore, old: &[u64], new: &[u64]) {
        ch.added.clear();
        ch.removed.clear();
        ch.kept = 0;
        let pair = |k: u64| {
            let (a, b) = unpack_pair(k);
            (store.handle(a), store.handle(b))
        };
        let (mut i, mut j) = (0, 0);
        while i < old.len() || j < new.len() {
            if j == new.len() || (i < old.len() && old[i] < new[j]) {
                ch.removed.push(pair(old[i]));
                i += 1;
            } else if i == old.len() || new[j] < old[i] {
                ch.added.push(pair(new[j]));
                j += 1;
            } else {
                ch.kept += 1;
                i += 1;
                j += 1;
            }
        }
    }

    /// The changes computed by the last update.
    pub fn changes(&self) -> &PairChanges {
        &self.changes
    }

    /// Records an update that changed no pair: nothing added or removed, every pair kept.
    pub fn keep_all(&mut self) -> &PairChanges {
        self.changes.added.clear();
        self.changes.removed.clear();
        self.changes.kept = self.keys.len();
        &self.changes
    }

    /// True when a user pair filter is installed.
    pub fn has_user_filter(&self) -> bool {
        self.user_filter.is_some()
    }

    /// The current pairs as handles, sorted.
    pub fn pairs(&self, store: &ProxyStore) -> Vec<(ProxyHandle, ProxyHandle)> {
        self.keys
            .iter()
            .map(|&k| {
                let (a, b) = unpack_pair(k);
                (store.handle(a), store.handle(b))
            })
            .collect()
    }

    /// The current pairs as sorted keys.
    pub fn keys(&self) -> &[u64] {
        &self.keys
    }

    /// True when the pair of slots `a`, `b` is current (binary search).
    pub fn contains(&self, a: u32, b: u32) -> bool {
        self.keys.binary_search(&pair_key(a, b)).is_ok()
    }

    /// Number of current pairs.
    pub fn len(&self) -> usize {
        self.keys.len()
    }

    /// True when there is no current pair.
    pub fn is_empty(&self) -> bool {
        self.keys.is_empty()
    }
}
