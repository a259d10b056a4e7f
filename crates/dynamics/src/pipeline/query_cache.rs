//! The scene-query tree a [`World`] keeps between queries ([`QueryCache`]), and its refresh
//! by the step.
//!
//! A query walks a tree over the bodies' boxes at their current poses (see
//! [`crate::pipeline::queries`]). The world keeps the tree, the per-body items and the
//! placed objects of the last query. A later query reuses them as they are while no body
//! moved (`CachedTree::current`), refits the tree when bodies moved, and rebuilds it when
//! the refit tree has grown too much or the bodies changed.
//!
//! **The step keeps a used tree current.** When a query used the tree since the last step,
//! the step ends by placing the bodies at their new poses and refitting the tree
//! ([`World::refresh_query_tree`], timed as [`super::PipelineTimings::query_tree`]), while
//! the poses it has just written are in the cache. A query right after the step then only
//! takes the tree. This is where Bullet and Rapier pay for the same work: their ray casts
//! walk the broadphase's tree (`btDbvtBroadphase::rayTest`, Rapier's
//! `BroadPhaseBvh::as_query_pipeline`), which their step keeps current. Measured
//! on the raytests scene (`examples/ray_batch.rs`, one thread): see the ARCHITECTURE's
//! fourteenth round. A world that stops querying stops paying after one step: the refresh
//! runs only for a tree used since the last one.

use super::queries::{QueryItem, QueryObject};
use super::World;
use crate::body_set::BodySet;
use carom_collision::math::{Aabb, Real};
use carom_collision::midphase::{Bvh, BvhLayout};
use carom_collision::Result;
use std::sync::Mutex;

/// The tree and the per-body items of the last [`World::query`], kept for the next one
/// (see the module docs). Cloning a world gives the clone an empty cache.
#[derive(Default)]
pub(crate) struct QueryCache {
    /// Behind a lock because queries take the tree through `&World`.
    slot: Mutex<Option<CachedTree>>,
}

/// A tree with the boxes it was fitted to and its node area when built, the items of the
/// bodies it covers (in its primitive order) with the collision world's objects stamp they
/// were read at, and the objects of the last query (reused as they are while `current`).
pub(super) struct CachedTree {
    pub(super) bvh: Bvh,
    pub(super) stamp: u64,
    pub(super) items: Vec<QueryItem>,
    pub(super) boxes: Vec<Aabb>,
    pub(super) built_area: Real,
    pub(super) objects: Vec<QueryObject>,
    /// A buffer for the boxes of the next refresh, and one for the node boxes of a refit
    /// (the step's refresh allocates nothing).
    pub(super) spare: Vec<Aabb>,
    pub(super) scratch: Vec<Aabb>,
    /// The objects, boxes and tree are those of the bodies' poses as they are now: no
    /// body moved since they were computed. While a [`super::queries::WorldQuery`] lives
    /// it borrows the world, so nothing can move; every `&mut` method of [`World`] that
    /// can move or replace a body clears this ([`QueryCache::moved`]), and the step's
    /// refresh sets it.
    pub(super) current: bool,
    /// A query used the tree since the last step: the next step refreshes it.
    pub(super) used: bool,
}

/// A cached tree for bodies that are still the same: the tree, the boxes it was fitted to
/// and its node area when built.
pub(super) type PreviousTree<'a> = (Bvh, &'a [Aabb], Real);

impl QueryCache {
    /// How much a refitted tree's node area may grow over its build's before the next query
    /// rebuilds it.
    pub const REBUILD_GROWTH: Real = 1.25;

    /// Largest number of bodies in a leaf of the tree. An exact body test costs far more
    /// than a node visit, so the leaves are smaller than a mesh's (8 triangles): the
    /// closest-first walk then orders nearly every body by its box entry. Two rather than
    /// one, which doubles the nodes each refit goes through: callgrind, the 500-ray batch
    /// of the raytests scene with its tree (40 batches after 100 steps), 137.6 M
    /// instructions with leaves of 8, 138.8 M with 1, 131.4 M with 2.
    pub const LEAF_SIZE: usize = 2;

    /// The tree's node layout: unquantised (`f32` boxes in its 4-wide nodes). A mesh's
    /// tree is quantised to halve its memory; this one is small (about 170 wide nodes for
    /// 1000 bodies, 22 KB) and refitted before nearly every query, where quantising every
    /// node was half the refit, and its rays then converted the planes of every node they
    /// visited. Callgrind, the 500-ray batch of the raytests scene with its tree (40
    /// batches after 100 steps): 130.6 M instructions quantised, 120.7 M unquantised.
    pub const LAYOUT: BvhLayout = BvhLayout::Unquantized;

    /// The tree over `boxes`: `previous` (a tree of the same bodies) reused when no box
    /// changed, refitted when some did and it has not grown too much, a new one otherwise;
    /// with its node area when built.
    /// `scratch` holds the refit's node boxes (see [`Bvh::refit_with`]).
    pub(super) fn tree_for(
        previous: Option<PreviousTree>,
        boxes: &[Aabb],
        scratch: &mut Vec<Aabb>,
    ) -> Result<(Bvh, Real)> {
        if let Some((bvh, old_boxes, built_area)) = previous {
            if old_boxes == boxes {
                return Ok((bvh, built_area));
            }
            let mut bvh = bvh;
            bvh.refit_with(boxes, scratch)?;
            if bvh.node_area() <= Self::REBUILD_GROWTH * built_area {
                return Ok((bvh, built_area));
            }
        }
        let bvh = Bvh::with_max_leaf_size(boxes, QueryCache::LAYOUT, QueryCache::LEAF_SIZE)?;
        let area = bvh.node_area();
        Ok((bvh, area))
    }

    /// Takes the kept tree out (a poisoned lock, after a panic elsewhere while it was held,
    /// only loses the cache).
    pub(super) fn take(&self) -> Option<CachedTree> {
        self.slot.lock().ok().and_then(|mut g| g.take())
    }

    /// Keeps `tree` for the next query.
    pub(super) fn put(&self, tree: CachedTree) {
        if let Ok(mut g) = self.slot.lock() {
            *g = Some(tree);
        }
    }
}

impl QueryCache {
    /// Some body may have moved or been replaced: the kept objects and boxes no longer
    /// describe the bodies (`CachedTree::current`).
    pub(super) fn moved(&mut self) {
        if let Some(c) = self.slot_mut() {
            c.current = false;
        }
    }

    /// The kept tree, through `&mut` (no locking).
    fn slot_mut(&mut self) -> Option<&mut CachedTree> {
        match self.slot.get_mut() {
            Ok(s) => s.as_mut(),
            Err(_) => None,
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

/// Places the bodies of `items` at their current poses in `set`: their query objects (pose,
/// ball, groups) into `objects` and their world boxes into `boxes`, both cleared first.
pub(super) fn place(
    items: &[QueryItem],
    set: &BodySet,
    objects: &mut Vec<QueryObject>,
    boxes: &mut Vec<Aabb>,
) {
    objects.clear();
    boxes.clear();
    for item in items {
        let pose = set.pose_of(item.body.index as usize);
        let (world, center) = item.placed(&pose);
        boxes.push(world);
        objects.push(QueryObject {
            pose,
            center,
            radius: item.radius,
            group: item.group,
        });
    }
}

impl World {
    /// Ends a step: when a query used the kept tree since the last step and the world's
    /// objects are the same, places the bodies at their new poses and refits (or rebuilds)
    /// the tree, so that the next query finds it current; otherwise only marks it stale.
    /// A failed refit drops the cache (the next query builds afresh). True when it
    /// refreshed the tree.
    pub(super) fn refresh_query_tree(&mut self) -> bool {
        let stamp = self.collision.objects_stamp();
        let set = self.dynamics.bodies();
        let slot = match self.query_cache.slot.get_mut() {
            Ok(s) => s,
            Err(_) => return false,
        };
        let Some(mut c) = slot.take() else {
            return false;
        };
        c.current = false;
        if !c.used || c.stamp != stamp {
            c.used = false;
            *slot = Some(c);
            return false;
        }
        let mut boxes = std::mem::take(&mut c.spare);
        place(&c.items, set, &mut c.objects, &mut boxes);
        let previous = Some((c.bvh, c.boxes.as_slice(), c.built_area));
        if let Ok((bvh, area)) = QueryCache::tree_for(previous, &boxes, &mut c.scratch) {
            c.bvh = bvh;
            c.built_area = area;
            c.spare = std::mem::replace(&mut c.boxes, boxes);
            c.current = true;
            c.used = false;
            *slot = Some(c);
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use carom_collision::math::Vec3;

    /// Unit boxes on a 10 × 10 grid, 3 m apart, each moved by `offset(i)`.
    fn grid(offset: impl Fn(usize) -> Vec3) -> Vec<Aabb> {
        (0..100)
            .map(|i| {
                let c = Vec3::new((i % 10) as Real * 3.0, 0.0, (i / 10) as Real * 3.0) + offset(i);
                Aabb::new(c - Vec3::splat(0.5), c + Vec3::splat(0.5))
            })
            .collect()
    }

    /// The cache's rebuild rule: a tree whose boxes jitter is refitted and keeps its build's
    /// area; one whose boxes swap places across the grid (same bounds, crossing subtrees) has
    /// grown past `REBUILD_GROWTH` and is rebuilt, with the area of a fresh build; without a
    /// previous tree (other bodies) it is built afresh. Every tree handed out bounds its
    /// boxes as a fresh one does.
    #[test]
    fn refitted_trees_are_rebuilt_when_their_area_grows() {
        let fresh_area = |boxes: &[Aabb]| {
            Bvh::with_max_leaf_size(boxes, QueryCache::LAYOUT, QueryCache::LEAF_SIZE)
                .unwrap()
                .node_area()
        };
        let first = grid(|_| Vec3::ZERO);
        let (bvh, built) = QueryCache::tree_for(None, &first, &mut Vec::new()).unwrap();
        assert_eq!(built, fresh_area(&first));

        // The same boxes: the same tree, untouched.
        let same = bvh.clone();
        let (bvh, area) =
            QueryCache::tree_for(Some((bvh, &first, built)), &first, &mut Vec::new()).unwrap();
        assert_eq!(area, built);
        assert!(bvh == same);

        // Jitter of 2 cm: refitted, the build's area kept, the tree bounds the new boxes.
        let jitter = grid(|i| Vec3::new(0.02 * (i % 3) as Real, 0.01, -0.02 * (i % 2) as Real));
        let (bvh, area) =
            QueryCache::tree_for(Some((bvh, &first, built)), &jitter, &mut Vec::new()).unwrap();
        assert_eq!(area, built, "a jittered tree was rebuilt");
        assert!(bvh.node_area() <= QueryCache::REBUILD_GROWTH * built);
        let mut seen = [false; 100];
        for (i, b) in jitter.iter().enumerate() {
            bvh.for_each_candidate_on_ray(b.center() - Vec3::Y * 5.0, Vec3::Y, 10.0, |p, _| {
                seen[i] |= p as usize == i;
                true
            });
        }
        assert!(seen.iter().all(|&s| s), "a refitted tree lost a box");

        // Boxes scrambled across the grid (box i takes the place of 37 i mod 100): the same
        // bounds, but every subtree now spans the grid; rebuilt.
        let swapped = grid(|i| {
            let j = (37 * i) % 100;
            Vec3::new(
                (j % 10) as Real * 3.0 - (i % 10) as Real * 3.0,
                0.0,
                (j / 10) as Real * 3.0 - (i / 10) as Real * 3.0,
            )
        });
        let (bvh, area) =
            QueryCache::tree_for(Some((bvh, &jitter, area)), &swapped, &mut Vec::new()).unwrap();
        assert_eq!(area, fresh_area(&swapped), "a scrambled tree was kept");
        assert_eq!(bvh.node_area(), area);
    }
}
