//! Joint rows in the step: build, refresh, warm start, solve and store, shared by both
//! solvers. Joints are solved sequentially in slot order, before the contacts of each
//! iteration (Bullet solves non-contact constraints first as well). Runs of equality rows
//! (a ball joint's point, a fixed joint's rotation) are solved as coupled blocks
//! ([`Block`](super::rows::Block)); the soft step rebuilds every joint's rows from the current poses before each
//! solve and relax pass ([`refresh`]).

use super::{Softness, SolverBody};
use crate::body_set::BodySet;
use crate::joint::{build_rows, refresh_rows, JointRows, JointSet, ROW_SLOTS};
use carom_collision::math::Real;

/// Rows of every active joint; `impulse_in` converts stored per-step impulses to the
/// solver's units.
pub(crate) fn build_all(
    joints: &JointSet,
    set: &BodySet,
    bodies: &[SolverBody],
    h: Real,
    impulse_in: Real,
) -> Vec<JointRows> {
    joints
        .iter()
        .filter_map(|(handle, j)| build_rows(handle.index as usize, j, set, bodies, h, impulse_in))
        .collect()
}

/// Rebuilds every joint's rows from the bodies' current poses, keeping the accumulated
/// impulses (soft step, between substeps; no allocation once the rows exist).
pub(crate) fn refresh(
    rows: &mut [JointRows],
    joints: &JointSet,
    set: &BodySet,
    bodies: &[SolverBody],
    h: Real,
) {
    for jr in rows.iter_mut() {
        if let Some(j) = joints.get_index(jr.joint) {
            refresh_rows(jr, j, set, bodies, h);
        }
    }
}

/// Applies the accumulated impulses.
pub(crate) fn warm_start(rows: &mut [JointRows], bodies: &mut [SolverBody]) {
    for jr in rows.iter_mut() {
        let (mut a, mut b) = (bodies[jr.a], bodies[jr.b]);
        for (_, row) in jr.rows.iter() {
            row.warm_start(&mut a, &mut b);
        }
        write_back(bodies, jr, a, b);
    }
}

fn write_back(bodies: &mut [SolverBody], jr: &JointRows, a: SolverBody, b: SolverBody) {
    if a.dynamic {
        bodies[jr.a] = a;
    }
    if b.dynamic {
        bodies[jr.b] = b;
    }
}

/// One pass over every row: blocks of equality rows together, the other rows one by one,
/// in row order.
pub(crate) fn solve(
    rows: &mut [JointRows],
    bodies: &mut [SolverBody],
    soft: Softness,
    inv_h: Real,
    use_bias: bool,
    track_deltas: bool,
) {
    for jr in rows.iter_mut() {
        let (mut a, mut b) = (bodies[jr.a], bodies[jr.b]);
        let mut next_block = 0;
        let mut i = 0;
        while i < jr.rows.len() {
            match jr.blocks.get(next_block) {
                Some(block) if block.start == i => {
                    let run = &mut jr.rows[i..i + block.len];
                    block.solve(run, &mut a, &mut b, soft, use_bias, track_deltas);
                    i += block.len;
                    next_block += 1;
                }
                _ => {
                    let row = &mut jr.rows[i].1;
                    row.solve(&mut a, &mut b, soft, inv_h, use_bias, track_deltas);
                    i += 1;
                }
            }
        }
        write_back(bodies, jr, a, b);
    }
}

/// Stores the impulses (scaled to per-step units) for warm starting and breaking.
pub(crate) fn store(rows: &[JointRows], joints: &mut JointSet, scale: Real) {
    for jr in rows {
        if let Some(j) = joints.get_index_mut(jr.joint) {
            j.impulses = [0.0; ROW_SLOTS];
            for (slot, row) in &jr.rows {
                j.impulses[*slot] = row.impulse * scale;
            }
        }
    }
}
