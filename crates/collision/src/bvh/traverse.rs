//! Stackless traversals of a [`Bvh`] against a box, a ray and a point.
//!
//! The loop is that of Bullet's `btQuantizedBvh::walkStacklessQuantizedTree`: visit node `i`;
//! if its box passes the test and it is a leaf, report its primitives; if the box fails and
//! the node is internal, jump to its escape index; otherwise go to `i + 1`. No stack, no
//! recursion, memory read in order. Boxes are tested in the layout's own coordinates:
//! query boxes are quantised outward and rays are mapped into the quantised frame once,
//! so quantised nodes are never decoded on the hot path.
//!
//! Ray–box tests follow the robust slab test of Ize, "Robust BVH Ray Traversal" (JCGT 2013):
//! the exit distance is scaled by `1 + 2γ₃` so a ray touching a box is never culled.

use super::quantize::Quantization;
use super::static_bvh::{leaf_range, Bvh, Nodes, QuantizedNode, UnquantizedNode, LEAF_FLAG};
use super::wide::{walk_ordered, WideNodes, WideRay};
use crate::math::{Aabb, Real, Vec3, Vec3A, EPSILON};
use smallvec::SmallVec;

/// `1 + 2γ₃` with `γₙ = nε / (1 - nε)` (Ize 2013), plus slack for the quantised mapping and
/// for the rounding of the leaf test's `t`, so a box is never culled against a tied hit.
pub(crate) const ROBUST_EXIT: Real =
    1.0 + 2.0 * (3.0 * EPSILON / (1.0 - 3.0 * EPSILON)) + 32.0 * EPSILON;

/// A ray prepared for slab tests against the boxes of one layout.
#[derive(Clone, Copy)]
pub(crate) struct PreparedRay {
    lo: Vec3A,
    hi: Vec3A,
    inv: Vec3A,
}

impl PreparedRay {
    #[inline]
    fn new(origin: Vec3, dir: Vec3, pad: Vec3) -> Self {
        PreparedRay {
            lo: Vec3A::from(-pad - origin),
            hi: Vec3A::from(pad - origin),
            inv: Vec3A::from(dir.recip()),
        }
    }

    /// True when the ray meets the box `[min, max]` (in the prepared frame) within
    /// `[0, max_t]`.
    #[inline(always)]
    fn hits(&self, min: Vec3A, max: Vec3A, max_t: Real) -> bool {
        self.entry(min, max, max_t) <= max_t * ROBUST_EXIT
    }

    /// Entry parameter of the ray into the box (clamped to 0), or infinity when it misses
    /// the box within `[0, max_t]`.
    #[inline(always)]
    fn entry(&self, min: Vec3A, max: Vec3A, max_t: Real) -> Real {
        let t1 = (min + self.lo) * self.inv;
        let t2 = (max + self.hi) * self.inv;
        let near = t1.min(t2).max_element().max(0.0);
        let far = t1.max(t2).min_element().min(max_t) * ROBUST_EXIT;
        if near <= far {
            near
        } else {
            Real::INFINITY
        }
    }
}

/// The ray in quantised coordinates (origin, direction) and the outward pad covering the
/// rounding of the mapping. The affine map keeps the ray parameter `t`.
#[inline]
fn quantized_ray(q: &Quantization, origin: Vec3, dir: Vec3) -> (Vec3, Vec3, Vec3) {
    let o = (origin - q.origin) * q.scale;
    let d = dir * q.scale;
    let pad = (o.abs() + Vec3::splat(65536.0)) * (8.0 * EPSILON);
    (o, d, pad)
}

/// Node access shared by the two layouts.
pub(crate) trait NodeSet {
    /// Query box in the layout's coordinates.
    type BoxQuery: Copy;
    fn len(&self) -> usize;
    fn data(&self, i: usize) -> u32;
    /// Conservative world box of node `i`.
    fn aabb(&self, i: usize) -> Aabb;
    fn box_query(&self, aabb: &Aabb) -> Self::BoxQuery;
    fn overlaps(&self, i: usize, q: &Self::BoxQuery) -> bool;
    fn ray(&self, origin: Vec3, dir: Vec3) -> PreparedRay;
    fn ray_hits(&self, i: usize, r: &PreparedRay, max_t: Real) -> bool;
    /// Entry parameter into node `i`'s box, infinity on a miss.
    fn ray_entry(&self, i: usize, r: &PreparedRay, max_t: Real) -> Real;
}

/// Quantised nodes with their quantisation.
pub(crate) struct QNodes<'a>(pub &'a [QuantizedNode], pub &'a Quantization);

#[inline(always)]
fn u16v(v: [u16; 3]) -> Vec3A {
    Vec3A::new(v[0] as Real, v[1] as Real, v[2] as Real)
}

impl NodeSet for QNodes<'_> {
    type BoxQuery = ([u16; 3], [u16; 3]);
    #[inline(always)]
    fn len(&self) -> usize {
        self.0.len()
    }
    #[inline(always)]
    fn data(&self, i: usize) -> u32 {
        self.0[i].data
    }
    fn aabb(&self, i: usize) -> Aabb {
        self.1.dequantize(self.0[i].min, self.0[i].max)
    }
    fn box_query(&self, aabb: &Aabb) -> Self::BoxQuery {
        (
            self.1.quantize(aabb.min, false),
            self.1.quantize(aabb.max, true),
        )
    }
    #[inline(always)]
    fn overlaps(&self, i: usize, q: &Self::BoxQuery) -> bool {
        let n = &self.0[i];
        n.min[0] <= q.1[0]
            && n.max[0] >= q.0[0]
            && n.min[1] <= q.1[1]
            && n.max[1] >= q.0[1]
            && n.min[2] <= q.1[2]
            && n.max[2] >= q.0[2]
    }
    fn ray(&self, origin: Vec3, dir: Vec3) -> PreparedRay {
        let (o, d, pad) = quantized_ray(self.1, origin, dir);
        PreparedRay::new(o, d, pad)
    }
    #[inline(always)]
    fn ray_hits(&self, i: usize, r: &PreparedRay, max_t: Real) -> bool {
        let n = &self.0[i];
        r.hits(u16v(n.min), u16v(n.max), max_t)
    }
    #[inline(always)]
    fn ray_entry(&self, i: usize, r: &PreparedRay, max_t: Real) -> Real {
        let n = &self.0[i];
        r.entry(u16v(n.min), u16v(n.max), max_t)
    }
}

impl NodeSet for &[UnquantizedNode] {
    type BoxQuery = Aabb;
    #[inline(always)]
    fn len(&self) -> usize {
        (**self).len()
    }
    #[inline(always)]
    fn data(&self, i: usize) -> u32 {
        self[i].data
    }
    fn aabb(&self, i: usize) -> Aabb {
        Aabb::new(Vec3::from(self[i].min), Vec3::from(self[i].max))
    }
    fn box_query(&self, aabb: &Aabb) -> Aabb {
        *aabb
    }
    #[inline(always)]
    fn overlaps(&self, i: usize, q: &Aabb) -> bool {
        self.aabb(i).intersects(q)
    }
    fn ray(&self, origin: Vec3, dir: Vec3) -> PreparedRay {
        PreparedRay::new(origin, dir, Vec3::ZERO)
    }
    #[inline(always)]
    fn ray_hits(&self, i: usize, r: &PreparedRay, max_t: Real) -> bool {
        r.hits(
            Vec3A::from_array(self[i].min),
            Vec3A::from_array(self[i].max),
            max_t,
        )
    }
    #[inline(always)]
    fn ray_entry(&self, i: usize, r: &PreparedRay, max_t: Real) -> Real {
        r.entry(
            Vec3A::from_array(self[i].min),
            Vec3A::from_array(self[i].max),
            max_t,
        )
    }
}

/// Runs `$body` with `$ns` bound to the node set of `$bvh`, monomorphised per layout.
macro_rules! with_nodes {
    ($bvh:expr, $ns:ident => $body:expr) => {
        match &$bvh.nodes {
            Nodes::Quantized(v, q) => {
                let $ns = QNodes(v, q);
                $body
            }
            Nodes::Unquantized(v) => {
                let $ns = &v[..];
                $body
            }
        }
    };
}
pub(crate) use with_nodes;

/// Walks the tree: `test(i)` decides whether node `i` is entered; leaves' primitives go to
/// `leaf(prim)`, which returns `false` to stop. Returns `false` when stopped.
#[inline(always)]
fn walk<N: NodeSet>(
    ns: &N,
    order: &[u32],
    mut test: impl FnMut(&N, usize) -> bool,
    mut leaf: impl FnMut(u32) -> bool,
) -> bool {
    let n = ns.len();
    let mut i = 0;
    while i < n {
        let data = ns.data(i);
        let hit = test(ns, i);
        if data & LEAF_FLAG != 0 {
            if hit {
                let (first, count) = leaf_range(data);
                for &p in &order[first..first + count] {
                    if !leaf(p) {
                        return false;
                    }
                }
            }
            i += 1;
        } else if hit {
            i += 1;
        } else {
            i = data as usize;
        }
    }
    true
}

impl Bvh {
    /// Calls `f(primitive)` for every primitive whose node boxes overlap `aabb` (a superset
    /// of the primitives whose own boxes overlap it; callers test exactly). `f` returns
    /// `false` to stop early.
    pub fn for_each_candidate_in_aabb(&self, aabb: &Aabb, f: impl FnMut(u32) -> bool) {
        if !aabb.intersects(&self.root_aabb()) {
            return;
        }
        with_nodes!(self, ns => {
            let q = ns.box_query(aabb);
            walk(&ns, &self.order, |ns, i| ns.overlaps(i, &q), f);
        })
    }

    /// Calls `f(primitive, &mut max_t)` for every primitive whose node boxes the ray
    /// `origin + t·dir`, `t ∈ [0, max_t]`, enters. `f` may shrink `max_t` (closest hit) and
    /// returns `false` to stop (any hit).
    pub fn for_each_candidate_on_ray(
        &self,
        origin: Vec3,
        dir: Vec3,
        max_t: Real,
        mut f: impl FnMut(u32, &mut Real) -> bool,
    ) {
        let mut max_t = max_t;
        with_nodes!(self, ns => {
            let r = ns.ray(origin, dir);
            if !ns.ray_hits(0, &r, max_t) {
                return;
            }
            let n = ns.len();
            let mut i = 0;
            while i < n {
                let data = ns.data(i);
                let hit = ns.ray_hits(i, &r, max_t);
                if data & LEAF_FLAG != 0 {
                    if hit {
                        let (first, count) = leaf_range(data);
                        for &p in &self.order[first..first + count] {
                            if !f(p, &mut max_t) {
                                return;
                            }
                        }
                    }
                    i += 1;
                } else if hit {
                    i += 1;
                } else {
                    i = data as usize;
                }
            }
        })
    }

    /// Like [`Bvh::for_each_candidate_on_ray`], but visits the nearer child first and skips
    /// subtrees entered beyond the current `max_t`: the fast path for closest hits. Uses a
    /// small stack of deferred far children (the stackless walk cannot order children).
    /// Both layouts walk their 4-wide nodes (`bvh::wide`), and a tree whose root is a leaf
    /// its one leaf; every primitive a closest hit needs is visited.
    pub fn for_each_candidate_on_ray_ordered(
        &self,
        origin: Vec3,
        dir: Vec3,
        max_t: Real,
        mut f: impl FnMut(u32, &mut Real) -> bool,
    ) {
        let mut max_t = max_t;
        match (&self.nodes, &self.wide) {
            (Nodes::Quantized(_, q), WideNodes::Quantized(w)) if !w.is_empty() => {
                let (o, d, pad) = quantized_ray(q, origin, dir);
                let ray = WideRay::new(o, d, pad);
                walk_ordered(w, &self.order, &ray, &mut max_t, f);
                return;
            }
            (Nodes::Unquantized(_), WideNodes::Unquantized(w)) if !w.is_empty() => {
                // The boxes are padded by a few ulps already (`pad_ulps`), as for the
                // binary walk.
                let ray = WideRay::new(origin, dir, Vec3::ZERO);
                walk_ordered(w, &self.order, &ray, &mut max_t, f);
                return;
            }
            _ => {}
        }
        with_nodes!(self, ns => {
            let r = ns.ray(origin, dir);
            if ns.ray_entry(0, &r, max_t) == Real::INFINITY {
                return;
            }
            let mut stack = RayStack::new();
            let mut node = 0usize;
            loop {
                let data = ns.data(node);
                let mut next = None;
                if data & LEAF_FLAG != 0 {
                    let (first, count) = leaf_range(data);
                    for &p in &self.order[first..first + count] {
                        if !f(p, &mut max_t) {
                            return;
                        }
                    }
                } else {
                    let (l, rc) = (node + 1, right_child_of(&ns, node));
                    let tl = ns.ray_entry(l, &r, max_t);
                    let tr = ns.ray_entry(rc, &r, max_t);
                    let (near, far, t_far) = if tl <= tr { (l, rc, tr) } else { (rc, l, tl) };
                    if tl.min(tr) < Real::INFINITY {
                        next = Some(near);
                        if t_far < Real::INFINITY {
                            stack.push((far as u32, t_far));
                        }
                    }
                }
                node = match next {
                    Some(n) => n,
                    None => loop {
                        match stack.pop() {
                            Some((n, t)) if t <= max_t * ROBUST_EXIT => break n as usize,
                            Some(_) => continue,
                            None => return,
                        }
                    },
                };
            }
        })
    }

    /// Calls `f(primitive, &mut max_dist_sq)` for every primitive whose node boxes lie within
    /// `sqrt(max_dist_sq)` of `point`. `f` may shrink the bound (closest point) and returns
    /// `false` to stop.
    pub fn for_each_candidate_near_point(
        &self,
        point: Vec3,
        max_dist_sq: Real,
        mut f: impl FnMut(u32, &mut Real) -> bool,
    ) {
        let mut bound = max_dist_sq;
        with_nodes!(self, ns => {
            let n = ns.len();
            let mut i = 0;
            while i < n {
                let data = ns.data(i);
                let hit = box_dist_sq(&ns.aabb(i), point) <= bound;
                if data & LEAF_FLAG != 0 {
                    if hit {
                        let (first, count) = leaf_range(data);
                        for &p in &self.order[first..first + count] {
                            if !f(p, &mut bound) {
                                return;
                            }
                        }
                    }
                    i += 1;
                } else if hit {
                    i += 1;
                } else {
                    i = data as usize;
                }
            }
        })
    }
}

/// Squared distance from `p` to the box (0 inside), shrunk by the rounding error of the
/// coordinates so it never exceeds the computed distance to anything inside the box.
#[inline]
pub(crate) fn box_dist_sq(b: &Aabb, p: Vec3) -> Real {
    let d = (b.min - p).max(p - b.max);
    let slack = (p.abs() + b.min.abs().max(b.max.abs())) * (8.0 * EPSILON);
    (d - slack).max(Vec3::ZERO).length_squared()
}

/// Right child of internal node `i`: the escape index of its left child `i + 1`.
#[inline]
pub(crate) fn right_child_of<N: NodeSet>(ns: &N, i: usize) -> usize {
    let left = ns.data(i + 1);
    if left & LEAF_FLAG != 0 {
        i + 2
    } else {
        left as usize
    }
}

/// Deferred far children of the ordered ray walk: an inline array, spilling to the heap only
/// for trees deeper than it (degenerate inputs), so no allocation per ray. The inline array
/// is left uninitialised (`SmallVec`): zeroing the 384 bytes of the array of 48 it replaced
/// was a `memset` call per walk, 84 instructions of a world ray's ~5,500 for each of its two
/// walks.
pub(crate) struct RayStack(SmallVec<[(u32, Real); 64]>);

impl RayStack {
    #[inline]
    pub(crate) fn new() -> Self {
        RayStack(SmallVec::new())
    }
    #[inline]
    pub(crate) fn push(&mut self, e: (u32, Real)) {
        self.0.push(e);
    }
    #[inline]
    pub(crate) fn pop(&mut self) -> Option<(u32, Real)> {
        self.0.pop()
    }
}
