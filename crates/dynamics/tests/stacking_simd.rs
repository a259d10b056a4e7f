//! The four-wide SIMD contact solve of the soft step (`SolverParams::simd`) against the
//! scalar one: a 10-box stack and a 20-row pyramid stand for 2000 steps with SIMD on
//! (drift under 1 cm after settling), and the SIMD and scalar runs end at the same poses.
mod common;
use carom_dynamics::collision::math::{Real, Vec3};
use carom_dynamics::SolverKind;
use common::*;

const SETTLE: usize = 60;

/// Returns (drift after settling, final positions).
fn run(simd: bool, pyr: bool, n_steps: usize) -> (Real, Vec<Vec3>) {
    let (mut sim, boxes) = if pyr {
        pyramid(SolverKind::SoftStep, 20)
    } else {
        stack(SolverKind::SoftStep, 10)
    };
    let mut p = *sim.world.params();
    p.sleep.enabled = false;
    p.solver.simd = simd;
    sim.world.set_params(p).unwrap();
    for _ in 0..SETTLE {
        sim.step();
    }
    let settled: Vec<Vec3> = boxes.iter().map(|&b| sim.pos(b)).collect();
    for _ in SETTLE..n_steps {
        sim.step();
    }
    let drift = max_drift(&sim, &boxes, &settled);
    (drift, boxes.iter().map(|&b| sim.pos(b)).collect())
}

fn check(pyr: bool) {
    let n = steps(2000, 300);
    let (drift, on) = run(true, pyr, n);
    let (drift_off, off) = run(false, pyr, n);
    eprintln!("pyramid={pyr} steps={n} drift simd={drift:.5} m scalar={drift_off:.5} m");
    assert!(drift < 0.01, "SIMD drift {drift}");
    assert!(drift_off < 0.01, "scalar drift {drift_off}");
    let apart = on
        .iter()
        .zip(&off)
        .map(|(a, b)| (*a - *b).length())
        .fold(0.0, Real::max);
    assert!(apart < 0.01, "SIMD and scalar runs end {apart} m apart");
}

#[test]
fn ten_box_stack_stands_with_simd() {
    check(false);
}

#[test]
fn pyramid_stands_with_simd() {
    check(true);
}
