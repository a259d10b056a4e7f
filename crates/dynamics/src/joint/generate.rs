//! The row generator shared by the per-step preparation and the per-substep refresh of
//! module `build`: from the joint frames, every joint type emits its rows in a fixed order
//! through a [`Sink`]. The order and count depend only on the joint's description, never on
//! the poses, so a refresh can overwrite the rows of the preparation in place (a row that
//! is geometrically undefined at some pose — the cone's swing axis at zero swing — is
//! emitted inactive instead of being left out).

use super::build::{atan2, rotation_vector, ROW_SLOTS};
use super::{Axis, AxisMode, JointKind, Motor};
use crate::solver::rows::{Row, RowKind};
use crate::solver::Softness;
use carom_collision::math::{Quat, Real, Vec3, Vec3A};

/// The joint frames at the current poses. The vectors are [`Vec3A`] (SIMD registers in
/// `f32`), as are the rows' Jacobians they become.
pub(super) struct Frames {
    /// Lever arm from A's centre of mass to B's anchor.
    pub ra: Vec3A,
    /// Lever arm from B's centre of mass to B's anchor.
    pub rb: Vec3A,
    /// From A's anchor to B's.
    pub d: Vec3A,
    /// Frame A's axes in world space (the columns of its rotation matrix).
    pub axes_a: [Vec3A; 3],
    /// Frame B's rotation in world space.
    pub rot_b: Quat,
    /// `q_fa⁻¹ q_fb`, normalised.
    pub q_rel: Quat,
}

impl Frames {
    #[inline]
    fn axis_a(&self, i: usize) -> Vec3A {
        self.axes_a[i]
    }

    /// Frame A's rotation applied to `u` (`(x₀ u_x + x₁ u_y) + x₂ u_z`, the order of glam's
    /// `Mat3 * Vec3`).
    #[inline]
    fn rotate_a(&self, u: Vec3) -> Vec3A {
        self.axes_a[0] * u.x + self.axes_a[1] * u.y + self.axes_a[2] * u.z
    }
}

/// Where generated rows go: appended (the tests' oracle), written whole into the slots laid
/// out for them from the given index on (preparation into a planned range, see
/// [`row_kinds`]), or written over the existing rows from the given index on, keeping their kinds, bounds
/// and impulses (refresh).
pub(super) enum Sink<'a> {
    /// Appending is the tests' oracle (`build::prepare_joint`); the solvers fill planned
    /// slots.
    #[cfg(test)]
    Append(&'a mut Vec<Row>),
    Fill(&'a mut [Row], usize),
    Overwrite(&'a mut [Row], usize),
}

impl Sink<'_> {
    /// One row for `slot` with Jacobian `j` and error `c`; `kind` gives the row kind and
    /// its motor bound, and is only evaluated when appending.
    #[inline]
    fn put(&mut self, slot: usize, j: [Vec3A; 3], c: Real, kind: impl FnOnce() -> (RowKind, Real)) {
        match self {
            #[cfg(test)]
            Sink::Append(rows) => {
                let (kind, max) = kind();
                rows.push(Row::new(slot as u8, j, c, kind, max));
            }
            Sink::Fill(rows, i) => {
                let (kind, max) = kind();
                if let Some(row) = rows.get_mut(*i) {
                    *row = Row::new(slot as u8, j, c, kind, max);
                }
                *i += 1;
            }
            Sink::Overwrite(rows, i) => {
                if let Some(row) = rows.get_mut(*i) {
                    row.set(j, c);
                }
                *i += 1;
            }
        }
    }

    /// A row of kind `kind` (an inequality or equality row) that does nothing at this pose:
    /// zero Jacobian, zero error and zero impulse (a row that would be absent).
    #[inline]
    fn put_inactive(&mut self, slot: usize, kind: RowKind) {
        let zero = [Vec3A::ZERO; 3];
        match self {
            #[cfg(test)]
            Sink::Append(rows) => rows.push(Row::new(slot as u8, zero, 0.0, kind, 0.0)),
            Sink::Fill(rows, i) => {
                if let Some(row) = rows.get_mut(*i) {
                    *row = Row::new(slot as u8, zero, 0.0, kind, 0.0);
                }
                *i += 1;
            }
            Sink::Overwrite(rows, i) => {
                if let Some(row) = rows.get_mut(*i) {
                    row.set(zero, 0.0);
                    row.impulse = 0.0;
                }
                *i += 1;
            }
        }
    }

    #[inline]
    fn linear(
        &mut self,
        slot: usize,
        axis: Vec3A,
        f: &Frames,
        c: Real,
        kind: impl FnOnce() -> (RowKind, Real),
    ) {
        let j = [axis, -f.ra.cross(axis), f.rb.cross(axis)];
        self.put(slot, j, c, kind);
    }

    #[inline]
    fn angular(
        &mut self,
        slot: usize,
        axis: Vec3A,
        c: Real,
        kind: impl FnOnce() -> (RowKind, Real),
    ) {
        self.put(slot, [Vec3A::ZERO, -axis, axis], c, kind);
    }
}

const EQUALITY: fn() -> (RowKind, Real) = || (RowKind::Equality, 0.0);
const INEQUALITY: fn() -> (RowKind, Real) = || (RowKind::Inequality, 0.0);

/// Whether a joint of type `kind` holds B's anchor on A's (ball, hinge, cone-twist,
/// fixed): that part is not emitted as rows but solved as one world-frame
/// [`PointBlock`](crate::solver::rows::PointBlock) built from the same frames.
pub(super) fn has_point(kind: &JointKind) -> bool {
    matches!(
        kind,
        JointKind::Ball | JointKind::Fixed | JointKind::Hinge { .. } | JointKind::ConeTwist { .. }
    )
}

/// Emits the rows of a joint of type `kind` at frames `f`; `h` is the substep. The point
/// part of the joints for which [`has_point`] holds is left to their point block.
pub(super) fn generate(kind: &JointKind, f: &Frames, h: Real, sink: &mut Sink) {
    let lock = Axis::default();
    match *kind {
        JointKind::Ball => {}
        JointKind::Fixed => angular_axes(f, &[lock; 3], h, sink),
        JointKind::Slider { limits, motor } => {
            let x = Axis {
                mode: limited(limits),
                motor,
                spring: None,
            };
            linear_axes(f, &[x, lock, lock], h, sink);
            angular_axes(f, &[lock; 3], h, sink);
        }
        JointKind::Generic6Dof {
            ref linear,
            ref angular,
        } => {
            linear_axes(f, linear, h, sink);
            angular_axes(f, angular, h, sink);
        }
        JointKind::Hinge { limits, motor } => hinge(f, limits, motor, h, sink),
        JointKind::ConeTwist {
            swing1,
            swing2,
            twist,
        } => cone_twist(f, swing1, swing2, twist, sink),
    }
}

/// The rows [`generate`] emits for a joint of type `kind`, in emission order, as equality
/// flags (`true` for an [`RowKind::Equality`] row), and their count. They depend on the
/// description only (see the module docs), so a step lays out the rows of every joint
/// before building any, and builds the joints of one colour in parallel blocks. Mirrors
/// `generate` branch for branch (the tests compare the two for every joint type).
pub(super) fn row_kinds(kind: &JointKind) -> ([bool; ROW_SLOTS], usize) {
    let mut list = ([false; ROW_SLOTS], 0);
    let mut push = |eq: bool| {
        if let Some(k) = list.0.get_mut(list.1) {
            *k = eq;
        }
        list.1 += 1;
    };
    let lock = Axis::default();
    match *kind {
        JointKind::Ball => {}
        JointKind::Fixed => (0..3).for_each(|_| axis_kinds(&lock, &mut push)),
        JointKind::Slider { limits, motor } => {
            let x = Axis {
                mode: limited(limits),
                motor,
                spring: None,
            };
            for ax in [&x, &lock, &lock, &lock, &lock, &lock] {
                axis_kinds(ax, &mut push);
            }
        }
        JointKind::Generic6Dof {
            ref linear,
            ref angular,
        } => linear
            .iter()
            .chain(angular)
            .for_each(|ax| axis_kinds(ax, &mut push)),
        JointKind::Hinge { limits, motor } => {
            push(true);
            push(true);
            let ax = Axis {
                mode: limited(limits),
                motor,
                spring: None,
            };
            if !(ax.mode == AxisMode::Free && motor.is_none()) {
                axis_kinds(&ax, &mut push);
            }
        }
        JointKind::ConeTwist { twist, .. } => {
            // The swing limit (an inequality row, inactive at zero swing), then the twist:
            // one equality row for a zero span, else two limits.
            push(false);
            if twist == 0.0 {
                push(true);
            } else {
                push(false);
                push(false);
            }
        }
    }
    list
}

/// The kinds of [`axis_rows`]' rows for `ax`.
fn axis_kinds(ax: &Axis, push: &mut impl FnMut(bool)) {
    match ax.mode {
        AxisMode::Locked => {
            push(true);
            return;
        }
        AxisMode::Free => {}
        AxisMode::Limited { low, high } if low == high => push(true),
        AxisMode::Limited { .. } => {
            push(false);
            push(false);
        }
    }
    if ax.motor.is_some() || ax.spring.is_some() {
        push(false);
    }
}

fn limited(limits: Option<(Real, Real)>) -> AxisMode {
    limits.map_or(AxisMode::Free, |(low, high)| AxisMode::Limited {
        low,
        high,
    })
}

/// Rows for one coordinate `value` along a generic axis: limits or lock, motor, spring.
/// `row(sink, slot, sign, c, kind)` emits one row along `sign · axis`.
fn axis_rows<S>(base: usize, ax: &Axis, value: Real, h: Real, sink: &mut Sink, row: S)
where
    S: Fn(&mut Sink, usize, Real, Real, &dyn Fn() -> (RowKind, Real)),
{
    match ax.mode {
        AxisMode::Locked => {
            row(sink, base, 1.0, value, &EQUALITY);
            return;
        }
        AxisMode::Free => {}
        AxisMode::Limited { low, high } if low == high => {
            row(sink, base, 1.0, value - low, &EQUALITY)
        }
        AxisMode::Limited { low, high } => {
            row(sink, base, 1.0, value - low, &INEQUALITY);
            row(sink, base + 1, -1.0, high - value, &INEQUALITY);
        }
    }
    if let Some(m) = ax.motor {
        let kind = || (RowKind::Motor { speed: m.speed }, m.max_force * h);
        row(sink, base + 2, 1.0, 0.0, &kind);
    } else if let Some(s) = ax.spring {
        let kind = || {
            let softness = Softness::new(s.hertz, s.damping_ratio, h);
            (RowKind::Spring { softness }, 0.0)
        };
        row(sink, base + 2, 1.0, value - s.rest, &kind);
    }
}

fn linear_axes(f: &Frames, axes: &[Axis; 3], h: Real, sink: &mut Sink) {
    for (i, ax) in axes.iter().enumerate() {
        let axis = f.axis_a(i);
        let value = f.d.dot(axis);
        axis_rows(3 * i, ax, value, h, sink, |s, slot, sign, c, kind| {
            s.linear(slot, axis * sign, f, c, kind)
        });
    }
}

fn angular_axes(f: &Frames, axes: &[Axis; 3], h: Real, sink: &mut Sink) {
    let e = rotation_vector(f.q_rel);
    for (i, ax) in axes.iter().enumerate() {
        let axis = f.axis_a(i);
        axis_rows(9 + 3 * i, ax, e[i], h, sink, |s, slot, sign, c, kind| {
            s.angular(slot, axis * sign, c, kind)
        });
    }
}

/// Hinge about frame Z: two rows keep the Z axes aligned (`c = pᵢ·(z_a × z_b)` is B's
/// rotation about `pᵢ`), then limits and motor on the angle of B's X axis in A's XY plane.
fn hinge(f: &Frames, limits: Option<(Real, Real)>, motor: Option<Motor>, h: Real, sink: &mut Sink) {
    let za = f.axis_a(2);
    let zb = Vec3A::from(f.rot_b * Vec3::Z);
    let err = za.cross(zb);
    for i in 0..2 {
        let p = f.axis_a(i);
        sink.angular(9 + 3 * i, p, p.dot(err), EQUALITY);
    }
    let ax = Axis {
        mode: limited(limits),
        motor,
        spring: None,
    };
    if ax.mode == AxisMode::Free && motor.is_none() {
        return;
    }
    let q = f.q_rel;
    let angle = wrap_angle(2.0 * atan2(q.z, q.w));
    axis_rows(15, &ax, angle, h, sink, |s, slot, sign, c, kind| {
        s.angular(slot, za * sign, c, kind)
    });
}

pub(super) fn wrap_angle(a: Real) -> Real {
    use carom_collision::math::consts::PI;
    if a > PI {
        a - 2.0 * PI
    } else if a < -PI {
        a + 2.0 * PI
    } else {
        a
    }
}

/// Cone-twist: `q_rel = q_swing · q_twist` with the twist about X. The swing angle `φ` along
/// the swing direction `u = (0, u_y, u_z)` is limited by the ellipse
/// `1/φ_max² = (u_y/swing2)² + (u_z/swing1)²`; the twist angle by `±twist` (a zero `twist`
/// is one equality row, slot 12). Limit rows are
/// always present and act speculatively while inside the limits; at (nearly) zero swing the
/// swing direction is undefined and the swing row is inactive.
fn cone_twist(f: &Frames, swing1: Real, swing2: Real, twist: Real, sink: &mut Sink) {
    let q = if f.q_rel.w < 0.0 { -f.q_rel } else { f.q_rel };
    let tw_len = (q.x * q.x + q.w * q.w).sqrt();
    let q_twist = if tw_len > 1e-9 {
        Quat::from_xyzw(q.x / tw_len, 0.0, 0.0, q.w / tw_len)
    } else {
        Quat::IDENTITY
    };
    let twist_angle = wrap_angle(2.0 * atan2(q_twist.x, q_twist.w));
    let swing = rotation_vector((q * q_twist.conjugate()).normalize());
    let phi = swing.length();
    if phi > 1e-6 {
        let u = swing / phi;
        let (s1, s2) = (swing1.max(1e-3), swing2.max(1e-3));
        let inv_sq = (u.y / s2).powi(2) + (u.z / s1).powi(2);
        let phi_max = if inv_sq > 0.0 {
            1.0 / inv_sq.sqrt()
        } else {
            s1.max(s2)
        };
        let axis = f.rotate_a(u);
        sink.angular(9, -axis, phi_max - phi, INEQUALITY);
    } else {
        sink.put_inactive(9, RowKind::Inequality);
    }
    let tw = (f.axis_a(0) + Vec3A::from(f.rot_b * Vec3::X)).normalize_or_zero();
    if twist == 0.0 {
        // A zero span locks the twist: one equality row instead of two limits that meet
        // (as a generic axis whose limits are equal).
        if tw != Vec3A::ZERO {
            sink.angular(12, tw, twist_angle, EQUALITY);
        } else {
            sink.put_inactive(12, RowKind::Equality);
        }
    } else if tw != Vec3A::ZERO {
        sink.angular(12, tw, twist_angle + twist, INEQUALITY);
        sink.angular(13, -tw, twist - twist_angle, INEQUALITY);
    } else {
        sink.put_inactive(12, RowKind::Inequality);
        sink.put_inactive(13, RowKind::Inequality);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_angle_stays_in_range() {
        use carom_collision::math::consts::PI;
        assert!((wrap_angle(1.5 * PI) + 0.5 * PI).abs() < 1e-5);
        assert!((wrap_angle(-1.5 * PI) - 0.5 * PI).abs() < 1e-5);
        assert_eq!(wrap_angle(0.25), 0.25);
    }
}
