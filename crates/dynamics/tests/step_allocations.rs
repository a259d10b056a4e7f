//! Allocations of a whole [`World::step`] after warm-up, counted with a counting global
//! allocator (this test binary only). The counter is process-wide, so allocations on rayon's
//! worker threads (the parallel narrowphase and solver) count too. For the same reason the
//! binary has a single `#[test]` that runs the checks one after the other: with several, the
//! test harness's own thread records one test's result (and allocates) while the next one
//! counts, which made the counts flaky. With the default broadphase (the two trees) the
//! solver, the islands, the narrowphase, the pipeline's adapter and the broadphase allocate
//! nothing in the steady state.
mod common;
mod pipeline;
use carom_dynamics::collision::math::{Isometry, Quat, Real, Vec3};
use carom_dynamics::collision::narrowphase::{Dispatcher, NarrowObject, NarrowPhase};
use carom_dynamics::collision::world::ObjectHandle;
use carom_dynamics::{BodyDesc, PipelineParams, SolverKind, World};
use pipeline::{cuboid, dyn_box, ground, world};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

struct Counting;

static COUNTING: AtomicBool = AtomicBool::new(false);
static COUNT: AtomicUsize = AtomicUsize::new(0);

fn note() {
    if COUNTING.load(Ordering::Relaxed) {
        COUNT.fetch_add(1, Ordering::Relaxed);
    }
}

// SAFETY: forwards to the system allocator; the bookkeeping touches only atomics.
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

fn count_allocations(f: impl FnOnce()) -> usize {
    COUNT.store(0, Ordering::SeqCst);
    COUNTING.store(true, Ordering::SeqCst);
    f();
    COUNTING.store(false, Ordering::SeqCst);
    COUNT.load(Ordering::SeqCst)
}

/// Allocations of each of 20 steps of a resting stack of `n` boxes, after 200 warm-up steps.
fn stack_step_allocations(n: usize) -> Vec<usize> {
    let mut w = world(false);
    ground(&mut w, 0.5);
    for i in 0..n {
        dyn_box(
            &mut w,
            Vec3::splat(0.5),
            Vec3::new(0.0, 0.5 + i as Real, 0.0),
        );
    }
    for _ in 0..200 {
        w.step(1.0 / 60.0).unwrap();
    }
    (0..20)
        .map(|_| {
            count_allocations(|| {
                w.step(1.0 / 60.0).unwrap();
            })
        })
        .collect()
}

/// Allocations of [`carom_dynamics::DynamicsWorld::step`] alone (hand-made contacts, built
/// outside the count) in each of 20 steps of a resting stack of `n` boxes, after warm-up.
fn dynamics_step_allocations(kind: SolverKind, n: usize) -> Vec<usize> {
    let (mut sim, _) = common::stack(kind, n);
    for _ in 0..100 {
        sim.step();
    }
    (0..20)
        .map(|_| {
            let mut contacts = sim.contacts();
            common::warm_from(&sim.prev, &mut contacts);
            let dt = sim.dt;
            let count = count_allocations(|| {
                sim.last_report = sim.world.step(dt, &mut contacts).unwrap();
            });
            sim.prev = contacts;
            count
        })
        .collect()
}

/// Every check of this binary, one after the other (see the module docs for why it is one
/// test).
#[test]
fn steps_allocate_nothing_after_warm_up() {
    a_resting_dynamics_step_allocates_nothing();
    a_resting_world_step_allocates_nothing();
    the_narrowphase_regenerates_manifolds_without_allocating();
    a_settled_pile_steps_without_allocating();
}

fn a_resting_dynamics_step_allocates_nothing() {
    for kind in [SolverKind::SoftStep, SolverKind::SequentialImpulse] {
        let small = dynamics_step_allocations(kind, 4);
        let large = dynamics_step_allocations(kind, 16);
        eprintln!(
            "{kind:?} DynamicsWorld::step allocations: 4 boxes {small:?}, 16 boxes {large:?}"
        );
        // The solver and the islands (union-find, wake and sleep arrays) reuse their buffers.
        assert!(
            small.iter().chain(&large).all(|&c| c == 0),
            "{small:?} {large:?}"
        );
    }
}

fn a_resting_world_step_allocates_nothing() {
    // A one-thread pool: a worker's first task would grow its thread-local scratch once.
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let (small, large) = pool.install(|| (stack_step_allocations(4), stack_step_allocations(16)));
    eprintln!("World::step allocations per step: 4 boxes {small:?}, 16 boxes {large:?}");
    assert!(
        small.iter().chain(&large).all(|&c| c == 0),
        "{small:?} {large:?}"
    );
}

/// A settled pile of boxes (12 boxes in three staggered columns on the ground).
fn settled_pile(parallel: bool) -> World {
    let mut p = PipelineParams::default();
    p.dynamics.gravity = Vec3::new(0.0, -10.0, 0.0);
    p.dynamics.sleep.enabled = false;
    p.dynamics.parallel = parallel;
    let mut w = World::new(p).unwrap();
    ground(&mut w, 0.5);
    for i in 0..12 {
        let x = (i % 3) as Real * 1.02 - 1.0;
        let y = 0.5 + (i / 3) as Real * 1.01;
        let q = Quat::from_rotation_y(0.02 * i as Real);
        w.add_body(&BodyDesc::dynamic(
            cuboid(Vec3::splat(0.5)),
            Isometry::new(Vec3::new(x, y, 0.1 * (i % 2) as Real), q),
            1000.0,
        ))
        .unwrap();
    }
    for _ in 0..300 {
        w.step(1.0 / 60.0).unwrap();
    }
    w
}

/// The narrowphase stage alone on the settled pile's shapes and poses, with every box turned
/// a little more at each step so that no manifold stays coherent: each step regenerates
/// every box–box manifold (SAT, clipping, reduction, matching), through the parallel loop
/// over pairs, and allocates nothing. (On a one-thread pool: with more threads, a worker's
/// first task grows its thread-local scratch once and rayon's deques resize now and then.)
fn the_narrowphase_regenerates_manifolds_without_allocating() {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    pool.install(narrowphase_regeneration);
}

fn narrowphase_regeneration() {
    let w = settled_pile(false);
    let objects: Vec<(ObjectHandle, NarrowObject)> = w
        .collision()
        .iter()
        .map(|(h, o)| {
            let mut n = NarrowObject::new(&o.shape, o.pose);
            n.margin = o.margin;
            (h, n)
        })
        .collect();
    let pairs = w.collision().pairs();
    let mut np: NarrowPhase<ObjectHandle> = NarrowPhase::new(Dispatcher::default());
    let lookup_at = |step: usize| {
        let objects = &objects;
        move |h: ObjectHandle| {
            let k = objects.iter().position(|(o, _)| *o == h)?;
            let mut n = objects[k].1;
            let turn = Quat::from_rotation_y(1.0e-3 * (step * (k + 1)) as Real);
            n.pose.rotation = (turn * n.pose.rotation).normalize();
            Some(n)
        }
    };
    np.step(&pairs, &[], lookup_at(0)).unwrap();
    for step in 1..20 {
        np.step(&[], &[], lookup_at(step)).unwrap();
    }
    let counts: Vec<usize> = (20..40)
        .map(|step| {
            let lookup = lookup_at(step);
            count_allocations(|| {
                np.step(&[], &[], lookup).unwrap();
            })
        })
        .collect();
    let touching = np.manifolds().count();
    eprintln!(
        "{} pairs, {touching} manifolds, allocations {counts:?}",
        np.len()
    );
    assert!(touching >= 12, "the pile touches: {touching}");
    // Not coherent: the manifolds were regenerated (their generation pose is this step's).
    assert!(np.manifolds().all(|p| p.manifold.generated_at.is_some()));
    assert!(counts.iter().all(|&c| c == 0), "{counts:?}");
}

/// The whole pipeline on the settled pile (one-thread pool), serial and parallel stages:
/// no allocation per step.
fn a_settled_pile_steps_without_allocating() {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    pool.install(settled_pile_steps);
}

/// With `queried`, a ray is cast (outside the count) before every step, so that every step
/// also refreshes the world's query tree (`pipeline::query_cache`).
fn settled_pile_steps() {
    for (parallel, queried) in [(false, false), (true, false), (false, true)] {
        let mut w = settled_pile(parallel);
        let cast = |w: &World| {
            if queried {
                w.raycast(Vec3::new(0.0, 0.5, -5.0), Vec3::Z, 10.0, u32::MAX)
                    .unwrap()
                    .expect("the ray meets the pile");
            }
        };
        cast(&w);
        w.step(1.0 / 60.0).unwrap();
        let counts: Vec<usize> = (0..20)
            .map(|_| {
                cast(&w);
                count_allocations(|| {
                    w.step(1.0 / 60.0).unwrap();
                })
            })
            .collect();
        let r = w.last_report();
        eprintln!(
            "parallel {parallel}, queried {queried}: {} pairs, {} manifolds, allocations \
             {counts:?}",
            r.pairs, r.manifolds
        );
        assert_eq!(r.timings.query_tree.is_zero(), !queried);
        assert!(r.manifolds >= 12, "the pile touches: {}", r.manifolds);
        assert!(counts.iter().all(|&c| c == 0), "{counts:?}");
    }
}
