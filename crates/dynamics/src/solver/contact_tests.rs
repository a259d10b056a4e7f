//! Test-only companions of the contact solve (module `contact`): the row-by-row oracle of
//! the frame-velocity solve, used by `contact_simd_tests.rs`.

use super::{soft_terms, solve_friction, ContactConstraint, SolverBody};
use carom_collision::math::Real;

/// [`solve_soft`](super::solve_soft) applying every row to the bodies (the form before
/// [`FrameVelocity`](super::FrameVelocity)): the
/// oracle of the frame form's test.
pub(crate) fn solve_soft_rows(
    c: &mut ContactConstraint,
    a: &mut SolverBody,
    b: &mut SolverBody,
    inv_h: Real,
    max_push: Real,
    use_bias: bool,
) {
    solve_friction(c, a, b);
    let (linear, soft) = (c.normal.dot(b.dp - a.dp), c.softness);
    for p in c.points[..c.len].iter_mut() {
        let row = &p.normal_row;
        let s = p.separation + row.displacement(linear, a, b);
        let (bias, mass_scale, impulse_scale) = soft_terms(soft, s, inv_h, max_push, use_bias);
        let vn = row.velocity(c.normal, a, b);
        let lambda = -row.mass * mass_scale * (vn + bias) - impulse_scale * p.normal_impulse;
        let new = (p.normal_impulse + lambda).max(0.0);
        row.apply(c.normal, new - p.normal_impulse, a, b);
        p.normal_impulse = new;
        p.max_normal_impulse = p.max_normal_impulse.max(new);
    }
}
