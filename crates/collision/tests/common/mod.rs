//! Shared test helpers: a tiny deterministic RNG, surface sampling and inside tests.
#![allow(dead_code)]

use carom_collision::math::{consts::PI, Real, Vec3};
use carom_collision::shape::{Shape, SupportMap};

/// xorshift64* — deterministic, dependency-free.
pub struct Rng(u64);

impl Rng {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Self {
        Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }
    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> Real {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let x = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D);
        ((x >> 11) as f64 / (1u64 << 53) as f64) as Real
    }
    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: Real, hi: Real) -> Real {
        lo + (hi - lo) * self.uniform()
    }
    /// A uniformly distributed unit vector.
    pub fn unit(&mut self) -> Vec3 {
        let z = self.range(-1.0, 1.0);
        let a = self.range(0.0, 2.0 * PI);
        let r = (1.0 - z * z).max(0.0).sqrt();
        Vec3::new(r * a.cos(), r * a.sin(), z)
    }
}

/// The 43 Taru points of Bullet's benchmark (crates/scenes/data/taru.obj).
pub fn taru_points() -> Vec<Vec3> {
    include_str!("../../../scenes/data/taru.obj")
        .lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let c: Vec<Real> = l
                .split_whitespace()
                .map(|x| x.parse::<f64>().unwrap() as Real)
                .collect();
            Vec3::new(c[0], c[1], c[2])
        })
        .collect()
}

/// Uniform-ish random points on the surface of a convex shape (local frame).
pub fn sample_surface(shape: &Shape, n: usize, rng: &mut Rng) -> Vec<Vec3> {
    (0..n).map(|_| sample_one(shape, rng)).collect()
}

fn sample_one(shape: &Shape, rng: &mut Rng) -> Vec3 {
    match shape {
        Shape::Sphere(s) => rng.unit() * s.radius(),
        Shape::Cuboid(b) => {
            let h = b.half_extents();
            let mut p = Vec3::new(
                rng.range(-h.x, h.x),
                rng.range(-h.y, h.y),
                rng.range(-h.z, h.z),
            );
            let axis = (rng.uniform() * 3.0) as usize % 3;
            p[axis] = if rng.uniform() < 0.5 {
                -h[axis]
            } else {
                h[axis]
            };
            p
        }
        Shape::Capsule(c) => {
            let d = rng.unit();
            let y = if rng.uniform() < 0.5 {
                rng.range(-c.half_height(), c.half_height())
            } else {
                c.half_height() * d.y.signum()
            };
            if y.abs() < c.half_height() {
                let r = Vec3::new(d.x, 0.0, d.z).normalize_or_zero() * c.radius();
                Vec3::new(r.x, y, r.z)
            } else {
                Vec3::new(0.0, y, 0.0) + d * c.radius()
            }
        }
        Shape::Cylinder(c) => {
            let a = rng.range(0.0, 2.0 * PI);
            match (rng.uniform() * 3.0) as usize {
                0 => Vec3::new(
                    c.radius() * a.cos(),
                    rng.range(-c.half_height(), c.half_height()),
                    c.radius() * a.sin(),
                ),
                k => {
                    let r = c.radius() * rng.uniform().sqrt();
                    let y = if k == 1 {
                        c.half_height()
                    } else {
                        -c.half_height()
                    };
                    Vec3::new(r * a.cos(), y, r * a.sin())
                }
            }
        }
        Shape::Cone(c) => {
            let a = rng.range(0.0, 2.0 * PI);
            let rim = Vec3::new(c.radius() * a.cos(), -c.half_height(), c.radius() * a.sin());
            if rng.uniform() < 0.5 {
                let t = rng.uniform().sqrt();
                Vec3::new(0.0, c.half_height(), 0.0).lerp(rim, t)
            } else {
                let r = rng.uniform().sqrt();
                Vec3::new(rim.x * r, -c.half_height(), rim.z * r)
            }
        }
        Shape::ConvexHull(h) => {
            let tris = h.triangles();
            let t = tris[(rng.uniform() * tris.len() as Real) as usize % tris.len()];
            let v = h.vertices();
            barycentric(v[t[0] as usize], v[t[1] as usize], v[t[2] as usize], rng)
        }
        Shape::Triangle(t) => barycentric(t.a, t.b, t.c, rng),
        Shape::Scaled(s) => sample_one(s.inner(), rng) * s.scale(),
        _ => panic!("not a convex shape"),
    }
}

fn barycentric(a: Vec3, b: Vec3, c: Vec3, rng: &mut Rng) -> Vec3 {
    let (mut u, mut v) = (rng.uniform(), rng.uniform());
    if u + v > 1.0 {
        u = 1.0 - u;
        v = 1.0 - v;
    }
    a + (b - a) * u + (c - a) * v
}

/// Implicit inside test with tolerance `tol` (independent of the support functions).
pub fn inside(shape: &Shape, p: Vec3, tol: Real) -> bool {
    match shape {
        Shape::Sphere(s) => p.length() <= s.radius() + tol,
        Shape::Cuboid(b) => (p.abs() - b.half_extents()).max_element() <= tol,
        Shape::Capsule(c) => {
            let y = p.y.clamp(-c.half_height(), c.half_height());
            (p - Vec3::new(0.0, y, 0.0)).length() <= c.radius() + tol
        }
        Shape::Cylinder(c) => {
            Vec3::new(p.x, 0.0, p.z).length() <= c.radius() + tol
                && p.y.abs() <= c.half_height() + tol
        }
        Shape::Cone(c) => {
            let h = c.half_height();
            let frac = ((h - p.y) / (2.0 * h)).clamp(0.0, 1.0);
            p.y >= -h - tol
                && p.y <= h + tol
                && Vec3::new(p.x, 0.0, p.z).length() <= c.radius() * frac + tol * 2.0
        }
        Shape::ConvexHull(h) => h.faces().iter().all(|f| f.normal.dot(p) - f.offset <= tol),
        Shape::Triangle(t) => {
            // On the triangle's plane and inside its edges.
            let n = t.scaled_normal();
            let len = n.length();
            if len == 0.0 {
                return false;
            }
            let n = n / len;
            if n.dot(p - t.a).abs() > tol {
                return false;
            }
            let edges = [(t.a, t.b), (t.b, t.c), (t.c, t.a)];
            edges
                .iter()
                .all(|(u, v)| (*v - *u).cross(p - *u).dot(n) >= -tol * (*v - *u).length())
        }
        Shape::Scaled(s) => {
            let q = p / s.scale();
            let k = s.scale().abs().max_element();
            inside(s.inner(), q, tol / s.scale().abs().min_element().min(k))
        }
        _ => {
            let _ = shape.as_convex().map(|c| c.support(Vec3::X));
            false
        }
    }
}
