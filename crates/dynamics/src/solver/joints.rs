//! Joint rows in the step: prepare, refresh, warm start, solve and store, shared by both
//! solvers. Joints are solved sequentially in slot order, before the contacts of each
//! iteration (Bullet solves non-contact constraints first as well). Runs of equality rows
//! (a ball joint's point, a fixed joint's rotation) are solved as coupled blocks
//! ([`Block`]).
//!
//! The rows live in the world-owned [`JointScratch`]: [`prepare`] fills it once per step
//! (no allocation once the buffers have grown to the joint count), and the soft step
//! [`refresh`]es the rows in place after each position update (Box3D's split of
//! `b3PrepareJoint` from the substep solves; module `joint::build`).

use super::rows::{Block, Motion, Row};
use super::{Softness, SolverBody};
use crate::body_set::BodySet;
use crate::joint::{prepare_joint, refresh_joint, JointRows, JointSet, ROW_SLOTS};
use carom_collision::math::Real;

/// The joint rows of the current step, reused from step to step: one [`JointRows`] per
/// active joint (in slot order), their rows and blocks in two shared buffers.
#[derive(Debug, Clone, Default)]
pub(crate) struct JointScratch {
    pub joints: Vec<JointRows>,
    pub rows: Vec<Row>,
    pub blocks: Vec<Block>,
}

/// Builds the rows of every active joint for a step with substep `h` (the whole step for
/// sequential impulses); `impulse_in` converts stored per-step impulses to the solver's
/// units.
pub(crate) fn prepare(
    s: &mut JointScratch,
    joints: &JointSet,
    set: &BodySet,
    bodies: &[SolverBody],
    h: Real,
    impulse_in: Real,
) {
    s.joints.clear();
    s.rows.clear();
    s.blocks.clear();
    for (handle, j) in joints.iter() {
        let index = handle.index as usize;
        let (rows, blocks) = (&mut s.rows, &mut s.blocks);
        if let Some(jr) = prepare_joint(index, j, set, bodies, h, impulse_in, rows, blocks) {
            s.joints.push(jr);
        }
    }
}

/// Updates every joint's rows to the bodies' current poses, keeping the accumulated
/// impulses (soft step, after each position update).
pub(crate) fn refresh(
    s: &mut JointScratch,
    joints: &JointSet,
    set: &BodySet,
    bodies: &[SolverBody],
) {
    for jr in &s.joints {
        if let Some(j) = joints.get_index(jr.joint) {
            refresh_joint(jr, j, set, bodies, &mut s.rows, &mut s.blocks);
        }
    }
}

/// Applies the accumulated impulses.
pub(crate) fn warm_start(s: &mut JointScratch, bodies: &mut [SolverBody]) {
    for jr in &s.joints {
        let (mut a, mut b) = (Motion::of(&bodies[jr.a]), Motion::of(&bodies[jr.b]));
        for row in &s.rows[jr.rows.clone()] {
            row.warm_start(&mut a, &mut b);
        }
        write_back(bodies, jr, a, b);
    }
}

fn write_back(bodies: &mut [SolverBody], jr: &JointRows, a: Motion, b: Motion) {
    a.store(&mut bodies[jr.a]);
    b.store(&mut bodies[jr.b]);
}

/// One pass over every row: valid blocks of equality rows together, the other rows one by
/// one, in row order. Each row's error is the one of its last build or refresh.
pub(crate) fn solve(
    s: &mut JointScratch,
    bodies: &mut [SolverBody],
    soft: Softness,
    inv_h: Real,
    use_bias: bool,
) {
    for jr in &s.joints {
        let (mut a, mut b) = (Motion::of(&bodies[jr.a]), Motion::of(&bodies[jr.b]));
        let rows = &mut s.rows[jr.rows.clone()];
        let mut i = 0;
        for block in &s.blocks[jr.blocks.clone()] {
            for row in &mut rows[i..block.start] {
                row.solve(&mut a, &mut b, soft, inv_h, use_bias);
            }
            let end = block.start + block.len;
            let run = &mut rows[block.start..end];
            if block.valid {
                block.solve(run, &mut a, &mut b, soft, use_bias);
            } else {
                for row in run {
                    row.solve(&mut a, &mut b, soft, inv_h, use_bias);
                }
            }
            i = end;
        }
        for row in &mut rows[i..] {
            row.solve(&mut a, &mut b, soft, inv_h, use_bias);
        }
        write_back(bodies, jr, a, b);
    }
}

/// Stores the impulses (scaled to per-step units) for warm starting and breaking.
pub(crate) fn store(s: &JointScratch, joints: &mut JointSet, scale: Real) {
    for jr in &s.joints {
        if let Some(j) = joints.get_index_mut(jr.joint) {
            j.impulses = [0.0; ROW_SLOTS];
            for row in &s.rows[jr.rows.clone()] {
                j.impulses[row.slot as usize] = row.impulse * scale;
            }
        }
    }
}
