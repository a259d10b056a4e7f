//! Generic one-dimensional constraint rows, the building blocks of every joint.
//!
//! A row is a Jacobian `J = (lin_a, ang_a, lin_b, ang_b)` with a position error `C`, solved
//! as in Catto's sequential impulses: `λ = -m_eff·(J v + bias)`, accumulated and clamped.
//! Bullet's joints (`btTypedConstraint::getInfo2`) and Box2D v3's joints are written the same
//! way; here every joint type only *builds* rows and one routine solves them all.

use super::{inv_or_zero, Softness, SolverBody};
use carom_collision::math::{Real, Vec3};

/// How a row constrains its velocity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum RowKind {
    /// `C = 0`, impulse unbounded.
    Equality,
    /// `C ≥ 0`, impulse ≥ 0 (limits); speculative while `C > 0`.
    Inequality,
    /// Drive `J v` to `speed` with `|impulse| ≤ max`.
    Motor { speed: Real },
    /// `C = 0` through a spring of its own softness, in every pass.
    Spring { softness: Softness },
}

/// One prepared row.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Row {
    pub lin_a: Vec3,
    pub ang_a: Vec3,
    pub lin_b: Vec3,
    pub ang_b: Vec3,
    pub inv_k: Real,
    pub c: Real,
    pub kind: RowKind,
    pub lo: Real,
    pub hi: Real,
    pub impulse: Real,
}

impl Row {
    /// A row with Jacobian `J` and error `c`; bounds come from `kind` (`max` for motors).
    pub fn new(j: [Vec3; 4], c: Real, kind: RowKind, max: Real) -> Row {
        let (lo, hi) = match kind {
            RowKind::Equality | RowKind::Spring { .. } => (Real::NEG_INFINITY, Real::INFINITY),
            RowKind::Inequality => (0.0, Real::INFINITY),
            RowKind::Motor { .. } => (-max, max),
        };
        Row {
            lin_a: j[0],
            ang_a: j[1],
            lin_b: j[2],
            ang_b: j[3],
            inv_k: 0.0,
            c,
            kind,
            lo,
            hi,
            impulse: 0.0,
        }
    }

    /// A linear row along `axis` between anchors at lever arms `ra` (from A's centre of mass
    /// to B's anchor) and `rb`.
    pub fn linear(axis: Vec3, ra: Vec3, rb: Vec3, c: Real, kind: RowKind, max: Real) -> Row {
        Row::new([-axis, -ra.cross(axis), axis, rb.cross(axis)], c, kind, max)
    }

    /// An angular row about `axis` (`J v = axis · (ω_b − ω_a)`).
    pub fn angular(axis: Vec3, c: Real, kind: RowKind, max: Real) -> Row {
        Row::new([Vec3::ZERO, -axis, Vec3::ZERO, axis], c, kind, max)
    }

    /// Computes the effective mass from the two bodies.
    pub fn finish(mut self, a: &SolverBody, b: &SolverBody) -> Row {
        let k = a.inv_m * self.lin_a.length_squared()
            + b.inv_m * self.lin_b.length_squared()
            + self.ang_a.dot(a.inv_i * self.ang_a)
            + self.ang_b.dot(b.inv_i * self.ang_b);
        self.inv_k = inv_or_zero(k);
        self
    }

    #[inline]
    fn velocity(&self, a: &SolverBody, b: &SolverBody) -> Real {
        self.lin_a.dot(a.v) + self.ang_a.dot(a.w) + self.lin_b.dot(b.v) + self.ang_b.dot(b.w)
    }

    #[inline]
    fn apply(&self, a: &mut SolverBody, b: &mut SolverBody, lambda: Real) {
        a.v += self.lin_a * (a.inv_m * lambda);
        a.w += a.inv_i * self.ang_a * lambda;
        b.v += self.lin_b * (b.inv_m * lambda);
        b.w += b.inv_i * self.ang_b * lambda;
    }

    /// Applies the accumulated impulse.
    pub fn warm_start(&self, a: &mut SolverBody, b: &mut SolverBody) {
        self.apply(a, b, self.impulse);
    }

    /// One sequential-impulse update. `soft` is the position feedback of equality and
    /// violated inequality rows when `use_bias`; `track_deltas` updates `C` from the position
    /// deltas of the substeps (soft step) instead of keeping the value of the preparation.
    pub fn solve(
        &mut self,
        a: &mut SolverBody,
        b: &mut SolverBody,
        soft: Softness,
        inv_h: Real,
        use_bias: bool,
        track_deltas: bool,
    ) {
        let c = if track_deltas {
            self.c
                + self.lin_a.dot(a.dp)
                + self.ang_a.dot(a.dq)
                + self.lin_b.dot(b.dp)
                + self.ang_b.dot(b.dq)
        } else {
            self.c
        };
        let (bias, mass_scale, impulse_scale) = match self.kind {
            RowKind::Equality if use_bias => {
                (soft.bias_rate * c, soft.mass_scale, soft.impulse_scale)
            }
            RowKind::Inequality if c > 0.0 => (c * inv_h, 1.0, 0.0),
            RowKind::Inequality if use_bias => {
                (soft.bias_rate * c, soft.mass_scale, soft.impulse_scale)
            }
            RowKind::Motor { speed } => (-speed, 1.0, 0.0),
            RowKind::Spring { softness } => (
                softness.bias_rate * c,
                softness.mass_scale,
                softness.impulse_scale,
            ),
            _ => (0.0, 1.0, 0.0),
        };
        let cdot = self.velocity(a, b);
        let lambda = -self.inv_k * mass_scale * (cdot + bias) - impulse_scale * self.impulse;
        let new = (self.impulse + lambda).clamp(self.lo, self.hi);
        let lambda = new - self.impulse;
        self.impulse = new;
        self.apply(a, b, lambda);
    }
}
