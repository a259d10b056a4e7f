//! Constraint solvers: sequential impulses with split impulses, and the substepping soft step.
//!
//! Both solve the same prepared data: contact constraints (module `contact`) built from the
//! [`crate::ContactManifold`] inputs, and generic one-dimensional joint rows (module `rows`). They
//! differ in how position error is removed without adding energy:
//! - Sequential impulses ([`SolverKind::SequentialImpulse`]), after Catto, "Iterative Dynamics with Temporal Coherence"
//!   (GDC 2005) and Bullet's `btSequentialImpulseConstraintSolver` — warm-started velocity
//!   iterations, then split impulses (Bullet's `splitImpulse`): penetration is resolved by
//!   pseudo-velocities that move the bodies but are thrown away after the step.
//! - The soft step ([`SolverKind::SoftStep`]), Box2D v3's solver (Catto, "Solver2D", 2024) — substeps with
//!   soft constraints (a contact hertz and damping ratio), a relax pass without bias, and a
//!   restitution pass at the end.
//!
//! Contacts are graph-coloured (module `coloring`): constraints of one colour share no dynamic
//! body, so a colour may be solved in parallel with rayon and still give the same bits as a
//! sequential solve (each constraint reads and writes only its own two bodies). The soft step
//! runs all its substeps in one parallel region that walks a list of stages (modules `stages`
//! and `soft_stages`, after Box2D v3's solver stages).

#[cfg(test)]
mod alloc_tests;
pub(crate) mod coloring;
pub(crate) mod contact;
pub(crate) mod contact_simd;
pub(crate) mod joints;
pub(crate) mod rows;
pub(crate) mod sequential;
pub(crate) mod soft_stages;
pub(crate) mod soft_step;
pub(crate) mod stages;
mod timing;

pub use timing::StepTimings;

/// The solver's reusable buffers, owned by the world and cleared, not freed, from step to
/// step (see [`contact::ContactScratch`]).
#[derive(Debug, Clone, Default)]
pub(crate) struct SolverScratch {
    /// Contact constraints and their colouring.
    pub contacts: contact::ContactScratch,
    /// Per-step constants of the moving bodies' integration.
    pub terms: Vec<crate::integrate::BodyTerms>,
    /// The soft step's stage list (module `stages`).
    pub stages: stages::StageList<soft_stages::SoftStage>,
}

use crate::body_set::BodySet;
use crate::contact::ContactManifold;
use crate::joint::JointSet;

use carom_collision::math::{check_non_negative, check_positive, Mat3, Real, Vec3};
use carom_collision::{CaromError, Result};
use serde::{Deserialize, Serialize};

/// Which solver [`crate::DynamicsWorld::step`] uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum SolverKind {
    /// Sequential impulses with split impulses (Bullet).
    SequentialImpulse,
    /// Substepping soft step (Box2D v3). The default: see the crate docs for the comparison.
    #[default]
    SoftStep,
}

/// Solver settings. Defaults follow Bullet (sequential impulses) and Box2D v3 (soft step).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SolverParams {
    /// Which solver.
    pub kind: SolverKind,
    /// Sequential impulses: velocity iterations (Bullet's `m_numIterations`).
    pub velocity_iterations: u32,
    /// Sequential impulses: split-impulse (position) iterations.
    pub position_iterations: u32,
    /// Sequential impulses: fraction of the penetration removed per step by split impulses
    /// (Bullet's `m_erp2`).
    pub split_erp: Real,
    /// Sequential impulses: Baumgarte factor of the joints (Bullet's `m_erp`).
    pub joint_erp: Real,
    /// Soft step: substeps per step (Box2D's `subStepCount`).
    pub substeps: u32,
    /// Soft step: contact stiffness in hertz (capped at a quarter of the substep rate).
    pub contact_hertz: Real,
    /// Soft step: contact damping ratio.
    pub contact_damping_ratio: Real,
    /// Soft step: joint stiffness in hertz.
    pub joint_hertz: Real,
    /// Soft step: joint damping ratio.
    pub joint_damping_ratio: Real,
    /// Soft step: largest speed at which penetration is pushed out, m/s.
    pub max_push_velocity: Real,
    /// Penetration allowed without correction, m (Box2D's `linearSlop`).
    pub linear_slop: Real,
    /// Approach speed below which restitution is ignored, m/s.
    pub restitution_threshold: Real,
    /// Apply last step's impulses first.
    pub warm_starting: bool,
    /// Smallest colour, in scalar constraints, solved in parallel (when the `parallel`
    /// feature is on): the soft step makes a smaller colour one block of its stage list
    /// (module `soft_stages`), sequential impulses solve it on the calling thread. The
    /// default, 64 (one block of sixteen four-wide constraints), splits every colour of more
    /// than one block, as Box2D v3 cuts every active colour into blocks
    /// (`b2SolverStage_*`, `colorConstraintBlockSize`): with 256 the tail colours of a pile
    /// or a stack ran on one thread, 7 % of "1000 stack"'s step instructions.
    pub parallel_min_batch: usize,
    /// Soft step: solve the contacts of each colour four at a time with SIMD lanes
    /// (module `contact_simd`, after Box2D v3); the overflow colour stays scalar. Both paths
    /// give the same physics.
    pub simd: bool,
}

impl Default for SolverParams {
    fn default() -> Self {
        SolverParams {
            kind: SolverKind::default(),
            velocity_iterations: 10,
            position_iterations: 10,
            split_erp: 0.8,
            joint_erp: 0.2,
            substeps: 4,
            contact_hertz: 30.0,
            contact_damping_ratio: 10.0,
            joint_hertz: 60.0,
            joint_damping_ratio: 2.0,
            max_push_velocity: 3.0,
            linear_slop: 0.005,
            restitution_threshold: 1.0,
            warm_starting: true,
            parallel_min_batch: 64,
            simd: true,
        }
    }
}

impl SolverParams {
    /// Checks every value.
    pub fn validate(&self) -> Result<()> {
        for (name, n) in [
            ("solver.velocity_iterations", self.velocity_iterations),
            ("solver.substeps", self.substeps),
        ] {
            if n == 0 || n > 1000 {
                return Err(CaromError::invalid(name, n, "must be in 1..=1000"));
            }
        }
        if self.position_iterations > 1000 {
            let n = self.position_iterations;
            return Err(CaromError::invalid(
                "solver.position_iterations",
                n,
                "must be <= 1000",
            ));
        }
        check_non_negative("solver.split_erp", self.split_erp)?;
        check_non_negative("solver.joint_erp", self.joint_erp)?;
        check_positive("solver.contact_hertz", self.contact_hertz)?;
        check_non_negative("solver.contact_damping_ratio", self.contact_damping_ratio)?;
        check_positive("solver.joint_hertz", self.joint_hertz)?;
        check_non_negative("solver.joint_damping_ratio", self.joint_damping_ratio)?;
        check_positive("solver.max_push_velocity", self.max_push_velocity)?;
        check_non_negative("solver.linear_slop", self.linear_slop)?;
        check_non_negative("solver.restitution_threshold", self.restitution_threshold)?;
        Ok(())
    }
}

/// Everything one solver step works on.
pub(crate) struct StepContext<'a> {
    pub set: &'a mut BodySet,
    pub bodies: &'a mut [SolverBody],
    pub manifolds: &'a mut [ContactManifold],
    pub joints: &'a mut JointSet,
    pub gravity: Vec3,
    pub dt: Real,
    pub params: &'a SolverParams,
    pub gyroscopic: bool,
    pub parallel: bool,
    pub timings: &'a mut StepTimings,
    /// Reused buffers: no allocation in the solver once they have grown to the scene.
    pub scratch: &'a mut SolverScratch,
    /// The joint rows of the step, reused likewise.
    pub joint_scratch: &'a mut joints::JointScratch,
}

/// Per-body state the solver works on (Box2D v3's `b2BodyState`), copied from the body set
/// at the start of a step and back at the end. `dp`/`dq` are the position and rotation-vector
/// deltas since the start of the step (soft step), or the split-impulse pseudo-velocities
/// (sequential impulses).
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C)]
pub(crate) struct SolverBody {
    pub v: Vec3,
    pub w: Vec3,
    pub dp: Vec3,
    pub dq: Vec3,
    pub inv_m: Real,
    pub inv_i: Mat3,
    /// Dynamic and awake: the only bodies whose state the solver writes.
    pub dynamic: bool,
}

impl SolverBody {
    /// `v, w, dp, dq` as three rows of four scalars (the SIMD gather transposes them):
    /// `[v.x, v.y, v.z, w.x], [w.y, w.z, dp.x, dp.y], [dp.z, dq.x, dq.y, dq.z]`. `repr(C)`
    /// keeps the four vectors adjacent at the start of the struct (checked at compile time
    /// below), so this is three plain vector loads.
    #[inline(always)]
    pub fn state(&self) -> [[Real; 4]; 3] {
        // SAFETY: `SolverBody` is `repr(C)` and starts with the twelve scalars of `v, w, dp,
        // dq` without padding (checked at compile time below); `[[Real; 4]; 3]` has the same size and
        // no stricter alignment than `Real`, and every bit pattern is a valid `Real`.
        unsafe { std::ptr::read_unaligned(self as *const SolverBody as *const [[Real; 4]; 3]) }
    }

    /// Sets `v` and `w` from the first rows of [`SolverBody::state`] (the last two scalars
    /// of the second row are ignored).
    #[inline(always)]
    pub fn set_velocities(&mut self, r0: [Real; 4], r1: [Real; 4]) {
        self.v = Vec3::new(r0[0], r0[1], r0[2]);
        self.w = Vec3::new(r0[3], r1[0], r1[1]);
    }

    /// Velocity of the material point at lever arm `r`.
    #[inline]
    pub fn point_velocity(&self, r: Vec3) -> Vec3 {
        self.v + self.w.cross(r)
    }
}

// [`SolverBody::state`] reads `v, w, dp, dq` as twelve consecutive scalars from the start.
const _: () = {
    use std::mem::{offset_of, size_of};
    let r = size_of::<Real>();
    assert!(size_of::<Vec3>() == 3 * r);
    assert!(offset_of!(SolverBody, v) == 0);
    assert!(offset_of!(SolverBody, w) == 3 * r);
    assert!(offset_of!(SolverBody, dp) == 6 * r);
    assert!(offset_of!(SolverBody, dq) == 9 * r);
};

/// Soft-constraint coefficients (Box2D v3's `b2Softness`, from Catto's "Solver2D"): a spring
/// of frequency `hertz` and damping ratio `zeta` integrated implicitly over a step `h`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Softness {
    pub bias_rate: Real,
    pub mass_scale: Real,
    pub impulse_scale: Real,
}

impl Softness {
    /// A rigid constraint without position feedback.
    pub const RIGID: Softness = Softness {
        bias_rate: 0.0,
        mass_scale: 1.0,
        impulse_scale: 0.0,
    };

    /// `b2MakeSoft`: ω = 2π·hertz, a1 = 2ζ + hω, a2 = hω·a1, a3 = 1/(1 + a2);
    /// bias rate ω/a1, mass scale a2·a3, impulse scale a3.
    pub fn new(hertz: Real, zeta: Real, h: Real) -> Softness {
        if hertz <= 0.0 {
            return Softness::RIGID;
        }
        let omega = 2.0 * carom_collision::math::consts::PI * hertz;
        let a1 = 2.0 * zeta + h * omega;
        let a2 = h * omega * a1;
        let a3 = 1.0 / (1.0 + a2);
        Softness {
            bias_rate: omega / a1,
            mass_scale: a2 * a3,
            impulse_scale: a3,
        }
    }

    /// Baumgarte stabilisation: a rigid constraint that removes `erp` of the error per step.
    pub fn baumgarte(erp: Real, dt: Real) -> Softness {
        Softness {
            bias_rate: erp / dt,
            mass_scale: 1.0,
            impulse_scale: 0.0,
        }
    }
}

/// Inverse of a scalar effective mass, 0 when the mass is zero.
#[inline]
pub(crate) fn inv_or_zero(k: Real) -> Real {
    if k > Real::EPSILON {
        1.0 / k
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn softness_scales_sum_to_one_and_stiffen_with_hertz() {
        let h = 1.0 / 240.0;
        let mut last_rate = 0.0;
        for hertz in [1.0, 10.0, 30.0, 60.0] {
            let s = Softness::new(hertz, 1.0, h);
            // a2·a3 + a3 = (a2 + 1) / (1 + a2) = 1.
            assert!((s.mass_scale + s.impulse_scale - 1.0).abs() < 1e-5);
            assert!(s.bias_rate > last_rate);
            last_rate = s.bias_rate;
        }
        assert_eq!(Softness::new(0.0, 1.0, h), Softness::RIGID);
    }

    #[test]
    fn params_are_validated() {
        let p = SolverParams {
            substeps: 0,
            ..Default::default()
        };
        assert!(p.validate().is_err());
        let p = SolverParams {
            contact_hertz: Real::NAN,
            ..Default::default()
        };
        assert!(p
            .validate()
            .unwrap_err()
            .to_string()
            .contains("contact_hertz"));
        assert!(SolverParams::default().validate().is_ok());
    }
}
