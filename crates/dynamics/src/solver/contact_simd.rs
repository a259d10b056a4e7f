//! Four-wide SIMD contact solve for the soft step, after Box2D v3's `contact_solver.c`
//! (`b2ContactConstraintSIMD`, `b2GatherBodies`, `b2ScatterBodies`,
//! `b2SolveContactTwoPointsTask`).
//!
//! Inside one colour no two constraints share a dynamic body, so four consecutive
//! constraints of a colour can be solved at once: their data is transposed into one
//! structure-of-arrays [`WideConstraint`] (lane `l` = constraint `l`; a short group is padded
//! with empty lanes whose rows have zero mass), the velocities of their bodies are gathered
//! into lanes, the rows are solved with `wide` vectors, and the velocities of the dynamic
//! bodies are scattered back (static and kinematic bodies, which several lanes may share,
//! are read but never written). The overflow colour, whose constraints may share bodies,
//! stays on the scalar path.
//!
//! Every lane computes exactly the arithmetic of the scalar routines in module `contact`
//! (same operations in the same order, no fused multiply-add), so both paths give the same
//! physics; the grouping depends only on the colour order, never on the thread count.
//! The lane type is selected from [`Real`] in one place ([`W`]): `f32x4` or `f64x4`.

use crate::contact::MAX_MANIFOLD_POINTS;
use carom_collision::math::Real;
use std::ops::Range;

#[path = "contact_simd_build.rs"]
mod build;
#[cfg(test)]
pub(crate) use build::store;
pub(crate) use build::{assign, store_range};

#[path = "contact_simd_prep.rs"]
mod prep;
#[cfg(test)]
pub(crate) use build::{build, fill, write_back};
pub(crate) use prep::build_range_wide;
#[cfg(test)]
pub(crate) use prep::build_range_wide_on;

#[path = "contact_simd_run.rs"]
mod run;
pub(crate) use run::{solve_range, Restitution, SoftSolve, WarmStart};
#[cfg(test)]
pub(crate) use run::{solve_range_on, Isa};

#[cfg(test)]
#[path = "contact_simd_drivers.rs"]
mod drivers;
#[cfg(test)]
pub(crate) use drivers::solve;

/// Maps a scalar type to its four-lane vector.
pub(crate) trait Lanes {
    /// Four lanes of `Self`.
    type W;
}

impl Lanes for f32 {
    type W = wide::f32x4;
}

impl Lanes for f64 {
    type W = wide::f64x4;
}

/// Four lanes of [`Real`]: `wide::f32x4` in the f32 build, `wide::f64x4` in the f64 build.
pub(crate) type W = <Real as Lanes>::W;

/// Lanes per wide constraint.
pub(crate) const LANES: usize = 4;

/// Colour-order index of a padding lane in [`WideScratch::members`].
const NONE: usize = usize::MAX;

/// Body slot, manifold index of a padding lane in a [`WideConstraint`] (whose indices are
/// `u32`: half the bytes of `usize`, and slots and manifold indices stay far below 2³²).
const NO_SLOT: u32 = u32::MAX;

/// A vector of four lanes of [`Vec3`](carom_collision::math::Vec3).
#[derive(Debug, Clone, Copy, Default)]
struct V3 {
    x: W,
    y: W,
    z: W,
}

impl V3 {
    /// Same order of operations as glam's `Vec3::dot`.
    #[inline(always)]
    fn dot(self, o: V3) -> W {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    #[inline(always)]
    fn sub(self, o: V3) -> V3 {
        V3 {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }

    #[inline(always)]
    fn add(self, o: V3) -> V3 {
        V3 {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }

    /// `self × o` in glam's order of operations (`Vec3::cross`).
    #[inline(always)]
    fn cross(self, o: V3) -> V3 {
        V3 {
            x: self.y * o.z - o.y * self.z,
            y: self.z * o.x - o.z * self.x,
            z: self.x * o.y - o.x * self.y,
        }
    }

    #[inline(always)]
    fn scale(self, s: W) -> V3 {
        V3 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }
}

/// The stored half of four [`super::contact::ContactRow`]s: the angular impulse directions
/// premultiplied by the inverse world inertias and the effective mass. The angular
/// Jacobians `r × d` themselves are not stored: each pass recomputes them from the point's
/// lever arms ([`WidePoint::arm_a`], shared by the normal and both tangent rows), as Box2D v3
/// recomputes its Jacobians from the anchors (`b2ContactConstraintSIMD` keeps anchors, not
/// Jacobians). Same operations as the scalar `ContactRow::new`, so the same bits.
#[derive(Debug, Clone, Copy, Default)]
struct WideRow {
    inv_ang_a: V3,
    inv_ang_b: V3,
    mass: W,
}

/// The angular Jacobians `r_a × d`, `r_b × d` of one row of four points, recomputed from the
/// lever arms in each pass (see [`WideRow`]).
#[derive(Clone, Copy)]
struct Angular {
    a: V3,
    b: V3,
}

impl Angular {
    /// `(r_a × d, r_b × d)` in glam's order of operations (the bits of `Vec3::cross`).
    #[inline(always)]
    fn new(p: &WidePoint, d: V3) -> Angular {
        Angular {
            a: p.arm_a.cross(d),
            b: p.arm_b.cross(d),
        }
    }

    /// `J v`, as `ContactRow::velocity`.
    #[inline(always)]
    fn velocity(&self, d: V3, a: &WideBody, b: &WideBody) -> W {
        d.dot(b.v.sub(a.v)) + self.b.dot(b.w) - self.a.dot(a.w)
    }

    /// `J Δx`, as `ContactRow::displacement`, given its linear part `d · (Δx_b − Δx_a)`
    /// (the same for every point of a constraint: the position deltas do not change during
    /// a pass, so the solve computes it once per constraint).
    #[inline(always)]
    fn displacement(&self, linear: W, a: &WideBody, b: &WideBody) -> W {
        linear + self.b.dot(b.dq) - self.a.dot(a.dq)
    }

    /// `J v` given its linear part `u = d · (v_b − v_a)`, which the solve tracks per
    /// constraint and direction (see [`solve_soft`]).
    #[inline(always)]
    fn velocity_from(&self, u: W, a: &WideBody, b: &WideBody) -> W {
        u + self.b.dot(b.w) - self.a.dot(a.w)
    }
}

impl WideRow {
    /// The angular half of [`WideRow::apply`]; the linear half is applied once per
    /// constraint (see [`solve_soft`]).
    #[inline(always)]
    fn apply_angular(&self, lambda: W, a: &mut WideBody, b: &mut WideBody) {
        a.w = a.w.sub(self.inv_ang_a.scale(lambda));
        b.w = b.w.add(self.inv_ang_b.scale(lambda));
    }

    /// As `ContactRow::apply`.
    #[inline(always)]
    fn apply(&self, d: V3, lambda: W, a: &mut WideBody, b: &mut WideBody) {
        a.v = a.v.sub(d.scale(lambda * a.inv_m));
        a.w = a.w.sub(self.inv_ang_a.scale(lambda));
        b.v = b.v.add(d.scale(lambda * b.inv_m));
        b.w = b.w.add(self.inv_ang_b.scale(lambda));
    }
}

/// Point `k` of four constraints (zero rows in lanes with fewer points).
#[derive(Debug, Clone, Copy, Default)]
struct WidePoint {
    /// Lever arms of the point from the centres of mass of A and B (zero in lanes without
    /// the point).
    arm_a: V3,
    arm_b: V3,
    normal_row: WideRow,
    tangent_rows: [WideRow; 2],
    separation: W,
    normal_impulse: W,
    tangent_impulse: [W; 2],
    max_normal_impulse: W,
}

/// Four contact constraints of one colour in structure-of-arrays form (Box2D v3's
/// `b2ContactConstraintSIMD`).
#[derive(Debug, Clone)]
pub(crate) struct WideConstraint {
    /// Body slots of each lane (`NO_SLOT` for padding).
    a: [u32; LANES],
    b: [u32; LANES],
    /// Whether the solve writes the lane's body back (dynamic bodies only: a static or
    /// kinematic body may be shared by several lanes and threads, and is only read).
    write_a: [bool; LANES],
    write_b: [bool; LANES],
    /// Manifold of each lane (`NO_SLOT` for padding), where `store` writes the impulses.
    manifold: [u32; LANES],
    /// Point count of each lane.
    lens: [u32; LANES],
    inv_m_a: W,
    inv_m_b: W,
    normal: V3,
    /// The first tangent `t₀`; the second is `t₁ = n × t₀` (exactly how the preparation
    /// builds it, so the lanes' [`WideConstraint::tangent1`] has the scalar constraint's
    /// bits), recomputed once per pass instead of stored: 48 bytes less to stream.
    tangent: V3,
    friction: W,
    restitution: W,
    bias_rate: W,
    mass_scale: W,
    impulse_scale: W,
    points: [WidePoint; MAX_MANIFOLD_POINTS],
    /// Largest point count of the lanes.
    len: usize,
    /// Normal relative velocity of each point at preparation, read only by the restitution
    /// pass: kept out of [`WidePoint`], so the points the solve, relax and warm-start passes
    /// stream are 32 lane values (512 bytes, eight cache lines) instead of 33.
    relative_velocity: [W; MAX_MANIFOLD_POINTS],
}

/// The velocities and position deltas of four bodies (Box2D v3's `b2BodyStateW`).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct WideBody {
    v: V3,
    w: V3,
    dp: V3,
    dq: V3,
    inv_m: W,
}

/// The wide constraints of a step, reused from step to step (cleared, not freed).
#[derive(Debug, Clone, Default)]
pub(crate) struct WideScratch {
    /// Wide constraints, colour after colour.
    pub cons: Vec<WideConstraint>,
    /// Range of `cons` of each colour (overflow excluded).
    pub ranges: Vec<Range<usize>>,
    /// The overflow colour, as a range of the scalar constraints.
    pub overflow: Range<usize>,
    /// The colour-order index of the constraint in each lane of `cons` (`NONE` for
    /// padding), assigned before the lanes are built.
    pub members: Vec<[usize; LANES]>,
}

/// Warm start, as `contact::warm_start` in every lane.
#[inline(always)]
pub(crate) fn warm_start(c: &mut WideConstraint, a: &mut WideBody, b: &mut WideBody) {
    let (tx, ty) = (c.tangent, c.tangent1());
    for p in &c.points[..c.len] {
        let (ni, [ti0, ti1]) = (p.normal_impulse, p.tangent_impulse);
        let imp = c.normal.scale(ni).add(tx.scale(ti0)).add(ty.scale(ti1));
        let (r, [t0, t1]) = (&p.normal_row, &p.tangent_rows);
        a.v = a.v.sub(imp.scale(a.inv_m));
        a.w = a.w.sub(
            r.inv_ang_a
                .scale(ni)
                .add(t0.inv_ang_a.scale(ti0))
                .add(t1.inv_ang_a.scale(ti1)),
        );
        b.v = b.v.add(imp.scale(b.inv_m));
        b.w = b.w.add(
            r.inv_ang_b
                .scale(ni)
                .add(t0.inv_ang_b.scale(ti0))
                .add(t1.inv_ang_b.scale(ti1)),
        );
    }
}

/// The linear velocities of a constraint's two body lanes during [`solve_soft`], tracked
/// along the constraint's orthonormal frame instead of in the bodies: four lanes of
/// `contact::FrameVelocity` (see there), with the same operations in the same order. Per
/// row 3 lane operations instead of 22 (the linear dot product and the two linear updates),
/// and the body velocities and the frame leave the registers during the point loops.
struct Linear {
    /// The second tangent `t₁ = n × t₀` ([`WideConstraint::tangent1`]), computed once per
    /// constraint and pass.
    t1: V3,
    /// `n · (v_b − v_a)`, `t₀ · (v_b − v_a)`, `t₁ · (v_b − v_a)`.
    u: [W; 3],
    /// Sum of the impulse changes along `n`, `t₀`, `t₁`.
    total: [W; 3],
    /// `m_a⁻¹ + m_b⁻¹`.
    inv_m: W,
}

impl Linear {
    #[inline(always)]
    fn new(c: &WideConstraint, a: &WideBody, b: &WideBody) -> Linear {
        let dv = b.v.sub(a.v);
        let zero = W::splat(0.0);
        let t1 = c.tangent1();
        Linear {
            t1,
            u: [c.normal.dot(dv), c.tangent.dot(dv), t1.dot(dv)],
            total: [zero; 3],
            inv_m: a.inv_m + b.inv_m,
        }
    }

    /// Records impulse change `lambda` along direction `k` (0: normal, 1, 2: tangents).
    #[inline(always)]
    fn push(&mut self, k: usize, lambda: W) {
        self.u[k] += lambda * self.inv_m;
        self.total[k] += lambda;
    }

    /// Applies the summed linear impulse to both bodies.
    #[inline(always)]
    fn finish(&self, c: &WideConstraint, a: &mut WideBody, b: &mut WideBody) {
        let (t0, t1) = (c.tangent, self.t1);
        let imp = c
            .normal
            .scale(self.total[0])
            .add(t0.scale(self.total[1]))
            .add(t1.scale(self.total[2]));
        a.v = a.v.sub(imp.scale(a.inv_m));
        b.v = b.v.add(imp.scale(b.inv_m));
    }
}

/// Coulomb friction, as `contact::solve_friction` in every lane (linear part in `lin`).
#[inline(always)]
fn solve_friction(c: &mut WideConstraint, a: &mut WideBody, b: &mut WideBody, lin: &mut Linear) {
    let one = W::splat(1.0);
    let (t0, t1) = (c.tangent, lin.t1);
    for p in c.points[..c.len].iter_mut() {
        let (j0, j1) = (Angular::new(p, t0), Angular::new(p, t1));
        let [r0, r1] = &p.tangent_rows;
        let old = p.tangent_impulse;
        let new = [
            old[0] - r0.mass * j0.velocity_from(lin.u[1], a, b),
            old[1] - r1.mass * j1.velocity_from(lin.u[2], a, b),
        ];
        let max = c.friction * p.normal_impulse;
        let len_sq = new[0] * new[0] + new[1] * new[1];
        // Lanes inside the cone keep `new` (scale exactly 1, and `x · 1` is `x` bit for
        // bit); the others are projected. The square root and the division are the
        // slowest instructions of the solve: skipped when every lane sticks, as most
        // resting contacts do.
        let outside = len_sq.simd_gt(max * max);
        let new = if outside.any() {
            let scale = outside.select(max / len_sq.sqrt(), one);
            [new[0] * scale, new[1] * scale]
        } else {
            new
        };
        p.tangent_impulse = new;
        let (d0, d1) = (new[0] - old[0], new[1] - old[1]);
        r0.apply_angular(d0, a, b);
        lin.push(1, d0);
        r1.apply_angular(d1, a, b);
        lin.push(2, d1);
    }
}

/// Soft-step solve (`b2SolveContactTwoPointsTask`), as `contact::solve_soft` in every lane:
/// friction, then the normal rows with soft feedback when `use_bias` (relax otherwise). The
/// linear velocities follow the constraint frame ([`Linear`]), as in the scalar routine.
#[inline(always)]
pub(crate) fn solve_soft(
    c: &mut WideConstraint,
    a: &mut WideBody,
    b: &mut WideBody,
    inv_h: Real,
    max_push: Real,
    use_bias: bool,
) {
    let mut lin = Linear::new(c, a, b);
    solve_friction(c, a, b, &mut lin);
    let (zero, one) = (W::splat(0.0), W::splat(1.0));
    let (inv_h, min_bias) = (W::splat(inv_h), W::splat(-max_push));
    let n = c.normal;
    let linear = n.dot(b.dp.sub(a.dp));
    for p in c.points[..c.len].iter_mut() {
        let row = &p.normal_row;
        let j = Angular::new(p, n);
        let s = p.separation + j.displacement(linear, a, b);
        let gap = s.simd_gt(zero);
        let (bias, mass_scale, impulse_scale) = if use_bias {
            (
                gap.select(s * inv_h, (c.bias_rate * s).max(min_bias)),
                gap.select(one, c.mass_scale),
                gap.select(zero, c.impulse_scale),
            )
        } else {
            (gap.select(s * inv_h, zero), one, zero)
        };
        let vn = j.velocity_from(lin.u[0], a, b);
        let lambda = -row.mass * mass_scale * (vn + bias) - impulse_scale * p.normal_impulse;
        let new = (p.normal_impulse + lambda).max(zero);
        let d = new - p.normal_impulse;
        row.apply_angular(d, a, b);
        lin.push(0, d);
        p.normal_impulse = new;
        p.max_normal_impulse = p.max_normal_impulse.max(new);
    }
    lin.finish(c, a, b);
}

impl WideConstraint {
    /// The second tangent of every lane, `t₁ = n × t₀`: the preparation's `n.cross(t1)`
    /// with glam's order of operations ([`V3::cross`]), so the same bits as the scalar
    /// constraint's `tangent[1]` (zero in padding lanes).
    #[inline(always)]
    fn tangent1(&self) -> V3 {
        self.normal.cross(self.tangent)
    }
}

/// Whether any lane has restitution: the restitution pass skips the others entirely, as
/// `contact::apply_restitution` returns at once for a constraint without restitution.
pub(crate) fn has_restitution(c: &WideConstraint) -> bool {
    c.restitution.simd_ne(W::splat(0.0)).any()
}

/// Restitution pass (`b2ApplyRestitution`), as `contact::apply_restitution` in every lane:
/// lanes that did not approach faster than `threshold`, carried no impulse or have no
/// restitution are left unchanged.
#[inline(always)]
pub(crate) fn apply_restitution(
    c: &mut WideConstraint,
    a: &mut WideBody,
    b: &mut WideBody,
    threshold: Real,
) {
    let zero = W::splat(0.0);
    let threshold = W::splat(-threshold);
    let bouncy = !c.restitution.simd_eq(zero);
    let n = c.normal;
    for (p, &v0) in c.points[..c.len].iter_mut().zip(&c.relative_velocity) {
        let skip = v0.simd_gt(threshold) | p.max_normal_impulse.simd_eq(zero);
        let active = bouncy & !skip;
        let row = &p.normal_row;
        let vn = Angular::new(p, n).velocity(n, a, b);
        let lambda = -row.mass * (vn + c.restitution * v0);
        let new = active.select((p.normal_impulse + lambda).max(zero), p.normal_impulse);
        row.apply(n, new - p.normal_impulse, a, b);
        p.normal_impulse = new;
    }
}

#[cfg(test)]
#[path = "contact_simd_tests.rs"]
mod tests;
