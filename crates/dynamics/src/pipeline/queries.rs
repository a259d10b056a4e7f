//! Scene queries through a [`World`]: ray casts (one or a batch) and linear shape casts
//! against every body with a shape, closest hit first.
//!
//! The broadphase answers box-overlap pairs over boxes of the last step's poses, fattened
//! by speculative margins (and a method without a tree has no ray walk at all), so a query
//! builds a [`Bvh`] (binned SAH, 4-wide nodes of `f32` boxes, `carom_collision::midphase`)
//! over the bodies' current world boxes, then walks it closest-first: a ray visits the
//! nearer child first and shrinks its `max_t` at every hit (Bullet's
//! `btDbvt::rayTestInternal`, Jolt's `CastRay` with a closest-hit collector),
//! so the exact `query::raycast` runs on few shapes; a shape cast visits the leaves whose
//! boxes meet the cast shape's box swept by its motion. Building is `O(N log N)`; a
//! [`WorldQuery`] keeps the tree for many queries against the same state (the batch form
//! builds one for its whole batch).
//!
//! The world keeps the tree between queries (`QueryCache`, in `query_cache.rs`, which also
//! has the step keep a used tree current, so that a query right after a step only takes it,
//! as the peers' broadphase trees are kept by their steps): when the same bodies are
//! queried again, it is reused as is if no body moved, refitted to the new boxes otherwise
//! (`Bvh::refit`, about a seventieth of a build's instructions for 1000 bodies), and
//! rebuilt when the refitted tree's node area (`Bvh::node_area`, the surface area
//! heuristic's cost for a fixed topology) has grown past `QueryCache::REBUILD_GROWTH`
//! times the area it had when built, so the topology follows bodies that move far (Bullet's
//! `btDbvt` refits and re-inserts for the same reason) while a settled scene keeps its tree.
//! (It rebuilt after every eight refits before: in "raytests" the rebuilds were half the
//! 500-ray batch's instructions.) Results do not depend on the topology (closest hit, ties
//! to the lower body slot), so a refitted tree answers exactly what a fresh one would.
//! The cache also keeps each body's query item (body, shape, filter groups, local box and ball
//! radius) with the collision world's `objects_stamp`, which changes whenever an object is
//! added or removed or its filter changes: while it holds, a query reads only the bodies'
//! poses, not the collision objects, the object-to-body map and the shapes (the raytests
//! batch's build 0.115 → 0.086 ms, medians of six alternated `ray_batch 400 150` runs).
//!
//! A candidate costs little when the ray passes it by: each body also keeps a ball around
//! its posed local box, and a ray that clearly misses the ball (by 1e-4 of the lengths
//! involved) skips the exact test; the exact test gets the ray made once per ray
//! (`query::raycast_ray`) and, for hulls, stops at the current closest hit
//! (`ray_hull_solid`). In the raytests batch this turned away 83 % of the hull candidates.
//!
//! Poses are the bodies' current poses (what [`World::bodies`] reports, including teleports
//! since the last step), not the collision objects' poses of the last step.

use super::query_cache::{place, CachedTree, QueryCache};
use super::World;
use crate::body_set::BodyHandle;
use carom_collision::math::{check_finite_vec, check_isometry, Aabb, Isometry, Mat3, Real, Vec3};
use carom_collision::midphase::Bvh;
use carom_collision::query::{raycast_ray, shape_cast, Ray, RayHit, ShapeCastHit};
use carom_collision::shape::Shape;
use carom_collision::{CaromError, Result};
use std::sync::Arc;

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
    /// Per body (in the order of `items`): its pose and ball at this query.
    objects: Vec<QueryObject>,
    /// Per body: what does not change while the world's objects stay the same.
    items: Vec<QueryItem>,
    bvh: Option<Bvh>,
    /// Where the tree and the items go back when the query is dropped.
    cache: Option<Kept<'w>>,
}

/// What a [`WorldQuery`] hands back to the world's cache with its tree, items and objects:
/// the objects' stamp, the boxes the tree was fitted to, its node area when built, and the
/// buffers of the next refresh (boxes, and the node boxes of a refit).
#[derive(Debug)]
struct Kept<'w> {
    cache: &'w QueryCache,
    stamp: u64,
    boxes: Vec<Aabb>,
    built_area: Real,
    spare: Vec<Aabb>,
    scratch: Vec<Aabb>,
}

/// A body as a query sees it at its current pose: the pose, and a ball around the shape
/// (the centre of its posed local box and that box's half diagonal), which lets a ray skip
/// the shape's exact test when it clearly passes by; with the body's collision group, so
/// that the test of a candidate reads this one record.
#[derive(Debug, Clone, Copy)]
pub(super) struct QueryObject {
    pub(super) pose: Isometry,
    pub(super) center: Vec3,
    pub(super) radius: Real,
    pub(super) group: u32,
}

/// What a query needs of a body that stays the same while the collision world's objects,
/// shapes and filters do (`CollisionWorld::objects_stamp`): kept by the cache, so a query
/// of an unchanged world reads only the bodies' poses (the collision objects, the
/// object-to-body map and the shapes' boxes were most of the query's build, and most of its
/// cache misses after a step).
#[derive(Debug, Clone)]
pub(super) struct QueryItem {
    pub(super) body: BodyHandle,
    shape: Arc<Shape>,
    /// The collision object's filter groups (what a query's mask tests).
    pub(super) group: u32,
    /// The shape's local box: centre and half extents (unused for planes).
    local_center: Vec3,
    local_half: Vec3,
    /// The ball's radius: the local box's half diagonal, infinite for planes.
    pub(super) radius: Real,
}

impl QueryItem {
    /// The body's world box and ball centre at `pose`: Arvo's transformed local box,
    /// conservative and O(1) (the tight box costs six support queries per hull, which made
    /// the 500-ray batch of the raytests scene 1.4x slower), with the box's centre through
    /// the same matrix as its half extents (`Aabb::transformed` rotates it by the quaternion
    /// as well); planes are unbounded, so they keep their own box.
    #[inline]
    pub(super) fn placed(&self, pose: &Isometry) -> (Aabb, Vec3) {
        if let Shape::Plane(_) = &*self.shape {
            return (self.shape.aabb(pose), pose.translation);
        }
        let r = Mat3::from_quat(pose.rotation);
        let c = r * self.local_center + pose.translation;
        (
            Aabb::from_center_half_extents(c, r.abs() * self.local_half),
            c,
        )
    }
}

/// True only when the ray clearly misses the ball of `radius` around `center` within
/// `[0, max_t]`: the ball's distance from the line, or its extent along the ray, is out of
/// reach by more than a margin of 1e-4 of the lengths and coordinates involved. That is far
/// above the rounding of the centre (taken from the world box) and of this test, so a ray
/// that meets the shape inside the ball is never turned away. NaN never rejects, and
/// neither does an infinite radius (planes).
#[inline]
fn misses_ball(ray: &Ray, center: Vec3, radius: Real, max_t: Real) -> bool {
    let m = center - ray.origin;
    // The centre is rounded at its coordinates' scale, the offset at the ray origin's.
    let scale = 2.0 * m.abs().max_element() + center.abs().max_element();
    let r = radius + 1e-4 * (radius + scale + ray.origin.abs().max_element());
    let along = m.dot(ray.dir);
    m.cross(ray.dir).length_squared() > r * r || along + r < 0.0 || along - r > max_t
}

impl Drop for WorldQuery<'_> {
    fn drop(&mut self) {
        if let (Some(bvh), Some(k)) = (self.bvh.take(), self.cache.take()) {
            k.cache.put(CachedTree {
                bvh,
                stamp: k.stamp,
                items: std::mem::take(&mut self.items),
                boxes: k.boxes,
                built_area: k.built_area,
                objects: std::mem::take(&mut self.objects),
                spare: k.spare,
                scratch: k.scratch,
                // A query borrows the world: no body moved while it lived.
                current: true,
                used: true,
            });
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
            let o = &self.objects[i as usize];
            if o.group & mask == 0 || misses_ball(ray, o.center, o.radius, *max_t) {
                return true;
            }
            let item = &self.items[i as usize];
            let body = &item.body;
            if let Ok(Some(hit)) = raycast_ray(&item.shape, &o.pose, ray, *max_t, true) {
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
            let (o, item) = (&self.objects[i as usize], &self.items[i as usize]);
            let (body, other, other_pose) = (&item.body, &*item.shape, &o.pose);
            if o.group & mask == 0 {
                continue;
            }
            let limit = best.map_or(max_time, |b| b.hit.toi);
            let hit = shape_cast(shape, &pose, velocity, other, other_pose, Vec3::ZERO, limit)?;
            if let Some(hit) = hit {
                // Ties go to the lower body slot (objects are not in slot order once slots
                // are reused), as for rays.
                if best.is_none_or(|b| {
                    hit.toi < b.hit.toi || (hit.toi == b.hit.toi && body.index < b.body.index)
                }) {
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
        let stamp = self.collision.objects_stamp();
        // The last query's items when the objects are the same (the stamp), its tree when
        // the bodies are, and its objects and boxes buffers in any case; all of it as it is
        // when no body moved since (`CachedTree::current`).
        let (items, previous, mut objects, spare, mut scratch) = match self.query_cache.take() {
            Some(c) if c.stamp == stamp && c.current => {
                return Ok(WorldQuery {
                    objects: c.objects,
                    items: c.items,
                    bvh: Some(c.bvh),
                    cache: Some(Kept {
                        cache: &self.query_cache,
                        stamp,
                        boxes: c.boxes,
                        built_area: c.built_area,
                        spare: c.spare,
                        scratch: c.scratch,
                    }),
                });
            }
            Some(c) if c.stamp == stamp => (
                c.items,
                Some((c.bvh, c.boxes, c.built_area)),
                c.objects,
                c.spare,
                c.scratch,
            ),
            Some(c) => {
                let items = self.query_items();
                let same = items.len() == c.items.len()
                    && items.iter().zip(&c.items).all(|(a, b)| a.body == b.body);
                let previous = same.then_some((c.bvh, c.boxes, c.built_area));
                (items, previous, c.objects, c.spare, c.scratch)
            }
            None => (self.query_items(), None, Vec::new(), Vec::new(), Vec::new()),
        };
        let mut boxes = spare;
        place(&items, set, &mut objects, &mut boxes);
        if boxes.is_empty() {
            return Ok(WorldQuery {
                objects,
                items,
                bvh: None,
                cache: None,
            });
        }
        let (bvh, area, spare) = match previous {
            Some((bvh, old, built)) => {
                let previous = Some((bvh, old.as_slice(), built));
                let (bvh, area) = QueryCache::tree_for(previous, &boxes, &mut scratch)?;
                (bvh, area, old)
            }
            None => {
                let (bvh, area) = QueryCache::tree_for(None, &boxes, &mut scratch)?;
                (bvh, area, Vec::new())
            }
        };
        Ok(WorldQuery {
            objects,
            items,
            bvh: Some(bvh),
            cache: Some(Kept {
                cache: &self.query_cache,
                stamp,
                boxes,
                built_area: area,
                spare,
                scratch,
            }),
        })
    }

    /// The query items of the bodies with a shape, in the collision world's order.
    fn query_items(&self) -> Vec<QueryItem> {
        self.collision
            .iter()
            .filter_map(|(h, o)| {
                let body = self.body_of_object(h)?;
                let (local_center, local_half, radius) = match &*o.shape {
                    Shape::Plane(_) => (Vec3::ZERO, Vec3::ZERO, Real::INFINITY),
                    s => {
                        let local = s.local_aabb();
                        let half = local.half_extents();
                        (local.center(), half, half.length())
                    }
                };
                Some(QueryItem {
                    body,
                    shape: Arc::clone(&o.shape),
                    group: o.filter.group,
                    local_center,
                    local_half,
                    radius,
                })
            })
            .collect()
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The ball test only turns away rays that miss the ball: every ray the exact ray–ball
    /// interval puts inside the ball within `[0, max_t]` passes, including tangent rays,
    /// rays from inside, rays ending at the ball and everything 10 km out; and it does
    /// reject misses (else it would buy nothing).
    #[test]
    fn the_ball_test_never_rejects_a_ray_that_meets_the_ball() {
        use carom_collision::query::ray::analytic::ray_ball;
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut unit = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as Real / (1u64 << 53) as Real
        };
        let (mut met, mut missed, mut rejected) = (0, 0, 0);
        for case in 0..40_000 {
            let far = if case % 4 == 0 { 1.0e4 } else { 0.0 };
            let mut v = |s: Real| Vec3::new(unit() - 0.5, unit() - 0.5, unit() - 0.5) * s;
            let center = Vec3::splat(far) + v(20.0);
            let radius = [0.0, 0.01, 1.0, 7.0][case % 4 / 2 + case % 2 * 2];
            let origin = Vec3::splat(far) + v(40.0);
            let mut dir = (center - origin).normalize_or(Vec3::X);
            if case % 3 == 0 {
                // Tangent: aim at a point on the ball's rim, seen from the origin.
                let side = dir.any_orthonormal_vector();
                dir = (center + side * radius - origin).normalize_or(Vec3::X);
            } else if case % 3 == 1 {
                dir = (dir + v(1.0)).normalize_or(Vec3::X);
            }
            let ray = Ray::new(origin, dir).unwrap();
            let reach = (center - origin).length();
            let max_t = [reach, 0.5 * reach, Real::INFINITY, reach - radius][case % 4];
            let m = ray.origin - center;
            let meets = ray_ball(m, ray.dir, Vec3::ZERO, radius)
                .is_some_and(|i| i.t1 >= 0.0 && i.t0 <= max_t);
            let no = misses_ball(&ray, center, radius, max_t);
            if meets {
                met += 1;
                assert!(!no, "case {case}: a ray meeting the ball was rejected");
            } else {
                missed += 1;
                rejected += usize::from(no);
            }
        }
        assert!(met > 5_000 && missed > 5_000, "{met} met, {missed} missed");
        // Many misses here graze the ball (tangent aims, bounds ending at it): still more than
        // half are turned away.
        assert!(
            rejected * 2 > missed,
            "{rejected} of {missed} misses rejected"
        );
        // Infinite balls (planes) and NaN never reject.
        let ray = Ray::new(Vec3::ZERO, Vec3::X).unwrap();
        assert!(!misses_ball(&ray, Vec3::Y * 1e6, Real::INFINITY, 1.0));
        assert!(!misses_ball(&ray, Vec3::splat(Real::NAN), 1.0, 1.0));
    }
}
