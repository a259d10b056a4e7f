//! The interface every in-process engine of `carom-bench scenes` implements, so the harness
//! times Carom and its Rust peers the same way: build from a [`Scene`], step, cast the scene's
//! rays, report per-stage timings and the state of the dynamic bodies for the sanity figures.

use carom_scenes::Scene;

/// How an engine is asked to run a scene.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct EngineConfig {
    /// Worker threads for the step and the ray batch (1 = single-threaded).
    pub threads: usize,
    /// Whether bodies may fall asleep.
    pub sleeping: bool,
}

/// Time spent in each stage of one step, in milliseconds. `None` where the engine does not
/// expose the stage separately (its time is then part of another stage or of "other").
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StageTimes {
    /// Broadphase (pair finding).
    pub broadphase: Option<f64>,
    /// Midphase and narrowphase (contact generation).
    pub narrowphase: Option<f64>,
    /// Constraint solver.
    pub solver: Option<f64>,
    /// Integration of velocities and positions.
    pub integration: Option<f64>,
}

impl StageTimes {
    /// Adds `other` stage by stage (a stage stays `None` only if both are `None`).
    pub fn accumulate(&mut self, other: &StageTimes) {
        fn add(a: &mut Option<f64>, b: Option<f64>) {
            if let Some(b) = b {
                *a = Some(a.unwrap_or(0.0) + b);
            }
        }
        add(&mut self.broadphase, other.broadphase);
        add(&mut self.narrowphase, other.narrowphase);
        add(&mut self.solver, other.solver);
        add(&mut self.integration, other.integration);
    }

    /// Every stage divided by `n` (turns a sum over steps into a mean per step).
    pub fn scaled(&self, factor: f64) -> StageTimes {
        let f = |x: Option<f64>| x.map(|v| v * factor);
        StageTimes {
            broadphase: f(self.broadphase),
            narrowphase: f(self.narrowphase),
            solver: f(self.solver),
            integration: f(self.integration),
        }
    }
}

/// The state of one dynamic body, in scene order, for the sanity figures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyState {
    /// Centre (body origin) in world space.
    pub position: [f64; 3],
    /// Linear velocity.
    pub velocity: [f64; 3],
}

/// One physics engine running one scene.
pub trait Engine {
    /// Short name used in tables and files ("rapier", "carom").
    fn name(&self) -> &'static str;
    /// Advances the simulation by the scene's time step and returns the stage split.
    fn step(&mut self) -> StageTimes;
    /// Casts the scene's rays (closest hit each) and returns how many hit something.
    fn cast_rays(&mut self) -> usize;
    /// The dynamic bodies, in the order of the scene's dynamic bodies.
    fn bodies(&self) -> Vec<BodyState>;
}

/// Builds an engine for a scene.
pub type EngineBuilder = fn(&Scene, EngineConfig) -> Result<Box<dyn Engine>, String>;

/// The in-process engines, by name.
pub fn builders() -> Vec<(&'static str, EngineBuilder)> {
    vec![
        ("carom", super::carom_engine::build as EngineBuilder),
        ("rapier", super::rapier_peer::build as EngineBuilder),
    ]
}

/// The initial state of a scene's dynamic bodies (positions, zero velocity).
pub fn initial_states(scene: &Scene) -> Vec<BodyState> {
    scene
        .bodies
        .iter()
        .filter(|b| !b.is_static())
        .map(|b| {
            let t = b.pose.translation;
            BodyState {
                position: [t.x as f64, t.y as f64, t.z as f64],
                velocity: [0.0; 3],
            }
        })
        .collect()
}
