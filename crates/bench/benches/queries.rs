//! Proximity-query micro-benchmarks, each beside parry3d's same query in the same run:
//! distance, penetration (contact on overlapping poses), ray cast and shape cast for
//! box–box, hull–hull (hulls of 8, 32 and 128 points), capsule–hull and sphere–triangle.
//!
//! Run briefly with
//! `cargo bench -p carom-bench --bench queries -- --warm-up-time 1 --measurement-time 2`.
//! Each measurement loops over the same 64 poses for both libraries. parry3d uses glam 0.33:
//! values are converted through arrays once, outside the timed loops.

use carom_collision::math::{Isometry, Real, Vec3};
use carom_collision::query;
use carom_collision::shape::{Capsule, ConvexHull, Cuboid, Shape, Sphere, Triangle};
use criterion::{criterion_group, criterion_main, Criterion};
use parry3d::math::{Pose as PPose, Vec3 as PVec3};
use parry3d::query::{Ray as PRay, ShapeCastOptions};
use parry3d::shape::SharedShape;
use std::hint::black_box;

mod common;
use common::{pp, pv, Rng};

const N: usize = 64;

struct Case {
    name: String,
    a: Shape,
    b: Shape,
    pa: SharedShape,
    pb: SharedShape,
    /// Typical size, used to place the poses.
    size: Real,
}

fn hull_points(rng: &mut Rng, n: usize, r: Real) -> Vec<Vec3> {
    (0..n).map(|_| rng.unit() * r).collect()
}

fn cases() -> Vec<Case> {
    let mut rng = Rng(42);
    let mut out = Vec::new();
    let h = Vec3::new(0.5, 0.4, 0.6);
    let bx = Cuboid::new(h).unwrap();
    out.push(Case {
        name: "box-box".into(),
        a: Shape::Cuboid(bx),
        b: Shape::Cuboid(bx),
        pa: SharedShape::cuboid(0.5, 0.4, 0.6),
        pb: SharedShape::cuboid(0.5, 0.4, 0.6),
        size: 0.6,
    });
    for n in [8, 32, 128] {
        let p1 = hull_points(&mut rng, n, 0.6);
        let p2 = hull_points(&mut rng, n, 0.6);
        let conv = |p: &[Vec3]| {
            SharedShape::convex_hull(&p.iter().map(|v| pv(*v)).collect::<Vec<_>>()).unwrap()
        };
        out.push(Case {
            name: format!("hull{n}-hull{n}"),
            a: Shape::ConvexHull(ConvexHull::new(&p1).unwrap()),
            b: Shape::ConvexHull(ConvexHull::new(&p2).unwrap()),
            pa: conv(&p1),
            pb: conv(&p2),
            size: 0.6,
        });
    }
    let p2 = hull_points(&mut rng, 32, 0.6);
    out.push(Case {
        name: "capsule-hull32".into(),
        a: Shape::Capsule(Capsule::new(0.3, 0.5).unwrap()),
        b: Shape::ConvexHull(ConvexHull::new(&p2).unwrap()),
        pa: SharedShape::capsule_y(0.5, 0.3),
        pb: SharedShape::convex_hull(&p2.iter().map(|v| pv(*v)).collect::<Vec<_>>()).unwrap(),
        size: 0.6,
    });
    let (t0, t1, t2) = (
        Vec3::new(-1.0, 0.0, -1.0),
        Vec3::new(1.0, 0.0, -1.0),
        Vec3::new(0.0, 0.0, 1.0),
    );
    out.push(Case {
        name: "sphere-triangle".into(),
        a: Shape::Sphere(Sphere::new(0.4).unwrap()),
        b: Shape::Triangle(Triangle::new(t0, t1, t2).unwrap()),
        pa: SharedShape::ball(0.4),
        pb: SharedShape::triangle(pv(t0), pv(t1), pv(t2)),
        size: 0.5,
    });
    out
}

/// N pose pairs with B at distance `dist * size` from A (negative: overlapping).
fn pose_pairs(rng: &mut Rng, size: Real, dist: Real) -> Vec<(Isometry, Isometry)> {
    (0..N)
        .map(|_| {
            let a = Isometry::new(rng.unit() * 3.0, rng.quat());
            let b = Isometry::new(a.translation + rng.unit() * size * (2.0 + dist), rng.quat());
            (a, b)
        })
        .collect()
}

fn bench_queries(c: &mut Criterion) {
    let mut rng = Rng(7);
    for case in cases() {
        let sep = pose_pairs(&mut rng, case.size, 1.0);
        let pen = pose_pairs(&mut rng, case.size, -0.8);
        let psep: Vec<(PPose, PPose)> = sep.iter().map(|(a, b)| (pp(a), pp(b))).collect();
        let ppen: Vec<(PPose, PPose)> = pen.iter().map(|(a, b)| (pp(a), pp(b))).collect();

        let mut g = c.benchmark_group(format!("distance/{}", case.name));
        g.bench_function("carom", |bch| {
            bch.iter(|| {
                for (a, b) in &sep {
                    black_box(query::distance(&case.a, a, &case.b, b).unwrap());
                }
            })
        });
        g.bench_function("parry3d", |bch| {
            bch.iter(|| {
                for (a, b) in &psep {
                    black_box(parry3d::query::distance(a, &*case.pa, b, &*case.pb).unwrap());
                }
            })
        });
        g.finish();

        let mut g = c.benchmark_group(format!("penetration/{}", case.name));
        g.bench_function("carom", |bch| {
            bch.iter(|| {
                for (a, b) in &pen {
                    black_box(query::contact(&case.a, a, &case.b, b, 0.0).unwrap());
                }
            })
        });
        g.bench_function("parry3d", |bch| {
            bch.iter(|| {
                for (a, b) in &ppen {
                    black_box(parry3d::query::contact(a, &*case.pa, b, &*case.pb, 0.0).unwrap());
                }
            })
        });
        g.finish();

        // Ray casts against B, from random points around it towards its centre region.
        let rays: Vec<(Vec3, Vec3)> = (0..N)
            .map(|_| {
                let o = rng.unit() * 3.0;
                (o, (rng.unit() * 0.3 - o).normalize())
            })
            .collect();
        let prays: Vec<PRay> = rays
            .iter()
            .map(|(o, d)| PRay::new(pv(*o), pv(*d)))
            .collect();
        let pose_b = Isometry::IDENTITY;
        let ppose_b = pp(&pose_b);
        let mut g = c.benchmark_group(format!("raycast/{}(B)", case.name));
        g.bench_function("carom", |bch| {
            bch.iter(|| {
                for (o, d) in &rays {
                    black_box(query::raycast(&case.b, &pose_b, *o, *d, 10.0, true).unwrap());
                }
            })
        });
        g.bench_function("parry3d", |bch| {
            bch.iter(|| {
                for r in &prays {
                    black_box(case.pb.cast_ray_and_get_normal(&ppose_b, r, 10.0, true));
                }
            })
        });
        g.finish();

        // Shape casts: B flies towards A.
        let casts: Vec<(Isometry, Isometry, Vec3)> = sep
            .iter()
            .map(|(a, b)| {
                (
                    *a,
                    *b,
                    (a.translation - b.translation) * 1.5 + rng.unit() * 0.2,
                )
            })
            .collect();
        let pcasts: Vec<(PPose, PPose, PVec3)> = casts
            .iter()
            .map(|(a, b, v)| (pp(a), pp(b), pv(*v)))
            .collect();
        let mut g = c.benchmark_group(format!("shape_cast/{}", case.name));
        g.bench_function("carom", |bch| {
            bch.iter(|| {
                for (a, b, v) in &casts {
                    black_box(
                        query::shape_cast(&case.a, a, Vec3::ZERO, &case.b, b, *v, 1.0).unwrap(),
                    );
                }
            })
        });
        g.bench_function("parry3d", |bch| {
            bch.iter(|| {
                for (a, b, v) in &pcasts {
                    black_box(
                        parry3d::query::cast_shapes(
                            a,
                            PVec3::ZERO,
                            &*case.pa,
                            b,
                            *v,
                            &*case.pb,
                            ShapeCastOptions::with_max_time_of_impact(1.0),
                        )
                        .unwrap(),
                    );
                }
            })
        });
        g.finish();
    }
}

criterion_group!(benches, bench_queries);
criterion_main!(benches);
