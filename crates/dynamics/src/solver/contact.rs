//! Contact constraints: preparation from [`ContactManifold`] inputs and the per-constraint
//! solve routines of both solvers.
//!
//! Each manifold becomes one constraint with up to four points; each point has a normal row
//! (impulse ≥ 0) and a two-dimensional friction row clamped to the Coulomb cone
//! `|λ_t| ≤ μ λ_n` (Catto, "Iterative Dynamics with Temporal Coherence"; Bullet's
//! `btSequentialImpulseConstraintSolver::setupContactConstraint`). The anchor of a point is
//! the midpoint of its two witness points, as in Box2D.

use super::coloring::{colour_into, ColourScratch, Colouring, PairConstraint};
use super::{inv_or_zero, Softness, SolverBody, SolverParams};
use crate::body_set::BodySet;
use crate::contact::{ContactManifold, MAX_MANIFOLD_POINTS};
use carom_collision::math::{Real, Vec3};

#[path = "contact_prepare.rs"]
mod prep;
pub(crate) use prep::Preparer;

#[cfg(test)]
#[path = "contact_tests.rs"]
mod tests;
#[cfg(test)]
pub(crate) use tests::solve_soft_rows;

/// One Jacobian row of a contact point along a unit direction `d` (the normal or a tangent):
/// the angular parts `r_a × d`, `r_b × d` and the same premultiplied by the inverse world
/// inertias, so a solve is dot products and scaled adds only (no matrix product, no cross
/// product in the iteration loop; Box2D's and Rapier's contact solvers store the same).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct ContactRow {
    /// `r_a × d`.
    pub ang_a: Vec3,
    /// `r_b × d`.
    pub ang_b: Vec3,
    /// `I_a⁻¹ (r_a × d)`: change of A's angular velocity per unit impulse (negated).
    pub inv_ang_a: Vec3,
    /// `I_b⁻¹ (r_b × d)`: change of B's angular velocity per unit impulse.
    pub inv_ang_b: Vec3,
    /// Effective mass `1 / (J M⁻¹ Jᵀ)`.
    pub mass: Real,
}

impl ContactRow {
    /// A zero row: no mass, so its impulse stays zero.
    pub const ZERO: ContactRow = ContactRow {
        ang_a: Vec3::ZERO,
        ang_b: Vec3::ZERO,
        inv_ang_a: Vec3::ZERO,
        inv_ang_b: Vec3::ZERO,
        mass: 0.0,
    };

    fn new(a: &SolverBody, b: &SolverBody, ra: Vec3, rb: Vec3, d: Vec3) -> ContactRow {
        let (ang_a, ang_b) = (ra.cross(d), rb.cross(d));
        let (inv_ang_a, inv_ang_b) = (a.inv_i * ang_a, b.inv_i * ang_b);
        let k = a.inv_m + b.inv_m + ang_a.dot(inv_ang_a) + ang_b.dot(inv_ang_b);
        ContactRow {
            ang_a,
            ang_b,
            inv_ang_a,
            inv_ang_b,
            mass: inv_or_zero(k),
        }
    }

    /// Relative velocity of B with respect to A along the row (`J v`).
    #[inline(always)]
    fn velocity(&self, d: Vec3, a: &SolverBody, b: &SolverBody) -> Real {
        d.dot(b.v - a.v) + self.ang_b.dot(b.w) - self.ang_a.dot(a.w)
    }

    /// Relative displacement along the row from the position deltas (`J Δx`), given its
    /// linear part `d · (Δx_b − Δx_a)`, which is the same for every point of a constraint
    /// (computed once per constraint and pass).
    #[inline(always)]
    fn displacement(&self, linear: Real, a: &SolverBody, b: &SolverBody) -> Real {
        linear + self.ang_b.dot(b.dq) - self.ang_a.dot(a.dq)
    }

    /// Applies impulse `lambda` along the row: `-λ` to A, `+λ` to B.
    #[inline(always)]
    fn apply(&self, d: Vec3, lambda: Real, a: &mut SolverBody, b: &mut SolverBody) {
        a.v -= d * (lambda * a.inv_m);
        a.w -= self.inv_ang_a * lambda;
        b.v += d * (lambda * b.inv_m);
        b.w += self.inv_ang_b * lambda;
    }

    /// Applies impulse `lambda` to the pseudo-velocities (split impulses).
    #[inline(always)]
    fn apply_push(&self, d: Vec3, lambda: Real, a: &mut SolverBody, b: &mut SolverBody) {
        a.dp -= d * (lambda * a.inv_m);
        a.dq -= self.inv_ang_a * lambda;
        b.dp += d * (lambda * b.inv_m);
        b.dq += self.inv_ang_b * lambda;
    }
}

/// One prepared contact point.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct PointConstraint {
    /// The normal row.
    pub normal_row: ContactRow,
    /// The two friction rows (along the constraint's tangents).
    pub tangent_rows: [ContactRow; 2],
    pub separation: Real,
    /// Normal relative velocity at preparation (for restitution).
    pub relative_velocity: Real,
    pub normal_impulse: Real,
    pub tangent_impulse: [Real; 2],
    pub push_impulse: Real,
    pub max_normal_impulse: Real,
    /// Lever arm from A's centre of mass to the anchor, from which the rows are built (the
    /// SIMD build computes the rows of four constraints at once from these).
    pub arm_a: Vec3,
    /// Lever arm from B's centre of mass to the anchor.
    pub arm_b: Vec3,
}

/// One prepared manifold.
#[derive(Debug, Clone)]
pub(crate) struct ContactConstraint {
    pub a: usize,
    pub b: usize,
    pub manifold: usize,
    pub normal: Vec3,
    pub tangent: [Vec3; 2],
    pub friction: Real,
    pub restitution: Real,
    pub softness: Softness,
    pub points: [PointConstraint; MAX_MANIFOLD_POINTS],
    pub len: usize,
}

impl PointConstraint {
    /// An empty point (zero rows and impulses).
    pub const ZERO: PointConstraint = PointConstraint {
        normal_row: ContactRow::ZERO,
        tangent_rows: [ContactRow::ZERO; 2],
        separation: 0.0,
        relative_velocity: 0.0,
        normal_impulse: 0.0,
        tangent_impulse: [0.0; 2],
        push_impulse: 0.0,
        max_normal_impulse: 0.0,
        arm_a: Vec3::ZERO,
        arm_b: Vec3::ZERO,
    };
}

impl ContactConstraint {
    /// A constraint without points (all zero): the padding lanes of the SIMD solve.
    pub const EMPTY: ContactConstraint = ContactConstraint {
        a: 0,
        b: 0,
        manifold: 0,
        normal: Vec3::ZERO,
        tangent: [Vec3::ZERO; 2],
        friction: 0.0,
        restitution: 0.0,
        softness: Softness {
            bias_rate: 0.0,
            mass_scale: 0.0,
            impulse_scale: 0.0,
        },
        points: [PointConstraint::ZERO; MAX_MANIFOLD_POINTS],
        len: 0,
    };
}

impl PairConstraint for ContactConstraint {
    fn bodies(&self) -> (usize, usize) {
        (self.a, self.b)
    }
}

/// The contact constraints of a step and the buffers that build them, owned by the world and
/// reused from step to step (cleared, not freed): once they have grown to the scene, preparing
/// and solving contacts allocates nothing (Box2D v3 keeps its constraints in a per-world
/// arena for the same reason).
#[derive(Debug, Clone, Default)]
pub(crate) struct ContactScratch {
    /// The constraints, in colour order.
    pub cons: Vec<ContactConstraint>,
    /// Constraint order and colour ranges (`ranges` index `cons`).
    pub colouring: Colouring,
    /// The constraints grouped four-wide for the SIMD solve (module `contact_simd`).
    pub wide: super::contact_simd::WideScratch,
    /// Manifold index of each selected manifold.
    selected: Vec<usize>,
    /// Body slots of each selected manifold.
    pairs: Vec<(usize, usize)>,
    /// Point count of each selected manifold (read by the lane assignment, which would
    /// otherwise look each manifold up again).
    lens: Vec<u8>,
    colour: ColourScratch,
}

impl ContactScratch {
    /// The manifold index of each selected manifold (indexed by the colouring's `order`).
    pub(crate) fn selected(&self) -> &[usize] {
        &self.selected
    }
}

/// Selects the manifolds that touch an awake dynamic body and colours them (module
/// `coloring`), with the colour ranges in `scratch.colouring.ranges`, and builds their
/// constraints in colour order. Scalar (`simd` false): all of them into `scratch.cons`.
/// SIMD: the colours but the overflow one go four at a time into the lanes of
/// `scratch.wide` (`contact_simd::assign`) and the overflow colour into `scratch.cons`; the
/// constraints themselves are *not* built here but by the soft step's prepare stages, in
/// parallel blocks (`soft_stages`, with a [`Preparer`]), and `scratch.cons` is only sized
/// to the overflow colour. `impulse_in` scales the stored impulses (per-step units) to the
/// solver's units (0 disables warm start). The manifolds are coloured first and each
/// constraint is built once, at its place: no reordering copy of the (large) constraints.
/// Allocates only when a buffer of `scratch` must grow.
#[allow(clippy::too_many_arguments)]
pub(crate) fn prepare(
    manifolds: &[ContactManifold],
    set: &BodySet,
    bodies: &[SolverBody],
    impulse_in: Real,
    soft: Softness,
    static_soft: Softness,
    simd: bool,
    scratch: &mut ContactScratch,
) {
    let ContactScratch {
        cons,
        colouring,
        wide,
        selected,
        pairs,
        lens,
        colour,
    } = scratch;
    selected.clear();
    pairs.clear();
    lens.clear();
    for (m_index, m) in manifolds.iter().enumerate() {
        let (a, b) = (m.body_a.index as usize, m.body_b.index as usize);
        if m.points().is_empty() || !(bodies[a].dynamic || bodies[b].dynamic) {
            continue;
        }
        selected.push(m_index);
        pairs.push((a, b));
        lens.push(m.points().len().min(MAX_MANIFOLD_POINTS) as u8);
    }
    colour_into(
        pairs,
        bodies.len(),
        |i| bodies[i].dynamic,
        colour,
        colouring,
    );
    let order = &colouring.order;
    if simd {
        let points = |k: usize| usize::from(lens[order[k]]);
        let ranges = &colouring.ranges;
        super::contact_simd::assign(wide, ranges, points);
        // The overflow colour's constraints are prepared in place by the prepare stages;
        // stale entries are overwritten there (every field the solve reads).
        let n = ranges.last().map_or(0, |r| r.len());
        cons.truncate(n);
        cons.resize(n, ContactConstraint::EMPTY);
        wide.overflow = 0..n;
    } else {
        let p = Preparer {
            manifolds,
            selected,
            order,
            set,
            bodies,
            impulse_in,
            soft: (soft, static_soft),
        };
        cons.clear();
        cons.extend((0..order.len()).map(|k| {
            let mut c = ContactConstraint::EMPTY;
            p.make(k, &mut c, true);
            c
        }));
    }
}

/// Applies the accumulated impulses (warm start).
pub(crate) fn warm_start(c: &mut ContactConstraint, a: &mut SolverBody, b: &mut SolverBody) {
    for p in &c.points[..c.len] {
        let imp = c.normal * p.normal_impulse
            + c.tangent[0] * p.tangent_impulse[0]
            + c.tangent[1] * p.tangent_impulse[1];
        let (t0, t1) = (&p.tangent_rows[0], &p.tangent_rows[1]);
        a.v -= imp * a.inv_m;
        a.w -= p.normal_row.inv_ang_a * p.normal_impulse
            + t0.inv_ang_a * p.tangent_impulse[0]
            + t1.inv_ang_a * p.tangent_impulse[1];
        b.v += imp * b.inv_m;
        b.w += p.normal_row.inv_ang_b * p.normal_impulse
            + t0.inv_ang_b * p.tangent_impulse[0]
            + t1.inv_ang_b * p.tangent_impulse[1];
    }
}

/// Coulomb friction on both tangent directions, clamped to the cone `μ λ_n`.
#[inline]
fn solve_friction(c: &mut ContactConstraint, a: &mut SolverBody, b: &mut SolverBody) {
    let (t0, t1) = (c.tangent[0], c.tangent[1]);
    for p in c.points[..c.len].iter_mut() {
        let [r0, r1] = &p.tangent_rows;
        let old = p.tangent_impulse;
        let mut new = [
            old[0] - r0.mass * r0.velocity(t0, a, b),
            old[1] - r1.mass * r1.velocity(t1, a, b),
        ];
        let max = c.friction * p.normal_impulse;
        let len_sq = new[0] * new[0] + new[1] * new[1];
        if len_sq > max * max {
            let s = max / len_sq.sqrt();
            new = [new[0] * s, new[1] * s];
        }
        p.tangent_impulse = new;
        r0.apply(t0, new[0] - old[0], a, b);
        r1.apply(t1, new[1] - old[1], a, b);
    }
}

/// Sequential impulses, velocity pass: friction then the normal rows (Box2D v2.4's order).
/// The normal target is the restitution bounce, minus `separation/dt` for speculative points
/// (they may close the gap but not more).
pub(crate) fn solve_velocity_si(
    c: &mut ContactConstraint,
    a: &mut SolverBody,
    b: &mut SolverBody,
    dt: Real,
    threshold: Real,
) {
    solve_friction(c, a, b);
    for p in c.points[..c.len].iter_mut() {
        // The bounce `-e·v₀` if the point closes during this step (a speculative point then
        // bounces up to one step early, keeping the energy), else the gap that may still be
        // closed (Bullet subtracts the gap from the bounce, which loses energy).
        let closes = p.separation + p.relative_velocity * dt <= 0.0;
        let target = if p.relative_velocity < -threshold && closes && c.restitution > 0.0 {
            -c.restitution * p.relative_velocity
        } else {
            -p.separation.max(0.0) / dt
        };
        let row = &p.normal_row;
        let vn = row.velocity(c.normal, a, b);
        let new = (p.normal_impulse - row.mass * (vn - target)).max(0.0);
        row.apply(c.normal, new - p.normal_impulse, a, b);
        p.normal_impulse = new;
    }
}

/// Sequential impulses, split-impulse pass (Bullet's `resolveSplitPenetrationImpulse`): push
/// pseudo-velocities (`dp`, `dq`) so that `erp` of the penetration beyond the slop is removed
/// this step; they move the bodies once and are then discarded, so no energy is added.
pub(crate) fn solve_push_si(
    c: &mut ContactConstraint,
    a: &mut SolverBody,
    b: &mut SolverBody,
    erp_over_dt: Real,
    slop: Real,
) {
    for p in c.points[..c.len].iter_mut() {
        let target = erp_over_dt * (-(p.separation + slop)).max(0.0);
        if target <= 0.0 && p.push_impulse == 0.0 {
            continue;
        }
        let row = &p.normal_row;
        // The pushes of the previous points moved `dp`: the linear part is recomputed.
        let vn = row.displacement(c.normal.dot(b.dp - a.dp), a, b);
        let new = (p.push_impulse + row.mass * (target - vn)).max(0.0);
        row.apply_push(c.normal, new - p.push_impulse, a, b);
        p.push_impulse = new;
    }
}

/// The linear velocities of a constraint's two bodies during [`solve_soft`], tracked in
/// the constraint's orthonormal frame `(n, t₀, t₁)` instead of in the bodies.
///
/// Every row of a constraint has the linear part `±d` for one of the three directions, the
/// same for all its points; only the angular parts differ from point to point. An impulse
/// `λ` along `d` changes `v_b − v_a` by `λ (m_a⁻¹ + m_b⁻¹) d`, hence `d · (v_b − v_a)` by
/// `λ (m_a⁻¹ + m_b⁻¹)` and the projections on the two other directions not at all. So the
/// solve projects `v_b − v_a` on the frame once, updates one projection per row by a
/// multiply-add, sums the impulses per direction, and applies the linear impulse
/// `Σλ_n n + Σλ₀ t₀ + Σλ₁ t₁` to both bodies once at the end: the velocities of applying
/// every row to the bodies (Box2D v3, Rapier) in exact arithmetic, to round-off in floating
/// point (the frame is orthonormal to round-off; `contact_simd_tests.rs` checks it against
/// the row-by-row solve, [`solve_soft_rows`]). The four-wide solve (module `contact_simd`) does the same, operation for
/// operation.
pub(crate) struct FrameVelocity {
    /// `n · (v_b − v_a)`, `t₀ · (v_b − v_a)`, `t₁ · (v_b − v_a)`.
    u: [Real; 3],
    /// Sums of the impulse changes along `n`, `t₀`, `t₁`.
    total: [Real; 3],
    /// `m_a⁻¹ + m_b⁻¹`.
    inv_m: Real,
}

impl FrameVelocity {
    #[inline(always)]
    fn new(c: &ContactConstraint, a: &SolverBody, b: &SolverBody) -> FrameVelocity {
        let dv = b.v - a.v;
        FrameVelocity {
            u: [c.normal.dot(dv), c.tangent[0].dot(dv), c.tangent[1].dot(dv)],
            total: [0.0; 3],
            inv_m: a.inv_m + b.inv_m,
        }
    }

    /// Records the impulse change `lambda` along direction `k` (0 normal, 1 and 2 tangents).
    #[inline(always)]
    fn push(&mut self, k: usize, lambda: Real) {
        self.u[k] += lambda * self.inv_m;
        self.total[k] += lambda;
    }

    /// Applies the summed linear impulse to both bodies.
    #[inline(always)]
    fn finish(&self, c: &ContactConstraint, a: &mut SolverBody, b: &mut SolverBody) {
        let imp =
            c.normal * self.total[0] + c.tangent[0] * self.total[1] + c.tangent[1] * self.total[2];
        a.v -= imp * a.inv_m;
        b.v += imp * b.inv_m;
    }
}

impl ContactRow {
    /// [`ContactRow::velocity`] given its linear part `u`.
    #[inline(always)]
    fn velocity_from(&self, u: Real, a: &SolverBody, b: &SolverBody) -> Real {
        u + self.ang_b.dot(b.w) - self.ang_a.dot(a.w)
    }

    /// The angular half of [`ContactRow::apply`].
    #[inline(always)]
    fn apply_angular(&self, lambda: Real, a: &mut SolverBody, b: &mut SolverBody) {
        a.w -= self.inv_ang_a * lambda;
        b.w += self.inv_ang_b * lambda;
    }
}

/// Soft step: friction, then the normal rows (Box2D v3's `b2SolveContact`, with Box2D v2.4's
/// friction-first order, which creeps less in the pyramid test). The separation is
/// updated from the position deltas of the substeps; with `use_bias` penetration is pushed
/// out softly (capped at `max_push`), without it (relax) the rows are rigid and bias-free.
/// The linear velocities follow the constraint frame ([`FrameVelocity`]).
pub(crate) fn solve_soft(
    c: &mut ContactConstraint,
    a: &mut SolverBody,
    b: &mut SolverBody,
    inv_h: Real,
    max_push: Real,
    use_bias: bool,
) {
    let mut lin = FrameVelocity::new(c, a, b);
    for p in c.points[..c.len].iter_mut() {
        let [r0, r1] = &p.tangent_rows;
        let old = p.tangent_impulse;
        let mut new = [
            old[0] - r0.mass * r0.velocity_from(lin.u[1], a, b),
            old[1] - r1.mass * r1.velocity_from(lin.u[2], a, b),
        ];
        let max = c.friction * p.normal_impulse;
        let len_sq = new[0] * new[0] + new[1] * new[1];
        if len_sq > max * max {
            let s = max / len_sq.sqrt();
            new = [new[0] * s, new[1] * s];
        }
        p.tangent_impulse = new;
        let (d0, d1) = (new[0] - old[0], new[1] - old[1]);
        r0.apply_angular(d0, a, b);
        lin.push(1, d0);
        r1.apply_angular(d1, a, b);
        lin.push(2, d1);
    }
    let (linear, soft) = (c.normal.dot(b.dp - a.dp), c.softness);
    for p in c.points[..c.len].iter_mut() {
        let row = &p.normal_row;
        let s = p.separation + row.displacement(linear, a, b);
        let (bias, mass_scale, impulse_scale) = soft_terms(soft, s, inv_h, max_push, use_bias);
        let vn = row.velocity_from(lin.u[0], a, b);
        let lambda = -row.mass * mass_scale * (vn + bias) - impulse_scale * p.normal_impulse;
        let new = (p.normal_impulse + lambda).max(0.0);
        let d = new - p.normal_impulse;
        row.apply_angular(d, a, b);
        lin.push(0, d);
        p.normal_impulse = new;
        p.max_normal_impulse = p.max_normal_impulse.max(new);
    }
    lin.finish(c, a, b);
}

/// Bias, mass scale and impulse scale of a normal row at separation `s`: speculative (the
/// gap may close within the substep), soft (penetration with `use_bias`), or rigid.
#[inline(always)]
fn soft_terms(
    soft: Softness,
    s: Real,
    inv_h: Real,
    max_push: Real,
    use_bias: bool,
) -> (Real, Real, Real) {
    if s > 0.0 {
        (s * inv_h, 1.0, 0.0)
    } else if use_bias {
        (
            (soft.bias_rate * s).max(-max_push),
            soft.mass_scale,
            soft.impulse_scale,
        )
    } else {
        (0.0, 1.0, 0.0)
    }
}

/// Soft step, restitution pass (Box2D v3's `b2ApplyRestitution`): points that approached
/// faster than the threshold and carried an impulse get the bounce velocity `-e·v₀`.
pub(crate) fn apply_restitution(
    c: &mut ContactConstraint,
    a: &mut SolverBody,
    b: &mut SolverBody,
    threshold: Real,
) {
    if c.restitution == 0.0 {
        return;
    }
    for p in c.points[..c.len].iter_mut() {
        if p.relative_velocity > -threshold || p.max_normal_impulse == 0.0 {
            continue;
        }
        let row = &p.normal_row;
        let vn = row.velocity(c.normal, a, b);
        let lambda = -row.mass * (vn + c.restitution * p.relative_velocity);
        let new = (p.normal_impulse + lambda).max(0.0);
        row.apply(c.normal, new - p.normal_impulse, a, b);
        p.normal_impulse = new;
    }
}

/// Writes the accumulated impulses (scaled to per-step units) and the friction direction back
/// into the manifolds.
pub(crate) fn store(cons: &[ContactConstraint], manifolds: &mut [ContactManifold], scale: Real) {
    for c in cons {
        let m = &mut manifolds[c.manifold];
        m.tangent = c.tangent[0];
        for (out, p) in m.points_mut().iter_mut().zip(&c.points[..c.len]) {
            out.normal_impulse = p.normal_impulse * scale;
            out.tangent_impulse = [p.tangent_impulse[0] * scale, p.tangent_impulse[1] * scale];
        }
    }
}

/// Default softness values for the two solvers.
pub(crate) fn softness_pair(params: &SolverParams, h: Real) -> (Softness, Softness) {
    let hertz = params.contact_hertz.min(0.25 / h);
    (
        Softness::new(hertz, params.contact_damping_ratio, h),
        Softness::new(2.0 * hertz, params.contact_damping_ratio, h),
    )
}
