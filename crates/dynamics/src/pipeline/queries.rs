//! Scene queries through a [`World`]: ray casts (one or a batch) and linear shape casts
//! against every body with a shape, closest hit first.
//!
//! The broadphase methods of the collision world answer box-overlap pairs, not rays (the
//! default hierarchical grid has no ray walk), so a query builds a [`Bvh`] (binned SAH,
//! stackless, `carom_collision::midphase`) over the bodies' current world boxes, then walks
//! it closest-first: a ray visits the nearer child first and shrinks its `max_t` at every
//! hit (Bullet's `btDbvt::rayTestInternal`, Jolt's `CastRay` with a closest-hit collector),
//! so the exact `query::raycast` runs on few shapes; a shape cast visits the leaves whose
//! boxes meet the cast shape's box swept by its motion. Building is `O(N log N)`; a
//! [`WorldQuery`] keeps the tree for many queries against the same state (the batch form
//! builds one for its whole batch).
//!
//! The world keeps the tree between queries ([`QueryCache`]): when the same bodies are
//! queried again, it is reused as is if no box changed, refitted to the new boxes otherwise
//! (`Bvh::refit`, about a fifth of a build's instructions for 1000 bodies), and rebuilt
//! after [`QueryCache::REFITS_PER_BUILD`] refits so the topology follows bodies that move
//! far (Bullet's `btDbvt` refits and re-inserts for the same reason). Results do not
//! depend on the topology (closest hit, ties to the lower body slot), so a refitted tree
//! answers exactly what a fresh one would.
//!
//! Poses are the bodies' current poses (what [`World::bodies`] reports, including teleports
//! since the last step), not the collision objects' poses of the last step.

use super::World;
use crate::body_set::BodyHandle;
use carom_collision::broadphase::Filter;
use carom_collision::math::{check_finite_vec, check_isometry, Aabb, Isometry, Real, Vec3};
use carom_collision::midphase::{Bvh, BvhLayout};
use carom_collision::query::{raycast, shape_cast, Ray, RayHit, ShapeCastHit};
use carom_collision::shape::Shape;
use carom_collision::{CaromError, Result};
use std::sync::Mutex;

/// A ray hit on a body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyRayHit {
    /// The body hit.
    pub body: BodyHandle,
    /// Distance along the unit direction, point and outward normal.
    pub hit: RayHit,
}

/// A shape-cast hit on a body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyShapeCastHit {
    /// The body hit.
    pub body: BodyHandle,
    /// Time of impact (fraction of the velocity), witness points and normal from the cast
    /// shape (A) towards the body (B).
    pub hit: ShapeCastHit,
}

/// A closest-hit query structure over the bodies of a [`World`] at one moment (see the
/// module docs). Built by [`World::query`].
#[derive(Debug)]
pub struct WorldQuery<'w> {
    objects: Vec<(BodyHandle, &'w Shape, Isometry, Filter)>,
    bvh: Option<Bvh>,
    /// Where the tree goes back when the query is dropped, with the boxes it was fitted to.
    cache: Option<(&'w QueryCache, Vec<Aabb>, u32)>,
}

/// The tree of the last [`World::query`], kept for the next one (see the module docs).
/// Cloning a world gives the clone an empty cache.
#[derive(Default)]
pub(crate) struct QueryCache {
    slot: Mutex<Option<CachedTree>>,
}

/// A tree with the bodies and boxes it was fitted to, and the refits since its build.
struct CachedTree {
    bvh: Bvh,
    bodies: Vec<BodyHandle>,
    boxes: Vec<Aabb>,
    refits: u32,
}

impl QueryCache {
    /// Refits of a cached tree before the next query rebuilds it.
    pub const REFITS_PER_BUILD: u32 = 8;

    /// The tree over `boxes` (of `bodies`, in this order) and its refit count: the cached
    /// one reused or refitted when it covers the same bodies, a new one otherwise.
    fn tree_for(&self, bodies: &[BodyHandle], boxes: &[Aabb]) -> Result<(Bvh, u32)> {
        // A poisoned lock (a panic elsewhere while it was held) only loses the cache.
        let cached = self.slot.lock().ok().and_then(|mut g| g.take());
        if let Some(c) = cached {
            if c.bodies == bodies {
                if c.boxes == boxes {
                    return Ok((c.bvh, c.refits));
                }
                if c.refits < Self::REFITS_PER_BUILD {
                    let mut bvh = c.bvh;
                    bvh.refit(boxes)?;
                    return Ok((bvh, c.refits + 1));
                }
            }
        }
        Ok((Bvh::new(boxes, BvhLayout::default())?, 0))
    }

    /// Keeps `bvh` for the next query.
    fn put(&self, bvh: Bvh, bodies: Vec<BodyHandle>, boxes: Vec<Aabb>, refits: u32) {
        if let Ok(mut g) = self.slot.lock() {
            *g = Some(CachedTree {
                bvh,
                bodies,
                boxes,
                refits,
            });
        }
    }
}

impl Clone for QueryCache {
    fn clone(&self) -> Self {
        QueryCache::default()
    }
}

impl std::fmt::Debug for QueryCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let cached = self.slot.lock().map(|g| g.is_some()).unwrap_or(false);
        f.debug_struct("QueryCache")
            .field("cached", &cached)
            .finish()
    }
}

impl Drop for WorldQuery<'_> {
    fn drop(&mut self) {
        if let (Some(bvh), Some((cache, boxes, refits))) = (self.bvh.take(), self.cache.take()) {
            let bodies = self.objects.iter().map(|o| o.0).collect();
            cache.put(bvh, bodies, boxes, refits);
        }
    }
}

fn check_max(name: &str, v: Real) -> Result<Real> {
    if v.is_nan() || v < 0.0 {
        return Err(CaromError::invalid(name, v, "must be >= 0"));
    }
    Ok(v)
}

impl<'w> WorldQuery<'w> {
    /// The closest hit of the ray `origin + t·dir` (`dir` is normalised; must be finite and
    /// non-zero) with `t <= max_distance` (may be infinite) on a body whose collision group
    /// meets `mask`; `None` on a miss. Rays starting inside a body hit it at distance 0.
    pub fn raycast(
        &self,
        origin: Vec3,
        dir: Vec3,
        max_distance: Real,
        mask: u32,
    ) -> Result<Option<BodyRayHit>> {
        let ray = Ray::new(origin, dir)?;
        let max_distance = check_max("max_distance", max_distance)?;
        Ok(self.cast_ray(&ray, max_distance, mask))
    }

    fn cast_ray(&self, ray: &Ray, max_distance: Real, mask: u32) -> Option<BodyRayHit> {
        let bvh = self.bvh.as_ref()?;
        let mut best: Option<BodyRayHit> = None;
        bvh.for_each_candidate_on_ray_ordered(ray.origin, ray.dir, max_distance, |i, max_t| {
            let (body, shape, pose, filter) = &self.objects[i as usize];
            if filter.group & mask == 0 {
                return true;
            }
            if let Ok(Some(hit)) = raycast(shape, pose, ray.origin, ray.dir, *max_t, true) {
                // Ties go to the lower body slot, whatever the walk order.
                let better = match &best {
                    None => true,
                    Some(b) => {
                        hit.distance < b.hit.distance
                            || (hit.distance == b.hit.distance && body.index < b.body.index)
                    }
                };
                if better && hit.distance <= *max_t {
                    *max_t = hit.distance;
                    best = Some(BodyRayHit { body: *body, hit });
                }
            }
            true
        });
        best
    }

    /// [`WorldQuery::raycast`] for each ray (`origins` and `dirs` of equal length; one
    /// direction for all is accepted). Every ray is checked before any is cast. Runs in
    /// parallel with the `parallel` feature; the results do not depend on the thread count.
    pub fn raycast_batch(
        &self,
        origins: &[Vec3],
        dirs: &[Vec3],
        max_distance: Real,
        mask: u32,
    ) -> Result<Vec<Option<BodyRayHit>>> {
        if dirs.len() != origins.len() && dirs.len() != 1 {
            return Err(CaromError::invalid(
                "directions",
                dirs.len(),
                format!("need {} directions (one per origin) or 1", origins.len()),
            ));
        }
        let max_distance = check_max("max_distance", max_distance)?;
        let rays = origins
            .iter()
            .enumerate()
            .map(|(i, &o)| {
                let d = dirs[if dirs.len() == 1 { 0 } else { i }];
                Ray::new(o, d).map_err(|_| {
                    CaromError::invalid(
                        format!("ray {i} (origin, direction)"),
                        (o, d),
                        "origin must be finite, direction finite and non-zero",
                    )
                })
            })
            .collect::<Result<Vec<Ray>>>()?;
        let cast = |r: &Ray| self.cast_ray(r, max_distance, mask);
        #[cfg(feature = "parallel")]
        {
            use rayon::prelude::*;
            Ok(rays.par_iter().with_min_len(16).map(cast).collect())
        }
        #[cfg(not(feature = "parallel"))]
        Ok(rays.iter().map(cast).collect())
    }

    /// The first body hit by `shape` moving from `pose` with `velocity` over times
    /// `[0, max_time]` (the shape is at `pose + velocity·t`, without rotation), on bodies
    /// whose collision group meets `mask`. A body already overlapping at `t = 0` is hit at 0.
    /// Ties go to the lower body slot.
    pub fn shape_cast(
        &self,
        shape: &Shape,
        pose: &Isometry,
        velocity: Vec3,
        max_time: Real,
        mask: u32,
    ) -> Result<Option<BodyShapeCastHit>> {
        let pose = check_isometry("pose", *pose)?;
        let velocity = check_finite_vec("velocity", velocity)?;
        let max_time = check_max("max_time", max_time)?;
        if !max_time.is_finite() {
            return Err(CaromError::invalid("max_time", max_time, "must be finite"));
        }
        let Some(bvh) = self.bvh.as_ref() else {
            return Ok(None);
        };
        let swept: Aabb = shape.aabb(&pose).swept(velocity * max_time);
        let mut candidates = Vec::new();
        bvh.for_each_candidate_in_aabb(&swept, |i| {
            candidates.push(i);
            true
        });
        candidates.sort_unstable();
        let mut best: Option<BodyShapeCastHit> = None;
        for i in candidates {
            let (body, other, other_pose, filter) = &self.objects[i as usize];
            if filter.group & mask == 0 {
                continue;
            }
            let limit = best.map_or(max_time, |b| b.hit.toi);
            let hit = shape_cast(shape, &pose, velocity, other, other_pose, Vec3::ZERO, limit)?;
            if let Some(hit) = hit {
                if best.is_none_or(|b| hit.toi < b.hit.toi) {
                    best = Some(BodyShapeCastHit { body: *body, hit });
                }
            }
        }
        Ok(best)
    }

    /// Number of bodies the query sees.
    pub fn len(&self) -> usize {
        self.objects.len()
    }

    /// True when no body has a shape.
    pub fn is_empty(&self) -> bool {
        self.objects.is_empty()
    }
}

impl World {
    /// A query structure over the bodies with a shape, at their current poses (see
    /// [`crate::pipeline::queries`]).
    pub fn query(&self) -> Result<WorldQuery<'_>> {
        let set = self.bodies();
        let mut objects = Vec::new();
        let mut boxes = Vec::new();
        for (h, o) in self.collision.iter() {
            let Some(body) = self.body_of_object(h) else {
                continue;
            };
            let pose = set.pose_of(body.index as usize);
            // Arvo's transformed local box: conservative and O(1) (the tight box costs six
            // support queries per hull, which made the 500-ray batch of the raytests scene
            // 1.4x slower); planes are unbounded, so they keep their own box.
            boxes.push(match &*o.shape {
                Shape::Plane(_) => o.shape.aabb(&pose),
                s => s.local_aabb().transformed(&pose),
            });
            objects.push((body, &*o.shape, pose, o.filter));
        }
        if boxes.is_empty() {
            return Ok(WorldQuery {
                objects,
                bvh: None,
                cache: None,
            });
        }
        let bodies: Vec<BodyHandle> = objects.iter().map(|o| o.0).collect();
        let (bvh, refits) = self.query_cache.tree_for(&bodies, &boxes)?;
        Ok(WorldQuery {
            objects,
            bvh: Some(bvh),
            cache: Some((&self.query_cache, boxes, refits)),
        })
    }

    /// The closest body hit by a ray (see [`WorldQuery::raycast`]); builds a query structure
    /// for this one ray, so prefer [`World::query`] or [`World::raycast_batch`] for many.
    pub fn raycast(
        &self,
        origin: Vec3,
        dir: Vec3,
        max_distance: Real,
        mask: u32,
    ) -> Result<Option<BodyRayHit>> {
        self.query()?.raycast(origin, dir, max_distance, mask)
    }

    /// The closest body hit by each ray (see [`WorldQuery::raycast_batch`]).
    pub fn raycast_batch(
        &self,
        origins: &[Vec3],
        dirs: &[Vec3],
        max_distance: Real,
        mask: u32,
    ) -> Result<Vec<Option<BodyRayHit>>> {
        self.query()?
            .raycast_batch(origins, dirs, max_distance, mask)
    }

    /// The first body hit by a moving shape (see [`WorldQuery::shape_cast`]).
    pub fn shape_cast(
        &self,
        shape: &Shape,
        pose: &Isometry,
        velocity: Vec3,
        max_time: Real,
        mask: u32,
    ) -> Result<Option<BodyShapeCastHit>> {
        self.query()?
            .shape_cast(shape, pose, velocity, max_time, mask)
    }
}
