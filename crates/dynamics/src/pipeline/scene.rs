//! Building a [`World`] from a `carom-scenes` description (the benchmark scenes of
//! `shared/bench/SCENES.md`). `carom-scenes` does not depend on dynamics, so the builder
//! lives here.

use super::{PipelineParams, World};
use crate::body::{BodyDesc, BodyType, MassSpec};
use crate::joint::JointDesc;
use carom_collision::Result;
use carom_scenes::Scene;

impl World {
    /// A world holding every body and joint of `scene`, with the scene's gravity and, for
    /// the sequential-impulse solver, its iteration count. Bodies are created in scene order,
    /// so [`World::handles`] of the new world lists `scene.bodies[i]` at index `i`. Masses
    /// are given (`MassSpec::Mass`, inertia from the shape); mass 0 is a static body.
    /// Friction combines by geometric mean ([`crate::mix_friction`]), not Bullet's product.
    pub fn from_scene(scene: &Scene) -> Result<World> {
        Self::from_scene_with(scene, PipelineParams::default())
    }

    /// [`World::from_scene`] with other settings (the scene's gravity still applies).
    pub fn from_scene_with(scene: &Scene, mut params: PipelineParams) -> Result<World> {
        params.dynamics.gravity = scene.gravity;
        params.dynamics.solver.velocity_iterations = scene.solver.iterations.max(1);
        let mut world = World::new(params)?;
        let mut handles = Vec::with_capacity(scene.bodies.len());
        for b in &scene.bodies {
            let desc = BodyDesc {
                body_type: if b.is_static() {
                    BodyType::Static
                } else {
                    BodyType::Dynamic
                },
                pose: b.pose,
                shape: Some(b.shape.clone()),
                mass: MassSpec::Mass(b.mass),
                friction: b.friction,
                restitution: b.restitution,
                linear_damping: b.linear_damping,
                angular_damping: b.angular_damping,
                ..Default::default()
            };
            handles.push(world.add_body(&desc)?);
        }
        for j in &scene.joints {
            world.create_joint(&JointDesc::from_scene(j, &handles)?)?;
        }
        Ok(world)
    }
}
