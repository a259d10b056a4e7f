//! The two-tree broadphase allocates nothing per update in the steady state: boxes that
//! jitter inside and out of their fat boxes (refits, queries, candidate merges, pair diffs)
//! reuse the buffers grown during a warm-up. The hashed grid, the hierarchical grid and the
//! sort-and-sweep (rebuilt from scratch at every update) and the incremental sweep-and-prune
//! reuse theirs too. The two trees with Manhattan insertion (no rotations, deeper trees) take
//! longer to reach their steady state: no allocation after the first 96 updates.

use carom_collision::broadphase::{
    AnyBroadPhase, BroadPhase, Filter, Method, ProxyHandle, TreeBroadPhase,
};
use carom_collision::math::{Aabb, Real, Vec3};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;

thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
    static COUNT: Cell<usize> = const { Cell::new(0) };
}

fn note() {
    if COUNTING.try_with(|c| c.get()).unwrap_or(false) {
        let _ = COUNT.try_with(|n| n.set(n.get() + 1));
    }
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        note();
        System.alloc(layout)
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        note();
        System.alloc_zeroed(layout)
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        note();
        System.realloc(ptr, layout, new_size)
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// A 10×10×10 lattice of unit boxes 0.05 apart (neighbours pair through their margins),
/// each displaced by `phase`-dependent wobble of up to 0.12 (beyond the fat margin).
fn frame(bp: &mut impl BroadPhase, handles: &[ProxyHandle], step: usize) -> usize {
    for (k, &h) in handles.iter().enumerate() {
        let (i, j, l) = ((k % 10) as Real, ((k / 10) % 10) as Real, (k / 100) as Real);
        let phase = (step * 7 + k * 13) % 24;
        let wobble = 0.01 * (phase as Real - 12.0);
        let c = Vec3::new(i * 1.05 + wobble, j * 1.05, l * 1.05 - wobble);
        let aabb = Aabb::new(c - Vec3::splat(0.5), c + Vec3::splat(0.5));
        bp.update_proxy(h, aabb, Vec3::new(0.01, 0.0, -0.01))
            .unwrap();
    }
    let ch = bp.update_pairs();
    ch.added.len() + ch.removed.len()
}

#[test]
fn a_steady_tree_broadphase_update_allocates_nothing() {
    // Every box moves, so the update takes the split (parallel) descent: run it on a
    // one-thread rayon pool, as the pipeline does (`pool.install`), so that every task runs
    // on the counting thread and no parallel loop goes through rayon's injector queue (see
    // below).
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let mut bp = TreeBroadPhase::default();
    let handles: Vec<ProxyHandle> = (0..1000)
        .map(|_| {
            bp.create_proxy(Aabb::new(Vec3::ZERO, Vec3::ONE), Filter::default())
                .unwrap()
        })
        .collect();
    let (pairs, changes, count) = pool.install(|| {
        for step in 0..48 {
            frame(&mut bp, &handles, step);
        }
        let pairs = bp.pair_count();
        COUNT.with(|n| n.set(0));
        COUNTING.with(|c| c.set(true));
        let mut changes = 0;
        for step in 48..96 {
            changes += frame(&mut bp, &handles, step);
        }
        COUNTING.with(|c| c.set(false));
        (pairs, changes, COUNT.with(|n| n.get()))
    });
    assert!(pairs > 500, "the lattice pairs: {pairs}");
    assert!(changes > 100, "pairs came and went: {changes}");
    assert_eq!(count, 0, "allocations in 48 steady updates");
}

#[test]
fn steady_rebuilt_and_sweep_updates_allocate_nothing() {
    // The lattice, plus a few larger boxes (other hierarchy levels) and a huge one (the
    // oversize list). Run on a rayon worker, as the pipeline does (`pool.install`): a
    // parallel loop started from outside a pool goes through rayon's injector queue, which
    // allocates a block now and then whatever the caller does.
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    for method in [Method::Grid, Method::HGrid, Method::Sap, Method::SortSweep] {
        let mut bp = AnyBroadPhase::new(method);
        let handles: Vec<ProxyHandle> = (0..1000)
            .map(|_| {
                bp.create_proxy(Aabb::new(Vec3::ZERO, Vec3::ONE), Filter::default())
                    .unwrap()
            })
            .collect();
        for k in 0..6 {
            let c = Vec3::new(3.0 * k as Real, 11.0, 2.0);
            let size = if k == 5 { 1.0e4 } else { 1.5 + k as Real };
            bp.create_proxy(Aabb::new(c, c + Vec3::splat(size)), Filter::new(true))
                .unwrap();
        }
        let (pairs, changes, count) = pool.install(|| {
            for step in 0..48 {
                frame(&mut bp, &handles, step);
            }
            let pairs = bp.pair_count();
            COUNT.with(|n| n.set(0));
            COUNTING.with(|c| c.set(true));
            let mut changes = 0;
            for step in 48..96 {
                changes += frame(&mut bp, &handles, step);
            }
            COUNTING.with(|c| c.set(false));
            (pairs, changes, COUNT.with(|n| n.get()))
        });
        assert!(pairs > 500, "{method:?}: the lattice pairs: {pairs}");
        assert!(changes > 100, "{method:?}: pairs came and went: {changes}");
        assert_eq!(count, 0, "{method:?}: allocations in 48 steady updates");
    }
}

#[test]
fn manhattan_trees_stop_allocating_after_a_longer_warm_up() {
    // Bullet's Manhattan descent does no rotations, so its trees are deeper and keep
    // deepening for longer while the boxes jitter: the traversal buffers grow in the first
    // two windows of 48 updates (364 and 9 allocations), then never again. One thread, as
    // in the test above, so that every allocation is counted.
    use carom_collision::bvh::InsertStrategy;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let mut bp = TreeBroadPhase::new(InsertStrategy::Manhattan, TreeBroadPhase::DEFAULT_MARGIN);
    let handles: Vec<ProxyHandle> = (0..1000)
        .map(|_| {
            bp.create_proxy(Aabb::new(Vec3::ZERO, Vec3::ONE), Filter::default())
                .unwrap()
        })
        .collect();
    let (counts, changes) = pool.install(|| {
        let (mut counts, mut changes) = (Vec::new(), 0);
        for window in 0..5 {
            COUNT.with(|n| n.set(0));
            COUNTING.with(|c| c.set(true));
            for step in window * 48..(window + 1) * 48 {
                changes += frame(&mut bp, &handles, step);
            }
            COUNTING.with(|c| c.set(false));
            counts.push(COUNT.with(|n| n.get()));
        }
        (counts, changes)
    });
    assert!(changes > 100, "pairs came and went: {changes}");
    assert!(counts[0] > 0, "the warm-up grows the buffers: {counts:?}");
    assert_eq!(
        counts[2..],
        [0, 0, 0],
        "allocations per window of 48 updates: {counts:?}"
    );
}
