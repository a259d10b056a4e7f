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

/// The per-body constants of the velocity and position updates over substeps of `h`,
/// gathered once per step from the body set's cold data ([`crate::BodyInfo`], forces), so
/// the substeps run over one compact array of the bodies that move (awake dynamic and live
/// kinematic ones) instead of every slot. Each value is the expression the update used to
/// evaluate in every substep, evaluated once: the results are the same bits.
#[derive(Debug, Clone, Copy)]
pub(crate) struct BodyTerms {
    /// Body slot.
    slot: usize,
    /// Velocity change per substep from gravity and the applied force: `(g s + F/m) h`.
    dv: Vec3,
    /// Angular velocity change per substep from the applied torque: `I⁻¹ (τ h)`.
    dw: Vec3,
    /// Damping factors per substep, `(1 − d)^h` (applied when the damping is positive).
    damp_v: Real,
    damp_w: Real,
    /// Speed limits and their squares.
    max_v: Real,
    max_w: Real,
    max_v_sq: Real,
    max_w_sq: Real,
    /// Body-space inertia (the inverse of the local inverse inertia) for the gyroscopic term,
    /// computed when first needed (`INERTIA` set): most bodies of a falling pile do not
    /// rotate until they land.
    inertia: Mat3,
    /// `DYNAMIC`, `GYROSCOPIC`, `INERTIA`, `DAMP_V`, `DAMP_W` bits.
    flags: u8,
}

const DYNAMIC: u8 = 1;
const GYROSCOPIC: u8 = 2;
const INERTIA: u8 = 4;
const DAMP_V: u8 = 8;
const DAMP_W: u8 = 16;

/// Fills `out` with the [`BodyTerms`] of every moving body for substeps of `h` (after
/// [`load`]): [`select_terms`], then [`fill_terms`] for each. Allocates only when `out`
/// must grow.
pub(crate) fn prepare_terms(
    set: &BodySet,
    bodies: &[SolverBody],
    gravity: Vec3,
    h: Real,
    gyroscopic: bool,
    out: &mut Vec<BodyTerms>,
) {
    select_terms(set, bodies, out);
    for t in out.iter_mut() {
        fill_terms(t, set, &bodies[t.slot], gravity, h, gyroscopic);
    }
}

/// Resizes `out` to one entry per moving body (awake dynamic or live kinematic), in slot
/// order, and sets only each entry's slot; [`fill_terms`] writes the rest (the soft step
/// does that in the parallel blocks of its first velocity stage, so only this cheap pass
/// over the slots stays serial). Allocates only when `out` must grow.
pub(crate) fn select_terms(set: &BodySet, bodies: &[SolverBody], out: &mut Vec<BodyTerms>) {
    let mut n = 0;
    for (i, b) in bodies.iter().enumerate() {
        let kinematic = || set.is_alive(i) && set.info[i].body_type == BodyType::Kinematic;
        if !(b.dynamic || kinematic()) {
            continue;
        }
        if let Some(t) = out.get_mut(n) {
            t.slot = i;
        } else {
            out.push(BodyTerms::at(i));
        }
        n += 1;
    }
    out.truncate(n);
}

impl BodyTerms {
    /// Terms of slot `slot` with nothing else set yet ([`fill_terms`] sets them).
    fn at(slot: usize) -> BodyTerms {
        BodyTerms {
            slot,
            dv: Vec3::ZERO,
            dw: Vec3::ZERO,
            damp_v: 1.0,
            damp_w: 1.0,
            max_v: 0.0,
            max_w: 0.0,
            max_v_sq: 0.0,
            max_w_sq: 0.0,
            inertia: Mat3::ZERO,
            flags: 0,
        }
    }
}

/// Writes every field of `out` but its slot (set by [`select_terms`]) for substeps of `h`:
/// `b` is the solver body of that slot.
#[inline(always)] // once per body and step, from the soft step's first velocity stage
pub(crate) fn fill_terms(
    out: &mut BodyTerms,
    set: &BodySet,
    b: &SolverBody,
    gravity: Vec3,
    h: Real,
    gyroscopic: bool,
) {
    let i = out.slot;
    let info = &set.info[i];
    let mut t = BodyTerms {
        slot: i,
        dv: Vec3::ZERO,
        dw: Vec3::ZERO,
        damp_v: 1.0,
        damp_w: 1.0,
        max_v: info.max_linear_speed,
        max_w: info.max_angular_speed,
        max_v_sq: info.max_linear_speed * info.max_linear_speed,
        max_w_sq: info.max_angular_speed * info.max_angular_speed,
        inertia: Mat3::ZERO,
        flags: 0,
    };
    if b.dynamic {
        t.flags |= DYNAMIC;
        t.dv = (gravity * info.gravity_scale + set.force[i] * b.inv_m) * h;
        t.dw = b.inv_i * (set.torque[i] * h);
        if gyroscopic && !is_isotropic(&info.inv_inertia_local) {
            t.flags |= GYROSCOPIC;
            // Until `INERTIA` is set: the local inverse inertia.
            t.inertia = info.inv_inertia_local;
        }
        if info.linear_damping > 0.0 {
            t.flags |= DAMP_V;
            t.damp_v = (1.0 - info.linear_damping).clamp(0.0, 1.0).powf(h);
        }
        if info.angular_damping > 0.0 {
            t.flags |= DAMP_W;
            t.damp_w = (1.0 - info.angular_damping).clamp(0.0, 1.0).powf(h);
        }
    }
    *out = t;
}

/// Whether a local inverse inertia is a multiple of the identity (cubes, spheres, regular
/// solids). The gyroscopic torque `ω × I ω` of such a body is zero for every `ω`, and the
/// implicit step [`gyroscopic_implicit`] (whose residual `h ω × I ω` is then zero in exact
/// arithmetic) returns `ω` unchanged, so [`prepare_terms`] skips it: its ~300 instructions
/// per body and substep only added round-off ("1000 stack": 7 % of the solver's
/// instructions). Exact comparisons: a nearly isotropic body keeps the term.
fn is_isotropic(m: &Mat3) -> bool {
    let d = m.x_axis.x;
    m.y_axis.y == d
        && m.z_axis.z == d
        && m.x_axis.y == 0.0
        && m.x_axis.z == 0.0
        && m.y_axis.x == 0.0
        && m.y_axis.z == 0.0
        && m.z_axis.x == 0.0
        && m.z_axis.y == 0.0
}

/// Velocity update over `h` for awake dynamic bodies: gravity and forces, torques, the
/// implicit gyroscopic term, damping (`terms` from [`prepare_terms`] with the same `h`).
pub(crate) fn integrate_velocities(
    terms: &mut [BodyTerms],
    rotation: &[Quat],
    bodies: &mut [SolverBody],
    h: Real,
) {
    for t in terms {
        if t.flags & DYNAMIC == 0 {
            continue;
        }
        integrate_velocity(t, rotation[t.slot], &mut bodies[t.slot], h);
    }
}

/// [`integrate_velocities`] of one body: `b` is the body of `t` (slot [`BodyTerms::slot`]),
/// `q` its rotation; does nothing unless the body is dynamic.
#[inline(always)] // per body and substep: the call cost a fifth of its instructions
pub(crate) fn integrate_velocity(t: &mut BodyTerms, q: Quat, b: &mut SolverBody, h: Real) {
    if t.flags & DYNAMIC == 0 {
        return;
    }
    b.v += t.dv;
    b.w += t.dw;
    if t.flags & GYROSCOPIC != 0 && b.w != Vec3::ZERO && t.has_inertia() {
        b.w = gyroscopic_implicit(q, t.inertia, b.w, h);
    }
    if t.flags & DAMP_V != 0 {
        b.v *= t.damp_v;
    }
    if t.flags & DAMP_W != 0 {
        b.w *= t.damp_w;
    }
}

impl BodyTerms {
    /// The body's slot.
    #[inline]
    pub(crate) fn slot(&self) -> usize {
        self.slot
    }

    /// Makes `inertia` the body-space inertia on first use; false (and no gyroscopic term
    /// from then on) when the local inverse inertia is singular or invalid.
    #[inline]
    fn has_inertia(&mut self) -> bool {
        if self.flags & INERTIA == 0 {
            let det = self.inertia.determinant();
            if det.is_nan() || det <= 0.0 {
                self.flags &= !GYROSCOPIC;
                return false;
            }
            self.inertia = self.inertia.inverse();
            self.flags |= INERTIA;
        }
        true
    }
}

/// One Newton step of the implicit gyroscopic equation `I (ω' − ω) + h ω' × I ω' = 0` in
/// body space (Bullet's `btRigidBody::computeGyroscopicImpulseImplicit_Body`), with `inertia`
/// the body-space inertia. Keeps free rotation of asymmetric bodies stable where the
/// explicit term would gain energy. Out of line: [`integrate_velocity`] is inlined into the
/// substep loops, which rarely take this branch.
#[inline(never)]
fn gyroscopic_implicit(q: Quat, inertia: Mat3, w: Vec3, h: Real) -> Vec3 {
    let wb = q.inverse() * w;
    let iwb = inertia * wb;
    let f = wb.cross(iwb) * h;
    let jac = inertia + (skew_mul(wb, inertia) - skew(iwb)) * h;
    let det = jac.determinant().abs();
    if det.is_nan() || det <= Real::EPSILON {
        return w;
    }
    let wb_new = wb - jac.inverse() * f;
    q * wb_new
}

/// `skew(w) * m` as three cross products `w × mᵢ` of `m`'s columns: 18 operations instead
/// of the 45 of a matrix product with the skew matrix's zeros. The same values bit for bit:
/// each component of the product is `(0·a + (−w_k)·b) + w_j·c`, the cross product's
/// `w_j·c − b·w_k` (the zero term adds exactly, subtraction is adding the negation); only
/// the sign of an exactly zero component may differ.
#[inline]
fn skew_mul(w: Vec3, m: Mat3) -> Mat3 {
    Mat3::from_cols(w.cross(m.x_axis), w.cross(m.y_axis), w.cross(m.z_axis))
}

/// `v` (of squared length `v2 > max²`) shortened to length `max`. When `v2` overflows
/// (speeds beyond ~1.8e19 in f32, from a huge impulse, force or gravity scale) the vector is
/// first divided by its largest component, and infinite components give the direction, so
/// the clamp keeps the direction instead of zeroing the speed or making NaN.
#[inline]
pub(crate) fn clamp_length(v: Vec3, v2: Real, max: Real) -> Vec3 {
    if v2.is_finite() {
        return v * (max / v2.sqrt());
    }
    clamp_length_overflowing(v, max)
}

#[cold]
#[inline(never)]
fn clamp_length_overflowing(v: Vec3, max: Real) -> Vec3 {
    let m = v.abs().max_element();
    let dir = if m.is_finite() {
        v / m
    } else {
        // Infinite components (NaN ones count for nothing).
        Vec3::select(
            v.abs().cmpeq(Vec3::splat(Real::INFINITY)),
            v.signum(),
            Vec3::ZERO,
        )
    };
    dir.normalize_or_zero() * max
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
            b.v = clamp_length(b.v, v2, info.max_linear_speed);
        }
        let w2 = b.w.length_squared();
        if w2 > info.max_angular_speed * info.max_angular_speed {
            b.w = clamp_length(b.w, w2, info.max_angular_speed);
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

/// The soft step's position update over `h` for the moving bodies of `terms`: first the
/// speed clamp of [`clamp_speeds`] (dynamic bodies), then the pose update of
/// [`integrate_positions`] with the deltas tracked in `dp`/`dq` — both in one pass over the
/// moving bodies, in the same order per body as the two separate passes, so the same bits.
#[cfg(test)]
pub(crate) fn clamp_and_integrate_positions(
    terms: &[BodyTerms],
    set: &mut BodySet,
    bodies: &mut [SolverBody],
    h: Real,
) {
    for t in terms {
        let i = t.slot;
        let (p, q) = (&mut set.position[i], &mut set.rotation[i]);
        clamp_and_integrate_position(t, p, q, &mut bodies[i], h);
    }
}

/// [`clamp_and_integrate_positions`] of one body: `b` is the body of `t` (slot
/// [`BodyTerms::slot`]), `p` and `q` its position and rotation.
#[inline]
pub(crate) fn clamp_and_integrate_position(
    t: &BodyTerms,
    p: &mut Vec3,
    q: &mut Quat,
    b: &mut SolverBody,
    h: Real,
) {
    if t.flags & DYNAMIC != 0 {
        let v2 = b.v.length_squared();
        if v2 > t.max_v_sq {
            b.v = clamp_length(b.v, v2, t.max_v);
        }
        let w2 = b.w.length_squared();
        if w2 > t.max_w_sq {
            b.w = clamp_length(b.w, w2, t.max_w);
        }
    }
    let (v, w) = (b.v, b.w);
    *p += v * h;
    *q = integrate_rotation(*q, w, h);
    b.dp += v * h;
    b.dq += w * h;
}

/// Copies velocities back, refreshes world inertias and clears forces.
pub(crate) fn store(set: &mut BodySet, bodies: &[SolverBody]) {
    for (i, b) in bodies.iter().enumerate() {
        if b.dynamic {
            set.linear_velocity[i] = b.v;
            set.angular_velocity[i] = b.w;
            set.update_world_inertia(i);
        }
    }
    clear_forces(set, bodies.len());
}

/// Zeroes the force and torque accumulators of slots `..n` (the end of a step; the soft step
/// stores the velocities and world inertias in its parallel stages and then calls this).
/// When all of them are known to be zero already ([`BodySet::forces_zero`]), nothing is
/// written (an idle world's step: 1,077 bodies' 26 kB zeroed again each step before).
pub(crate) fn clear_forces(set: &mut BodySet, n: usize) {
    if set.forces_zero {
        return;
    }
    let n = n.min(set.force.len()).min(set.torque.len());
    set.force[..n].fill(Vec3::ZERO);
    set.torque[..n].fill(Vec3::ZERO);
    set.forces_zero = n == set.force.len() && n == set.torque.len();
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::BodyDesc;
    use carom_collision::math::Isometry;
    use carom_collision::shape::{Cuboid, Shape};
    use std::sync::Arc;

    fn cube() -> Arc<Shape> {
        Arc::new(Cuboid::new(Vec3::splat(0.5)).unwrap().into())
    }

    /// Terms and the substep updates against the closed forms: gravity and damping
    /// (`v(t) = (v₀ + …)`, `(1 − d)^t`), kinematic bodies moving at their velocity, static
    /// bodies not listed, the speed clamp, and a body with an infinite inertia (zero inverse)
    /// rotating without a gyroscopic term.
    #[test]
    fn substeps_follow_the_closed_forms() {
        let mut set = BodySet::new();
        let mut damped = BodyDesc::dynamic(cube(), Isometry::IDENTITY, 1000.0);
        damped.linear_damping = 0.3;
        damped.angular_damping = 0.6;
        damped.gravity_scale = 0.0;
        damped.linear_velocity = Vec3::new(2.0, 0.0, 0.0);
        damped.angular_velocity = Vec3::new(0.0, 0.0, 1.0);
        let damped = set.insert(&damped).unwrap();
        let mut fixed_rotation = BodyDesc::dynamic(cube(), Isometry::IDENTITY, 1000.0);
        fixed_rotation.angular_velocity = Vec3::new(0.0, 3.0, 0.0);
        fixed_rotation.max_linear_speed = 1.0;
        let fixed_rotation = set.insert(&fixed_rotation).unwrap();
        // An infinite inertia: a zero inverse, singular, so no gyroscopic term.
        let slot = fixed_rotation.index as usize;
        set.info[slot].inv_inertia_local = Mat3::ZERO;
        set.inv_inertia_world[slot] = Mat3::ZERO;
        let mut kinematic = BodyDesc::fixed(cube(), Isometry::IDENTITY);
        kinematic.body_type = BodyType::Kinematic;
        kinematic.linear_velocity = Vec3::new(0.0, 0.0, -1.5);
        let kinematic = set.insert(&kinematic).unwrap();
        set.insert(&BodyDesc::fixed(cube(), Isometry::IDENTITY))
            .unwrap();
        // Free rotation about a non-principal axis: a 1 × 2 × 3 box precesses (the
        // gyroscopic term, with the inertia inverted on first use), keeping the magnitude of
        // its angular momentum.
        let spin = Vec3::new(1.0, 2.0, 3.0);
        let brick: Arc<Shape> = Arc::new(Cuboid::new(Vec3::new(0.5, 1.0, 1.5)).unwrap().into());
        let mut spinning_brick = BodyDesc::dynamic(brick, Isometry::IDENTITY, 1000.0);
        spinning_brick.angular_velocity = spin;
        let spinning_brick = set.insert(&spinning_brick).unwrap();

        let mut bodies = Vec::new();
        load(&set, &mut bodies);
        let (g, h, n) = (Vec3::new(0.0, -10.0, 0.0), 0.01, 50);
        let mut terms = Vec::new();
        prepare_terms(&set, &bodies, g, h, true, &mut terms);
        assert_eq!(terms.len(), 4, "static bodies are not integrated");
        let brick = spinning_brick.index as usize;
        let momentum = |set: &BodySet, w: Vec3| {
            let r = Mat3::from_quat(set.rotation[brick]);
            let inertia_world = r * set.info[brick].inv_inertia_local.inverse() * r.transpose();
            inertia_world * w
        };
        let l0 = momentum(&set, spin);
        for _ in 0..n {
            integrate_velocities(&mut terms, &set.rotation, &mut bodies, h);
            clamp_and_integrate_positions(&terms, &mut set, &mut bodies, h);
        }
        let t = h * n as Real;
        let (d, f) = (damped.index as usize, fixed_rotation.index as usize);
        let k = kinematic.index as usize;
        let close =
            |x: Real, y: Real| assert!((x - y).abs() < 1e-4 * (1.0 + y.abs()), "{x} vs {y}");
        close(bodies[d].v.x, 2.0 * (0.7 as Real).powf(t));
        close(bodies[d].w.z, (0.4 as Real).powf(t));
        // Free fall, clamped at 1 m/s; the infinite inertia spins on unchanged.
        close(bodies[f].v.length(), 1.0);
        assert_eq!(bodies[f].w, Vec3::new(0.0, 3.0, 0.0));
        close(set.position[k].z, -1.5 * t);
        let w_brick = bodies[brick].w;
        assert!(
            (w_brick - spin).length() > 0.05,
            "the brick precesses: {w_brick}"
        );
        let l1 = momentum(&set, w_brick);
        // Bullet's one-step implicit scheme keeps |L| (the direction drifts by O(h)).
        assert!(
            (l1.length() - l0.length()).abs() < 1e-2 * l0.length(),
            "{l1} vs {l0}"
        );
        close(bodies[k].dp.z, -1.5 * t);
    }

    /// The isotropic skip against the slow path: for inverse inertias that are multiples of
    /// the identity (tiny to huge, and zero), the full implicit step returns `ω` to
    /// round-off for every rotation and `ω` (random, axis-aligned, zero, fast spins up to
    /// 4 rad per step; `h` of 1/240 to 1 s), so skipping it changes nothing but round-off; and bodies that are not
    /// isotropic (a brick, a cube with a rounding-size off-diagonal, a slightly unequal
    /// diagonal) keep the term.
    #[test]
    fn isotropic_bodies_skip_an_identity_gyroscopic_step() {
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as Real / (1u64 << 53) as Real * 2.0 - 1.0
        };
        for scale in [0.0, 1e-6, 1.0 / 6.0, 1.0, 1e6] {
            let inv = Mat3::from_diagonal(Vec3::splat(scale));
            assert!(is_isotropic(&inv));
            if scale == 0.0 {
                continue; // no inertia to invert: `has_inertia` refuses it as well
            }
            let inertia = inv.inverse();
            for k in 0..200 {
                let q = Quat::from_xyzw(next(), next(), next(), next()).normalize();
                let w = match k {
                    0 => Vec3::ZERO,
                    1 => Vec3::X * 50.0,
                    2 => Vec3::new(0.0, -1e-7, 0.0),
                    _ => Vec3::new(next(), next(), next()) * (10.0 as Real).powi(k % 5 - 1),
                };
                for h in [1.0 / 240.0, 1.0 / 60.0, 1.0] {
                    if h * w.length() > 4.0 {
                        continue; // beyond any speed limit: the slow path's own round-off
                    }
                    let full = gyroscopic_implicit(q, inertia, w, h);
                    let tol = 1e-5 * w.length() + Real::MIN_POSITIVE;
                    assert!((full - w).length() <= tol, "{full} vs {w}");
                }
            }
        }
        let brick = Mat3::from_diagonal(Vec3::new(1.0, 2.0, 3.0));
        let mut skewed = Mat3::IDENTITY;
        skewed.x_axis.y = 1e-7;
        let unequal = Mat3::from_diagonal(Vec3::new(1.0, 1.0, 1.0 + 1e-6));
        for m in [brick, skewed, unequal] {
            assert!(!is_isotropic(&m), "{m}");
        }
        // `prepare_terms` sets the gyroscopic flag for the brick only.
        let mut set = BodySet::new();
        set.insert(&BodyDesc::dynamic(cube(), Isometry::IDENTITY, 1000.0))
            .unwrap();
        let brick: Arc<Shape> = Arc::new(Cuboid::new(Vec3::new(0.5, 1.0, 1.5)).unwrap().into());
        set.insert(&BodyDesc::dynamic(brick, Isometry::IDENTITY, 1000.0))
            .unwrap();
        let mut bodies = Vec::new();
        load(&set, &mut bodies);
        let mut terms = Vec::new();
        prepare_terms(&set, &bodies, Vec3::ZERO, 0.01, true, &mut terms);
        let flags: Vec<bool> = terms.iter().map(|t| t.flags & GYROSCOPIC != 0).collect();
        assert_eq!(flags, [false, true]);
    }

    #[test]
    fn skew_mul_is_the_skew_matrix_product_bit_for_bit() {
        // The oracle is the matrix product it replaces; random, huge, tiny and far-apart
        // magnitudes, zero components and zero columns (signs of zero aside, compared by
        // value: `0.0 == -0.0`).
        let mut s = 0x2545_F491_4F6C_DD1D_u64;
        let mut next = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) as Real * 2.0 - 1.0
        };
        let mut vecs = vec![Vec3::ZERO, Vec3::X, Vec3::new(0.0, 1.0e-30, -3.0e20)];
        for k in 0..200 {
            let scale = [1.0, 1.0e-6, 1.0e6, 1.0e15][k % 4];
            let mut v = Vec3::new(next(), next(), next()) * scale;
            if k % 5 == 0 {
                v[k % 3] = 0.0;
            }
            vecs.push(v);
        }
        for (i, &w) in vecs.iter().enumerate() {
            let m = Mat3::from_cols(vecs[(i + 1) % vecs.len()], vecs[(i + 7) % vecs.len()], {
                let c = vecs[(i + 13) % vecs.len()];
                if i % 3 == 0 {
                    Vec3::ZERO
                } else {
                    c
                }
            });
            let (fast, full) = (skew_mul(w, m), skew(w) * m);
            assert_eq!(fast.to_cols_array(), full.to_cols_array(), "{w:?} {m:?}");
        }
    }
}
