//! The collision world: shapes with poses and filters, a broadphase, and the
//! narrowphase. Objects are named by generational handles; [`CollisionWorld::update`]
//! recomputes the boxes of the objects that moved (`Shape::aabb(pose)`) and reports the
//! broadphase pairs added and removed, in a deterministic order.
//!
//! The broadphase is an [`AnyBroadPhase`] (an enum over every method, no `dyn`), chosen with
//! [`Method`].

use crate::broadphase::{AnyBroadPhase, BroadPhase, Filter, Method, ProxyHandle, UserFilter};
use crate::error::{CaromError, Result};
use crate::math::{check_isometry, Aabb, Isometry, Real, Stamp, Vec3};
use crate::narrowphase::{NarrowObject, NarrowPhase};
use crate::shape::Shape;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// A handle to an object of a [`CollisionWorld`]: its slot and the slot's generation
/// (the broadphase proxy handle of the object).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct ObjectHandle {
    /// Slot index.
    pub index: u32,
    /// Generation of the slot.
    pub generation: u32,
}

impl From<ProxyHandle> for ObjectHandle {
    fn from(p: ProxyHandle) -> Self {
        ObjectHandle {
            index: p.index,
            generation: p.generation,
        }
    }
}

impl ObjectHandle {
    fn proxy(self) -> ProxyHandle {
        ProxyHandle {
            index: self.index,
            generation: self.generation,
        }
    }
}

/// An object's motion over the step and whether it may stop short of it
/// ([`CollisionObject::motion`], [`CollisionObject::may_stop`]).
type Motion = (Vec3, bool);

/// One object: a shared shape at a pose, with a collision filter.
#[derive(Debug, Clone)]
pub struct CollisionObject {
    /// The shape (shared, immutable).
    pub shape: Arc<Shape>,
    /// World pose.
    pub pose: Isometry,
    /// Collision filter.
    pub filter: Filter,
    /// World box at the last update (the shape's box expanded by `margin`, the linear part
    /// of it only along `motion`; see [`CollisionObject::motion`]).
    pub aabb: Aabb,
    /// Speculative margin (length): the box is expanded by it (its `motion` part only along
    /// the motion), and a pair generates contact
    /// points up to `max(prediction, margin_a + margin_b)` apart, less the part of the two
    /// margins that is linear motion when their motions are set (see
    /// [`CollisionObject::motion`]). A dynamics pipeline sets it from the object's motion over
    /// the coming step. 0 by default.
    pub margin: Real,
    /// Linear displacement over the coming step (`v dt`, included in `margin`), for
    /// speculative contacts: a pair counts the *relative* displacement of its two objects,
    /// `margin_a - |motion_a| + margin_b - |motion_b| + |motion_a - motion_b|`, so bodies moving
    /// together (a falling column) get no speculative contacts from their common motion.
    /// Zero by default ([`CollisionWorld::set_motion`]). The box is grown by the margin's
    /// own part `max(margin - |motion|, 0)` and swept along the motion (so with a zero
    /// motion, by the whole margin).
    pub motion: Vec3,
    /// The object's displacement over the coming step may fall anywhere between zero and
    /// `motion` (a contact may stop it), not just `motion`: a pair then takes the largest
    /// relative displacement of the cases, e.g. `max(|motion_a - motion_b|, |motion_b|)`
    /// when only A may stop. A dynamics pipeline sets it for a body that has just landed on
    /// another, so a body falling with it still gets speculative points against it. False
    /// by default; it has no effect with a zero motion. The box needs no change: it is
    /// swept from the pose along the whole motion.
    pub may_stop: bool,
    /// True when hinted resting ([`CollisionWorld::set_resting`]) or static: pairs of two
    /// such objects are not updated by the narrowphase.
    pub resting: bool,
    handle: ObjectHandle,
    dirty: bool,
    displacement: Vec3,
}

impl CollisionObject {
    /// Stores what [`CollisionWorld::sync_object`] computed; the object is up to date (a
    /// pending `set_pose` must not be applied again by `update`).
    #[inline(always)]
    fn set_synced(&mut self, pose: Isometry, margin: Real, motion: Motion, aabb: Aabb, d: Vec3) {
        self.pose = pose;
        self.margin = margin;
        (self.motion, self.may_stop) = motion;
        self.aabb = aabb;
        self.displacement = d;
        self.dirty = false;
    }
}

/// Pairs of objects that started or stopped overlapping (broadphase boxes) at an update.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct WorldPairChanges {
    /// New pairs, sorted by (lower index, higher index).
    pub added: Vec<(ObjectHandle, ObjectHandle)>,
    /// Pairs that ended (or whose object was removed), sorted the same way.
    pub removed: Vec<(ObjectHandle, ObjectHandle)>,
}

/// Wall-clock time of the stages of the last [`CollisionWorld::update`].
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct UpdateTimings {
    /// Box updates and broadphase pair update.
    pub broadphase: Duration,
    /// Narrowphase (manifold updates of every pair).
    pub narrowphase: Duration,
}

/// [`check_isometry`] with its common case inline: a finite pose whose rotation's squared
/// length is within `4 ε` of 1 passes unchanged (then `||q| − 1| ≤ 4 ε` too, where
/// [`check_isometry`] also returns it unchanged); anything else takes the full check, which
/// renormalises or names the bad value. Same result, a fifth of the instructions.
#[inline(always)]
fn check_pose_fast(pose: Isometry) -> Result<Isometry> {
    let q = pose.rotation;
    if pose.translation.is_finite()
        && q.is_finite()
        && (q.length_squared() - 1.0).abs() <= 4.0 * Real::EPSILON
    {
        Ok(pose)
    } else {
        check_isometry("pose", pose)
    }
}

/// The broadphase box of an object whose shape's box is `aabb`, for its speculative `margin`
/// and linear `motion` (see [`CollisionObject::margin`]): the shape's box grown by the
/// margin's own part `max(margin - |motion|, 0)` on every side, then swept along `motion`.
///
/// A pair's points are generated up to `own_a + own_b + |motion_a - motion_b|` apart, and two
/// objects moving along their motions can only come that close during the step when these
/// boxes overlap (each body's box over the step lies in its swept box), so the swept boxes
/// find every pair that can meet. Growing the box by the whole margin on every side, as
/// before, also paired bodies moving side by side or apart: on "3000 fall" 21.4 k pairs for
/// 6.3 k manifolds. Rapier builds its broadphase boxes the same way (the box at the current
/// pose merged with the box at the predicted pose, grown by the prediction distance);
/// Bullet's `btDbvtBroadphase` sweeps its fat boxes along the displacement too.
#[inline]
fn speculative_box(aabb: Aabb, margin: Real, motion: Vec3) -> Aabb {
    let own = (margin - motion.length()).max(0.0);
    let m = Vec3::splat(own);
    Aabb::new(aabb.min - m, aabb.max + m).swept(motion)
}

/// True when `sum`, a sum of values, shows them all finite: a NaN or infinite term makes the
/// sum NaN or infinite, and then `sum * 0` is NaN. (A sum of finite terms can overflow: the
/// caller then takes its slow, exact checks.)
#[inline(always)]
fn finite_sum(sum: Real) -> bool {
    sum * 0.0 == 0.0
}

/// Objects plus a broadphase (see the module docs).
#[derive(Debug, Clone, Default)]
pub struct CollisionWorld {
    objects: Vec<Option<CollisionObject>>,
    broadphase: AnyBroadPhase,
    dirty: Vec<u32>,
    changes: WorldPairChanges,
    narrowphase: NarrowPhase<ObjectHandle>,
    timings: UpdateTimings,
    /// Number of objects that are not resting: when none is, no manifold can change and
    /// the narrowphase skips its shape tests (`NarrowPhase::step_with`).
    active: usize,
    /// Changes whenever an object is added or removed or its filter changes.
    stamp: Stamp,
}

impl CollisionWorld {
    /// An empty world using the broadphase `method`.
    pub fn new(method: Method) -> Self {
        CollisionWorld {
            broadphase: AnyBroadPhase::new(method),
            ..Default::default()
        }
    }

    /// A number that names the world's objects with their shapes and filters: it is unique
    /// in the process, given when the world is made and again whenever an object is added
    /// or removed or its filter changes (an object's shape never changes), and kept by a
    /// clone. Two calls that return the same number saw the same objects, shapes and
    /// filters (poses, motions and resting hints may differ), so a cache of per-object data
    /// keyed by it never serves stale data; `carom_dynamics`' query tree keeps one.
    pub fn objects_stamp(&self) -> u64 {
        self.stamp.get()
    }

    /// The broadphase.
    pub fn broadphase(&self) -> &AnyBroadPhase {
        &self.broadphase
    }

    /// Installs or clears a user pair filter (called with the two objects' handles).
    pub fn set_user_filter(
        &mut self,
        filter: Option<Arc<dyn Fn(ObjectHandle, ObjectHandle) -> bool + Send + Sync>>,
    ) {
        let f: Option<UserFilter> = filter.map(|f| {
            Arc::new(move |a: ProxyHandle, b: ProxyHandle| f(a.into(), b.into())) as UserFilter
        });
        self.broadphase.set_user_filter(f);
    }

    /// Adds an object; its box is computed now. A non-finite pose or a shape whose box is
    /// not finite is an error.
    pub fn add(
        &mut self,
        shape: Arc<Shape>,
        pose: Isometry,
        filter: Filter,
    ) -> Result<ObjectHandle> {
        let pose = check_isometry("pose", pose)?;
        if !shape.is_convex() {
            // Only pairs that can ever meet need an algorithm: two static objects, or
            // filters that exclude each other, never reach the narrowphase.
            for o in self.objects.iter().flatten() {
                if !filter.can_pair(&o.filter) {
                    continue;
                }
                self.narrowphase.dispatcher.check_pair(&shape, &o.shape)?;
            }
        }
        let aabb = shape.aabb(&pose);
        let handle: ObjectHandle = self.broadphase.create_proxy(aabb, filter)?.into();
        let i = handle.index as usize;
        if i >= self.objects.len() {
            self.objects.resize(i + 1, None);
        }
        self.active += usize::from(!filter.is_static);
        self.stamp = Stamp::fresh();
        self.objects[i] = Some(CollisionObject {
            shape,
            pose,
            filter,
            aabb,
            margin: 0.0,
            motion: Vec3::ZERO,
            may_stop: false,
            resting: filter.is_static,
            handle,
            dirty: false,
            displacement: Vec3::ZERO,
        });
        Ok(handle)
    }

    fn slot(&self, h: ObjectHandle) -> Result<usize> {
        match self.objects.get(h.index as usize) {
            Some(Some(o)) if o.handle == h => Ok(h.index as usize),
            _ => Err(CaromError::UnknownHandle(format!("{h:?}"))),
        }
    }

    /// The object named by `h`.
    pub fn get(&self, h: ObjectHandle) -> Result<&CollisionObject> {
        let i = self.slot(h)?;
        Ok(self.objects[i].as_ref().expect("slot checked"))
    }

    /// Moves an object; its box is recomputed at the next [`CollisionWorld::update`].
    pub fn set_pose(&mut self, h: ObjectHandle, pose: Isometry) -> Result<()> {
        let i = self.slot(h)?;
        let pose = check_isometry("pose", pose)?;
        let o = self.objects[i].as_mut().expect("slot checked");
        o.displacement = pose.translation - o.pose.translation;
        o.pose = pose;
        if !o.dirty {
            o.dirty = true;
            self.dirty.push(i as u32);
        }
        Ok(())
    }

    /// Moves an object and sets its speculative margin (see [`CollisionObject::margin`]); a
    /// negative or non-finite margin is an error.
    pub fn set_pose_with_margin(
        &mut self,
        h: ObjectHandle,
        pose: Isometry,
        margin: Real,
    ) -> Result<()> {
        let margin = crate::math::check_non_negative("margin", margin)?;
        self.set_pose(h, pose)?;
        self.objects[h.index as usize]
            .as_mut()
            .expect("slot checked")
            .margin = margin;
        Ok(())
    }

    /// Sets the object's linear displacement over the coming step (see
    /// [`CollisionObject::motion`]; the margin should include its length). A non-finite
    /// motion is an error. The box follows the motion (it is swept along it), so a changed
    /// motion recomputes the box at the next [`CollisionWorld::update`].
    pub fn set_motion(&mut self, h: ObjectHandle, motion: Vec3) -> Result<()> {
        let i = self.slot(h)?;
        let motion = crate::math::check_finite_vec("motion", motion)?;
        let o = self.objects[i].as_mut().expect("slot checked");
        if o.motion != motion {
            o.motion = motion;
            if !o.dirty {
                // The pose has not moved since the last box update.
                o.displacement = Vec3::ZERO;
                o.dirty = true;
                self.dirty.push(i as u32);
            }
        }
        Ok(())
    }

    /// Moves an object, sets its speculative margin and motion (see
    /// [`CollisionObject::margin`], [`CollisionObject::motion`] and
    /// [`CollisionObject::may_stop`]), and updates its box and
    /// broadphase proxy now instead of at the next [`CollisionWorld::update`]: what
    /// [`CollisionWorld::set_pose_with_margin`] then [`CollisionWorld::set_motion`] do, in one
    /// pass with one handle check (a dynamics pipeline calls it for every moving body at every
    /// step). Every argument is validated (a non-finite pose, a negative or non-finite margin,
    /// a non-finite motion, or a box that overflows are errors) before anything changes.
    pub fn sync_object(
        &mut self,
        h: ObjectHandle,
        pose: Isometry,
        margin: Real,
        motion: Vec3,
        may_stop: bool,
    ) -> Result<()> {
        let i = self.slot(h)?;
        let Some(o) = self.objects[i].as_mut() else {
            return Err(CaromError::UnknownHandle(format!("{h:?}")));
        };
        // The usual case first: box and displacement from the pose as given, then one test
        // of everything (`finite_sum` is finite only when every term is, and a sum that
        // overflows only sends a valid pose to the named checks, which pass it). Anything
        // else takes the named checks, in their order, which build the errors and may
        // renormalise the rotation.
        let aabb = speculative_box(o.shape.aabb(&pose), margin, motion);
        let displacement = pose.translation - o.pose.translation;
        let q = pose.rotation;
        let sum = (pose.translation + motion + displacement + aabb.min + aabb.max).element_sum()
            + (q.x + q.y)
            + (q.z + q.w)
            + margin;
        if !(finite_sum(sum)
            && margin >= 0.0
            && (q.length_squared() - 1.0).abs() <= 4.0 * Real::EPSILON
            && aabb.min.cmple(aabb.max).all())
        {
            return self.sync_object_checked(i, pose, margin, (motion, may_stop));
        }
        self.broadphase
            .update_proxy_checked(h.proxy(), &aabb, displacement)?;
        o.set_synced(pose, margin, (motion, may_stop), aabb, displacement);
        Ok(())
    }

    /// [`CollisionWorld::sync_object`] with every argument checked by name, for the poses
    /// its single test did not pass (invalid values, a rotation to renormalise, or values so
    /// large that their sum overflows).
    #[cold]
    #[inline(never)]
    fn sync_object_checked(
        &mut self,
        i: usize,
        pose: Isometry,
        margin: Real,
        (motion, may_stop): Motion,
    ) -> Result<()> {
        let pose = check_pose_fast(pose)?;
        crate::math::check_non_negative("margin", margin)?;
        crate::math::check_finite_vec("motion", motion)?;
        let o = self.objects[i].as_mut().expect("slot checked");
        let aabb = speculative_box(o.shape.aabb(&pose), margin, motion);
        let displacement = pose.translation - o.pose.translation;
        // A pose far out can overflow the box or the displacement: checked before anything
        // changes, so the broadphase can take them unchecked (the handle is live: an object
        // and its proxy share it).
        crate::math::check_aabb(&aabb)?;
        crate::math::check_finite_vec("displacement", displacement)?;
        self.broadphase
            .update_proxy_checked(o.handle.proxy(), &aabb, displacement)?;
        o.set_synced(pose, margin, (motion, may_stop), aabb, displacement);
        Ok(())
    }

    /// Excludes the pair of live objects `a`, `b` from contact generation, or lets it back
    /// in ([`NarrowPhase::set_excluded`]): the broadphase still pairs them, the narrowphase
    /// keeps their manifold empty. Lifted when either object is removed.
    pub fn set_pair_excluded(
        &mut self,
        a: ObjectHandle,
        b: ObjectHandle,
        excluded: bool,
    ) -> Result<()> {
        self.slot(a)?;
        self.slot(b)?;
        self.narrowphase.set_excluded(a, b, excluded);
        Ok(())
    }

    /// Changes an object's filter.
    pub fn set_filter(&mut self, h: ObjectHandle, filter: Filter) -> Result<()> {
        let i = self.slot(h)?;
        self.broadphase.set_filter(h.proxy(), filter)?;
        let o = self.objects[i].as_mut().expect("slot checked");
        o.filter = filter;
        self.stamp = Stamp::fresh();
        let was = o.resting;
        o.resting |= filter.is_static;
        self.active -= usize::from(o.resting && !was);
        Ok(())
    }

    /// Hints that an object is resting (sleeping) or moving again. Pairs of two resting (or
    /// static) objects keep their manifolds unchanged until one of them moves again.
    pub fn set_resting(&mut self, h: ObjectHandle, resting: bool) -> Result<()> {
        let i = self.slot(h)?;
        self.broadphase.set_resting(h.proxy(), resting)?;
        let o = self.objects[i].as_mut().expect("slot checked");
        let was = o.resting;
        o.resting = resting || o.filter.is_static;
        self.active = self.active + usize::from(was && !o.resting) - usize::from(o.resting && !was);
        Ok(())
    }

    /// Removes an object; its pairs are reported as removed by the next update, and the
    /// exclusions naming it are lifted.
    pub fn remove(&mut self, h: ObjectHandle) -> Result<CollisionObject> {
        let i = self.slot(h)?;
        self.broadphase.remove_proxy(h.proxy())?;
        self.narrowphase.clear_exclusions_of(h);
        let o = self.objects[i].take().expect("slot checked");
        self.active -= usize::from(!o.resting);
        self.stamp = Stamp::fresh();
        Ok(o)
    }

    /// Number of objects.
    pub fn len(&self) -> usize {
        self.broadphase.len()
    }

    /// True when there is no object.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Recomputes the boxes of moved objects and updates the broadphase pairs.
    pub fn update(&mut self) -> Result<&WorldPairChanges> {
        let start = Instant::now();
        let mut dirty = std::mem::take(&mut self.dirty);
        dirty.sort_unstable();
        for &i in &dirty {
            let Some(o) = self.objects[i as usize].as_mut() else {
                continue;
            };
            if !o.dirty {
                continue;
            }
            o.dirty = false;
            o.aabb = speculative_box(o.shape.aabb(&o.pose), o.margin, o.motion);
            self.broadphase
                .update_proxy(o.handle.proxy(), o.aabb, o.displacement)?;
        }
        dirty.clear();
        self.dirty = dirty;
        let ch = self.broadphase.update_pairs();
        // Reused buffers: no allocation once they have grown.
        let conv = |v: &[(ProxyHandle, ProxyHandle)],
                    out: &mut Vec<(ObjectHandle, ObjectHandle)>| {
            out.clear();
            out.extend(v.iter().map(|&(a, b)| (a.into(), b.into())));
        };
        conv(&ch.added, &mut self.changes.added);
        conv(&ch.removed, &mut self.changes.removed);
        let mid = Instant::now();
        let objects = &self.objects;
        let (added, removed) = (&self.changes.added, &self.changes.removed);
        let lookup = |h: ObjectHandle| {
            let o = objects.get(h.index as usize)?.as_ref()?;
            (o.handle == h).then_some(NarrowObject {
                shape: &o.shape,
                pose: o.pose,
                margin: o.margin,
                motion: o.motion,
                may_stop: o.may_stop,
                active: !o.resting,
            })
        };
        debug_assert_eq!(
            self.active,
            objects.iter().flatten().filter(|o| !o.resting).count()
        );
        self.narrowphase
            .step_with(added, removed, lookup, self.active > 0)?;
        self.timings = UpdateTimings {
            broadphase: mid - start,
            narrowphase: mid.elapsed(),
        };
        Ok(&self.changes)
    }

    /// Stage timings of the last [`CollisionWorld::update`].
    pub fn timings(&self) -> UpdateTimings {
        self.timings
    }

    /// The narrowphase: manifolds and contact events of the last update.
    pub fn narrowphase(&self) -> &NarrowPhase<ObjectHandle> {
        &self.narrowphase
    }

    /// The narrowphase, to configure the dispatcher, mark sensors or store impulses.
    pub fn narrowphase_mut(&mut self) -> &mut NarrowPhase<ObjectHandle> {
        &mut self.narrowphase
    }

    /// The current broadphase pairs (as of the last update), sorted.
    pub fn pairs(&self) -> Vec<(ObjectHandle, ObjectHandle)> {
        self.broadphase
            .pairs()
            .into_iter()
            .map(|(a, b)| (a.into(), b.into()))
            .collect()
    }

    /// Iterates over the live objects in slot order.
    pub fn iter(&self) -> impl Iterator<Item = (ObjectHandle, &CollisionObject)> {
        self.objects.iter().flatten().map(|o| (o.handle, o))
    }
}
