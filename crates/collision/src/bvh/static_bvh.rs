//! A static bounding-volume hierarchy with fixed topology, in two node layouts.
//!
//! The layout follows Bullet's `btQuantizedBvh` (`btOptimizedBvh`) as presented in Coumans,
//! "Optimizing Proximity Queries for CPU, SPU and GPU" (SIGGRAPH 2010): nodes in depth-first
//! order, each either a leaf (a range of primitives) or an internal node whose left child
//! follows it and whose *escape index* points just past its subtree, so traversal needs no
//! stack. Quantised nodes are 16 bytes: the box as six `u16` relative to the hierarchy's
//! bounds (minimum rounded down, maximum rounded up, so no primitive is ever missed) and one
//! `u32` holding the escape index or the leaf's primitive range. The unquantised layout
//! stores boxes as [`Real`]s, for comparison; both give identical query results.
//!
//! [`Bvh::refit`] recomputes the boxes after primitives moved without changing topology.

use super::build::{build_with_leaves, BuildOutput, MAX_LEAF_SIZE};
use super::quantize::Quantization;
use super::traverse::{right_child_of, with_nodes, NodeSet, QNodes};
use super::wide::{collapse, collapse_into, refit_real, WideNodes};
use crate::error::{CaromError, Result};
use crate::math::{Aabb, Real, Vec3, EPSILON};
use serde::{Deserialize, Serialize};

/// Flag bit of a leaf's `data`.
pub(crate) const LEAF_FLAG: u32 = 1 << 31;
const COUNT_SHIFT: u32 = 28;
const FIRST_MASK: u32 = (1 << COUNT_SHIFT) - 1;
/// Largest number of primitives a [`Bvh`] can hold.
pub const MAX_PRIMITIVES: usize = FIRST_MASK as usize;

/// Which node layout a [`Bvh`] stores.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
pub enum BvhLayout {
    /// 16-byte nodes with boxes quantised to `u16` (the default).
    #[default]
    Quantized,
    /// Nodes with [`Real`] boxes (28 bytes in `f32`), for comparison.
    Unquantized,
}

/// A 16-byte node: box quantised relative to the hierarchy bounds, and the escape index
/// (internal node) or primitive range (leaf, top bit set).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct QuantizedNode {
    /// Quantised lower corner (rounded down).
    pub min: [u16; 3],
    /// Quantised upper corner (rounded up).
    pub max: [u16; 3],
    /// Escape index, or `LEAF | (count - 1) << 28 | first` for a leaf.
    pub data: u32,
}

/// A node with a [`Real`] box (padded outward by a few ulps).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct UnquantizedNode {
    /// Lower corner.
    pub min: [Real; 3],
    /// Upper corner.
    pub max: [Real; 3],
    /// Escape index or leaf range, as in [`QuantizedNode::data`].
    pub data: u32,
}

/// The nodes, in one of the two layouts.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub(crate) enum Nodes {
    Quantized(Vec<QuantizedNode>, Quantization),
    Unquantized(Vec<UnquantizedNode>),
}

/// A static BVH over primitive boxes (triangles, heightfield cells, compound children).
/// Build with [`Bvh::new`]; query with the traversals in `bvh::traverse`. Serialised without
/// its 4-wide nodes, which are derived from the binary ones when loading; equality compares
/// what is serialised (see the `PartialEq` impl).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(try_from = "BvhData", into = "BvhData")]
pub struct Bvh {
    pub(crate) nodes: Nodes,
    /// Primitive indices; a leaf covers a contiguous range.
    pub(crate) order: Vec<u32>,
    /// Exact bounds of all primitives.
    pub(crate) bounds: Aabb,
    /// The nodes collapsed to 4-wide nodes for closest-hit rays (`bvh::wide`), in the
    /// layout's coordinates; empty when the root is a leaf.
    pub(crate) wide: WideNodes,
}

/// Equal binary nodes, primitive order and bounds: what a hierarchy serialises. The 4-wide
/// nodes are derived from those and left out: a refitted unquantised tree keeps the wide
/// topology of its build, where a loaded copy collapses afresh (possibly pulling up other
/// grandchildren), and both answer every query alike.
impl PartialEq for Bvh {
    fn eq(&self, other: &Self) -> bool {
        self.nodes == other.nodes && self.order == other.order && self.bounds == other.bounds
    }
}

/// The serialised form of a [`Bvh`]: everything but the derived 4-wide nodes. Loading checks
/// the tree structure (ranges and escape indices in bounds, subtrees nested), so corrupted
/// bytes give an error rather than a panic in a traversal.
#[derive(Serialize, Deserialize)]
struct BvhData {
    nodes: Nodes,
    order: Vec<u32>,
    bounds: Aabb,
}

impl TryFrom<BvhData> for Bvh {
    type Error = String;
    fn try_from(d: BvhData) -> std::result::Result<Self, String> {
        let data: Vec<u32> = match &d.nodes {
            Nodes::Quantized(v, _) => v.iter().map(|n| n.data).collect(),
            Nodes::Unquantized(v) => v.iter().map(|n| n.data).collect(),
        };
        if let Err(reason) = check_structure(&data, &d.order) {
            let _ = crate::shape::serde_check::record::<()>(Err(CaromError::Parse {
                what: "BVH".into(),
                reason: reason.clone(),
            }));
            return Err(reason);
        }
        Ok(Bvh {
            wide: wide_nodes(&d.nodes),
            nodes: d.nodes,
            order: d.order,
            bounds: d.bounds,
        })
    }
}

/// Checks that `data` (node escape indices and leaf ranges) forms a depth-first tree over
/// `order`, a permutation-sized list of primitive indices in range.
fn check_structure(data: &[u32], order: &[u32]) -> std::result::Result<(), String> {
    let n = data.len();
    let escape = |i: usize| {
        if data[i] & LEAF_FLAG != 0 {
            i + 1
        } else {
            data[i] as usize
        }
    };
    if n == 0 || order.is_empty() || escape(0) != n {
        return Err("invalid BVH: empty, or the root does not span the nodes".into());
    }
    if let Some(p) = order.iter().find(|&&p| p as usize >= order.len()) {
        return Err(format!("invalid BVH: primitive {p} out of range"));
    }
    for (i, &d) in data.iter().enumerate() {
        if d & LEAF_FLAG != 0 {
            let (first, count) = leaf_range(d);
            if first + count > order.len() {
                return Err(format!("invalid BVH: leaf {i} out of range"));
            }
        } else {
            let e = d as usize;
            // Left child i + 1, right child r, both inside the subtree, the right one
            // ending where the parent does.
            if e <= i + 2 || e > n {
                return Err(format!("invalid BVH: escape index of node {i}"));
            }
            let r = escape(i + 1);
            if r <= i + 1 || r >= e || escape(r) != e {
                return Err(format!("invalid BVH: children of node {i}"));
            }
        }
    }
    Ok(())
}

impl From<Bvh> for BvhData {
    fn from(b: Bvh) -> Self {
        BvhData {
            nodes: b.nodes,
            order: b.order,
            bounds: b.bounds,
        }
    }
}

/// Encodes a leaf's primitive range.
#[inline]
fn leaf_data(first: u32, count: u32) -> u32 {
    debug_assert!((1..=8).contains(&count) && first <= FIRST_MASK);
    LEAF_FLAG | ((count - 1) << COUNT_SHIFT) | first
}

/// Decodes a leaf's `data` into `(first, count)`.
#[inline(always)]
pub(crate) fn leaf_range(data: u32) -> (usize, usize) {
    (
        (data & FIRST_MASK) as usize,
        (((data >> COUNT_SHIFT) & 7) + 1) as usize,
    )
}

/// Pads a box outward by a few ulps so that a ray lying in a face plane of the exact box
/// never produces `0 · ∞` on the padded one.
#[inline]
fn pad_ulps(aabb: &Aabb) -> Aabb {
    let tiny = Real::MIN_POSITIVE;
    Aabb::new(
        aabb.min - (aabb.min.abs() * (4.0 * EPSILON) + Vec3::splat(tiny)),
        aabb.max + (aabb.max.abs() * (4.0 * EPSILON) + Vec3::splat(tiny)),
    )
}

fn check_boxes(boxes: &[Aabb]) -> Result<()> {
    if boxes.is_empty() {
        return Err(CaromError::invalid(
            "boxes",
            0usize,
            "a BVH needs at least one primitive",
        ));
    }
    if boxes.len() > MAX_PRIMITIVES {
        return Err(CaromError::invalid(
            "boxes.len()",
            boxes.len(),
            format!("a BVH holds at most {MAX_PRIMITIVES} primitives"),
        ));
    }
    // One pass without branches (a refit checks every box each time), then the first bad
    // box for the error.
    if !boxes.iter().fold(true, |ok, b| ok & b.is_valid()) {
        if let Some((i, b)) = boxes.iter().enumerate().find(|(_, b)| !b.is_valid()) {
            return Err(CaromError::invalid(
                format!("boxes[{i}]"),
                b,
                "must be finite with min <= max",
            ));
        }
    }
    Ok(())
}

impl Bvh {
    /// Builds a BVH over primitive boxes (binned SAH, see `bvh::build`). Primitive `i`
    /// is reported as `i` by the traversals. Errors for no boxes, invalid boxes, or more
    /// than [`MAX_PRIMITIVES`].
    pub fn new(boxes: &[Aabb], layout: BvhLayout) -> Result<Self> {
        Self::with_max_leaf_size(boxes, layout, MAX_LEAF_SIZE)
    }

    /// [`Bvh::new`] with leaves of at most `max_leaf_size` primitives (clamped to
    /// `1..=`[`MAX_LEAF_SIZE`]; `new` uses the largest). Leaves of one primitive suit
    /// primitives that cost far more to test than a node visit, such as the bodies of a
    /// world query: the closest-first ray walk then visits each one in the order its box is
    /// entered and skips those beyond the closest hit, where a leaf's primitives would be
    /// tested in storage order.
    pub fn with_max_leaf_size(
        boxes: &[Aabb],
        layout: BvhLayout,
        max_leaf_size: usize,
    ) -> Result<Self> {
        check_boxes(boxes)?;
        let BuildOutput {
            nodes,
            escapes,
            order,
        } = build_with_leaves(boxes, max_leaf_size);
        let aabbs: Vec<Aabb> = nodes.iter().map(|n| n.aabb).collect();
        let data: Vec<u32> = nodes
            .iter()
            .zip(&escapes)
            .map(|(n, &e)| {
                if n.is_leaf() {
                    leaf_data(n.first_or_right, n.count)
                } else {
                    e
                }
            })
            .collect();
        let bounds = aabbs[0];
        let nodes = make_nodes(layout, &aabbs, &data, &bounds);
        Ok(Bvh {
            wide: wide_nodes(&nodes),
            nodes,
            order,
            bounds,
        })
    }

    /// The node layout.
    pub fn layout(&self) -> BvhLayout {
        match self.nodes {
            Nodes::Quantized(..) => BvhLayout::Quantized,
            Nodes::Unquantized(_) => BvhLayout::Unquantized,
        }
    }

    /// Number of nodes.
    pub fn num_nodes(&self) -> usize {
        match &self.nodes {
            Nodes::Quantized(v, _) => v.len(),
            Nodes::Unquantized(v) => v.len(),
        }
    }

    /// Number of primitives.
    pub fn num_primitives(&self) -> usize {
        self.order.len()
    }

    /// Number of 4-wide nodes kept for closest-hit rays (0 for single-leaf hierarchies).
    pub fn num_wide_nodes(&self) -> usize {
        self.wide.len()
    }

    /// Bytes used by the nodes (binary and 4-wide) and the primitive order.
    pub fn memory_bytes(&self) -> usize {
        let nodes = match &self.nodes {
            Nodes::Quantized(v, _) => v.len() * std::mem::size_of::<QuantizedNode>(),
            Nodes::Unquantized(v) => v.len() * std::mem::size_of::<UnquantizedNode>(),
        };
        nodes + self.wide.bytes() + self.order.len() * 4 + std::mem::size_of::<Self>()
    }

    /// Exact bounds of all primitives.
    pub fn root_aabb(&self) -> Aabb {
        self.bounds
    }

    /// The same hierarchy in another layout.
    pub fn with_layout(&self, layout: BvhLayout) -> Bvh {
        let (aabbs, data) = self.node_boxes_and_data();
        let nodes = make_nodes(layout, &aabbs, &data, &self.bounds);
        Bvh {
            wide: wide_nodes(&nodes),
            nodes,
            order: self.order.clone(),
            bounds: self.bounds,
        }
    }

    /// Refits the boxes to new primitive boxes (same count, same topology), re-quantising
    /// against the new bounds. Query results afterwards equal those of a fresh build. The
    /// quantised layout collapses its 4-wide nodes again (the same as a fresh build's); the
    /// unquantised one keeps their topology and rewrites their boxes.
    pub fn refit(&mut self, boxes: &[Aabb]) -> Result<()> {
        self.refit_with(boxes, &mut Vec::new())
    }

    /// [`Bvh::refit`] with a caller's buffer for the node boxes it fits: no allocation once
    /// the buffer has held as many boxes as the tree has nodes (a tree refitted every step).
    pub fn refit_with(&mut self, boxes: &[Aabb], scratch: &mut Vec<Aabb>) -> Result<()> {
        check_boxes(boxes)?;
        if boxes.len() != self.order.len() {
            return Err(CaromError::invalid(
                "boxes.len()",
                boxes.len(),
                format!(
                    "refit needs the {} primitives of the build",
                    self.order.len()
                ),
            ));
        }
        // In place: the node boxes are fitted bottom-up from the node data (no node is
        // dequantised), re-quantised into the same node array, and the 4-wide nodes are
        // collapsed again into their own buffer. The same nodes as `make_nodes` and
        // `wide_nodes` over fresh arrays (`refit_in_place_is_a_fresh_fit` compares them).
        with_nodes!(self, ns => fit_node_boxes(&ns, &self.order, boxes, scratch));
        let aabbs = scratch.as_slice();
        self.bounds = aabbs[0];
        match &mut self.nodes {
            Nodes::Quantized(v, q) => {
                *q = Quantization::new(&self.bounds);
                for (n, a) in v.iter_mut().zip(aabbs) {
                    *n = quantized_node(q, a, n.data);
                }
                if let WideNodes::Quantized(w) = &mut self.wide {
                    collapse_into(v.as_slice(), w);
                }
            }
            Nodes::Unquantized(v) => {
                for (n, a) in v.iter_mut().zip(aabbs) {
                    *n = unquantized_node(a, n.data);
                }
                // The wide nodes keep their topology (see `refit_real`).
                if let WideNodes::Unquantized(w) = &mut self.wide {
                    refit_real(w, v);
                }
            }
        }
        Ok(())
    }

    /// The sum of the surface areas of every node's box (as stored: quantised boxes widened
    /// to the grid): the surface area heuristic's cost of the tree up to its leaf terms,
    /// which depend only on the topology. A tree [`Bvh::refit`] to moved boxes keeps its
    /// topology, and this sum tells how much worse its boxes have become than those of the
    /// build (MacDonald and Booth 1990; Wald, Boulos and Shirley 2007 rebuild a refitted
    /// tree when it grows too much). Zero for a tree of points.
    pub fn node_area(&self) -> Real {
        match &self.nodes {
            Nodes::Quantized(v, q) => v
                .iter()
                .map(|n| q.dequantize(n.min, n.max).surface_area())
                .sum(),
            Nodes::Unquantized(v) => v
                .iter()
                .map(|n| Aabb::new(Vec3::from(n.min), Vec3::from(n.max)).surface_area())
                .sum(),
        }
    }

    /// Checks this hierarchy against the primitive boxes it should bound (used when a mesh
    /// is deserialised): one primitive per box, `order` a permutation, finite bounds equal to
    /// the union of the boxes, the leaves covering `order` in depth-first sequence (each
    /// primitive in exactly one leaf), the quantisation the one of those bounds, and every node box
    /// exactly the box [`Bvh::new`] or [`Bvh::refit`] gives for its subtree. Errors name the
    /// first broken invariant.
    pub fn check_primitives(&self, boxes: &[Aabb]) -> Result<()> {
        let bad = |what: &str, value: String, reason: &str| {
            Err(CaromError::invalid(format!("bvh.{what}"), value, reason))
        };
        if boxes.len() != self.order.len() {
            return bad(
                "num_primitives",
                self.order.len().to_string(),
                &format!("must equal the {} primitives", boxes.len()),
            );
        }
        let mut seen = vec![false; boxes.len()];
        for &p in &self.order {
            match seen.get_mut(p as usize) {
                Some(s) if !*s => *s = true,
                _ => {
                    return bad(
                        "order",
                        p.to_string(),
                        "not a permutation of the primitives",
                    )
                }
            }
        }
        if !(self.bounds.is_valid() && self.bounds.min.is_finite() && self.bounds.max.is_finite()) {
            return bad("bounds", format!("{:?}", self.bounds), "must be finite");
        }
        let (_, data) = self.node_boxes_and_data();
        // Depth-first leaves cover `order` in sequence, each primitive exactly once.
        let mut next = 0;
        for (i, &d) in data.iter().enumerate() {
            if d & LEAF_FLAG != 0 {
                let (first, count) = leaf_range(d);
                if first != next {
                    return bad(
                        "leaf",
                        i.to_string(),
                        "leaf ranges must cover the primitives in order, once each",
                    );
                }
                next = first + count;
            }
        }
        if next != self.order.len() {
            return bad(
                "leaf",
                next.to_string(),
                "leaf ranges must cover the primitives in order, once each",
            );
        }
        // The structure is checked above, so the fit's indices are in bounds.
        let mut aabbs = Vec::new();
        with_nodes!(self, ns => fit_node_boxes(&ns, &self.order, boxes, &mut aabbs));
        if aabbs[0] != self.bounds {
            return bad(
                "bounds",
                format!("{:?}", self.bounds),
                "must be the union of the primitive boxes",
            );
        }
        if let Nodes::Quantized(_, q) = &self.nodes {
            if *q != Quantization::new(&self.bounds) {
                return bad(
                    "quantization",
                    format!("{q:?}"),
                    "inconsistent with the bounds",
                );
            }
        }
        let expected = make_nodes(self.layout(), &aabbs, &data, &self.bounds);
        if expected != self.nodes {
            return bad(
                "nodes",
                format!("{} nodes", data.len()),
                "a node box does not match its primitives",
            );
        }
        Ok(())
    }

    /// Conservative boxes and data of all nodes.
    pub(crate) fn node_boxes_and_data(&self) -> (Vec<Aabb>, Vec<u32>) {
        match &self.nodes {
            Nodes::Quantized(v, q) => (
                v.iter().map(|n| q.dequantize(n.min, n.max)).collect(),
                v.iter().map(|n| n.data).collect(),
            ),
            Nodes::Unquantized(v) => (
                v.iter()
                    .map(|n| Aabb::new(Vec3::from(n.min), Vec3::from(n.max)))
                    .collect(),
                v.iter().map(|n| n.data).collect(),
            ),
        }
    }
}

/// Right child of internal node `i`: the escape index of its left child `i + 1` (over a
/// plain data array; the library uses `traverse::right_child_of`, the refit's oracle this).
#[cfg(test)]
pub(crate) fn right_child(data: &[u32], i: usize) -> usize {
    let left = data[i + 1];
    if left & LEAF_FLAG != 0 {
        i + 2
    } else {
        left as usize
    }
}

/// The 4-wide nodes of either layout.
pub(crate) fn wide_nodes(nodes: &Nodes) -> WideNodes {
    match nodes {
        Nodes::Quantized(v, _) => WideNodes::Quantized(collapse(v.as_slice())),
        Nodes::Unquantized(v) => WideNodes::Unquantized(collapse(v.as_slice())),
    }
}

pub(crate) fn make_nodes(layout: BvhLayout, aabbs: &[Aabb], data: &[u32], bounds: &Aabb) -> Nodes {
    match layout {
        BvhLayout::Quantized => {
            let q = Quantization::new(bounds);
            let nodes = aabbs
                .iter()
                .zip(data)
                .map(|(a, &d)| quantized_node(&q, a, d))
                .collect();
            Nodes::Quantized(nodes, q)
        }
        BvhLayout::Unquantized => Nodes::Unquantized(
            aabbs
                .iter()
                .zip(data)
                .map(|(a, &d)| unquantized_node(a, d))
                .collect(),
        ),
    }
}

/// The quantised node of box `a` (rounded outwards) with `data`.
#[inline]
fn quantized_node(q: &Quantization, a: &Aabb, data: u32) -> QuantizedNode {
    QuantizedNode {
        min: q.quantize(a.min, false),
        max: q.quantize(a.max, true),
        data,
    }
}

/// The unquantised node of box `a` (padded by a few ulps) with `data`.
#[inline]
fn unquantized_node(a: &Aabb, data: u32) -> UnquantizedNode {
    let p = pad_ulps(a);
    UnquantizedNode {
        min: p.min.to_array(),
        max: p.max.to_array(),
        data,
    }
}

/// The exact box of every node of `ns` over the primitive `boxes` (leaves in `order`),
/// fitted bottom-up into `aabbs` (resized to the node count): a node's children follow it
/// in the depth-first layout.
fn fit_node_boxes(ns: &impl NodeSet, order: &[u32], boxes: &[Aabb], aabbs: &mut Vec<Aabb>) {
    aabbs.clear();
    aabbs.resize(ns.len(), Aabb::EMPTY);
    for i in (0..aabbs.len()).rev() {
        let d = ns.data(i);
        aabbs[i] = if d & LEAF_FLAG != 0 {
            let (first, count) = leaf_range(d);
            order[first..first + count]
                .iter()
                .fold(Aabb::EMPTY, |acc, &p| acc.merge(&boxes[p as usize]))
        } else {
            aabbs[i + 1].merge(&aabbs[right_child_of(ns, i)])
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn node_sizes() {
        assert_eq!(std::mem::size_of::<QuantizedNode>(), 16);
    }

    /// `node_area` against the node boxes as `node_boxes_and_data` decodes them, on both
    /// layouts: one box (the root is the leaf), 200 scattered boxes with internal nodes, and
    /// a tree of points (zero up to the quantisation's widening).
    #[test]
    fn node_area_sums_the_node_boxes() {
        let a = Aabb::new(Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0));
        let scattered: Vec<Aabb> = (0..200)
            .map(|i| {
                let c = Vec3::new((i * 7 % 23) as Real, (i * 5 % 11) as Real, (i % 13) as Real);
                Aabb::new(c, c + Vec3::new(0.5, 1.0 + (i % 3) as Real, 0.25))
            })
            .collect();
        let p = Aabb::new(Vec3::ONE, Vec3::ONE);
        for layout in [BvhLayout::Quantized, BvhLayout::Unquantized] {
            let one = Bvh::new(&[a], layout).unwrap();
            assert!((one.node_area() - 22.0).abs() <= 1e-3 * 22.0, "{layout:?}");
            let many = Bvh::new(&scattered, layout).unwrap();
            let (boxes, _) = many.node_boxes_and_data();
            assert!(boxes.len() > 3, "{layout:?}");
            let want: Real = boxes.iter().map(Aabb::surface_area).sum();
            assert_eq!(many.node_area(), want, "{layout:?}");
            assert!(want > many.bounds.surface_area(), "{layout:?}");
            // Zero, but for the quantisation's widening of a point by round-off.
            let points = Bvh::new(&[p, p, p], layout).unwrap().node_area();
            assert!((0.0..=1e-9).contains(&points), "{layout:?}: {points}");
        }
    }

    #[test]
    fn loading_checks_the_tree_structure() {
        let boxes: Vec<Aabb> = (0..50)
            .map(|i| Aabb::new(Vec3::splat(i as Real), Vec3::splat(i as Real + 1.5)))
            .collect();
        let bvh = Bvh::new(&boxes, BvhLayout::Quantized).unwrap();
        let back = Bvh::try_from(BvhData::from(bvh.clone())).unwrap();
        assert_eq!(back, bvh);
        let Nodes::Quantized(nodes, q) = &bvh.nodes else {
            unreachable!()
        };
        let n = nodes.len();
        let data: Vec<u32> = nodes.iter().map(|x| x.data).collect();
        // Every corruption of one node's data or of the order is caught or harmless.
        let mut caught = 0;
        for i in 0..n {
            for bad in [
                0u32,
                1,
                i as u32 + 1,
                n as u32 + 5,
                LEAF_FLAG | 60,
                u32::MAX,
            ] {
                let mut v = nodes.clone();
                v[i].data = bad;
                let d = BvhData {
                    nodes: Nodes::Quantized(v, *q),
                    order: bvh.order.clone(),
                    bounds: bvh.bounds,
                };
                match Bvh::try_from(d) {
                    Err(_) => caught += 1,
                    Ok(b) => {
                        // Accepted: a consistent tree, so the traversals run.
                        let mut count = 0;
                        b.for_each_candidate_in_aabb(&b.root_aabb(), |_| {
                            count += 1;
                            true
                        });
                        b.for_each_candidate_on_ray_ordered(Vec3::ZERO, Vec3::ONE, 1e3, |_, _| {
                            true
                        });
                        assert!(count <= 8 * n);
                    }
                }
            }
        }
        assert!(caught > n, "{caught} of {} corruptions caught", 6 * n);
        assert!(data.iter().any(|d| d & LEAF_FLAG == 0));
        let mut order = bvh.order.clone();
        order[3] = 50;
        let d = BvhData {
            nodes: bvh.nodes.clone(),
            order,
            bounds: bvh.bounds,
        };
        assert!(Bvh::try_from(d).is_err());
    }

    #[test]
    fn rejects_bad_boxes() {
        assert!(Bvh::new(&[], BvhLayout::Quantized).is_err());
        let bad = Aabb::new(Vec3::ZERO, Vec3::new(Real::NAN, 0.0, 0.0));
        let e = Bvh::new(&[bad], BvhLayout::Quantized).unwrap_err();
        assert!(e.to_string().contains("boxes[0]"));
        let mut bvh = Bvh::new(&[Aabb::new(Vec3::ZERO, Vec3::ONE)], BvhLayout::Quantized).unwrap();
        assert!(bvh.refit(&[]).is_err());
    }
}
