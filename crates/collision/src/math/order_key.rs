//! Order-preserving integer keys for floats (Terdiman, "Radix Sort Revisited", 2000): the
//! broadphase sorts and compares box bounds as `u32` keys, rounded outwards to `f32` so the
//! `f64` build stays conservative.

use super::Real;

/// Maps an `f32` to a `u32` with the same order (`a < b` ⇔ `key(a) < key(b)`; `-0 < +0`).
/// NaN must not be passed (the broadphase rejects it at input).
#[inline]
pub fn f32_to_ordered(x: f32) -> u32 {
    let b = x.to_bits();
    if b & 0x8000_0000 != 0 {
        !b
    } else {
        b | 0x8000_0000
    }
}

/// The largest `f32` below a finite `f`.
#[inline]
fn next_down(f: f32) -> f32 {
    if f == 0.0 {
        -f32::from_bits(1)
    } else if f > 0.0 {
        f32::from_bits(f.to_bits() - 1)
    } else {
        f32::from_bits(f.to_bits() + 1)
    }
}

/// A `u32` order key of `x` rounded *down* to `f32`: `key ≤ key(y)` for every `y ≥ x`, so a
/// sweep over these keys never skips a true overlap, in the `f64` build too.
#[inline]
pub fn real_floor_key(x: Real) -> u32 {
    #[allow(clippy::unnecessary_cast)]
    let f = x as f32;
    let f = if (f as Real) > x { next_down(f) } else { f };
    f32_to_ordered(f)
}

/// A `u32` order key of `x` rounded *up* to `f32`.
#[inline]
pub fn real_ceil_key(x: Real) -> u32 {
    #[allow(clippy::unnecessary_cast)]
    let f = x as f32;
    let f = if (f as Real) < x { -next_down(-f) } else { f };
    f32_to_ordered(f)
}

/// The value (as [`Real`]) of an order key from [`f32_to_ordered`].
#[inline]
pub fn ordered_to_real(k: u32) -> Real {
    let bits = if k & 0x8000_0000 != 0 {
        k & 0x7FFF_FFFF
    } else {
        !k
    };
    f32::from_bits(bits) as Real
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn float_keys_preserve_order() {
        let xs: [f32; 9] = [-1e30, -2.5, -1.0, -1e-30, -0.0, 0.0, 1e-30, 3.0, 1e30];
        for w in xs.windows(2) {
            assert!(f32_to_ordered(w[0]) < f32_to_ordered(w[1]), "{w:?}");
        }
        let x: Real = 0.1;
        assert!(real_floor_key(x) <= real_ceil_key(x));
        assert!(real_floor_key(x) <= f32_to_ordered(0.1));
    }

    #[test]
    fn round_trip() {
        // Values representable in f32 round-trip exactly.
        for x in [-3.5, 0.0, 0.5, 1024.0, -65536.0] {
            assert_eq!(ordered_to_real(real_floor_key(x)), x);
        }
        // Others (in the f64 build) are bracketed: floor key <= x <= ceil key.
        for x in [1e-20, 7.25e10, -0.1] {
            assert!(
                ordered_to_real(real_floor_key(x)) <= x && x <= ordered_to_real(real_ceil_key(x))
            );
        }
    }
}
