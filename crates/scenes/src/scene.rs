//! Plain scene descriptions, independent of any engine.

use carom_collision::math::{Isometry, Real, Vec3};
use carom_collision::shape::Shape;
use std::sync::Arc;

/// One body of a scene. `mass == 0` means static.
#[derive(Debug, Clone)]
pub struct SceneBody {
    /// Collision shape (shared between bodies where Bullet shares it).
    pub shape: Arc<Shape>,
    /// Initial pose.
    pub pose: Isometry,
    /// Mass in kg; 0 for static bodies.
    pub mass: Real,
    /// Friction coefficient (Bullet combines by product).
    pub friction: Real,
    /// Restitution coefficient.
    pub restitution: Real,
    /// Linear damping per second (Bullet's convention).
    pub linear_damping: Real,
    /// Angular damping per second.
    pub angular_damping: Real,
}

impl SceneBody {
    /// A body with Bullet's defaults: friction 0.5, no restitution, no damping.
    pub fn new(shape: Arc<Shape>, pose: Isometry, mass: Real) -> Self {
        SceneBody {
            shape,
            pose,
            mass,
            friction: 0.5,
            restitution: 0.0,
            linear_damping: 0.0,
            angular_damping: 0.0,
        }
    }

    /// True for static bodies.
    pub fn is_static(&self) -> bool {
        self.mass == 0.0
    }
}

/// Joint types used by the scenes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum JointKind {
    /// Bullet `btHingeConstraint`: rotation about the frames' local Z axis, limited to
    /// `[low, high]` radians.
    Hinge {
        /// Lower angle limit.
        low: Real,
        /// Upper angle limit.
        high: Real,
    },
    /// Bullet `btConeTwistConstraint` with `setLimit(swing1, swing2, twist)`.
    ConeTwist {
        /// Swing span about the frame's Z axis.
        swing1: Real,
        /// Swing span about the frame's Y axis.
        swing2: Real,
        /// Twist span about the frame's X axis.
        twist: Real,
    },
}

/// A joint between two bodies of the scene, with a frame on each in body-local coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct JointDesc {
    /// Index of body A in [`Scene::bodies`].
    pub body_a: usize,
    /// Index of body B.
    pub body_b: usize,
    /// Joint frame in A's local frame.
    pub frame_a: Isometry,
    /// Joint frame in B's local frame.
    pub frame_b: Isometry,
    /// Type and limits.
    pub kind: JointKind,
    /// Bullet's `disableCollisionsBetweenLinkedBodies`.
    pub disable_collisions: bool,
}

/// Solver settings a scene asks for (Bullet's names).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverSettings {
    /// Velocity iterations (`m_numIterations`).
    pub iterations: u32,
    /// Baumgarte factor for contacts (`m_erp2` is the split-impulse one).
    pub erp: Real,
    /// Error reduction of the split-impulse position pass.
    pub erp2: Real,
    /// Global constraint force mixing.
    pub global_cfm: Real,
}

impl Default for SolverSettings {
    /// BenchmarkDemo: 5 iterations, Bullet's HEAD defaults otherwise.
    fn default() -> Self {
        SolverSettings {
            iterations: 5,
            erp: 0.2,
            erp2: 0.2,
            global_cfm: 0.0,
        }
    }
}

/// A whole scene.
#[derive(Debug, Clone)]
pub struct Scene {
    /// Bullet's name for the scene ("3000 fall", …).
    pub name: &'static str,
    /// Gravity, m/s².
    pub gravity: Vec3,
    /// Time step of one frame, s.
    pub dt: Real,
    /// Static and dynamic bodies.
    pub bodies: Vec<SceneBody>,
    /// Joints between bodies.
    pub joints: Vec<JointDesc>,
    /// Rays cast after each step: `(from, to)` in world space.
    pub rays: Vec<(Vec3, Vec3)>,
    /// Solver settings.
    pub solver: SolverSettings,
}

impl Scene {
    /// Number of dynamic bodies.
    pub fn dynamic_count(&self) -> usize {
        self.bodies.iter().filter(|b| !b.is_static()).count()
    }
}
