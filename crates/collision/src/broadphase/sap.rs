//! Incremental three-axis sweep-and-prune (Baraff 1992; Bullet's `btAxisSweep3`,
//! `src/BulletCollision/BroadphaseCollision/btAxisSweep3Internal.h`).
//!
//! Each axis keeps the sorted list of the proxies' min and max endpoints. When a proxy moves,
//! its endpoints are moved by insertion sort; every time a min endpoint passes a max endpoint
//! (or the reverse) the two proxies start or stop overlapping on that axis, and the pair is
//! added to or removed from the overlap set if they overlap on the two other axes (tested on
//! endpoint *indices*). The talk: best when most objects hardly move, hard to parallelise.
//!
//! Endpoints are quantised to `u32` keys by an order-preserving map of the value rounded
//! outwards to `f32` (Terdiman's float-to-integer trick), so the structure is unbounded (no
//! world box, unlike Bullet's 16-bit quantisation) and conservative; reported pairs are
//! checked on the exact boxes. Ties put min endpoints before max endpoints, so touching boxes
//! overlap. Many proxies added at once (or a first update) rebuild the lists from scratch by
//! radix sort instead of N insertion sorts.

use super::radix::radix_sort_by_key;
use super::{impl_common_broadphase, pair_key, unpack_pair, BroadPhase, Filter, PairCache};
use super::{PairChanges, ProxyHandle, ProxyStore};
use crate::error::Result;
use crate::math::{real_ceil_key, real_floor_key, Aabb, Vec3};
use std::collections::HashSet;
use std::hash::{BuildHasherDefault, Hasher};

/// A multiplicative hasher for `u64` pair keys (Fibonacci hashing).
#[derive(Default, Clone, Copy)]
pub struct PairKeyHasher(u64);

impl Hasher for PairKeyHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0.rotate_left(5) ^ b as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        }
    }
    fn write_u64(&mut self, k: u64) {
        self.0 = (k ^ (k >> 29)).wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ (k >> 32);
    }
}

/// A set of pair keys (iteration order is never used for output).
pub type PairSet = HashSet<u64, BuildHasherDefault<PairKeyHasher>>;

const SENTINEL: u32 = u32::MAX;

#[derive(Debug, Clone, Copy)]
struct Endpoint {
    /// `((value << 1) | is_max) + 1`; 0 and `u64::MAX` are the sentinels.
    key: u64,
    handle: u32,
}

impl Endpoint {
    #[inline]
    fn is_max(&self) -> bool {
        (self.key - 1) & 1 == 1
    }
}

#[inline]
fn min_key(v: u32) -> u64 {
    ((v as u64) << 1) + 1
}

#[inline]
fn max_key(v: u32) -> u64 {
    (((v as u64) << 1) | 1) + 1
}

/// Endpoint indices of one proxy on the three axes.
#[derive(Debug, Clone, Copy, Default)]
struct Handle {
    min: [u32; 3],
    max: [u32; 3],
}

/// The incremental sweep-and-prune broadphase (see the module docs).
#[derive(Debug, Clone)]
pub struct SweepAndPrune {
    store: ProxyStore,
    cache: PairCache,
    axes: [Vec<Endpoint>; 3],
    handles: Vec<Handle>,
    in_lists: Vec<bool>,
    pending_add: Vec<u32>,
    removed_any: bool,
    overlaps: PairSet,
    /// The pair keys handed to the cache at each update (it hands back its previous array):
    /// a steady update allocates nothing.
    pairs: Vec<u64>,
    /// Pending additions above which the lists are rebuilt from scratch.
    pub rebuild_threshold: usize,
}

impl Default for SweepAndPrune {
    fn default() -> Self {
        Self::new()
    }
}

fn keys_of(b: &Aabb) -> ([u64; 3], [u64; 3]) {
    let mut lo = [0; 3];
    let mut hi = [0; 3];
    for a in 0..3 {
        lo[a] = min_key(real_floor_key(b.min[a]));
        hi[a] = max_key(real_ceil_key(b.max[a]));
    }
    (lo, hi)
}

impl SweepAndPrune {
    /// An empty broadphase.
    pub fn new() -> Self {
        let sentinels = || {
            vec![
                Endpoint {
                    key: 0,
                    handle: SENTINEL,
                },
                Endpoint {
                    key: u64::MAX,
                    handle: SENTINEL,
                },
            ]
        };
        SweepAndPrune {
            store: ProxyStore::new(),
            cache: PairCache::new(),
            axes: [sentinels(), sentinels(), sentinels()],
            handles: Vec::new(),
            in_lists: Vec::new(),
            pending_add: Vec::new(),
            removed_any: false,
            overlaps: PairSet::default(),
            pairs: Vec::new(),
            rebuild_threshold: 64,
        }
    }

    /// Number of pairs whose quantised boxes overlap (a superset of the reported pairs).
    pub fn overlap_count(&self) -> usize {
        self.overlaps.len()
    }

    /// Do `a` and `b` overlap on the two axes other than `axis` (by endpoint indices)?
    #[inline]
    fn overlap_others(&self, a: u32, b: u32, axis: usize) -> bool {
        let (ha, hb) = (&self.handles[a as usize], &self.handles[b as usize]);
        let (j, k) = ((axis + 1) % 3, (axis + 2) % 3);
        ha.min[j] < hb.max[j]
            && hb.min[j] < ha.max[j]
            && ha.min[k] < hb.max[k]
            && hb.min[k] < ha.max[k]
    }

    /// Moves endpoint `i` (a min) down while its predecessor is greater.
    fn sort_min_down(&mut self, axis: usize, mut i: usize, update: bool) {
        let cur = self.axes[axis][i];
        loop {
            let prev = self.axes[axis][i - 1];
            if prev.key <= cur.key {
                break;
            }
            if prev.is_max() {
                if update && self.overlap_others(cur.handle, prev.handle, axis) {
                    self.overlaps.insert(pair_key(cur.handle, prev.handle));
                }
                self.handles[prev.handle as usize].max[axis] += 1;
            } else {
                self.handles[prev.handle as usize].min[axis] += 1;
            }
            self.axes[axis][i] = prev;
            i -= 1;
        }
        self.axes[axis][i] = cur;
        self.handles[cur.handle as usize].min[axis] = i as u32;
    }

    /// Moves endpoint `i` (a min) up while its successor is smaller.
    fn sort_min_up(&mut self, axis: usize, mut i: usize, update: bool) {
        let cur = self.axes[axis][i];
        loop {
            let next = self.axes[axis][i + 1];
            if next.key >= cur.key {
                break;
            }
            if next.is_max() {
                if update && self.overlap_others(cur.handle, next.handle, axis) {
                    self.overlaps.remove(&pair_key(cur.handle, next.handle));
                }
                self.handles[next.handle as usize].max[axis] -= 1;
            } else {
                self.handles[next.handle as usize].min[axis] -= 1;
            }
            self.axes[axis][i] = next;
            i += 1;
        }
        self.axes[axis][i] = cur;
        self.handles[cur.handle as usize].min[axis] = i as u32;
    }

    /// Moves endpoint `i` (a max) down while its predecessor is greater.
    fn sort_max_down(&mut self, axis: usize, mut i: usize, update: bool) {
        let cur = self.axes[axis][i];
        loop {
            let prev = self.axes[axis][i - 1];
            if prev.key <= cur.key {
                break;
            }
            if !prev.is_max() {
                if update && self.overlap_others(cur.handle, prev.handle, axis) {
                    self.overlaps.remove(&pair_key(cur.handle, prev.handle));
                }
                self.handles[prev.handle as usize].min[axis] += 1;
            } else {
                self.handles[prev.handle as usize].max[axis] += 1;
            }
            self.axes[axis][i] = prev;
            i -= 1;
        }
        self.axes[axis][i] = cur;
        self.handles[cur.handle as usize].max[axis] = i as u32;
    }

    /// Moves endpoint `i` (a max) up while its successor is smaller.
    fn sort_max_up(&mut self, axis: usize, mut i: usize, update: bool) {
        let cur = self.axes[axis][i];
        loop {
            let next = self.axes[axis][i + 1];
            if next.key >= cur.key {
                break;
            }
            if !next.is_max() {
                if update && self.overlap_others(cur.handle, next.handle, axis) {
                    self.overlaps.insert(pair_key(cur.handle, next.handle));
                }
                self.handles[next.handle as usize].min[axis] -= 1;
            } else {
                self.handles[next.handle as usize].max[axis] -= 1;
            }
            self.axes[axis][i] = next;
            i += 1;
        }
        self.axes[axis][i] = cur;
        self.handles[cur.handle as usize].max[axis] = i as u32;
    }

    /// Bullet's `updateHandle`: set the new keys, grow first (min down, max up), then shrink.
    fn move_endpoints(&mut self, h: u32, b: &Aabb) {
        let (lo, hi) = keys_of(b);
        for axis in 0..3 {
            let hd = self.handles[h as usize];
            let (emin, emax) = (hd.min[axis] as usize, hd.max[axis] as usize);
            let old_lo = self.axes[axis][emin].key;
            let old_hi = self.axes[axis][emax].key;
            self.axes[axis][emin].key = lo[axis];
            self.axes[axis][emax].key = hi[axis];
            if lo[axis] < old_lo {
                self.sort_min_down(axis, emin, true);
            }
            if hi[axis] > old_hi {
                let e = self.handles[h as usize].max[axis] as usize;
                self.sort_max_up(axis, e, true);
            }
            if lo[axis] > old_lo {
                let e = self.handles[h as usize].min[axis] as usize;
                self.sort_min_up(axis, e, true);
            }
            if hi[axis] < old_hi {
                let e = self.handles[h as usize].max[axis] as usize;
                self.sort_max_down(axis, e, true);
            }
        }
    }

    /// Bullet's `addHandle`: append the endpoints just below the max sentinel and sort them
    /// down; pairs are updated on the last axis only (the others are already in place).
    fn insert_handle(&mut self, h: u32) {
        let (lo, hi) = keys_of(&self.store.aabbs()[h as usize]);
        for axis in 0..3 {
            let list = &mut self.axes[axis];
            let n = list.len();
            let sentinel = list[n - 1];
            list[n - 1] = Endpoint {
                key: lo[axis],
                handle: h,
            };
            list.push(Endpoint {
                key: hi[axis],
                handle: h,
            });
            list.push(sentinel);
            self.handles[h as usize].min[axis] = (n - 1) as u32;
            self.handles[h as usize].max[axis] = n as u32;
        }
        for axis in 0..3 {
            let update = axis == 2;
            let e = self.handles[h as usize].min[axis] as usize;
            self.sort_min_down(axis, e, update);
            let e = self.handles[h as usize].max[axis] as usize;
            self.sort_max_down(axis, e, update);
        }
        self.in_lists[h as usize] = true;
    }

    /// Rebuilds the lists of all live proxies by radix sort and the overlap set by a sweep
    /// over axis 0.
    fn rebuild(&mut self) {
        let live = self.store.live_indices();
        let boxes = self.store.aabbs();
        let mut scratch = Vec::new();
        for axis in 0..3 {
            let mut list: Vec<Endpoint> = Vec::with_capacity(2 * live.len() + 2);
            for &h in &live {
                let b = &boxes[h as usize];
                list.push(Endpoint {
                    key: min_key(real_floor_key(b.min[axis])),
                    handle: h,
                });
                list.push(Endpoint {
                    key: max_key(real_ceil_key(b.max[axis])),
                    handle: h,
                });
            }
            radix_sort_by_key(&mut list, &mut scratch, |e| e.key);
            list.insert(
                0,
                Endpoint {
                    key: 0,
                    handle: SENTINEL,
                },
            );
            list.push(Endpoint {
                key: u64::MAX,
                handle: SENTINEL,
            });
            for (i, e) in list.iter().enumerate().skip(1).take(2 * live.len()) {
                let hd = &mut self.handles[e.handle as usize];
                if e.is_max() {
                    hd.max[axis] = i as u32;
                } else {
                    hd.min[axis] = i as u32;
                }
            }
            self.axes[axis] = list;
        }
        for &h in &live {
            self.in_lists[h as usize] = true;
        }
        // Sweep axis 0 with an active list.
        self.overlaps.clear();
        let mut active: Vec<u32> = Vec::new();
        let mut slot = vec![0u32; self.handles.len()];
        let list = std::mem::take(&mut self.axes[0]);
        for e in &list[1..list.len() - 1] {
            if e.is_max() {
                let s = slot[e.handle as usize] as usize;
                active.swap_remove(s);
                if s < active.len() {
                    slot[active[s] as usize] = s as u32;
                }
            } else {
                for &a in &active {
                    if self.overlap_others(e.handle, a, 0) {
                        self.overlaps.insert(pair_key(e.handle, a));
                    }
                }
                slot[e.handle as usize] = active.len() as u32;
                active.push(e.handle);
            }
        }
        self.axes[0] = list;
    }

    /// Drops the endpoints and pairs of removed proxies (one pass over each list).
    fn purge_removed(&mut self) {
        let alive = self.store.alive();
        self.overlaps.retain(|&k| {
            let (a, b) = unpack_pair(k);
            alive[a as usize] && alive[b as usize]
        });
        for axis in 0..3 {
            let list = &mut self.axes[axis];
            list.retain(|e| e.handle == SENTINEL || alive[e.handle as usize]);
            for (i, e) in list.iter().enumerate() {
                if e.handle != SENTINEL {
                    let hd = &mut self.handles[e.handle as usize];
                    if e.is_max() {
                        hd.max[axis] = i as u32;
                    } else {
                        hd.min[axis] = i as u32;
                    }
                }
            }
        }
        for (i, flag) in self.in_lists.iter_mut().enumerate() {
            *flag &= alive[i];
        }
    }
}

impl BroadPhase for SweepAndPrune {
    fn name(&self) -> &'static str {
        "sap"
    }

    fn create_proxy(&mut self, aabb: Aabb, filter: Filter) -> Result<ProxyHandle> {
        let h = self.store.create(aabb, filter)?;
        let i = h.index as usize;
        if i == self.handles.len() {
            self.handles.push(Handle::default());
            self.in_lists.push(false);
        }
        self.pending_add.push(h.index);
        Ok(h)
    }

    fn update_proxy(&mut self, proxy: ProxyHandle, aabb: Aabb, _displacement: Vec3) -> Result<()> {
        self.store.set_aabb(proxy, aabb)?;
        if self.in_lists[proxy.index as usize] {
            self.move_endpoints(proxy.index, &aabb);
        }
        Ok(())
    }

    fn remove_proxy(&mut self, proxy: ProxyHandle) -> Result<()> {
        self.store.remove(proxy)?;
        self.removed_any = true;
        Ok(())
    }

    fn set_resting(&mut self, proxy: ProxyHandle, _resting: bool) -> Result<()> {
        self.store.check(proxy).map(|_| ())
    }

    fn update_pairs(&mut self) -> &PairChanges {
        if self.removed_any {
            self.purge_removed();
            self.removed_any = false;
        }
        let mut pending = std::mem::take(&mut self.pending_add);
        pending.retain(|&h| self.store.is_alive(h as usize));
        if pending.len() > self.rebuild_threshold {
            self.rebuild();
        } else {
            for &h in &pending {
                self.insert_handle(h);
            }
        }
        pending.clear();
        self.pending_add = pending;
        let boxes = self.store.aabbs();
        let mut keys = std::mem::take(&mut self.pairs);
        keys.clear();
        keys.extend(self.overlaps.iter().copied().filter(|&k| {
            let (a, b) = unpack_pair(k);
            boxes[a as usize].intersects(&boxes[b as usize])
        }));
        let changes = self
            .cache
            .replace_reusing(&mut self.store, &mut keys, false);
        self.pairs = keys;
        changes
    }

    impl_common_broadphase!();
}
