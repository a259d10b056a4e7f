//! Snapshots of `carom.World`: a short header holding the `dt` of `step()`, then
//! `carom_dynamics::World::to_bytes` (which has its own header, version and checksum).
//! Decoded shapes are re-checked by `serialize::validate_shape`.

use crate::convert::scalar;
use crate::errors::{core, invalid};
use carom_collision::math::Real;
use carom_dynamics::World;
use pyo3::prelude::*;

/// Header of `World.to_bytes()`: a tag, then the `dt` of `step()` (f64 LE), then the core
/// snapshot.
const PY_MAGIC: &[u8] = b"CAROMPYWORLD\x01";

pub(crate) fn decode(data: &[u8]) -> PyResult<(World, Real)> {
    let rest = data.strip_prefix(PY_MAGIC).ok_or_else(|| {
        invalid("invalid carom world snapshot: missing header (not bytes made by World.to_bytes())")
    })?;
    if rest.len() < 8 {
        return Err(invalid(format!(
            "invalid carom world snapshot: truncated ({} bytes)",
            data.len()
        )));
    }
    let mut dt = [0u8; 8];
    dt.copy_from_slice(&rest[..8]);
    let dt = f64::from_le_bytes(dt);
    let dt_r = scalar("snapshot dt", dt)?;
    if !(dt_r > 0.0 && dt_r.is_finite()) {
        return Err(invalid(format!("invalid carom world snapshot: dt = {dt}")));
    }
    let world = core(|| World::from_bytes_with(&rest[8..], crate::serialize::validate_shape))?;
    Ok((world, dt_r))
}

/// The bytes of `World.to_bytes()`.
pub(crate) fn encode(world: &World, dt: Real) -> PyResult<Vec<u8>> {
    let core_bytes = core(|| world.to_bytes())?;
    let mut out = PY_MAGIC.to_vec();
    out.extend_from_slice(&f64::from(dt).to_le_bytes());
    out.extend_from_slice(&core_bytes);
    Ok(out)
}
