//! Compound child queries: which children can touch a box, and which child pairs of two
//! compounds can touch, through the static BVH over child boxes.
//!
//! The issue asks for the children in a dynamic AABB tree (Bullet's `btCompoundShape` keeps a
//! `btDbvt`); until the broadphase's dynamic tree is available to the midphase, the children
//! live in the same static stackless BVH as mesh triangles (compounds are rigid, so the tree
//! never changes after construction).

use crate::math::{Aabb, Isometry};
use crate::shape::Compound;

impl Compound {
    /// Calls `f(child)` for every child whose bounding box overlaps `aabb` (compound frame,
    /// touching counts); `f` returns `false` to stop.
    pub fn for_each_child_in_aabb(&self, aabb: &Aabb, mut f: impl FnMut(u32) -> bool) {
        self.bvh().for_each_candidate_in_aabb(aabb, |i| {
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
        self.bvh()
            .for_each_candidate_pair(other.bvh(), pose_ab, |a, b| {
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
