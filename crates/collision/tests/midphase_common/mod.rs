//! Shared generators for the midphase tests: a seeded RNG and test meshes.
#![allow(dead_code)]

use carom_collision::math::{Real, Vec3};

/// A small seeded generator (PCG-like LCG), so tests need no extra crate.
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u32(&mut self) -> u32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 33) as u32
    }
    /// Uniform in [0, 1).
    pub fn f(&mut self) -> Real {
        (self.next_u32() as f64 / (1u64 << 31) as f64) as Real
    }
    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: Real, hi: Real) -> Real {
        lo + (hi - lo) * self.f()
    }
    pub fn vec(&mut self, lo: Real, hi: Real) -> Vec3 {
        Vec3::new(self.range(lo, hi), self.range(lo, hi), self.range(lo, hi))
    }
    pub fn unit(&mut self) -> Vec3 {
        loop {
            let v = self.vec(-1.0, 1.0);
            let l = v.length();
            if l > 0.1 && l <= 1.0 {
                return v / l;
            }
        }
    }
}

/// A wavy grid of `n × n` cells over `[0, size]²` (y up), two triangles per cell, offset.
pub fn grid_mesh(n: usize, size: Real, offset: Vec3) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut v = Vec::new();
    for i in 0..=n {
        for j in 0..=n {
            let x = size * i as Real / n as Real;
            let z = size * j as Real / n as Real;
            let y = (x * 0.7).sin() * (z * 0.5).cos() * size * 0.05;
            v.push(Vec3::new(x, y, z) + offset);
        }
    }
    let mut t = Vec::new();
    let w = (n + 1) as u32;
    for i in 0..n as u32 {
        for j in 0..n as u32 {
            let a = i * w + j;
            t.push([a, a + 1, a + w]);
            t.push([a + 1, a + w + 1, a + w]);
        }
    }
    (v, t)
}

/// A soup of random triangles in `[lo, hi]³`, with some degenerate ones (repeated corner,
/// collinear corners, a point) mixed in.
pub fn soup_mesh(rng: &mut Rng, n: usize, lo: Real, hi: Real) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut v = Vec::new();
    let mut t = Vec::new();
    for k in 0..n {
        let c = rng.vec(lo, hi);
        let s = (hi - lo) * 0.08;
        let a = c + rng.vec(-s, s);
        let (b, d) = match k % 10 {
            0 => (a, c + rng.vec(-s, s)),
            1 => {
                let b = c + rng.vec(-s, s);
                (b, a + (b - a) * 2.0)
            }
            2 => (a, a),
            _ => (c + rng.vec(-s, s), c + rng.vec(-s, s)),
        };
        let base = v.len() as u32;
        v.extend([a, b, d]);
        t.push([base, base + 1, base + 2]);
    }
    (v, t)
}
