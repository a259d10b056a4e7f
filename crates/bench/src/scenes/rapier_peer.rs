//! The Rapier peer of `carom-bench scenes`: builds a [`Scene`] in rapier3d 0.36.1 and steps
//! it with `PhysicsPipeline`, timing the stages with rapier's own counters (feature
//! `profiler`). The ray scene casts with rapier's `QueryPipeline::cast_ray`.
//!
//! Same as the scene: counts, shapes and sizes, poses, masses, Bullet's inertia (see
//! [`super::inertia`]; colliders have density 0 and the body gets the mass properties), friction
//! and restitution combined by product (`CoefficientCombineRule::Multiply`, as Bullet),
//! damping values, gravity, time step, `num_solver_iterations` = the scene's iterations, joint
//! frames and limits, no collision between jointed bodies, sleeping on or off.
//!
//! Deviations (rapier's API has no equivalent):
//! - Solver: rapier's TGS-soft "iterations" are substeps, each with one PGS pass and
//!   stabilisation; Bullet's are PGS sweeps of one step. Bullet's erp/erp2/cfm/split-impulse
//!   settings have no counterpart: rapier's default contact softness and joint stiffness are kept.
//! - Margins: rapier's convex hulls have no margin (Bullet adds 0.04 outside), which is what
//!   the scene specifies for Carom; rapier's contact prediction distance is its default.
//! - Damping: rapier applies `v /= 1 + dt·d`, Bullet `v *= (1 − d)^dt` (same value passed).
//! - Sleeping: rapier's default thresholds and time (Bullet: 2 s, ragdolls 0.8 s, 1.6/2.5).
//! - Cone-twist joints: a spherical joint with independent limits on the twist (X) and the
//!   two swing axes (Y, Z), i.e. a box of angles instead of Bullet's elliptic cone; the limits
//!   are hard (Bullet's softness/bias/relaxation have no counterpart).
//! - Hinges: a revolute joint about the frames' Z axis (the frames are turned so that rapier's
//!   X joint axis is Bullet's Z), with a hard limit.
//! - Stages: rapier has no separate integration timer (`velocity_update_time` is never
//!   started in 0.36.1): integration is inside "solver".

use super::engine::{BodyState, Engine, EngineConfig, StageTimes};
use super::inertia::bullet_inertia;
use carom_collision::math::{Isometry, Vec3};
use carom_collision::shape::Shape;
use carom_scenes::{JointKind, Scene};
use rapier3d::math::{Pose3, Rot3};
use rapier3d::prelude::*;
use rayon::prelude::*;

/// Rays per parallel task in the multi-threaded ray batch (Bullet's `btParallelFor` grain).
const RAY_GRAIN: usize = 20;

fn vec(v: Vec3) -> Vector {
    Vector::new(v.x as _, v.y as _, v.z as _)
}

fn pose(p: &Isometry) -> Pose3 {
    let q = p.rotation;
    Pose3::from_parts(
        vec(p.translation),
        Rot3::from_xyzw(q.x as _, q.y as _, q.z as _, q.w as _),
    )
}

/// A rapier collider builder for a scene shape.
fn collider(shape: &Shape) -> Result<ColliderBuilder, String> {
    Ok(match shape {
        Shape::Cuboid(c) => {
            let h = c.half_extents();
            ColliderBuilder::cuboid(h.x as _, h.y as _, h.z as _)
        }
        Shape::Sphere(s) => ColliderBuilder::ball(s.radius() as _),
        Shape::Capsule(c) => ColliderBuilder::capsule_y(c.half_height() as _, c.radius() as _),
        Shape::ConvexHull(h) => {
            let pts: Vec<Vector> = h.vertices().iter().map(|&v| vec(v)).collect();
            ColliderBuilder::convex_hull(&pts).ok_or("rapier rejected a convex hull")?
        }
        Shape::TriMesh(m) => ColliderBuilder::trimesh(
            m.vertices().iter().map(|&v| vec(v)).collect(),
            m.indices().to_vec(),
        )
        .map_err(|e| format!("rapier rejected a mesh: {e:?}"))?,
        Shape::Plane(p) => {
            // Rapier's half-space passes through the collider origin: move it to the plane.
            ColliderBuilder::new(SharedShape::halfspace(vec(p.normal())))
                .translation(vec(p.normal() * p.offset()))
        }
        other => return Err(format!("no rapier shape for {}", other.kind_name())),
    })
}

/// Rapier's world for one scene.
pub struct RapierEngine {
    pipeline: PhysicsPipeline,
    gravity: Vector,
    params: IntegrationParameters,
    islands: IslandManager,
    broad_phase: BroadPhaseBvh,
    narrow_phase: NarrowPhase,
    bodies: RigidBodySet,
    colliders: ColliderSet,
    impulse_joints: ImpulseJointSet,
    multibody_joints: MultibodyJointSet,
    soft_bodies: SoftBodySet,
    ccd: CCDSolver,
    dynamic: Vec<RigidBodyHandle>,
    rays: Vec<Ray>,
    pool: rayon::ThreadPool,
}

/// Builds `scene` in rapier (see the module docs for what is the same and what deviates).
pub fn build(scene: &Scene, config: EngineConfig) -> Result<Box<dyn Engine>, String> {
    let mut bodies = RigidBodySet::new();
    let mut colliders = ColliderSet::new();
    let mut handles = Vec::with_capacity(scene.bodies.len());
    let mut dynamic = Vec::new();
    for b in &scene.bodies {
        let builder = if b.is_static() {
            RigidBodyBuilder::fixed()
        } else {
            let mass = b.mass as f64;
            let i = bullet_inertia(&b.shape, mass)
                .ok_or_else(|| format!("dynamic {} has no inertia", b.shape.kind_name()))?;
            let mprops = MassProperties::new(
                Vector::ZERO,
                mass as _,
                Vector::new(i[0] as _, i[1] as _, i[2] as _),
            );
            RigidBodyBuilder::dynamic()
                .additional_mass_properties(mprops)
                .linear_damping(b.linear_damping as _)
                .angular_damping(b.angular_damping as _)
                .can_sleep(config.sleeping)
        };
        let h = bodies.insert(builder.pose(pose(&b.pose)));
        let c = collider(&b.shape)?
            .density(0.0)
            .friction(b.friction as _)
            .restitution(b.restitution as _)
            .friction_combine_rule(CoefficientCombineRule::Multiply)
            .restitution_combine_rule(CoefficientCombineRule::Multiply);
        colliders.insert_with_parent(c, h, &mut bodies);
        handles.push(h);
        if !b.is_static() {
            dynamic.push(h);
        }
    }
    let mut impulse_joints = ImpulseJointSet::new();
    // Turns rapier's revolute axis (local X) onto Bullet's hinge axis (local Z).
    let x_to_z = Isometry::from_rotation(carom_collision::math::Quat::from_rotation_y(
        -std::f64::consts::FRAC_PI_2 as _,
    ));
    for j in &scene.joints {
        let joint = match j.kind {
            JointKind::Hinge { low, high } => {
                GenericJointBuilder::new(JointAxesMask::LOCKED_REVOLUTE_AXES)
                    .local_frame1(pose(&j.frame_a.mul(&x_to_z)))
                    .local_frame2(pose(&j.frame_b.mul(&x_to_z)))
                    .limits(JointAxis::AngX, [low as _, high as _])
            }
            JointKind::ConeTwist {
                swing1,
                swing2,
                twist,
            } => GenericJointBuilder::new(JointAxesMask::LOCKED_SPHERICAL_AXES)
                .local_frame1(pose(&j.frame_a))
                .local_frame2(pose(&j.frame_b))
                .limits(JointAxis::AngX, [-twist as _, twist as _])
                .limits(JointAxis::AngY, [-swing2 as _, swing2 as _])
                .limits(JointAxis::AngZ, [-swing1 as _, swing1 as _]),
        }
        .contacts_enabled(!j.disable_collisions);
        impulse_joints.insert(handles[j.body_a], handles[j.body_b], joint.build(), true);
    }
    let params = IntegrationParameters {
        dt: scene.dt as _,
        num_solver_iterations: scene.solver.iterations.max(1) as usize,
        ..IntegrationParameters::default()
    };
    let mut pipeline = PhysicsPipeline::new();
    pipeline.counters.enable();
    pipeline
        .configure_thread_pool(config.threads.max(1))
        .map_err(|e| e.to_string())?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(config.threads.max(1))
        .build()
        .map_err(|e| e.to_string())?;
    let rays = scene
        .rays
        .iter()
        .map(|&(from, to)| Ray::new(vec(from), vec(to - from)))
        .collect();
    Ok(Box::new(RapierEngine {
        pipeline,
        gravity: vec(scene.gravity),
        params,
        islands: IslandManager::new(),
        broad_phase: BroadPhaseBvh::new(),
        narrow_phase: NarrowPhase::new(),
        bodies,
        colliders,
        impulse_joints,
        multibody_joints: MultibodyJointSet::new(),
        soft_bodies: SoftBodySet::new(),
        ccd: CCDSolver::new(),
        dynamic,
        rays,
        pool,
    }))
}

impl Engine for RapierEngine {
    fn name(&self) -> &'static str {
        "rapier"
    }

    fn step(&mut self) -> StageTimes {
        self.pipeline.step(
            self.gravity,
            &self.params,
            &mut self.islands,
            &mut self.broad_phase,
            &mut self.narrow_phase,
            &mut self.bodies,
            &mut self.colliders,
            &mut self.impulse_joints,
            &mut self.multibody_joints,
            &mut self.soft_bodies,
            &mut self.ccd,
            &(),
            &(),
        );
        let c = &self.pipeline.counters;
        StageTimes {
            broadphase: Some(
                c.cd.broad_phase_time.time_ms() + c.cd.final_broad_phase_time.time_ms(),
            ),
            narrowphase: Some(c.cd.narrow_phase_time.time_ms()),
            solver: Some(c.stages.solver_time.time_ms()),
            integration: None,
        }
    }

    fn cast_rays(&mut self) -> usize {
        if self.rays.is_empty() {
            return 0;
        }
        let (bp, np, bodies, colliders) = (
            &self.broad_phase,
            &self.narrow_phase,
            &self.bodies,
            &self.colliders,
        );
        let cast = |chunk: &[Ray]| {
            let qp = bp.as_query_pipeline(
                np.query_dispatcher(),
                bodies,
                colliders,
                QueryFilter::default(),
            );
            chunk
                .iter()
                .filter(|r| qp.cast_ray(r, 1.0, true).is_some())
                .count()
        };
        if self.pool.current_num_threads() == 1 {
            return cast(&self.rays);
        }
        let rays = &self.rays;
        self.pool
            .install(|| rays.par_chunks(RAY_GRAIN).map(cast).sum())
    }

    fn bodies(&self) -> Vec<BodyState> {
        self.dynamic
            .iter()
            .map(|&h| {
                let b = &self.bodies[h];
                let (p, v) = (b.translation(), b.linvel());
                BodyState {
                    position: [p.x as f64, p.y as f64, p.z as f64],
                    velocity: [v.x as f64, v.y as f64, v.z as f64],
                }
            })
            .collect()
    }
}
