//! Stacks stay standing: a 10-box stack and a 20-row pyramid, each solver, sleeping off.
//!
//! Drift is the largest displacement of any box between the settled state (after 1 s, once
//! the contacts have taken the load) and the end; the settling itself (the soft contacts'
//! compression) is bounded separately. Figures are printed with `--nocapture`.
mod common;
use carom_dynamics::collision::math::{Real, Vec3};
use carom_dynamics::SolverKind;
use common::*;

const SETTLE: usize = 60;

/// Returns (settle displacement, drift after settling, ms per step).
fn run(kind: SolverKind, pyr: bool, iterations: u32, n_steps: usize) -> (Real, Real, f64) {
    let (mut sim, boxes) = if pyr {
        pyramid(kind, 20)
    } else {
        stack(kind, 10)
    };
    let mut p = *sim.world.params();
    p.sleep.enabled = false;
    p.solver.velocity_iterations = iterations;
    sim.world.set_params(p).unwrap();
    let start: Vec<Vec3> = boxes.iter().map(|&b| sim.pos(b)).collect();
    for _ in 0..SETTLE {
        sim.step();
    }
    let settled: Vec<Vec3> = boxes.iter().map(|&b| sim.pos(b)).collect();
    let settle = max_drift(&sim, &boxes, &start);
    let t = std::time::Instant::now();
    for _ in SETTLE..n_steps {
        sim.step();
    }
    let ms = t.elapsed().as_secs_f64() * 1e3 / (n_steps - SETTLE) as f64;
    let drift = max_drift(&sim, &boxes, &settled);
    let name = if pyr { "pyramid20" } else { "stack10" };
    eprintln!("{kind:?} {name} it={iterations} steps={n_steps} settle={settle:.4} m drift={drift:.4} m ms/step={ms:.3}");
    (settle, drift, ms)
}

#[test]
fn ten_box_stack_stands_soft_step() {
    let (settle, drift, _) = run(SolverKind::SoftStep, false, 10, steps(2000, 2000));
    assert!(
        drift < 0.01 && settle < 0.03,
        "settle {settle} drift {drift}"
    );
}

#[test]
fn ten_box_stack_stands_sequential_impulse() {
    let (settle, drift, _) = run(SolverKind::SequentialImpulse, false, 60, steps(2000, 1000));
    assert!(
        drift < 0.01 && settle < 0.03,
        "settle {settle} drift {drift}"
    );
}

#[test]
fn pyramid_stands_soft_step() {
    let (settle, drift, _) = run(SolverKind::SoftStep, true, 10, steps(2000, 300));
    // 20 soft contacts in series: the settling compression is larger than for the stack.
    assert!(
        drift < 0.01 && settle < 0.05,
        "settle {settle} drift {drift}"
    );
}

#[test]
fn pyramid_stands_sequential_impulse() {
    let (settle, drift, _) = run(SolverKind::SequentialImpulse, true, 40, steps(2000, 200));
    assert!(
        drift < 0.01 && settle < 0.03,
        "settle {settle} drift {drift}"
    );
}
