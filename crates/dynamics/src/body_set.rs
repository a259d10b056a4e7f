//! Live bodies: generational handles and hot data in flat arrays.
//!
//! The layout follows Box2D v3 (`body.h`, `solver_set.h`) and the architecture note: the data
//! the solver touches every step (centre-of-mass positions, rotations, velocities, inverse
//! masses, world inverse inertias) lives in one flat array per quantity, indexed by the body
//! slot; cold data (damping, user data, …) lives in [`BodyInfo`]. Handles are
//! `(index, generation)` pairs (Box2D's `b2BodyId`): removing a body bumps the slot's
//! generation, so a stale handle is an error, never another body.

use crate::body::{BodyDesc, BodyType};
use carom_collision::math::{check_finite_vec, Isometry, Mat3, Mat3A, Quat, Real, Vec3};
use carom_collision::shape::Shape;
use carom_collision::{CaromError, Result};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// A stable reference to a body: slot index plus the generation of that slot.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct BodyHandle {
    /// Slot index in the body arrays.
    pub index: u32,
    /// Generation of the slot when the body was created.
    pub generation: u32,
}

/// Cold per-body data.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct BodyInfo {
    /// Dynamic, kinematic or static.
    pub body_type: BodyType,
    /// Collision shape, if any (snapshots store shapes once, beside the set).
    #[serde(skip)]
    pub shape: Option<Arc<Shape>>,
    /// Mass (0 for non-dynamic bodies).
    pub mass: Real,
    /// Centre of mass in the body frame.
    pub local_com: Vec3,
    /// Inverse inertia about the centre of mass in body axes.
    pub inv_inertia_local: Mat3,
    /// Friction coefficient.
    pub friction: Real,
    /// Restitution coefficient.
    pub restitution: Real,
    /// Linear damping per second.
    pub linear_damping: Real,
    /// Angular damping per second.
    pub angular_damping: Real,
    /// Gravity multiplier.
    pub gravity_scale: Real,
    /// Whether the body may sleep.
    pub can_sleep: bool,
    /// Largest linear speed.
    pub max_linear_speed: Real,
    /// Largest angular speed.
    pub max_angular_speed: Real,
    /// User value.
    pub user_data: u64,
    /// True while the body sleeps.
    pub sleeping: bool,
    /// Time the body has rested (see [`crate::island::SleepParams`]), s.
    pub sleep_time: Real,
    /// Centre-of-mass position where the body's current rest began: the drift rule of
    /// [`crate::island::SleepParams::drift`] measures from it.
    #[serde(default)]
    pub rest_position: Vec3,
    /// Rotation where the body's current rest began (see `rest_position`).
    #[serde(default)]
    pub rest_rotation: Quat,
    /// Radius about the centre of mass of a ball holding the shape (0 without a shape):
    /// how far a rotation can move a point of the body. Derived from the shape, so not part
    /// of a snapshot.
    #[serde(skip)]
    pub reach: Real,
}

/// The radius about `com` (body frame) of a ball holding `shape`: the farthest corner of its
/// local bounding box; 0 without a shape or when that is not finite, which
/// leaves the body to the velocity rule of sleeping.
pub(crate) fn reach(shape: Option<&Shape>, com: Vec3) -> Real {
    let r = shape.map_or(0.0, |s| {
        let b = s.local_aabb();
        (b.min - com).abs().max((b.max - com).abs()).length()
    });
    if r.is_finite() {
        r
    } else {
        0.0
    }
}

/// All bodies of a world. Hot data is public read-only through accessors; the arrays are
/// indexed by [`BodyHandle::index`] and contain dead slots (zero inverse mass).
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct BodySet {
    generation: Vec<u32>,
    alive: Vec<bool>,
    free: Vec<u32>,
    pub(crate) position: Vec<Vec3>,
    pub(crate) rotation: Vec<Quat>,
    pub(crate) linear_velocity: Vec<Vec3>,
    pub(crate) angular_velocity: Vec<Vec3>,
    pub(crate) inv_mass: Vec<Real>,
    pub(crate) inv_inertia_world: Vec<Mat3>,
    pub(crate) force: Vec<Vec3>,
    pub(crate) torque: Vec<Vec3>,
    pub(crate) info: Vec<BodyInfo>,
    /// Slots woken by user calls since the last step (reported by the next step).
    pub(crate) woken_by_user: Vec<usize>,
    /// True when every force and torque accumulator is known to be zero (set by
    /// [`crate::integrate::clear_forces`] over all slots, cleared by every call that adds a
    /// force or torque): a step in which nothing moves then skips zeroing them again.
    /// False (unknown) in a new or restored set; not part of a snapshot.
    #[serde(skip)]
    pub(crate) forces_zero: bool,
    /// True when no body is known to sleep: set by a pass of [`crate::island::needed`]
    /// that found none, cleared when the islands put a body to sleep (the only writer of a
    /// `true` sleep flag). False (unknown) in a new or restored set; not part of a snapshot.
    #[serde(skip)]
    pub(crate) none_asleep: bool,
    /// The largest rest timer of an awake dynamic body after the last
    /// [`crate::island::update_sleep`] with sleeping enabled, `None` (unknown) before it and
    /// in a restored set: timers only go down between steps, so it bounds them all.
    #[serde(skip)]
    pub(crate) max_rest: Option<Real>,
}

impl BodySet {
    /// An empty set.
    pub fn new() -> Self {
        Self::default()
    }

    /// Validates `desc` and adds the body.
    pub fn insert(&mut self, desc: &BodyDesc) -> Result<BodyHandle> {
        let (pose, m) = desc.validate()?;
        let com = pose.transform_point(m.local_com);
        let info = BodyInfo {
            body_type: desc.body_type,
            shape: desc.shape.clone(),
            mass: m.mass,
            local_com: m.local_com,
            inv_inertia_local: m.inv_inertia_local,
            friction: desc.friction,
            restitution: desc.restitution,
            linear_damping: desc.linear_damping,
            angular_damping: desc.angular_damping,
            gravity_scale: desc.gravity_scale,
            can_sleep: desc.can_sleep,
            max_linear_speed: desc.max_linear_speed,
            max_angular_speed: desc.max_angular_speed,
            user_data: desc.user_data,
            sleeping: false,
            sleep_time: 0.0,
            rest_position: com,
            rest_rotation: pose.rotation,
            reach: reach(desc.shape.as_deref(), m.local_com),
        };
        let index = match self.free.pop() {
            Some(i) => i as usize,
            None => {
                self.generation.push(0);
                self.alive.push(false);
                self.position.push(Vec3::ZERO);
                self.rotation.push(Quat::IDENTITY);
                self.linear_velocity.push(Vec3::ZERO);
                self.angular_velocity.push(Vec3::ZERO);
                self.inv_mass.push(0.0);
                self.inv_inertia_world.push(Mat3::ZERO);
                self.force.push(Vec3::ZERO);
                self.torque.push(Vec3::ZERO);
                self.info.push(info.clone());
                self.generation.len() - 1
            }
        };
        self.alive[index] = true;
        self.position[index] = com;
        self.rotation[index] = pose.rotation;
        self.linear_velocity[index] = desc.linear_velocity;
        self.angular_velocity[index] = desc.angular_velocity;
        self.inv_mass[index] = m.inv_mass;
        self.force[index] = Vec3::ZERO;
        self.torque[index] = Vec3::ZERO;
        self.info[index] = info;
        self.update_world_inertia(index);
        Ok(BodyHandle {
            index: index as u32,
            generation: self.generation[index],
        })
    }

    /// Removes a body; its handle (and every copy of it) becomes stale.
    pub fn remove(&mut self, h: BodyHandle) -> Result<()> {
        let i = self.slot(h)?;
        self.alive[i] = false;
        self.generation[i] = self.generation[i].wrapping_add(1);
        self.inv_mass[i] = 0.0;
        self.inv_inertia_world[i] = Mat3::ZERO;
        self.linear_velocity[i] = Vec3::ZERO;
        self.angular_velocity[i] = Vec3::ZERO;
        self.info[i].body_type = BodyType::Static;
        self.info[i].shape = None;
        self.free.push(i as u32);
        Ok(())
    }

    /// Checks the consistency of a decoded set (a snapshot): equal array lengths, free slots
    /// in range, unique and dead, woken slots in range, finite states.
    pub(crate) fn check_structure(&self) -> Result<()> {
        let n = self.generation.len();
        let lens = [
            self.alive.len(),
            self.position.len(),
            self.rotation.len(),
            self.linear_velocity.len(),
            self.angular_velocity.len(),
            self.inv_mass.len(),
            self.inv_inertia_world.len(),
            self.force.len(),
            self.torque.len(),
            self.info.len(),
        ];
        let bad = |what: &str, v: String| Err(CaromError::invalid("snapshot.bodies", v, what));
        if lens.iter().any(|&l| l != n) {
            return bad("arrays of different lengths", format!("{n} vs {lens:?}"));
        }
        let mut seen = vec![false; n];
        for &f in &self.free {
            let f = f as usize;
            if f >= n || self.alive[f] || seen[f] {
                return bad("bad free slot", f.to_string());
            }
            seen[f] = true;
        }
        if self.free.len() + self.alive.iter().filter(|&&a| a).count() != n {
            return bad("free list does not cover the dead slots", n.to_string());
        }
        if let Some(&w) = self.woken_by_user.iter().find(|&&w| w >= n) {
            return bad("woken slot out of range", w.to_string());
        }
        for i in 0..n {
            let finite = self.position[i].is_finite()
                && self.rotation[i].is_finite()
                && self.linear_velocity[i].is_finite()
                && self.angular_velocity[i].is_finite()
                && self.force[i].is_finite()
                && self.torque[i].is_finite()
                && self.inv_mass[i].is_finite()
                && self.inv_inertia_world[i].is_finite();
            if !finite {
                return bad("non-finite body state", format!("slot {i}"));
            }
        }
        Ok(())
    }

    /// The slot of a live handle, or [`CaromError::UnknownHandle`].
    pub fn slot(&self, h: BodyHandle) -> Result<usize> {
        let i = h.index as usize;
        if i < self.alive.len() && self.alive[i] && self.generation[i] == h.generation {
            Ok(i)
        } else {
            Err(CaromError::UnknownHandle(format!("{h:?}")))
        }
    }

    /// True if `h` names a live body.
    pub fn contains(&self, h: BodyHandle) -> bool {
        self.slot(h).is_ok()
    }

    /// Number of slots (live or dead): the length of every hot array.
    pub fn capacity(&self) -> usize {
        self.alive.len()
    }

    /// Number of live bodies.
    pub fn len(&self) -> usize {
        self.alive.len() - self.free.len()
    }

    /// True if there is no live body.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Handles of the live bodies, in slot order.
    pub fn handles(&self) -> impl Iterator<Item = BodyHandle> + '_ {
        (0..self.alive.len())
            .filter(|&i| self.alive[i])
            .map(|i| self.handle_of(i))
    }

    pub(crate) fn handle_of(&self, i: usize) -> BodyHandle {
        BodyHandle {
            index: i as u32,
            generation: self.generation[i],
        }
    }

    /// True when `i` is in range and names a live slot.
    pub(crate) fn is_alive_checked(&self, i: usize) -> bool {
        i < self.alive.len() && self.alive[i]
    }

    pub(crate) fn is_alive(&self, i: usize) -> bool {
        self.alive[i]
    }

    /// True for a live, dynamic, awake body slot.
    pub(crate) fn is_awake_dynamic(&self, i: usize) -> bool {
        self.alive[i] && self.info[i].body_type == BodyType::Dynamic && !self.info[i].sleeping
    }

    /// Recomputes the world inverse inertia `R I⁻¹ Rᵀ` of slot `i` from its rotation.
    pub(crate) fn update_world_inertia(&mut self, i: usize) {
        self.inv_inertia_world[i] =
            world_inertia(self.rotation[i], &self.info[i].inv_inertia_local);
    }

    /// Cold data of a body.
    pub fn info(&self, h: BodyHandle) -> Result<&BodyInfo> {
        Ok(&self.info[self.slot(h)?])
    }

    /// Pose of the body frame (the shape's frame).
    pub fn pose(&self, h: BodyHandle) -> Result<Isometry> {
        Ok(self.pose_of(self.slot(h)?))
    }

    pub(crate) fn pose_of(&self, i: usize) -> Isometry {
        let q = self.rotation[i];
        Isometry::new(self.position[i] - q * self.info[i].local_com, q)
    }

    /// World position of the centre of mass.
    pub fn center_of_mass(&self, h: BodyHandle) -> Result<Vec3> {
        Ok(self.position[self.slot(h)?])
    }

    /// Linear velocity of the centre of mass.
    pub fn linear_velocity(&self, h: BodyHandle) -> Result<Vec3> {
        Ok(self.linear_velocity[self.slot(h)?])
    }

    /// Angular velocity (world axes).
    pub fn angular_velocity(&self, h: BodyHandle) -> Result<Vec3> {
        Ok(self.angular_velocity[self.slot(h)?])
    }

    /// Inverse mass (0 for static and kinematic bodies).
    pub fn inv_mass(&self, h: BodyHandle) -> Result<Real> {
        Ok(self.inv_mass[self.slot(h)?])
    }

    /// World inverse inertia tensor.
    pub fn inv_inertia_world(&self, h: BodyHandle) -> Result<Mat3> {
        Ok(self.inv_inertia_world[self.slot(h)?])
    }

    /// True while the body sleeps.
    pub fn is_sleeping(&self, h: BodyHandle) -> Result<bool> {
        Ok(self.info[self.slot(h)?].sleeping)
    }

    /// Sets the pose of the body frame (teleport); wakes the body.
    pub fn set_pose(&mut self, h: BodyHandle, pose: Isometry) -> Result<()> {
        let i = self.slot(h)?;
        let pose = carom_collision::math::check_isometry("pose", pose)?;
        self.position[i] = pose.transform_point(self.info[i].local_com);
        self.rotation[i] = pose.rotation;
        self.update_world_inertia(i);
        self.wake_slot(i);
        Ok(())
    }

    /// Sets the linear velocity; wakes the body. Static bodies reject it, as do velocities
    /// whose length overflows.
    pub fn set_linear_velocity(&mut self, h: BodyHandle, v: Vec3) -> Result<()> {
        let i = self.movable_slot(h, "linear_velocity")?;
        self.linear_velocity[i] = check_vector("linear_velocity", v)?;
        self.wake_slot(i);
        Ok(())
    }

    /// Sets the angular velocity; wakes the body. Static bodies reject it, as do velocities
    /// whose length overflows.
    pub fn set_angular_velocity(&mut self, h: BodyHandle, w: Vec3) -> Result<()> {
        let i = self.movable_slot(h, "angular_velocity")?;
        self.angular_velocity[i] = check_vector("angular_velocity", w)?;
        self.wake_slot(i);
        Ok(())
    }

    /// Sets the linear and angular velocities of several bodies: every handle and value is
    /// checked (as [`BodySet::set_linear_velocity`]) before any body changes.
    pub fn set_velocities(&mut self, items: &[(BodyHandle, Vec3, Vec3)]) -> Result<()> {
        let mut slots = Vec::with_capacity(items.len());
        for (k, &(h, v, w)) in items.iter().enumerate() {
            let i = self.movable_slot(h, &format!("handles[{k}]"))?;
            check_vector(&format!("linear[{k}]"), v)?;
            check_vector(&format!("angular[{k}]"), w)?;
            slots.push(i);
        }
        for (&i, &(_, v, w)) in slots.iter().zip(items) {
            self.linear_velocity[i] = v;
            self.angular_velocity[i] = w;
            self.wake_slot(i);
        }
        Ok(())
    }

    /// Adds a force (N) at the centre of mass for the next step; wakes the body. A force
    /// whose sum with the forces already added overflows is refused.
    pub fn add_force(&mut self, h: BodyHandle, f: Vec3) -> Result<()> {
        let i = self.slot(h)?;
        self.force[i] = check_vector("force", self.force[i] + check_finite_vec("force", f)?)?;
        self.forces_zero = false;
        self.wake_slot(i);
        Ok(())
    }

    /// Adds a torque (N·m) for the next step; wakes the body (refused as in
    /// [`BodySet::add_force`]).
    pub fn add_torque(&mut self, h: BodyHandle, t: Vec3) -> Result<()> {
        let i = self.slot(h)?;
        self.torque[i] = check_vector("torque", self.torque[i] + check_finite_vec("torque", t)?)?;
        self.forces_zero = false;
        self.wake_slot(i);
        Ok(())
    }

    /// Adds a force at a world point (force plus the torque `(p − com) × f`; refused as in
    /// [`BodySet::add_force`]).
    pub fn add_force_at_point(&mut self, h: BodyHandle, f: Vec3, point: Vec3) -> Result<()> {
        let i = self.slot(h)?;
        check_finite_vec("force", f)?;
        check_finite_vec("point", point)?;
        let force = check_vector("force", self.force[i] + f)?;
        let torque = check_vector(
            "torque",
            self.torque[i] + (point - self.position[i]).cross(f),
        )?;
        self.force[i] = force;
        self.torque[i] = torque;
        self.forces_zero = false;
        self.wake_slot(i);
        Ok(())
    }

    /// Applies an impulse (N·s) at a world point: changes the velocities now; wakes the body.
    /// An impulse that would make a velocity's length overflow is refused.
    pub fn apply_impulse(&mut self, h: BodyHandle, impulse: Vec3, point: Vec3) -> Result<()> {
        let i = self.slot(h)?;
        check_finite_vec("impulse", impulse)?;
        check_finite_vec("point", point)?;
        let v = self.linear_velocity[i] + impulse * self.inv_mass[i];
        let w = self.angular_velocity[i]
            + self.inv_inertia_world[i] * (point - self.position[i]).cross(impulse);
        self.linear_velocity[i] = check_vector("impulse", v)?;
        self.angular_velocity[i] = check_vector("impulse", w)?;
        self.wake_slot(i);
        Ok(())
    }

    /// Applies an angular impulse (N·m·s); wakes the body (refused as in
    /// [`BodySet::apply_impulse`]).
    pub fn apply_angular_impulse(&mut self, h: BodyHandle, impulse: Vec3) -> Result<()> {
        let i = self.slot(h)?;
        check_finite_vec("angular_impulse", impulse)?;
        let w = self.angular_velocity[i] + self.inv_inertia_world[i] * impulse;
        self.angular_velocity[i] = check_vector("angular_impulse", w)?;
        self.wake_slot(i);
        Ok(())
    }

    /// Wakes a body (its island wakes at the next step).
    pub fn wake(&mut self, h: BodyHandle) -> Result<()> {
        let i = self.slot(h)?;
        self.wake_slot(i);
        Ok(())
    }

    pub(crate) fn wake_slot(&mut self, i: usize) {
        if self.info[i].body_type == BodyType::Dynamic {
            if self.info[i].sleeping {
                self.woken_by_user.push(i);
            }
            self.info[i].sleeping = false;
            self.info[i].sleep_time = 0.0;
        }
    }

    fn movable_slot(&self, h: BodyHandle, what: &str) -> Result<usize> {
        let i = self.slot(h)?;
        if self.info[i].body_type == BodyType::Static {
            return Err(CaromError::invalid(
                what,
                format!("{h:?}"),
                "a static body cannot be given a velocity",
            ));
        }
        Ok(i)
    }

    /// Kinetic energy `½ m v² + ½ ωᵀ I ω` of all dynamic bodies.
    pub fn kinetic_energy(&self) -> Real {
        let mut e = 0.0;
        for i in 0..self.capacity() {
            if self.alive[i] && self.inv_mass[i] > 0.0 {
                let v = self.linear_velocity[i];
                let w = self.angular_velocity[i];
                let inertia = self.inv_inertia_world[i].inverse();
                e += 0.5 * v.length_squared() / self.inv_mass[i] + 0.5 * w.dot(inertia * w);
            }
        }
        e
    }
}

/// The world inverse inertia `R I⁻¹ Rᵀ` of a body with rotation `q` and local inverse inertia
/// `inv_local` ([`BodySet::update_world_inertia`], and the soft step's parallel store).
///
/// In SIMD columns ([`Mat3A`]): glam's `Mat3A` builds `R` from the quaternion with the same
/// scalar expressions as `Mat3`, and its products are the same multiplications and additions
/// in the same order, one lane per row, so the result is [`world_inertia_reference`]'s bit
/// for bit (`world_inertia_is_the_scalar_product_bit_for_bit`) at about half the
/// instructions (one `mulps` per column term instead of three `mulss`).
#[inline(always)]
pub(crate) fn world_inertia(q: Quat, inv_local: &Mat3) -> Mat3 {
    let r = Mat3A::from_quat(q);
    Mat3::from(r * Mat3A::from(*inv_local) * r.transpose())
}

/// The scalar `R I⁻¹ Rᵀ` that [`world_inertia`] computes in SIMD columns (its test oracle).
#[cfg(test)]
pub(crate) fn world_inertia_reference(q: Quat, inv_local: &Mat3) -> Mat3 {
    let r = Mat3::from_quat(q);
    r * *inv_local * r.transpose()
}

/// `v` when it is finite and its length is too (speeds, forces and impulses past ~1.8e19 in
/// f32 overflow the squared length that the step's margins and clamps use); an error naming
/// `name` otherwise.
pub(crate) fn check_vector(name: &str, v: Vec3) -> Result<Vec3> {
    let v = check_finite_vec(name, v)?;
    if !v.length().is_finite() {
        return Err(CaromError::invalid(
            name,
            format!("{:?}", v.to_array()),
            "its length overflows",
        ));
    }
    Ok(v)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// Values for the oracle tests: random ones, signed zeros, tiny and huge magnitudes.
    fn values() -> Vec<Real> {
        let mut s = 0x9e37_79b9_7f4a_7c15_u64;
        let mut out = vec![0.0, -0.0, 1.0, -1.0, 0.5, 1e-30, -1e-30, 1e20, -3e15];
        for _ in 0..64 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            out.push((s >> 11) as Real / (1u64 << 53) as Real * 2.0 - 1.0);
        }
        out
    }

    /// Rotations: identity and axis turns (exact zeros and signed zeros), random unit ones,
    /// unnormalised, huge (overflowing products), infinite and NaN ones.
    fn rotations() -> Vec<Quat> {
        let v = values();
        let mut out = vec![
            Quat::IDENTITY,
            Quat::from_xyzw(-0.0, 0.0, -0.0, 1.0),
            Quat::from_xyzw(0.0, 0.0, 0.0, -1.0),
            Quat::from_xyzw(1.0, 0.0, 0.0, 0.0),
            Quat::from_xyzw(0.0, -0.0, -1.0, -0.0),
            Quat::from_rotation_y(0.5),
            Quat::from_xyzw(3.0, -4.0, 0.0, 12.0),
            Quat::from_xyzw(1e19, 0.0, 0.0, 1.0),
            Quat::from_xyzw(1e9, 1e9, 0.0, 1.0),
            Quat::from_xyzw(Real::INFINITY, 0.0, 0.0, 1.0),
            Quat::from_xyzw(0.0, Real::NAN, 0.0, 1.0),
        ];
        for k in 0..40 {
            let q = Quat::from_xyzw(v[k + 9], v[k + 10], v[k + 11], v[k + 12]);
            out.push(if k % 2 == 0 { q.normalize() } else { q });
        }
        out
    }

    /// The bits of a value, every NaN as one: Rust leaves the sign and payload of a NaN
    /// result unspecified (RFC 3514; LLVM may swap the operands of a product, and x86 returns
    /// the first NaN operand), so two compilations of the same expression may differ there,
    /// the old routine against itself included. Every other value must match bit for bit.
    pub(crate) fn real_bits(x: Real) -> u64 {
        if x.is_nan() {
            u64::MAX
        } else {
            x.to_bits() as u64
        }
    }

    fn mat_bits(m: &Mat3) -> Vec<u64> {
        m.to_cols_array().iter().map(|&x| real_bits(x)).collect()
    }

    #[test]
    fn world_inertia_is_the_scalar_product_bit_for_bit() {
        let v = values();
        let mut inertias = vec![
            Mat3::ZERO,
            Mat3::IDENTITY * 6.0,
            Mat3::from_diagonal(Vec3::new(1.0, 2.0, 3.0)),
            Mat3::from_diagonal(Vec3::new(-0.0, 0.0, 1e-30)),
            Mat3::from_cols(
                Vec3::new(1.0, -0.0, 0.0),
                Vec3::new(-0.0, 2.0, -0.0),
                Vec3::Z,
            ),
            Mat3::from_diagonal(Vec3::new(Real::INFINITY, 1.0, 1.0)),
            Mat3::from_diagonal(Vec3::new(1.0, Real::NAN, 1.0)),
        ];
        for k in 0..20 {
            let c = |i: usize| Vec3::new(v[k + i], v[k + i + 1], v[k + i + 2]);
            inertias.push(Mat3::from_cols(c(0), c(3), c(6)));
        }
        for q in rotations() {
            for m in &inertias {
                let (fast, slow) = (world_inertia(q, m), world_inertia_reference(q, m));
                assert_eq!(mat_bits(&fast), mat_bits(&slow), "{q:?} {m:?}");
            }
        }
    }
}
