//! Reproducer for the soft-step joint accuracy: pendulum period, amplitude and energy.
//! `cargo run --release -p carom-dynamics --example pendulum_repro`
use carom_dynamics::collision::math::{consts::PI, Isometry, Real, Vec3};
use carom_dynamics::collision::shape::{Shape, Sphere};
use carom_dynamics::*;
use std::sync::Arc;

/// Returns (relative period error, late amplitude, largest rod-length error, largest energy
/// gain over m g l) of a sphere of radius `r` pinned 1 m from its centre.
fn run(kind: SolverKind, hinge: bool, r: Real, dt: Real, theta0: Real) -> [Real; 4] {
    let (g, l) = (9.81 as Real, 1.0 as Real);
    let mut p = WorldParams {
        gravity: Vec3::new(0.0, -g, 0.0),
        ..Default::default()
    };
    p.solver.kind = kind;
    p.sleep.enabled = false;
    let mut w = DynamicsWorld::new(p).unwrap();
    let pivot = w
        .create_body(&BodyDesc {
            body_type: BodyType::Static,
            pose: Isometry::from_translation(Vec3::new(0.0, 2.0, 0.0)),
            ..Default::default()
        })
        .unwrap();
    let s: Arc<Shape> = Arc::new(Sphere::new(r).unwrap().into());
    let at = Vec3::new(l * theta0.sin(), 2.0 - l * theta0.cos(), 0.0);
    let bob = w
        .create_body(&BodyDesc::dynamic(
            s,
            Isometry::from_translation(at),
            1000.0,
        ))
        .unwrap();
    let frame_b = Isometry::from_translation(Vec3::new(0.0, 2.0, 0.0) - at);
    let kind_j = if hinge {
        JointKind::Hinge {
            limits: None,
            motor: None,
        }
    } else {
        JointKind::Ball
    };
    w.create_joint(&JointDesc::new(
        pivot,
        bob,
        Isometry::IDENTITY,
        frame_b,
        kind_j,
    ))
    .unwrap();
    let m = 1.0 / w.bodies().inv_mass(bob).unwrap();
    let energy = |w: &DynamicsWorld| {
        w.bodies().kinetic_energy() + m * g * w.bodies().center_of_mass(bob).unwrap().y
    };
    let e0 = energy(&w);
    let expected = 2.0 * PI * ((0.4 * r * r + l * l) / (g * l)).sqrt();
    let mut crossings = Vec::new();
    let mut last_x = at.x;
    let (mut amp, mut len_err, mut gain): (Real, Real, Real) = (0.0, 0.0, 0.0);
    for i in 0..(10.0 * expected / dt) as usize {
        w.step(dt, &mut []).unwrap();
        let c = w.bodies().center_of_mass(bob).unwrap();
        if i as Real * dt > 8.0 * expected {
            amp = amp.max((c.x / l).clamp(-1.0, 1.0).asin().abs());
        }
        len_err = len_err.max(((c - Vec3::new(0.0, 2.0, 0.0)).length() - l).abs());
        gain = gain.max((energy(&w) - e0) / (m * g * l));
        if last_x > 0.0 && c.x <= 0.0 {
            crossings.push((i as Real + last_x / (last_x - c.x)) * dt);
        }
        last_x = c.x;
    }
    let period = (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as Real;
    [period / expected - 1.0, amp, len_err, gain]
}

fn main() {
    let theta0: Real = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(0.08);
    for kind in [SolverKind::SoftStep, SolverKind::SequentialImpulse] {
        for hinge in [false, true] {
            for r in [0.02, 0.2] {
                for dt in [1.0 / 60.0, 1.0 / 240.0] {
                    let [e, amp, le, gain] = run(kind, hinge, r, dt, theta0);
                    println!(
                        "{kind:?} hinge={hinge} r={r} dt=1/{:.0}: period {:+.3}% amp {amp:.4} \
                         len err {le:.1e} max energy gain {gain:+.1e} mgl",
                        1.0 / dt,
                        e * 100.0
                    );
                }
            }
        }
    }
}
