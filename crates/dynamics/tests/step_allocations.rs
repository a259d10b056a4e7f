//! Allocations of a whole [`World::step`] on a resting stack after warm-up, counted with a
//! counting global allocator (this test binary only). The solver itself allocates nothing
//! (unit test `solver::alloc_tests`); what remains is outside it (islands, sleeping, the
//! collision update), and must not grow with time: every counted step makes the same number.
mod common;
mod pipeline;
use carom_dynamics::collision::math::{Real, Vec3};
use carom_dynamics::SolverKind;
use pipeline::{dyn_box, ground, world};
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

// SAFETY: forwards to the system allocator; the bookkeeping touches only `Cell`s.
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
    COUNT.with(|n| n.set(0));
    COUNTING.with(|c| c.set(true));
    f();
    COUNTING.with(|c| c.set(false));
    COUNT.with(|n| n.get())
}

/// Allocations of each of 20 steps of a resting stack of `n` boxes, after 100 warm-up steps.
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
    for _ in 0..100 {
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

#[test]
fn a_resting_dynamics_step_allocates_only_outside_the_solver() {
    for kind in [SolverKind::SoftStep, SolverKind::SequentialImpulse] {
        let small = dynamics_step_allocations(kind, 4);
        let large = dynamics_step_allocations(kind, 16);
        eprintln!(
            "{kind:?} DynamicsWorld::step allocations: 4 boxes {small:?}, 16 boxes {large:?}"
        );
        // The solver allocates nothing; the rest (islands: union-find parents, roots, the
        // awake flags, minimum rest times) is a fixed number of vectors per step.
        assert!(
            small.iter().chain(&large).all(|&c| c == small[0]),
            "{small:?} {large:?}"
        );
        assert!(small[0] <= 6, "{small:?}");
    }
}

#[test]
fn a_resting_world_step_allocates_the_same_number_every_step() {
    let small = stack_step_allocations(4);
    let large = stack_step_allocations(16);
    eprintln!("World::step allocations per step: 4 boxes {small:?}, 16 boxes {large:?}");
    // Steady state: the count does not grow with time. (It grows with the number of bodies
    // in the collision update, outside this crate's solver.)
    assert!(small.iter().all(|&c| c == small[0]), "{small:?}");
    assert!(large.iter().all(|&c| c == large[0]), "{large:?}");
}
