//! Unit tests of `rows` (kept apart to keep the module under 700 lines).

use super::*;

fn body(seed: Real) -> SolverBody {
    let v = |k: Real| Vec3::new(seed * k, 0.3 - seed * k, 0.7 * k - seed);
    SolverBody {
        v: v(1.3),
        w: v(-0.9),
        dp: Vec3::ZERO,
        dq: Vec3::ZERO,
        inv_m: 0.5 + seed,
        inv_i: Mat3::from_diagonal(Vec3::new(1.0 + seed, 2.0 - seed, 1.5)),
        dynamic: true,
    }
}

/// The full `J v` and impulse update, linear terms included (the reference).
fn velocity_ref(r: &Row, a: &Motion, b: &Motion) -> Real {
    r.lin.dot(b.v - a.v) + r.ang_a.dot(a.w) + r.ang_b.dot(b.w)
}

fn apply_ref(r: &Row, a: &mut Motion, b: &mut Motion, lambda: Real) {
    a.v -= r.lin * (a.inv_m * lambda);
    a.w += r.ia * lambda;
    b.v += r.lin * (b.inv_m * lambda);
    b.w += r.ib * lambda;
}

/// An angular row (zero `lin`) skips only terms that are zero: its velocity and impulse
/// update equal the full formula bit for bit (nonzero results); a linear row is not
/// marked, and a refresh re-marks the row.
#[test]
fn angular_rows_skip_only_zero_terms() {
    let (sa, sb) = (body(0.21), body(0.67));
    let axis = Vec3A::new(0.3, -0.8, 0.52).normalize();
    let mut row = Row::new(9, [Vec3A::ZERO, -axis, axis], 0.01, RowKind::Equality, 0.0);
    assert!(row.angular);
    row.finish(&PairInertia::of(&sa, &sb));
    let (a, b) = (Motion::of(&sa), Motion::of(&sb));
    let v = row.velocity(&a, &b);
    assert_ne!(v, 0.0);
    assert_eq!(v.to_bits(), velocity_ref(&row, &a, &b).to_bits());
    let (mut a1, mut b1, mut a2, mut b2) = (a, b, a, b);
    row.apply(&mut a1, &mut b1, 0.37);
    apply_ref(&row, &mut a2, &mut b2, 0.37);
    assert_eq!((a1.v, a1.w, b1.v, b1.w), (a2.v, a2.w, b2.v, b2.w));
    // A refresh to a linear Jacobian clears the mark, and the linear terms count.
    let lin = Vec3A::new(0.0, 1.0, 0.0);
    row.set([lin, Vec3A::X, Vec3A::Y], 0.0);
    assert!(!row.angular);
    row.finish(&PairInertia::of(&sa, &sb));
    assert_eq!(
        row.velocity(&a, &b).to_bits(),
        velocity_ref(&row, &a, &b).to_bits()
    );
}

/// The oracle of [`PointBlock`]: the three equality rows along an orthonormal frame
/// `[axis, −r_a × axis, r_b × axis]` with error `d · axis`, solved as a 3×3 [`Block`].
/// Both are the same linear system up to a rotation, so one solve gives the same
/// velocities and the same impulse (as components along the frame) up to round-off:
/// long and zero lever arms, a static A, a frame far from the axes, with and without
/// bias; a singular `K` (no inverse mass or inertia) changes nothing and stays finite.
#[test]
fn point_block_matches_three_rows_along_a_frame() {
    let soft = Softness::new(60.0, 2.0, 1.0 / 240.0);
    let q =
        carom_collision::math::Quat::from_axis_angle(Vec3::new(0.3, -1.0, 0.6).normalize(), 0.9);
    let frame = [q * Vec3::X, q * Vec3::Y, q * Vec3::Z].map(Vec3A::from);
    let mut static_a = body(0.0);
    static_a.inv_m = 0.0;
    static_a.inv_i = Mat3::ZERO;
    static_a.v = Vec3::ZERO;
    static_a.w = Vec3::ZERO;
    let arms = [
        (Vec3A::new(0.4, -0.2, 0.1), Vec3A::new(-0.3, 0.25, 0.2)),
        (Vec3A::new(2.0, 1.5, -0.7), Vec3A::new(0.01, 0.0, -0.02)),
        (Vec3A::ZERO, Vec3A::ZERO),
    ];
    let d = Vec3A::new(0.02, -0.01, 0.03);
    for (sa, sb) in [(body(0.13), body(0.44)), (static_a, body(0.3))] {
        for (ra, rb) in arms {
            for use_bias in [true, false] {
                let p = PairInertia::of(&sa, &sb);
                let mut rows: Vec<Row> = (0..3)
                    .map(|i| {
                        let axis = frame[i];
                        let j = [axis, -ra.cross(axis), rb.cross(axis)];
                        let mut r = Row::new(0, j, d.dot(axis), RowKind::Equality, 0.0);
                        r.impulse = 0.1 * (i as Real + 1.0);
                        r
                    })
                    .collect();
                let mut block = Block::new(0, 3);
                block.update(&mut rows, &p);
                let mut point = PointBlock::new(ra, rb, d, frame);
                point.impulse = frame[0] * 0.1 + frame[1] * 0.2 + frame[2] * 0.3;
                point.update(&p);
                assert!(block.valid && point.valid);
                let (mut a, mut b) = (Motion::of(&sa), Motion::of(&sb));
                let (mut ea, mut eb) = (a, b);
                point.solve(&mut a, &mut b, soft, use_bias);
                block.solve(&mut rows, &mut ea, &mut eb, soft, use_bias);
                let close = |x: Vec3A, y: Vec3A| (x - y).length() <= 1e-4 * (1.0 + y.length());
                let what = format!("ra {ra} rb {rb} bias {use_bias}");
                assert!(close(a.v, ea.v) && close(a.w, ea.w), "{what}");
                assert!(close(b.v, eb.v) && close(b.w, eb.w), "{what}");
                assert_ne!((b.v, b.w), (Motion::of(&sb).v, Motion::of(&sb).w), "{what}");
                let slots = point.slot_impulses(point.impulse);
                for (s, r) in slots.iter().zip(&rows) {
                    assert!(
                        (s - r.impulse).abs() <= 1e-4 * (1.0 + r.impulse.abs()),
                        "{what}"
                    );
                }
                // The warm start applies the same impulse as the rows' warm start.
                let (mut a, mut b) = (Motion::of(&sa), Motion::of(&sb));
                let (mut ea, mut eb) = (a, b);
                point.warm_start(&mut a, &mut b);
                for r in &rows {
                    r.warm_start(&mut ea, &mut eb);
                }
                assert!(
                    close(a.w, ea.w) && close(b.v, eb.v) && close(b.w, eb.w),
                    "{what}"
                );
            }
        }
    }
    // Singular: neither body can move. The block falls back, applies nothing, stays finite.
    let mut frozen = static_a;
    frozen.v = Vec3::new(1.0, 0.0, 0.0);
    let mut point = PointBlock::new(arms[0].0, arms[0].1, d, frame);
    point.update(&PairInertia::of(&static_a, &frozen));
    assert!(!point.valid);
    let (mut a, mut b) = (Motion::of(&static_a), Motion::of(&frozen));
    point.solve(&mut a, &mut b, soft, true);
    assert_eq!(
        (a.v, a.w, b.v, b.w),
        (Vec3A::ZERO, Vec3A::ZERO, Vec3A::X, Vec3A::ZERO)
    );
    assert!(point.impulse.is_finite());
}

/// `Block::solve` on two and three rows equals the coupled update written out with the
/// full row formulas: `λ = -K⁻¹ (J v + bias)·mass_scale - impulse·impulse_scale`.
#[test]
fn block_solve_matches_the_coupled_formula() {
    let (sa, sb) = (body(0.13), body(0.44));
    let (ra, rb) = (Vec3A::new(0.4, -0.2, 0.1), Vec3A::new(-0.3, 0.25, 0.2));
    let soft = Softness::new(60.0, 2.0, 1.0 / 240.0);
    for n in [2, 3] {
        for use_bias in [true, false] {
            let mut rows: Vec<Row> = (0..n)
                .map(|i| {
                    let axis = [Vec3A::X, Vec3A::Y, Vec3A::Z][i];
                    let j = [axis, -ra.cross(axis), rb.cross(axis)];
                    let mut r = Row::new(i as u8, j, 0.01 * i as Real, RowKind::Equality, 0.0);
                    r.impulse = 0.1 * (i as Real + 1.0);
                    r
                })
                .collect();
            let mut block = Block::new(0, n);
            block.update(&mut rows, &PairInertia::of(&sa, &sb));
            assert!(block.valid);
            let mut expected = rows.clone();
            let (mut a, mut b) = (Motion::of(&sa), Motion::of(&sb));
            let (mut ea, mut eb) = (a, b);
            block.solve(&mut rows, &mut a, &mut b, soft, use_bias);
            // The reference.
            let (ms, is) = if use_bias {
                (soft.mass_scale, soft.impulse_scale)
            } else {
                (1.0, 0.0)
            };
            let (mut rhs, mut acc) = (Vec3A::ZERO, Vec3A::ZERO);
            for (i, r) in expected.iter().enumerate() {
                let bias = if use_bias { soft.bias_rate * r.c } else { 0.0 };
                rhs[i] = velocity_ref(r, &ea, &eb) + bias;
                acc[i] = r.impulse;
            }
            let lambda = -PairInertia::mul(&block.inv_k, rhs) * ms - acc * is;
            for (i, r) in expected.iter_mut().enumerate() {
                r.impulse += lambda[i];
                apply_ref(r, &mut ea, &mut eb, lambda[i]);
            }
            assert_eq!((a.v, a.w, b.v, b.w), (ea.v, ea.w, eb.v, eb.w), "{n} rows");
            for (r, e) in rows.iter().zip(&expected) {
                assert_eq!(r.impulse.to_bits(), e.impulse.to_bits());
            }
        }
    }
}
