//! The two-tree broadphase's parallel candidate search (split descents, chunked queries of
//! the moved proxies) gives bit-identical pairs and changes on 1, 2 and 8 threads, and the
//! pairs a brute force finds, on scenes large enough to take the parallel paths: every
//! proxy moved (full descent), many moved (chunked queries), few moved (the serial loop);
//! on 2 and 8 threads the merge of the candidates is split into chunks too.
#![cfg(feature = "parallel")]

mod broadphase_common;

use broadphase_common::{moved_box, random_box, Rng, Scene, SCENES};
use carom_collision::broadphase::{BroadPhase, Filter, ProxyHandle, TreeBroadPhase};
use carom_collision::math::Real;

/// Per frame: the sorted pairs (slot indices), the added and the removed pairs.
type Frames = Vec<(Vec<(u32, u32)>, Vec<(u32, u32)>, Vec<(u32, u32)>)>;

/// The brute-force pairs of the live proxies: exact boxes overlapping, filters accepting.
fn oracle(bp: &TreeBroadPhase, live: &[(ProxyHandle, Filter)]) -> Vec<(u32, u32)> {
    let mut out = Vec::new();
    for (i, &(a, fa)) in live.iter().enumerate() {
        let ba = bp.aabb(a).unwrap();
        for &(b, fb) in &live[i + 1..] {
            if ba.intersects(&bp.aabb(b).unwrap()) && fa.can_pair(&fb) {
                out.push((a.index.min(b.index), a.index.max(b.index)));
            }
        }
    }
    out.sort_unstable();
    out
}

fn sorted(v: &[(ProxyHandle, ProxyHandle)]) -> Vec<(u32, u32)> {
    let mut out: Vec<(u32, u32)> = v
        .iter()
        .map(|(a, b)| (a.index.min(b.index), a.index.max(b.index)))
        .collect();
    out.sort_unstable();
    out
}

/// Runs `frames` updates of `n` proxies (one in ten static, some put to rest, a few
/// removed), moving the fraction `moving` of the dynamic ones per frame, with the
/// broadphase's full-descent fraction set to `full_fraction`; checks each frame against
/// the brute force when `check`. Also returns the largest candidate count seen.
fn record(
    scene: Scene,
    n: usize,
    moving: Real,
    full_fraction: Real,
    frames: usize,
    check: bool,
) -> (Frames, usize) {
    let mut rng = Rng(0x5eed ^ n as u64);
    let mut bp = TreeBroadPhase::default();
    bp.full_sweep_fraction = full_fraction;
    let mut live: Vec<(ProxyHandle, Filter)> = (0..n)
        .map(|k| {
            let f = Filter::new(k % 10 == 3);
            (bp.create_proxy(random_box(&mut rng, scene), f).unwrap(), f)
        })
        .collect();
    for &(h, f) in live.iter().step_by(17) {
        if !f.is_static {
            bp.set_resting(h, true).unwrap();
        }
    }
    let mut out = Frames::new();
    let mut most = 0;
    for frame in 0..frames {
        for &(h, f) in &live {
            if f.is_static || rng.unit() >= moving {
                continue;
            }
            let b = bp.aabb(h).unwrap();
            let (nb, d) = moved_box(&mut rng, &b, scene);
            bp.update_proxy(h, nb, d).unwrap();
        }
        if frame == 1 {
            // Removals, and a resting proxy woken up.
            for k in (0..live.len()).step_by(41).rev() {
                bp.remove_proxy(live.remove(k).0).unwrap();
            }
            bp.set_resting(live[0].0, false).unwrap();
        }
        let ch = bp.update_pairs().clone();
        most = most.max(bp.candidate_count());
        let pairs = sorted(&bp.pairs());
        if check {
            assert_eq!(
                pairs,
                oracle(&bp, &live),
                "{scene:?}, n {n}, moving {moving}, full {full_fraction}, frame {frame}"
            );
        }
        out.push((pairs, sorted(&ch.added), sorted(&ch.removed)));
    }
    (out, most)
}

#[cfg(feature = "parallel")]
#[test]
fn parallel_candidate_search_matches_one_thread_and_brute_force() {
    let pool = |n| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
    };
    let pools = [pool(1), pool(2), pool(8)];
    for scene in SCENES {
        let n = if scene == Scene::Degenerate {
            700
        } else {
            2000
        };
        // (moved fraction, full-descent fraction): all moved by descent, all moved by
        // chunked queries, a third moved (chunked), a few moved (serial queries).
        for (moving, full) in [(1.0, 0.0), (1.0, 2.0), (0.35, 0.5), (0.01, 0.5)] {
            let (one, most) = pools[0].install(|| record(scene, n, moving, full, 4, true));
            assert!(one.iter().all(|f| !f.0.is_empty()), "{scene:?}: no pairs");
            if scene == Scene::Uniform {
                // Enough candidates for the split merge on 2 and 8 threads (4096 a chunk).
                assert!(most > 2 * 4096, "{most} candidates");
            }
            for p in &pools[1..] {
                let (many, _) = p.install(|| record(scene, n, moving, full, 4, false));
                assert_eq!(one, many, "{scene:?}, moving {moving}, full {full}");
            }
        }
    }
}
