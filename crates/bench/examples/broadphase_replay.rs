//! The broadphase input of a benchmark scene, recorded once and replayed through one
//! broadphase method alone, so an instruction counter can compare methods and settings on the
//! boxes the pipeline really produces, independently of the machine's load:
//!
//! ```sh
//! cargo build --release -p carom-bench --example broadphase_replay
//! ./target/release/examples/broadphase_replay record 1 300 /tmp/scene1.bp
//! valgrind --tool=callgrind --collect-atstart=no --toggle-collect='*replay_steps*' \
//!     ./target/release/examples/broadphase_replay replay /tmp/scene1.bp tree
//! callgrind_annotate --inclusive=yes callgrind.out.<pid> | grep replay_steps
//! ```
//!
//! `record <scene> <steps> <file>` steps the scene (sleeping off, one thread) and writes,
//! after every step, each collision object's box (shape box grown by its speculative margin)
//! and position. `replay <file> <method> [margin] [motion_scale] [refit 0|1] [optimize] [full_sweep_fraction]` creates the
//! proxies at the recorded initial boxes, then per step moves every non-static proxy
//! (displacement = change of position, as `CollisionWorld::update` does) and updates the
//! pairs; `margin` (default `TreeBroadPhase::DEFAULT_MARGIN`, the library's), `motion_scale` and `refit` tune the `tree` method. It prints the pair
//! count of the last step and a checksum of all pair changes, equal for every method.

use carom_collision::broadphase::{
    AnyBroadPhase, BroadPhase, Filter, InsertStrategy, Method, ProxyHandle, TreeBroadPhase,
};
use carom_collision::math::{Aabb, Real, Vec3};
use carom_dynamics::{PipelineParams, World};
use std::io::{Read, Write};

struct Recording {
    filters: Vec<Filter>,
    /// Per step (0 = before the first step), per object: box and position.
    frames: Vec<Vec<(Aabb, Vec3)>>,
}

fn snapshot(world: &World) -> Vec<(Aabb, Vec3)> {
    world
        .collision()
        .iter()
        .map(|(_, o)| (o.aabb, o.pose.translation))
        .collect()
}

// Stored as f32 in both precisions (the cast is a no-op in the f32 build).
#[allow(clippy::unnecessary_cast)]
fn record(scene: usize, steps: usize, path: &str) -> Result<(), String> {
    let scene = carom_scenes::bullet::scene(scene).ok_or("unknown scene")?;
    let mut params = PipelineParams::default();
    params.dynamics.sleep.enabled = false;
    params.dynamics.parallel = false;
    let mut world = World::from_scene_with(&scene, params).map_err(|e| e.to_string())?;
    let filters: Vec<Filter> = world.collision().iter().map(|(_, o)| o.filter).collect();
    let mut frames = vec![snapshot(&world)];
    for _ in 0..steps {
        world.step(scene.dt).map_err(|e| e.to_string())?;
        frames.push(snapshot(&world));
    }
    let mut out = Vec::new();
    let mut put = |x: u32| out.extend_from_slice(&x.to_le_bytes());
    put(filters.len() as u32);
    put(frames.len() as u32);
    for f in &filters {
        put(f.group);
        put(f.mask);
        put(f.is_static as u32);
    }
    for frame in &frames {
        for (b, p) in frame {
            for v in [b.min, b.max, *p] {
                for c in v.to_array() {
                    put((c as f32).to_bits());
                }
            }
        }
    }
    std::fs::File::create(path)
        .and_then(|mut f| f.write_all(&out))
        .map_err(|e| e.to_string())
}

fn load(path: &str) -> Result<Recording, String> {
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .and_then(|mut f| f.read_to_end(&mut bytes))
        .map_err(|e| e.to_string())?;
    let mut words = bytes
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]));
    let mut next = || words.next().ok_or("truncated recording");
    let (n, steps) = (next()? as usize, next()? as usize);
    let mut filters = Vec::with_capacity(n);
    for _ in 0..n {
        let (group, mask, is_static) = (next()?, next()?, next()? != 0);
        filters.push(Filter {
            group,
            mask,
            is_static,
        });
    }
    let mut frames = Vec::with_capacity(steps);
    for _ in 0..steps {
        let mut frame = Vec::with_capacity(n);
        for _ in 0..n {
            let mut v = [Vec3::ZERO; 3];
            for x in &mut v {
                let mut c = [0.0 as Real; 3];
                for y in &mut c {
                    *y = f32::from_bits(next()?) as Real;
                }
                *x = Vec3::from_array(c);
            }
            frame.push((Aabb::new(v[0], v[1]), v[2]));
        }
        frames.push(frame);
    }
    Ok(Recording { filters, frames })
}

/// Moves every non-static proxy through the recorded frames; returns the last pair count and
/// a checksum of every added and removed pair.
#[inline(never)]
fn replay_steps(bp: &mut AnyBroadPhase, rec: &Recording, handles: &[ProxyHandle]) -> (usize, u64) {
    let mut sum = 0u64;
    for s in 1..rec.frames.len() {
        for (i, &h) in handles.iter().enumerate() {
            if rec.filters[i].is_static {
                continue;
            }
            let (aabb, p) = rec.frames[s][i];
            let disp = p - rec.frames[s - 1][i].1;
            bp.update_proxy(h, aabb, disp)
                .expect("recorded boxes are valid");
        }
        let ch = bp.update_pairs();
        for (n, list) in [&ch.added, &ch.removed].into_iter().enumerate() {
            for &(a, b) in list {
                let k = ((a.index as u64) << 32 | b.index as u64) ^ ((n as u64) << 63);
                sum = sum.wrapping_mul(0x100_0000_01b3).wrapping_add(k ^ s as u64);
            }
        }
    }
    (bp.pair_count(), sum)
}

fn replay(path: &str, method: &str, args: &[String]) -> Result<(), String> {
    let rec = load(path)?;
    let method: Method = method
        .parse()
        .map_err(|e: carom_collision::CaromError| e.to_string())?;
    let mut bp = AnyBroadPhase::new(method);
    if let AnyBroadPhase::Tree(t) = &mut bp {
        let margin: Real = args
            .first()
            .and_then(|a| a.parse().ok())
            .unwrap_or(TreeBroadPhase::DEFAULT_MARGIN);
        let strategy = if method == Method::TreeManhattan {
            InsertStrategy::Manhattan
        } else {
            InsertStrategy::SurfaceArea
        };
        *t = TreeBroadPhase::new(strategy, margin);
        if let Some(scale) = args.get(1).and_then(|a| a.parse().ok()) {
            t.set_motion_scale(scale);
        }
        if let Some(refit) = args.get(2) {
            t.refit_moving = refit != "0";
        }
        if let Some(n) = args.get(3).and_then(|a| a.parse().ok()) {
            t.optimize_per_update = n;
        }
        if let Some(f) = args.get(4).and_then(|a| a.parse().ok()) {
            t.full_sweep_fraction = f;
        }
    }
    let handles: Vec<ProxyHandle> = rec.frames[0]
        .iter()
        .zip(&rec.filters)
        .map(|(&(aabb, _), &f)| bp.create_proxy(aabb, f).expect("valid box"))
        .collect();
    bp.update_pairs();
    let (pairs, sum) = replay_steps(&mut bp, &rec, &handles);
    if let AnyBroadPhase::Tree(t) = &bp {
        println!("tree: {} candidate pairs at the end", t.candidate_count());
    }
    println!(
        "{method:?} {args:?}: {} steps, {pairs} pairs at the end, change checksum {sum:016x}",
        rec.frames.len() - 1
    );
    Ok(())
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let result = match args.get(1).map(String::as_str) {
        Some("record") if args.len() >= 5 => match (args[2].parse(), args[3].parse()) {
            (Ok(scene), Ok(steps)) => record(scene, steps, &args[4]),
            _ => Err("record <scene> <steps> <file>".into()),
        },
        Some("replay") if args.len() >= 4 => replay(&args[2], &args[3], &args[4..]),
        _ => Err("usage: record <scene> <steps> <file> | replay <file> <method> [margin] [motion_scale] [refit 0|1] [optimize] [full_sweep_fraction]".into()),
    };
    if let Err(e) = result {
        eprintln!("{e}");
        std::process::exit(1);
    }
}
