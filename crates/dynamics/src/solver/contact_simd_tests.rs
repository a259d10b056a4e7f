//! One wide solve equals four scalar solves (module `contact_simd`).

use super::super::contact::{self, ContactConstraint, ContactRow, PointConstraint};
use super::super::{Softness, SolverBody};
use super::*;
use carom_collision::math::{Mat3, Vec3};

/// A small deterministic generator (xorshift), so the test needs no extra crate.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> Real {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as Real / (1u64 << 53) as Real
    }
    fn range(&mut self, lo: Real, hi: Real) -> Real {
        lo + (hi - lo) * self.next()
    }
    fn vec(&mut self, s: Real) -> Vec3 {
        Vec3::new(self.range(-s, s), self.range(-s, s), self.range(-s, s))
    }
}

fn body(rng: &mut Rng, dynamic: bool) -> SolverBody {
    let (inv_m, inv_i) = if dynamic {
        let d = Vec3::new(
            rng.range(0.2, 2.0),
            rng.range(0.2, 2.0),
            rng.range(0.2, 2.0),
        );
        (rng.range(0.1, 2.0), Mat3::from_diagonal(d))
    } else {
        (0.0, Mat3::ZERO)
    };
    SolverBody {
        v: rng.vec(2.0),
        w: rng.vec(2.0),
        dp: rng.vec(0.01),
        dq: rng.vec(0.01),
        inv_m,
        inv_i,
        dynamic,
    }
}

fn row(a: &SolverBody, b: &SolverBody, ra: Vec3, rb: Vec3, d: Vec3) -> ContactRow {
    let (ang_a, ang_b) = (ra.cross(d), rb.cross(d));
    let (inv_ang_a, inv_ang_b) = (a.inv_i * ang_a, b.inv_i * ang_b);
    let k = a.inv_m + b.inv_m + ang_a.dot(inv_ang_a) + ang_b.dot(inv_ang_b);
    ContactRow {
        ang_a,
        ang_b,
        inv_ang_a,
        inv_ang_b,
        mass: if k > 0.0 { 1.0 / k } else { 0.0 },
    }
}

/// `count` constraints on distinct dynamic bodies (even slots; B of every other one is the
/// shared static body 0), random points, impulses, separations and velocities.
fn scene(rng: &mut Rng, count: usize) -> (Vec<SolverBody>, Vec<ContactConstraint>) {
    let mut bodies = vec![body(rng, false)];
    let mut cons = Vec::new();
    for k in 0..count {
        let a = bodies.len();
        bodies.push(body(rng, true));
        let b = if k % 2 == 0 {
            0
        } else {
            let dynamic = rng.next() < 0.8;
            bodies.push(body(rng, dynamic));
            bodies.len() - 1
        };
        let n = rng.vec(1.0).normalize();
        let (t0, t1) = carom_collision::math::orthonormal_basis(n);
        let len = 1 + (rng.next() * 4.0) as usize % MAX_MANIFOLD_POINTS;
        let mut points = [PointConstraint::default(); MAX_MANIFOLD_POINTS];
        for p in points.iter_mut().take(len) {
            let (ra, rb) = (rng.vec(1.0), rng.vec(1.0));
            let (ba, bb) = (&bodies[a], &bodies[b]);
            *p = PointConstraint {
                normal_row: row(ba, bb, ra, rb, n),
                tangent_rows: [row(ba, bb, ra, rb, t0), row(ba, bb, ra, rb, t1)],
                separation: rng.range(-0.05, 0.02),
                relative_velocity: rng.range(-4.0, 1.0),
                normal_impulse: rng.range(0.0, 2.0),
                tangent_impulse: [rng.range(-0.5, 0.5), rng.range(-0.5, 0.5)],
                push_impulse: 0.0,
                max_normal_impulse: if rng.next() < 0.2 {
                    0.0
                } else {
                    rng.range(0.0, 2.0)
                },
            };
        }
        let softness = Softness::new(rng.range(10.0, 60.0), rng.range(0.5, 10.0), 1.0 / 240.0);
        cons.push(ContactConstraint {
            a,
            b,
            manifold: k,
            normal: n,
            tangent: [t0, t1],
            friction: rng.range(0.0, 1.0),
            restitution: if rng.next() < 0.5 {
                0.0
            } else {
                rng.range(0.0, 1.0)
            },
            softness,
            points,
            len,
        });
    }
    (bodies, cons)
}

fn close(x: Real, y: Real, what: &str) {
    let tol = if cfg!(test) && std::mem::size_of::<Real>() == 4 {
        1e-5
    } else {
        1e-12
    };
    assert!(
        (x - y).abs() <= tol * (1.0 + x.abs().max(y.abs())),
        "{what}: simd {x} vs scalar {y}"
    );
}

fn compare(
    bodies: &[SolverBody],
    bodies2: &[SolverBody],
    cons: &[ContactConstraint],
    cons2: &[ContactConstraint],
) {
    for (i, (x, y)) in bodies.iter().zip(bodies2).enumerate() {
        for k in 0..3 {
            close(x.v[k], y.v[k], &format!("body {i} v"));
            close(x.w[k], y.w[k], &format!("body {i} w"));
        }
    }
    for (c, d) in cons.iter().zip(cons2) {
        for (p, q) in c.points[..c.len].iter().zip(&d.points[..d.len]) {
            close(p.normal_impulse, q.normal_impulse, "normal impulse");
            close(
                p.tangent_impulse[0],
                q.tangent_impulse[0],
                "tangent impulse 0",
            );
            close(
                p.tangent_impulse[1],
                q.tangent_impulse[1],
                "tangent impulse 1",
            );
            close(
                p.max_normal_impulse,
                q.max_normal_impulse,
                "max normal impulse",
            );
        }
    }
}

/// Every pass of the soft step, wide (four lanes, last group padded) against the scalar
/// routines constraint by constraint, over several random scenes.
#[test]
fn wide_solve_equals_scalar_solves() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for count in [1, 3, 4, 5, 8, 11] {
        let (mut bodies, mut cons) = scene(&mut rng, count);
        let (mut bodies2, mut cons2) = (bodies.clone(), cons.clone());
        // One colour holding everything (the scene shares only the static body), plus an
        // empty overflow colour.
        let ranges = [0..count, count..count];
        let mut wide = WideScratch::default();
        build(&cons, &ranges, &bodies, &mut wide);
        assert_eq!(wide.cons.len(), count.div_ceil(LANES));
        let inv_h = 240.0;
        for pass in 0..4 {
            let scalar =
                |c: &mut ContactConstraint, a: &mut SolverBody, b: &mut SolverBody| match pass {
                    0 => contact::warm_start(c, a, b),
                    1 => contact::solve_soft(c, a, b, inv_h, 3.0, true),
                    2 => contact::solve_soft(c, a, b, inv_h, 3.0, false),
                    _ => contact::apply_restitution(c, a, b, 1.0),
                };
            let simd = |c: &mut WideConstraint, a: &mut WideBody, b: &mut WideBody| match pass {
                0 => warm_start(c, a, b),
                1 => solve_soft(c, a, b, inv_h, 3.0, true),
                2 => solve_soft(c, a, b, inv_h, 3.0, false),
                _ => apply_restitution(c, a, b, 1.0),
            };
            solve(&mut wide, &mut cons, &mut bodies, false, 1, simd, scalar);
            super::super::coloring::solve_coloured(
                &mut cons2,
                &ranges,
                &mut bodies2,
                false,
                1,
                scalar,
            );
            write_back(&wide, &mut cons);
            compare(&bodies, &bodies2, &cons, &cons2);
        }
        // Static body never written.
        assert_eq!(bodies[0], bodies2[0]);
    }
}

/// The overflow colour runs on the scalar path.
#[test]
fn overflow_colour_is_solved_scalar() {
    let mut rng = Rng(7);
    let (mut bodies, mut cons) = scene(&mut rng, 6);
    let (mut bodies2, mut cons2) = (bodies.clone(), cons.clone());
    let ranges = [0..2, 2..6];
    let mut wide = WideScratch::default();
    build(&cons, &ranges, &bodies, &mut wide);
    assert_eq!(wide.cons.len(), 1);
    assert_eq!(wide.overflow, 2..6);
    let scalar = |c: &mut ContactConstraint, a: &mut SolverBody, b: &mut SolverBody| {
        contact::solve_soft(c, a, b, 240.0, 3.0, true)
    };
    solve(
        &mut wide,
        &mut cons,
        &mut bodies,
        false,
        1,
        |c, a, b| solve_soft(c, a, b, 240.0, 3.0, true),
        scalar,
    );
    write_back(&wide, &mut cons);
    super::super::coloring::solve_coloured(&mut cons2, &ranges, &mut bodies2, false, 1, scalar);
    compare(&bodies, &bodies2, &cons, &cons2);
}
