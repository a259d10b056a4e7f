//! `make demo`: builds Carom's shapes and the benchmark scenes and prints what they are.
//! Later capabilities (queries, broadphase, dynamics) extend this report.

use carom_collision::math::{Isometry, Quat, Real, Vec3};
use carom_collision::shape::*;
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
    Ok(())
}
