//! Body descriptions: what a user fills in to create a rigid body, validated once at creation.
//!
//! Follows the "description separate from live object" practice of Box2D v3 (`b2BodyDef`) and
//! Jolt (`BodyCreationSettings`): a [`BodyDesc`] with [`Default`], turned into live hot data by
//! [`crate::BodySet::insert`].

use carom_collision::broadphase::Filter;
use carom_collision::math::{
    check_finite, check_finite_vec, check_isometry, check_non_negative, check_positive, Isometry,
    Mat3, Real, Vec3,
};
use carom_collision::shape::{MassProperties, Shape};
use carom_collision::{CaromError, Result};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// Largest gravity scale a body accepts: beyond it the gravity's velocity change of a step
/// approaches the range of f32 and means nothing physical.
pub const MAX_GRAVITY_SCALE: Real = 1.0e6;

/// How a body moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
pub enum BodyType {
    /// Moved by forces, contacts and joints.
    #[default]
    Dynamic,
    /// Moved only by its velocity, which the user sets; infinite mass for the solver.
    Kinematic,
    /// Never moves; infinite mass.
    Static,
}

/// How the mass of a body is given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MassSpec {
    /// Mass and inertia from the shape's volume and this density (kg/m³).
    Density(Real),
    /// This total mass; the inertia is the shape's, scaled to the mass (uniform density).
    Mass(Real),
    /// Explicit mass properties (centre of mass in the body frame, inertia about it).
    Properties(MassProperties),
}

/// Everything needed to create a rigid body. Validated by [`BodyDesc::validate`] (called by
/// [`crate::BodySet::insert`]); bad values are rejected with an error naming them.
#[derive(Debug, Clone)]
pub struct BodyDesc {
    /// Dynamic, kinematic or static.
    pub body_type: BodyType,
    /// Pose of the body frame (the shape's frame) in world space.
    pub pose: Isometry,
    /// Linear velocity of the centre of mass, m/s.
    pub linear_velocity: Vec3,
    /// Angular velocity, rad/s, world axes.
    pub angular_velocity: Vec3,
    /// Collision shape; used for the mass properties of dynamic bodies.
    pub shape: Option<Arc<Shape>>,
    /// Mass or density.
    pub mass: MassSpec,
    /// Coulomb friction coefficient (combined by geometric mean by [`crate::mix_friction`]).
    pub friction: Real,
    /// Restitution coefficient in `[0, 1]` (combined by max by [`crate::mix_restitution`]).
    pub restitution: Real,
    /// Linear damping per second: `v *= (1 - d)^dt` (Bullet's convention).
    pub linear_damping: Real,
    /// Angular damping per second.
    pub angular_damping: Real,
    /// Multiplier of the world gravity for this body.
    pub gravity_scale: Real,
    /// Whether the body (and its island) may fall asleep.
    pub can_sleep: bool,
    /// Largest linear speed, m/s; faster bodies are clamped after the solve.
    pub max_linear_speed: Real,
    /// Largest angular speed, rad/s.
    pub max_angular_speed: Real,
    /// Arbitrary user value.
    pub user_data: u64,
    /// Collision filter of the body's collision object in a [`crate::World`] (groups and
    /// masks; `is_static` is set from `body_type`).
    pub filter: Filter,
}

impl Default for BodyDesc {
    fn default() -> Self {
        BodyDesc {
            body_type: BodyType::Dynamic,
            pose: Isometry::IDENTITY,
            linear_velocity: Vec3::ZERO,
            angular_velocity: Vec3::ZERO,
            shape: None,
            mass: MassSpec::Density(1000.0),
            friction: 0.5,
            restitution: 0.0,
            linear_damping: 0.0,
            angular_damping: 0.0,
            gravity_scale: 1.0,
            can_sleep: true,
            max_linear_speed: 400.0,
            max_angular_speed: 100.0,
            user_data: 0,
            filter: Filter::default(),
        }
    }
}

/// The validated, derived quantities of a body that the solver needs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResolvedMass {
    /// Mass, 0 for static and kinematic bodies.
    pub mass: Real,
    /// Inverse mass, 0 for static and kinematic bodies.
    pub inv_mass: Real,
    /// Centre of mass in the body frame.
    pub local_com: Vec3,
    /// Inverse inertia about the centre of mass, body axes (zero for non-dynamic bodies).
    pub inv_inertia_local: Mat3,
}

impl BodyDesc {
    /// A dynamic body with `shape` at `pose` and the given density.
    pub fn dynamic(shape: Arc<Shape>, pose: Isometry, density: Real) -> Self {
        BodyDesc {
            shape: Some(shape),
            pose,
            mass: MassSpec::Density(density),
            ..Default::default()
        }
    }

    /// A static body with `shape` at `pose`.
    pub fn fixed(shape: Arc<Shape>, pose: Isometry) -> Self {
        BodyDesc {
            body_type: BodyType::Static,
            shape: Some(shape),
            pose,
            ..Default::default()
        }
    }

    /// Checks every value and computes the mass properties.
    pub fn validate(&self) -> Result<(Isometry, ResolvedMass)> {
        let pose = check_isometry("body.pose", self.pose)?;
        crate::body_set::check_vector("body.linear_velocity", self.linear_velocity)?;
        crate::body_set::check_vector("body.angular_velocity", self.angular_velocity)?;
        check_non_negative("body.friction", self.friction)?;
        let e = check_non_negative("body.restitution", self.restitution)?;
        if e > 1.0 {
            return Err(CaromError::invalid("body.restitution", e, "must be <= 1"));
        }
        check_non_negative("body.linear_damping", self.linear_damping)?;
        check_non_negative("body.angular_damping", self.angular_damping)?;
        let g = check_finite("body.gravity_scale", self.gravity_scale)?;
        if g.abs() > MAX_GRAVITY_SCALE {
            return Err(CaromError::invalid(
                "body.gravity_scale",
                g,
                format!("must be within ±{MAX_GRAVITY_SCALE:e}"),
            ));
        }
        check_positive("body.max_linear_speed", self.max_linear_speed)?;
        check_positive("body.max_angular_speed", self.max_angular_speed)?;
        let mass = match self.body_type {
            BodyType::Dynamic => self.resolve_dynamic_mass()?,
            BodyType::Kinematic | BodyType::Static => ResolvedMass {
                mass: 0.0,
                inv_mass: 0.0,
                local_com: self
                    .shape
                    .as_ref()
                    .map(|s| s.mass_properties(1.0))
                    .filter(|m| m.mass > 0.0 && m.center_of_mass.is_finite())
                    .map_or(Vec3::ZERO, |m| m.center_of_mass),
                inv_inertia_local: Mat3::ZERO,
            },
        };
        if self.body_type == BodyType::Static
            && (self.linear_velocity != Vec3::ZERO || self.angular_velocity != Vec3::ZERO)
        {
            return Err(CaromError::invalid(
                "body.linear_velocity",
                self.linear_velocity,
                "a static body cannot move (use a kinematic body)",
            ));
        }
        Ok((pose, mass))
    }

    fn resolve_dynamic_mass(&self) -> Result<ResolvedMass> {
        let unit = |what: &str| -> Result<MassProperties> {
            let shape = self.shape.as_ref().ok_or_else(|| {
                CaromError::invalid(
                    "body.shape",
                    "None",
                    format!("a dynamic body with {what} needs a shape"),
                )
            })?;
            let mp = shape.mass_properties(1.0);
            if mp.mass.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater)
                || !mp.mass.is_finite()
            {
                return Err(CaromError::invalid(
                    "body.shape",
                    shape.kind_name(),
                    "has no volume: give MassSpec::Properties for a dynamic body",
                ));
            }
            Ok(mp)
        };
        let props = match self.mass {
            MassSpec::Density(d) => {
                let d = check_positive("body.mass (density)", d)?;
                let mp = unit("a density")?;
                MassProperties {
                    mass: mp.mass * d,
                    center_of_mass: mp.center_of_mass,
                    inertia: mp.inertia * d,
                }
            }
            MassSpec::Mass(m) => {
                let m = check_positive("body.mass", m)?;
                let mp = unit("a mass")?;
                let k = m / mp.mass;
                MassProperties {
                    mass: m,
                    center_of_mass: mp.center_of_mass,
                    inertia: mp.inertia * k,
                }
            }
            MassSpec::Properties(mp) => {
                check_positive("body.mass", mp.mass)?;
                check_finite_vec("body.mass.center_of_mass", mp.center_of_mass)?;
                mp
            }
        };
        let inv_inertia_local = invert_inertia(props.inertia)?;
        Ok(ResolvedMass {
            mass: props.mass,
            inv_mass: 1.0 / props.mass,
            local_com: props.center_of_mass,
            inv_inertia_local,
        })
    }
}

/// Inverts an inertia tensor; rejects non-finite or non-positive-definite ones.
fn invert_inertia(inertia: Mat3) -> Result<Mat3> {
    let diag = Vec3::new(inertia.x_axis.x, inertia.y_axis.y, inertia.z_axis.z);
    let det = inertia.determinant();
    let positive = |x: Real| x.is_finite() && x > 0.0;
    if !inertia.is_finite() || !positive(diag.min_element()) || !positive(det) {
        return Err(CaromError::invalid(
            "body.mass.inertia",
            inertia,
            "must be finite and positive definite",
        ));
    }
    Ok(inertia.inverse())
}

/// Combined friction of two bodies: geometric mean (Box2D's `b2MixFriction`).
pub fn mix_friction(a: Real, b: Real) -> Real {
    (a * b).sqrt()
}

/// Combined restitution of two bodies: the larger one (Box2D's `b2MixRestitution`).
pub fn mix_restitution(a: Real, b: Real) -> Real {
    a.max(b)
}
