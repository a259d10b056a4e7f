//! The dynamic AABB tree: a binary tree of boxes over moving objects, updated incrementally.
//!
//! Follows the talk's `btDbvt` (Bullet, `src/BulletCollision/BroadphaseCollision/btDbvt.cpp`)
//! and Box2D v3's `b2DynamicTree` (`box2d/src/dynamic_tree.c`, Catto, "Dynamic Bounding
//! Volume Hierarchies", GDC 2019):
//! - nodes live in one flat array with a free list threaded through unused nodes (no
//!   allocation per node); a leaf keeps its node index for its whole life, so the index is
//!   the proxy id, paired with a generation to detect stale handles;
//! - leaves store *fat* boxes: the object's box grown by a margin and swept by its predicted
//!   displacement, so small motions ([`DynamicTree::move_proxy`]) change nothing;
//! - insertion picks the sibling by a cost ([`InsertStrategy`]): Bullet's Manhattan-distance
//!   descent, or the surface-area heuristic with a branch-and-bound search and tree rotations
//!   (in `tree_insert.rs`);
//! - removal re-links the sibling to the grandparent and refits the ancestors;
//! - [`DynamicTree::optimize_incremental`] re-inserts a few leaves per call (the talk's
//!   "incremental tree optimization").
//!
//! Queries are in `tree_query.rs`, the invariant checker in `tree_validate.rs`.

use crate::error::{CaromError, Result};
use crate::math::{Aabb, Real, Vec3};

/// "No node".
pub(crate) const NULL: u32 = u32::MAX;

/// How [`DynamicTree`] chooses where to insert a leaf.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum InsertStrategy {
    /// Surface-area heuristic: branch-and-bound search for the sibling that minimises the
    /// total area added to the tree, then tree rotations on the way up (Box2D v3,
    /// `b2FindBestSibling` and `b2RotateNodes`).
    #[default]
    SurfaceArea,
    /// Descend towards the child whose centre is nearest in Manhattan distance, no rotations
    /// (Bullet's `btDbvt::insertleaf` with `Select`/`Proximity`, as shown in the talk).
    Manhattan,
}

/// A handle to a leaf of a [`DynamicTree`]: its node index and generation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct TreeProxy {
    /// Node index of the leaf.
    pub index: u32,
    /// Generation of the node when the leaf was created.
    pub generation: u32,
}

/// A tree node. Internal nodes have two children; leaves have `child1 == NULL` and carry
/// `user` data. Free nodes have `height == -1` and link the free list through `parent`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Node {
    pub aabb: Aabb,
    pub parent: u32,
    pub child1: u32,
    pub child2: u32,
    pub height: i32,
    pub user: u32,
    pub generation: u32,
}

impl Node {
    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.child1 == NULL
    }
}

/// A dynamic bounding-volume tree over boxes with `u32` user data (see the module docs).
#[derive(Debug, Clone)]
pub struct DynamicTree {
    pub(crate) nodes: Vec<Node>,
    pub(crate) root: u32,
    pub(crate) free_list: u32,
    pub(crate) leaf_count: usize,
    pub(crate) strategy: InsertStrategy,
    margin: Real,
    motion_scale: Real,
    opt_cursor: u32,
}

impl Default for DynamicTree {
    fn default() -> Self {
        Self::new(InsertStrategy::default(), 0.1)
    }
}

impl DynamicTree {
    /// An empty tree. `margin` is how much leaf boxes are grown on every side.
    pub fn new(strategy: InsertStrategy, margin: Real) -> Self {
        DynamicTree {
            nodes: Vec::new(),
            root: NULL,
            free_list: NULL,
            leaf_count: 0,
            strategy,
            margin: margin.max(0.0),
            motion_scale: 2.0,
            opt_cursor: 0,
        }
    }

    /// The insertion strategy.
    pub fn strategy(&self) -> InsertStrategy {
        self.strategy
    }

    /// The fat-box margin.
    pub fn margin(&self) -> Real {
        self.margin
    }

    /// Sets how many times the given displacement the fat boxes are swept by (default 2).
    pub fn set_motion_scale(&mut self, scale: Real) {
        self.motion_scale = scale.max(0.0);
    }

    /// Number of leaves.
    pub fn len(&self) -> usize {
        self.leaf_count
    }

    /// True when the tree has no leaf.
    pub fn is_empty(&self) -> bool {
        self.leaf_count == 0
    }

    /// Height of the tree (0 for a single leaf or an empty tree).
    pub fn height(&self) -> i32 {
        if self.root == NULL {
            0
        } else {
            self.nodes[self.root as usize].height
        }
    }

    /// The box of the root (all leaves), if any.
    pub fn root_aabb(&self) -> Option<Aabb> {
        (self.root != NULL).then(|| self.nodes[self.root as usize].aabb)
    }

    /// Sum of the surface areas of the internal nodes over the root's: the SAH cost used to
    /// compare insertion strategies (lower is better).
    pub fn area_ratio(&self) -> Real {
        if self.root == NULL {
            return 0.0;
        }
        let root_area = self.nodes[self.root as usize].aabb.surface_area();
        let total: Real = self
            .nodes
            .iter()
            .filter(|n| n.height > 0)
            .map(|n| n.aabb.surface_area())
            .sum();
        if root_area > 0.0 {
            total / root_area
        } else {
            0.0
        }
    }

    pub(crate) fn allocate_node(&mut self) -> u32 {
        if self.free_list == NULL {
            let i = self.nodes.len() as u32;
            self.nodes.push(Node {
                aabb: Aabb::EMPTY,
                parent: NULL,
                child1: NULL,
                child2: NULL,
                height: 0,
                user: 0,
                generation: 0,
            });
            return i;
        }
        let i = self.free_list;
        let n = &mut self.nodes[i as usize];
        self.free_list = n.parent;
        n.parent = NULL;
        n.child1 = NULL;
        n.child2 = NULL;
        n.height = 0;
        i
    }

    pub(crate) fn free_node(&mut self, i: u32) {
        let free = self.free_list;
        let n = &mut self.nodes[i as usize];
        n.height = -1;
        n.generation = n.generation.wrapping_add(1);
        n.child1 = NULL;
        n.child2 = NULL;
        n.parent = free;
        self.free_list = i;
    }

    /// The fat box for an object box and its predicted displacement.
    pub fn fat_aabb(&self, aabb: &Aabb, displacement: Vec3) -> Aabb {
        aabb.expanded(self.margin)
            .swept(displacement * self.motion_scale)
    }

    fn check(&self, proxy: TreeProxy) -> Result<usize> {
        let i = proxy.index as usize;
        match self.nodes.get(i) {
            Some(n) if n.height == 0 && n.generation == proxy.generation => Ok(i),
            _ => Err(CaromError::UnknownHandle(format!("{proxy:?}"))),
        }
    }

    /// Inserts a leaf for an object with box `aabb` (validated) and user data `user`; the
    /// leaf stores the fat box.
    pub fn create_proxy(&mut self, aabb: Aabb, user: u32) -> Result<TreeProxy> {
        crate::math::check_aabb(&aabb)?;
        let fat = self.fat_aabb(&aabb, Vec3::ZERO);
        Ok(self.create_proxy_fat(fat, user))
    }

    /// Inserts a leaf whose stored (fat) box is exactly `fat` (not validated).
    pub(crate) fn create_proxy_fat(&mut self, fat: Aabb, user: u32) -> TreeProxy {
        let leaf = self.allocate_node();
        let n = &mut self.nodes[leaf as usize];
        n.aabb = fat;
        n.user = user;
        n.height = 0;
        let generation = n.generation;
        self.insert_leaf(leaf, self.root);
        self.leaf_count += 1;
        TreeProxy {
            index: leaf,
            generation,
        }
    }

    /// Replaces the user data of a leaf. A stale or unknown handle is an error.
    pub fn set_user(&mut self, proxy: TreeProxy, user: u32) -> Result<()> {
        let i = self.check(proxy)?;
        self.nodes[i].user = user;
        Ok(())
    }

    /// The user data of a leaf. A stale or unknown handle is an error.
    pub fn user(&self, proxy: TreeProxy) -> Result<u32> {
        Ok(self.nodes[self.check(proxy)?].user)
    }

    /// Removes a leaf. A stale or unknown handle is an error.
    pub fn destroy_proxy(&mut self, proxy: TreeProxy) -> Result<()> {
        let i = self.check(proxy)? as u32;
        self.remove_leaf(i);
        self.free_node(i);
        self.leaf_count -= 1;
        Ok(())
    }

    /// Moves a leaf to the object box `aabb` with predicted `displacement`. Does nothing and
    /// returns `false` when `aabb` is still inside the fat box (and the fat box is not much
    /// larger than needed); otherwise re-inserts the leaf with a new fat box and returns
    /// `true`.
    pub fn move_proxy(&mut self, proxy: TreeProxy, aabb: Aabb, displacement: Vec3) -> Result<bool> {
        let i = self.check(proxy)?;
        crate::math::check_aabb(&aabb)?;
        Ok(self.move_leaf(i as u32, &aabb, displacement))
    }

    /// [`DynamicTree::move_proxy`] for a leaf index known to be live and a validated box.
    pub(crate) fn move_leaf(&mut self, leaf: u32, aabb: &Aabb, displacement: Vec3) -> bool {
        debug_assert!(
            self.nodes[leaf as usize].height == 0,
            "move_leaf on a non-leaf"
        );
        if !self.needs_new_fat(leaf as usize, aabb, displacement) {
            return false;
        }
        let new_fat = self.fat_aabb(aabb, displacement);
        self.move_proxy_fat(leaf, new_fat);
        true
    }

    /// The fat box of a leaf index known to be live.
    #[inline]
    pub(crate) fn leaf_fat(&self, leaf: u32) -> Aabb {
        self.nodes[leaf as usize].aabb
    }

    /// Like [`DynamicTree::move_proxy`], but a leaf whose box left its fat box keeps its
    /// place in the tree: the fat box is replaced and the ancestors are refitted up to the
    /// first one whose box does not change (Box2D v3's `b2DynamicTree_EnlargeProxy`, which
    /// refits instead of re-inserting the proxies of moving bodies; rapier's BVH broadphase
    /// does the same). O(depth) with no sibling search; the topology is only as good as
    /// it was, which [`DynamicTree::optimize_incremental`] restores over time. Returns
    /// `true` when the fat box changed.
    pub fn refit_proxy(
        &mut self,
        proxy: TreeProxy,
        aabb: Aabb,
        displacement: Vec3,
    ) -> Result<bool> {
        let i = self.check(proxy)?;
        crate::math::check_aabb(&aabb)?;
        Ok(self.refit_leaf(i as u32, &aabb, displacement))
    }

    /// [`DynamicTree::refit_proxy`] for a leaf index known to be live and a validated box
    /// (the broadphase, which owns its leaves and has validated the box, calls this).
    pub(crate) fn refit_leaf(&mut self, leaf: u32, aabb: &Aabb, displacement: Vec3) -> bool {
        let i = leaf as usize;
        debug_assert!(self.nodes[i].height == 0, "refit_leaf on a non-leaf");
        if !self.needs_new_fat(i, aabb, displacement) {
            return false;
        }
        self.refit_fat(leaf, aabb, displacement);
        true
    }

    /// The refit of [`DynamicTree::refit_leaf`] once [`DynamicTree::needs_new_fat`] said
    /// yes: the leaf takes a fresh fat box and its ancestors are refitted.
    pub(crate) fn refit_fat(&mut self, leaf: u32, aabb: &Aabb, displacement: Vec3) {
        let i = leaf as usize;
        self.nodes[i].aabb = self.fat_aabb(aabb, displacement);
        let mut p = self.nodes[i].parent;
        while p != NULL {
            let n = self.nodes[p as usize];
            let merged = self.nodes[n.child1 as usize]
                .aabb
                .merge(&self.nodes[n.child2 as usize].aabb);
            if merged == n.aabb {
                // The ancestors were computed from this same box: nothing above changes.
                break;
            }
            self.nodes[p as usize].aabb = merged;
            p = n.parent;
        }
    }

    /// True when leaf `i`'s fat box must be replaced for the object box `aabb` moving by
    /// `displacement`: the box left it, or the fat box is far larger than a fresh one (the
    /// object stopped; a stale sweep would keep producing useless candidate pairs).
    #[inline(always)]
    pub(crate) fn needs_new_fat(&self, i: usize, aabb: &Aabb, displacement: Vec3) -> bool {
        let fat = self.nodes[i].aabb;
        if !fat.contains(aabb) {
            return true;
        }
        let grow = displacement.abs() * (4.0 * self.motion_scale) + Vec3::splat(4.0 * self.margin);
        !Aabb::new(aabb.min - grow, aabb.max + grow).contains(&fat)
    }

    /// Re-inserts leaf `i` with the fat box `fat`. With the Manhattan strategy the search
    /// starts at the closest ancestor that removal did not resize (the talk's btDbvt::update
    /// trick), otherwise at the root.
    pub(crate) fn move_proxy_fat(&mut self, i: u32, fat: Aabb) {
        let start = self.remove_leaf(i);
        self.nodes[i as usize].aabb = fat;
        let start = match self.strategy {
            InsertStrategy::Manhattan => {
                // Walk up until the subtree contains the new box (or the root).
                let mut s = start;
                while s != NULL
                    && self.nodes[s as usize].parent != NULL
                    && !self.nodes[s as usize].aabb.contains(&fat)
                {
                    s = self.nodes[s as usize].parent;
                }
                s
            }
            InsertStrategy::SurfaceArea => self.root,
        };
        let start = if start == NULL { self.root } else { start };
        self.insert_leaf(i, start);
    }

    /// The fat box stored in a leaf.
    pub fn fat_aabb_of(&self, proxy: TreeProxy) -> Result<Aabb> {
        Ok(self.nodes[self.check(proxy)?].aabb)
    }

    /// The user data of a leaf.
    pub fn user_data(&self, proxy: TreeProxy) -> Result<u32> {
        Ok(self.nodes[self.check(proxy)?].user)
    }

    /// Removes leaf `leaf` from the tree structure (the node stays allocated): its sibling
    /// takes the parent's place and the ancestors are refitted. Returns the grandparent (the
    /// lowest node whose subtree changed), or the new root.
    pub(crate) fn remove_leaf(&mut self, leaf: u32) -> u32 {
        if leaf == self.root {
            self.root = NULL;
            return NULL;
        }
        let parent = self.nodes[leaf as usize].parent;
        let grand = self.nodes[parent as usize].parent;
        let p = self.nodes[parent as usize];
        let sibling = if p.child1 == leaf { p.child2 } else { p.child1 };
        self.free_node(parent);
        self.nodes[leaf as usize].parent = NULL;
        if grand == NULL {
            self.root = sibling;
            self.nodes[sibling as usize].parent = NULL;
            return sibling;
        }
        let g = &mut self.nodes[grand as usize];
        if g.child1 == parent {
            g.child1 = sibling;
        } else {
            g.child2 = sibling;
        }
        self.nodes[sibling as usize].parent = grand;
        self.refit_upwards(grand, false);
        grand
    }

    /// Recomputes boxes and heights from `index` to the root (with rotations when `rotate`).
    pub(crate) fn refit_upwards(&mut self, mut index: u32, rotate: bool) {
        while index != NULL {
            if rotate {
                self.rotate(index);
            }
            let n = self.nodes[index as usize];
            let (c1, c2) = (self.nodes[n.child1 as usize], self.nodes[n.child2 as usize]);
            let node = &mut self.nodes[index as usize];
            node.aabb = c1.aabb.merge(&c2.aabb);
            node.height = 1 + c1.height.max(c2.height);
            index = node.parent;
        }
    }

    /// Re-inserts `count` leaves, cycling through the node array: the talk's incremental
    /// optimisation, which undoes the quality loss of many moves a few leaves at a time.
    pub fn optimize_incremental(&mut self, count: usize) {
        if self.leaf_count < 3 || self.nodes.is_empty() {
            return;
        }
        let mut done = 0;
        let mut scanned = 0;
        let n = self.nodes.len() as u32;
        while done < count && scanned < self.nodes.len() {
            let i = self.opt_cursor % n;
            self.opt_cursor = (i + 1) % n;
            scanned += 1;
            if self.nodes[i as usize].height == 0 {
                let fat = self.nodes[i as usize].aabb;
                self.remove_leaf(i);
                self.insert_leaf(i, self.root);
                debug_assert_eq!(self.nodes[i as usize].aabb, fat);
                done += 1;
            }
        }
    }

    /// Removes every leaf (their handles become stale).
    pub fn clear(&mut self) {
        for i in (0..self.nodes.len() as u32).rev() {
            if self.nodes[i as usize].height >= 0 {
                self.free_node(i);
            }
        }
        self.root = NULL;
        self.leaf_count = 0;
        self.opt_cursor = 0;
    }
}
