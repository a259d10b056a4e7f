//! BVH-versus-BVH traversal: candidate primitive pairs of two hierarchies at a relative pose
//! (mesh-vs-mesh triangle pairs, compound-vs-compound child pairs).
//!
//! Simultaneous descent as in Gottschalk, Lin and Manocha, "OBBTree" (SIGGRAPH 1996) and
//! Bullet's `btGImpactCollisionAlgorithm`: a small stack of node pairs; when both nodes are
//! internal the one with the larger box is split. Boxes of B are moved into A's frame with
//! Arvo's transform of the centre and `|R|`-mapped half extents, padded for rounding.

use super::static_bvh::{leaf_range, Bvh, Nodes, LEAF_FLAG};
use super::traverse::{right_child_of, with_nodes, NodeSet, QNodes};
use crate::math::{Aabb, Isometry, EPSILON};

/// Box `b` (in B's frame) moved into A's frame by `pose_ab`, padded so it always contains
/// the exact image of every box inside `b`.
#[inline]
pub(crate) fn transformed_padded(b: &Aabb, pose_ab: &Isometry) -> Aabb {
    let t = b.transformed(pose_ab);
    let pad = (t.min.abs().max(t.max.abs()) + b.extents()) * (8.0 * EPSILON);
    Aabb::new(t.min - pad, t.max + pad)
}

impl Bvh {
    /// Calls `f(a, b)` for every pair of primitives, `a` of `self` and `b` of `other`, whose
    /// leaf boxes overlap when `other` is placed at `pose_ab` (B's pose in A's frame). This is
    /// a superset of the pairs whose primitive boxes overlap; callers test exactly. Pairs come
    /// in a deterministic order.
    pub fn for_each_candidate_pair(
        &self,
        other: &Bvh,
        pose_ab: &Isometry,
        mut f: impl FnMut(u32, u32),
    ) {
        with_nodes!(self, na => with_nodes!(other, nb => {
            pair_walk(&na, &self.order, &nb, &other.order, pose_ab, &mut f)
        }))
    }
}

fn pair_walk<A: NodeSet, B: NodeSet>(
    na: &A,
    order_a: &[u32],
    nb: &B,
    order_b: &[u32],
    pose_ab: &Isometry,
    f: &mut impl FnMut(u32, u32),
) {
    let mut stack: Vec<(usize, usize)> = vec![(0, 0)];
    while let Some((ia, ib)) = stack.pop() {
        let box_a = na.aabb(ia);
        let box_b = transformed_padded(&nb.aabb(ib), pose_ab);
        if !box_a.intersects(&box_b) {
            continue;
        }
        let (da, db) = (na.data(ia), nb.data(ib));
        let (leaf_a, leaf_b) = (da & LEAF_FLAG != 0, db & LEAF_FLAG != 0);
        match (leaf_a, leaf_b) {
            (true, true) => {
                let (fa, ca) = leaf_range(da);
                let (fb, cb) = leaf_range(db);
                for &pa in &order_a[fa..fa + ca] {
                    for &pb in &order_b[fb..fb + cb] {
                        f(pa, pb);
                    }
                }
            }
            _ => {
                let split_a = !leaf_a && (leaf_b || box_a.surface_area() >= box_b.surface_area());
                // Push right first so the left subtree is visited first.
                if split_a {
                    stack.push((right_child_of(na, ia), ib));
                    stack.push((ia + 1, ib));
                } else {
                    stack.push((ia, right_child_of(nb, ib)));
                    stack.push((ia, ib + 1));
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::BvhLayout;
    use crate::math::{Quat, Real, Vec3};

    #[test]
    fn pairs_match_brute_force_on_boxes() {
        let mut s = 99u64;
        let mut next = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 33) as f64 / (1u64 << 31) as f64) as Real
        };
        let mut mk = |n: usize| -> Vec<Aabb> {
            (0..n)
                .map(|_| {
                    let c = Vec3::new(next(), next(), next()) * 6.0;
                    Aabb::from_center_half_extents(c, Vec3::new(next(), next(), next()) * 1.0)
                })
                .collect()
        };
        let (ba, bb) = (mk(120), mk(90));
        let pose = Isometry::new(Vec3::new(1.0, -0.5, 0.3), Quat::from_rotation_y(0.7));
        for layout in [BvhLayout::Quantized, BvhLayout::Unquantized] {
            let ta = Bvh::new(&ba, layout).unwrap();
            let tb = Bvh::new(&bb, layout).unwrap();
            let mut got = Vec::new();
            ta.for_each_candidate_pair(&tb, &pose, |a, b| got.push((a, b)));
            got.sort_unstable();
            let n_got = got.len();
            got.dedup();
            assert_eq!(n_got, got.len(), "no pair twice");
            // Every exactly overlapping pair must be a candidate.
            let mut exact = 0;
            for (i, a) in ba.iter().enumerate() {
                for (j, b) in bb.iter().enumerate() {
                    if a.intersects(&b.transformed(&pose)) {
                        exact += 1;
                        assert!(got.binary_search(&(i as u32, j as u32)).is_ok());
                    }
                }
            }
            assert!(exact > 20, "the test must produce overlaps ({exact})");
        }
    }
}
