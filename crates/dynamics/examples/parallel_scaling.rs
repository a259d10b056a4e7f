//! Two-thread speed-up of one `carom-scenes` scene, measured so that a loaded machine hurts
//! both sides alike: two copies of the scene (sleeping off), one stepped in a one-thread
//! rayon pool and one in a `threads`-thread pool, are stepped alternately, step by step.
//! Both do exactly the same work at each step (the results are bit-identical whatever the
//! thread count, checked here through the state hashes), so each step gives one ratio of
//! wall times taken within milliseconds of each other. Prints the medians of the per-step
//! times, the median of the per-step ratios, and the whole-step and per-stage (solver,
//! narrowphase) ratios. As a control of how much of a second core the machine gives, each
//! step is followed by the same embarrassingly parallel loop (sines, about 1 ms on one
//! thread) in both pools: its median ratio is the speed-up the machine allows at that time
//! for compute-bound work. A second control streams an 8 MB buffer (read, scale, write back,
//! several times the cores' L2): its ratio is what the machine's memory bandwidth allows a
//! stage that streams data out of cache (on the 2-core VM of the bench, about 1.1x against
//! 1.7x for the compute control).
//!
//! A third copy is stepped in the same pool with `PipelineParams::spin_workers` off (the
//! pool's other threads then sleep between the step's parallel loops), also step by step, so
//! the line "without spinning workers" compares the two policies under the same conditions.
//!
//! `cargo run --release -p carom-dynamics --example parallel_scaling -- [scene 1–8] [steps]
//! [threads]`

use carom_dynamics::{PipelineParams, World};
use std::time::Instant;

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        return f64::NAN;
    }
    v[v.len() / 2]
}

/// The control workload: a parallel sum of sines (no allocation, no shared writes).
fn control() -> f64 {
    use rayon::prelude::*;
    (0..200_000u32)
        .into_par_iter()
        .with_min_len(4096)
        .map(|i| (i as f64 * 1e-3).sin())
        .sum()
}

/// The memory-bound control: one pass of `x ← 1.0001 x + 0.5` over `buf`, in chunks.
fn stream(buf: &mut [f32]) {
    use rayon::prelude::*;
    buf.par_chunks_mut(16_384)
        .for_each(|c| c.iter_mut().for_each(|x| *x = *x * 1.0001 + 0.5));
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let number: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(2);
    let steps: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(300);
    let threads: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(2);
    let scene = carom_scenes::bullet::scene(number).ok_or("scene number must be 1–8")?;
    let mut params = PipelineParams::default();
    params.dynamics.sleep.enabled = false;
    let pools = [
        rayon::ThreadPoolBuilder::new().num_threads(1).build()?,
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()?,
    ];
    let mut worlds = [
        World::from_scene_with(&scene, params)?,
        World::from_scene_with(&scene, params)?,
    ];
    let mut no_spin = World::from_scene_with(
        &scene,
        PipelineParams {
            spin_workers: false,
            ..params
        },
    )?;
    let mut no_spin_times = vec![];
    // Per side: whole step, solver (+ islands), narrowphase, per step.
    let mut times = [[vec![], vec![], vec![]], [vec![], vec![], vec![]]];
    let mut ratios = vec![];
    let mut controls = vec![];
    let mut streams = vec![];
    let mut buf = vec![1.0f32; 2 << 20];
    // Per side: the solver's sub-stages (islands, prepare, forces, warm start, solve,
    // integrate, relax, restitution, store), per step.
    let mut subs: [[Vec<f64>; 9]; 2] = Default::default();
    for step in 0..steps {
        let mut wall = [0.0; 2];
        // The order alternates so that each two-thread copy follows the one-thread step
        // (its pool idle meanwhile) as often as it follows the other two-thread copy or the
        // controls: without spinning, one thread, with spinning; then with, one, without.
        let mut no_spin_step =
            |pool: &rayon::ThreadPool| -> Result<(), Box<dyn std::error::Error>> {
                let t0 = Instant::now();
                pool.install(|| no_spin.step(scene.dt))?;
                no_spin_times.push(t0.elapsed().as_secs_f64() * 1e3);
                Ok(())
            };
        let even = step % 2 == 0;
        if even {
            no_spin_step(&pools[1])?;
        }
        let sides = if even { [0, 1] } else { [1, 0] };
        for side in sides {
            let w = &mut worlds[side];
            let t0 = Instant::now();
            let (t, d) = pools[side]
                .install(|| w.step(scene.dt).map(|r| (r.timings, r.dynamics.timings)))?;
            let parts = [
                d.islands,
                d.prepare,
                d.forces,
                d.warm_start,
                d.solve,
                d.integrate,
                d.relax,
                d.restitution,
                d.store,
            ];
            for (v, p) in subs[side].iter_mut().zip(parts) {
                v.push(p.as_secs_f64() * 1e3);
            }
            wall[side] = t0.elapsed().as_secs_f64() * 1e3;
            times[side][0].push(wall[side]);
            times[side][1].push((t.solver + t.islands).as_secs_f64() * 1e3);
            times[side][2].push(t.narrowphase.as_secs_f64() * 1e3);
        }
        if !even {
            no_spin_step(&pools[1])?;
        }
        ratios.push(wall[0] / wall[1]);
        let mut c = [0.0; 2];
        for side in 0..2 {
            let t0 = Instant::now();
            std::hint::black_box(pools[side].install(control));
            c[side] = t0.elapsed().as_secs_f64();
        }
        controls.push(c[0] / c[1]);
        for side in 0..2 {
            let t0 = Instant::now();
            pools[side].install(|| stream(&mut buf));
            c[side] = t0.elapsed().as_secs_f64();
        }
        streams.push(c[0] / c[1]);
    }
    let same = worlds[0].dynamics().state_hash() == worlds[1].dynamics().state_hash();
    let m: Vec<[f64; 3]> = times
        .iter_mut()
        .map(|side| [0, 1, 2].map(|k| median(&mut side[k])))
        .collect();
    println!(
        "scene {number}, {steps} steps, 1 vs {threads} threads (medians, ms/step): \
         step {:.3} vs {:.3} = {:.2}x, solver {:.3} vs {:.3} = {:.2}x, narrowphase {:.3} vs \
         {:.3} = {:.2}x; median per-step ratio {:.2}x; control {:.2}x (compute), {:.2}x \
         (8 MB stream); bit-identical: {same}",
        m[0][0],
        m[1][0],
        m[0][0] / m[1][0],
        m[0][1],
        m[1][1],
        m[0][1] / m[1][1],
        m[0][2],
        m[1][2],
        m[0][2] / m[1][2],
        median(&mut ratios),
        median(&mut controls),
        median(&mut streams),
    );
    let names = [
        "islands",
        "prepare",
        "forces",
        "warm start",
        "solve",
        "integrate",
        "relax",
        "restitution",
        "store",
    ];
    for (k, name) in names.iter().enumerate() {
        let a = median(&mut subs[0][k]);
        let b = median(&mut subs[1][k]);
        println!("  {name:<12} {a:.3} vs {b:.3} ms = {:.2}x", a / b);
    }
    let r = median(&mut no_spin_times);
    println!(
        "  without spinning workers: {r:.3} ms/step = {:.2}x over one thread (with: {:.2}x)",
        m[0][0] / r,
        m[0][0] / m[1][0]
    );
    let same = same && no_spin.dynamics().state_hash() == worlds[0].dynamics().state_hash();
    if !same {
        return Err("the runs differ".into());
    }
    Ok(())
}
