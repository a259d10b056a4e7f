//! Physical invariants through the full pipeline (real broadphase and narrowphase, not
//! hand-made contacts): stacks stand, a sliding box stops where Coulomb friction says.
mod pipeline;
use carom_dynamics::collision::math::{Real, Vec3};
use carom_dynamics::*;
use pipeline::*;

const SETTLE: usize = 60;
const DT: Real = 1.0 / 60.0;

/// Runs `n_steps` with sleeping off; returns (settling displacement, drift after settling).
fn run(w: &mut World, boxes: &[BodyHandle], n_steps: usize, name: &str) -> (Real, Real) {
    let start: Vec<Vec3> = boxes.iter().map(|&b| pos(w, b)).collect();
    for _ in 0..SETTLE {
        w.step(DT).unwrap();
    }
    let settled: Vec<Vec3> = boxes.iter().map(|&b| pos(w, b)).collect();
    let settle = max_drift(w, boxes, &start);
    let t = std::time::Instant::now();
    for _ in SETTLE..n_steps {
        w.step(DT).unwrap();
    }
    let ms = t.elapsed().as_secs_f64() * 1e3 / (n_steps - SETTLE).max(1) as f64;
    let drift = max_drift(w, boxes, &settled);
    eprintln!("{name}: steps={n_steps} settle={settle:.4} m drift={drift:.4} m ms/step={ms:.3}");
    (settle, drift)
}

#[test]
fn ten_box_stack_stands_for_2000_steps() {
    let mut w = world(false);
    ground(&mut w, 0.5);
    let boxes = box_column(&mut w, 10);
    let (settle, drift) = run(&mut w, &boxes, 2000, "stack10");
    assert!(
        drift < 0.01 && settle < 0.05,
        "settle {settle} drift {drift}"
    );
}

#[test]
fn twenty_row_pyramid_stands() {
    let mut w = world(false);
    ground(&mut w, 0.5);
    let pitch: Real = 1.05;
    let mut boxes = Vec::new();
    for r in 0..20 {
        let count = 20 - r;
        let x0 = -0.5 * pitch * (count as Real - 1.0);
        for j in 0..count {
            let p = Vec3::new(x0 + pitch * j as Real, 0.5 + r as Real, 0.0);
            boxes.push(dyn_box(&mut w, Vec3::splat(0.5), p));
        }
    }
    let (settle, drift) = run(&mut w, &boxes, steps(2000, 400), "pyramid20");
    assert!(
        drift < 0.01 && settle < 0.08,
        "settle {settle} drift {drift}"
    );
}

/// A box launched at v₀ on a flat floor stops after d = v₀² / (2 μ g).
#[test]
fn sliding_box_stops_where_coulomb_says() {
    for mu in [0.2 as Real, 0.5] {
        let mut w = world(false);
        let g: Real = 10.0;
        // Friction mixes by geometric mean: both surfaces get μ.
        ground(&mut w, mu);
        let mut d = BodyDesc::dynamic(
            cuboid(Vec3::splat(0.25)),
            carom_dynamics::collision::math::Isometry::from_translation(Vec3::new(0.0, 0.25, 0.0)),
            1000.0,
        );
        d.friction = mu;
        let b = w.add_body(&d).unwrap();
        for _ in 0..30 {
            w.step(DT).unwrap();
        }
        let v0: Real = 4.0;
        w.bodies_mut()
            .set_linear_velocity(b, Vec3::new(v0, 0.0, 0.0))
            .unwrap();
        let x0 = pos(&w, b).x;
        for _ in 0..240 {
            w.step(DT).unwrap();
        }
        let dist = pos(&w, b).x - x0;
        let expected = v0 * v0 / (2.0 * mu * g);
        eprintln!("mu={mu}: slid {dist:.4} m, Coulomb {expected:.4} m");
        assert!(
            (dist - expected).abs() < 0.05 * expected,
            "mu {mu}: slid {dist}, expected {expected}"
        );
        assert!(w.bodies().linear_velocity(b).unwrap().length() < 1e-2);
        assert!(pos(&w, b).y > 0.2 && pos(&w, b).y < 0.26);
    }
}
