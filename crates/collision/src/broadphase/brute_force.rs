//! The brute-force all-pairs broadphase: the reference every other method is tested against
//! (as Jolt keeps `BroadPhaseBruteForce` beside its quad-tree broadphase).

use super::impl_rebuilt_proxies;
use super::{impl_common_broadphase, pair_key, BroadPhase, PairCache, PairChanges, ProxyStore};

/// Tests every pair of live proxies, O(N²) per update. Obviously correct; the oracle.
#[derive(Debug, Clone, Default)]
pub struct BruteForce {
    store: ProxyStore,
    cache: PairCache,
}

impl BruteForce {
    /// An empty broadphase.
    pub fn new() -> Self {
        Self::default()
    }
}

impl BroadPhase for BruteForce {
    fn name(&self) -> &'static str {
        "brute_force"
    }

    fn update_pairs(&mut self) -> &PairChanges {
        let live = self.store.live_indices();
        let boxes = self.store.aabbs();
        let mut keys = Vec::new();
        for (n, &a) in live.iter().enumerate() {
            for &b in &live[n + 1..] {
                if boxes[a as usize].intersects(&boxes[b as usize]) {
                    keys.push(pair_key(a, b));
                }
            }
        }
        // Generated in (a, b) order with a < b ascending: already sorted.
        self.cache.replace(&mut self.store, keys, true)
    }

    impl_common_broadphase!();
    impl_rebuilt_proxies!();
}
