//! `Bvh::refit` in place against the refit it replaced (every node box fitted into a new
//! array from decoded node data, then fresh quantised and 4-wide arrays), bit for bit; the
//! unquantised layout's wide nodes keep their lanes, with their boxes read again.

use super::static_bvh::{leaf_range, make_nodes, right_child, wide_nodes, Nodes, LEAF_FLAG};
use super::wide::WideNodes;
use super::{Bvh, BvhLayout};
use crate::math::{Aabb, Real, Vec3};

/// The previous `Bvh::refit`: the oracle.
fn fresh_fit(bvh: &Bvh, boxes: &[Aabb]) -> Bvh {
    let (_, data) = bvh.node_boxes_and_data();
    let mut aabbs = vec![Aabb::EMPTY; data.len()];
    for i in (0..data.len()).rev() {
        aabbs[i] = if data[i] & LEAF_FLAG != 0 {
            let (first, count) = leaf_range(data[i]);
            bvh.order[first..first + count]
                .iter()
                .fold(Aabb::EMPTY, |acc, &p| acc.merge(&boxes[p as usize]))
        } else {
            aabbs[i + 1].merge(&aabbs[right_child(&data, i)])
        };
    }
    let mut out = bvh.clone();
    out.bounds = aabbs[0];
    out.nodes = make_nodes(bvh.layout(), &aabbs, &data, &out.bounds);
    match (&out.nodes, &mut out.wide) {
        // The unquantised wide nodes keep their lanes: each lane's box is the new box of the
        // binary node it names.
        (Nodes::Unquantized(v), WideNodes::Unquantized(w)) => {
            for node in w.iter_mut() {
                for lane in 0..4 {
                    let src = node.sources[lane];
                    if src != u32::MAX {
                        for a in 0..3 {
                            node.planes[a][lane] = v[src as usize].min[a];
                            node.planes[3 + a][lane] = v[src as usize].max[a];
                        }
                    }
                }
            }
        }
        _ => out.wide = wide_nodes(&out.nodes),
    }
    out
}

fn boxes(n: usize, seed: u64, scale: Real, at: Vec3) -> Vec<Aabb> {
    let mut s = seed | 1;
    let mut unit = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as Real / (1u64 << 53) as Real
    };
    (0..n)
        .map(|_| {
            let c = at + Vec3::new(unit(), unit(), unit()) * scale;
            let h = Vec3::new(unit(), unit(), unit()) * (0.05 * scale);
            Aabb::new(c - h, c + h)
        })
        .collect()
}

/// Scattered boxes moved to other scattered boxes, to far from the origin, to one point
/// (all boxes equal) and from one box to a moved one; both layouts, leaves of 1 and 8, and
/// two refits in a row (the second reuses the buffers of the first).
#[test]
fn refit_in_place_is_a_fresh_fit() {
    let far = Vec3::new(1.0e4, -2.0e4, 3.0e3);
    let point = vec![Aabb::new(Vec3::splat(2.0), Vec3::splat(2.0)); 300];
    let cases = [
        (
            boxes(300, 1, 10.0, Vec3::ZERO),
            boxes(300, 2, 10.0, Vec3::ZERO),
        ),
        (boxes(300, 3, 10.0, Vec3::ZERO), boxes(300, 4, 50.0, far)),
        (boxes(300, 5, 1.0, Vec3::ZERO), point.clone()),
        (point, boxes(300, 6, 0.01, far)),
        (boxes(1, 7, 1.0, Vec3::ZERO), boxes(1, 8, 1.0, far)),
    ];
    for (first, second) in &cases {
        for layout in [BvhLayout::Quantized, BvhLayout::Unquantized] {
            for leaf in [1, 8] {
                let mut bvh = Bvh::with_max_leaf_size(first, layout, leaf).unwrap();
                for next in [second, first] {
                    let want = fresh_fit(&bvh, next);
                    // `refit_with` and a buffer left dirty by another tree: the same tree.
                    let mut other = bvh.clone();
                    let mut scratch = vec![Aabb::new(Vec3::ZERO, Vec3::ONE); 7];
                    other.refit_with(next, &mut scratch).unwrap();
                    bvh.refit(next).unwrap();
                    assert!(bvh == want, "{layout:?}, leaves of {leaf}");
                    assert!(other == want && other.wide == want.wide, "refit_with");
                    assert!(bvh.wide == want.wide, "{layout:?}, leaves of {leaf}");
                    // A saved and loaded copy collapses afresh: equal as a hierarchy.
                    let bytes = postcard::to_allocvec(&bvh).unwrap();
                    let back: Bvh = postcard::from_bytes(&bytes).unwrap();
                    assert!(back == bvh, "{layout:?}, leaves of {leaf}: reloaded");
                    // Whatever the wide topology, the tree bounds every box it holds.
                    assert!(bvh.check_primitives(next).is_ok());
                    for (i, b) in next.iter().enumerate() {
                        let mut seen = false;
                        let d = b.max - b.min + Vec3::splat(1.0);
                        bvh.for_each_candidate_on_ray_ordered(b.min - d, d, 1.0e9, |p, _| {
                            seen |= p as usize == i;
                            true
                        });
                        assert!(seen, "{layout:?}, leaves of {leaf}: box {i} lost");
                    }
                }
            }
        }
    }
}
