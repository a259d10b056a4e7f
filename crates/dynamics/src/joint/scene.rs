//! Conversion from the engine-independent scene joints of `carom-scenes`.

use super::{JointDesc, JointKind};
use crate::body_set::BodyHandle;
use carom_collision::math::Real;
use carom_collision::{CaromError, Result};

impl JointDesc {
    /// Converts a scene joint; `handles[i]` is the body created for `scene.bodies[i]`.
    /// Bullet's hinge limits map to [`JointKind::Hinge`] (axis = frame Z) and
    /// `btConeTwistConstraint::setLimit(swing1, swing2, twist)` to [`JointKind::ConeTwist`].
    pub fn from_scene(desc: &carom_scenes::JointDesc, handles: &[BodyHandle]) -> Result<Self> {
        let get = |name: &str, i: usize| {
            handles.get(i).copied().ok_or_else(|| {
                CaromError::invalid(
                    name,
                    i,
                    format!("only {} bodies were created", handles.len()),
                )
            })
        };
        let kind = match desc.kind {
            carom_scenes::JointKind::Hinge { low, high } => JointKind::Hinge {
                limits: Some((low, high)),
                motor: None,
            },
            carom_scenes::JointKind::ConeTwist {
                swing1,
                swing2,
                twist,
            } => JointKind::ConeTwist {
                swing1,
                swing2,
                twist,
            },
        };
        let out = JointDesc {
            body_a: get("joint.body_a", desc.body_a)?,
            body_b: get("joint.body_b", desc.body_b)?,
            frame_a: desc.frame_a,
            frame_b: desc.frame_b,
            kind,
            break_impulse: Real::INFINITY,
            disable_collisions: desc.disable_collisions,
        };
        out.validate()?;
        Ok(out)
    }
}
