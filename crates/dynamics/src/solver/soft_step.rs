//! The substepping soft step of Box2D v3 (Catto, "Solver2D", 2024; `solver.c`,
//! `contact_solver.c`).
//!
//! Per step: prepare the constraints once; then for each of `n` substeps of `h = dt/n`:
//! integrate velocities, warm start, solve with soft position feedback (contact hertz and
//! damping ratio; penetration recovery capped at `max_push_velocity`), integrate positions,
//! and relax (solve again without bias, so the feedback leaves no velocity behind); finally a
//! restitution pass. Constraint errors follow the substeps through the position deltas
//! (`dp`, `dq`) accumulated since the start of the step. Impulses are per substep inside and
//! stored per step outside.

use super::coloring::solve_coloured;
use super::contact::ContactConstraint;
use super::contact_simd::WideScratch;
use super::timing::lap;
use super::{contact, contact_simd, joints, Softness, SolverBody, StepContext};
use crate::integrate;
use carom_collision::math::{Real, Vec3};
use std::ops::Range;
use std::time::Instant;

/// Runs one step of the soft-step solver.
pub(crate) fn step(ctx: &mut StepContext) {
    let p = *ctx.params;
    let n = p.substeps.max(1);
    let h = ctx.dt / n as Real;
    let inv_h = 1.0 / h;
    let mut t = Instant::now();

    for b in ctx.bodies.iter_mut() {
        b.dp = Vec3::ZERO;
        b.dq = Vec3::ZERO;
    }
    let warm = if p.warm_starting {
        1.0 / n as Real
    } else {
        0.0
    };
    let (soft, static_soft) = contact::softness_pair(&p, h);
    let scratch = &mut ctx.scratch.contacts;
    let terms = &mut ctx.scratch.terms;
    integrate::prepare_terms(ctx.set, ctx.bodies, ctx.gravity, h, ctx.gyroscopic, terms);
    let simd = p.simd;
    contact::prepare(
        ctx.manifolds,
        ctx.set,
        ctx.bodies,
        warm,
        soft,
        static_soft,
        simd,
        scratch,
    );
    let (cons, ranges, wide) = (
        &mut scratch.cons,
        &scratch.colouring.ranges[..],
        &mut scratch.wide,
    );
    let rows = &mut *ctx.joint_scratch;
    joints::prepare(rows, ctx.joints, ctx.set, ctx.bodies, h, warm);
    let joint_soft = Softness::new(p.joint_hertz, p.joint_damping_ratio, h);
    let (par, min) = (ctx.parallel, p.parallel_min_batch);
    let max_push = p.max_push_velocity;
    lap(&mut t, &mut ctx.timings.prepare);

    for _ in 0..n {
        integrate::integrate_velocities(&mut terms[..], &ctx.set.rotation, ctx.bodies, h);
        lap(&mut t, &mut ctx.timings.forces);

        if p.warm_starting {
            joints::warm_start(rows, ctx.bodies);
            if simd {
                let b = &mut *ctx.bodies;
                let (w, s) = (contact_simd::warm_start, contact::warm_start);
                contact_simd::solve(wide, cons, b, par, min, w, s);
            } else {
                solve_coloured(cons, ranges, ctx.bodies, par, min, contact::warm_start);
            }
        }
        lap(&mut t, &mut ctx.timings.warm_start);

        joints::solve(rows, ctx.bodies, joint_soft, inv_h, true);
        let solve = (inv_h, max_push, true);
        solve_contacts(simd, wide, cons, ranges, ctx.bodies, (par, min), solve);
        lap(&mut t, &mut ctx.timings.solve);

        // The speed clamp of the solve and the position update, fused in one pass.
        integrate::clamp_and_integrate_positions(terms, ctx.set, ctx.bodies, h);
        lap(&mut t, &mut ctx.timings.integrate);

        // Joint rows follow the new poses (they stay valid until the next position update).
        joints::refresh(rows, ctx.joints, ctx.set, ctx.bodies);
        joints::solve(rows, ctx.bodies, joint_soft, inv_h, false);
        let relax = (inv_h, max_push, false);
        solve_contacts(simd, wide, cons, ranges, ctx.bodies, (par, min), relax);
        lap(&mut t, &mut ctx.timings.relax);
    }

    let threshold = p.restitution_threshold;
    if simd {
        contact_simd::solve_active(
            wide,
            cons,
            ctx.bodies,
            (par, min),
            contact_simd::has_restitution,
            |c, a, b| contact_simd::apply_restitution(c, a, b, threshold),
            |c, a, b| contact::apply_restitution(c, a, b, threshold),
        );
        contact_simd::store(wide, ctx.manifolds, n as Real);
    } else {
        solve_coloured(cons, ranges, ctx.bodies, par, min, |c, a, b| {
            contact::apply_restitution(c, a, b, threshold)
        });
    }
    lap(&mut t, &mut ctx.timings.restitution);

    contact::store(cons, ctx.manifolds, n as Real);
    joints::store(rows, ctx.joints, n as Real);
    lap(&mut t, &mut ctx.timings.store);
}

/// One soft contact pass (`(inv_h, max_push, use_bias)`) over every colour: four-wide with
/// SIMD when `simd` (the overflow colour scalar), else scalar; `(parallel, min_batch)` as
/// in [`solve_coloured`].
fn solve_contacts(
    simd: bool,
    wide: &mut WideScratch,
    cons: &mut [ContactConstraint],
    ranges: &[Range<usize>],
    bodies: &mut [SolverBody],
    (par, min): (bool, usize),
    (inv_h, max_push, use_bias): (Real, Real, bool),
) {
    if simd {
        contact_simd::solve(
            wide,
            cons,
            bodies,
            par,
            min,
            |c, a, b| contact_simd::solve_soft(c, a, b, inv_h, max_push, use_bias),
            |c, a, b| contact::solve_soft(c, a, b, inv_h, max_push, use_bias),
        );
    } else {
        solve_coloured(cons, ranges, bodies, par, min, |c, a, b| {
            contact::solve_soft(c, a, b, inv_h, max_push, use_bias)
        });
    }
}
