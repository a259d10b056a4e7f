//! Compound child queries: which children can touch a box, and which child pairs of two
//! compounds can touch, through the dynamic AABB trees over the child boxes (Bullet's
//! `btCompoundShape` with its `btDbvt`, and `btCompoundCompoundCollisionAlgorithm`'s
//! tree-vs-tree descent). Candidates from the trees are re-tested against the exact child
//! boxes, so the results equal the brute-force ones in [`brute_force_child_pairs`] and
//! [`brute_force_children_in_aabb`].

use crate::math::{Aabb, Isometry};
use crate::shape::Compound;

impl Compound {
    /// Calls `f(child)` for every child whose bounding box overlaps `aabb` (compound frame,
    /// touching counts); `f` returns `false` to stop.
    pub fn for_each_child_in_aabb(&self, aabb: &Aabb, mut f: impl FnMut(u32) -> bool) {
        self.tree().query_aabb(aabb, |_, i| {
            if self.child_aabbs()[i as usize].intersects(aabb) {
                f(i)
            } else {
                true
            }
        });
    }

    /// Children whose bounding boxes overlap `aabb` (compound frame), ascending.
    pub fn children_in_aabb(&self, aabb: &Aabb) -> Vec<u32> {
        let mut out = Vec::new();
        self.for_each_child_in_aabb(aabb, |i| {
            out.push(i);
            true
        });
        out.sort_unstable();
        out
    }

    /// Child pairs `(a, b)`, `a` of `self` and `b` of `other` placed at `pose_ab` (B's pose
    /// in A's frame), whose boxes overlap in A's frame (B's child box moved by `pose_ab` with
    /// [`Aabb::transformed`]). Sorted.
    pub fn child_pairs(&self, other: &Compound, pose_ab: &Isometry) -> Vec<(u32, u32)> {
        let mut out = Vec::new();
        self.tree()
            .query_tree_transformed(other.tree(), pose_ab, |a, b| {
                if child_pair_overlaps(self, other, pose_ab, a, b) {
                    out.push((a, b));
                }
            });
        out.sort_unstable();
        out
    }
}

/// The exact pair test of [`Compound::child_pairs`]; also the brute-force oracle's test.
pub fn child_pair_overlaps(
    a: &Compound,
    b: &Compound,
    pose_ab: &Isometry,
    ia: u32,
    ib: u32,
) -> bool {
    let box_b = b.child_aabbs()[ib as usize].transformed(pose_ab);
    a.child_aabbs()[ia as usize].intersects(&box_b)
}

/// All children whose boxes overlap `aabb`, ascending, by testing every child: the oracle
/// of [`Compound::children_in_aabb`].
pub fn brute_force_children_in_aabb(c: &Compound, aabb: &Aabb) -> Vec<u32> {
    (0..c.children().len() as u32)
        .filter(|&i| c.child_aabbs()[i as usize].intersects(aabb))
        .collect()
}

/// All overlapping child pairs, sorted, by testing every pair: the oracle of
/// [`Compound::child_pairs`].
pub fn brute_force_child_pairs(a: &Compound, b: &Compound, pose_ab: &Isometry) -> Vec<(u32, u32)> {
    let mut out = Vec::new();
    for ia in 0..a.children().len() as u32 {
        for ib in 0..b.children().len() as u32 {
            if child_pair_overlaps(a, b, pose_ab, ia, ib) {
                out.push((ia, ib));
            }
        }
    }
    out
}
