//! Box (cuboid), `carom.Box` in Python.

use super::support::{sign_nonzero, SupportMap};
use super::MassProperties;
use crate::error::{CaromError, Result};
use crate::math::{
    check_non_negative, check_positive_vec, Aabb, Quat, Real, Vec3, Vec3A, Vec3Swizzles,
};
use serde::{Deserialize, Serialize};

/// Default collision margin, Bullet's `CONVEX_DISTANCE_MARGIN` (0.04 length units). Shapes
/// clamp it to a fraction of their smallest dimension so small shapes keep a real core.
pub const DEFAULT_MARGIN: Real = 0.04;

/// Fraction of the smallest half-dimension a default margin may take.
pub(crate) const MAX_MARGIN_FRACTION: Real = 0.2;

/// An axis-aligned box centred at the origin with half extents `half_extents`.
/// The margin lies inside the box: the core is the box shrunk by the margin.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Cuboid {
    half_extents: Vec3,
    margin: Real,
}

impl Cuboid {
    /// A box; every half extent must be finite and > 0. The margin defaults to
    /// `min(DEFAULT_MARGIN, 0.2 · smallest half extent)`.
    pub fn new(half_extents: Vec3) -> Result<Self> {
        let he = check_positive_vec("half_extents", half_extents)?;
        Ok(Cuboid {
            half_extents: he,
            margin: DEFAULT_MARGIN.min(MAX_MARGIN_FRACTION * he.min_element()),
        })
    }

    /// The same box with another margin, in `[0, smallest half extent)`.
    pub fn with_margin(mut self, margin: Real) -> Result<Self> {
        check_non_negative("margin", margin)?;
        if margin >= self.half_extents.min_element() {
            return Err(CaromError::invalid(
                "margin",
                margin,
                format!(
                    "must be smaller than the smallest half extent {}",
                    self.half_extents.min_element()
                ),
            ));
        }
        self.margin = margin;
        Ok(self)
    }

    /// Half extents.
    pub fn half_extents(&self) -> Vec3 {
        self.half_extents
    }

    /// Local bounding box.
    pub fn local_aabb(&self) -> Aabb {
        Aabb::from_center_half_extents(Vec3::ZERO, self.half_extents)
    }

    /// Volume `8 hx hy hz`.
    pub fn volume(&self) -> Real {
        8.0 * self.half_extents.x * self.half_extents.y * self.half_extents.z
    }

    /// Solid box: `Ixx = m (hy² + hz²) / 3`.
    pub fn mass_properties(&self, density: Real) -> MassProperties {
        let m = density * self.volume();
        let h2 = self.half_extents * self.half_extents;
        MassProperties::new(
            m,
            Vec3::ZERO,
            Vec3::new(h2.y + h2.z, h2.x + h2.z, h2.x + h2.y) * (m / 3.0),
        )
    }

    /// The 8 corners; corner `i` has `+x` when bit 0 is set, `+y` bit 1, `+z` bit 2.
    pub fn vertices(&self) -> [Vec3; 8] {
        let h = self.half_extents;
        std::array::from_fn(|i| {
            Vec3::new(
                if i & 1 != 0 { h.x } else { -h.x },
                if i & 2 != 0 { h.y } else { -h.y },
                if i & 4 != 0 { h.z } else { -h.z },
            )
        })
    }
}

impl SupportMap for Cuboid {
    #[inline]
    fn support(&self, dir: Vec3) -> Vec3 {
        Vec3::new(
            sign_nonzero(dir.x),
            sign_nonzero(dir.y),
            sign_nonzero(dir.z),
        ) * self.half_extents
    }
    #[inline]
    fn support_core(&self, dir: Vec3) -> Vec3 {
        Vec3::new(
            sign_nonzero(dir.x),
            sign_nonzero(dir.y),
            sign_nonzero(dir.z),
        ) * (self.half_extents - Vec3::splat(self.margin))
    }
    #[inline]
    fn margin(&self) -> Real {
        self.margin
    }
}

/// The half extents of the world box of a centred box with half extents `h` rotated by the
/// unit quaternion `q`: `|R(q)| h` (Arvo, "Transforming Axis-Aligned Bounding Boxes",
/// Graphics Gems 1990). Bit for bit the value of `Mat3::from_quat(q)` with
/// `|c0| h.x + |c1| h.y + |c2| h.z`, but on SIMD lanes: the nine matrix entries come as
/// three vectors (the diagonal, the sums `xy + wz`… and the differences `xy − wz`… of
/// glam's `from_quat`, with the same operands in the same order), which are blended into
/// the three columns, so the broadphase's per-body sync builds no scalar matrix.
#[inline]
pub(crate) fn rotated_half_extents(q: Quat, h: Vec3) -> Vec3 {
    let v = Vec3A::from(q.xyz());
    let v2 = v + v;
    let sq = v * v2; // (xx, yy, zz)
    let cross = v.yxx() * v2.zzy(); // (yz, xz, xy)
    let wv = v2 * q.w; // (wx, wy, wz), glam's `w * x2` (a product commutes bit for bit)
    let diag = Vec3A::ONE - (sq.yxx() + sq.zzy()); // (1 − (yy + zz), 1 − (xx + zz), 1 − (xx + yy))
    let sum = (cross + wv).abs().yzx(); // |(xz + wy, xy + wz, yz + wx)|
    let diff = (cross - wv).abs().zxy(); // |(xy − wz, yz − wx, xz − wy)|
    let diag = diag.abs();
    // Columns of |R|: c0 = (d.x, sum.y, diff.z), c1 = (diff.x, d.y, sum.z),
    // c2 = (sum.x, diff.y, d.z); lane masks pick the entries.
    let lane = |i: usize| Vec3A::AXES[i].cmpgt(Vec3A::ZERO);
    let (l0, l1, l2) = (lane(0), lane(1), lane(2));
    let c0 = Vec3A::select(l0, diag, Vec3A::select(l1, sum, diff));
    let c1 = Vec3A::select(l1, diag, Vec3A::select(l2, sum, diff));
    let c2 = Vec3A::select(l2, diag, Vec3A::select(l0, sum, diff));
    Vec3::from(c0 * h.x + c1 * h.y + c2 * h.z)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Mat3;

    /// The scalar matrix path this replaces (the oracle).
    fn via_matrix(q: Quat, h: Vec3) -> Vec3 {
        let m = Mat3::from_quat(q);
        m.x_axis.abs() * h.x + m.y_axis.abs() * h.y + m.z_axis.abs() * h.z
    }

    #[test]
    fn rotated_half_extents_match_the_matrix_bit_for_bit() {
        let mut s = 7u64;
        let mut next = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 33) as f64 / (1u64 << 31) as f64) as Real * 2.0 - 1.0
        };
        let mut quats = vec![
            Quat::IDENTITY,
            Quat::from_rotation_x(crate::math::consts::FRAC_PI_2),
            Quat::from_rotation_y(crate::math::consts::PI),
            Quat::from_rotation_z(-crate::math::consts::FRAC_PI_4),
            Quat::from_xyzw(0.0, 0.0, 0.0, -1.0),
            Quat::from_rotation_x(1.0e-7),
        ];
        for _ in 0..2000 {
            let q = Quat::from_xyzw(next(), next(), next(), next());
            if q.length_squared() > 1.0e-6 {
                quats.push(q.normalize());
            }
        }
        let extents = [
            Vec3::new(0.5, 1.0, 2.0),
            Vec3::ZERO,
            Vec3::new(0.0, 3.0, 0.0),
            Vec3::new(1.0e-4, 1.0e4, 0.25),
            Vec3::splat(1.0e6),
        ];
        for &q in &quats {
            for &h in &extents {
                let (got, want) = (rotated_half_extents(q, h), via_matrix(q, h));
                assert_eq!(
                    got.to_array().map(Real::to_bits),
                    want.to_array().map(Real::to_bits),
                    "{q:?} {h:?}"
                );
            }
        }
    }
}
