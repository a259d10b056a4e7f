//! The solver allocates nothing in steady state: a counting global allocator (this test
//! binary only) counts the allocations made by the calling thread during the solver step of
//! a resting stack, after one warm-up step has grown the world-owned scratch buffers.

use super::{sequential, soft_step, SolverBody, SolverKind, SolverParams, SolverScratch};
use super::{StepContext, StepTimings};
use crate::body::BodyDesc;
use crate::body_set::{BodyHandle, BodySet};
use crate::contact::{ContactManifold, ContactPoint};
use crate::integrate;
use crate::joint::{Axis, AxisMode, JointDesc, JointKind, JointSet, Motor, Spring};
use carom_collision::math::{Isometry, Quat, Real, Vec3};
use carom_collision::shape::{Cuboid, Shape};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::Arc;

/// Counts the allocations (and reallocations) of threads that switched counting on.
struct Counting;

thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
    static COUNT: Cell<usize> = const { Cell::new(0) };
}

fn note() {
    // `try_with`: the allocator may run while thread locals are being torn down.
    let on = COUNTING.try_with(|c| c.get()).unwrap_or(false);
    if on {
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

/// Allocations made by this thread while running `f`.
fn count_allocations(f: impl FnOnce()) -> usize {
    COUNT.with(|n| n.set(0));
    COUNTING.with(|c| c.set(true));
    f();
    COUNTING.with(|c| c.set(false));
    COUNT.with(|n| n.get())
}

/// A ground box and `n` unit boxes stacked on it, with the four face contacts of each
/// resting pair (separation 0, normal +Y from the lower body to the upper one).
fn resting_stack(n: usize) -> (BodySet, Vec<ContactManifold>) {
    let mut set = BodySet::new();
    let ground: Arc<Shape> = Arc::new(Cuboid::new(Vec3::new(20.0, 0.5, 20.0)).unwrap().into());
    let unit: Arc<Shape> = Arc::new(Cuboid::new(Vec3::splat(0.5)).unwrap().into());
    let at = |y: Real| Isometry::new(Vec3::new(0.0, y, 0.0), Quat::IDENTITY);
    let mut handles: Vec<BodyHandle> =
        vec![set.insert(&BodyDesc::fixed(ground, at(-0.5))).unwrap()];
    for i in 0..n {
        let desc = BodyDesc::dynamic(unit.clone(), at(0.5 + i as Real), 1000.0);
        handles.push(set.insert(&desc).unwrap());
    }
    let mut manifolds = Vec::new();
    for pair in handles.windows(2) {
        let mut m = ContactManifold::new(pair[0], pair[1], Vec3::Y);
        m.friction = 0.6;
        for (k, (x, z)) in [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)]
            .into_iter()
            .enumerate()
        {
            let p = ContactPoint::new(Vec3::new(x, 0.5, z), Vec3::new(x, -0.5, z), 0.0, k as u32);
            m.push(p).unwrap();
        }
        manifolds.push(m);
    }
    (set, manifolds)
}

/// One joint of each type between consecutive boxes of the stack (bodies `1..`), anchored
/// at the face they share.
fn stack_joints(set: &BodySet, n: usize) -> JointSet {
    let mut joints = JointSet::default();
    let handles: Vec<BodyHandle> = set.handles().collect();
    let spring = Axis {
        mode: AxisMode::Free,
        motor: None,
        spring: Some(Spring {
            hertz: 5.0,
            damping_ratio: 0.5,
            rest: 0.0,
        }),
    };
    let motor = Some(Motor {
        speed: 0.5,
        max_force: 10.0,
    });
    let kinds = [
        JointKind::Ball,
        JointKind::Hinge {
            limits: Some((-0.5, 0.5)),
            motor,
        },
        JointKind::ConeTwist {
            swing1: 0.4,
            swing2: 0.3,
            twist: 0.2,
        },
        JointKind::Slider {
            limits: Some((-0.1, 0.1)),
            motor,
        },
        JointKind::Fixed,
        JointKind::Generic6Dof {
            linear: [Axis::default(), spring, Axis::default()],
            angular: [Axis::default(), spring, Axis::default()],
        },
    ];
    for (i, pair) in handles[1..=n].windows(2).enumerate() {
        let frame_a = Isometry::from_translation(Vec3::new(0.0, 0.5, 0.0));
        let frame_b = Isometry::from_translation(Vec3::new(0.0, -0.5, 0.0));
        let kind = kinds[i % kinds.len()];
        joints.insert(JointDesc::new(pair[0], pair[1], frame_a, frame_b, kind));
    }
    joints
}

/// Allocations of the solver step in each of `steps` steps after a warm-up step, with a
/// joint between every two boxes when `with_joints`.
fn solver_allocations(kind: SolverKind, steps: usize, with_joints: bool) -> Vec<usize> {
    let (mut set, mut manifolds) = resting_stack(8);
    let mut joints = if with_joints {
        stack_joints(&set, 8)
    } else {
        JointSet::default()
    };
    let mut bodies: Vec<SolverBody> = Vec::new();
    let mut scratch = SolverScratch::default();
    let mut joint_scratch = super::joints::JointScratch::default();
    let params = SolverParams {
        kind,
        ..Default::default()
    };
    let mut counts = Vec::with_capacity(steps + 1);
    for _ in 0..=steps {
        integrate::load(&set, &mut bodies);
        let mut timings = StepTimings::default();
        let mut ctx = StepContext {
            set: &mut set,
            bodies: &mut bodies,
            manifolds: &mut manifolds,
            joints: &mut joints,
            gravity: Vec3::new(0.0, -9.81, 0.0),
            dt: 1.0 / 60.0,
            params: &params,
            gyroscopic: true,
            parallel: false,
            timings: &mut timings,
            scratch: &mut scratch,
            joint_scratch: &mut joint_scratch,
        };
        counts.push(count_allocations(|| match kind {
            SolverKind::SoftStep => soft_step::step(&mut ctx),
            SolverKind::SequentialImpulse => sequential::step(&mut ctx),
        }));
    }
    // The stack really was solved: every contact carries weight, every joint has rows.
    assert!(manifolds.iter().all(|m| m.total_normal_impulse() > 0.0));
    assert_eq!(joint_scratch.joints.len(), joints.len());
    assert!(joint_scratch.rows.len() >= 3 * joints.len());
    counts.remove(0);
    counts
}

#[test]
fn the_counter_sees_allocations() {
    let n = count_allocations(|| {
        let v: Vec<u64> = std::hint::black_box(vec![1, 2, 3]);
        drop(v);
    });
    assert_eq!(n, 1);
}

#[test]
fn soft_step_solver_allocates_nothing_after_warm_up() {
    let counts = solver_allocations(SolverKind::SoftStep, 20, false);
    assert!(
        counts.iter().all(|&c| c == 0),
        "allocations per step: {counts:?}"
    );
}

#[test]
fn sequential_impulse_solver_allocates_nothing_after_warm_up() {
    let counts = solver_allocations(SolverKind::SequentialImpulse, 20, false);
    assert!(
        counts.iter().all(|&c| c == 0),
        "allocations per step: {counts:?}"
    );
}

#[test]
fn joint_rows_allocate_nothing_after_warm_up() {
    for kind in [SolverKind::SoftStep, SolverKind::SequentialImpulse] {
        let counts = solver_allocations(kind, 20, true);
        assert!(
            counts.iter().all(|&c| c == 0),
            "{kind:?}: allocations per step: {counts:?}"
        );
    }
}
