//! The stage-parallel soft step (`solver::stages`, `solver::soft_stages`) on benchmark
//! scenes large enough that every colour and body stage is cut into many blocks: the state
//! after each run hashes to the same bits on 1, 2, 3 and 8 threads, with SIMD lanes and with
//! the scalar path, with and without joints (the one-thread run, which walks the stages in
//! order on the calling thread, is the oracle).
mod pipeline;
use carom_dynamics::*;
use carom_scenes::Scene;
use pipeline::steps;

fn hash(scene: &Scene, simd: bool, min_batch: usize, threads: usize, n: (usize, usize)) -> u64 {
    let (n, least) = n;
    let mut p = PipelineParams::default();
    p.dynamics.solver.simd = simd;
    p.dynamics.solver.parallel_min_batch = min_batch;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut w = World::from_scene_with(scene, p).unwrap();
        let mut manifolds = 0;
        for _ in 0..n {
            manifolds = manifolds.max(w.step(1.0 / 60.0).unwrap().manifolds);
        }
        assert!(manifolds > least, "too few contacts ({manifolds})");
        w.state_hash()
    })
}

/// `n`: steps, and the fewest manifolds the run must reach.
fn check(scene: &Scene, n: (usize, usize)) {
    for (simd, min_batch) in [(true, 256), (true, 1), (false, 1)] {
        let one = hash(scene, simd, min_batch, 1, n);
        for threads in [2, 3, 8] {
            let many = hash(scene, simd, min_batch, threads, n);
            assert_eq!(
                one, many,
                "simd {simd}, min batch {min_batch}: {threads} threads"
            );
        }
    }
}

#[test]
fn stacked_boxes_are_bit_identical_on_any_thread_count() {
    check(&carom_scenes::bullet::stacked_boxes(), (steps(40, 8), 1000));
}

#[test]
fn ragdolls_are_bit_identical_on_any_thread_count() {
    // 1360 joints in single-block stages between the contact colours.
    check(&carom_scenes::bullet::ragdolls(), (150, 200));
}

/// State hash after `n` steps of a dynamic plank carrying a 6 × 6 grid of boxes (two
/// layers) on `threads` threads: the plank touches 36 boxes, more than there are colours,
/// so the overflow colour is not empty and its scalar constraints are built by the prepare
/// stage (`SoftStage::PrepareRest`) beside the wide ones; the second layer's few
/// constraints per colour give the one-block colours of that stage.
fn plank_hash(simd: bool, min_batch: usize, threads: usize, n: usize) -> u64 {
    use carom_dynamics::collision::math::{Real, Vec3};
    let mut p = PipelineParams::default();
    p.dynamics.gravity = Vec3::new(0.0, -10.0, 0.0);
    p.dynamics.sleep.enabled = false;
    p.dynamics.solver.simd = simd;
    p.dynamics.solver.parallel_min_batch = min_batch;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    pool.install(|| {
        let mut w = World::new(p).unwrap();
        pipeline::ground(&mut w, 0.6);
        pipeline::dyn_box(&mut w, Vec3::new(4.0, 0.1, 4.0), Vec3::new(0.0, 0.1, 0.0));
        for layer in 0..2 {
            for i in 0..6 {
                for k in 0..6 {
                    let (x, z) = (-3.0 + 1.2 * i as Real, -3.0 + 1.2 * k as Real);
                    let y = 0.45 + 0.5 * layer as Real;
                    let h = Vec3::splat(0.25 - 0.02 * layer as Real);
                    pipeline::dyn_box(&mut w, h, Vec3::new(x, y, z));
                }
            }
        }
        let mut manifolds = 0;
        for _ in 0..n {
            manifolds = manifolds.max(w.step(1.0 / 60.0).unwrap().manifolds);
        }
        assert!(manifolds >= 36 + 36, "too few contacts ({manifolds})");
        w.state_hash()
    })
}

#[test]
fn an_overflowing_plank_is_bit_identical_on_any_thread_count() {
    let n = pipeline::steps(60, 20);
    for (simd, min_batch) in [(true, 64), (true, 1), (false, 1)] {
        let one = plank_hash(simd, min_batch, 1, n);
        for threads in [2, 3, 8] {
            let many = plank_hash(simd, min_batch, threads, n);
            assert_eq!(
                one, many,
                "simd {simd}, min batch {min_batch}: {threads} threads"
            );
        }
    }
}
