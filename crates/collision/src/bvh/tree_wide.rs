//! A 4-wide snapshot of a [`DynamicTree`] for many box queries in a row.
//!
//! The tree broadphase queries every moved proxy's fat box against the moving tree; on
//! "3000 fall" that is a few hundred queries per update, each visiting some fifty binary
//! nodes and testing both children's boxes one at a time. Collapsing every two levels of
//! the binary tree into one node with up to four children, their boxes stored plane by plane
//! (structure of arrays), lets one pass of 4-lane comparisons test the four boxes at once and
//! halves the levels a query walks. This is the multi-branching BVH of Wald, Benthin and
//! Boulos, "Getting Rid of Packets" (IEEE RT 2008) and Embree's `BVH4`; Jolt's broadphase
//! (`QuadTree.h`) keeps its dynamic tree four-wide for the same reason. Here the binary tree
//! stays the structure that is updated (insert, refit, remove); the wide copy is rebuilt
//! from it in one linear pass before a batch of queries ([`WideTree::rebuild`]).
//!
//! The lanes hold the binary nodes' boxes bit for bit and the comparisons are the ones of
//! [`Aabb::intersects`] (touching counts), so a query reports exactly the leaves the binary
//! `DynamicTree::overlapping_leaves` reports (in another order).

use super::dynamic_tree::{DynamicTree, NULL};
use crate::math::{Aabb, Real};

/// Four lanes of [`Real`] (`wide`'s `f32x4`, or `f64x4` in the f64 build).
#[cfg(not(feature = "f64"))]
type W = wide::f32x4;
/// Four lanes of [`Real`] (`wide`'s `f32x4`, or `f64x4` in the f64 build).
#[cfg(feature = "f64")]
type W = wide::f64x4;

/// One wide node: up to four children's boxes, plane by plane.
#[derive(Debug, Clone, Copy)]
struct WideTreeNode {
    /// Min x, y, z and max x, y, z of the children; lane `k` is child `k`. Unused lanes hold
    /// an inverted infinite box (min `+∞`, max `−∞`), which no finite box intersects.
    planes: [[Real; 4]; 6],
    /// Child `k`: a leaf's user data when bit `k` of `leaf_mask` is set, else the index of
    /// a wide node.
    children: [u32; 4],
    /// Which children are leaves.
    leaf_mask: u32,
}

/// A node with no child.
const EMPTY_NODE: WideTreeNode = WideTreeNode {
    planes: [
        [Real::INFINITY; 4],
        [Real::INFINITY; 4],
        [Real::INFINITY; 4],
        [Real::NEG_INFINITY; 4],
        [Real::NEG_INFINITY; 4],
        [Real::NEG_INFINITY; 4],
    ],
    children: [NULL; 4],
    leaf_mask: 0,
};

impl WideTreeNode {
    /// Sets lane `k` to a child with box `b`: a leaf with user data `child`, or the wide
    /// node `child`.
    #[inline(always)]
    fn set(&mut self, k: usize, b: &Aabb, child: u32, leaf: bool) {
        self.planes[0][k] = b.min.x;
        self.planes[1][k] = b.min.y;
        self.planes[2][k] = b.min.z;
        self.planes[3][k] = b.max.x;
        self.planes[4][k] = b.max.y;
        self.planes[5][k] = b.max.z;
        self.children[k] = child;
        self.leaf_mask |= (leaf as u32) << k;
    }
}

/// A 4-wide copy of a [`DynamicTree`]'s boxes and leaves (see the module docs). Its buffers
/// are kept between rebuilds: no allocation once it has held the largest tree.
#[derive(Debug, Clone, Default)]
pub struct WideTree {
    nodes: Vec<WideTreeNode>,
    /// The user data of the only leaf when the tree is a single leaf.
    single: Option<(Aabb, u32)>,
    /// Per wide node, the binary node it was made from (the rebuild's queue).
    pending: Vec<u32>,
}

impl WideTree {
    /// An empty wide tree.
    pub fn new() -> Self {
        Self::default()
    }

    /// Number of wide nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Rebuilds the copy from `tree`: each wide node takes a binary node's two children,
    /// an internal child replaced by its own two children. One breadth-first pass over the
    /// internal nodes: wide node `w` is made from binary node `pending[w]`, and numbers are
    /// handed out as internal children are queued, so every node is pushed once, complete.
    pub fn rebuild(&mut self, tree: &DynamicTree) {
        self.nodes.clear();
        self.pending.clear();
        self.single = None;
        if tree.root == NULL {
            return;
        }
        let nodes = &tree.nodes;
        let root = &nodes[tree.root as usize];
        if root.is_leaf() {
            self.single = Some((root.aabb, root.user));
            return;
        }
        // Every wide node but the root holds at least one binary internal node's two
        // children, so the leaf count bounds the number of wide nodes.
        self.nodes.reserve(tree.leaf_count);
        self.pending.reserve(tree.leaf_count);
        self.pending.push(tree.root);
        let mut w = 0;
        while w < self.pending.len() {
            let n = &nodes[self.pending[w] as usize];
            w += 1;
            let mut node = EMPTY_NODE;
            let mut lane = 0;
            for c in [n.child1, n.child2] {
                let cn = &nodes[c as usize];
                if cn.is_leaf() {
                    node.set(lane, &cn.aabb, cn.user, true);
                    lane += 1;
                    continue;
                }
                for g in [cn.child1, cn.child2] {
                    let gn = &nodes[g as usize];
                    if gn.is_leaf() {
                        node.set(lane, &gn.aabb, gn.user, true);
                    } else {
                        node.set(lane, &gn.aabb, self.pending.len() as u32, false);
                        self.pending.push(g);
                    }
                    lane += 1;
                }
            }
            self.nodes.push(node);
        }
    }

    /// Calls `f(user)` for every leaf whose box intersects `aabb` (touching counts), with a
    /// caller-owned stack (cleared first): the leaves of
    /// `DynamicTree::overlapping_leaves` on the tree this copy was rebuilt from.
    #[inline]
    pub fn overlapping_leaves(&self, aabb: &Aabb, stack: &mut Vec<u32>, mut f: impl FnMut(u32)) {
        stack.clear();
        if let Some((bx, user)) = self.single {
            if bx.intersects(aabb) {
                f(user);
            }
            return;
        }
        if self.nodes.is_empty() {
            return;
        }
        let q = [
            W::splat(aabb.max.x),
            W::splat(aabb.max.y),
            W::splat(aabb.max.z),
            W::splat(aabb.min.x),
            W::splat(aabb.min.y),
            W::splat(aabb.min.z),
        ];
        let mut i = 0u32;
        loop {
            let n = &self.nodes[i as usize];
            let p = n.planes.map(W::from);
            // Aabb::intersects: child.min <= q.max and q.min <= child.max, per axis.
            let hit = p[0].simd_le(q[0])
                & p[1].simd_le(q[1])
                & p[2].simd_le(q[2])
                & q[3].simd_le(p[3])
                & q[4].simd_le(p[4])
                & q[5].simd_le(p[5]);
            let mut bits = hit.to_bitmask();
            while bits != 0 {
                let k = bits.trailing_zeros();
                bits &= bits - 1;
                let c = n.children[k as usize];
                if n.leaf_mask & (1 << k) != 0 {
                    f(c);
                } else {
                    stack.push(c);
                }
            }
            match stack.pop() {
                Some(next) => i = next,
                None => return,
            }
        }
    }
}
