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
//!
//! Everything from the build of the wide contact constraints (SIMD; the selection, the
//! colouring and the lane assignment run before) to the restitution pass is one list of
//! stages (module `stages`, Box2D's `b2SolverStage`s) run in one parallel region: the
//! contact build in the blocks of each colour's passes, the body stages in blocks of
//! bodies, each joint and contact colour in blocks of constraints, the overflow colours as
//! single blocks, and the store of the velocities, world inertias and wide constraints'
//! impulses (module `soft_stages`).

use super::soft_stages::{self, Pass, SoftStage};
use super::stages::thread_count;
use super::timing::lap;
use super::{contact, contact_simd, joints, Softness, StepContext};
use crate::integrate;
use carom_collision::math::{Real, Vec3};
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
    // Only the selection is serial: the first velocity stage fills the terms in its blocks.
    integrate::select_terms(ctx.set, ctx.bodies, terms);
    let simd = p.simd;
    let threads = thread_count(ctx.parallel);
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
    let rows = &mut *ctx.joint_scratch;
    // The rows, blocks and effective masses are built by the first joint pass (parallel
    // blocks of each colour); only the layout is serial.
    joints::plan(rows, ctx.joints, ctx.bodies);

    let plan = &mut ctx.scratch.stages;
    let colours = if simd {
        &scratch.wide.ranges[..]
    } else {
        let r = &scratch.colouring.ranges[..];
        &r[..r.len().saturating_sub(1)]
    };
    let overflow = if simd {
        scratch.wide.overflow.len()
    } else {
        scratch.colouring.ranges.last().map_or(0, |r| r.len())
    };
    let shape = soft_stages::Shape {
        substeps: n,
        warm_starting: p.warm_starting,
        joint_colours: &rows.colours,
        colours,
        lanes: if simd { contact_simd::LANES } else { 1 },
        overflow,
        bodies: terms.len(),
        min_batch: p.parallel_min_batch,
        wide: if simd { scratch.wide.cons.len() } else { 0 },
        prepare: simd,
    };
    soft_stages::plan(plan, &shape);
    let consts = soft_stages::Consts {
        h,
        inv_h,
        joint_soft: Softness::new(p.joint_hertz, p.joint_damping_ratio, h),
        max_push: p.max_push_velocity,
        restitution_threshold: p.restitution_threshold,
        simd,
        impulse_scale: n as Real,
        impulse_in: warm,
        contact_soft: (soft, static_soft),
        min_batch: p.parallel_min_batch,
        gravity: ctx.gravity,
        gyroscopic: ctx.gyroscopic,
    };
    lap(&mut t, &mut ctx.timings.prepare);

    soft_stages::run(
        plan,
        threads,
        consts,
        ctx.set,
        ctx.bodies,
        terms,
        scratch,
        rows,
        ctx.joints,
        ctx.manifolds,
    );
    for (kind, d) in plan.durations() {
        let slot = match kind {
            SoftStage::IntegrateVelocities(_) => &mut ctx.timings.forces,
            SoftStage::IntegratePositions => &mut ctx.timings.integrate,
            SoftStage::StoreBodies | SoftStage::StoreImpulses => &mut ctx.timings.store,
            SoftStage::Prepare(_) | SoftStage::PrepareRest => &mut ctx.timings.prepare,
            SoftStage::Joints(pass, _, _)
            | SoftStage::Colour(pass, _)
            | SoftStage::Serial(pass, _, _) => match pass {
                Pass::WarmStart => &mut ctx.timings.warm_start,
                Pass::Solve => &mut ctx.timings.solve,
                Pass::Relax => &mut ctx.timings.relax,
                Pass::Restitution => &mut ctx.timings.restitution,
            },
        };
        *slot += d;
    }
    t = Instant::now();

    // The wide constraints' impulses, the velocities and the world inertias were stored by
    // the last stages; what is left is serial and small.
    contact::store(&scratch.cons, ctx.manifolds, n as Real);
    joints::store(rows, ctx.joints, n as Real, true);
    integrate::clear_forces(ctx.set, ctx.bodies.len());
    lap(&mut t, &mut ctx.timings.store);
}
