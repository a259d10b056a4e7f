//! Generic one-dimensional constraint rows, the building blocks of every joint.
//!
//! A row is a Jacobian `J = (lin_a, ang_a, lin_b, ang_b)` with a position error `C`, solved
//! as in Catto's sequential impulses: `λ = -m_eff·(J v + bias)`, accumulated and clamped.
//! Bullet's joints (`btTypedConstraint::getInfo2`) and Box2D v3's joints are written the same
//! way; here every joint type only *builds* rows and one routine solves them all.

use super::{inv_or_zero, Softness, SolverBody};
use carom_collision::math::{Mat3, Real, Vec3};

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
    pub(crate) fn velocity(&self, a: &SolverBody, b: &SolverBody) -> Real {
        self.lin_a.dot(a.v) + self.ang_a.dot(a.w) + self.lin_b.dot(b.v) + self.ang_b.dot(b.w)
    }

    #[inline]
    pub(crate) fn apply(&self, a: &mut SolverBody, b: &mut SolverBody, lambda: Real) {
        a.v += self.lin_a * (a.inv_m * lambda);
        a.w += a.inv_i * self.ang_a * lambda;
        b.v += self.lin_b * (b.inv_m * lambda);
        b.w += b.inv_i * self.ang_b * lambda;
    }

    /// Applies the accumulated impulse.
    pub fn warm_start(&self, a: &mut SolverBody, b: &mut SolverBody) {
        self.apply(a, b, self.impulse);
    }

    /// `J · (dp, dq)`: how far the position deltas since the step start moved the row.
    #[inline]
    pub(crate) fn delta(&self, a: &SolverBody, b: &SolverBody) -> Real {
        self.lin_a.dot(a.dp) + self.ang_a.dot(a.dq) + self.lin_b.dot(b.dp) + self.ang_b.dot(b.dq)
    }

    /// The position error: `C` of the preparation plus, when `track_deltas`, the change
    /// linearised from the position deltas (exact right after a refresh, which folds the
    /// deltas so far into `c`).
    #[inline]
    fn error(&self, a: &SolverBody, b: &SolverBody, track_deltas: bool) -> Real {
        if track_deltas {
            self.c + self.delta(a, b)
        } else {
            self.c
        }
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
        let c = self.error(a, b, track_deltas);
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

/// Up to three consecutive equality rows solved together: `λ = -K⁻¹ (J v + bias)` with the
/// full coupled effective mass `K = J M⁻¹ Jᵀ` (Box2D v3 / box3d `b3SolveSphericalJoint`'s
/// `b3Solve3`, Bullet's `btPoint2PointConstraint` reaches the same by iterating). Solving
/// the rows one after another instead is one Gauss–Seidel sweep on a `K` whose rows are
/// strongly coupled when a lever arm is long against the body's radius of gyration; with
/// the soft step's single iteration per substep that sweep leaves most of the error.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Block {
    /// First row index in the joint's row list.
    pub start: usize,
    /// Number of rows (1..=3).
    pub len: usize,
    /// Inverse of `K`, padded with the identity past `len`.
    pub inv_k: Mat3,
}

impl Block {
    /// The block over `rows` (all equality rows, with their slots), or `None` when its `K`
    /// is nearly singular (then the rows are solved one by one).
    pub fn new(
        start: usize,
        rows: &[(usize, Row)],
        a: &SolverBody,
        b: &SolverBody,
    ) -> Option<Block> {
        let len = rows.len();
        debug_assert!((1..=3).contains(&len));
        // K_ij = J_i M⁻¹ J_jᵀ: one inverse-inertia product per row, then dot products.
        let mut k = Mat3::IDENTITY;
        let ang: [(Vec3, Vec3); 3] = std::array::from_fn(|j| {
            let r = &rows[j.min(len - 1)].1;
            (a.inv_i * r.ang_a, b.inv_i * r.ang_b)
        });
        for (j, (_, rj)) in rows.iter().enumerate() {
            for (i, (_, ri)) in rows.iter().enumerate().take(j + 1) {
                let kij = a.inv_m * ri.lin_a.dot(rj.lin_a)
                    + b.inv_m * ri.lin_b.dot(rj.lin_b)
                    + ri.ang_a.dot(ang[j].0)
                    + ri.ang_b.dot(ang[j].1);
                k.col_mut(j)[i] = kij;
                k.col_mut(i)[j] = kij;
            }
        }
        let diag: Real = (0..3).map(|i| k.col(i)[i]).product();
        let det = k.determinant();
        // Relative conditioning test: a nearly singular K is solved row by row instead.
        if !(det.is_finite() && diag > 0.0 && det > 1e-4 * diag) {
            return None;
        }
        Some(Block {
            start,
            len,
            inv_k: k.inverse(),
        })
    }

    /// One block update of `rows` (the block's rows), with the same soft feedback as
    /// [`Row::solve`] gives an equality row.
    pub fn solve(
        &self,
        rows: &mut [(usize, Row)],
        a: &mut SolverBody,
        b: &mut SolverBody,
        soft: Softness,
        use_bias: bool,
        track_deltas: bool,
    ) {
        let mut rhs = Vec3::ZERO;
        let mut acc = Vec3::ZERO;
        for (i, (_, r)) in rows.iter().enumerate() {
            let bias = if use_bias {
                soft.bias_rate * r.error(a, b, track_deltas)
            } else {
                0.0
            };
            rhs[i] = r.velocity(a, b) + bias;
            acc[i] = r.impulse;
        }
        let (mass_scale, impulse_scale) = if use_bias {
            (soft.mass_scale, soft.impulse_scale)
        } else {
            (1.0, 0.0)
        };
        let lambda = -(self.inv_k * rhs) * mass_scale - acc * impulse_scale;
        for (i, (_, r)) in rows.iter_mut().enumerate() {
            r.impulse += lambda[i];
            r.apply(a, b, lambda[i]);
        }
    }
}
