//! Shared helpers of the broadphase tests: a deterministic RNG and scene generators.
#![allow(dead_code)]

use carom_collision::math::{Aabb, Real, Vec3};

/// SplitMix64: small, deterministic, good enough for test scenes.
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    pub fn unit(&mut self) -> Real {
        (self.next_u64() >> 11) as f64 as Real / (1u64 << 53) as f64 as Real
    }
    pub fn range(&mut self, lo: Real, hi: Real) -> Real {
        lo + (hi - lo) * self.unit()
    }
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n.max(1) as u64) as usize
    }
    pub fn vec(&mut self, lo: Real, hi: Real) -> Vec3 {
        Vec3::new(self.range(lo, hi), self.range(lo, hi), self.range(lo, hi))
    }
}

/// The kinds of scenes every broadphase must agree on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Scene {
    /// Similar boxes in a cube, many overlaps.
    Uniform,
    /// Sizes from 1e-3 to 1e3 (log-uniform).
    Mixed,
    /// Uniform boxes around (1e5, -1e5, 1e5).
    Far,
    /// Boxes and points snapped to an integer lattice: zero extents and touching faces.
    Degenerate,
}

pub const SCENES: [Scene; 4] = [Scene::Uniform, Scene::Mixed, Scene::Far, Scene::Degenerate];

/// A random box of the scene kind.
pub fn random_box(rng: &mut Rng, scene: Scene) -> Aabb {
    match scene {
        Scene::Uniform => {
            let c = rng.vec(-10.0, 10.0);
            Aabb::from_center_half_extents(c, rng.vec(0.2, 1.5))
        }
        Scene::Mixed => {
            let size = (10.0 as Real).powf(rng.range(-3.0, 3.0));
            let c = rng.vec(-300.0, 300.0);
            Aabb::from_center_half_extents(c, rng.vec(0.2, 1.0) * size)
        }
        Scene::Far => {
            let c = Vec3::new(1.0e5, -1.0e5, 1.0e5) + rng.vec(-15.0, 15.0);
            Aabb::from_center_half_extents(c, rng.vec(0.0, 1.5))
        }
        Scene::Degenerate => {
            let lo = Vec3::new(
                rng.below(8) as Real,
                rng.below(8) as Real,
                rng.below(8) as Real,
            );
            let ext = Vec3::new(
                rng.below(3) as Real,
                rng.below(3) as Real,
                rng.below(3) as Real,
            );
            Aabb::new(lo, lo + ext)
        }
    }
}

/// The box moved by a small random step (re-snapped for degenerate scenes).
pub fn moved_box(rng: &mut Rng, b: &Aabb, scene: Scene) -> (Aabb, Vec3) {
    if scene == Scene::Degenerate {
        let nb = random_box(rng, scene);
        return (nb, nb.center() - b.center());
    }
    let scale = match scene {
        Scene::Mixed => b.extents().max_element().max(0.01),
        _ => 1.0,
    };
    let d = rng.vec(-0.5, 0.5) * scale;
    (Aabb::new(b.min + d, b.max + d), d)
}
