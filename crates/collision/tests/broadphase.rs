//! Every broadphase against the brute-force oracle over many frames of motion, inserts,
//! removes, sleeping and filter changes, on uniform, mixed-size, far-away and degenerate
//! scenes; and the brute force itself against a naive check written here.

mod broadphase_common;

use broadphase_common::{moved_box, random_box, Rng, Scene, SCENES};
use carom_collision::broadphase::{AnyBroadPhase, BroadPhase, Filter, Method, ProxyHandle};
use carom_collision::math::Aabb;
use std::collections::{BTreeMap, BTreeSet};

type Pairs = Vec<(ProxyHandle, ProxyHandle)>;

/// Applies the same random operation sequence to all broadphases and checks after each
/// update that all report the brute-force pair set and the same changes.
fn run(scene: Scene, seed: u64, n: usize, frames: usize) {
    let methods: Vec<Method> = Method::ALL.to_vec();
    let mut bps: Vec<AnyBroadPhase> = methods.iter().map(|&m| AnyBroadPhase::new(m)).collect();
    let mut rng = Rng(seed);
    let mut live: BTreeMap<ProxyHandle, (Aabb, Filter)> = BTreeMap::new();
    let mut total_pairs = 0usize;
    let mut total_changes = 0usize;
    let create = |bps: &mut Vec<AnyBroadPhase>, b: Aabb, f: Filter| {
        let hs: Vec<ProxyHandle> = bps
            .iter_mut()
            .map(|bp| bp.create_proxy(b, f).unwrap())
            .collect();
        assert!(
            hs.windows(2).all(|w| w[0] == w[1]),
            "same handle from every method"
        );
        hs[0]
    };
    for _ in 0..n {
        let b = random_box(&mut rng, scene);
        let f = Filter::new(rng.below(8) == 0);
        live.insert(create(&mut bps, b, f), (b, f));
    }
    for frame in 0..frames {
        if frame > 0 {
            let handles: Vec<ProxyHandle> = live.keys().copied().collect();
            for &h in &handles {
                let r = rng.below(100);
                let (b, f) = live[&h];
                if r < 40 && !f.is_static {
                    let (nb, d) = moved_box(&mut rng, &b, scene);
                    for bp in &mut bps {
                        bp.update_proxy(h, nb, d).unwrap();
                    }
                    live.insert(h, (nb, f));
                } else if r < 44 {
                    for bp in &mut bps {
                        bp.remove_proxy(h).unwrap();
                    }
                    live.remove(&h);
                } else if r < 47 {
                    let rest = rng.below(2) == 0;
                    for bp in &mut bps {
                        bp.set_resting(h, rest).unwrap();
                    }
                } else if r < 48 {
                    let nf = Filter {
                        group: 1 << rng.below(3),
                        mask: if rng.below(2) == 0 { u32::MAX } else { 0b101 },
                        is_static: rng.below(4) == 0,
                    };
                    for bp in &mut bps {
                        bp.set_filter(h, nf).unwrap();
                    }
                    live.insert(h, (b, nf));
                }
            }
            for _ in 0..rng.below(n / 10 + 2) {
                let b = random_box(&mut rng, scene);
                let f = Filter::new(rng.below(8) == 0);
                live.insert(create(&mut bps, b, f), (b, f));
            }
        }
        let changes: Vec<_> = bps.iter_mut().map(|bp| bp.update_pairs().clone()).collect();
        let pairs: Vec<Pairs> = bps.iter().map(|bp| bp.pairs()).collect();
        // Naive oracle for the brute force itself.
        let items: Vec<_> = live.iter().collect();
        let mut naive = BTreeSet::new();
        for (i, (ha, (ba, fa))) in items.iter().enumerate() {
            for (hb, (bb, fb)) in &items[i + 1..] {
                if ba.intersects(bb) && fa.can_pair(fb) {
                    naive.insert((**ha.min(hb), **ha.max(hb)));
                }
            }
        }
        let naive: Pairs = naive.into_iter().collect();
        let brute = methods
            .iter()
            .position(|&m| m == Method::BruteForce)
            .unwrap();
        assert_eq!(
            pairs[brute], naive,
            "brute force vs naive, {scene:?} frame {frame}"
        );
        for (k, m) in methods.iter().enumerate() {
            assert_eq!(pairs[k], naive, "{m:?} {scene:?} seed {seed} frame {frame}");
            assert_eq!(
                changes[k], changes[brute],
                "{m:?} changes, {scene:?} frame {frame}"
            );
            assert_eq!(bps[k].pair_count(), naive.len());
            assert_eq!(bps[k].len(), live.len());
        }
        total_pairs += naive.len();
        total_changes += changes[brute].added.len() + changes[brute].removed.len();
    }
    // Guard: the scenes must actually exercise pairs and pair changes.
    assert!(
        total_pairs > frames,
        "{scene:?}: too few pairs ({total_pairs})"
    );
    assert!(
        total_changes > frames,
        "{scene:?}: too few changes ({total_changes})"
    );
}

#[test]
fn all_methods_match_brute_force_uniform() {
    run(Scene::Uniform, 1, 250, 25);
}

#[test]
fn all_methods_match_brute_force_mixed_sizes() {
    run(Scene::Mixed, 2, 250, 25);
}

#[test]
fn all_methods_match_brute_force_far_from_origin() {
    run(Scene::Far, 3, 250, 25);
}

#[test]
fn all_methods_match_brute_force_degenerate_and_touching() {
    run(Scene::Degenerate, 4, 120, 25);
}

#[test]
fn all_methods_match_brute_force_more_seeds() {
    for (k, &scene) in SCENES.iter().enumerate() {
        run(scene, 100 + k as u64, 60, 10);
    }
}

#[test]
fn changes_decompose_pairs() {
    // added ∪ kept = current, removed ∩ current = ∅, in sorted order.
    let mut bp = AnyBroadPhase::new(Method::Tree);
    let mut rng = Rng(9);
    let mut hs = Vec::new();
    for _ in 0..100 {
        hs.push(
            bp.create_proxy(random_box(&mut rng, Scene::Uniform), Filter::default())
                .unwrap(),
        );
    }
    let mut prev: BTreeSet<_> = BTreeSet::new();
    for _ in 0..10 {
        for &h in &hs {
            let b = bp.aabb(h).unwrap();
            let (nb, d) = moved_box(&mut rng, &b, Scene::Uniform);
            bp.update_proxy(h, nb, d).unwrap();
        }
        let ch = bp.update_pairs().clone();
        let cur: BTreeSet<_> = bp.pairs().into_iter().collect();
        assert!(ch
            .added
            .windows(2)
            .all(|w| (w[0].0.index, w[0].1.index) < (w[1].0.index, w[1].1.index)));
        assert!(ch
            .removed
            .windows(2)
            .all(|w| (w[0].0.index, w[0].1.index) < (w[1].0.index, w[1].1.index)));
        let mut expect = prev.clone();
        for p in &ch.removed {
            assert!(expect.remove(p), "removed pair was present");
        }
        assert_eq!(expect.len(), ch.kept);
        for p in &ch.added {
            assert!(expect.insert(*p), "added pair was absent");
        }
        assert_eq!(expect, cur);
        prev = cur;
    }
}

#[test]
fn user_filter_and_masks() {
    use std::sync::Arc;
    for m in Method::ALL {
        let mut bp = AnyBroadPhase::new(m);
        let b = Aabb::new(
            carom_collision::math::Vec3::ZERO,
            carom_collision::math::Vec3::ONE,
        );
        let a = bp
            .create_proxy(
                b,
                Filter {
                    group: 1,
                    mask: 2,
                    is_static: false,
                },
            )
            .unwrap();
        let c = bp
            .create_proxy(
                b,
                Filter {
                    group: 2,
                    mask: 1,
                    is_static: false,
                },
            )
            .unwrap();
        let d = bp
            .create_proxy(
                b,
                Filter {
                    group: 4,
                    mask: 4,
                    is_static: false,
                },
            )
            .unwrap();
        let s1 = bp.create_proxy(b, Filter::new(true)).unwrap();
        let s2 = bp.create_proxy(b, Filter::new(true)).unwrap();
        bp.update_pairs();
        let pairs = bp.pairs();
        assert!(pairs.contains(&(a, c)), "{m:?}");
        assert!(!pairs.iter().any(|p| p.0 == d || p.1 == d), "{m:?} mask");
        assert!(!pairs.contains(&(s1, s2)), "{m:?} static-static");
        bp.set_user_filter(Some(Arc::new(move |x, y| !(x == a && y == c))));
        let ch = bp.update_pairs().clone();
        assert_eq!(ch.removed, vec![(a, c)], "{m:?}");
    }
}
