//! Time integration: semi-implicit (symplectic) Euler.
//!
//! Velocities first (gravity, forces, damping, and the gyroscopic term solved implicitly in
//! body space with one Newton step, Bullet's `computeGyroscopicImpulseImplicit_Body`), then
//! positions from the new velocities; the rotation is updated by `q += ½ h ω q` and
//! renormalised (Box2D/Bullet). Speeds are clamped to each body's limits.

use crate::body::BodyType;
use crate::body_set::BodySet;
use crate::solver::SolverBody;
use carom_collision::math::{skew, Mat3, Quat, Real, Vec3};

/// Copies the awake part of the body set into solver bodies.
pub(crate) fn load(set: &BodySet, out: &mut Vec<SolverBody>) {
    out.clear();
    out.extend((0..set.capacity()).map(|i| {
        let dynamic = set.is_awake_dynamic(i);
        let moving = set.is_alive(i) && set.info[i].body_type == BodyType::Kinematic;
        SolverBody {
            v: if dynamic || moving {
                set.linear_velocity[i]
            } else {
                Vec3::ZERO
            },
            w: if dynamic || moving {
                set.angular_velocity[i]
            } else {
                Vec3::ZERO
            },
            dp: Vec3::ZERO,
            dq: Vec3::ZERO,
            inv_m: if dynamic { set.inv_mass[i] } else { 0.0 },
            inv_i: if dynamic {
                set.inv_inertia_world[i]
            } else {
                Mat3::ZERO
            },
            dynamic,
        }
    }));
}

/// Velocity update over `h` for awake dynamic bodies.
pub(crate) fn integrate_velocities(
    set: &BodySet,
    bodies: &mut [SolverBody],
    gravity: Vec3,
    h: Real,
    gyroscopic: bool,
) {
    for (i, b) in bodies.iter_mut().enumerate() {
        if !b.dynamic {
            continue;
        }
        let info = &set.info[i];
        b.v += (gravity * info.gravity_scale + set.force[i] * b.inv_m) * h;
        b.w += b.inv_i * (set.torque[i] * h);
        if gyroscopic && b.w != Vec3::ZERO {
            b.w = gyroscopic_implicit(set.rotation[i], info.inv_inertia_local, b.w, h);
        }
        if info.linear_damping > 0.0 {
            b.v *= (1.0 - info.linear_damping).clamp(0.0, 1.0).powf(h);
        }
        if info.angular_damping > 0.0 {
            b.w *= (1.0 - info.angular_damping).clamp(0.0, 1.0).powf(h);
        }
    }
}

/// One Newton step of the implicit gyroscopic equation `I (ω' − ω) + h ω' × I ω' = 0` in
/// body space (Bullet's `btRigidBody::computeGyroscopicImpulseImplicit_Body`). Keeps free
/// rotation of asymmetric bodies stable where the explicit term would gain energy.
fn gyroscopic_implicit(q: Quat, inv_inertia_local: Mat3, w: Vec3, h: Real) -> Vec3 {
    let det = inv_inertia_local.determinant();
    if det.is_nan() || det <= 0.0 {
        return w;
    }
    let inertia = inv_inertia_local.inverse();
    let wb = q.inverse() * w;
    let iwb = inertia * wb;
    let f = wb.cross(iwb) * h;
    let jac = inertia + (skew(wb) * inertia - skew(iwb)) * h;
    if jac.determinant().abs().is_nan() || jac.determinant().abs() <= Real::EPSILON {
        return w;
    }
    let wb_new = wb - jac.inverse() * f;
    q * wb_new
}

/// Clamps a body's speeds to its limits.
pub(crate) fn clamp_speeds(set: &BodySet, bodies: &mut [SolverBody]) {
    for (i, b) in bodies.iter_mut().enumerate() {
        if !b.dynamic {
            continue;
        }
        let info = &set.info[i];
        let v2 = b.v.length_squared();
        if v2 > info.max_linear_speed * info.max_linear_speed {
            b.v *= info.max_linear_speed / v2.sqrt();
        }
        let w2 = b.w.length_squared();
        if w2 > info.max_angular_speed * info.max_angular_speed {
            b.w *= info.max_angular_speed / w2.sqrt();
        }
    }
}

/// Rotation `q` advanced by angular velocity `w` over `h`, renormalised.
#[inline]
pub(crate) fn integrate_rotation(q: Quat, w: Vec3, h: Real) -> Quat {
    let dq = Quat::from_xyzw(w.x, w.y, w.z, 0.0) * q;
    let q2 = Quat::from_xyzw(
        q.x + 0.5 * h * dq.x,
        q.y + 0.5 * h * dq.y,
        q.z + 0.5 * h * dq.z,
        q.w + 0.5 * h * dq.w,
    );
    q2.normalize()
}

/// Position update over `h` for awake dynamic and kinematic bodies with velocities `v + extra_v`
/// (the split-impulse pseudo-velocities for sequential impulses, zero for the soft step).
/// Accumulates the deltas in `dp`/`dq` when `track`.
pub(crate) fn integrate_positions(
    set: &mut BodySet,
    bodies: &mut [SolverBody],
    h: Real,
    push: bool,
) {
    for (i, b) in bodies.iter_mut().enumerate() {
        let kinematic = set.is_alive(i) && set.info[i].body_type == BodyType::Kinematic;
        if !(b.dynamic || kinematic) {
            continue;
        }
        let (v, w) = if push {
            (b.v + b.dp, b.w + b.dq)
        } else {
            (b.v, b.w)
        };
        set.position[i] += v * h;
        set.rotation[i] = integrate_rotation(set.rotation[i], w, h);
        if !push {
            b.dp += v * h;
            b.dq += w * h;
        }
    }
}

/// Copies velocities back, refreshes world inertias and clears forces.
pub(crate) fn store(set: &mut BodySet, bodies: &[SolverBody]) {
    for (i, b) in bodies.iter().enumerate() {
        if b.dynamic {
            set.linear_velocity[i] = b.v;
            set.angular_velocity[i] = b.w;
            set.update_world_inertia(i);
        }
        set.force[i] = Vec3::ZERO;
        set.torque[i] = Vec3::ZERO;
    }
}
