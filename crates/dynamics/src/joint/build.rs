//! Row building for every joint type, from the current body poses.
//!
//! Linear rows constrain `d · aᵢ`, where `d` runs from A's anchor to B's and `aᵢ` are frame
//! A's axes in world space; A's angular Jacobian uses the lever arm to B's anchor, which
//! accounts for the axis turning with A (Bullet's `btGeneric6DofConstraint`). Angular errors
//! come from the relative rotation `q = q_fa⁻¹ q_fb`: its rotation vector for locked axes,
//! the twist angle about Z for the hinge (Bullet's `getHingeAngle`), a swing–twist
//! decomposition about X for the cone-twist joint with an elliptic swing cone
//! (`btConeTwistConstraint`).
//!
//! Rows are built in two phases, as Box2D v3 / box3d split `b3PrepareJoint` from the
//! substep solves: [`prepare_joint`] runs once per step and fixes everything that does not
//! move — which rows exist, their kinds, bounds, slots and warm-start impulses, which runs
//! form blocks, the world-frame point block of the joints that hold B's anchor on A's
//! ([`PointBlock`]), and the anchors and frame rotations in the bodies' centre-of-mass frames;
//! [`refresh_own`] runs after every position update of the soft step and only rotates the
//! anchors and axes by the current body rotations, recomputes the errors, and updates the
//! effective masses (with the step's fixed inverse inertias). Both run the same generator
//! (module `generate`), which writes through a sink that either appends rows or overwrites
//! the Jacobian and error of the next existing one, so the two cannot disagree on the row
//! order.

use super::generate::{generate, has_point, row_kinds, Frames, Sink};
use super::{Joint, JointKind};
use crate::body_set::BodySet;
use crate::solver::rows::{Block, PairInertia, PointBlock, Row, RowKind};
use crate::solver::SolverBody;
use carom_collision::math::{Mat3, Quat, Real, Vec3, Vec3A};
use std::ops::Range;

/// Row slots per joint: 6 axes × (lower/equality, upper, motor).
pub(crate) const ROW_SLOTS: usize = 18;

/// One active joint in the step: its bodies, the ranges of its rows and blocks in the
/// solver's joint scratch, and the per-step constants the refreshes start from.
#[derive(Debug, Clone)]
pub(crate) struct JointRows {
    /// Joint slot.
    pub joint: usize,
    /// Body slots.
    pub a: usize,
    pub b: usize,
    /// The joint's rows in the shared row buffer.
    pub rows: Range<usize>,
    /// The joint's blocks in the shared block buffer (`start` relative to `rows.start`).
    pub blocks: Range<usize>,
    /// The joint has a finite `break_impulse`: only then does the soft step sum its rows'
    /// substep impulses for breaking.
    pub breakable: bool,
    /// The world-frame point block of a ball, hinge, cone-twist or fixed joint (solved
    /// before the rows), holding what were its first three rows (slots 0, 3, 6).
    pub point: Option<PointBlock>,
    /// Anchor of frame A relative to A's centre of mass, in A's body axes (box3d's
    /// `frameA.p = rot(q, f.p - localCenter)` before the rotation).
    local_a: Vec3,
    local_b: Vec3,
    /// Joint frame rotations in the body frames.
    frame_qa: Quat,
    frame_qb: Quat,
}

/// Rotation vector (axis × angle, angle in `[0, π]`) of a unit quaternion.
pub(crate) fn rotation_vector(q: Quat) -> Vec3 {
    let q = if q.w < 0.0 { -q } else { q };
    let v = Vec3::new(q.x, q.y, q.z);
    let s = v.length();
    if s < 1e-12 {
        return 2.0 * v;
    }
    v * (2.0 * atan2(s, q.w) / s)
}

/// `y.atan2(x)` for the joint angles, which take it up to seven times per joint and step
/// (the twist and swing of a cone-twist joint at the preparation and at every substep's
/// refresh): in the `f32` build a polynomial within 2·10⁻⁸ of `atan` on `[0, 1]`
/// (Abramowitz and Stegun 4.4.49, eight terms) after the usual octant reduction, about a
/// quarter of the instructions of libm's `atan2f` (which was 5 % of "136 ragdolls"). The
/// result is within 3·10⁻⁷ rad of the exact angle (about one unit in the last place of
/// angles near π; tested against the `f64` `atan2`). Zeros, infinities and NaN take the
/// standard function, as does the `f64` build.
#[inline]
pub(crate) fn atan2(y: Real, x: Real) -> Real {
    #[cfg(feature = "f64")]
    {
        y.atan2(x)
    }
    #[cfg(not(feature = "f64"))]
    {
        use carom_collision::math::consts::{FRAC_PI_2, PI};
        let (ax, ay) = (x.abs(), y.abs());
        let (lo, hi) = (ax.min(ay), ax.max(ay));
        // Comparisons are false for NaN: both arguments finite, not both zero.
        if !(ax < Real::INFINITY && ay < Real::INFINITY && hi > 0.0) {
            return y.atan2(x);
        }
        let t = lo / hi;
        let t2 = t * t;
        // A&S 4.4.49's coefficients, rounded to f32.
        const A: [Real; 8] = [
            -0.333_331_47,
            0.199_935_51,
            -0.142_089,
            0.106_562_64,
            -0.075_289_64,
            0.042_909_615,
            -0.016_165_737,
            0.002_866_225_8,
        ];
        let mut p = A[7];
        for &a in A[..7].iter().rev() {
            p = p * t2 + a;
        }
        let mut r = t + t * t2 * p;
        if ay > ax {
            r = FRAC_PI_2 - r;
        }
        if x < 0.0 {
            r = PI - r;
        }
        // The sign of `y`, a zero's included (`atan2(-0, x)` is `-0` or `-π`).
        r.copysign(y)
    }
}

impl JointRows {
    /// The joint frames from the bodies' current poses.
    #[inline]
    fn frames(&self, set: &BodySet) -> Frames {
        let (qa, qb) = (set.rotation[self.a], set.rotation[self.b]);
        let (pa, pb) = (set.position[self.a], set.position[self.b]);
        let rot_a = qa * self.frame_qa;
        let rot_b = qb * self.frame_qb;
        let rb = qb * self.local_b;
        let anchor_b = pb + rb;
        let anchor_a = pa + qa * self.local_a;
        let axes_a = Mat3::from_quat(rot_a);
        Frames {
            ra: Vec3A::from(anchor_b - pa),
            rb: Vec3A::from(rb),
            d: Vec3A::from(anchor_b - anchor_a),
            axes_a: [
                Vec3A::from(axes_a.x_axis),
                Vec3A::from(axes_a.y_axis),
                Vec3A::from(axes_a.z_axis),
            ],
            rot_b,
            q_rel: (rot_a.conjugate() * rot_b).normalize(),
        }
    }
}

/// Builds the rows of `joint` (slot `index`) for a step with substep `h` (for motor force
/// bounds and spring softness), appending them to `rows` and its blocks to `blocks`;
/// stored impulses are scaled by `impulse_in`. Returns `None` (and appends nothing) for
/// broken joints or joints between non-moving bodies. The effective masses are computed
/// only with `with_masses` (else [`masses_own`] must run before the rows are used). The
/// oracle of [`prepare_own`], which the solvers use.
#[cfg(test)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn prepare_joint(
    index: usize,
    joint: &Joint,
    set: &BodySet,
    bodies: &[SolverBody],
    h: Real,
    impulse_in: Real,
    rows: &mut Vec<Row>,
    blocks: &mut Vec<Block>,
    with_masses: bool,
) -> Option<JointRows> {
    let desc = &joint.desc;
    let (a, b) = (desc.body_a.index as usize, desc.body_b.index as usize);
    if joint.broken || !(bodies[a].dynamic || bodies[b].dynamic) {
        return None;
    }
    let (row_start, block_start) = (rows.len(), blocks.len());
    let mut jr = JointRows::planned(index, joint, row_start..row_start, block_start..block_start);
    build_rows(
        &mut jr,
        joint,
        set,
        (h, impulse_in),
        &mut Sink::Append(rows),
    );
    jr.rows = row_start..rows.len();
    let own = &mut rows[jr.rows.clone()];
    warm_impulses(own, joint, impulse_in);
    block_runs(own, |start, len| blocks.push(Block::new(start, len)));
    jr.blocks = block_start..blocks.len();
    if with_masses {
        masses(&mut jr, rows, blocks, bodies);
    }
    Some(jr)
}

/// How many rows and blocks [`prepare_joint`] gives a joint of type `kind`: fixed by the
/// description (module `generate`'s `row_kinds`), so a step lays out every joint's ranges
/// first and then builds the joints in parallel ([`prepare_own`]).
pub(crate) fn layout(kind: &JointKind) -> (usize, usize) {
    let (eq, n) = row_kinds(kind);
    let mut blocks = 0;
    runs(n, |i| eq[i], |_, _| blocks += 1);
    (n, blocks)
}

/// [`prepare_joint`] with masses, for a joint laid out by a plan (`jr` from
/// [`JointRows::planned`], with the ranges [`layout`] gave it): its rows are built into
/// `own` and its blocks into `own_blocks` (those ranges of the shared buffers, every slot
/// overwritten), then their effective masses with the bodies `sa`, `sb`. The same values,
/// bit for bit, as `prepare_joint`; touches nothing but `jr`, `own` and `own_blocks`, so
/// the joints of one colour are built in parallel blocks (the soft step's first joint
/// pass), not one after another before the step.
#[allow(clippy::too_many_arguments)]
pub(crate) fn prepare_own(
    jr: &mut JointRows,
    joint: &Joint,
    set: &BodySet,
    (sa, sb): (&SolverBody, &SolverBody),
    h: Real,
    impulse_in: Real,
    own: &mut [Row],
    own_blocks: &mut [Block],
) {
    *jr = JointRows::planned(jr.joint, joint, jr.rows.clone(), jr.blocks.clone());
    let mut sink = Sink::Fill(own, 0);
    build_rows(jr, joint, set, (h, impulse_in), &mut sink);
    debug_assert!(
        matches!(sink, Sink::Fill(r, n) if n == r.len()),
        "the layout of {:?} disagrees with its rows",
        joint.desc.kind
    );
    warm_impulses(own, joint, impulse_in);
    let mut k = 0;
    block_runs(own, |start, len| {
        if let Some(b) = own_blocks.get_mut(k) {
            *b = Block::new(start, len);
        }
        k += 1;
    });
    debug_assert_eq!(k, own_blocks.len(), "blocks of {:?}", joint.desc.kind);
    masses_own(jr.point.as_mut(), own, own_blocks, sa, sb);
}

impl JointRows {
    /// Joint `index` with the row and block ranges `rows`, `blocks` of the shared buffers;
    /// its anchors, frame rotations and point block are set when its rows are built
    /// ([`build_rows`]), so a plan touches nothing but the description.
    pub(crate) fn planned(
        index: usize,
        joint: &Joint,
        rows: Range<usize>,
        blocks: Range<usize>,
    ) -> JointRows {
        let desc = &joint.desc;
        JointRows {
            joint: index,
            breakable: desc.break_impulse.is_finite(),
            a: desc.body_a.index as usize,
            b: desc.body_b.index as usize,
            rows,
            blocks,
            local_a: Vec3::ZERO,
            local_b: Vec3::ZERO,
            frame_qa: desc.frame_a.rotation,
            frame_qb: desc.frame_b.rotation,
            point: None,
        }
    }
}

/// The anchors relative to the bodies' centres of mass, the frames at the current poses,
/// the point block of the joints that have one (its warm-start impulse from the stored slot
/// impulses scaled by `impulse_in`), and the rows through `sink`.
fn build_rows(
    jr: &mut JointRows,
    joint: &Joint,
    set: &BodySet,
    (h, impulse_in): (Real, Real),
    sink: &mut Sink,
) {
    let desc = &joint.desc;
    jr.local_a = desc.frame_a.translation - set.info[jr.a].local_com;
    jr.local_b = desc.frame_b.translation - set.info[jr.b].local_com;
    let f = jr.frames(set);
    if has_point(&desc.kind) {
        let mut p = PointBlock::new(f.ra, f.rb, f.d, f.axes_a);
        // The stored slot impulses are components along frame A's axes.
        let s = |k: usize| joint.impulses[k] * impulse_in;
        p.impulse = f.axes_a[0] * s(0) + f.axes_a[1] * s(3) + f.axes_a[2] * s(6);
        jr.point = Some(p);
    }
    generate(&desc.kind, &f, h, sink);
}

/// The rows' warm-start impulses: the stored slot impulses scaled by `impulse_in`, clamped
/// to the rows' bounds.
fn warm_impulses(own: &mut [Row], joint: &Joint, impulse_in: Real) {
    for row in own.iter_mut() {
        row.impulse = (joint.impulses[row.slot as usize] * impulse_in).clamp(row.lo, row.hi);
    }
}

/// Calls `block(start, len)` for each block of `own`: runs of two or three consecutive
/// equality rows.
fn block_runs(own: &[Row], block: impl FnMut(usize, usize)) {
    runs(own.len(), |i| own[i].kind == RowKind::Equality, block);
}

/// The blocks of `n` rows whose row `i` is an equality row when `eq(i)`: the runs of two or
/// three consecutive equality rows, in order, as `block(start, len)`.
fn runs(n: usize, eq: impl Fn(usize) -> bool, mut block: impl FnMut(usize, usize)) {
    let mut i = 0;
    while i < n {
        let mut end = i;
        while end < n && end - i < 3 && eq(end) {
            end += 1;
        }
        if end - i >= 2 {
            block(i, end - i);
            i = end;
        } else {
            i = end.max(i + 1);
        }
    }
}

/// [`refresh_own`] on the shared buffers (tests).
#[cfg(test)]
pub(crate) fn refresh_joint(
    jr: &mut JointRows,
    joint: &Joint,
    set: &BodySet,
    bodies: &[SolverBody],
    rows: &mut [Row],
    blocks: &mut [Block],
) {
    let (own, own_blocks) = (&mut rows[jr.rows.clone()], &mut blocks[jr.blocks.clone()]);
    let (sa, sb) = (&bodies[jr.a], &bodies[jr.b]);
    refresh_own(jr, joint, set, sa, sb, own, own_blocks);
}

/// Updates the rows of `jr` from the bodies' *current* poses (the soft step moves them every
/// substep), keeping kinds, bounds and accumulated impulses. Box2D v3 rotates the anchors by
/// each body's delta rotation in every solve (`b2SolveRevoluteJoint`); a row built once per
/// step keeps the lever arms and axes of the step start, a linearisation that lets the
/// joint drift and pump energy.
///
/// Touches only the joint's two solver bodies `sa`, `sb` (read for their inverse masses and
/// inertias) and its own rows and blocks (`own`, `own_blocks`: the ranges `jr.rows` and
/// `jr.blocks` of the shared buffers), so the joints of one colour may be refreshed at the
/// same time.
pub(crate) fn refresh_own(
    jr: &mut JointRows,
    joint: &Joint,
    set: &BodySet,
    sa: &SolverBody,
    sb: &SolverBody,
    own: &mut [Row],
    own_blocks: &mut [Block],
) {
    let f = jr.frames(set);
    if let Some(p) = &mut jr.point {
        p.set(f.ra, f.rb, f.d, f.axes_a);
    }
    let mut sink = Sink::Overwrite(own, 0);
    // `h` only sizes motor bounds and spring softness, which an overwrite keeps.
    generate(&joint.desc.kind, &f, 0.0, &mut sink);
    debug_assert!(matches!(sink, Sink::Overwrite(r, n) if n == r.len()));
    masses_own(jr.point.as_mut(), own, own_blocks, sa, sb);
}

/// Effective masses: the point block's and each block's `K⁻¹`, the scalar mass of every
/// other row.
#[cfg(test)]
fn masses(jr: &mut JointRows, rows: &mut [Row], blocks: &mut [Block], bodies: &[SolverBody]) {
    let (sa, sb) = (&bodies[jr.a], &bodies[jr.b]);
    masses_own(
        jr.point.as_mut(),
        &mut rows[jr.rows.clone()],
        &mut blocks[jr.blocks.clone()],
        sa,
        sb,
    );
}

/// [`masses`] on one joint's point block, own rows and blocks (`own`, `blocks`: the joint's
/// ranges of the shared buffers) with its bodies `sa`, `sb`.
#[inline]
pub(crate) fn masses_own(
    point: Option<&mut PointBlock>,
    own: &mut [Row],
    blocks: &mut [Block],
    sa: &SolverBody,
    sb: &SolverBody,
) {
    let p = PairInertia::of(sa, sb);
    if let Some(point) = point {
        point.update(&p);
    }
    let mut i = 0;
    for block in blocks {
        for row in &mut own[i..block.start] {
            row.finish(&p);
        }
        let end = block.start + block.len;
        block.update(&mut own[block.start..end], &p);
        i = end;
    }
    for row in &mut own[i..] {
        row.finish(&p);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atan2_is_within_3e_7_of_the_exact_angle_everywhere() {
        // Oracle: the f64 `atan2` of the same (exactly widened) arguments. Every octant and
        // axis, tiny and huge magnitudes, signed zeros, infinities and NaN.
        let mut worst: f64 = 0.0;
        let mut check = |y: Real, x: Real| {
            let got = atan2(y, x) as f64;
            let want = (y as f64).atan2(x as f64);
            if want.is_nan() {
                assert!(got.is_nan(), "atan2({y}, {x}) = {got}");
                return;
            }
            let err = (got - want).abs();
            worst = worst.max(err);
            assert!(err <= 3e-7, "atan2({y}, {x}) = {got}, want {want}");
            assert_eq!(
                got.is_sign_negative(),
                want.is_sign_negative(),
                "atan2({y}, {x})"
            );
        };
        let n = 20_000;
        for k in 0..n {
            let a = (k as f64 / n as f64 - 0.5) * 2.0 * std::f64::consts::PI;
            for r in [1e-30, 1e-6, 0.7, 1.0, 3.5e4, 1e30] {
                check((r * a.sin()) as Real, (r * a.cos()) as Real);
            }
        }
        let specials = [
            0.0,
            -0.0,
            1e-45,
            -1e-45,
            1.0,
            -1.0,
            Real::INFINITY,
            -Real::INFINITY,
        ];
        for &y in &specials {
            for &x in &specials {
                check(y, x);
            }
        }
        check(Real::NAN, 1.0);
        check(1.0, Real::NAN);
        assert!(worst > 0.0 || cfg!(feature = "f64"));
    }

    #[test]
    fn rotation_vector_is_axis_times_angle() {
        let axis = Vec3::new(1.0, -2.0, 0.5).normalize();
        for angle in [0.0, 1e-4, 0.5, 2.0, 3.1] {
            let q = Quat::from_axis_angle(axis, angle);
            assert!(
                (rotation_vector(q) - axis * angle).length() < 1e-4,
                "{angle}"
            );
            // The double cover gives the same rotation vector.
            assert!(
                (rotation_vector(-q) - axis * angle).length() < 1e-4,
                "{angle}"
            );
        }
    }
}
