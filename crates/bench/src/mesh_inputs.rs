//! The inputs of `carom-bench midphase`, shared with `examples/ray_instructions.rs` (which
//! includes this file by path) so the instruction counts measure exactly the bench's meshes
//! and rays: a generated height grid, random rays toward a mesh's bounds, and the conversion
//! to parry3d's vectors.

use carom_collision::math::{Aabb, Real, Vec3};

/// parry3d's vector type (its own glam version: converted through components).
pub type PVec = parry3d::math::Vector;

/// A small deterministic generator (a 64-bit LCG), the same on every machine.
pub struct Lcg(pub u64);
impl Lcg {
    /// A uniform number in [0, 1).
    pub fn f(&mut self) -> Real {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 40) as f64 / (1u64 << 24) as f64) as Real
    }
}

/// A wavy height grid of `n × n` cells (2 triangles each) over 1000 × 1000 units.
pub fn generated_mesh(n: usize) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let size = 1000.0 as Real;
    let mut v = Vec::with_capacity((n + 1) * (n + 1));
    for i in 0..=n {
        for j in 0..=n {
            let x = size * i as Real / n as Real;
            let z = size * j as Real / n as Real;
            let y = (x * 0.031).sin() * (z * 0.017).cos() * 40.0 + (x * 0.4 + z * 0.3).sin();
            v.push(Vec3::new(x, y, z));
        }
    }
    let w = (n + 1) as u32;
    let mut t = Vec::with_capacity(2 * n * n);
    for i in 0..n as u32 {
        for j in 0..n as u32 {
            let a = i * w + j;
            t.push([a, a + 1, a + w]);
            t.push([a + 1, a + w + 1, a + w]);
        }
    }
    (v, t)
}

/// Rays from a sphere around the mesh toward random points of its bounding box.
pub fn rays(bounds: &Aabb, n: usize) -> Vec<(Vec3, Vec3)> {
    let mut rng = Lcg(12345);
    let c = bounds.center();
    let r = bounds.extents().length() * 0.75;
    (0..n)
        .map(|_| {
            let d = loop {
                let v = Vec3::new(rng.f() * 2.0 - 1.0, rng.f(), rng.f() * 2.0 - 1.0);
                if v.length() > 0.1 && v.length() <= 1.0 {
                    break v.normalize();
                }
            };
            let origin = c + d * r;
            let e = bounds.extents();
            let target = bounds.min + Vec3::new(rng.f() * e.x, rng.f() * e.y, rng.f() * e.z);
            (origin, (target - origin).normalize())
        })
        .collect()
}

/// A Carom vector as a parry3d vector.
pub fn pv(v: Vec3) -> PVec {
    PVec::new(v.x as _, v.y as _, v.z as _)
}
