//! Row building for every joint type, from the current body poses.
//!
//! Linear rows constrain `d · aᵢ`, where `d` runs from A's anchor to B's and `aᵢ` are frame
//! A's axes in world space; A's angular Jacobian uses the lever arm to B's anchor, which
//! accounts for the axis turning with A (Bullet's `btGeneric6DofConstraint`). Angular errors
//! come from the relative rotation `q = q_fa⁻¹ q_fb`: its rotation vector for locked axes,
//! the twist angle about Z for the hinge (Bullet's `getHingeAngle`), a swing–twist
//! decomposition about X for the cone-twist joint with an elliptic swing cone
//! (`btConeTwistConstraint`).

use super::{Axis, AxisMode, Joint, JointKind};
use crate::body_set::BodySet;
use crate::solver::rows::{Block, Row, RowKind};
use crate::solver::{Softness, SolverBody};
use carom_collision::math::{Quat, Real, Vec3};

/// Row slots per joint: 6 axes × (lower/equality, upper, motor).
pub(crate) const ROW_SLOTS: usize = 18;

/// The rows of one joint this step, each with its warm-starting slot, and the runs of
/// equality rows solved as blocks.
#[derive(Debug, Clone)]
pub(crate) struct JointRows {
    pub joint: usize,
    pub a: usize,
    pub b: usize,
    pub rows: Vec<(usize, Row)>,
    pub blocks: Vec<Block>,
}

/// Rotation vector (axis × angle, angle in `[0, π]`) of a unit quaternion.
pub(crate) fn rotation_vector(q: Quat) -> Vec3 {
    let q = if q.w < 0.0 { -q } else { q };
    let v = Vec3::new(q.x, q.y, q.z);
    let s = v.length();
    if s < 1e-12 {
        return 2.0 * v;
    }
    v * (2.0 * s.atan2(q.w) / s)
}

struct Frames {
    ra: Vec3,
    rb: Vec3,
    d: Vec3,
    rot_a: Quat,
    rot_b: Quat,
    q_rel: Quat,
}

impl Frames {
    fn axis_a(&self, i: usize) -> Vec3 {
        self.rot_a * unit(i)
    }
}

fn unit(i: usize) -> Vec3 {
    [Vec3::X, Vec3::Y, Vec3::Z][i]
}

/// Builds the rows of `joint` (slot `index`) with substep `h` (for motor force bounds and
/// spring softness). Returns `None` for broken joints or joints between non-moving bodies.
pub(crate) fn build_rows(
    index: usize,
    joint: &Joint,
    set: &BodySet,
    bodies: &[SolverBody],
    h: Real,
    impulse_in: Real,
) -> Option<JointRows> {
    let desc = &joint.desc;
    let (a, b) = (desc.body_a.index as usize, desc.body_b.index as usize);
    if joint.broken || !(bodies[a].dynamic || bodies[b].dynamic) {
        return None;
    }
    let mut jr = JointRows {
        joint: index,
        a,
        b,
        rows: Vec::with_capacity(6),
        blocks: Vec::with_capacity(2),
    };
    fill_rows(joint, set, bodies, h, &mut jr);
    for (slot, row) in jr.rows.iter_mut() {
        row.impulse = (joint.impulses[*slot] * impulse_in).clamp(row.lo, row.hi);
    }
    Some(jr)
}

/// Rebuilds the rows of `jr` from the bodies' *current* poses (the soft step moves them every
/// substep), keeping each slot's accumulated impulse. Box2D v3 rotates the anchors by each
/// body's delta rotation in every solve (`b2SolveRevoluteJoint`); a row built once per step
/// keeps the lever arms and axes of the step start, a linearisation that lets the joint
/// drift and pump energy. `C` is shifted by `-J·(dp, dq)` so that the delta tracking of
/// [`Row::solve`] starts from the current error.
pub(crate) fn refresh_rows(
    jr: &mut JointRows,
    joint: &Joint,
    set: &BodySet,
    bodies: &[SolverBody],
    h: Real,
) {
    let mut impulses = [0.0; ROW_SLOTS];
    for (slot, row) in &jr.rows {
        impulses[*slot] = row.impulse;
    }
    fill_rows(joint, set, bodies, h, jr);
    let (sa, sb) = (&bodies[jr.a], &bodies[jr.b]);
    for (slot, row) in jr.rows.iter_mut() {
        row.impulse = impulses[*slot].clamp(row.lo, row.hi);
        row.c -= row.delta(sa, sb);
    }
}

/// Fills `jr.rows` and `jr.blocks` (cleared first, capacity kept) from the current poses.
fn fill_rows(joint: &Joint, set: &BodySet, bodies: &[SolverBody], h: Real, jr: &mut JointRows) {
    let desc = &joint.desc;
    let (a, b) = (jr.a, jr.b);
    let fa = set.pose_of(a).mul(&desc.frame_a);
    let fb = set.pose_of(b).mul(&desc.frame_b);
    let d = fb.translation - fa.translation;
    let q_rel = (fa.rotation.inverse() * fb.rotation).normalize();
    let f = Frames {
        ra: fb.translation - set.position[a],
        rb: fb.translation - set.position[b],
        d,
        rot_a: fa.rotation,
        rot_b: fb.rotation,
        q_rel,
    };
    let rows = &mut jr.rows;
    rows.clear();
    let lock = Axis::default();
    match desc.kind {
        JointKind::Ball => linear_axes(&f, &[lock; 3], h, rows),
        JointKind::Fixed => {
            linear_axes(&f, &[lock; 3], h, rows);
            angular_axes(&f, &[lock; 3], h, rows);
        }
        JointKind::Slider { limits, motor } => {
            let x = Axis {
                mode: limits.map_or(AxisMode::Free, |(low, high)| AxisMode::Limited {
                    low,
                    high,
                }),
                motor,
                spring: None,
            };
            linear_axes(&f, &[x, lock, lock], h, rows);
            angular_axes(&f, &[lock; 3], h, rows);
        }
        JointKind::Generic6Dof { linear, angular } => {
            linear_axes(&f, &linear, h, rows);
            angular_axes(&f, &angular, h, rows);
        }
        JointKind::Hinge { limits, motor } => {
            linear_axes(&f, &[lock; 3], h, rows);
            hinge(&f, limits, motor, h, rows);
        }
        JointKind::ConeTwist {
            swing1,
            swing2,
            twist,
        } => {
            linear_axes(&f, &[lock; 3], h, rows);
            cone_twist(&f, swing1, swing2, twist, rows);
        }
    }
    let (sa, sb) = (&bodies[a], &bodies[b]);
    // Runs of up to three consecutive equality rows become blocks; the other rows (and the
    // rows of a block too ill-conditioned to invert) get their scalar effective mass.
    jr.blocks.clear();
    let mut i = 0;
    while i < rows.len() {
        let mut end = i;
        while end < rows.len() && end - i < 3 && rows[end].1.kind == RowKind::Equality {
            end += 1;
        }
        let block = if end - i >= 2 {
            Block::new(i, &rows[i..end], sa, sb)
        } else {
            None
        };
        match block {
            Some(block) => {
                jr.blocks.push(block);
                i = end;
            }
            None => {
                let end = end.max(i + 1);
                for (_, row) in &mut rows[i..end] {
                    *row = row.finish(sa, sb);
                }
                i = end;
            }
        }
    }
}

/// Rows for one coordinate `value` along a generic axis: limits or lock, motor, spring.
fn axis_rows(
    base: usize,
    ax: &Axis,
    value: Real,
    h: Real,
    make: &dyn Fn(Real, Real, RowKind, Real) -> Row,
    rows: &mut Vec<(usize, Row)>,
) {
    match ax.mode {
        AxisMode::Locked => rows.push((base, make(1.0, value, RowKind::Equality, 0.0))),
        AxisMode::Free => {}
        AxisMode::Limited { low, high } if low == high => {
            rows.push((base, make(1.0, value - low, RowKind::Equality, 0.0)))
        }
        AxisMode::Limited { low, high } => {
            rows.push((base, make(1.0, value - low, RowKind::Inequality, 0.0)));
            rows.push((base + 1, make(-1.0, high - value, RowKind::Inequality, 0.0)));
        }
    }
    if ax.mode == AxisMode::Locked {
        return;
    }
    if let Some(m) = ax.motor {
        let kind = RowKind::Motor { speed: m.speed };
        rows.push((base + 2, make(1.0, 0.0, kind, m.max_force * h)));
    } else if let Some(s) = ax.spring {
        let softness = Softness::new(s.hertz, s.damping_ratio, h);
        rows.push((
            base + 2,
            make(1.0, value - s.rest, RowKind::Spring { softness }, 0.0),
        ));
    }
}

fn linear_axes(f: &Frames, axes: &[Axis; 3], h: Real, rows: &mut Vec<(usize, Row)>) {
    for (i, ax) in axes.iter().enumerate() {
        let axis = f.axis_a(i);
        let value = f.d.dot(axis);
        let make = |sign: Real, c: Real, kind: RowKind, max: Real| {
            Row::linear(axis * sign, f.ra, f.rb, c, kind, max)
        };
        axis_rows(3 * i, ax, value, h, &make, rows);
    }
}

fn angular_axes(f: &Frames, axes: &[Axis; 3], h: Real, rows: &mut Vec<(usize, Row)>) {
    let e = rotation_vector(f.q_rel);
    for (i, ax) in axes.iter().enumerate() {
        let axis = f.axis_a(i);
        let make =
            |sign: Real, c: Real, kind: RowKind, max: Real| Row::angular(axis * sign, c, kind, max);
        axis_rows(9 + 3 * i, ax, e[i], h, &make, rows);
    }
}

/// Hinge about frame Z: two rows keep the Z axes aligned (`c = pᵢ·(z_a × z_b)` is B's
/// rotation about `pᵢ`), then limits and motor on the angle of B's X axis in A's XY plane.
fn hinge(
    f: &Frames,
    limits: Option<(Real, Real)>,
    motor: Option<super::Motor>,
    h: Real,
    rows: &mut Vec<(usize, Row)>,
) {
    let za = f.axis_a(2);
    let zb = f.rot_b * Vec3::Z;
    let err = za.cross(zb);
    for i in 0..2 {
        let p = f.axis_a(i);
        rows.push((
            9 + 3 * i,
            Row::angular(p, p.dot(err), RowKind::Equality, 0.0),
        ));
    }
    let q = f.q_rel;
    let angle = 2.0 * q.z.atan2(q.w);
    let angle = wrap_angle(angle);
    let ax = Axis {
        mode: limits.map_or(AxisMode::Free, |(low, high)| AxisMode::Limited {
            low,
            high,
        }),
        motor,
        spring: None,
    };
    let make =
        |sign: Real, c: Real, kind: RowKind, max: Real| Row::angular(za * sign, c, kind, max);
    axis_rows(15, &ax, angle, h, &make, rows);
}

fn wrap_angle(a: Real) -> Real {
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
/// `1/φ_max² = (u_y/swing2)² + (u_z/swing1)²`; the twist angle by `±twist`. Limit rows are
/// always present and act speculatively while inside the limits.
fn cone_twist(f: &Frames, swing1: Real, swing2: Real, twist: Real, rows: &mut Vec<(usize, Row)>) {
    let q = if f.q_rel.w < 0.0 { -f.q_rel } else { f.q_rel };
    let tw_len = (q.x * q.x + q.w * q.w).sqrt();
    let q_twist = if tw_len > 1e-9 {
        Quat::from_xyzw(q.x / tw_len, 0.0, 0.0, q.w / tw_len)
    } else {
        Quat::IDENTITY
    };
    let twist_angle = wrap_angle(2.0 * q_twist.x.atan2(q_twist.w));
    let swing = rotation_vector((q * q_twist.inverse()).normalize());
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
        let axis = f.rot_a * u;
        rows.push((
            9,
            Row::angular(-axis, phi_max - phi, RowKind::Inequality, 0.0),
        ));
    }
    let tw = (f.axis_a(0) + f.rot_b * Vec3::X).normalize_or_zero();
    if tw != Vec3::ZERO {
        rows.push((
            12,
            Row::angular(tw, twist_angle + twist, RowKind::Inequality, 0.0),
        ));
        rows.push((
            13,
            Row::angular(-tw, twist - twist_angle, RowKind::Inequality, 0.0),
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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

    #[test]
    fn wrap_angle_stays_in_range() {
        use carom_collision::math::consts::PI;
        assert!((wrap_angle(1.5 * PI) + 0.5 * PI).abs() < 1e-5);
        assert!((wrap_angle(-1.5 * PI) - 0.5 * PI).abs() < 1e-5);
        assert_eq!(wrap_angle(0.25), 0.25);
    }
}
