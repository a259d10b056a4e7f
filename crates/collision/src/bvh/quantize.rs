//! The quantisation of a static BVH's node boxes: the affine map between world coordinates
//! and the `u16` coordinates of [`super::QuantizedNode`]s (Bullet's `btQuantizedBvh::quantize`
//! and `unQuantize`), conservative in both directions: minima are rounded down and maxima up,
//! so a dequantised box always contains the box that was quantised.

use crate::math::{Aabb, Real, Vec3, EPSILON};
use serde::{Deserialize, Serialize};

/// Largest quantised coordinate used for node boxes (one unit of headroom on each side).
const QUANT_MAX: Real = 65534.0;

/// The affine map between world coordinates and quantised ones.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Quantization {
    /// World point of quantised coordinate 0.
    pub origin: Vec3,
    /// Quantised units per world unit, per axis.
    pub scale: Vec3,
    /// World units per quantised unit.
    pub inv_scale: Vec3,
    /// Outward padding of dequantised boxes covering the rounding of `origin + q * inv_scale`.
    pub dequantize_pad: Vec3,
}

impl Quantization {
    /// The quantisation of `bounds`, grown slightly so every point of it maps strictly inside
    /// `[1, 65534]`.
    pub fn new(bounds: &Aabb) -> Self {
        let size = bounds.extents().max_element();
        let magnitude = bounds.min.abs().max(bounds.max.abs()).max_element();
        let pad = size * 1.0e-3 + magnitude * 16.0 * EPSILON + 1.0e-6;
        let origin = bounds.min - Vec3::splat(pad);
        let extent = bounds.extents() + Vec3::splat(2.0 * pad);
        let scale = Vec3::splat(QUANT_MAX - 1.0) / extent;
        let inv_scale = extent / (QUANT_MAX - 1.0);
        let dequantize_pad = (origin.abs() + extent) * (8.0 * EPSILON) + inv_scale * 0.01;
        Quantization {
            origin,
            scale,
            inv_scale,
            dequantize_pad,
        }
    }

    /// Quantised coordinates of `p` rounded down (`up = false`) or up, with one unit of
    /// margin for rounding, clamped to `u16`.
    ///
    /// The value is clamped to `[0, 65535]` first and then rounded by truncation (a
    /// non-negative value's floor; its ceiling adds one when the truncation is below it):
    /// the same integer as rounding then clamping (both bounds are integers and rounding is
    /// monotone; NaN gives 0 either way), without the `floor`/`ceil` library calls that the
    /// baseline x86-64 target makes (a third of a mesh box query's instructions).
    #[inline]
    pub fn quantize(&self, p: Vec3, up: bool) -> [u16; 3] {
        let x = (p - self.origin) * self.scale;
        let mut out = [0u16; 3];
        for i in 0..3 {
            let slack = 1.0 + x[i].abs() * 4.0 * EPSILON;
            out[i] = if up {
                let c = (x[i] + slack).clamp(0.0, 65535.0);
                let t = c as u16;
                t + u16::from((t as Real) < c)
            } else {
                (x[i] - slack).clamp(0.0, 65535.0) as u16
            };
        }
        out
    }

    /// The world box containing the quantised box `[min, max]`.
    #[inline]
    pub fn dequantize(&self, min: [u16; 3], max: [u16; 3]) -> Aabb {
        let lo = Vec3::new(min[0] as Real, min[1] as Real, min[2] as Real);
        let hi = Vec3::new(max[0] as Real, max[1] as Real, max[2] as Real);
        Aabb::new(
            self.origin + lo * self.inv_scale - self.dequantize_pad,
            self.origin + hi * self.inv_scale + self.dequantize_pad,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rounding `quantize` replaced: `floor`/`ceil`, then the clamp.
    fn quantize_by_floor_ceil(q: &Quantization, p: Vec3, up: bool) -> [u16; 3] {
        let x = (p - q.origin) * q.scale;
        [0, 1, 2].map(|i| {
            let slack = 1.0 + x[i].abs() * 4.0 * EPSILON;
            let v = if up {
                (x[i] + slack).ceil()
            } else {
                (x[i] - slack).floor()
            };
            v.clamp(0.0, 65535.0) as u16
        })
    }

    #[test]
    fn quantize_rounds_like_floor_and_ceil() {
        // Unit scale and origin 0: the quantised coordinate is the point itself (plus or
        // minus the one-unit slack), so integers, half-integers, the clamp bounds, points
        // outside them, NaN and infinities are all hit exactly.
        let unit = Quantization {
            origin: Vec3::ZERO,
            scale: Vec3::ONE,
            inv_scale: Vec3::ONE,
            dequantize_pad: Vec3::ZERO,
        };
        let far = Quantization::new(&Aabb::new(
            Vec3::new(1.0e3, -250.0, -0.5),
            Vec3::new(1.0e3 + 500.0, 37.0, 0.5),
        ));
        let mut values: Vec<Real> = vec![
            0.0,
            -0.0,
            0.5,
            1.0,
            1.5,
            2.0,
            -0.5,
            -1.0,
            -1.5,
            -2.0,
            65533.0,
            65534.0,
            65534.5,
            65535.0,
            65536.0,
            65536.5,
            65537.0,
            1.0e9,
            -1.0e9,
            Real::NAN,
            Real::INFINITY,
            Real::NEG_INFINITY,
            Real::EPSILON,
            1.0 - Real::EPSILON,
            1.0 + Real::EPSILON,
        ];
        let mut seed = 0x2545_f491_u32;
        for _ in 0..20_000 {
            seed ^= seed << 13;
            seed ^= seed >> 17;
            seed ^= seed << 5;
            values.push((seed as Real / u32::MAX as Real) * 70_000.0 - 2_000.0);
        }
        for q in [&unit, &far] {
            for (k, &v) in values.iter().enumerate() {
                let w = values[(k * 7 + 3) % values.len()];
                let p = if std::ptr::eq(q, &far) {
                    // Spread over (and beyond) the far box: world units.
                    Vec3::new(1.0e3 + v * 0.01, v * 0.004 - 250.0, w * 1.0e-5)
                } else {
                    Vec3::new(v, w, -v)
                };
                for up in [false, true] {
                    assert_eq!(
                        q.quantize(p, up),
                        quantize_by_floor_ceil(q, p, up),
                        "{p:?} up {up}"
                    );
                }
            }
        }
    }

    #[test]
    fn quantization_is_conservative() {
        let bounds = Aabb::new(
            Vec3::new(1.0e4, -3.0, 0.0),
            Vec3::new(1.0e4 + 2.0, 5.0, 0.0),
        );
        let q = Quantization::new(&bounds);
        for k in 0..200 {
            let t = k as Real / 199.0;
            let p = bounds.min + bounds.extents() * t;
            let b = Aabb::new(p, p + bounds.extents() * 0.001 * t);
            let d = q.dequantize(q.quantize(b.min, false), q.quantize(b.max, true));
            assert!(d.contains(&b), "{d:?} must contain {b:?}");
        }
    }
}
