//! The sanity figure of a scene run (issue 8: "final mean height, resting bodies, nothing
//! below the ground, stacks standing, ragdolls at rest"), computed the same way for every
//! engine from the dynamic bodies' final states and their initial positions.

use super::engine::BodyState;
use carom_collision::shape::Shape;
use carom_scenes::Scene;
use serde::Serialize;

/// A body slower than this (m/s) counts as resting.
pub const REST_SPEED: f64 = 0.1;

/// Sanity figures of one run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct Sanity {
    /// Dynamic bodies.
    pub bodies: usize,
    /// Mean height (y) of the dynamic bodies at the end.
    pub mean_height: f64,
    /// Bodies slower than [`REST_SPEED`] at the end.
    pub resting: usize,
    /// Bodies whose centre is below [`floor`] (fell through the ground or off the world).
    pub below_ground: usize,
    /// Largest distance any body moved from its start (the stack scene's "stays standing").
    pub max_drift: f64,
    /// Largest final speed (explosions show here).
    pub max_speed: f64,
    /// Bodies with a non-finite position or velocity.
    pub non_finite: usize,
}

/// The height under which a body's centre means it went through the ground: 0.5 m under the
/// ground box's top face or the plane, 5 m under the landscape's lowest point (y = −46.8 after
/// its −25 m translation).
pub fn floor(scene: &Scene) -> f64 {
    let has_mesh = scene
        .bodies
        .iter()
        .any(|b| b.is_static() && matches!(*b.shape, Shape::TriMesh(_)));
    if has_mesh {
        -51.8
    } else {
        -0.5
    }
}

/// Computes the figures from the initial and final states (same order, same length).
pub fn sanity(scene: &Scene, initial: &[BodyState], last: &[BodyState]) -> Sanity {
    let floor = floor(scene);
    let mut s = Sanity {
        bodies: last.len(),
        ..Sanity::default()
    };
    let norm = |v: [f64; 3]| (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let mut finite = 0usize;
    for (a, b) in initial.iter().zip(last) {
        let ok = b.position.iter().chain(&b.velocity).all(|x| x.is_finite());
        if !ok {
            s.non_finite += 1;
            continue;
        }
        finite += 1;
        s.mean_height += b.position[1];
        let speed = norm(b.velocity);
        s.resting += usize::from(speed < REST_SPEED);
        s.below_ground += usize::from(b.position[1] < floor);
        let d = [0, 1, 2].map(|k| b.position[k] - a.position[k]);
        s.max_drift = s.max_drift.max(norm(d));
        s.max_speed = s.max_speed.max(speed);
    }
    s.non_finite += initial.len().abs_diff(last.len());
    if finite > 0 {
        s.mean_height /= finite as f64;
    }
    s
}

/// Problems with a short run of `steps` steps (for the test mode): non-finite states, bodies
/// under the ground, bodies faster than free fall allows plus `slack` m/s, and for the stack
/// scene any body moved more than 0.5 m. Empty when everything is sane.
pub fn short_run_problems(scene: &Scene, s: &Sanity, steps: usize, slack: f64) -> Vec<String> {
    let mut out = Vec::new();
    if s.non_finite > 0 {
        out.push(format!("{} bodies non-finite or missing", s.non_finite));
    }
    if s.below_ground > 0 {
        out.push(format!("{} bodies below the ground", s.below_ground));
    }
    let g = scene.gravity.length() as f64;
    let free_fall = g * scene.dt as f64 * steps as f64;
    if s.max_speed > free_fall + slack {
        out.push(format!(
            "max speed {:.2} m/s > free fall {free_fall:.2} + {slack}",
            s.max_speed
        ));
    }
    if scene.name == "1000 stack" && s.max_drift > 0.5 {
        out.push(format!("stack moved {:.3} m", s.max_drift));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn st(p: [f64; 3], v: [f64; 3]) -> BodyState {
        BodyState {
            position: p,
            velocity: v,
        }
    }

    #[test]
    fn figures_follow_their_definitions() {
        let scene = carom_scenes::bullet::scene(2).unwrap();
        let a = [st([0.0, 1.0, 0.0], [0.0; 3]), st([5.0, 3.0, 0.0], [0.0; 3])];
        let b = [
            st([0.0, 1.0, 0.3], [0.0, 0.05, 0.0]),
            st([5.0, -2.0, 0.0], [3.0, 4.0, 0.0]),
        ];
        let s = sanity(&scene, &a, &b);
        assert_eq!((s.bodies, s.resting, s.below_ground), (2, 1, 1));
        assert!((s.mean_height - -0.5).abs() < 1e-12);
        assert!((s.max_drift - 5.0).abs() < 1e-12 && (s.max_speed - 5.0).abs() < 1e-12);
        assert_eq!(short_run_problems(&scene, &s, 10, 1.0).len(), 3);
        let nan = [st([f64::NAN, 0.0, 0.0], [0.0; 3]), b[0]];
        let s = sanity(&scene, &a, &nan);
        assert_eq!(s.non_finite, 1);
        assert!(!short_run_problems(&scene, &s, 10, 1.0).is_empty());
    }
}
