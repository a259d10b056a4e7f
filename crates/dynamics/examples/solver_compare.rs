//! Stability and speed of the two solvers on the stacking scenes (10-box stack, 20-row
//! pyramid), with the analytic test contacts of `tests/common`.
//!
//! `cargo run --release -p carom-dynamics --example solver_compare -- [steps] [seq]`
//! (`seq`: solve colours sequentially instead of with rayon).
//!
//! Prints, per solver and scene: the settling displacement (first second), the drift after
//! settling, and the solver's time per step (`StepReport::timings.total`, contact
//! generation excluded).
#[path = "../tests/common/mod.rs"]
mod common;

use carom_dynamics::collision::math::Vec3;
use carom_dynamics::SolverKind;
use common::*;

fn main() {
    let steps: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(2000);
    let parallel = std::env::args().nth(2).as_deref() != Some("seq");
    let configs = [
        (SolverKind::SoftStep, 10),
        (SolverKind::SequentialImpulse, 10),
        (SolverKind::SequentialImpulse, 40),
    ];
    println!("scene      solver             iters  settle_m  drift_m   solver_ms/step");
    for pyr in [false, true] {
        for (kind, iterations) in configs {
            let (mut sim, boxes) = if pyr {
                pyramid(kind, 20)
            } else {
                stack(kind, 10)
            };
            let mut p = *sim.world.params();
            p.sleep.enabled = false;
            p.parallel = parallel;
            p.solver.velocity_iterations = iterations;
            sim.world.set_params(p).unwrap();
            let start: Vec<Vec3> = boxes.iter().map(|&b| sim.pos(b)).collect();
            for _ in 0..60 {
                sim.step();
            }
            let settle = max_drift(&sim, &boxes, &start);
            let settled: Vec<Vec3> = boxes.iter().map(|&b| sim.pos(b)).collect();
            let mut solver_time = std::time::Duration::ZERO;
            for _ in 60..steps {
                sim.step();
                solver_time += sim.last_report.timings.total;
            }
            let drift = max_drift(&sim, &boxes, &settled);
            let ms = solver_time.as_secs_f64() * 1e3 / (steps - 60) as f64;
            let name = if pyr { "pyramid20" } else { "stack10" };
            println!(
                "{name:<10} {:<18} {iterations:>5}  {settle:>8.4}  {drift:>8.4}  {ms:>8.3}",
                format!("{kind:?}")
            );
            if pyr {
                println!("    last step: {:?}", sim.last_report.timings);
            }
        }
    }
}
