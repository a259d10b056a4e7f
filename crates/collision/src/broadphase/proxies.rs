//! The proxy slots every broadphase shares: boxes, filters and generational handles.

use super::{Filter, ProxyHandle};
use crate::error::{CaromError, Result};
use crate::math::{check_aabb, Aabb};

/// Dense storage of proxies: slot `i` holds the exact box, the filter and the generation of
/// the proxy with index `i`. Removed slots are recycled only after [`ProxyStore::end_frame`]
/// (called by `update_pairs`), so pairs reported as removed still name valid old handles.
#[derive(Debug, Clone, Default)]
pub struct ProxyStore {
    aabbs: Vec<Aabb>,
    filters: Vec<Filter>,
    generations: Vec<u32>,
    alive: Vec<bool>,
    free: Vec<u32>,
    pending_free: Vec<u32>,
    len: usize,
}

impl ProxyStore {
    /// An empty store.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a proxy after validating its box.
    pub fn create(&mut self, aabb: Aabb, filter: Filter) -> Result<ProxyHandle> {
        check_aabb(&aabb)?;
        self.len += 1;
        if let Some(index) = self.free.pop() {
            let i = index as usize;
            self.generations[i] = self.generations[i].wrapping_add(1);
            self.aabbs[i] = aabb;
            self.filters[i] = filter;
            self.alive[i] = true;
            return Ok(ProxyHandle {
                index,
                generation: self.generations[i],
            });
        }
        let index = u32::try_from(self.aabbs.len())
            .map_err(|_| CaromError::invalid("proxy count", self.aabbs.len(), "too many"))?;
        self.aabbs.push(aabb);
        self.filters.push(filter);
        self.generations.push(0);
        self.alive.push(true);
        Ok(ProxyHandle {
            index,
            generation: 0,
        })
    }

    /// Checks that `proxy` names a live proxy.
    pub fn check(&self, proxy: ProxyHandle) -> Result<usize> {
        let i = proxy.index as usize;
        if i < self.alive.len() && self.alive[i] && self.generations[i] == proxy.generation {
            Ok(i)
        } else {
            Err(CaromError::UnknownHandle(format!("{proxy:?}")))
        }
    }

    /// Sets the box of a live proxy (validated) and returns the previous one.
    pub fn set_aabb(&mut self, proxy: ProxyHandle, aabb: Aabb) -> Result<Aabb> {
        let i = self.check(proxy)?;
        check_aabb(&aabb)?;
        Ok(std::mem::replace(&mut self.aabbs[i], aabb))
    }

    /// Sets the box of slot `i`, which the caller knows to be live, with a box it has
    /// validated (the two-tree broadphase's per-step path from the collision world).
    #[inline]
    pub(crate) fn set_aabb_trusted(&mut self, i: usize, aabb: Aabb) {
        debug_assert!(self.alive[i] && check_aabb(&aabb).is_ok());
        self.aabbs[i] = aabb;
    }

    /// Sets the filter of a live proxy.
    pub fn set_filter(&mut self, proxy: ProxyHandle, filter: Filter) -> Result<()> {
        let i = self.check(proxy)?;
        self.filters[i] = filter;
        Ok(())
    }

    /// Removes a live proxy; its slot is recycled after the next [`ProxyStore::end_frame`].
    pub fn remove(&mut self, proxy: ProxyHandle) -> Result<usize> {
        let i = self.check(proxy)?;
        self.alive[i] = false;
        self.pending_free.push(proxy.index);
        self.len -= 1;
        Ok(i)
    }

    /// Makes the slots removed since the last call reusable (in a deterministic order).
    pub fn end_frame(&mut self) {
        if self.pending_free.is_empty() {
            return;
        }
        // Descending, so popping from the end of `free` takes the lowest index first. The
        // indices are distinct, so the unstable sort is deterministic.
        self.free.append(&mut self.pending_free);
        self.free.sort_unstable_by(|a, b| b.cmp(a));
    }

    /// The box of a live proxy.
    pub fn aabb(&self, proxy: ProxyHandle) -> Result<Aabb> {
        Ok(self.aabbs[self.check(proxy)?])
    }

    /// The handle of the proxy in slot `index` (live, or removed since the last frame).
    #[inline]
    pub fn handle(&self, index: u32) -> ProxyHandle {
        ProxyHandle {
            index,
            generation: self.generations[index as usize],
        }
    }

    /// All boxes by slot (dead slots hold stale boxes; see [`ProxyStore::is_alive`]).
    #[inline]
    pub fn aabbs(&self) -> &[Aabb] {
        &self.aabbs
    }

    /// All filters by slot.
    #[inline]
    pub fn filters(&self) -> &[Filter] {
        &self.filters
    }

    /// True when slot `index` holds a live proxy.
    #[inline]
    pub fn is_alive(&self, index: usize) -> bool {
        self.alive[index]
    }

    /// Liveness of every slot.
    #[inline]
    pub fn alive(&self) -> &[bool] {
        &self.alive
    }

    /// Number of slots (live or not).
    #[inline]
    pub fn capacity(&self) -> usize {
        self.aabbs.len()
    }

    /// Number of live proxies.
    #[inline]
    pub fn len(&self) -> usize {
        self.len
    }

    /// True when there is no live proxy.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Indices of the live proxies, ascending.
    pub fn live_indices(&self) -> Vec<u32> {
        (0..self.alive.len() as u32)
            .filter(|&i| self.alive[i as usize])
            .collect()
    }

    /// [`ProxyStore::live_indices`] into a reused buffer (cleared first).
    pub fn live_indices_into(&self, out: &mut Vec<u32>) {
        out.clear();
        out.extend((0..self.alive.len() as u32).filter(|&i| self.alive[i as usize]));
    }
}
