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
        // The second tangent as the preparation builds it (the wide constraint recomputes it).
        let t0 = carom_collision::math::orthonormal_basis(n).0;
        let t1 = n.cross(t0);
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
                arm_a: ra,
                arm_b: rb,
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
            same_bits(&bodies, &bodies2, &cons, &cons2);
        }
        // Static body never written.
        assert_eq!(bodies[0], bodies2[0]);
    }
}

/// The wide passes recompute the rows' `r × d` from the lever arms in the scalar order, so
/// they give the scalar routines' velocities and impulses bit for bit, not only to
/// round-off.
fn same_bits(
    bodies: &[SolverBody],
    bodies2: &[SolverBody],
    cons: &[ContactConstraint],
    cons2: &[ContactConstraint],
) {
    let bits = |v: Vec3| v.to_array().map(|x| x.to_bits());
    for (i, (x, y)) in bodies.iter().zip(bodies2).enumerate() {
        assert_eq!(bits(x.v), bits(y.v), "body {i} v");
        assert_eq!(bits(x.w), bits(y.w), "body {i} w");
    }
    for (c, d) in cons.iter().zip(cons2) {
        for (p, q) in c.points[..c.len].iter().zip(&d.points[..d.len]) {
            let imp = |p: &PointConstraint| {
                [
                    p.normal_impulse,
                    p.tangent_impulse[0],
                    p.tangent_impulse[1],
                    p.max_normal_impulse,
                ]
                .map(|x| x.to_bits())
            };
            assert_eq!(imp(p), imp(q), "manifold {}", c.manifold);
        }
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

/// Lane `l` of `w` holds exactly (bit for bit) constraint `c`, or is an empty padding lane.
fn assert_lane(w: &WideConstraint, l: usize, c: Option<&ContactConstraint>, bodies: &[SolverBody]) {
    let lane = |x: &W| x.as_array()[l];
    let lane3 = |v: &V3| Vec3::new(lane(&v.x), lane(&v.y), lane(&v.z));
    let empty = ContactConstraint::EMPTY;
    let c_or = c.unwrap_or(&empty);
    let index = |x: u32| if x == NO_SLOT { NONE } else { x as usize };
    assert_eq!(index(w.manifold[l]), c.map_or(NONE, |c| c.manifold));
    assert_eq!(w.lens[l] as usize, c_or.len);
    let (wa, wb) = (index(w.a[l]), index(w.b[l]));
    assert_eq!((wa, wb), c.map_or((NONE, NONE), |c| (c.a, c.b)));
    let dynamic = |s: usize| s != NONE && bodies[s].dynamic;
    assert_eq!((w.write_a[l], w.write_b[l]), (dynamic(wa), dynamic(wb)));
    let inv_m = |s: usize| if s == NONE { 0.0 } else { bodies[s].inv_m };
    assert_eq!(lane(&w.inv_m_a).to_bits(), inv_m(wa).to_bits());
    assert_eq!(lane(&w.inv_m_b).to_bits(), inv_m(wb).to_bits());
    assert_eq!(lane3(&w.normal), c_or.normal);
    assert_eq!(lane3(&w.tangent), c_or.tangent[0]);
    assert_eq!(lane3(&w.tangent1()), c_or.tangent[1]);
    assert_eq!(lane(&w.friction), c_or.friction);
    assert_eq!(lane(&w.restitution), c_or.restitution);
    assert_eq!(lane(&w.bias_rate), c_or.softness.bias_rate);
    assert_eq!(lane(&w.mass_scale), c_or.softness.mass_scale);
    assert_eq!(lane(&w.impulse_scale), c_or.softness.impulse_scale);
    // Points from `w.len` on are never read (and may be stale).
    for (k, wp) in w.points[..w.len].iter().enumerate() {
        let p = if k < c_or.len {
            c_or.points[k]
        } else {
            PointConstraint::ZERO
        };
        let rows = [
            (&wp.normal_row, &p.normal_row, w.normal),
            (&wp.tangent_rows[0], &p.tangent_rows[0], w.tangent),
            (&wp.tangent_rows[1], &p.tangent_rows[1], w.tangent1()),
        ];
        assert_eq!(lane3(&wp.arm_a), p.arm_a);
        assert_eq!(lane3(&wp.arm_b), p.arm_b);
        for (wr, r, d) in rows {
            // The solve's recomputed Jacobian is the scalar row's, bit for bit (up to the
            // sign of zero in a lane without the point, where the row's mass is zero).
            let j = Angular::new(wp, d);
            let bits = |v: Vec3| v.to_array().map(|x| if x == 0.0 { 0 } else { x.to_bits() });
            assert_eq!(bits(lane3(&j.a)), bits(r.ang_a));
            assert_eq!(bits(lane3(&j.b)), bits(r.ang_b));
            assert_eq!(lane3(&wr.inv_ang_a), r.inv_ang_a);
            assert_eq!(lane3(&wr.inv_ang_b), r.inv_ang_b);
            assert_eq!(lane(&wr.mass).to_bits(), r.mass.to_bits());
        }
        assert_eq!(lane(&wp.separation), p.separation);
        assert_eq!(lane(&w.relative_velocity[k]), p.relative_velocity);
        assert_eq!(lane(&wp.normal_impulse), p.normal_impulse);
        assert_eq!(lane(&wp.tangent_impulse[0]), p.tangent_impulse[0]);
        assert_eq!(lane(&wp.tangent_impulse[1]), p.tangent_impulse[1]);
        assert_eq!(lane(&wp.max_normal_impulse), p.max_normal_impulse);
    }
}

/// `fill` writes every colour but the overflow one into lanes, bit for bit, padding the
/// last group of a colour, and keeps the overflow colour scalar. Run twice on the same
/// buffers, the second time with fewer constraints and other values: nothing of the first
/// run survives in the reused wide constraints.
#[test]
fn fill_writes_every_lane_and_overwrites_stale_ones() {
    let mut rng = Rng(0x5eed);
    let mut wide = WideScratch::default();
    let mut overflow_cons = Vec::new();
    for (count, ranges) in [
        (11, vec![0..7, 7..9, 9..11]),
        (5, vec![0..2, 2..3, 3..5]),
        (3, vec![0..3, 3..3]),
        (0, vec![Range { start: 0, end: 0 }]),
    ] {
        let (bodies, cons) = scene(&mut rng, count);
        let made = std::sync::atomic::AtomicUsize::new(0);
        let points = |k: usize| cons[k].len;
        fill(
            &mut wide,
            &mut overflow_cons,
            &ranges,
            &bodies,
            points,
            |k, c, _| {
                made.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                *c = cons[k].clone();
            },
        );
        let made = made.load(std::sync::atomic::Ordering::Relaxed);
        assert_eq!(made, count, "each constraint is prepared once");
        let (overflow, colours) = ranges.split_last().unwrap();
        assert_eq!(wide.ranges.len(), colours.len());
        assert_eq!(
            wide.cons.len(),
            colours
                .iter()
                .map(|r| r.len().div_ceil(LANES))
                .sum::<usize>()
        );
        for (r, wr) in colours.iter().zip(&wide.ranges) {
            assert_eq!(wr.len(), r.len().div_ceil(LANES));
            // Grouped by point count, most points first, colour order within a count.
            let mut expected: Vec<usize> = r.clone().collect();
            expected.sort_by_key(|&k| std::cmp::Reverse(cons[k].len));
            for (g, w) in wide.cons[wr.clone()].iter().enumerate() {
                let mut len = 0;
                for l in 0..LANES {
                    let c = expected.get(g * LANES + l).map(|&k| &cons[k]);
                    len = len.max(c.map_or(0, |c| c.len));
                    assert_lane(w, l, c, &bodies);
                }
                assert_eq!(w.len, len);
            }
        }
        assert_eq!(wide.overflow, 0..overflow.len());
        assert_eq!(overflow_cons.len(), overflow.len());
        for (c, d) in overflow_cons.iter().zip(&cons[overflow.clone()]) {
            assert_eq!(c.manifold, d.manifold);
        }
    }
}

/// `store` writes each lane's impulses and friction direction into its manifold exactly as
/// `contact::store` writes the scalar constraint's.
#[test]
fn store_matches_the_scalar_store() {
    use crate::body_set::BodyHandle;
    use crate::contact::{ContactManifold, ContactPoint};
    let mut rng = Rng(99);
    let (bodies, cons) = scene(&mut rng, 10);
    let handle = |i: usize| BodyHandle {
        index: i as u32,
        generation: 0,
    };
    let manifolds: Vec<ContactManifold> = cons
        .iter()
        .map(|c| {
            let mut m = ContactManifold::new(handle(c.a), handle(c.b), c.normal);
            for k in 0..c.len {
                m.push(ContactPoint::new(Vec3::ZERO, Vec3::ZERO, 0.0, k as u32))
                    .unwrap();
            }
            m
        })
        .collect();
    let mut wide = WideScratch::default();
    let mut overflow = Vec::new();
    let points = |k: usize| cons[k].len;
    fill(
        &mut wide,
        &mut overflow,
        &[0..10, 10..10],
        &bodies,
        points,
        |k, c, _| *c = cons[k].clone(),
    );
    let (mut m_wide, mut m_scalar) = (manifolds.clone(), manifolds);
    store(&wide, &mut m_wide, 4.0);
    contact::store(&cons, &mut m_scalar, 4.0);
    for (x, y) in m_wide.iter().zip(&m_scalar) {
        assert_eq!(x.tangent, y.tangent);
        assert!(x.total_normal_impulse() > 0.0);
        for (p, q) in x.points().iter().zip(y.points()) {
            assert_eq!(p.normal_impulse, q.normal_impulse);
            assert_eq!(p.tangent_impulse, q.tangent_impulse);
        }
    }
}

/// The soft solve with the linear velocities in the constraint frame
/// (`contact::FrameVelocity`) against the row-by-row solve (`contact::solve_soft_rows`, the
/// oracle): random constraints (one to four points, shared static body, kinematic-like
/// bodies without mass), solve and relax passes in turn; then degenerate ones: touching
/// points (zero separation), zero velocities, a body without mass on both sides but one
/// lane, and bodies moving at 10³ m/s far from the origin.
#[test]
fn frame_solve_matches_row_by_row_solve() {
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    let check = |bodies: Vec<SolverBody>, cons: Vec<ContactConstraint>| {
        let (mut b1, mut c1) = (bodies.clone(), cons.clone());
        let (mut b2, mut c2) = (bodies, cons);
        for pass in 0..6 {
            let bias = pass % 2 == 0;
            for (x, y) in c1.iter_mut().zip(c2.iter_mut()) {
                let (i, j) = (x.a, x.b);
                let (mut a1, mut bb1) = (b1[i], b1[j]);
                contact::solve_soft(x, &mut a1, &mut bb1, 240.0, 3.0, bias);
                if b1[i].dynamic {
                    b1[i] = a1;
                }
                if b1[j].dynamic {
                    b1[j] = bb1;
                }
                let (mut a2, mut bb2) = (b2[i], b2[j]);
                contact::solve_soft_rows(y, &mut a2, &mut bb2, 240.0, 3.0, bias);
                if b2[i].dynamic {
                    b2[i] = a2;
                }
                if b2[j].dynamic {
                    b2[j] = bb2;
                }
            }
            compare(&b1, &b2, &c1, &c2);
        }
    };
    for count in [1, 2, 5, 9, 16] {
        let (bodies, cons) = scene(&mut rng, count);
        check(bodies, cons);
    }
    // Degenerate: touching, at rest, and fast far-away bodies.
    let (mut bodies, mut cons) = scene(&mut rng, 8);
    for (k, c) in cons.iter_mut().enumerate() {
        for p in c.points[..c.len].iter_mut() {
            if k % 2 == 0 {
                p.separation = 0.0;
            }
        }
    }
    for (k, b) in bodies.iter_mut().enumerate() {
        match k % 3 {
            0 => {
                b.v = Vec3::ZERO;
                b.w = Vec3::ZERO;
            }
            1 => b.v += Vec3::new(1e3, -1e3, 5e2),
            _ => {}
        }
    }
    check(bodies.clone(), cons.clone());
    // A lane whose bodies both carry no mass: its impulses and velocities stay put.
    for b in bodies.iter_mut() {
        b.inv_m = 0.0;
        b.inv_i = Mat3::ZERO;
    }
    for c in cons.iter_mut() {
        for p in c.points[..c.len].iter_mut() {
            for r in [&mut p.normal_row]
                .into_iter()
                .chain(p.tangent_rows.iter_mut())
            {
                *r = ContactRow::ZERO;
            }
        }
    }
    let before = bodies.clone();
    let mut after = bodies.clone();
    for c in cons.iter_mut() {
        let (i, j) = (c.a, c.b);
        let (mut a, mut b) = (after[i], after[j]);
        contact::solve_soft(c, &mut a, &mut b, 240.0, 3.0, true);
        after[i] = a;
        after[j] = b;
    }
    assert_eq!(before, after);
}

/// The layout the solve streams through: a point keeps its two lever arms, three rows of
/// `I⁻¹ (r × d)` (both bodies) and effective mass, and five impulse and separation values —
/// 32 lane values (512 bytes in f32, eight cache lines), down from 45 (720 bytes) while the
/// rows also kept `r × d` and 33 while the point kept its relative velocity (now in the
/// constraint, read by the restitution pass only).
#[test]
fn a_wide_point_is_32_lane_values() {
    assert_eq!(
        std::mem::size_of::<WidePoint>(),
        32 * std::mem::size_of::<W>()
    );
    assert_eq!(std::mem::size_of::<WideRow>(), 7 * std::mem::size_of::<W>());
}

/// A wide constraint: 145 lane values (13 per constraint — the second tangent is
/// recomputed —, 4 × 32 per point, the four points' relative velocities) and 80 bytes of
/// `u32` lane indices, write flags and the point count — 2,400 bytes in f32 (2,512 with
/// `usize` indices, a stored second tangent and the relative velocity in the points).
#[test]
fn a_wide_constraint_is_145_lane_values_and_80_bytes() {
    let (w, align) = (std::mem::size_of::<W>(), std::mem::align_of::<W>());
    let raw = 145 * w + 4 * 4 * 4 + 2 * 4 + std::mem::size_of::<usize>();
    assert_eq!(raw, 145 * w + 80);
    assert_eq!(
        std::mem::size_of::<WideConstraint>(),
        raw.div_ceil(align) * align
    );
}

/// `assign` (a counting sort by point count) puts every constraint in the lane the direct
/// rule gives: per colour, the four-point constraints first, then three, two and one, each
/// in colour order, four lanes per wide constraint, padding only in a colour's last one.
/// The oracle is that rule written as four filtered passes (the previous implementation);
/// point counts 0 (treated as 1) to 4, empty colours, colours of 1–40 constraints.
#[test]
fn lane_assignment_matches_the_four_pass_rule() {
    let mut rng = Rng(0xa551);
    let mut wide = WideScratch::default();
    for round in 0..200 {
        let colours = 1 + round % 7;
        let mut ranges = Vec::new();
        let mut start = 0;
        for _ in 0..=colours {
            let len = (rng.next() * 41.0) as usize % 41 * usize::from(rng.next() > 0.1);
            ranges.push(start..start + len);
            start += len;
        }
        let counts: Vec<usize> = (0..start)
            .map(|_| (rng.next() * 5.0) as usize % 5)
            .collect();
        assign(&mut wide, &ranges, |k| counts[k]);
        // The oracle.
        let mut members: Vec<[usize; LANES]> = Vec::new();
        let mut wide_ranges = Vec::new();
        for r in &ranges[..ranges.len() - 1] {
            let first = members.len();
            let mut lane = LANES;
            for count in (1..=MAX_MANIFOLD_POINTS).rev() {
                for k in r.clone().filter(|&k| counts[k].clamp(1, 4) == count) {
                    if lane == LANES {
                        members.push([NONE; LANES]);
                        lane = 0;
                    }
                    let last = members.len() - 1;
                    members[last][lane] = k;
                    lane += 1;
                }
            }
            wide_ranges.push(first..members.len());
        }
        assert_eq!(wide.members, members, "round {round}");
        assert_eq!(wide.ranges, wide_ranges, "round {round}");
        assert_eq!(wide.cons.len(), members.len());
    }
}

/// Every instruction set the CPU has runs the production kernels ([`WarmStart`],
/// [`SoftSolve`], [`Restitution`]) to the scalar routines' bits: the AVX and AVX-512 copies
/// of the passes differ from the baseline only in encoding and register allocation.
#[test]
fn every_instruction_set_gives_the_scalar_bits() {
    for isa in Isa::available() {
        let mut rng = Rng(0x2545_f491_4f6c_dd1d);
        for count in [1, 4, 7, 16] {
            let (mut bodies, mut cons) = scene(&mut rng, count);
            let (mut bodies2, mut cons2) = (bodies.clone(), cons.clone());
            let ranges = [0..count, count..count];
            let mut wide = WideScratch::default();
            build(&cons, &ranges, &bodies, &mut wide);
            let inv_h = 240.0;
            for pass in 0..4 {
                let scalar = |c: &mut ContactConstraint, a: &mut SolverBody, b: &mut SolverBody| {
                    match pass {
                        0 => contact::warm_start(c, a, b),
                        1 => contact::solve_soft(c, a, b, inv_h, 3.0, true),
                        2 => contact::solve_soft(c, a, b, inv_h, 3.0, false),
                        _ => contact::apply_restitution(c, a, b, 1.0),
                    }
                };
                let (cs, n) = (wide.cons.as_mut_ptr(), wide.cons.len());
                let (bs, nb) = (bodies.as_mut_ptr(), bodies.len());
                let all = |_: &WideConstraint| true;
                let solve = |use_bias| SoftSolve {
                    inv_h,
                    max_push: 3.0,
                    use_bias,
                };
                // SAFETY: `cs`, `bs` are the only access to the constraints and bodies here,
                // and `isa` is one the CPU has.
                unsafe {
                    match pass {
                        0 => solve_range_on(isa, cs, 0..n, bs, nb, &WarmStart, &all),
                        1 => solve_range_on(isa, cs, 0..n, bs, nb, &solve(true), &all),
                        2 => solve_range_on(isa, cs, 0..n, bs, nb, &solve(false), &all),
                        _ => {
                            let r = Restitution { threshold: 1.0 };
                            solve_range_on(isa, cs, 0..n, bs, nb, &r, &has_restitution)
                        }
                    }
                }
                super::super::coloring::solve_coloured(
                    &mut cons2,
                    &ranges,
                    &mut bodies2,
                    false,
                    1,
                    scalar,
                );
                write_back(&wide, &mut cons);
                same_bits(&bodies, &bodies2, &cons, &cons2);
            }
            assert_eq!(bodies[0], bodies2[0], "{isa:?}: static body written");
        }
    }
}
