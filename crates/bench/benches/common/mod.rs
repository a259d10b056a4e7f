//! Helpers shared by the criterion benches: a seeded generator and conversions of Carom's
//! math types to parry3d's (f32), done outside the timed loops.

use carom_collision::math::{vec3_to_f64, Isometry, Quat, Real, Vec3};
use parry3d::math::{Pose as PPose, Vec3 as PVec3};

/// A small deterministic generator (64-bit LCG), so every run benches the same cases.
pub struct Rng(pub u64);

impl Rng {
    /// Uniform in [0, 1).
    pub fn next(&mut self) -> Real {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) as Real
    }

    /// A random unit vector (rejection sampling in the unit ball).
    pub fn unit(&mut self) -> Vec3 {
        loop {
            let v = Vec3::new(self.next(), self.next(), self.next()) * 2.0 - Vec3::ONE;
            let l = v.length();
            if l > 0.1 && l <= 1.0 {
                return v / l;
            }
        }
    }

    /// A random rotation.
    pub fn quat(&mut self) -> Quat {
        Quat::from_axis_angle(self.unit(), self.next() * 6.0)
    }
}

/// A Carom vector as parry3d's.
pub fn pv(v: Vec3) -> PVec3 {
    let a = vec3_to_f64(v);
    PVec3::new(a[0] as f32, a[1] as f32, a[2] as f32)
}

/// A Carom pose as parry3d's.
#[allow(clippy::unnecessary_cast)] // a no-op in the f32 build, a conversion in the f64 build
pub fn pp(p: &Isometry) -> PPose {
    let q = p.rotation.to_array().map(|x| x as f32);
    PPose::from_parts(pv(p.translation), parry3d::math::Rot3::from_array(q))
}
