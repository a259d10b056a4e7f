//! Top-down BVH construction with a binned surface-area heuristic.
//!
//! Wald, "On fast Construction of SAH-based Bounding Volume Hierarchies" (IEEE RT 2007):
//! primitives are binned by centroid into [`NUM_BINS`] slabs along the longest axis of
//! their centroid bounds, and the split
//! minimising `SA(L)·N(L) + SA(R)·N(R)` is taken. Nodes are emitted in depth-first pre-order
//! (a node's left child follows it), which the stackless traversal of
//! `btQuantizedBvh` (Bullet, `src/BulletCollision/BroadphaseCollision/btQuantizedBvh.cpp`)
//! needs. The build uses an explicit stack, so degenerate splits cannot overflow the call
//! stack, and is fully deterministic (no sort with ties, no hashing).

use crate::math::{Aabb, Real, Vec3, Vec3A};

/// Number of centroid bins per axis.
pub const NUM_BINS: usize = 16;

/// Largest number of primitives in a leaf.
pub const MAX_LEAF_SIZE: usize = 8;

/// Cost of visiting an internal node relative to testing one primitive (SAH constant). Tuned
/// with `carom-bench midphase`: leaves of up to 8 triangles beat small leaves on both build
/// time and ray throughput (a leaf test reads contiguous data, a node visit often misses).
const TRAVERSAL_COST: Real = 3.0;

/// A node of the build output, before the final layout is chosen.
#[derive(Debug, Clone, Copy)]
pub(crate) struct BuildNode {
    /// Exact bounds of the primitives below.
    pub aabb: Aabb,
    /// For a leaf, the first primitive in the order array; for an internal node, the index
    /// of its right child.
    pub first_or_right: u32,
    /// Number of primitives for a leaf, 0 for an internal node.
    pub count: u32,
}

impl BuildNode {
    /// True for leaves.
    #[inline]
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }
}

/// Output of [`build`]: pre-order nodes, escape indices and the primitive order.
pub(crate) struct BuildOutput {
    /// Nodes in depth-first pre-order.
    pub nodes: Vec<BuildNode>,
    /// For every node, the index just past its subtree.
    pub escapes: Vec<u32>,
    /// Primitive indices, leaves refer to contiguous ranges of it.
    pub order: Vec<u32>,
}

/// A box on SIMD vectors, for the build's inner loops.
#[derive(Clone, Copy)]
struct ABox {
    min: Vec3A,
    max: Vec3A,
}

impl ABox {
    const EMPTY: ABox = ABox {
        min: Vec3A::splat(Real::INFINITY),
        max: Vec3A::splat(Real::NEG_INFINITY),
    };
    #[inline(always)]
    fn merge(&self, o: &ABox) -> ABox {
        ABox {
            min: self.min.min(o.min),
            max: self.max.max(o.max),
        }
    }
    #[inline(always)]
    fn include(&self, p: Vec3A) -> ABox {
        ABox {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }
    #[inline(always)]
    fn area(&self) -> Real {
        let e = (self.max - self.min).max(Vec3A::ZERO);
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }
    fn aabb(&self) -> Aabb {
        Aabb::new(Vec3::from(self.min), Vec3::from(self.max))
    }
}

#[derive(Clone, Copy)]
struct Bin {
    aabb: ABox,
    centroids: ABox,
    count: u32,
}

const EMPTY_BIN: Bin = Bin {
    aabb: ABox::EMPTY,
    centroids: ABox::EMPTY,
    count: 0,
};

impl Bin {
    #[inline]
    fn merge(&self, o: &Bin) -> Bin {
        Bin {
            aabb: self.aabb.merge(&o.aabb),
            centroids: self.centroids.merge(&o.centroids),
            count: self.count + o.count,
        }
    }
}

/// A range of primitives to split, with its bounds and the bounds of its centroids.
struct Task {
    start: usize,
    end: usize,
    /// The node whose right child this range becomes.
    parent: Option<usize>,
    aabb: ABox,
    centroids: ABox,
}

/// A primitive during the build: box, centroid and index, moved together so the passes over
/// a range read memory in order.
#[derive(Clone, Copy)]
struct Prim {
    aabb: ABox,
    /// Twice the centroid (`min + max`): binning only needs it up to scale.
    centroid: Vec3A,
    id: u32,
}

/// Builds the hierarchy over `boxes` (at least one, all valid), with leaves of up to
/// [`MAX_LEAF_SIZE`] primitives.
#[cfg(test)]
pub(crate) fn build(boxes: &[Aabb]) -> BuildOutput {
    build_with_leaves(boxes, MAX_LEAF_SIZE)
}

/// [`build`] with leaves of up to `max_leaf` primitives (1 ..= [`MAX_LEAF_SIZE`]; clamped).
/// Smaller leaves suit primitives whose own test costs far more than a node visit (a world
/// query's bodies): the closest-first walk then orders every primitive by its box entry,
/// not only the leaves.
pub(crate) fn build_with_leaves(boxes: &[Aabb], max_leaf: usize) -> BuildOutput {
    let max_leaf = max_leaf.clamp(1, MAX_LEAF_SIZE);
    let n = boxes.len();
    let mut order: Vec<Prim> = boxes
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let (min, max) = (Vec3A::from(b.min), Vec3A::from(b.max));
            Prim {
                aabb: ABox { min, max },
                centroid: min + max,
                id: i as u32,
            }
        })
        .collect();
    let mut nodes: Vec<BuildNode> = Vec::with_capacity(2 * n / max_leaf.max(2) + 8);
    let root = bounds_of(&order);
    let mut stack = vec![Task {
        start: 0,
        end: n,
        parent: None,
        aabb: root.aabb,
        centroids: root.centroids,
    }];
    while let Some(task) = stack.pop() {
        let index = nodes.len();
        if let Some(p) = task.parent {
            nodes[p].first_or_right = index as u32;
        }
        let prims = &mut order[task.start..task.end];
        match choose_split(prims, &task.aabb, &task.centroids, max_leaf) {
            Some((mid, left, right)) => {
                nodes.push(BuildNode {
                    aabb: task.aabb.aabb(),
                    first_or_right: 0,
                    count: 0,
                });
                stack.push(Task {
                    start: task.start + mid,
                    end: task.end,
                    parent: Some(index),
                    aabb: right.aabb,
                    centroids: right.centroids,
                });
                stack.push(Task {
                    start: task.start,
                    end: task.start + mid,
                    parent: None,
                    aabb: left.aabb,
                    centroids: left.centroids,
                });
            }
            None => nodes.push(BuildNode {
                aabb: task.aabb.aabb(),
                first_or_right: task.start as u32,
                count: (task.end - task.start) as u32,
            }),
        }
    }
    let escapes = escape_indices(&nodes);
    BuildOutput {
        nodes,
        escapes,
        order: order.iter().map(|p| p.id).collect(),
    }
}

/// Bounds and centroid bounds of a set of primitives.
fn bounds_of(prims: &[Prim]) -> Bin {
    prims.iter().fold(EMPTY_BIN, |acc, p| Bin {
        aabb: acc.aabb.merge(&p.aabb),
        centroids: acc.centroids.include(p.centroid),
        count: acc.count + 1,
    })
}

/// Escape index of every node: its index plus its subtree size. Children follow their
/// parent, so sizes are accumulated from the back.
fn escape_indices(nodes: &[BuildNode]) -> Vec<u32> {
    let mut size = vec![1u32; nodes.len()];
    for i in (0..nodes.len()).rev() {
        if !nodes[i].is_leaf() {
            size[i] = 1 + size[i + 1] + size[nodes[i].first_or_right as usize];
        }
    }
    (0..nodes.len()).map(|i| i as u32 + size[i]).collect()
}

/// Chooses a split of `prims` (reordering it) and returns the size of the left part and the
/// bounds of both parts, or `None` to make a leaf. One pass bins the primitives on all three
/// axes at once; the children's bounds come from the bins.
fn choose_split(
    prims: &mut [Prim],
    bounds: &ABox,
    cb: &ABox,
    max_leaf: usize,
) -> Option<(usize, Bin, Bin)> {
    let n = prims.len();
    if n <= 1 {
        return None;
    }
    // Bin along the longest axis of the centroid bounds only, as Wald (2007) does: a third
    // of the binning work of a three-axis sweep for a small loss of tree quality.
    let extent = cb.max - cb.min;
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let k = NUM_BINS as Real / extent[axis].max(Real::MIN_POSITIVE);
    let min = cb.min[axis];
    // (cost, last bin on the left, left, right)
    let mut best: Option<(Real, usize, Bin, Bin)> = None;
    if extent[axis] > 0.0 {
        let mut bins = [EMPTY_BIN; NUM_BINS];
        for p in prims.iter() {
            let c = p.centroid;
            let bin = &mut bins[bin_of(c[axis], min, k)];
            bin.aabb = bin.aabb.merge(&p.aabb);
            bin.centroids = bin.centroids.include(c);
            bin.count += 1;
        }
        let mut right = [EMPTY_BIN; NUM_BINS];
        let mut acc = EMPTY_BIN;
        for b in (1..NUM_BINS).rev() {
            acc = acc.merge(&bins[b]);
            right[b] = acc;
        }
        let mut left = EMPTY_BIN;
        for b in 0..NUM_BINS - 1 {
            left = left.merge(&bins[b]);
            let r = &right[b + 1];
            if left.count == 0 || r.count == 0 {
                continue;
            }
            let cost = left.aabb.area() * left.count as Real + r.aabb.area() * r.count as Real;
            if !matches!(best, Some((c, ..)) if cost >= c) {
                best = Some((cost, b, left, *r));
            }
        }
    }
    let parent_area = bounds.area();
    match best {
        Some((cost, last, left, right)) => {
            let leaf_cost = n as Real * parent_area;
            let split_cost = TRAVERSAL_COST * parent_area + cost;
            if n <= max_leaf && split_cost >= leaf_cost {
                return None;
            }
            let mid = partition(prims, |p| bin_of(p.centroid[axis], min, k) <= last);
            debug_assert!(mid == left.count as usize);
            Some((mid, left, right))
        }
        // All centroids coincide: split by position in the list.
        None if n > max_leaf => {
            let mid = n / 2;
            let left = bounds_of(&prims[..mid]);
            let right = bounds_of(&prims[mid..]);
            Some((mid, left, right))
        }
        None => None,
    }
}

#[inline]
fn bin_of(c: Real, min: Real, k: Real) -> usize {
    let b = ((c - min) * k) as isize;
    b.clamp(0, NUM_BINS as isize - 1) as usize
}

/// In-place partition: elements satisfying `left` first. Returns their count. The order is
/// a deterministic function of the input.
fn partition(v: &mut [Prim], left: impl Fn(&Prim) -> bool) -> usize {
    let mut i = 0;
    let mut j = v.len();
    while i < j {
        if left(&v[i]) {
            i += 1;
        } else {
            j -= 1;
            v.swap(i, j);
        }
    }
    i
}

#[cfg(test)]
mod tests {
    use super::*;

    fn random_boxes(n: usize, seed: u64) -> Vec<Aabb> {
        let mut s = seed;
        let mut next = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 33) as f64 / (1u64 << 31) as f64) as Real
        };
        (0..n)
            .map(|_| {
                let c = Vec3::new(next(), next(), next()) * 10.0;
                Aabb::from_center_half_extents(c, Vec3::new(next(), next(), next()) * 0.3)
            })
            .collect()
    }

    fn check_tree(boxes: &[Aabb], out: &BuildOutput) {
        let mut seen = vec![false; boxes.len()];
        for &p in &out.order {
            assert!(!seen[p as usize], "primitive {p} twice");
            seen[p as usize] = true;
        }
        assert!(seen.iter().all(|&s| s));
        assert_eq!(out.escapes[0] as usize, out.nodes.len());
        let mut leaf_prims = 0;
        for (i, node) in out.nodes.iter().enumerate() {
            if node.is_leaf() {
                assert!(node.count as usize <= MAX_LEAF_SIZE.max(1) || node.count > 0);
                assert_eq!(out.escapes[i] as usize, i + 1);
                let (s, c) = (node.first_or_right as usize, node.count as usize);
                for &p in &out.order[s..s + c] {
                    assert!(node.aabb.contains(&boxes[p as usize]));
                }
                leaf_prims += c;
            } else {
                let l = &out.nodes[i + 1];
                let r_idx = node.first_or_right as usize;
                assert_eq!(
                    out.escapes[i + 1] as usize,
                    r_idx,
                    "right follows left subtree"
                );
                assert_eq!(out.escapes[r_idx], out.escapes[i]);
                assert!(node.aabb.contains(&l.aabb) && node.aabb.contains(&out.nodes[r_idx].aabb));
            }
        }
        assert_eq!(leaf_prims, boxes.len());
    }

    #[test]
    fn tree_invariants_random_and_degenerate() {
        for n in [1, 2, 3, 5, 17, 300] {
            let boxes = random_boxes(n, n as u64);
            check_tree(&boxes, &build(&boxes));
        }
        // All boxes identical: split by count, leaves stay small.
        let same = vec![Aabb::new(Vec3::ONE, Vec3::ONE); 100];
        let out = build(&same);
        check_tree(&same, &out);
        assert!(out
            .nodes
            .iter()
            .all(|n| !n.is_leaf() || n.count as usize <= MAX_LEAF_SIZE));
    }

    /// Leaves of one primitive: every leaf holds one, for spread, identical and nested boxes.
    #[test]
    fn single_primitive_leaves() {
        let mut nested: Vec<Aabb> = (1..=9)
            .map(|k| Aabb::new(Vec3::splat(-(k as Real)), Vec3::splat(k as Real)))
            .collect();
        nested.extend(random_boxes(40, 3));
        for boxes in [
            random_boxes(300, 11),
            vec![Aabb::new(Vec3::ONE, Vec3::ONE); 37],
            nested,
        ] {
            let out = build_with_leaves(&boxes, 1);
            check_tree(&boxes, &out);
            assert!(out.nodes.iter().all(|n| !n.is_leaf() || n.count == 1));
            // Out-of-range sizes are clamped.
            let zero = build_with_leaves(&boxes, 0);
            assert_eq!(zero.order, out.order);
            let big = build_with_leaves(&boxes, 1000);
            assert_eq!(big.order, build(&boxes).order);
        }
    }

    #[test]
    fn build_is_deterministic() {
        let boxes = random_boxes(500, 7);
        let (a, b) = (build(&boxes), build(&boxes));
        assert_eq!(a.order, b.order);
        assert_eq!(a.escapes, b.escapes);
    }
}
