//! The narrowphase stage of the collision pipeline: one persistent manifold per broadphase
//! pair (created when the pair is added, dropped when it is removed), updated every step in
//! parallel over pairs (rayon, behind the `parallel` feature; the result does not depend on
//! the thread count), with contact events (begin, persist, end) in pair order. Sensor
//! objects report overlap only: their pairs get events but no contact points.

use super::dispatcher::Dispatcher;
use super::manifold::ContactManifold;
use crate::error::Result;
use crate::math::{Isometry, Real, Vec3};
use crate::shape::Shape;
use std::collections::BTreeSet;

/// One pair's state: its manifold and whether it touched at the last step.
#[derive(Debug, Clone, PartialEq)]
pub struct PairContact<H> {
    /// First object (the manifold's A).
    pub a: H,
    /// Second object (the manifold's B).
    pub b: H,
    /// The persistent manifold (empty for sensor pairs).
    pub manifold: ContactManifold,
    /// True when the shapes touched (a point at distance <= 0, or overlap for sensors).
    pub touching: bool,
    /// True when one of the objects is a sensor.
    pub sensor: bool,
    /// True when the pair is excluded from contact generation
    /// ([`NarrowPhase::set_excluded`]): its manifold stays empty and it reports no events.
    pub excluded: bool,
}

/// What the narrowphase needs to know about one object at a step.
#[derive(Debug, Clone, Copy)]
pub struct NarrowObject<'s> {
    /// The shape.
    pub shape: &'s Shape,
    /// Its world pose.
    pub pose: Isometry,
    /// Speculative margin of the object: a pair generates points up to
    /// `max(config.prediction, margin_a + margin_b)` apart, less the linear motions' share
    /// (see `motion`; [`super::Dispatcher::update_manifold_with_prediction`]).
    pub margin: Real,
    /// Linear displacement of the object over the coming step, included in `margin`: a
    /// pair's speculative distance counts the relative displacement of its objects,
    /// `margin_a - |motion_a| + margin_b - |motion_b| + |motion_a - motion_b|`, not the sum
    /// of their own.
    pub motion: Vec3,
    /// The displacement may fall anywhere between zero and `motion` (a contact may stop the
    /// object): the pair counts the largest relative displacement of those cases
    /// (`CollisionObject::may_stop` in the collision world).
    pub may_stop: bool,
    /// False for objects that do not move (resting or static): a pair of two inactive
    /// objects keeps its manifold (and impulses) unchanged, as sleeping pairs in Box2D and
    /// Bullet are not updated.
    pub active: bool,
}

impl<'s> NarrowObject<'s> {
    /// An active object without speculative margin.
    pub fn new(shape: &'s Shape, pose: Isometry) -> Self {
        NarrowObject {
            shape,
            pose,
            margin: 0.0,
            motion: Vec3::ZERO,
            may_stop: false,
            active: true,
        }
    }
}

/// What happened to a pair's contact at a step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ContactEventKind {
    /// The pair started touching.
    Begin,
    /// The pair still touches.
    Persist,
    /// The pair stopped touching (or was removed while touching).
    End,
}

/// A contact event of one pair.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ContactEvent<H> {
    /// First object.
    pub a: H,
    /// Second object.
    pub b: H,
    /// What happened.
    pub kind: ContactEventKind,
    /// True for sensor pairs.
    pub sensor: bool,
}

/// Manifolds for every broadphase pair, keyed by object handles `H` (ordered pairs).
///
/// The pairs live in one vector sorted by `(a, b)`, the pair order: a step removes and
/// inserts the broadphase's changes in place (one merge walk, then whole runs of pairs moved
/// by block swaps; runs that keep their place do not move) and
/// updates the manifolds over the slice in parallel, so the steady state allocates nothing
/// and the solver reads the manifolds contiguously. (A `BTreeMap` did the same with a node
/// walk per pair and three vectors collected per step.)
#[derive(Debug, Clone)]
pub struct NarrowPhase<H: Ord> {
    pairs: Vec<PairContact<H>>,
    /// `(a, b)` of every pair, in pair order: the searches of a step's changes read these
    /// 16 bytes per pair (L2-resident for tens of thousands of pairs) instead of striding
    /// through the 192-byte pairs. On "3000 fall" (~16 k pairs, ~150 added and ~100
    /// removed a step), the changes took 0.33–0.48 ms a step instead of 0.47–0.60.
    keys: Vec<(H, H)>,
    sensors: BTreeSet<H>,
    /// Excluded object pairs `(lower, higher)`, sorted ([`NarrowPhase::set_excluded`]).
    excluded: Vec<(H, H)>,
    events: Vec<ContactEvent<H>>,
    /// Per pair, the event of this step's update, written by the parallel update so that
    /// the serial pass that reports events reads only the pairs that have one (reused
    /// buffer). On "3000 fall" (about 6 k events of 16 k pairs) that pass went from
    /// 0.125–0.128 to 0.096–0.103 ms a step.
    event_kinds: Vec<Option<ContactEventKind>>,
    /// Indices of the pairs to remove, then the sorted pairs to add (reused buffers).
    dead: Vec<usize>,
    fresh: Vec<(H, H)>,
    /// Runs of kept pairs to move (`start`, `end`, destination) and the slots of the new
    /// pairs, in pair order (reused buffers of [`NarrowPhase::apply_changes`]).
    runs: Vec<(usize, usize, usize)>,
    slots: Vec<usize>,
    /// The last step changed no pair, found no object active and reported only `Persist`
    /// events, and no call has touched the pairs since: another such step would rebuild the
    /// same events, so it hands the last ones back instead (a world whose bodies all sleep,
    /// "1000 stack" after its first second: 0.016 ms a step for ~3,200 pairs before). Every
    /// `&mut` call that can change a pair, an exclusion, a sensor or the events clears it.
    settled: bool,
    /// The dispatcher (algorithms and manifold configuration).
    pub dispatcher: Dispatcher,
}

impl<H: Ord> Default for NarrowPhase<H> {
    fn default() -> Self {
        NarrowPhase {
            pairs: Vec::new(),
            keys: Vec::new(),
            sensors: BTreeSet::new(),
            excluded: Vec::new(),
            events: Vec::new(),
            event_kinds: Vec::new(),
            dead: Vec::new(),
            fresh: Vec::new(),
            runs: Vec::new(),
            slots: Vec::new(),
            settled: false,
            dispatcher: Dispatcher::default(),
        }
    }
}

fn new_pair<H>(a: H, b: H) -> PairContact<H> {
    PairContact {
        a,
        b,
        manifold: ContactManifold::new(),
        touching: false,
        sensor: false,
        excluded: false,
    }
}

/// Moves the run `v[s..e]` down to `v[d..]` (`d < s`) when `v[d..s]` holds only pairs to
/// overwrite: whole blocks are swapped (at most `s - d` records each), so a run moves in a
/// few block swaps rather than record by record, and the displaced records end in `v[..e]`'s
/// tail. A shift by one rotates the run (one memmove).
fn move_run_down<T>(v: &mut [T], mut s: usize, e: usize, mut d: usize) {
    let gap = s - d;
    if gap == 1 {
        v[d..e].rotate_left(1);
        return;
    }
    while s < e {
        let c = gap.min(e - s);
        let (lo, hi) = v.split_at_mut(s);
        lo[d..d + c].swap_with_slice(&mut hi[..c]);
        s += c;
        d += c;
    }
}

/// Moves the run `v[s..e]` up to start at `d` (`d > s`) when `v[e..d + e - s]` holds only
/// pairs to overwrite (the mirror of [`move_run_down`]).
fn move_run_up<T>(v: &mut [T], s: usize, mut e: usize, d: usize) {
    let gap = d - s;
    if gap == 1 {
        v[s..e + 1].rotate_right(1);
        return;
    }
    while e > s {
        let c = gap.min(e - s);
        let (lo, hi) = v.split_at_mut(e);
        lo[e - c..].swap_with_slice(&mut hi[gap - c..gap]);
        e -= c;
    }
}

/// The pair `(a, b)` in either order, as stored in [`NarrowPhase::set_excluded`]'s list.
fn ordered<H: Ord>(a: H, b: H) -> (H, H) {
    if a <= b {
        (a, b)
    } else {
        (b, a)
    }
}

/// True when the sorted exclusion list holds the pair `(a, b)` (either order).
fn is_in<H: Copy + Ord>(excluded: &[(H, H)], a: H, b: H) -> bool {
    !excluded.is_empty() && excluded.binary_search(&ordered(a, b)).is_ok()
}

impl<H: Copy + Ord + Send + Sync> NarrowPhase<H> {
    /// An empty narrowphase using `dispatcher`.
    pub fn new(dispatcher: Dispatcher) -> Self {
        NarrowPhase {
            dispatcher,
            ..Default::default()
        }
    }

    /// Marks an object as a sensor (overlap events only) or not; applies to pairs added
    /// afterwards and to existing pairs at the next step.
    pub fn set_sensor(&mut self, h: H, sensor: bool) {
        self.settled = false;
        if sensor {
            self.sensors.insert(h);
        } else {
            self.sensors.remove(&h);
        }
    }

    fn find(&self, a: H, b: H) -> std::result::Result<usize, usize> {
        self.keys.binary_search(&(a, b))
    }

    /// Creates the manifold of pair `(a, b)` (nothing when it exists).
    pub fn add_pair(&mut self, a: H, b: H) {
        self.settled = false;
        if let Err(i) = self.find(a, b) {
            let mut p = new_pair(a, b);
            p.excluded = is_in(&self.excluded, a, b);
            self.pairs.insert(i, p);
            self.keys.insert(i, (a, b));
        }
    }

    /// Excludes the pair of objects `a`, `b` (either order) from contact generation, or
    /// lets it back in. An excluded pair stays in the pair list (the broadphase still
    /// reports it) but is never updated: its manifold is emptied, it never touches, so it
    /// hands no point to a solver and reports no event (an `End` at the next step if it was
    /// touching). The exclusion applies to the pair present now and to the pair the
    /// broadphase may add later, until it is lifted; lifted, the pair is generated afresh at
    /// the next step. A dynamics pipeline excludes the bodies of a joint that disables their
    /// collisions, so they never reach contact generation (Bullet's
    /// `btCollisionObject::setIgnoreCollisionCheck`, checked by the dispatcher's
    /// `needsCollision`; Rapier skips pairs whose joint has contacts disabled). Excluding
    /// costs one flag test per pair and step; the exclusion list is searched only when a
    /// pair is added.
    pub fn set_excluded(&mut self, a: H, b: H, excluded: bool) {
        self.settled = false;
        let key = ordered(a, b);
        match (self.excluded.binary_search(&key), excluded) {
            (Err(i), true) => self.excluded.insert(i, key),
            (Ok(i), false) => {
                self.excluded.remove(i);
            }
            _ => {}
        }
        for (x, y) in [(a, b), (b, a)] {
            if let Ok(i) = self.find(x, y) {
                let p = &mut self.pairs[i];
                p.excluded = excluded;
                if excluded {
                    // `touching` stays: the next step reports the `End`.
                    p.manifold.clear();
                }
            }
        }
    }

    /// True when the pair `a`, `b` (either order) is excluded ([`NarrowPhase::set_excluded`]).
    pub fn is_excluded(&self, a: H, b: H) -> bool {
        is_in(&self.excluded, a, b)
    }

    /// Lifts every exclusion that names `h` (an object that was removed).
    pub fn clear_exclusions_of(&mut self, h: H) {
        self.settled = false;
        self.excluded.retain(|&(a, b)| a != h && b != h);
    }

    /// Drops the manifold of pair `(a, b)`; an `End` event is emitted if it touched.
    pub fn remove_pair(&mut self, a: H, b: H) {
        self.settled = false;
        if let Ok(i) = self.find(a, b) {
            let p = self.pairs.remove(i);
            self.keys.remove(i);
            if p.touching {
                self.events.push(ContactEvent {
                    a,
                    b,
                    kind: ContactEventKind::End,
                    sensor: p.sensor,
                });
            }
        }
    }

    /// Removes the pairs `removed` (events in that order) and inserts `added`, keeping the
    /// pair order, in place: O(pairs) moves, no allocation once the buffers have grown.
    fn apply_changes(&mut self, added: &[(H, H)], removed: &[(H, H)]) {
        self.dead.clear();
        for &(a, b) in removed {
            if let Ok(i) = self.find(a, b) {
                let p = &mut self.pairs[i];
                if p.touching {
                    // Once, even if `removed` names the pair twice.
                    p.touching = false;
                    self.events.push(ContactEvent {
                        a,
                        b,
                        kind: ContactEventKind::End,
                        sensor: p.sensor,
                    });
                }
                self.dead.push(i);
            }
        }
        self.dead.sort_unstable();
        self.dead.dedup();
        let (pairs, keys, dead) = (&mut self.pairs, &mut self.keys, &self.dead);
        // A pair removed and added again in the same step is created afresh.
        self.fresh.clear();
        self.fresh.extend(added.iter().copied().filter(
            |&(a, b)| match keys.binary_search(&(a, b)) {
                Ok(i) => dead.binary_search(&i).is_ok(),
                Err(_) => true,
            },
        ));
        if dead.is_empty() && self.fresh.is_empty() {
            return;
        }
        // Unique keys: an unstable sort is deterministic.
        self.fresh.sort_unstable();
        self.fresh.dedup();
        let fresh = &self.fresh;
        // One merge walk: the runs of kept pairs between removals and insertions, with their
        // destinations, and the slots of the new pairs.
        let (runs, slots) = (&mut self.runs, &mut self.slots);
        runs.clear();
        slots.clear();
        let n = pairs.len();
        let pos = |j: usize| {
            fresh
                .get(j)
                .map_or(n, |&k| keys.partition_point(|&p| p < k))
        };
        let (mut src, mut out, mut di, mut fj) = (0, 0, 0, 0);
        let mut nf = pos(0);
        loop {
            let nd = dead.get(di).copied().unwrap_or(n);
            let stop = nd.min(nf);
            if stop > src {
                if out != src {
                    runs.push((src, stop, out));
                }
                out += stop - src;
                src = stop;
            }
            if fj < fresh.len() && nf == src {
                slots.push(out);
                out += 1;
                fj += 1;
                nf = pos(fj);
            } else if di < dead.len() && nd == src {
                src += 1;
                di += 1;
            } else {
                break;
            }
        }
        if out > n {
            let (a0, b0) = fresh[0];
            pairs.resize_with(out, || new_pair(a0, b0));
            keys.resize(out, (a0, b0));
        }
        // Runs moving down go first, lowest first; runs moving up then, highest first: a
        // run's destination then holds only removed pairs, vacated slots or new slots.
        for &(s, e, d) in runs.iter().filter(|r| r.2 < r.0) {
            move_run_down(pairs, s, e, d);
            move_run_down(keys, s, e, d);
        }
        for &(s, e, d) in runs.iter().rev().filter(|r| r.2 > r.0) {
            move_run_up(pairs, s, e, d);
            move_run_up(keys, s, e, d);
        }
        for (&w, &(a, b)) in slots.iter().zip(fresh) {
            // Reuses the removed pair's point buffer when there is one.
            keys[w] = (a, b);
            let p = &mut pairs[w];
            p.a = a;
            p.b = b;
            p.manifold.clear();
            p.touching = false;
            p.sensor = false;
            p.excluded = is_in(&self.excluded, a, b);
        }
        pairs.truncate(out);
        keys.truncate(out);
    }

    /// One step: pairs `removed` are dropped and `added` created, then every manifold is
    /// updated from the shapes and poses given by `lookup` (pairs whose objects are unknown,
    /// or both inactive, are skipped and keep their state). Returns the events of this step,
    /// in pair order (removals first). On an error (the first in pair order, whatever the
    /// thread count) the manifolds may be partly updated and no event is reported.
    pub fn step<'s, F>(
        &mut self,
        added: &[(H, H)],
        removed: &[(H, H)],
        lookup: F,
    ) -> Result<&[ContactEvent<H>]>
    where
        F: Fn(H) -> Option<NarrowObject<'s>> + Sync,
    {
        self.step_with(added, removed, lookup, true)
    }

    /// [`NarrowPhase::step`], told whether any object may be active. With `any_active`
    /// false (every object resting or static: a world whose bodies all sleep), no pair
    /// can be updated, so none is looked up: excluded pairs are cleared, every other pair
    /// keeps its state, and the events are those `step` would report (a touching pair
    /// persists).
    pub fn step_with<'s, F>(
        &mut self,
        added: &[(H, H)],
        removed: &[(H, H)],
        lookup: F,
        any_active: bool,
    ) -> Result<&[ContactEvent<H>]>
    where
        F: Fn(H) -> Option<NarrowObject<'s>> + Sync,
    {
        let quiet = !any_active && added.is_empty() && removed.is_empty();
        if quiet && self.settled {
            return Ok(&self.events);
        }
        self.settled = false;
        self.events.clear();
        self.apply_changes(added, removed);
        debug_assert!(self
            .pairs
            .iter()
            .map(|p| (p.a, p.b))
            .eq(self.keys.iter().copied()));
        let dispatcher = &self.dispatcher;
        let sensors = &self.sensors;
        let update_pair = |p: &mut PairContact<H>| -> Result<()> {
            if p.excluded {
                p.manifold.clear();
                p.touching = false;
                return Ok(());
            }
            let (Some(oa), Some(ob)) = (lookup(p.a), lookup(p.b)) else {
                return Ok(());
            };
            if !(oa.active || ob.active) {
                return Ok(());
            }
            let (sa, pa, sb, pb) = (oa.shape, oa.pose, ob.shape, ob.pose);
            p.sensor = !sensors.is_empty() && (sensors.contains(&p.a) || sensors.contains(&p.b));
            if p.sensor {
                p.manifold.clear();
                let g = dispatcher.generate(sa, sb, &pa.inv_mul(&pb), true)?;
                p.touching = g.contacts.iter().any(|(c, _)| c.distance <= 0.0);
            } else {
                // Relative motion: bodies moving together cannot meet through it, unless
                // one may stop (the distance is convex in the two displacements, so the
                // largest relative one is at an end of their ranges).
                let own = |o: &NarrowObject| (o.margin - o.motion.length()).max(0.0);
                let mut relative = (oa.motion - ob.motion).length();
                if oa.may_stop {
                    relative = relative.max(ob.motion.length());
                }
                if ob.may_stop {
                    relative = relative.max(oa.motion.length());
                }
                let prediction = own(&oa) + own(&ob) + relative;
                dispatcher.update_manifold_with_prediction(
                    sa,
                    &pa,
                    sb,
                    &pb,
                    &mut p.manifold,
                    prediction,
                )?;
                p.touching = p.manifold.min_distance().is_some_and(|d| d <= 0.0);
            }
            Ok(())
        };
        let update = |p: &mut PairContact<H>, kind: &mut Option<ContactEventKind>| {
            let was = p.touching;
            update_pair(p)?;
            *kind = event_kind(was, p.touching);
            Ok(())
        };
        let kinds = &mut self.event_kinds;
        kinds.clear();
        kinds.resize(self.pairs.len(), None);
        if !any_active {
            for (p, kind) in self.pairs.iter_mut().zip(kinds.iter_mut()) {
                let was = p.touching;
                if p.excluded {
                    p.manifold.clear();
                    p.touching = false;
                }
                *kind = event_kind(was, p.touching);
            }
        }
        #[cfg(feature = "parallel")]
        let first_error = if !any_active {
            None
        } else {
            use rayon::prelude::*;
            self.pairs
                .par_iter_mut()
                .zip(kinds.par_iter_mut())
                .enumerate()
                .filter_map(|(i, (p, w))| update(p, w).err().map(|e| (i, e)))
                .min_by_key(|(i, _)| *i)
        };
        #[cfg(not(feature = "parallel"))]
        let first_error = self
            .pairs
            .iter_mut()
            .zip(kinds.iter_mut())
            .enumerate()
            .filter(|_| any_active)
            .find_map(|(i, (p, w))| update(p, w).err().map(|e| (i, e)));
        if let Some((_, e)) = first_error {
            return Err(e);
        }
        for (p, &kind) in self.pairs.iter().zip(&self.event_kinds) {
            let Some(kind) = kind else {
                continue;
            };
            self.events.push(ContactEvent {
                a: p.a,
                b: p.b,
                kind,
                sensor: p.sensor,
            });
        }
        self.settled = quiet
            && self
                .events
                .iter()
                .all(|e| e.kind == ContactEventKind::Persist);
        Ok(&self.events)
    }

    /// The events of the last step.
    pub fn events(&self) -> &[ContactEvent<H>] {
        &self.events
    }

    /// Every pair with its manifold, in pair order.
    pub fn pairs(&self) -> impl Iterator<Item = &PairContact<H>> {
        self.pairs.iter()
    }

    /// The pairs with at least one contact point, in pair order (the solver's input).
    pub fn manifolds(&self) -> impl Iterator<Item = &PairContact<H>> {
        self.pairs.iter().filter(|p| !p.manifold.is_empty())
    }

    /// Mutable manifolds in pair order (for the solver to store accumulated impulses).
    pub fn manifolds_mut(&mut self) -> impl Iterator<Item = &mut PairContact<H>> {
        self.settled = false;
        self.pairs.iter_mut().filter(|p| !p.manifold.is_empty())
    }

    /// Every pair with its manifold, in pair order, as a slice (to cut it into chunks).
    pub fn pair_slice(&self) -> &[PairContact<H>] {
        &self.pairs
    }

    /// Every pair, mutable, in pair order, as a slice (to write impulses back in parallel).
    /// Only the manifolds and flags are meant to be written: changing a pair's `a` or `b`
    /// breaks the pair order the narrowphase searches.
    pub fn pair_slice_mut(&mut self) -> &mut [PairContact<H>] {
        self.settled = false;
        &mut self.pairs
    }

    /// Every pair, mutable, in pair order (to restore saved manifolds from a snapshot).
    pub fn pairs_mut(&mut self) -> impl Iterator<Item = &mut PairContact<H>> {
        self.settled = false;
        self.pairs.iter_mut()
    }

    /// Replaces the events of the last step (to restore a snapshot).
    pub fn restore_events(&mut self, events: Vec<ContactEvent<H>>) {
        self.settled = false;
        self.events = events;
    }

    /// The pair `(a, b)`.
    pub fn get(&self, a: H, b: H) -> Option<&PairContact<H>> {
        self.find(a, b).ok().map(|i| &self.pairs[i])
    }

    /// Number of pairs.
    pub fn len(&self) -> usize {
        self.pairs.len()
    }

    /// True when there is no pair.
    pub fn is_empty(&self) -> bool {
        self.pairs.is_empty()
    }
}

/// The event of a pair that was touching (`was`) and is now (`now`).
fn event_kind(was: bool, now: bool) -> Option<ContactEventKind> {
    match (was, now) {
        (false, true) => Some(ContactEventKind::Begin),
        (true, true) => Some(ContactEventKind::Persist),
        (true, false) => Some(ContactEventKind::End),
        (false, false) => None,
    }
}

#[cfg(test)]
#[path = "pipeline_tests.rs"]
mod tests;
