//! Generic one-dimensional constraint rows, the building blocks of every joint.
//!
//! A row is a Jacobian `J = (−lin, ang_a, lin, ang_b)` with a position error `C`, solved
//! as in Catto's sequential impulses: `λ = -m_eff·(J v + bias)`, accumulated and clamped.
//! Bullet's joints (`btTypedConstraint::getInfo2`) and Box2D v3's joints are written the same
//! way; here every joint type only *builds* rows and one routine solves them all. The linear
//! parts of both bodies are equal and opposite (a linear row pushes the bodies apart along
//! one direction, an angular row has none), so a row keeps one `lin`.
//!
//! A row keeps its angular Jacobians premultiplied by the bodies' inverse world inertias
//! (`ia`, `ib`, computed with the effective mass): the inverse inertias are fixed for the
//! step, so applying an impulse is four scaled adds, as in the contact rows.

use super::{inv_or_zero, Softness, SolverBody};
use carom_collision::math::{Mat3, Real, Vec3, Vec3A};

/// The part of a body that solving a row reads and writes: its velocities and inverse
/// mass (the inverse inertia is folded into each row's `ia`/`ib`). Small, so a joint's
/// passes copy two of these rather than two whole [`SolverBody`]s.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Motion {
    pub v: Vec3A,
    pub w: Vec3A,
    pub inv_m: Real,
}

impl Motion {
    /// The velocities and inverse mass of `b`.
    #[inline]
    pub fn of(b: &SolverBody) -> Motion {
        Motion {
            v: Vec3A::from(b.v),
            w: Vec3A::from(b.w),
            inv_m: b.inv_m,
        }
    }

    /// Writes the velocities back into `b` when it is dynamic (the only bodies the solver
    /// changes).
    #[inline]
    pub fn store(&self, b: &mut SolverBody) {
        if b.dynamic {
            b.v = Vec3::from(self.v);
            b.w = Vec3::from(self.w);
        }
    }
}

/// What the effective masses of a joint's rows read of its two bodies: the sum of their
/// inverse masses and their inverse world inertias as SIMD columns, converted once per
/// joint and refresh rather than once per row. `I⁻¹ J` is then three lane-wise
/// multiply-adds, summed in the order of glam's `Mat3 * Vec3` (so the bits are the same).
#[derive(Debug, Clone, Copy)]
pub(crate) struct PairInertia {
    /// `m_a⁻¹ + m_b⁻¹`.
    pub inv_m: Real,
    /// Columns of A's inverse world inertia.
    pub a: [Vec3A; 3],
    /// Columns of B's inverse world inertia.
    pub b: [Vec3A; 3],
}

impl PairInertia {
    /// The inverse masses and inertias of `a` and `b`.
    #[inline]
    pub fn of(a: &SolverBody, b: &SolverBody) -> PairInertia {
        let cols = |m: &Mat3| {
            [
                Vec3A::from(m.x_axis),
                Vec3A::from(m.y_axis),
                Vec3A::from(m.z_axis),
            ]
        };
        PairInertia {
            inv_m: a.inv_m + b.inv_m,
            a: cols(&a.inv_i),
            b: cols(&b.inv_i),
        }
    }

    /// `M v` for the matrix with columns `m`: `(m₀ vₓ + m₁ v_y) + m₂ v_z`.
    #[inline]
    pub fn mul(m: &[Vec3A; 3], v: Vec3A) -> Vec3A {
        m[0] * v.x + m[1] * v.y + m[2] * v.z
    }
}

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
    /// Linear Jacobian of B (A's is `-lin`). The Jacobians are kept as [`Vec3A`] (SIMD
    /// registers with `f32`), as are the velocities of [`Motion`].
    pub lin: Vec3A,
    pub ang_a: Vec3A,
    pub ang_b: Vec3A,
    /// `I_a⁻¹ ang_a` and `I_b⁻¹ ang_b` (set by [`Row::finish`] or [`Block::update`]).
    pub ia: Vec3A,
    pub ib: Vec3A,
    pub inv_k: Real,
    pub c: Real,
    pub kind: RowKind,
    pub lo: Real,
    pub hi: Real,
    pub impulse: Real,
    /// The joint's warm-starting slot of this row (`< ROW_SLOTS`).
    pub slot: u8,
    /// `lin` is zero (an angular row): the solve skips the linear terms, which would only
    /// add and subtract zeros.
    pub angular: bool,
}

impl Row {
    /// A row for `slot` with Jacobian `j = [lin, ang_a, ang_b]` and error `c`; bounds come
    /// from `kind` (`max` for motors). The effective mass is set later ([`Row::finish`] or a
    /// [`Block`]).
    pub fn new(slot: u8, j: [Vec3A; 3], c: Real, kind: RowKind, max: Real) -> Row {
        let (lo, hi) = match kind {
            RowKind::Equality | RowKind::Spring { .. } => (Real::NEG_INFINITY, Real::INFINITY),
            RowKind::Inequality => (0.0, Real::INFINITY),
            RowKind::Motor { .. } => (-max, max),
        };
        Row {
            lin: j[0],
            ang_a: j[1],
            ang_b: j[2],
            ia: Vec3A::ZERO,
            ib: Vec3A::ZERO,
            inv_k: 0.0,
            c,
            kind,
            lo,
            hi,
            impulse: 0.0,
            slot,
            angular: j[0] == Vec3A::ZERO,
        }
    }

    /// Replaces the Jacobian and the error (a refresh from new poses), keeping the kind,
    /// bounds and accumulated impulse.
    #[inline]
    pub fn set(&mut self, j: [Vec3A; 3], c: Real) {
        self.lin = j[0];
        self.ang_a = j[1];
        self.ang_b = j[2];
        self.c = c;
        self.angular = j[0] == Vec3A::ZERO;
    }

    /// Computes the inertia-weighted angular Jacobians and the effective mass.
    #[inline]
    pub fn finish(&mut self, p: &PairInertia) {
        self.ia = PairInertia::mul(&p.a, self.ang_a);
        self.ib = PairInertia::mul(&p.b, self.ang_b);
        let angular = self.ang_a.dot(self.ia) + self.ang_b.dot(self.ib);
        // An angular row's linear term is zero (adding it changes at most a zero's sign).
        let k = if self.angular {
            angular
        } else {
            p.inv_m * self.lin.length_squared() + angular
        };
        self.inv_k = inv_or_zero(k);
    }

    /// `J v`. An angular row leaves out `lin · (v_b − v_a)`, which is ±0 there (the sum
    /// differs at most in the sign of a zero result).
    #[inline]
    pub(crate) fn velocity(&self, a: &Motion, b: &Motion) -> Real {
        let angular = self.ang_a.dot(a.w);
        if self.angular {
            return angular + self.ang_b.dot(b.w);
        }
        self.lin.dot(b.v - a.v) + angular + self.ang_b.dot(b.w)
    }

    /// Applies `lambda` along the row (`-` to A, `+` to B); an angular row changes no
    /// linear velocity.
    #[inline]
    pub(crate) fn apply(&self, a: &mut Motion, b: &mut Motion, lambda: Real) {
        if !self.angular {
            a.v -= self.lin * (a.inv_m * lambda);
            b.v += self.lin * (b.inv_m * lambda);
        }
        a.w += self.ia * lambda;
        b.w += self.ib * lambda;
    }

    /// Applies the accumulated impulse (nothing for a row without one, such as a limit
    /// that was not reached).
    pub fn warm_start(&self, a: &mut Motion, b: &mut Motion) {
        if self.impulse != 0.0 {
            self.apply(a, b, self.impulse);
        }
    }

    /// One sequential-impulse update. `soft` is the position feedback of equality and
    /// violated inequality rows when `use_bias`. `C` is the value of the last build or
    /// refresh: the soft step refreshes the rows whenever the poses have moved, so it is
    /// the current error.
    pub fn solve(
        &mut self,
        a: &mut Motion,
        b: &mut Motion,
        soft: Softness,
        inv_h: Real,
        use_bias: bool,
    ) {
        let c = self.c;
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
        // A clamped row (typically a limit far from being reached) changes nothing.
        if lambda != 0.0 {
            self.apply(a, b, lambda);
        }
    }
}

/// Up to three consecutive equality rows solved together: `λ = -K⁻¹ (J v + bias)` with the
/// full coupled effective mass `K = J M⁻¹ Jᵀ` (Box2D v3 / box3d `b3SolveSphericalJoint`'s
/// `b3Solve3`, Bullet's `btPoint2PointConstraint` reaches the same by iterating). Solving
/// the rows one after another instead is one Gauss–Seidel sweep on a `K` whose rows are
/// strongly coupled when a lever arm is long against the body's radius of gyration; with
/// the soft step's single iteration per substep that sweep leaves most of the error.
///
/// Which rows form a block is fixed when the joint's rows are built for the step; `K` is
/// recomputed at every refresh ([`Block::update`]), and a refresh that finds it nearly
/// singular marks the block invalid, so its rows are solved one by one until the next.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Block {
    /// First row index in the joint's row list.
    pub start: usize,
    /// Number of rows (1..=3).
    pub len: usize,
    /// Inverse of `K` as its three columns (SIMD registers, multiplied with
    /// [`PairInertia::mul`]), padded with the identity past `len` (meaningful when `valid`).
    pub inv_k: [Vec3A; 3],
    /// False when the last update found `K` nearly singular.
    pub valid: bool,
}

impl Block {
    /// A block over `len` rows from `start`, to be [updated](Block::update) before use.
    pub fn new(start: usize, len: usize) -> Block {
        debug_assert!((1..=3).contains(&len));
        Block {
            start,
            len,
            inv_k: [Vec3A::X, Vec3A::Y, Vec3A::Z],
            valid: false,
        }
    }

    /// Recomputes `K⁻¹` from `rows` (the block's rows, all equality rows) and their
    /// inertia-weighted Jacobians. When `K` is nearly singular the block is marked invalid
    /// and each row gets its scalar effective mass instead.
    pub fn update(&mut self, rows: &mut [Row], p: &PairInertia) {
        debug_assert_eq!(rows.len(), self.len);
        // K_ij = J_i M⁻¹ J_jᵀ: one inverse-inertia product per row, then dot products.
        for r in rows.iter_mut() {
            r.ia = PairInertia::mul(&p.a, r.ang_a);
            r.ib = PairInertia::mul(&p.b, r.ang_b);
        }
        // The six entries of the symmetric K, padded with the identity past `len`.
        let inv_m = p.inv_m;
        // Angular rows (zero `lin`, as the hinge's alignment rows and a fixed joint's
        // rotation) leave out the zero linear term.
        let linear = rows.iter().any(|r| !r.angular);
        let e = |ri: &Row, rj: &Row| {
            let angular = ri.ang_a.dot(rj.ia) + ri.ang_b.dot(rj.ib);
            if linear {
                inv_m * ri.lin.dot(rj.lin) + angular
            } else {
                angular
            }
        };
        let (k00, k01, k02, k11, k12, k22) = match rows {
            [r0, r1, r2] => (
                e(r0, r0),
                e(r0, r1),
                e(r0, r2),
                e(r1, r1),
                e(r1, r2),
                e(r2, r2),
            ),
            [r0, r1] => (e(r0, r0), e(r0, r1), 0.0, e(r1, r1), 0.0, 1.0),
            [r0] => (e(r0, r0), 0.0, 0.0, 1.0, 0.0, 1.0),
            _ => (1.0, 0.0, 0.0, 1.0, 0.0, 1.0),
        };
        // A nearly singular K is solved row by row instead.
        let inv = inverse_symmetric(k00, k01, k02, k11, k12, k22);
        self.valid = inv.is_some();
        if let Some(inv_k) = inv {
            self.inv_k = inv_k;
        } else {
            for r in rows.iter_mut() {
                r.finish(p);
            }
        }
    }

    /// One block update of `rows` (the block's rows), with the same soft feedback as
    /// [`Row::solve`] gives an equality row. Dispatches on the block size to a loop of fixed
    /// length, which the compiler unrolls (no per-row loop bookkeeping or index checks).
    pub fn solve(
        &self,
        rows: &mut [Row],
        a: &mut Motion,
        b: &mut Motion,
        soft: Softness,
        use_bias: bool,
    ) {
        match rows {
            [r0, r1, r2] => self.solve_n([r0, r1, r2], a, b, soft, use_bias),
            [r0, r1] => self.solve_n([r0, r1], a, b, soft, use_bias),
            [r0] => self.solve_n([r0], a, b, soft, use_bias),
            _ => {}
        }
    }

    /// [`Block::solve`] on `N` rows: `λ = -K⁻¹ (J v + bias)·mass_scale - impulse·impulse_scale`,
    /// with the entries past `N` zero (and `K⁻¹` padded with the identity).
    #[inline(always)]
    fn solve_n<const N: usize>(
        &self,
        mut rows: [&mut Row; N],
        a: &mut Motion,
        b: &mut Motion,
        soft: Softness,
        use_bias: bool,
    ) {
        let mut rhs = Vec3A::ZERO;
        let mut acc = Vec3A::ZERO;
        for (i, r) in rows.iter().enumerate() {
            let bias = if use_bias { soft.bias_rate * r.c } else { 0.0 };
            rhs[i] = r.velocity(a, b) + bias;
            acc[i] = r.impulse;
        }
        let (mass_scale, impulse_scale) = if use_bias {
            (soft.mass_scale, soft.impulse_scale)
        } else {
            (1.0, 0.0)
        };
        let lambda = -PairInertia::mul(&self.inv_k, rhs) * mass_scale - acc * impulse_scale;
        for (i, r) in rows.iter_mut().enumerate() {
            r.impulse += lambda[i];
            r.apply(a, b, lambda[i]);
        }
    }
}

/// The point part of a ball, hinge, cone-twist or fixed joint — B's anchor held on A's —
/// as one world-frame 3×3 block (Box2D v3's `b2SolveSphericalJoint`, Jolt's
/// `PointConstraintPart`): `ċ = v_b + ω_b × r_b − v_a − ω_a × r_a` (`r_a` runs from A's
/// centre of mass to B's anchor, as the rows' lever arm) with
/// `K = (m_a⁻¹ + m_b⁻¹) 𝟙 − [r_a]× I_a⁻¹ [r_a]× − [r_b]× I_b⁻¹ [r_b]×`, the error the world
/// vector between the anchors. Three rows along frame A's axes have the same `K` up to a
/// rotation, but their velocities cost nine dot products and their updates twelve
/// scaled adds; here `ċ` is two cross products, and applying `λ` is `∓ m⁻¹ λ` and
/// `∓ (I⁻¹ [r]×) λ` with the two matrices `I⁻¹ [r]×` kept from the last refresh (the analogue
/// of a row's `I⁻¹ Jᵀ`). The accumulated impulse is a world vector; the joint's warm-start
/// slots 0, 3 and 6 hold its components along frame A's axes ([`PointBlock::axes`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct PointBlock {
    /// Lever arm from A's centre of mass to B's anchor.
    pub ra: Vec3A,
    /// Lever arm from B's centre of mass to B's anchor.
    pub rb: Vec3A,
    /// Position error: from A's anchor to B's.
    pub c: Vec3A,
    /// Frame A's axes at the last build or refresh (for the stored slot impulses).
    pub axes: [Vec3A; 3],
    /// Columns of `I_a⁻¹ [r_a]×` and `I_b⁻¹ [r_b]×` (set by [`PointBlock::update`]).
    pub ma: [Vec3A; 3],
    pub mb: [Vec3A; 3],
    /// Columns of `K⁻¹` when `valid`; else the reciprocals of `K`'s diagonal on the
    /// diagonal (the axes are then solved one after another).
    pub inv_k: [Vec3A; 3],
    /// Accumulated impulse (world frame, applied `−` to A and `+` to B).
    pub impulse: Vec3A,
    /// The soft step's impulse summed over the substeps (for breaking, as
    /// `JointScratch::sums` for the rows).
    pub sum: Vec3A,
    /// False when the last update found `K` nearly singular.
    pub valid: bool,
}

impl PointBlock {
    /// A point block at lever arms `ra`, `rb`, error `c` and frame A's axes `axes`, without
    /// masses (to be [updated](PointBlock::update) before use) or impulse.
    pub fn new(ra: Vec3A, rb: Vec3A, c: Vec3A, axes: [Vec3A; 3]) -> PointBlock {
        PointBlock {
            ra,
            rb,
            c,
            axes,
            ma: [Vec3A::ZERO; 3],
            mb: [Vec3A::ZERO; 3],
            inv_k: [Vec3A::ZERO; 3],
            impulse: Vec3A::ZERO,
            sum: Vec3A::ZERO,
            valid: false,
        }
    }

    /// Replaces the geometry (a refresh from new poses), keeping the impulses.
    #[inline]
    pub fn set(&mut self, ra: Vec3A, rb: Vec3A, c: Vec3A, axes: [Vec3A; 3]) {
        self.ra = ra;
        self.rb = rb;
        self.c = c;
        self.axes = axes;
    }

    /// The components of the accumulated impulse along frame A's axes (slots 0, 3, 6).
    #[inline]
    pub fn slot_impulses(&self, v: Vec3A) -> [Real; 3] {
        [
            v.dot(self.axes[0]),
            v.dot(self.axes[1]),
            v.dot(self.axes[2]),
        ]
    }

    /// Recomputes `I⁻¹ [r]×` of both bodies and `K⁻¹` (cofactors of the symmetric `K`).
    /// When `K` is nearly singular the block is marked invalid and keeps the reciprocals
    /// of its diagonal for an axis-by-axis solve.
    pub fn update(&mut self, p: &PairInertia) {
        // Columns of [r]×: r × eₓ, r × e_y, r × e_z.
        let skew = |r: Vec3A| {
            [
                Vec3A::new(0.0, r.z, -r.y),
                Vec3A::new(-r.z, 0.0, r.x),
                Vec3A::new(r.y, -r.x, 0.0),
            ]
        };
        let (sa, sb) = (skew(self.ra), skew(self.rb));
        let mut k = [Vec3A::ZERO; 3];
        let e = [Vec3A::X, Vec3A::Y, Vec3A::Z];
        for i in 0..3 {
            self.ma[i] = PairInertia::mul(&p.a, sa[i]);
            self.mb[i] = PairInertia::mul(&p.b, sb[i]);
            // Column i of K: m⁻¹ eᵢ − r_a × (I_a⁻¹ [r_a]× eᵢ) − r_b × (I_b⁻¹ [r_b]× eᵢ).
            k[i] = e[i] * p.inv_m - self.ra.cross(self.ma[i]) - self.rb.cross(self.mb[i]);
        }
        // The upper triangle of the symmetric K.
        let (k00, k01, k02) = (k[0].x, k[1].x, k[2].x);
        let (k11, k12, k22) = (k[1].y, k[2].y, k[2].z);
        // The same inverse and conditioning test as `Block::update`.
        let inv = inverse_symmetric(k00, k01, k02, k11, k12, k22);
        self.valid = inv.is_some();
        if let Some(inv_k) = inv {
            self.inv_k = inv_k;
        } else {
            self.inv_k = [
                Vec3A::new(inv_or_zero(k00), 0.0, 0.0),
                Vec3A::new(0.0, inv_or_zero(k11), 0.0),
                Vec3A::new(0.0, 0.0, inv_or_zero(k22)),
            ];
        }
    }

    /// `ċ = v_b + ω_b × r_b − v_a − ω_a × r_a`.
    #[inline]
    pub(crate) fn velocity(&self, a: &Motion, b: &Motion) -> Vec3A {
        (b.v - a.v) + (b.w.cross(self.rb) - a.w.cross(self.ra))
    }

    /// Applies the world impulse `lambda` (`−` to A, `+` to B).
    #[inline]
    pub(crate) fn apply(&self, a: &mut Motion, b: &mut Motion, lambda: Vec3A) {
        a.v -= lambda * a.inv_m;
        a.w -= PairInertia::mul(&self.ma, lambda);
        b.v += lambda * b.inv_m;
        b.w += PairInertia::mul(&self.mb, lambda);
    }

    /// Applies the accumulated impulse.
    #[inline]
    pub fn warm_start(&self, a: &mut Motion, b: &mut Motion) {
        if self.impulse != Vec3A::ZERO {
            self.apply(a, b, self.impulse);
        }
    }

    /// One update with the soft feedback of an equality row:
    /// `λ = −K⁻¹ (ċ + bias)·mass_scale − impulse·impulse_scale`. An invalid block solves
    /// the world axes one after another with the diagonal of `K`.
    pub fn solve(&mut self, a: &mut Motion, b: &mut Motion, soft: Softness, use_bias: bool) {
        let (bias_rate, mass_scale, impulse_scale) = if use_bias {
            (soft.bias_rate, soft.mass_scale, soft.impulse_scale)
        } else {
            (0.0, 1.0, 0.0)
        };
        if self.valid {
            let rhs = self.velocity(a, b) + self.c * bias_rate;
            let lambda =
                -PairInertia::mul(&self.inv_k, rhs) * mass_scale - self.impulse * impulse_scale;
            self.impulse += lambda;
            self.apply(a, b, lambda);
        } else {
            for i in 0..3 {
                let rhs = self.velocity(a, b)[i] + self.c[i] * bias_rate;
                let l = -self.inv_k[i][i] * rhs * mass_scale - self.impulse[i] * impulse_scale;
                let mut lambda = Vec3A::ZERO;
                lambda[i] = l;
                self.impulse += lambda;
                self.apply(a, b, lambda);
            }
        }
    }
}

/// The inverse of a symmetric 3×3 `K` given by its upper triangle, by cofactors
/// (`K⁻¹ = C / det`), as its three columns (equal to its rows); `None` when `K` is nearly
/// singular by the relative test `det > 1e-4 · k00 k11 k22` (or not finite), for the
/// caller's row-by-row fallback. Shared by [`Block::update`] and [`PointBlock::update`].
#[inline(always)]
fn inverse_symmetric(
    k00: Real,
    k01: Real,
    k02: Real,
    k11: Real,
    k12: Real,
    k22: Real,
) -> Option<[Vec3A; 3]> {
    let c00 = k11 * k22 - k12 * k12;
    let c01 = k02 * k12 - k01 * k22;
    let c02 = k01 * k12 - k02 * k11;
    let det = k00 * c00 + k01 * c01 + k02 * c02;
    let diag = k00 * k11 * k22;
    if !(det.is_finite() && diag > 0.0 && det > 1e-4 * diag) {
        return None;
    }
    let c11 = k00 * k22 - k02 * k02;
    let c12 = k01 * k02 - k00 * k12;
    let c22 = k00 * k11 - k01 * k01;
    let inv_det = 1.0 / det;
    Some([
        Vec3A::new(c00, c01, c02) * inv_det,
        Vec3A::new(c01, c11, c12) * inv_det,
        Vec3A::new(c02, c12, c22) * inv_det,
    ])
}
#[cfg(test)]
#[path = "rows_tests.rs"]
mod tests;
