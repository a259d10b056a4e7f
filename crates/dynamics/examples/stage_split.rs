//! Mean and median wall time of every pipeline stage of one `carom-scenes` scene (sleeping off,
//! one thread unless told), to see where a step goes before profiling deeper. The last line,
//! "(prepare)", is the part of "solver" that prepares the contacts and joints.
//!
//! `cargo run --release -p carom-dynamics --example stage_split -- [scene 1–8] [steps]
//! [threads] [sleep]` (`sleep` turns sleeping on; the figures then cover steps 300 on,
//! when most bodies rest, and the last line counts the awake dynamic bodies).

use carom_dynamics::{PipelineParams, World};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let number: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(2);
    let steps: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(300);
    let threads: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(1);
    let sleep = args.next().is_some_and(|s| s == "sleep");
    let scene = carom_scenes::bullet::scene(number).ok_or("scene number must be 1–8")?;
    let mut params = PipelineParams::default();
    params.dynamics.sleep.enabled = sleep;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    let mut world = World::from_scene_with(&scene, params)?;
    let names = [
        "sync",
        "broadphase",
        "narrowphase",
        "contacts",
        "solver",
        "integrate",
        "islands",
        "total",
        "(prepare)",
    ];
    let mut t: Vec<Vec<f64>> = vec![vec![]; names.len()];
    let (mut pairs, mut manifolds, mut points) = (0, 0, 0);
    for step in 0..steps {
        let r = pool.install(|| world.step(1.0 / 60.0))?;
        if sleep && step < 300 {
            continue;
        }
        let s = &r.timings;
        let all = [
            s.sync,
            s.broadphase,
            s.narrowphase,
            s.contacts,
            s.solver,
            s.integrate,
            s.islands,
            s.total,
            // Inside "solver": the contacts' and joints' preparation and the stage plan.
            r.dynamics.timings.prepare,
        ];
        for (v, d) in t.iter_mut().zip(all) {
            v.push(d.as_secs_f64() * 1e3);
        }
        (pairs, manifolds, points) = (r.pairs, r.manifolds, r.contact_points);
    }
    for (n, v) in names.iter().zip(&mut t) {
        let mean = v.iter().sum::<f64>() / v.len() as f64;
        v.sort_by(f64::total_cmp);
        println!("{n:>12}: {mean:.3} ms mean, {:.3} median", v[v.len() / 2]);
    }
    println!("last step: {pairs} pairs, {manifolds} manifolds, {points} contact points");
    if sleep {
        println!("sleeping bodies at the end: {}", world.sleeping_count());
    }
    Ok(())
}
