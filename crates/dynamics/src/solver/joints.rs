//! Joint rows in the step: build, warm start, solve and store, shared by both solvers.
//! Joints are solved sequentially in slot order, before the contacts of each iteration
//! (Bullet solves non-contact constraints first as well).

use super::{Softness, SolverBody};
use crate::body_set::BodySet;
use crate::joint::{build_rows, JointRows, JointSet, ROW_SLOTS};
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

fn each_joint(
    rows: &mut [JointRows],
    bodies: &mut [SolverBody],
    mut f: impl FnMut(&mut crate::solver::rows::Row, &mut SolverBody, &mut SolverBody),
) {
    for jr in rows.iter_mut() {
        let (mut a, mut b) = (bodies[jr.a], bodies[jr.b]);
        for (_, row) in jr.rows.iter_mut() {
            f(row, &mut a, &mut b);
        }
        if a.dynamic {
            bodies[jr.a] = a;
        }
        if b.dynamic {
            bodies[jr.b] = b;
        }
    }
}

/// Applies the accumulated impulses.
pub(crate) fn warm_start(rows: &mut [JointRows], bodies: &mut [SolverBody]) {
    each_joint(rows, bodies, |r, a, b| r.warm_start(a, b));
}

/// One pass over every row.
pub(crate) fn solve(
    rows: &mut [JointRows],
    bodies: &mut [SolverBody],
    soft: Softness,
    inv_h: Real,
    use_bias: bool,
    track_deltas: bool,
) {
    each_joint(rows, bodies, |r, a, b| {
        r.solve(a, b, soft, inv_h, use_bias, track_deltas)
    });
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
