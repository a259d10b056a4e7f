//! The 500-ray batch of "raytests" (scene 7) alone, one thread: steps the scene, then casts
//! the batch `batches` times as `carom-bench` does (one `World::query`, 500 closest-hit
//! rays), printing the median time per batch and a checksum of the hits. A small target for
//! `valgrind --tool=callgrind` when working on world ray casts.
//!
//! `cargo run --release -p carom-dynamics --example ray_batch -- [steps] [batches] [warm]`
//!
//! With `warm`, no step runs between the batches: the batch finds the caches as the last
//! batch left them, which tells how much of its time is memory traffic.

use carom_dynamics::{PipelineParams, World};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let steps: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(300);
    let batches: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(200);
    let warm = args.next().is_some_and(|s| s == "warm");
    let scene = carom_scenes::bullet::scene(7).ok_or("no scene 7")?;
    let mut params = PipelineParams::default();
    params.dynamics.sleep.enabled = false;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let mut world = World::from_scene_with(&scene, params)?;
    for _ in 0..steps {
        pool.install(|| world.step(1.0 / 60.0))?;
    }
    let mut times = Vec::with_capacity(batches);
    let mut checksum = 0.0f64;
    let mut hits = 0;
    let mut build = Vec::with_capacity(batches);
    for _ in 0..batches {
        // A step between batches, as in the benchmark: the query's tree is refitted or
        // rebuilt for the moved bodies.
        if !warm {
            pool.install(|| world.step(1.0 / 60.0))?;
        }
        let t = std::time::Instant::now();
        let query = world.query()?;
        build.push(t.elapsed().as_secs_f64() * 1e3);
        for &(from, to) in &scene.rays {
            let d = to - from;
            if let Some(h) = query.raycast(from, d, d.length(), u32::MAX)? {
                hits += 1;
                checksum += h.hit.distance as f64;
            }
        }
        drop(query);
        times.push(t.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    build.sort_by(f64::total_cmp);
    println!(
        "{} batches of {} rays after {steps} steps: median {:.3} ms/batch ({:.3} ms of it the \
         query's tree), {} hits, distance sum {checksum:.6}",
        batches,
        scene.rays.len(),
        times[times.len() / 2],
        build[build.len() / 2],
        hits / batches.max(1),
    );
    Ok(())
}
