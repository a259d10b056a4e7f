//! Runs one `carom-scenes` scene on one thread, sleeping off, and prints the per-stage
//! time and the final state hash: a small, repeatable target for `valgrind --tool=callgrind`
//! and `perf` when working on the solver (the hash shows whether a change kept the bits).
//!
//! `cargo run --release -p carom-dynamics --example solver_profile -- [scene 1–8] [steps]`
//! (`CAROM_SOLVER_SIMD=off` selects the scalar contact solve.)

use carom_dynamics::{PipelineParams, World};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let number: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(2);
    let steps: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(60);
    let scene = carom_scenes::bullet::scene(number).ok_or("scene number must be 1–8")?;
    let mut params = PipelineParams::default();
    params.dynamics.sleep.enabled = false;
    params.dynamics.parallel = false;
    params.dynamics.solver.simd = std::env::var("CAROM_SOLVER_SIMD").map_or(true, |v| v != "off");
    let mut world = World::from_scene_with(&scene, params)?;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let (mut solver, mut integrate, mut total) = (0.0, 0.0, 0.0);
    pool.install(|| -> Result<(), carom_dynamics::collision::CaromError> {
        for _ in 0..steps {
            let t = world.step(scene.dt)?.timings;
            solver += (t.solver + t.islands).as_secs_f64();
            integrate += t.integrate.as_secs_f64();
            total += t.total.as_secs_f64();
        }
        Ok(())
    })?;
    let per = |s: f64| 1e3 * s / steps as f64;
    println!(
        "scene {number}, {steps} steps: {:.3} ms/step, solver+islands {:.3}, integrate {:.3}; \
         state hash {:016x}",
        per(total),
        per(solver),
        per(integrate),
        world.dynamics().state_hash()
    );
    Ok(())
}
