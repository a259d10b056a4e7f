//! The narrowphase stage of the collision pipeline: one persistent manifold per broadphase
//! pair (created when the pair is added, dropped when it is removed), updated every step in
//! parallel over pairs (rayon, behind the `parallel` feature; the result does not depend on
//! the thread count), with contact events (begin, persist, end) in pair order. Sensor
//! objects report overlap only: their pairs get events but no contact points.

use super::dispatcher::Dispatcher;
use super::manifold::ContactManifold;
use crate::error::Result;
use crate::math::{Isometry, Real};
use crate::shape::Shape;
use std::collections::{BTreeMap, BTreeSet};

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
}

/// What the narrowphase needs to know about one object at a step.
#[derive(Debug, Clone, Copy)]
pub struct NarrowObject<'s> {
    /// The shape.
    pub shape: &'s Shape,
    /// Its world pose.
    pub pose: Isometry,
    /// Speculative margin of the object: a pair generates points up to
    /// `max(config.prediction, margin_a + margin_b)` apart (see
    /// [`super::Dispatcher::update_manifold_with_prediction`]).
    pub margin: Real,
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
#[derive(Debug, Clone)]
pub struct NarrowPhase<H: Ord> {
    pairs: BTreeMap<(H, H), PairContact<H>>,
    sensors: BTreeSet<H>,
    events: Vec<ContactEvent<H>>,
    /// The dispatcher (algorithms and manifold configuration).
    pub dispatcher: Dispatcher,
}

impl<H: Ord> Default for NarrowPhase<H> {
    fn default() -> Self {
        NarrowPhase {
            pairs: BTreeMap::new(),
            sensors: BTreeSet::new(),
            events: Vec::new(),
            dispatcher: Dispatcher::default(),
        }
    }
}

impl<H: Copy + Ord + Send + Sync> NarrowPhase<H> {
    /// An empty narrowphase using `dispatcher`.
    pub fn new(dispatcher: Dispatcher) -> Self {
        NarrowPhase {
            pairs: BTreeMap::new(),
            sensors: BTreeSet::new(),
            events: Vec::new(),
            dispatcher,
        }
    }

    /// Marks an object as a sensor (overlap events only) or not; applies to pairs added
    /// afterwards and to existing pairs at the next step.
    pub fn set_sensor(&mut self, h: H, sensor: bool) {
        if sensor {
            self.sensors.insert(h);
        } else {
            self.sensors.remove(&h);
        }
    }

    /// Creates the manifold of pair `(a, b)`.
    pub fn add_pair(&mut self, a: H, b: H) {
        self.pairs.entry((a, b)).or_insert(PairContact {
            a,
            b,
            manifold: ContactManifold::new(),
            touching: false,
            sensor: false,
        });
    }

    /// Drops the manifold of pair `(a, b)`; an `End` event is emitted if it touched.
    pub fn remove_pair(&mut self, a: H, b: H) {
        if let Some(p) = self.pairs.remove(&(a, b)) {
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

    /// One step: pairs `removed` are dropped and `added` created, then every manifold is
    /// updated from the shapes and poses given by `lookup` (pairs whose objects are unknown,
    /// or both inactive, are skipped and keep their state). Returns the events of this step,
    /// in pair order (removals first).
    pub fn step<'s, F>(
        &mut self,
        added: &[(H, H)],
        removed: &[(H, H)],
        lookup: F,
    ) -> Result<&[ContactEvent<H>]>
    where
        F: Fn(H) -> Option<NarrowObject<'s>> + Sync,
    {
        self.events.clear();
        for &(a, b) in removed {
            self.remove_pair(a, b);
        }
        for &(a, b) in added {
            self.add_pair(a, b);
        }
        let dispatcher = &self.dispatcher;
        let sensors = &self.sensors;
        let update = |p: &mut PairContact<H>| -> Result<(bool, bool)> {
            let was = p.touching;
            let (Some(oa), Some(ob)) = (lookup(p.a), lookup(p.b)) else {
                return Ok((was, was));
            };
            if !(oa.active || ob.active) {
                return Ok((was, was));
            }
            let (sa, pa, sb, pb) = (oa.shape, oa.pose, ob.shape, ob.pose);
            p.sensor = sensors.contains(&p.a) || sensors.contains(&p.b);
            if p.sensor {
                p.manifold.clear();
                let g = dispatcher.generate(sa, sb, &pa.inv_mul(&pb), true)?;
                p.touching = g.contacts.iter().any(|(c, _)| c.distance <= 0.0);
            } else {
                let prediction = oa.margin + ob.margin;
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
            Ok((was, p.touching))
        };
        let mut refs: Vec<&mut PairContact<H>> = self.pairs.values_mut().collect();
        #[cfg(feature = "parallel")]
        let results: Vec<Result<(bool, bool)>> = {
            use rayon::prelude::*;
            refs.par_iter_mut().map(|p| update(p)).collect()
        };
        #[cfg(not(feature = "parallel"))]
        let results: Vec<Result<(bool, bool)>> = refs.iter_mut().map(|p| update(p)).collect();
        let mut events = Vec::new();
        for (p, r) in refs.iter().zip(results) {
            let kind = match r? {
                (false, true) => ContactEventKind::Begin,
                (true, true) => ContactEventKind::Persist,
                (true, false) => ContactEventKind::End,
                (false, false) => continue,
            };
            events.push(ContactEvent {
                a: p.a,
                b: p.b,
                kind,
                sensor: p.sensor,
            });
        }
        self.events.extend(events);
        Ok(&self.events)
    }

    /// The events of the last step.
    pub fn events(&self) -> &[ContactEvent<H>] {
        &self.events
    }

    /// Every pair with its manifold, in pair order.
    pub fn pairs(&self) -> impl Iterator<Item = &PairContact<H>> {
        self.pairs.values()
    }

    /// The pairs with at least one contact point, in pair order (the solver's input).
    pub fn manifolds(&self) -> impl Iterator<Item = &PairContact<H>> {
        self.pairs.values().filter(|p| !p.manifold.is_empty())
    }

    /// Mutable manifolds in pair order (for the solver to store accumulated impulses).
    pub fn manifolds_mut(&mut self) -> impl Iterator<Item = &mut PairContact<H>> {
        self.pairs.values_mut().filter(|p| !p.manifold.is_empty())
    }

    /// Every pair, mutable, in pair order (to restore saved manifolds from a snapshot).
    pub fn pairs_mut(&mut self) -> impl Iterator<Item = &mut PairContact<H>> {
        self.pairs.values_mut()
    }

    /// Replaces the events of the last step (to restore a snapshot).
    pub fn restore_events(&mut self, events: Vec<ContactEvent<H>>) {
        self.events = events;
    }

    /// The pair `(a, b)`.
    pub fn get(&self, a: H, b: H) -> Option<&PairContact<H>> {
        self.pairs.get(&(a, b))
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
