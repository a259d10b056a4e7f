//! `make demo`: builds Carom's shapes and the benchmark scenes and prints what they are.
//! Later capabilities (queries, broadphase, dynamics) extend this report.

use carom_collision::math::{Isometry, Quat, Real, Vec3};
use carom_collision::shape::*;
use carom_dynamics::{PipelineTimings, World};
use carom_scenes::bullet;
use std::sync::Arc;
use std::time::Instant;

fn fmt(v: Vec3) -> String {
    format!("({:8.4}, {:8.4}, {:8.4})", v.x, v.y, v.z)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    println!("Carom demo — precision: {}", std::any::type_name::<Real>());
    println!();
    println!("== Shapes (density 1000 kg/m³) ==");
    let taru = carom_scenes::data::taru_points();
    let t0 = Instant::now();
    let hull = ConvexHull::new(&taru)?;
    let hull_ms = t0.elapsed().as_secs_f64() * 1e3;
    let capsule: Arc<Shape> = Arc::new(Capsule::new(0.3, 0.5)?.into());
    let shapes: Vec<(&str, Shape)> = vec![
        ("Sphere(0.5)", Sphere::new(0.5)?.into()),
        (
            "Box(1, 0.5, 0.25)",
            Cuboid::new(Vec3::new(1.0, 0.5, 0.25))?.into(),
        ),
        ("Capsule(0.3, 0.5)", (*capsule).clone()),
        ("Cylinder(0.4, 0.6)", Cylinder::new(0.4, 0.6)?.into()),
        ("Cone(0.5, 0.75)", Cone::new(0.5, 0.75)?.into()),
        ("ConvexHull(Taru)", hull.clone().into()),
        (
            "Capsule scaled (2,1,0.5)",
            capsule.scaled(Vec3::new(2.0, 1.0, 0.5))?,
        ),
    ];
    println!(
        "{:<26} {:>10} {:>11} {:>28} {:>30}",
        "shape", "volume", "mass", "principal inertia", "local AABB half extents"
    );
    for (name, s) in &shapes {
        let mp = s.mass_properties(1000.0);
        let inertia = Vec3::new(
            mp.inertia.x_axis.x,
            mp.inertia.y_axis.y,
            mp.inertia.z_axis.z,
        );
        println!(
            "{:<26} {:>10.5} {:>11.3} {:>28} {:>30}",
            name,
            s.volume(),
            mp.mass,
            fmt(inertia),
            fmt(s.local_aabb().half_extents())
        );
    }
    println!(
        "Taru hull: {} input points -> {} vertices, {} faces, {} edges (built in {:.3} ms)",
        taru.len(),
        hull.vertices().len(),
        hull.faces().len(),
        hull.edges().len(),
        hull_ms
    );

    println!();
    println!("== Support queries: the point of each shape furthest along a direction ==");
    let pose = Isometry::new(Vec3::new(1.0, 2.0, 3.0), Quat::from_rotation_y(0.5));
    let dirs = [Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::new(-1.0, 2.0, 0.5)];
    for (name, s) in &shapes {
        let c = s.as_convex().ok_or("convex")?;
        let pts: Vec<String> = dirs.iter().map(|d| fmt(c.support(*d))).collect();
        println!("{:<26} {}", name, pts.join("  "));
    }
    println!("world AABB of the Taru hull at {:?}:", pose.translation);
    let aabb = Shape::from(hull).aabb(&pose);
    println!("  min {}  max {}", fmt(aabb.min), fmt(aabb.max));

    println!();
    println!("== Bullet's benchmark scenes (built by carom-scenes) ==");
    println!(
        "{:<16} {:>8} {:>8} {:>7} {:>6} {:>11}",
        "scene", "dynamic", "static", "joints", "rays", "build (ms)"
    );
    for n in 1..=8 {
        let t0 = Instant::now();
        let s = bullet::scene(n).ok_or("scene")?;
        let ms = t0.elapsed().as_secs_f64() * 1e3;
        println!(
            "{:<16} {:>8} {:>8} {:>7} {:>6} {:>11.2}",
            s.name,
            s.dynamic_count(),
            s.bodies.len() - s.dynamic_count(),
            s.joints.len(),
            s.rays.len(),
            ms
        );
    }

    println!();
    falling_boxes_demo()?;
    Ok(())
}

/// Simulates Bullet's "3000 fall" scene through the whole pipeline (`carom_dynamics::World`)
/// and prints steps, ms/step, stage times, resting bodies and final heights
/// (`CAROM_DEMO_STEPS` and `CAROM_SUBSTEPS` override the step and substep counts).
fn falling_boxes_demo() -> Result<(), Box<dyn std::error::Error>> {
    let steps: usize = std::env::var("CAROM_DEMO_STEPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(300);
    let scene = bullet::falling_boxes();
    println!(
        "== Simulation: \"{}\" ({} dynamic boxes, dt = 1/{:.0} s, {} threads) ==",
        scene.name,
        scene.dynamic_count(),
        1.0 / scene.dt,
        rayon::current_num_threads()
    );
    let t0 = Instant::now();
    let mut params = carom_dynamics::PipelineParams::default();
    if let Some(n) = std::env::var("CAROM_SUBSTEPS")
        .ok()
        .and_then(|s| s.parse().ok())
    {
        params.dynamics.solver.substeps = n;
    }
    let mut world = World::from_scene_with(&scene, params)?;
    println!("world built in {:.1} ms", t0.elapsed().as_secs_f64() * 1e3);
    let mut per_step = Vec::with_capacity(steps);
    let mut stages = PipelineTimings::default();
    for _ in 0..steps {
        let r = world.step(scene.dt)?;
        per_step.push(r.timings.total.as_secs_f64() * 1e3);
        let t = &r.timings;
        stages.sync += t.sync;
        stages.broadphase += t.broadphase;
        stages.narrowphase += t.narrowphase;
        stages.contacts += t.contacts;
        stages.solver += t.solver;
        stages.integrate += t.integrate;
        stages.islands += t.islands;
        stages.total += t.total;
    }
    let mean = per_step.iter().sum::<f64>() / steps.max(1) as f64;
    let mut sorted = per_step.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted.get(sorted.len() / 2).copied().unwrap_or(0.0);
    let ms = |d: std::time::Duration| d.as_secs_f64() * 1e3 / steps.max(1) as f64;
    println!(
        "steps: {steps}; ms/step: mean {mean:.2}, median {median:.2}, max {:.2}",
        sorted.last().copied().unwrap_or(0.0)
    );
    println!(
        "per stage (ms/step): sync {:.2}, broadphase {:.2}, narrowphase {:.2}, contacts {:.2}, solver {:.2}, integrate {:.2}, islands {:.2}",
        ms(stages.sync),
        ms(stages.broadphase),
        ms(stages.narrowphase),
        ms(stages.contacts),
        ms(stages.solver),
        ms(stages.integrate),
        ms(stages.islands)
    );
    let r = world.last_report();
    println!(
        "last step: {} pairs, {} manifolds, {} contact points",
        r.pairs, r.manifolds, r.contact_points
    );
    let deepest = world
        .collision()
        .narrowphase()
        .manifolds()
        .filter_map(|pc| pc.manifold.min_distance())
        .fold(0.0 as Real, Real::min);
    println!("deepest penetration among contacts: {:.4} m", -deepest);
    let bodies = world.bodies();
    let heights: Vec<Real> = bodies
        .handles()
        .filter(|&h| bodies.inv_mass(h).is_ok_and(|m| m > 0.0))
        .map(|h| bodies.center_of_mass(h).map(|p| p.y))
        .collect::<Result<_, _>>()?;
    let min = heights.iter().copied().fold(Real::INFINITY, Real::min);
    let mean_h = heights.iter().sum::<Real>() / heights.len().max(1) as Real;
    let below = heights.iter().filter(|&&y| y < 0.0).count();
    println!(
        "resting (asleep): {} of {}; centre heights: min {:.3} m, mean {:.3} m (box half height 1 m); below ground: {}",
        world.sleeping_count(),
        heights.len(),
        min,
        mean_h,
        below
    );
    Ok(())
}
