//! Broadphase: finding the pairs of objects whose axis-aligned boxes overlap, without testing
//! all N² pairs (the "broadphase N-body problem" of Coumans' SIGGRAPH 2010 talk).
//!
//! Every method implements [`BroadPhase`]: proxies (an [`Aabb`] plus a [`Filter`]) are created,
//! moved and removed through generational [`ProxyHandle`]s, and [`BroadPhase::update_pairs`]
//! returns the pairs added and removed since the previous update (the talk's "decompose
//! pairs"), in a deterministic order. Every method reports exactly the same pairs: those whose
//! *exact* boxes intersect (touching boxes included) and that pass the filter; internal
//! structures may use enlarged ("fat") boxes, but candidates are checked against the exact
//! boxes before they are reported.
//!
//! Methods:
//! - [`TreeBroadPhase`]: two dynamic AABB trees, moving and resting (Bullet's
//!   `btDbvtBroadphase`, Box2D v3's `b2BroadPhase`), built on [`DynamicTree`] (from
//!   [`crate::bvh`]);
//! - [`SweepAndPrune`]: incremental three-axis sweep-and-prune (Bullet's `btAxisSweep3`);
//! - [`SortSweep`]: one-axis sort-and-sweep from scratch each update, radix-sorted and
//!   parallel (OPCODE's box pruning; Game Physics Pearls ch. 7);
//! - [`HashGrid`]: an unbounded uniform grid (cells hashed "modulo" a table size);
//! - [`HierarchicalGrid`]: a hierarchy of grids for mixed object sizes;
//! - [`BruteForce`]: all pairs, the reference oracle of the tests.
//!
//! [`AnyBroadPhase`] is an enum over all of them (no `dyn`), chosen by [`Method`], and
//! [`overlapping_pairs`] is the one-call form.

mod any;
pub mod brute_force;
pub mod grid;
pub mod hgrid;
mod pair_keys;
mod pairs;
mod proxies;
pub mod radix;
pub mod sap;
pub mod sort_sweep;
mod tree_broadphase;
mod tree_search;

/// The dynamic AABB tree, moved to [`crate::bvh`] (compound shapes use it too).
pub use crate::bvh::{DynamicTree, HalfSpace, InsertStrategy, TreeProxy};
pub use any::{overlapping_pairs, AnyBroadPhase, Method};
pub use brute_force::BruteForce;
pub use grid::HashGrid;
pub use hgrid::HierarchicalGrid;
pub use pairs::{PairCache, PairChanges, UserFilter};
pub use proxies::ProxyStore;
pub use sap::SweepAndPrune;
pub use sort_sweep::SortSweep;
pub use tree_broadphase::TreeBroadPhase;

use crate::error::Result;
use crate::math::{Aabb, Vec3};
use serde::{Deserialize, Serialize};

/// A generational handle to a broadphase proxy: an index into dense arrays plus a generation
/// that is bumped whenever the index is reused, so a stale handle is detected instead of
/// silently naming another object (as Box2D's ids, `box2d/include/box2d/id.h`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct ProxyHandle {
    /// Slot index (dense, reused after removal).
    pub index: u32,
    /// Generation of the slot when the proxy was created.
    pub generation: u32,
}

impl ProxyHandle {
    /// The handle packed into one integer (generation in the high bits), for bindings.
    pub fn to_bits(self) -> u64 {
        ((self.generation as u64) << 32) | self.index as u64
    }

    /// The handle from [`ProxyHandle::to_bits`].
    pub fn from_bits(bits: u64) -> Self {
        ProxyHandle {
            index: bits as u32,
            generation: (bits >> 32) as u32,
        }
    }
}

/// Collision filtering data of a proxy. Two proxies `a`, `b` may pair when
/// `a.group & b.mask != 0 && b.group & a.mask != 0` (Box2D's category/mask rule) and they
/// are not both static.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Filter {
    /// Bits of the groups the proxy belongs to.
    pub group: u32,
    /// Bits of the groups the proxy may collide with.
    pub mask: u32,
    /// A static proxy never pairs with another static proxy (level geometry); the two-tree
    /// broadphase keeps static proxies in its resting tree.
    pub is_static: bool,
}

impl Default for Filter {
    fn default() -> Self {
        Filter {
            group: 1,
            mask: u32::MAX,
            is_static: false,
        }
    }
}

impl Filter {
    /// A filter with all groups, all masks, static or not.
    pub fn new(is_static: bool) -> Self {
        Filter {
            is_static,
            ..Filter::default()
        }
    }

    /// True when proxies with these filters may pair.
    #[inline]
    pub fn can_pair(&self, other: &Filter) -> bool {
        (self.group & other.mask) != 0
            && (other.group & self.mask) != 0
            && !(self.is_static && other.is_static)
    }
}

/// The interface every broadphase implements, so the collision world can use any of them.
///
/// Handles name proxies; a removed or never-created handle is rejected with
/// [`crate::CaromError::UnknownHandle`], and NaN or inverted boxes with
/// [`crate::CaromError::InvalidValue`]. Slots of removed proxies are reused only after the
/// next [`BroadPhase::update_pairs`], so the removed pairs it reports still carry the old
/// handles.
pub trait BroadPhase {
    /// A short name for reports ("tree", "sap", ...).
    fn name(&self) -> &'static str;

    /// Adds a proxy with box `aabb` and filter `filter`.
    fn create_proxy(&mut self, aabb: Aabb, filter: Filter) -> Result<ProxyHandle>;

    /// Moves a proxy to the box `aabb`; `displacement` is its predicted motion over the next
    /// step (used by methods that enlarge boxes along the motion, ignored by the others).
    fn update_proxy(&mut self, proxy: ProxyHandle, aabb: Aabb, displacement: Vec3) -> Result<()>;

    /// Removes a proxy; its pairs are reported as removed by the next update.
    fn remove_proxy(&mut self, proxy: ProxyHandle) -> Result<()>;

    /// Changes the filter of a proxy (takes effect at the next update).
    fn set_filter(&mut self, proxy: ProxyHandle, filter: Filter) -> Result<()>;

    /// Hints that a proxy went to sleep (`true`) or woke up (`false`). The two-tree broadphase
    /// migrates it between its trees; the others only check the handle.
    fn set_resting(&mut self, proxy: ProxyHandle, resting: bool) -> Result<()>;

    /// Installs (or clears) a user pair filter, called on candidate pairs that pass the
    /// group/mask test; a pair is kept when it returns `true`.
    fn set_user_filter(&mut self, filter: Option<UserFilter>);

    /// Finds the overlapping pairs and returns what changed since the previous update.
    fn update_pairs(&mut self) -> &PairChanges;

    /// The current pairs (as of the last update), sorted by (lower index, higher index).
    fn pairs(&self) -> Vec<(ProxyHandle, ProxyHandle)>;

    /// The number of current pairs.
    fn pair_count(&self) -> usize;

    /// The exact box of a proxy.
    fn aabb(&self, proxy: ProxyHandle) -> Result<Aabb>;

    /// The number of live proxies.
    fn len(&self) -> usize;

    /// True when there are no proxies.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Implements the bookkeeping methods of [`BroadPhase`] that every method shares, for a type
/// with fields `store: ProxyStore` and `cache: PairCache`.
macro_rules! impl_common_broadphase {
    () => {
        fn set_filter(
            &mut self,
            proxy: $crate::broadphase::ProxyHandle,
            filter: $crate::broadphase::Filter,
        ) -> $crate::error::Result<()> {
            self.store.set_filter(proxy, filter)
        }

        fn set_user_filter(&mut self, filter: Option<$crate::broadphase::UserFilter>) {
            self.cache.set_user_filter(filter);
        }

        fn pairs(
            &self,
        ) -> Vec<(
            $crate::broadphase::ProxyHandle,
            $crate::broadphase::ProxyHandle,
        )> {
            self.cache.pairs(&self.store)
        }

        fn pair_count(&self) -> usize {
            self.cache.len()
        }

        fn aabb(
            &self,
            proxy: $crate::broadphase::ProxyHandle,
        ) -> $crate::error::Result<$crate::math::Aabb> {
            self.store.aabb(proxy)
        }

        fn len(&self) -> usize {
            self.store.len()
        }
    };
}
pub(crate) use impl_common_broadphase;

/// Implements the proxy methods of [`BroadPhase`] (create, update, remove, set_resting) for
/// the methods that rebuild their structure from the stored boxes at every update (brute
/// force, sort-and-sweep, the grids): they only validate and store, in `store: ProxyStore`.
macro_rules! impl_rebuilt_proxies {
    () => {
        fn create_proxy(
            &mut self,
            aabb: $crate::math::Aabb,
            filter: $crate::broadphase::Filter,
        ) -> $crate::error::Result<$crate::broadphase::ProxyHandle> {
            self.store.create(aabb, filter)
        }

        fn update_proxy(
            &mut self,
            proxy: $crate::broadphase::ProxyHandle,
            aabb: $crate::math::Aabb,
            _displacement: $crate::math::Vec3,
        ) -> $crate::error::Result<()> {
            self.store.set_aabb(proxy, aabb).map(|_| ())
        }

        fn remove_proxy(
            &mut self,
            proxy: $crate::broadphase::ProxyHandle,
        ) -> $crate::error::Result<()> {
            self.store.remove(proxy).map(|_| ())
        }

        fn set_resting(
            &mut self,
            proxy: $crate::broadphase::ProxyHandle,
            _resting: bool,
        ) -> $crate::error::Result<()> {
            self.store.check(proxy).map(|_| ())
        }
    };
}
pub(crate) use impl_rebuilt_proxies;

/// Packs an unordered pair of slot indices into a sort key `(min << 32) | max`.
#[inline]
pub(crate) fn pair_key(a: u32, b: u32) -> u64 {
    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
    ((lo as u64) << 32) | hi as u64
}

/// The two slot indices of a [`pair_key`].
#[inline]
pub(crate) fn unpack_pair(key: u64) -> (u32, u32) {
    ((key >> 32) as u32, key as u32)
}
