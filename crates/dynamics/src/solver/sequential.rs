//! Sequential impulses with warm starting and split impulses.
//!
//! Catto, "Iterative Dynamics with Temporal Coherence" (GDC 2005); Bullet's
//! `btSequentialImpulseConstraintSolver` with `m_splitImpulse`: gravity and forces, warm
//! start, velocity iterations (joints, then contacts colour by colour), split-impulse
//! iterations on pseudo-velocities, and integration with `v + v_push`; the pseudo-velocities
//! are then dropped, so resolving penetration never adds kinetic energy.

use super::coloring::solve_coloured;
use super::timing::lap;
use super::{contact, joints, Softness, StepContext};
use crate::integrate;
use carom_collision::math::Vec3;
use std::time::Instant;

/// Runs one step of the sequential-impulse solver.
pub(crate) fn step(ctx: &mut StepContext) {
    let p = *ctx.params;
    let dt = ctx.dt;
    let mut t = Instant::now();
    let terms = &mut ctx.scratch.terms;
    integrate::prepare_terms(ctx.set, ctx.bodies, ctx.gravity, dt, ctx.gyroscopic, terms);
    integrate::integrate_velocities(&mut terms[..], &ctx.set.rotation, ctx.bodies, dt);
    lap(&mut t, &mut ctx.timings.forces);

    let warm = if p.warm_starting { 1.0 } else { 0.0 };
    let scratch = &mut ctx.scratch.contacts;
    contact::prepare(
        ctx.manifolds,
        ctx.set,
        ctx.bodies,
        warm,
        Softness::RIGID,
        Softness::RIGID,
        false,
        scratch,
    );
    let (cons, ranges) = (&mut scratch.cons, &scratch.colouring.ranges[..]);
    let rows = &mut *ctx.joint_scratch;
    joints::prepare(rows, ctx.joints, ctx.set, ctx.bodies, dt, warm);
    rows.order_by_slot();
    lap(&mut t, &mut ctx.timings.prepare);

    let bodies = &mut ctx.bodies[..];
    let (par, min) = (ctx.parallel, p.parallel_min_batch);
    if p.warm_starting {
        joints::warm_start(rows, bodies);
        solve_coloured(cons, ranges, bodies, par, min, contact::warm_start);
    }
    lap(&mut t, &mut ctx.timings.warm_start);

    let joint_soft = Softness::baumgarte(p.joint_erp, dt);
    let threshold = p.restitution_threshold;
    for _ in 0..p.velocity_iterations {
        joints::solve(rows, bodies, joint_soft, 1.0 / dt, true);
        solve_coloured(cons, ranges, bodies, par, min, |c, a, b| {
            contact::solve_velocity_si(c, a, b, dt, threshold)
        });
    }
    integrate::clamp_speeds(ctx.set, bodies);
    lap(&mut t, &mut ctx.timings.solve);

    for b in bodies.iter_mut() {
        b.dp = Vec3::ZERO;
        b.dq = Vec3::ZERO;
    }
    let (erp_over_dt, slop) = (p.split_erp / dt, p.linear_slop);
    for _ in 0..p.position_iterations {
        solve_coloured(cons, ranges, bodies, par, min, |c, a, b| {
            contact::solve_push_si(c, a, b, erp_over_dt, slop)
        });
    }
    lap(&mut t, &mut ctx.timings.relax);

    integrate::integrate_positions(ctx.set, bodies, dt, true);
    lap(&mut t, &mut ctx.timings.integrate);

    contact::store(cons, ctx.manifolds, 1.0);
    joints::store(rows, ctx.joints, 1.0, false);
    integrate::store(ctx.set, ctx.bodies);
    lap(&mut t, &mut ctx.timings.store);
}
