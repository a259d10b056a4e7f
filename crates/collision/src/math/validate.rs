//! Input validation helpers shared by every constructor. Each returns a [`CaromError`]
//! naming the argument and its value.

use super::{Aabb, Isometry, Quat, Real, Vec3};
use crate::error::{CaromError, Result};

/// Checks that `x` is finite.
pub fn check_finite(name: &str, x: Real) -> Result<Real> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(CaromError::invalid(name, x, "must be finite"))
    }
}

/// Checks that `x` is finite and strictly positive.
pub fn check_positive(name: &str, x: Real) -> Result<Real> {
    if x.is_finite() && x > 0.0 {
        Ok(x)
    } else {
        Err(CaromError::invalid(name, x, "must be finite and > 0"))
    }
}

/// Checks that `x` is finite and non-negative.
pub fn check_non_negative(name: &str, x: Real) -> Result<Real> {
    if x.is_finite() && x >= 0.0 {
        Ok(x)
    } else {
        Err(CaromError::invalid(name, x, "must be finite and >= 0"))
    }
}

/// Checks that every component of `v` is finite.
pub fn check_finite_vec(name: &str, v: Vec3) -> Result<Vec3> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(CaromError::invalid(name, v, "components must be finite"))
    }
}

/// Checks that every component of `v` is finite and strictly positive.
pub fn check_positive_vec(name: &str, v: Vec3) -> Result<Vec3> {
    if v.is_finite() && v.min_element() > 0.0 {
        Ok(v)
    } else {
        Err(CaromError::invalid(
            name,
            v,
            "components must be finite and > 0",
        ))
    }
}

/// Tolerance on `|q| - 1` accepted for a rotation quaternion before it is rejected.
pub const UNIT_QUAT_TOLERANCE: Real = 1.0e-3;

/// Checks that `q` is finite and of unit length (within [`UNIT_QUAT_TOLERANCE`]), and returns
/// it renormalised.
pub fn check_unit_quat(name: &str, q: Quat) -> Result<Quat> {
    if !q.is_finite() {
        return Err(CaromError::invalid(name, q, "components must be finite"));
    }
    let len = q.length();
    if (len - 1.0).abs() > UNIT_QUAT_TOLERANCE {
        return Err(CaromError::invalid(
            name,
            q,
            format!("must be a unit quaternion (x, y, z, w); its length is {len}"),
        ));
    }
    // Renormalise only when the length is off by more than round-off: dividing an already
    // unit quaternion by its computed length can change its last bit, so validating twice
    // would not give the same rotation (a restored snapshot re-encoded differently).
    if (len - 1.0).abs() <= 4.0 * Real::EPSILON {
        return Ok(q);
    }
    Ok(q / len)
}

/// Checks a pose: finite translation and unit rotation (renormalised).
pub fn check_isometry(name: &str, iso: Isometry) -> Result<Isometry> {
    // The field names are formatted only on failure: this runs on every pose update, and two
    // `format!`s cost ~1500 instructions and two allocations per call.
    let translation = match check_finite_vec(name, iso.translation) {
        Ok(t) => t,
        Err(_) => {
            return check_finite_vec(&format!("{name}.translation"), iso.translation).map(|_| iso)
        }
    };
    let rotation = match check_unit_quat(name, iso.rotation) {
        Ok(q) => q,
        Err(_) => return check_unit_quat(&format!("{name}.rotation"), iso.rotation).map(|_| iso),
    };
    Ok(Isometry {
        rotation,
        translation,
    })
}

/// Rejects NaN, infinite or inverted boxes, naming the bad value.
pub fn check_aabb(aabb: &Aabb) -> Result<()> {
    if !aabb.min.is_finite() || !aabb.max.is_finite() {
        return Err(CaromError::invalid("aabb", aabb, "bounds must be finite"));
    }
    if !aabb.min.cmple(aabb.max).all() {
        return Err(CaromError::invalid("aabb", aabb, "min must be <= max"));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_bad_values_and_names_them() {
        let e = check_positive("radius", -1.0).unwrap_err();
        assert!(e.to_string().contains("radius") && e.to_string().contains("-1"));
        assert!(check_positive("r", Real::NAN).is_err());
        assert!(check_positive("r", Real::INFINITY).is_err());
        assert!(check_positive("r", 0.0).is_err());
        assert!(check_non_negative("r", 0.0).is_ok());
        assert!(check_finite_vec("v", Vec3::new(0.0, Real::NAN, 0.0)).is_err());
        assert!(check_unit_quat("q", Quat::from_xyzw(0.0, 0.0, 0.0, 2.0)).is_err());
        let q = check_unit_quat("q", Quat::from_xyzw(0.0, 0.0, 0.0, 1.0 + 1e-4)).unwrap();
        assert!((q.length() - 1.0).abs() < 1e-6);
    }
}
