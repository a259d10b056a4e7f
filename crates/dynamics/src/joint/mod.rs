//! Joints: descriptions, a generational joint set, and conversion from scene descriptions.
//!
//! Every joint is a list of one-dimensional rows ([`crate::solver`]'s generic rows) built
//! each step from the two joint frames (and refreshed in place after every substep of the
//! soft step), as Bullet's `btTypedConstraint::getInfo2` does:
//! point-to-point (`btPoint2PointConstraint`), hinge (`btHingeConstraint`, axis = frame Z),
//! cone-twist (`btConeTwistConstraint`, twist axis = frame X, `setLimit(swing1, swing2,
//! twist)`), slider (axis = frame X), fixed, and a generic 6-DOF joint
//! (`btGeneric6DofSpring2Constraint`) with per-axis limits, springs and motors.

mod build;
mod generate;
mod scene;
#[cfg(test)]
mod tests;

pub(crate) use build::{layout, prepare_own, refresh_own, JointRows, ROW_SLOTS};

use crate::body_set::BodyHandle;
use carom_collision::math::{check_finite, check_isometry, check_non_negative, Isometry, Real};
use carom_collision::{CaromError, Result};
use serde::{Deserialize, Serialize};

/// A velocity motor: drives the joint coordinate at `speed` with at most `max_force`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Motor {
    /// Target speed (rad/s or m/s).
    pub speed: Real,
    /// Largest force (N) or torque (N·m).
    pub max_force: Real,
}

/// A spring on one coordinate: frequency, damping ratio and rest value.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Spring {
    /// Stiffness as a frequency, Hz.
    pub hertz: Real,
    /// Damping ratio (1 = critical).
    pub damping_ratio: Real,
    /// Coordinate at rest (m or rad).
    pub rest: Real,
}

/// How one axis of a generic 6-DOF joint moves.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub enum AxisMode {
    /// No relative motion.
    #[default]
    Locked,
    /// Free motion.
    Free,
    /// Motion within `[low, high]`.
    Limited {
        /// Lower bound.
        low: Real,
        /// Upper bound.
        high: Real,
    },
}

/// One axis of a generic 6-DOF joint.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Axis {
    /// Locked, free or limited.
    pub mode: AxisMode,
    /// Optional velocity motor.
    pub motor: Option<Motor>,
    /// Optional spring.
    pub spring: Option<Spring>,
}

/// The type and parameters of a joint.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum JointKind {
    /// Point-to-point: the frame origins coincide, rotation is free.
    Ball,
    /// Rotation about the frames' local Z axis only.
    Hinge {
        /// Angle limits `(low, high)` in radians.
        limits: Option<(Real, Real)>,
        /// Optional motor about the axis.
        motor: Option<Motor>,
    },
    /// Ball joint with an elliptic swing cone about frame Y/Z and a twist limit about X.
    ConeTwist {
        /// Swing span about the frame's Z axis, rad.
        swing1: Real,
        /// Swing span about the frame's Y axis, rad.
        swing2: Real,
        /// Twist span about the frame's X axis, rad (±twist).
        twist: Real,
    },
    /// Translation along frame A's X axis only.
    Slider {
        /// Translation limits `(low, high)`, m.
        limits: Option<(Real, Real)>,
        /// Optional motor along the axis.
        motor: Option<Motor>,
    },
    /// No relative motion.
    Fixed,
    /// Per-axis configuration: linear X, Y, Z then angular X, Y, Z (frame A axes; angles
    /// are the components of the relative rotation vector, exact for motion about one axis).
    Generic6Dof {
        /// Linear axes.
        linear: [Axis; 3],
        /// Angular axes.
        angular: [Axis; 3],
    },
}

/// Everything needed to create a joint.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JointDesc {
    /// First body.
    pub body_a: BodyHandle,
    /// Second body.
    pub body_b: BodyHandle,
    /// Joint frame in A's body frame.
    pub frame_a: Isometry,
    /// Joint frame in B's body frame.
    pub frame_b: Isometry,
    /// Type and parameters.
    pub kind: JointKind,
    /// The joint breaks when one row's impulse in a step exceeds this (N·s).
    pub break_impulse: Real,
    /// Disable contacts between the two bodies (see [`JointSet::collision_disabled`]).
    pub disable_collisions: bool,
}

impl JointDesc {
    /// A joint of `kind` with frames, unbreakable, collisions between the bodies disabled.
    pub fn new(
        body_a: BodyHandle,
        body_b: BodyHandle,
        frame_a: Isometry,
        frame_b: Isometry,
        kind: JointKind,
    ) -> Self {
        JointDesc {
            body_a,
            body_b,
            frame_a,
            frame_b,
            kind,
            break_impulse: Real::INFINITY,
            disable_collisions: true,
        }
    }

    /// Checks every value.
    pub fn validate(&self) -> Result<()> {
        check_isometry("joint.frame_a", self.frame_a)?;
        check_isometry("joint.frame_b", self.frame_b)?;
        if self.body_a == self.body_b {
            return Err(CaromError::invalid(
                "joint.body_b",
                self.body_b,
                "same body as body_a",
            ));
        }
        if self.break_impulse.is_nan() || self.break_impulse <= 0.0 {
            return Err(CaromError::invalid(
                "joint.break_impulse",
                self.break_impulse,
                "must be > 0",
            ));
        }
        let limits = |name: &str, l: Option<(Real, Real)>| -> Result<()> {
            if let Some((lo, hi)) = l {
                check_finite(&format!("{name}.low"), lo)?;
                check_finite(&format!("{name}.high"), hi)?;
                if lo > hi {
                    return Err(CaromError::invalid(name, (lo, hi), "low must be <= high"));
                }
            }
            Ok(())
        };
        let motor = |name: &str, m: Option<Motor>| -> Result<()> {
            if let Some(m) = m {
                check_finite(&format!("{name}.speed"), m.speed)?;
                check_non_negative(&format!("{name}.max_force"), m.max_force)?;
            }
            Ok(())
        };
        match self.kind {
            JointKind::Hinge {
                limits: l,
                motor: m,
            }
            | JointKind::Slider {
                limits: l,
                motor: m,
            } => {
                limits("joint.limits", l)?;
                motor("joint.motor", m)?;
            }
            JointKind::ConeTwist {
                swing1,
                swing2,
                twist,
            } => {
                check_non_negative("joint.swing1", swing1)?;
                check_non_negative("joint.swing2", swing2)?;
                check_non_negative("joint.twist", twist)?;
            }
            JointKind::Generic6Dof { linear, angular } => {
                for (k, ax) in linear.iter().chain(angular.iter()).enumerate() {
                    let name = format!("joint.axes[{k}]");
                    if let AxisMode::Limited { low, high } = ax.mode {
                        limits(&name, Some((low, high)))?;
                    }
                    motor(&format!("{name}.motor"), ax.motor)?;
                    if let Some(s) = ax.spring {
                        check_non_negative(&format!("{name}.spring.hertz"), s.hertz)?;
                        check_non_negative(
                            &format!("{name}.spring.damping_ratio"),
                            s.damping_ratio,
                        )?;
                        check_finite(&format!("{name}.spring.rest"), s.rest)?;
                    }
                }
            }
            JointKind::Ball | JointKind::Fixed => {}
        }
        Ok(())
    }
}

/// A stable reference to a joint.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct JointHandle {
    /// Slot index.
    pub index: u32,
    /// Generation of the slot.
    pub generation: u32,
}

/// A live joint.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Joint {
    /// Its description.
    pub desc: JointDesc,
    /// True once broken; a broken joint no longer acts.
    pub broken: bool,
    /// Accumulated impulses per row slot (per step, for warm starting).
    pub(crate) impulses: [Real; ROW_SLOTS],
    /// The largest magnitude of one row's impulse over the last step (N·s), summed over
    /// the substeps of the soft step: what breaking compares with `break_impulse`. Derived
    /// by the solver each step (not serialised).
    #[serde(skip)]
    pub(crate) step_peak: Real,
}

/// All joints of a world.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct JointSet {
    slots: Vec<(u32, Option<Joint>)>,
    free: Vec<u32>,
}

impl JointSet {
    /// Adds a validated joint (body handles are checked by the world).
    pub(crate) fn insert(&mut self, desc: JointDesc) -> JointHandle {
        let joint = Joint {
            desc,
            broken: false,
            impulses: [0.0; ROW_SLOTS],
            step_peak: 0.0,
        };
        let index = match self.free.pop() {
            Some(i) => i as usize,
            None => {
                self.slots.push((0, None));
                self.slots.len() - 1
            }
        };
        self.slots[index].1 = Some(joint);
        JointHandle {
            index: index as u32,
            generation: self.slots[index].0,
        }
    }

    /// Removes a joint.
    pub fn remove(&mut self, h: JointHandle) -> Result<Joint> {
        let slot = self.slot_mut(h)?;
        let joint = slot.1.take().expect("checked live");
        slot.0 = slot.0.wrapping_add(1);
        self.free.push(h.index);
        Ok(joint)
    }

    fn slot_mut(&mut self, h: JointHandle) -> Result<&mut (u32, Option<Joint>)> {
        match self.slots.get_mut(h.index as usize) {
            Some(s) if s.0 == h.generation && s.1.is_some() => Ok(s),
            _ => Err(CaromError::UnknownHandle(format!("{h:?}"))),
        }
    }

    /// The joint named by `h`.
    pub fn get(&self, h: JointHandle) -> Result<&Joint> {
        match self.slots.get(h.index as usize) {
            Some((g, Some(j))) if *g == h.generation => Ok(j),
            _ => Err(CaromError::UnknownHandle(format!("{h:?}"))),
        }
    }

    /// Live joints with their handles, in slot order.
    pub fn iter(&self) -> impl Iterator<Item = (JointHandle, &Joint)> {
        self.slots.iter().enumerate().filter_map(|(i, (g, j))| {
            j.as_ref().map(|j| {
                let h = JointHandle {
                    index: i as u32,
                    generation: *g,
                };
                (h, j)
            })
        })
    }

    pub(crate) fn iter_mut(&mut self) -> impl Iterator<Item = (JointHandle, &mut Joint)> {
        self.slots.iter_mut().enumerate().filter_map(|(i, (g, j))| {
            let generation = *g;
            j.as_mut().map(move |j| {
                let h = JointHandle {
                    index: i as u32,
                    generation,
                };
                (h, j)
            })
        })
    }

    pub(crate) fn get_index(&self, i: usize) -> Option<&Joint> {
        self.slots.get(i).and_then(|s| s.1.as_ref())
    }

    pub(crate) fn get_index_mut(&mut self, i: usize) -> Option<&mut Joint> {
        self.slots.get_mut(i).and_then(|s| s.1.as_mut())
    }

    /// Checks the consistency of a decoded set (a snapshot): free slots in range, unique and
    /// empty; every joint description valid.
    pub(crate) fn check_structure(&self) -> Result<()> {
        let n = self.slots.len();
        let mut seen = vec![false; n];
        for &f in &self.free {
            let f = f as usize;
            if f >= n || self.slots[f].1.is_some() || seen[f] {
                return Err(CaromError::invalid(
                    "snapshot.joints",
                    f,
                    "bad free joint slot",
                ));
            }
            seen[f] = true;
        }
        if self.free.len() + self.slots.iter().filter(|s| s.1.is_some()).count() != n {
            return Err(CaromError::invalid(
                "snapshot.joints",
                n,
                "free list does not cover the empty slots",
            ));
        }
        for (_, j) in self.iter() {
            j.desc.validate()?;
            if j.impulses.iter().any(|x| !x.is_finite()) {
                return Err(CaromError::invalid(
                    "snapshot.joints",
                    format!("{:?}", j.impulses),
                    "non-finite joint impulse",
                ));
            }
        }
        Ok(())
    }

    /// Number of live joints.
    pub fn len(&self) -> usize {
        self.slots.len() - self.free.len()
    }

    /// True when there is no joint.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// True if an unbroken joint between `a` and `b` disables their collisions: the
    /// collision side asks this before creating a contact pair.
    pub fn collision_disabled(&self, a: BodyHandle, b: BodyHandle) -> bool {
        self.iter().any(|(_, j)| {
            !j.broken
                && j.desc.disable_collisions
                && ((j.desc.body_a == a && j.desc.body_b == b)
                    || (j.desc.body_a == b && j.desc.body_b == a))
        })
    }
}
