//! The brute-force all-pairs broadphase: the reference every other method is tested against
//! (as Jolt keeps `BroadPhaseBruteForce` beside its quad-tree broadphase).

use super::{impl_common_broadphase, pair_key, BroadPhase, Filter, PairCache, PairChanges};
use super::{ProxyHandle, ProxyStore};
use crate::error::Result;
use crate::math::{Aabb, Vec3};

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

    fn create_proxy(&mut self, aabb: Aabb, filter: Filter) -> Result<ProxyHandle> {
        self.store.create(aabb, filter)
    }

    fn update_proxy(&mut self, proxy: ProxyHandle, aabb: Aabb, _displacement: Vec3) -> Result<()> {
        self.store.set_aabb(proxy, aabb).map(|_| ())
    }

    fn remove_proxy(&mut self, proxy: ProxyHandle) -> Result<()> {
        self.store.remove(proxy).map(|_| ())
    }

    fn set_resting(&mut self, proxy: ProxyHandle, _resting: bool) -> Result<()> {
        self.store.check(proxy).map(|_| ())
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
}
