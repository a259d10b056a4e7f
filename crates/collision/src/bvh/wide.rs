//! A 4-wide view of the BVH for closest-hit rays, in either node layout: [`WideNode`] for
//! the quantised one, [`WideRealNode`] for the unquantised one (the same collapse and walk,
//! generic over [`WideSource`] and [`WideBoxes`]).
//!
//! The binary, depth-first, stackless layout (`static_bvh`) is compact and ideal for box and
//! point queries, but a closest-hit ray pays one dependent cache miss per visited level: the
//! right child of a node lives past the left subtree. Profiling `carom-bench midphase`
//! (perf, 1M-triangle grid) put ~36 % of the ray time on the load of that far child's box.
//! Collapsing every two levels into one node with four children halves the number of levels
//! (and misses) per ray, and the four child boxes of a node are one 64-byte cache line, stored
//! plane by plane (structure of arrays) so one pass of 4-lane arithmetic tests all of them.
//! This is the multi-branching BVH of Wald, Benthin and Boulos, "Getting Rid of Packets"
//! (IEEE RT 2008) and of Embree's `BVH4`, and Jolt's `NodeCodecQuadTreeHalfFloat` (4 children
//! per node, boxes stored per axis); the collapse takes the child of largest area first, as
//! Jolt's `AABBTreeBuilder` does when it turns a binary tree into a quad tree.
//!
//! The wide nodes reuse the boxes of the binary nodes bit for bit (same quantisation and
//! outward rounding, or the same ulp-padded `Real` boxes) and the same leaves, so they are
//! as conservative as the binary layout; leaves still hold primitive ranges of
//! `Bvh::order`. The slab test
//! picks the near and far plane of each axis by the sign of the ray direction once per ray
//! (Williams et al., "An Efficient and Robust Ray–Box Intersection Algorithm", JGT 2005),
//! and scales the exit distance as Ize's robust test (`traverse::ROBUST_EXIT`).

use super::static_bvh::{leaf_range, QuantizedNode, UnquantizedNode, LEAF_FLAG};
use super::traverse::{RayStack, ROBUST_EXIT};
use crate::math::{Real, Vec3};

/// Marker of an unused child slot.
const EMPTY: u32 = u32::MAX;

/// Four child boxes and references in one cache line.
#[repr(C, align(64))]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WideNode {
    /// Quantised child boxes plane by plane: min x, min y, min z, max x, max y, max z; lane
    /// `k` is child `k`. Unused lanes hold an inverted box.
    pub planes: [[u16; 4]; 6],
    /// Child references: the index of a wide node, or a leaf's `data` (top bit set, as in
    /// [`QuantizedNode::data`]), or `u32::MAX` for an unused slot.
    pub children: [u32; 4],
}

const EMPTY_NODE: WideNode = WideNode {
    planes: [
        [u16::MAX; 4],
        [u16::MAX; 4],
        [u16::MAX; 4],
        [0; 4],
        [0; 4],
        [0; 4],
    ],
    children: [EMPTY; 4],
};

/// Four child boxes in [`Real`] coordinates and their references: the 4-wide node of the
/// unquantised layout (128 bytes in `f32`, two cache lines). The boxes are the binary
/// nodes' boxes (padded outward by a few ulps), plane by plane as in [`WideNode`], so the
/// slab test loads each plane as it is: no conversion. Each lane also names the binary node
/// it copies (in what would otherwise be padding), so a refit rewrites the planes from the
/// refitted binary nodes without collapsing again. Small trees that are refitted often (the
/// world query's tree over the bodies) use this layout.
#[repr(C, align(64))]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WideRealNode {
    /// Child boxes plane by plane: min x, min y, min z, max x, max y, max z; lane `k` is
    /// child `k`. Unused lanes hold an inverted box.
    pub planes: [[Real; 4]; 6],
    /// Child references, as in the `children` of a [`WideNode`].
    pub children: [u32; 4],
    /// The binary node each lane's box is taken from (`u32::MAX` for an unused lane).
    pub sources: [u32; 4],
}

const EMPTY_REAL_NODE: WideRealNode = WideRealNode {
    planes: [
        [Real::MAX; 4],
        [Real::MAX; 4],
        [Real::MAX; 4],
        [-Real::MAX; 4],
        [-Real::MAX; 4],
        [-Real::MAX; 4],
    ],
    children: [EMPTY; 4],
    sources: [EMPTY; 4],
};

/// The 4-wide nodes of a hierarchy, in its layout's coordinates.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum WideNodes {
    Quantized(Vec<WideNode>),
    Unquantized(Vec<WideRealNode>),
}

impl WideNodes {
    /// Number of wide nodes (0 when the root is a leaf).
    pub(crate) fn len(&self) -> usize {
        match self {
            WideNodes::Quantized(v) => v.len(),
            WideNodes::Unquantized(v) => v.len(),
        }
    }

    /// Bytes of the wide nodes.
    pub(crate) fn bytes(&self) -> usize {
        match self {
            WideNodes::Quantized(v) => std::mem::size_of_val(v.as_slice()),
            WideNodes::Unquantized(v) => std::mem::size_of_val(v.as_slice()),
        }
    }
}

/// Writes a box (`min`, `max`) into lane `lane` of a wide node's planes.
#[inline(always)]
fn put_lane<T: Copy>(planes: &mut [[T; 4]; 6], lane: usize, min: &[T; 3], max: &[T; 3]) {
    for a in 0..3 {
        planes[a][lane] = min[a];
        planes[3 + a][lane] = max[a];
    }
}

/// Binary nodes that collapse into 4-wide ones.
pub(crate) trait WideSource {
    /// The wide node they collapse into.
    type Wide: Copy;
    /// A wide node with no children.
    const EMPTY: Self::Wide;
    /// Area-like size of a node's box (ordering only).
    type Size: PartialOrd + Copy;
    fn len(&self) -> usize;
    fn data(&self, i: usize) -> u32;
    fn size(&self, i: usize) -> Self::Size;
    /// Writes node `i`'s box into lane `lane` of `w`.
    fn set_lane(&self, w: &mut Self::Wide, lane: usize, i: usize);
    /// The children of a wide node.
    fn children(w: &mut Self::Wide) -> &mut [u32; 4];
}

impl WideSource for [QuantizedNode] {
    type Wide = WideNode;
    const EMPTY: WideNode = EMPTY_NODE;
    type Size = u64;
    #[inline(always)]
    fn len(&self) -> usize {
        <[QuantizedNode]>::len(self)
    }
    #[inline(always)]
    fn data(&self, i: usize) -> u32 {
        self[i].data
    }
    #[inline(always)]
    fn size(&self, i: usize) -> u64 {
        let n = &self[i];
        let e = [0, 1, 2].map(|a| u64::from(n.max[a].saturating_sub(n.min[a])) + 1);
        e[0] * e[1] + e[1] * e[2] + e[2] * e[0]
    }
    #[inline(always)]
    fn set_lane(&self, w: &mut WideNode, lane: usize, i: usize) {
        put_lane(&mut w.planes, lane, &self[i].min, &self[i].max);
    }
    #[inline(always)]
    fn children(w: &mut WideNode) -> &mut [u32; 4] {
        &mut w.children
    }
}

impl WideSource for [UnquantizedNode] {
    type Wide = WideRealNode;
    const EMPTY: WideRealNode = EMPTY_REAL_NODE;
    type Size = Real;
    #[inline(always)]
    fn len(&self) -> usize {
        <[UnquantizedNode]>::len(self)
    }
    #[inline(always)]
    fn data(&self, i: usize) -> u32 {
        self[i].data
    }
    #[inline(always)]
    fn size(&self, i: usize) -> Real {
        let n = &self[i];
        let e = [0, 1, 2].map(|a| n.max[a] - n.min[a]);
        e[0] * e[1] + e[1] * e[2] + e[2] * e[0]
    }
    #[inline(always)]
    fn set_lane(&self, w: &mut WideRealNode, lane: usize, i: usize) {
        put_lane(&mut w.planes, lane, &self[i].min, &self[i].max);
        w.sources[lane] = i as u32;
    }
    #[inline(always)]
    fn children(w: &mut WideRealNode) -> &mut [u32; 4] {
        &mut w.children
    }
}

/// Collapses binary nodes into 4-wide nodes (empty when the root is a leaf).
/// Deterministic: ties in box size go to the first child in order.
pub(crate) fn collapse<S: WideSource + ?Sized>(nodes: &S) -> Vec<S::Wide> {
    let mut wide = Vec::new();
    collapse_into(nodes, &mut wide);
    wide
}

/// [`collapse`] into `wide`, reusing its buffer (a refit collapses the same tree again).
pub(crate) fn collapse_into<S: WideSource + ?Sized>(nodes: &S, wide: &mut Vec<S::Wide>) {
    wide.clear();
    if nodes.len() == 0 || nodes.data(0) & LEAF_FLAG != 0 {
        return;
    }
    let is_leaf = |i: usize| nodes.data(i) & LEAF_FLAG != 0;
    // The right child of internal node `i`: its left child's escape index.
    let right_of = |i: usize| {
        let left = nodes.data(i + 1);
        if left & LEAF_FLAG != 0 {
            i + 2
        } else {
            left as usize
        }
    };
    wide.push(S::EMPTY);
    // (binary node, wide node it becomes); the depth of a collapsed tree is far below 64.
    let mut stack: Vec<(usize, usize)> = Vec::with_capacity(64);
    stack.push((0, 0));
    while let Some((b, w)) = stack.pop() {
        let mut kids = [b + 1, right_of(b), 0, 0];
        let mut n = 2;
        while n < 4 {
            let mut pick: Option<(usize, S::Size)> = None;
            for (j, &k) in kids[..n].iter().enumerate() {
                if !is_leaf(k) {
                    let s = nodes.size(k);
                    if pick.is_none_or(|(_, best)| s > best) {
                        pick = Some((j, s));
                    }
                }
            }
            let Some((j, _)) = pick else { break };
            let k = kids[j];
            kids[j] = k + 1;
            kids[n] = right_of(k);
            n += 1;
        }
        let mut node = S::EMPTY;
        for (lane, &k) in kids[..n].iter().enumerate() {
            nodes.set_lane(&mut node, lane, k);
            S::children(&mut node)[lane] = if is_leaf(k) {
                nodes.data(k)
            } else {
                wide.push(S::EMPTY);
                stack.push((k, wide.len() - 1));
                (wide.len() - 1) as u32
            };
        }
        wide[w] = node;
    }
}

/// Rewrites the planes of unquantised wide nodes from the binary nodes their lanes name
/// (after a refit of those nodes): the collapse's topology is kept, as the refit keeps the
/// binary one.
pub(crate) fn refit_real(wide: &mut [WideRealNode], nodes: &[UnquantizedNode]) {
    for w in wide {
        for lane in 0..4 {
            if let Some(n) = nodes.get(w.sources[lane] as usize) {
                put_lane(&mut w.planes, lane, &n.min, &n.max);
            }
        }
    }
}

/// A wide node as the slab test reads it: its children and its planes as [`Real`] lanes.
pub(crate) trait WideBoxes {
    fn children(&self) -> &[u32; 4];
    /// Plane row `r` (see [`WideNode::planes`]).
    fn row(&self, r: usize) -> [Real; 4];
}

impl WideBoxes for WideNode {
    #[inline(always)]
    fn children(&self) -> &[u32; 4] {
        &self.children
    }
    /// The `u16` lanes converted (exactly).
    #[inline(always)]
    fn row(&self, r: usize) -> [Real; 4] {
        self.planes[r].map(Real::from)
    }
}

impl WideBoxes for WideRealNode {
    #[inline(always)]
    fn children(&self) -> &[u32; 4] {
        &self.children
    }
    #[inline(always)]
    fn row(&self, r: usize) -> [Real; 4] {
        self.planes[r]
    }
}

/// A ray in a wide node layout's coordinates (quantised, or world coordinates for
/// [`WideRealNode`]s), prepared for the sign-ordered slab test.
pub(crate) struct WideRay {
    /// Plane row of the near and far plane per axis.
    near_row: [usize; 3],
    far_row: [usize; 3],
    /// Offsets added to the near and far plane coordinates: minus the origin, minus (near of
    /// a min plane) or plus (a max plane) the rounding pad.
    near_off: [Real; 3],
    far_off: [Real; 3],
    inv: [Real; 3],
}

impl WideRay {
    /// From the origin and direction in quantised coordinates and the outward pad.
    pub(crate) fn new(o: Vec3, d: Vec3, pad: Vec3) -> Self {
        let mut r = WideRay {
            near_row: [0, 1, 2],
            far_row: [3, 4, 5],
            near_off: [0.0; 3],
            far_off: [0.0; 3],
            inv: [0.0; 3],
        };
        for a in 0..3 {
            let inv = 1.0 / d[a];
            let (lo, hi) = (-pad[a] - o[a], pad[a] - o[a]);
            r.inv[a] = inv;
            if inv.is_sign_negative() {
                r.near_row[a] = 3 + a;
                r.far_row[a] = a;
                r.near_off[a] = hi;
                r.far_off[a] = lo;
            } else {
                r.near_off[a] = lo;
                r.far_off[a] = hi;
            }
        }
        r
    }

    /// Entry parameter of the ray into each child box (clamped to 0), or infinity when it
    /// misses the box within `[0, max_t]`. A NaN slab (0 · ∞ for a ray in a box's plane)
    /// does not constrain, so the test stays conservative. On x86-64 in `f32` the four lanes
    /// run as one SSE2 vector ([`WideRay::entries_sse2`]), with the bits of
    /// [`WideRay::entries_scalar`].
    #[inline(always)]
    fn entries<N: WideBoxes>(&self, node: &N, max_t: Real) -> [Real; 4] {
        #[cfg(all(target_arch = "x86_64", not(feature = "f64")))]
        {
            self.entries_sse2(node, max_t)
        }
        #[cfg(not(all(target_arch = "x86_64", not(feature = "f64"))))]
        {
            self.entries_scalar(node, max_t)
        }
    }

    /// [`WideRay::entries`] lane by lane: the reference the vector form must match.
    #[inline(always)]
    #[cfg_attr(
        all(target_arch = "x86_64", not(feature = "f64"), not(test)),
        allow(dead_code)
    )]
    fn entries_scalar<N: WideBoxes>(&self, node: &N, max_t: Real) -> [Real; 4] {
        let mut near = [0.0 as Real; 4];
        let mut far = [max_t; 4];
        for a in 0..3 {
            let np = node.row(self.near_row[a]);
            let fp = node.row(self.far_row[a]);
            for k in 0..4 {
                let tn = (np[k] + self.near_off[a]) * self.inv[a];
                let tf = (fp[k] + self.far_off[a]) * self.inv[a];
                near[k] = if tn > near[k] { tn } else { near[k] };
                far[k] = if tf < far[k] { tf } else { far[k] };
            }
        }
        let mut out = [Real::INFINITY; 4];
        for k in 0..4 {
            if near[k] <= far[k] * ROBUST_EXIT {
                out[k] = near[k];
            }
        }
        out
    }

    /// [`WideRay::entries_scalar`] on one SSE2 vector of four lanes (glam's `Vec4`, which
    /// wraps an `__m128` on x86-64), without branches: the profile of the raytests batch put
    /// most of its instructions on the scalar form's 24 conversions and 24 data-dependent
    /// selects per node. On SSE2 `Vec4::max` is `maxps a, b` = `a > b ? a : b` and
    /// `Vec4::min` is `minps a, b` = `a < b ? a : b`, NaN taking `b`, so `tn.max(near)` and
    /// `tf.min(far)` are the scalar selects bit for bit (signed zeros included); `u16` lanes
    /// convert exactly. Other targets' `max` and `min` differ on NaN and zeros, so they keep
    /// the scalar form.
    #[cfg(all(target_arch = "x86_64", not(feature = "f64")))]
    #[inline(always)]
    fn entries_sse2<N: WideBoxes>(&self, node: &N, max_t: Real) -> [Real; 4] {
        use glam::Vec4;
        let row = |r: usize| Vec4::from_array(node.row(r));
        let mut near = Vec4::ZERO;
        let mut far = Vec4::splat(max_t);
        for a in 0..3 {
            let inv = Vec4::splat(self.inv[a]);
            let tn = (row(self.near_row[a]) + Vec4::splat(self.near_off[a])) * inv;
            let tf = (row(self.far_row[a]) + Vec4::splat(self.far_off[a])) * inv;
            near = tn.max(near);
            far = tf.min(far);
        }
        let keep = near.cmple(far * ROBUST_EXIT);
        Vec4::select(keep, near, Vec4::INFINITY).to_array()
    }
}

/// Closest-hit walk over the wide nodes: children in order of entry, nearest first, far
/// ones deferred on a small stack and dropped when they are entered beyond the current
/// `max_t`. `f(primitive, &mut max_t)` may shrink `max_t`, and returns `false` to stop.
#[inline(always)]
pub(crate) fn walk_ordered<N: WideBoxes>(
    wide: &[N],
    order: &[u32],
    ray: &WideRay,
    max_t: &mut Real,
    mut f: impl FnMut(u32, &mut Real) -> bool,
) {
    let mut stack = RayStack::new();
    let mut leaf = |data: u32, max_t: &mut Real| -> bool {
        let (first, count) = leaf_range(data);
        order[first..first + count].iter().all(|&p| f(p, max_t))
    };
    let mut node = 0usize;
    loop {
        let n = &wide[node];
        let entry = ray.entries(n, *max_t);
        // The children entered, sorted by entry (ties keep lane order).
        let mut hit = [(0.0 as Real, 0u32); 4];
        let mut m = 0;
        for (&t, &child) in entry.iter().zip(n.children()) {
            if t < Real::INFINITY && child != EMPTY {
                let mut j = m;
                while j > 0 && hit[j - 1].0 > t {
                    hit[j] = hit[j - 1];
                    j -= 1;
                }
                hit[j] = (t, child);
                m += 1;
            }
        }
        for &(t, c) in hit[1..m.max(1)].iter().rev() {
            stack.push((c, t));
        }
        let mut next = if m > 0 { Some(hit[0].1) } else { None };
        loop {
            let c = match next.take() {
                Some(c) => c,
                None => loop {
                    match stack.pop() {
                        Some((c, t)) if t <= *max_t * ROBUST_EXIT => break c,
                        Some(_) => continue,
                        None => return,
                    }
                },
            };
            if c & LEAF_FLAG != 0 {
                if !leaf(c, max_t) {
                    return;
                }
            } else {
                node = c as usize;
                break;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::{Bvh, BvhLayout};
    use crate::math::Aabb;

    #[test]
    fn node_is_one_cache_line() {
        assert_eq!(std::mem::size_of::<WideNode>(), 64);
        assert_eq!(std::mem::align_of::<WideNode>(), 64);
    }

    /// The vector slab test against its scalar reference, bit for bit, over random nodes
    /// (inverted padding lanes included) and rays with zero, negative and tiny direction
    /// components (infinite inverses, NaN slabs), origins inside and outside the boxes,
    /// and finite, zero and infinite `max_t`.
    #[test]
    fn vector_entries_are_the_scalar_bits() {
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        let comps: [Real; 7] = [0.0, -0.0, 1.0, -0.5, 1e-30, -3.0e4, 0.25];
        for case in 0..20_000 {
            let mut node = EMPTY_NODE;
            let lanes = 1 + (next() % 4) as usize;
            for k in 0..lanes {
                for a in 0..3 {
                    let (x, y) = ((next() % 65536) as u16, (next() % 65536) as u16);
                    node.planes[a][k] = x.min(y);
                    node.planes[3 + a][k] = x.max(y);
                }
            }
            let pick = |r: u64| -> Real {
                if r.is_multiple_of(3) {
                    comps[(r / 3 % 7) as usize]
                } else {
                    ((r >> 8) % 200_000) as Real * 0.5 - 30_000.0
                }
            };
            let o = Vec3::new(pick(next()), pick(next()), pick(next()));
            let d = Vec3::new(pick(next()), pick(next()), pick(next()));
            let pad = Vec3::splat((next() % 4) as Real * 0.01);
            let ray = WideRay::new(o, d, pad);
            let max_t = [0.0, 1.0, 7.5e3, Real::INFINITY][case % 4];
            let want = ray.entries_scalar(&node, max_t);
            let got = ray.entries(&node, max_t);
            assert_eq!(
                want.map(Real::to_bits),
                got.map(Real::to_bits),
                "case {case}: o {o}, d {d}, max_t {max_t}"
            );
            // The same boxes as `Real` planes (with their unused lanes inverted as
            // `EMPTY_REAL_NODE` has them): the same entries, in both forms.
            let mut real = EMPTY_REAL_NODE;
            for (row, q) in real.planes.iter_mut().zip(&node.planes) {
                for (x, &v) in row.iter_mut().zip(q).take(lanes) {
                    *x = Real::from(v);
                }
            }
            let ray = WideRay::new(o, d, Vec3::ZERO);
            let want = ray.entries_scalar(&node, max_t);
            for got in [ray.entries_scalar(&real, max_t), ray.entries(&real, max_t)] {
                for k in 0..lanes {
                    assert_eq!(want[k].to_bits(), got[k].to_bits(), "case {case} lane {k}");
                }
                assert!(got[lanes..].iter().all(|&t| t == Real::INFINITY));
            }
        }
    }

    #[test]
    fn collapse_keeps_every_leaf_once() {
        use crate::bvh::static_bvh::Nodes;
        for n in [1usize, 2, 3, 9, 40, 500] {
            let boxes: Vec<Aabb> = (0..n)
                .map(|i| {
                    let x = (i as Real * 0.37).sin() * 10.0;
                    let y = (i as Real * 0.11).cos() * 3.0;
                    let c = Vec3::new(x, y, i as Real * 0.01);
                    Aabb::from_center_half_extents(c, Vec3::splat(0.2))
                })
                .collect();
            let bvh = Bvh::new(&boxes, BvhLayout::Quantized).unwrap();
            let real = bvh.with_layout(BvhLayout::Unquantized);
            let (Nodes::Quantized(nodes, _), Nodes::Unquantized(real_nodes)) =
                (&bvh.nodes, &real.nodes)
            else {
                unreachable!()
            };
            let leaves: Vec<u32> = nodes
                .iter()
                .map(|n| n.data)
                .filter(|d| d & LEAF_FLAG != 0)
                .collect();
            // Both layouts collapse the same binary topology (their size orders may pick
            // different grandchildren to pull up).
            let children: Vec<[u32; 4]> = collapse(nodes.as_slice())
                .iter()
                .map(|w| w.children)
                .collect();
            let real_children: Vec<[u32; 4]> = collapse(real_nodes.as_slice())
                .iter()
                .map(|w| w.children)
                .collect();
            check_collapse(&children, leaves.clone());
            check_collapse(&real_children, leaves);
        }
    }

    /// Every leaf in exactly one lane, every wide node but the root referenced once, and
    /// at least two children per node.
    fn check_collapse(wide: &[[u32; 4]], mut leaves: Vec<u32>) {
        if leaves.len() == 1 {
            assert!(wide.is_empty());
            return;
        }
        let mut got: Vec<u32> = wide
            .iter()
            .flatten()
            .copied()
            .filter(|&c| c != EMPTY && c & LEAF_FLAG != 0)
            .collect();
        leaves.sort_unstable();
        got.sort_unstable();
        assert_eq!(got, leaves);
        let mut refs: Vec<u32> = wide
            .iter()
            .flatten()
            .copied()
            .filter(|&c| c != EMPTY && c & LEAF_FLAG == 0)
            .collect();
        refs.sort_unstable();
        assert_eq!(refs, (1..wide.len() as u32).collect::<Vec<_>>());
        assert!(wide.iter().all(|w| w[1] != EMPTY));
    }
}
