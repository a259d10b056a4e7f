//! Queries on the [`DynamicTree`]: box overlap, ray cast with fraction clipping, convex
//! sets of planes (frustum culling), tree-vs-tree pairs and the self-pair sweep.
//! Traversals use an explicit stack (Bullet's `btDbvt::collideTV`, `rayTestInternal`,
//! `collideKDOP`, `collideTT`; Box2D v3 `b2DynamicTree_Query`, `b2DynamicTree_RayCast`).

use super::dynamic_tree::{DynamicTree, NULL};
use super::TreeProxy;
use crate::math::{Aabb, Isometry, Real, Vec3};

/// A half-space `normal · x <= offset`: the inside of one plane of a convex volume such as a
/// view frustum (normals point outwards).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HalfSpace {
    /// Outward normal (need not be unit length).
    pub normal: Vec3,
    /// Plane offset: points with `normal · x <= offset` are inside.
    pub offset: Real,
}

impl HalfSpace {
    /// Smallest `normal · x` over the box: the box is fully outside when it exceeds `offset`.
    #[inline]
    fn min_dot(&self, b: &Aabb) -> Real {
        let n = self.normal;
        let p = Vec3::new(
            if n.x >= 0.0 { b.min.x } else { b.max.x },
            if n.y >= 0.0 { b.min.y } else { b.max.y },
            if n.z >= 0.0 { b.min.z } else { b.max.z },
        );
        n.dot(p)
    }

    /// Largest `normal · x` over the box: the box is fully inside when it is `<= offset`.
    #[inline]
    fn max_dot(&self, b: &Aabb) -> Real {
        let n = self.normal;
        let p = Vec3::new(
            if n.x >= 0.0 { b.max.x } else { b.min.x },
            if n.y >= 0.0 { b.max.y } else { b.min.y },
            if n.z >= 0.0 { b.max.z } else { b.min.z },
        );
        n.dot(p)
    }
}

impl DynamicTree {
    #[inline]
    fn proxy(&self, i: u32) -> TreeProxy {
        TreeProxy {
            index: i,
            generation: self.nodes[i as usize].generation,
        }
    }

    /// Calls `f(leaf, user)` for every leaf whose fat box intersects `aabb`; `f` returns
    /// `false` to stop the query.
    pub fn query_aabb(&self, aabb: &Aabb, f: impl FnMut(TreeProxy, u32) -> bool) {
        self.query_aabb_with(aabb, &mut Vec::new(), f)
    }

    /// [`DynamicTree::query_aabb`] with a caller-owned traversal stack (cleared first), so
    /// repeated queries allocate nothing.
    pub fn query_aabb_with(
        &self,
        aabb: &Aabb,
        stack: &mut Vec<u32>,
        mut f: impl FnMut(TreeProxy, u32) -> bool,
    ) {
        stack.clear();
        if self.root == NULL {
            return;
        }
        stack.push(self.root);
        while let Some(i) = stack.pop() {
            let n = &self.nodes[i as usize];
            if !n.aabb.intersects(aabb) {
                continue;
            }
            if n.is_leaf() {
                if !f(self.proxy(i), n.user) {
                    return;
                }
            } else {
                stack.push(n.child1);
                stack.push(n.child2);
            }
        }
    }

    /// Calls `f(user)` for every leaf whose fat box intersects `aabb`, with a caller-owned
    /// stack: the broadphase's query. Children are tested before they are pushed and leaves
    /// reported without being pushed, which halves the stack traffic of
    /// [`DynamicTree::query_aabb_with`] (the broadphase's hottest loop in piles).
    pub(crate) fn overlapping_leaves(
        &self,
        aabb: &Aabb,
        stack: &mut Vec<u32>,
        mut f: impl FnMut(u32),
    ) {
        stack.clear();
        if self.root == NULL {
            return;
        }
        let nodes = &self.nodes;
        let root = &nodes[self.root as usize];
        if !root.aabb.intersects(aabb) {
            return;
        }
        if root.is_leaf() {
            f(root.user);
            return;
        }
        stack.push(self.root);
        while let Some(i) = stack.pop() {
            let n = &nodes[i as usize];
            for c in [n.child1, n.child2] {
                let cn = &nodes[c as usize];
                if cn.aabb.intersects(aabb) {
                    if cn.is_leaf() {
                        f(cn.user);
                    } else {
                        stack.push(c);
                    }
                }
            }
        }
    }

    /// Casts the ray `origin + t * dir`, `t` in `[0, max_fraction]`. For every leaf whose fat
    /// box the ray enters at some `t` ≤ the current maximum, calls `f(leaf, user, t_enter)`,
    /// which returns the new maximum fraction: return the hit fraction to clip the ray
    /// (closest-hit queries), the current maximum to go on, or `0` to stop. Subtrees beyond
    /// the clipped fraction are skipped.
    pub fn ray_cast(
        &self,
        origin: Vec3,
        dir: Vec3,
        max_fraction: Real,
        mut f: impl FnMut(TreeProxy, u32, Real) -> Real,
    ) {
        if self.root == NULL || max_fraction.is_nan() || max_fraction < 0.0 {
            return;
        }
        let mut max_t = max_fraction;
        let mut stack = Vec::with_capacity(64);
        stack.push(self.root);
        while let Some(i) = stack.pop() {
            let n = &self.nodes[i as usize];
            let Some(t) = n.aabb.ray_intersection(origin, dir, max_t) else {
                continue;
            };
            if n.is_leaf() {
                let new_max = f(self.proxy(i), n.user, t);
                if new_max <= 0.0 {
                    return;
                }
                max_t = max_t.min(new_max);
            } else {
                stack.push(n.child1);
                stack.push(n.child2);
            }
        }
    }

    /// Calls `f(leaf, user)` for every leaf whose fat box is not entirely outside one of the
    /// `planes` (frustum culling; conservative like Bullet's `collideKDOP`). Subtrees fully
    /// inside a plane skip that plane's test further down.
    pub fn query_planes(&self, planes: &[HalfSpace], mut f: impl FnMut(TreeProxy, u32)) {
        if self.root == NULL {
            return;
        }
        let all: u64 = if planes.len() >= 64 {
            u64::MAX
        } else {
            (1u64 << planes.len()) - 1
        };
        let mut stack: Vec<(u32, u64)> = vec![(self.root, all)];
        'nodes: while let Some((i, mut active)) = stack.pop() {
            let n = &self.nodes[i as usize];
            for (k, p) in planes.iter().enumerate() {
                let bit = 1u64 << (k % 64);
                if k < 64 && active & bit == 0 {
                    continue;
                }
                if p.min_dot(&n.aabb) > p.offset {
                    continue 'nodes;
                }
                if k < 64 && p.max_dot(&n.aabb) <= p.offset {
                    active &= !bit;
                }
            }
            if n.is_leaf() {
                f(self.proxy(i), n.user);
            } else {
                stack.push((n.child1, active));
                stack.push((n.child2, active));
            }
        }
    }

    /// Calls `f(user_a, user_b)` for every pair of leaves, one from `self` and one from
    /// `other`, whose fat boxes intersect (simultaneous descent, Bullet's `collideTT`).
    pub fn query_tree(&self, other: &DynamicTree, f: impl FnMut(u32, u32)) {
        self.query_tree_with(other, &mut Vec::new(), f)
    }

    /// [`DynamicTree::query_tree`] with a caller-owned traversal stack (cleared first).
    pub fn query_tree_with(
        &self,
        other: &DynamicTree,
        stack: &mut Vec<(u32, u32)>,
        f: impl FnMut(u32, u32),
    ) {
        if self.root == NULL || other.root == NULL {
            stack.clear();
            return;
        }
        self.query_tree_from(other, (self.root, other.root), stack, f)
    }

    /// The descent of [`DynamicTree::query_tree_with`] from the node pair `start` (a node
    /// of `self`, a node of `other`): one task of a split descent
    /// ([`DynamicTree::tree_pair_tasks`]).
    pub(crate) fn query_tree_from(
        &self,
        other: &DynamicTree,
        start: (u32, u32),
        stack: &mut Vec<(u32, u32)>,
        mut f: impl FnMut(u32, u32),
    ) {
        stack.clear();
        stack.push(start);
        while let Some((a, b)) = stack.pop() {
            let (na, nb) = (&self.nodes[a as usize], &other.nodes[b as usize]);
            if !na.aabb.intersects(&nb.aabb) {
                continue;
            }
            match (na.is_leaf(), nb.is_leaf()) {
                (true, true) => f(na.user, nb.user),
                (true, false) => {
                    stack.push((a, nb.child1));
                    stack.push((a, nb.child2));
                }
                (false, true) => {
                    stack.push((na.child1, b));
                    stack.push((na.child2, b));
                }
                (false, false) => {
                    // Descend into the larger box first (better pruning).
                    if na.aabb.surface_area() >= nb.aabb.surface_area() {
                        stack.push((na.child1, b));
                        stack.push((na.child2, b));
                    } else {
                        stack.push((a, nb.child1));
                        stack.push((a, nb.child2));
                    }
                }
            }
        }
    }

    /// Like [`DynamicTree::query_tree`] with `other` placed at `pose_ab` (its pose in
    /// `self`'s frame): `other`'s node boxes are moved with [`Aabb::transformed`], which
    /// bounds the moved contents, so no overlapping leaf pair is missed.
    pub fn query_tree_transformed(
        &self,
        other: &DynamicTree,
        pose_ab: &Isometry,
        mut f: impl FnMut(u32, u32),
    ) {
        if self.root == NULL || other.root == NULL {
            return;
        }
        let moved = |b: u32| other.nodes[b as usize].aabb.transformed(pose_ab);
        let mut stack = Vec::with_capacity(128);
        stack.push((self.root, other.root, moved(other.root)));
        while let Some((a, b, box_b)) = stack.pop() {
            let (na, nb) = (&self.nodes[a as usize], &other.nodes[b as usize]);
            if !na.aabb.intersects(&box_b) {
                continue;
            }
            match (na.is_leaf(), nb.is_leaf()) {
                (true, true) => f(na.user, nb.user),
                (false, false) if na.aabb.surface_area() < box_b.surface_area() => {
                    stack.push((a, nb.child1, moved(nb.child1)));
                    stack.push((a, nb.child2, moved(nb.child2)));
                }
                (true, false) => {
                    stack.push((a, nb.child1, moved(nb.child1)));
                    stack.push((a, nb.child2, moved(nb.child2)));
                }
                (false, _) => {
                    stack.push((na.child1, b, box_b));
                    stack.push((na.child2, b, box_b));
                }
            }
        }
    }

    /// Calls `f(user_a, user_b)` once for every unordered pair of distinct leaves whose fat
    /// boxes intersect: the self-pair sweep (Bullet's `collideTT(root, root)`). Child pairs
    /// are tested before they are pushed, so the stack only holds overlapping pairs.
    pub fn self_pairs(&self, f: impl FnMut(u32, u32)) {
        self.self_pairs_with(&mut Vec::new(), f)
    }

    /// [`DynamicTree::self_pairs`] with a caller-owned traversal stack (cleared first).
    pub fn self_pairs_with(&self, stack: &mut Vec<(u32, u32)>, f: impl FnMut(u32, u32)) {
        if self.root == NULL {
            stack.clear();
            return;
        }
        self.self_pairs_from((self.root, self.root), stack, f)
    }

    /// The descent of [`DynamicTree::self_pairs_with`] from the node pair `start`: the
    /// pairs within one subtree when `start.0 == start.1`, else the pairs between two
    /// disjoint subtrees whose boxes intersect. One task of a split descent
    /// ([`DynamicTree::self_pair_tasks`]).
    pub(crate) fn self_pairs_from(
        &self,
        start: (u32, u32),
        stack: &mut Vec<(u32, u32)>,
        mut f: impl FnMut(u32, u32),
    ) {
        stack.clear();
        let nodes = &self.nodes;
        stack.push(start);
        let push = |stack: &mut Vec<(u32, u32)>, a: u32, b: u32| {
            if nodes[a as usize].aabb.intersects(&nodes[b as usize].aabb) {
                stack.push((a, b));
            }
        };
        while let Some((a, b)) = stack.pop() {
            let na = &nodes[a as usize];
            if a == b {
                if !na.is_leaf() {
                    stack.push((na.child1, na.child1));
                    stack.push((na.child2, na.child2));
                    push(stack, na.child1, na.child2);
                }
                continue;
            }
            let nb = &nodes[b as usize];
            match (na.is_leaf(), nb.is_leaf()) {
                (true, true) => f(na.user, nb.user),
                (true, false) => {
                    push(stack, a, nb.child1);
                    push(stack, a, nb.child2);
                }
                (false, true) => {
                    push(stack, na.child1, b);
                    push(stack, na.child2, b);
                }
                (false, false) => {
                    if na.height >= nb.height {
                        push(stack, na.child1, b);
                        push(stack, na.child2, b);
                    } else {
                        push(stack, a, nb.child1);
                        push(stack, a, nb.child2);
                    }
                }
            }
        }
    }
}
