//! The dynamic AABB tree: invariants after every operation, and every query against a brute
//! force over the leaves' fat boxes.

mod broadphase_common;

use broadphase_common::{moved_box, random_box, Rng, Scene, SCENES};
use carom_collision::broadphase::{DynamicTree, HalfSpace, InsertStrategy, TreeProxy};
use carom_collision::bvh::WideTree;
use carom_collision::math::{Aabb, Real, Vec3};
use std::collections::BTreeSet;

const STRATEGIES: [InsertStrategy; 2] = [InsertStrategy::SurfaceArea, InsertStrategy::Manhattan];

/// Builds a tree with random inserts, moves and removes, validating after every operation.
fn churn(
    strategy: InsertStrategy,
    scene: Scene,
    seed: u64,
    n: usize,
) -> (DynamicTree, Vec<TreeProxy>) {
    let mut rng = Rng(seed);
    let mut tree = DynamicTree::new(strategy, 0.05);
    let mut leaves = Vec::new();
    for k in 0..n {
        leaves.push(
            tree.create_proxy(random_box(&mut rng, scene), k as u32)
                .unwrap(),
        );
        tree.validate().unwrap();
    }
    for round in 0..3 {
        for &l in &leaves {
            let fat = tree.fat_aabb_of(l).unwrap();
            let (nb, d) = moved_box(&mut rng, &fat, scene);
            tree.move_proxy(l, nb, d).unwrap();
            tree.validate().unwrap();
            assert!(
                tree.fat_aabb_of(l).unwrap().contains(&nb),
                "fat box holds the object"
            );
        }
        let mut k = round;
        while k < leaves.len() {
            let l = leaves.remove(k);
            tree.destroy_proxy(l).unwrap();
            tree.validate().unwrap();
            assert!(tree.destroy_proxy(l).is_err(), "stale handle rejected");
            k += 7;
        }
        tree.optimize_incremental(10);
        tree.validate().unwrap();
    }
    assert_eq!(tree.len(), leaves.len());
    (tree, leaves)
}

fn fat_boxes(tree: &DynamicTree, leaves: &[TreeProxy]) -> Vec<(TreeProxy, Aabb, u32)> {
    leaves
        .iter()
        .map(|&l| (l, tree.fat_aabb_of(l).unwrap(), tree.user_data(l).unwrap()))
        .collect()
}

#[test]
fn invariants_hold_after_every_operation() {
    for s in STRATEGIES {
        for (k, &scene) in SCENES.iter().enumerate() {
            churn(s, scene, 10 + k as u64, 150);
        }
    }
}

#[test]
fn move_inside_fat_box_does_nothing() {
    let mut tree = DynamicTree::new(InsertStrategy::SurfaceArea, 0.5);
    let b = Aabb::new(Vec3::ZERO, Vec3::ONE);
    let l = tree.create_proxy(b, 0).unwrap();
    let _ = tree
        .create_proxy(Aabb::new(Vec3::splat(3.0), Vec3::splat(4.0)), 1)
        .unwrap();
    let d = Vec3::splat(0.2);
    assert!(!tree
        .move_proxy(l, Aabb::new(b.min + d, b.max + d), Vec3::ZERO)
        .unwrap());
    let far = Vec3::new(2.0, 0.0, 0.0);
    assert!(tree
        .move_proxy(l, Aabb::new(b.min + far, b.max + far), far)
        .unwrap());
    let fat = tree.fat_aabb_of(l).unwrap();
    // Swept by the predicted displacement (times the motion scale 2) and the margin.
    assert!(fat.max.x >= b.max.x + far.x + 2.0 * far.x + 0.5 - 1e-4);
    tree.validate().unwrap();
}

#[test]
fn aabb_query_matches_brute_force() {
    for s in STRATEGIES {
        let (tree, leaves) = churn(s, Scene::Uniform, 21, 200);
        let all = fat_boxes(&tree, &leaves);
        let mut rng = Rng(5);
        let mut hits_total = 0;
        for _ in 0..50 {
            let q = random_box(&mut rng, Scene::Uniform);
            let mut got = BTreeSet::new();
            tree.query_aabb(&q, |l, u| {
                assert_eq!(tree.user_data(l).unwrap(), u);
                assert!(got.insert(l));
                true
            });
            let expect: BTreeSet<_> = all
                .iter()
                .filter(|e| e.1.intersects(&q))
                .map(|e| e.0)
                .collect();
            assert_eq!(got, expect);
            hits_total += got.len();
        }
        assert!(hits_total > 50);
    }
}

#[test]
fn ray_cast_matches_brute_force_and_clips() {
    for s in STRATEGIES {
        let (tree, leaves) = churn(s, Scene::Uniform, 22, 200);
        let all = fat_boxes(&tree, &leaves);
        let mut rng = Rng(6);
        let mut hit_rays = 0;
        for _ in 0..100 {
            let o = rng.vec(-15.0, 15.0);
            let dir = rng.vec(-1.0, 1.0);
            let max_t: Real = 3.0;
            // All hits: the callback keeps the fraction.
            let mut got = BTreeSet::new();
            tree.ray_cast(o, dir, max_t, |l, _, t| {
                assert!((0.0..=max_t).contains(&t));
                got.insert(l);
                max_t
            });
            let expect: BTreeSet<_> = all
                .iter()
                .filter(|e| e.1.ray_intersection(o, dir, max_t).is_some())
                .map(|e| e.0)
                .collect();
            assert_eq!(got, expect);
            // Closest hit with clipping equals the brute-force minimum.
            let mut best: Option<Real> = None;
            tree.ray_cast(o, dir, max_t, |_, _, t| {
                best = Some(best.map_or(t, |b: Real| b.min(t)));
                t
            });
            let expect_best = all
                .iter()
                .filter_map(|e| e.1.ray_intersection(o, dir, max_t))
                .fold(None, |m: Option<Real>, t| Some(m.map_or(t, |m| m.min(t))));
            assert_eq!(best, expect_best);
            hit_rays += usize::from(best.is_some());
            // Returning 0 stops at the first hit.
            let mut count = 0;
            tree.ray_cast(o, dir, max_t, |_, _, _| {
                count += 1;
                0.0
            });
            assert!(count <= 1);
        }
        assert!((15..=95).contains(&hit_rays), "hit rate guard: {hit_rays}");
    }
}

#[test]
fn plane_query_matches_brute_force() {
    let (tree, leaves) = churn(InsertStrategy::SurfaceArea, Scene::Uniform, 23, 200);
    let all = fat_boxes(&tree, &leaves);
    let mut rng = Rng(7);
    for _ in 0..30 {
        let planes: Vec<HalfSpace> = (0..5)
            .map(|_| HalfSpace {
                normal: rng.vec(-1.0, 1.0),
                offset: rng.range(-2.0, 8.0),
            })
            .collect();
        let mut got = BTreeSet::new();
        tree.query_planes(&planes, |l, _| {
            got.insert(l);
        });
        // A box is culled when all its corners are outside one plane.
        let expect: BTreeSet<_> = all
            .iter()
            .filter(|e| {
                planes.iter().all(|p| {
                    (0..8).any(|i| {
                        let c = Vec3::new(
                            if i & 1 == 0 { e.1.min.x } else { e.1.max.x },
                            if i & 2 == 0 { e.1.min.y } else { e.1.max.y },
                            if i & 4 == 0 { e.1.min.z } else { e.1.max.z },
                        );
                        p.normal.dot(c) <= p.offset
                    })
                })
            })
            .map(|e| e.0)
            .collect();
        assert_eq!(got, expect);
    }
}

/// The leaves (user data) of the 4-wide copy's box query, sorted, with no duplicate.
fn wide_hits(wide: &WideTree, q: &Aabb, stack: &mut Vec<u32>) -> Vec<u32> {
    let mut got = Vec::new();
    wide.overlapping_leaves(q, stack, |u| got.push(u));
    let n = got.len();
    got.sort_unstable();
    got.dedup();
    assert_eq!(got.len(), n, "a leaf reported twice");
    got
}

#[test]
fn wide_tree_query_matches_brute_force() {
    // Random boxes, every leaf's own fat box, zero-size boxes at fat-box corners and boxes
    // touching a fat box's face only, on uniform, mixed-size, far (1e5) and lattice
    // (zero extents, touching faces) trees, against the brute force over the fat boxes.
    let mut stack = Vec::new();
    let mut wide = WideTree::new();
    for s in STRATEGIES {
        for (k, &scene) in SCENES.iter().enumerate() {
            let (tree, leaves) = churn(s, scene, 40 + k as u64, 160);
            let all = fat_boxes(&tree, &leaves);
            wide.rebuild(&tree);
            assert!(wide.node_count() <= tree.len());
            let mut rng = Rng(77 + k as u64);
            let mut queries: Vec<Aabb> = (0..40).map(|_| random_box(&mut rng, scene)).collect();
            for e in &all {
                let b = e.1;
                queries.push(b);
                queries.push(Aabb::new(b.max, b.max));
                queries.push(Aabb::new(b.min, b.min));
                let w = b.max.x - b.min.x;
                let face = Vec3::new(b.max.x, b.min.y, b.min.z);
                queries.push(Aabb::new(face, face + Vec3::new(w + 1.0, 0.0, 0.0)));
            }
            let mut hits = 0;
            for q in &queries {
                let expect: Vec<u32> = {
                    let mut v: Vec<u32> = all
                        .iter()
                        .filter(|e| e.1.intersects(q))
                        .map(|e| e.2)
                        .collect();
                    v.sort_unstable();
                    v
                };
                assert_eq!(wide_hits(&wide, q, &mut stack), expect, "{scene:?} {q:?}");
                hits += expect.len();
            }
            assert!(hits > queries.len(), "{scene:?}: {hits} hits");
        }
    }
    // An empty tree and a single leaf.
    let mut tree = DynamicTree::new(InsertStrategy::SurfaceArea, 0.0);
    wide.rebuild(&tree);
    let unit = Aabb::new(Vec3::ZERO, Vec3::ONE);
    assert!(wide_hits(&wide, &unit, &mut stack).is_empty());
    let l = tree.create_proxy(unit, 9).unwrap();
    wide.rebuild(&tree);
    assert_eq!(wide_hits(&wide, &unit, &mut stack), vec![9]);
    let touching = Aabb::new(Vec3::ONE, Vec3::splat(2.0));
    assert_eq!(wide_hits(&wide, &touching, &mut stack), vec![9]);
    let apart = Aabb::new(Vec3::splat(1.5), Vec3::splat(2.0));
    assert!(wide_hits(&wide, &apart, &mut stack).is_empty());
    tree.destroy_proxy(l).unwrap();
    wide.rebuild(&tree);
    assert!(wide_hits(&wide, &unit, &mut stack).is_empty());
}

#[test]
fn tree_vs_tree_and_self_pairs_match_brute_force() {
    for s in STRATEGIES {
        let (a, la) = churn(s, Scene::Degenerate, 24, 120);
        let (b, lb) = churn(s, Scene::Degenerate, 25, 90);
        let fa = fat_boxes(&a, &la);
        let fb = fat_boxes(&b, &lb);
        let mut got = Vec::new();
        a.query_tree(&b, |x, y| got.push((x, y)));
        got.sort_unstable();
        let mut expect = Vec::new();
        for x in &fa {
            for y in &fb {
                if x.1.intersects(&y.1) {
                    expect.push((x.2, y.2));
                }
            }
        }
        expect.sort_unstable();
        assert_eq!(got, expect);
        assert!(!expect.is_empty());

        let mut selfp = Vec::new();
        a.self_pairs(|x, y| selfp.push((x.min(y), x.max(y))));
        selfp.sort_unstable();
        let mut expect = Vec::new();
        for (i, x) in fa.iter().enumerate() {
            for y in &fa[i + 1..] {
                if x.1.intersects(&y.1) {
                    expect.push((x.2.min(y.2), x.2.max(y.2)));
                }
            }
        }
        expect.sort_unstable();
        assert_eq!(selfp, expect, "each pair exactly once");
    }
}

#[test]
fn bad_input_is_an_error() {
    let mut tree = DynamicTree::default();
    let nan = Aabb::new(Vec3::new(Real::NAN, 0.0, 0.0), Vec3::ONE);
    assert!(tree.create_proxy(nan, 0).is_err());
    let inverted = Aabb::new(Vec3::ONE, Vec3::ZERO);
    assert!(tree.create_proxy(inverted, 0).is_err());
    let l = tree
        .create_proxy(Aabb::new(Vec3::ZERO, Vec3::ONE), 0)
        .unwrap();
    assert!(tree.move_proxy(l, inverted, Vec3::ZERO).is_err());
    let stale = TreeProxy {
        index: l.index,
        generation: l.generation + 1,
    };
    assert!(tree
        .move_proxy(stale, Aabb::new(Vec3::ZERO, Vec3::ONE), Vec3::ZERO)
        .is_err());
    assert!(tree
        .destroy_proxy(TreeProxy {
            index: 99,
            generation: 0
        })
        .is_err());
    tree.destroy_proxy(l).unwrap();
    assert!(tree.fat_aabb_of(l).is_err());
    tree.validate().unwrap();
    assert!(tree.is_empty());
}

#[test]
fn sah_tree_is_not_worse_than_manhattan_on_clustered_boxes() {
    // Measured property behind the default: SAH insertion with rotations gives a lower
    // area ratio (cheaper queries) than the Manhattan descent on the same inserts.
    let mut rng = Rng(77);
    let boxes: Vec<Aabb> = (0..2000)
        .map(|_| random_box(&mut rng, Scene::Uniform))
        .collect();
    let ratio = |s| {
        let mut t = DynamicTree::new(s, 0.0);
        for (k, b) in boxes.iter().enumerate() {
            t.create_proxy(*b, k as u32).unwrap();
        }
        t.validate().unwrap();
        t.area_ratio()
    };
    let (sah, man) = (
        ratio(InsertStrategy::SurfaceArea),
        ratio(InsertStrategy::Manhattan),
    );
    assert!(sah < man, "SAH {sah} vs Manhattan {man}");
}

#[test]
fn two_tree_invariants_hold_after_every_operation() {
    // Both trees of the two-tree broadphase stay valid through creates, moves, removes,
    // sleeping/waking migrations and static proxies, and their leaves partition the live
    // proxies: resting or static ones in tree 1, moving ones in tree 0.
    use carom_collision::broadphase::{BroadPhase, Filter, ProxyHandle, TreeBroadPhase};
    for s in STRATEGIES {
        for (k, &scene) in SCENES.iter().enumerate() {
            let mut rng = Rng(900 + k as u64);
            let mut bp = TreeBroadPhase::new(s, 0.05);
            let check = |bp: &TreeBroadPhase, live: &[ProxyHandle]| {
                bp.tree(0).validate().unwrap();
                bp.tree(1).validate().unwrap();
                let resting = live.iter().filter(|&&h| bp.is_resting(h).unwrap()).count();
                assert_eq!(bp.tree(1).len(), resting);
                assert_eq!(bp.tree(0).len(), live.len() - resting);
            };
            let mut live = Vec::new();
            for _ in 0..60 {
                let f = Filter::new(rng.below(6) == 0);
                live.push(bp.create_proxy(random_box(&mut rng, scene), f).unwrap());
                check(&bp, &live);
            }
            for _frame in 0..4 {
                for i in 0..live.len() {
                    let h = live[i];
                    match rng.below(10) {
                        0..=5 => {
                            let (nb, d) = moved_box(&mut rng, &bp.aabb(h).unwrap(), scene);
                            bp.update_proxy(h, nb, d).unwrap();
                        }
                        6 | 7 => bp.set_resting(h, rng.below(2) == 0).unwrap(),
                        _ => {}
                    }
                    check(&bp, &live);
                }
                let gone = live.remove(rng.below(live.len()));
                bp.remove_proxy(gone).unwrap();
                check(&bp, &live);
                bp.update_pairs();
                check(&bp, &live);
            }
        }
    }
}

#[test]
fn refit_proxy_keeps_the_tree_valid_tight_and_queries_exact() {
    // Moves by refitting (the moving tree of the two-tree broadphase): the leaf keeps its
    // place, its fat box holds the object, the ancestors stay tight (the root box is the
    // union of the leaves' fat boxes) and box queries equal a brute force over fat boxes.
    for s in STRATEGIES {
        for (k, &scene) in SCENES.iter().enumerate() {
            let mut rng = Rng(700 + k as u64);
            let mut tree = DynamicTree::new(s, 0.05);
            let leaves: Vec<TreeProxy> = (0..120)
                .map(|u| tree.create_proxy(random_box(&mut rng, scene), u).unwrap())
                .collect();
            let mut refitted = 0;
            for _round in 0..5 {
                for &l in &leaves {
                    let fat = tree.fat_aabb_of(l).unwrap();
                    let (nb, d) = moved_box(&mut rng, &fat, scene);
                    refitted += tree.refit_proxy(l, nb, d).unwrap() as usize;
                    assert!(tree.fat_aabb_of(l).unwrap().contains(&nb));
                }
                tree.validate().unwrap();
                let all = fat_boxes(&tree, &leaves);
                let union = all.iter().fold(Aabb::EMPTY, |u, e| u.merge(&e.1));
                assert_eq!(tree.root_aabb(), Some(union), "root box is tight");
                for _ in 0..10 {
                    let q = random_box(&mut rng, scene);
                    let mut got = BTreeSet::new();
                    tree.query_aabb(&q, |l, _| got.insert(l));
                    let expect: BTreeSet<_> = all
                        .iter()
                        .filter(|e| e.1.intersects(&q))
                        .map(|e| e.0)
                        .collect();
                    assert_eq!(got, expect);
                }
            }
            assert!(refitted > 100, "moves left the fat boxes: {refitted}");
            let stale = leaves[0];
            tree.destroy_proxy(stale).unwrap();
            assert!(tree
                .refit_proxy(stale, random_box(&mut rng, scene), Vec3::ZERO)
                .is_err());
            let bad = Aabb::new(Vec3::ONE, Vec3::ZERO);
            assert!(tree.refit_proxy(leaves[1], bad, Vec3::ZERO).is_err());
        }
    }
}

#[test]
fn refitting_and_reinserting_two_tree_broadphases_report_the_brute_force_pairs() {
    // The two-tree broadphase with moving proxies refitted (the default) or re-inserted, and
    // with the pre-tuning margin and motion scale, reports exactly the brute force's pair
    // changes over frames of motion, sleep/wake, filter changes and removals.
    use carom_collision::broadphase::{BroadPhase, BruteForce, Filter, TreeBroadPhase};
    for (k, &scene) in SCENES.iter().enumerate() {
        let mut rng = Rng(1300 + k as u64);
        let mut variants: Vec<TreeBroadPhase> = Vec::new();
        // The last two take the moved proxies' queries on the 4-wide copy of the moving
        // tree whenever keys were found before (0) or never (infinity).
        for (refit, margin, scale, wide) in [
            (true, 0.05, 4.0, 1.0),
            (false, 0.05, 4.0, 1.0),
            (true, 0.1, 2.0, 1.0),
            (true, 0.05, 4.0, 0.0),
            (true, 0.05, 4.0, Real::INFINITY),
        ] {
            let mut t = TreeBroadPhase::new(InsertStrategy::SurfaceArea, margin);
            t.refit_moving = refit;
            t.set_motion_scale(scale);
            t.wide_query_keys = wide;
            variants.push(t);
        }
        let mut oracle = BruteForce::new();
        let mut live = Vec::new();
        for _ in 0..80 {
            let (b, f) = (random_box(&mut rng, scene), Filter::new(rng.below(8) == 0));
            let h = oracle.create_proxy(b, f).unwrap();
            for v in &mut variants {
                assert_eq!(v.create_proxy(b, f).unwrap(), h);
            }
            live.push(h);
        }
        let mut total = 0;
        for _frame in 0..12 {
            for &h in &live {
                match rng.below(10) {
                    0..=6 => {
                        let (nb, d) = moved_box(&mut rng, &oracle.aabb(h).unwrap(), scene);
                        oracle.update_proxy(h, nb, d).unwrap();
                        for v in &mut variants {
                            v.update_proxy(h, nb, d).unwrap();
                        }
                    }
                    7 => {
                        let r = rng.below(2) == 0;
                        for v in &mut variants {
                            v.set_resting(h, r).unwrap();
                        }
                    }
                    8 => {
                        let f = Filter::new(rng.below(5) == 0);
                        oracle.set_filter(h, f).unwrap();
                        for v in &mut variants {
                            v.set_filter(h, f).unwrap();
                        }
                    }
                    _ => {}
                }
            }
            if live.len() > 40 {
                let gone = live.remove(rng.below(live.len()));
                oracle.remove_proxy(gone).unwrap();
                for v in &mut variants {
                    v.remove_proxy(gone).unwrap();
                }
            }
            let expect = oracle.update_pairs().clone();
            total += expect.added.len() + expect.removed.len();
            for v in &mut variants {
                assert_eq!(v.update_pairs(), &expect);
                assert_eq!(v.pairs(), oracle.pairs());
            }
        }
        assert!(total >= 10, "pairs changed: {total}");
    }
}

#[test]
fn quiet_updates_report_the_brute_force_pairs() {
    // An update after which nothing changed returns the last pairs without a pass over the
    // candidates (a sleeping world); one change that marks no proxy moved must still be seen:
    // a box shrunk inside its fat box, a filter's mask, a resting hint, a user filter.
    use carom_collision::broadphase::{BroadPhase, BruteForce, Filter, TreeBroadPhase};
    use std::sync::Arc;
    // Two touching boxes; one pulled back by 1 % of its size (inside its fat box): the pair
    // ends although no proxy moved in the tree.
    let mut tree = TreeBroadPhase::new(InsertStrategy::SurfaceArea, 0.05);
    let a = tree
        .create_proxy(Aabb::new(Vec3::ZERO, Vec3::ONE), Filter::new(false))
        .unwrap();
    let b = Aabb::new(Vec3::new(1.0, 0.0, 0.0), Vec3::new(2.0, 1.0, 1.0));
    tree.create_proxy(b, Filter::new(false)).unwrap();
    assert_eq!(tree.update_pairs().added.len(), 1);
    assert_eq!(tree.update_pairs().kept, 1);
    let back = Aabb::new(Vec3::ZERO, Vec3::new(0.99, 1.0, 1.0));
    tree.update_proxy(a, back, Vec3::ZERO).unwrap();
    assert_eq!(tree.update_pairs().removed.len(), 1);
    assert!(tree.pairs().is_empty());
    for (k, &scene) in SCENES.iter().enumerate() {
        let mut rng = Rng(1700 + k as u64);
        let mut tree = TreeBroadPhase::new(InsertStrategy::SurfaceArea, 0.05);
        let mut oracle = BruteForce::new();
        let mut live = Vec::new();
        for _ in 0..60 {
            let (b, f) = (random_box(&mut rng, scene), Filter::new(rng.below(8) == 0));
            let h = oracle.create_proxy(b, f).unwrap();
            assert_eq!(tree.create_proxy(b, f).unwrap(), h);
            live.push(h);
        }
        let mut quiet = 0;
        for frame in 0..60 {
            let h = live[rng.below(live.len())];
            match frame % 6 {
                0 => {}
                1 => {
                    // A proxy with a pair shrunk to a point at a corner: inside its fat box,
                    // so not moved, but its pairs change.
                    let h = oracle.pairs().first().map_or(h, |p| p.0);
                    let b = oracle.aabb(h).unwrap();
                    let nb = Aabb::new(b.min, b.min);
                    oracle.update_proxy(h, nb, Vec3::ZERO).unwrap();
                    tree.update_proxy(h, nb, Vec3::ZERO).unwrap();
                }
                2 => {
                    let mut f = Filter::new(false);
                    f.mask = if frame % 4 == 0 { 0 } else { u32::MAX };
                    oracle.set_filter(h, f).unwrap();
                    tree.set_filter(h, f).unwrap();
                }
                3 => tree.set_resting(h, frame % 4 == 1).unwrap(),
                4 => {
                    // A user filter rejecting pairs of even slots, then none.
                    let uf: Option<carom_collision::broadphase::UserFilter> = (frame % 12 == 4)
                        .then(|| {
                            Arc::new(|a: _, b: _| {
                                let (a, b): (
                                    carom_collision::broadphase::ProxyHandle,
                                    carom_collision::broadphase::ProxyHandle,
                                ) = (a, b);
                                (a.index + b.index) % 2 == 1
                            }) as _
                        });
                    oracle.set_user_filter(uf.clone());
                    tree.set_user_filter(uf);
                }
                _ => {
                    let (nb, d) = moved_box(&mut rng, &oracle.aabb(h).unwrap(), scene);
                    oracle.update_proxy(h, nb, d).unwrap();
                    tree.update_proxy(h, nb, d).unwrap();
                }
            }
            for _ in 0..2 {
                let expect = oracle.update_pairs().clone();
                quiet += usize::from(expect.added.is_empty() && expect.removed.is_empty());
                assert_eq!(tree.update_pairs(), &expect, "frame {frame}");
                assert_eq!(tree.pairs(), oracle.pairs(), "frame {frame}");
            }
        }
        assert!(quiet >= 60, "{quiet} quiet updates");
    }
}

#[test]
fn quiet_updates_leave_the_trees_alone_and_moves_resume_their_optimisation() {
    // An update after which nothing changed neither queries nor re-optimises the trees
    // (nothing degraded them; an idle world's step paid for re-inserting four leaves per
    // tree before): the trees stay node for node as they were. The first update after a
    // move re-inserts leaves again, and the pairs stay the brute-force ones throughout.
    use carom_collision::broadphase::{BroadPhase, BruteForce, Filter, TreeBroadPhase};
    let scene = SCENES[0];
    let mut rng = Rng(4242);
    let mut tree = TreeBroadPhase::new(InsertStrategy::SurfaceArea, 0.05);
    let mut oracle = BruteForce::new();
    let mut live = Vec::new();
    for _ in 0..200 {
        let b = random_box(&mut rng, scene);
        let h = oracle.create_proxy(b, Filter::new(false)).unwrap();
        tree.create_proxy(b, Filter::new(false)).unwrap();
        live.push(h);
    }
    let snapshot = |t: &TreeBroadPhase| format!("{:?} {:?}", t.tree(0), t.tree(1));
    for round in 0..3 {
        for _ in 0..10 {
            let h = live[rng.below(live.len())];
            let (nb, d) = moved_box(&mut rng, &oracle.aabb(h).unwrap(), scene);
            oracle.update_proxy(h, nb, d).unwrap();
            tree.update_proxy(h, nb, d).unwrap();
        }
        let before = snapshot(&tree);
        assert_eq!(tree.update_pairs(), oracle.update_pairs(), "round {round}");
        assert_ne!(
            snapshot(&tree),
            before,
            "round {round}: the move re-optimised nothing"
        );
        let settled = snapshot(&tree);
        for quiet in 0..20 {
            assert_eq!(tree.update_pairs(), oracle.update_pairs(), "quiet {quiet}");
            assert_eq!(
                snapshot(&tree),
                settled,
                "quiet update {quiet} changed a tree"
            );
        }
        assert_eq!(tree.pairs(), oracle.pairs());
        tree.tree(0).validate().unwrap();
        tree.tree(1).validate().unwrap();
    }
}
