//! [`CollisionWorld::sync_objects`]: the per-step sync of many moving objects in two
//! passes. The first computes, for every object, the checked pose, the broadphase box, the
//! displacement and whether the broadphase must replace the proxy's fat box; it only reads
//! the world, so with the `parallel` feature it runs on rayon in fixed chunks. The second
//! writes the objects and the broadphase in order, serially: for most objects only the box
//! (their fat box still holds it), so the serial part is small. Box2D v3 does the same
//! (`b2FinalizeBodies` computes the boxes of the awake bodies in parallel tasks and flags
//! the enlarged ones; the broadphase tree is then updated serially).

use super::{check_pose_fast, speculative_box, CollisionWorld, ObjectHandle};
use crate::error::Result;
use crate::math::{Aabb, Isometry, Real, Vec3};

/// One moving object's new state for [`CollisionWorld::sync_objects`]: the arguments of
/// [`CollisionWorld::sync_object`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ObjectSync {
    /// The object.
    pub handle: ObjectHandle,
    /// Its new pose.
    pub pose: Isometry,
    /// Its speculative margin (see [`super::CollisionObject::margin`]).
    pub margin: Real,
    /// Its linear displacement over the coming step (see
    /// [`super::CollisionObject::motion`]).
    pub motion: Vec3,
}

/// The first pass's result for one object (`None` when a check failed: the second pass
/// then takes [`CollisionWorld::sync_object`], which reports the error).
#[derive(Debug, Clone, Copy)]
pub(super) struct Synced {
    pose: Isometry,
    aabb: Aabb,
    displacement: Vec3,
    /// The broadphase must do more than record the box (see
    /// `AnyBroadPhase::needs_update_checked`).
    update: bool,
}

/// Objects per task of the parallel first pass (from two tasks up).
#[cfg(feature = "parallel")]
const SYNC_CHUNK: usize = 512;

impl CollisionWorld {
    /// [`CollisionWorld::sync_object`] for every entry of `items`, in order, with the same
    /// results and the same errors (the entries before the first failing one are applied).
    ///
    /// When the handles are in strictly ascending slot order (as a pipeline's loop over its
    /// bodies gives), the boxes and the fat-box tests are computed first for all entries
    /// (in parallel with the `parallel` feature, in fixed chunks: the result does not depend
    /// on the thread count) and applied in a second, serial pass; otherwise the entries go
    /// through [`CollisionWorld::sync_object`] one by one (a repeated handle must see the
    /// previous entry's pose).
    pub fn sync_objects(&mut self, items: &[ObjectSync]) -> Result<()> {
        let ascending = items
            .windows(2)
            .all(|w| w[0].handle.index < w[1].handle.index);
        if !ascending {
            for s in items {
                self.sync_object(s.handle, s.pose, s.margin, s.motion)?;
            }
            return Ok(());
        }
        let mut out = std::mem::take(&mut self.sync_scratch);
        out.clear();
        out.resize(items.len(), None);
        self.prepare_syncs(items, &mut out);
        let mut result = Ok(());
        for (s, r) in items.iter().zip(&out) {
            let Some(r) = r else {
                // A check failed: the one-object path names the error.
                if let Err(e) = self.sync_object(s.handle, s.pose, s.margin, s.motion) {
                    result = Err(e);
                    break;
                }
                continue;
            };
            if let Err(e) =
                self.broadphase
                    .apply_checked(s.handle.proxy(), &r.aabb, r.displacement, r.update)
            {
                result = Err(e);
                break;
            }
            let o = self.objects[s.handle.index as usize]
                .as_mut()
                .expect("checked by the first pass");
            o.pose = r.pose;
            o.margin = s.margin;
            o.motion = s.motion;
            o.aabb = r.aabb;
            o.displacement = r.displacement;
            // Already up to date: a pending `set_pose` must not be applied again by `update`.
            o.dirty = false;
        }
        self.sync_scratch = out;
        result
    }

    /// The first pass of [`CollisionWorld::sync_objects`] into `out` (as long as `items`).
    fn prepare_syncs(&self, items: &[ObjectSync], out: &mut [Option<Synced>]) {
        #[cfg(feature = "parallel")]
        if items.len() >= 2 * SYNC_CHUNK {
            use rayon::prelude::*;
            out.par_chunks_mut(SYNC_CHUNK)
                .zip(items.par_chunks(SYNC_CHUNK))
                .with_max_len(1)
                .for_each(|(o, it)| {
                    for (o, s) in o.iter_mut().zip(it) {
                        *o = self.prepare_sync(s);
                    }
                });
            return;
        }
        for (o, s) in out.iter_mut().zip(items) {
            *o = self.prepare_sync(s);
        }
    }

    /// The checks and the box of [`CollisionWorld::sync_object`] for one entry, without
    /// changing anything; `None` when the handle is stale or a check fails.
    #[inline]
    fn prepare_sync(&self, s: &ObjectSync) -> Option<Synced> {
        let o = match self.objects.get(s.handle.index as usize) {
            Some(Some(o)) if o.handle == s.handle => o,
            _ => return None,
        };
        let pose = check_pose_fast(s.pose).ok()?;
        if !(s.margin.is_finite() && s.margin >= 0.0) || !s.motion.is_finite() {
            return None;
        }
        let aabb = speculative_box(o.shape.aabb(&pose), s.margin, s.motion);
        let displacement = pose.translation - o.pose.translation;
        let finite = aabb.min.is_finite() && aabb.max.is_finite() && displacement.is_finite();
        if !finite || !aabb.min.cmple(aabb.max).all() {
            return None;
        }
        let update = self
            .broadphase
            .needs_update_checked(s.handle.proxy(), &aabb, displacement);
        Some(Synced {
            pose,
            aabb,
            displacement,
            update,
        })
    }
}
