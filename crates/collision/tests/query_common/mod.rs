//! Shared helpers for the query tests: a seeded RNG, random shapes and poses, and
//! brute-force oracles for polytopes.
#![allow(dead_code)]

use carom_collision::math::{Isometry, Quat, Real, Vec3};
use carom_collision::query::closest_points::{
    closest_point_triangle, closest_points_segment_segment,
};
use carom_collision::shape::ConvexHull;

/// A property-test configuration with a fixed seed and no persisted failures, so CI runs the
/// same `cases` on every machine.
pub fn fixed_config(cases: u32, seed: u64) -> proptest::test_runner::Config {
    proptest::test_runner::Config {
        cases,
        rng_seed: proptest::test_runner::RngSeed::Fixed(seed),
        failure_persistence: None,
        ..proptest::test_runner::Config::default()
    }
}

/// Tolerance in length units, scaled to the precision of `Real`.
pub fn tol() -> Real {
    if std::mem::size_of::<Real>() == 8 {
        1e-9
    } else {
        2e-4
    }
}

/// A small deterministic RNG (PCG-style LCG).
pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> Real {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) as Real
    }
    pub fn range(&mut self, lo: Real, hi: Real) -> Real {
        lo + (hi - lo) * self.next()
    }
    pub fn vec(&mut self, s: Real) -> Vec3 {
        Vec3::new(self.range(-s, s), self.range(-s, s), self.range(-s, s))
    }
    pub fn unit(&mut self) -> Vec3 {
        loop {
            let v = self.vec(1.0);
            let l = v.length();
            if l > 0.1 && l <= 1.0 {
                return v / l;
            }
        }
    }
    pub fn quat(&mut self) -> Quat {
        Quat::from_axis_angle(self.unit(), self.range(-3.1, 3.1))
    }
    pub fn pose(&mut self, s: Real) -> Isometry {
        Isometry::new(self.vec(s), self.quat())
    }
}

/// A random hull of `n` points in a ball of radius `r`.
pub fn random_hull(rng: &mut Rng, n: usize, r: Real) -> ConvexHull {
    let pts: Vec<Vec3> = (0..n)
        .map(|_| rng.unit() * r * rng.range(0.5, 1.0))
        .collect();
    ConvexHull::new(&pts).unwrap()
}

/// World-space triangles and edges of a hull at `pose`.
pub fn hull_world(h: &ConvexHull, pose: &Isometry) -> (Vec<[Vec3; 3]>, Vec<[Vec3; 2]>) {
    let v: Vec<Vec3> = h
        .vertices()
        .iter()
        .map(|p| pose.transform_point(*p))
        .collect();
    let tris = h
        .triangles()
        .iter()
        .map(|t| [v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]])
        .collect();
    let edges = h
        .edges()
        .iter()
        .map(|e| [v[e[0] as usize], v[e[1] as usize]])
        .collect();
    (tris, edges)
}

/// Brute-force distance between two disjoint hulls: minimum over vertex–face (both ways)
/// and edge–edge feature pairs.
pub fn brute_hull_distance(a: &ConvexHull, pa: &Isometry, b: &ConvexHull, pb: &Isometry) -> Real {
    let (ta, ea) = hull_world(a, pa);
    let (tb, eb) = hull_world(b, pb);
    let mut best = Real::INFINITY;
    for (tris, others) in [(&ta, &eb), (&tb, &ea)] {
        for t in tris.iter() {
            for e in others.iter() {
                for p in e {
                    best = best.min((closest_point_triangle(*p, t[0], t[1], t[2]) - *p).length());
                }
            }
        }
    }
    for e in &ea {
        for f in &eb {
            let (c1, c2) = closest_points_segment_segment(e[0], e[1], f[0], f[1]);
            best = best.min((c1 - c2).length());
        }
    }
    best
}

/// The world-space axes of a hull: its face normals.
pub fn hull_normals(h: &ConvexHull, pose: &Isometry) -> Vec<Vec3> {
    h.faces()
        .iter()
        .map(|f| pose.transform_vector(f.normal))
        .collect()
}

/// Projection interval of a hull on an axis.
pub fn interval(h: &ConvexHull, pose: &Isometry, axis: Vec3) -> (Real, Real) {
    h.vertices()
        .iter()
        .fold((Real::INFINITY, -Real::INFINITY), |(lo, hi), p| {
            let d = pose.transform_point(*p).dot(axis);
            (lo.min(d), hi.max(d))
        })
}

/// Exact minimum translational distance of two overlapping hulls: the minimum overlap over
/// all face normals and edge–edge cross products (0 if some axis separates).
pub fn brute_hull_depth(a: &ConvexHull, pa: &Isometry, b: &ConvexHull, pb: &Isometry) -> Real {
    let mut axes = hull_normals(a, pa);
    axes.extend(hull_normals(b, pb));
    let (_, ea) = hull_world(a, pa);
    let (_, eb) = hull_world(b, pb);
    for e in &ea {
        for f in &eb {
            let c = (e[1] - e[0]).cross(f[1] - f[0]);
            if c.length() > 1e-6 {
                axes.push(c.normalize());
            }
        }
    }
    let mut best = Real::INFINITY;
    for ax in axes {
        let (a0, a1) = interval(a, pa, ax);
        let (b0, b1) = interval(b, pb, ax);
        let overlap = (a1 - b0).min(b1 - a0);
        best = best.min(overlap.max(0.0));
    }
    best
}

/// Signed distance of a point to a hull's boundary in world space: max over face planes
/// (exact inside; a lower bound outside, exact when the nearest feature is a face).
pub fn hull_plane_distance(h: &ConvexHull, pose: &Isometry, p: Vec3) -> Real {
    let q = pose.inverse_transform_point(p);
    h.faces()
        .iter()
        .map(|f| f.normal.dot(q) - f.offset)
        .fold(-Real::INFINITY, Real::max)
}
