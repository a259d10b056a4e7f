//! Python bindings of Carom: the extension module `carom._carom`, re-exported by the
//! `carom` package (`python/carom/__init__.py`).
//!
//! The bindings are thin: conversions (`convert`, `pose`), the error mapping and panic guard
//! (`errors`), the shape base class (`shape`) and its subclasses (`shapes`, `composite`),
//! byte encoding for pickling (`serialize`) and parallel batches (`batch`). No Rust panic
//! reaches the interpreter: every call into the core runs under `errors::guard`.

// `f64::from(x)` with `x: Real` is a no-op in the f64 build by design (like `x as Real`).
#![allow(clippy::useless_conversion)]

mod batch;
mod broadphase;
mod collision_world;
mod composite;
mod convert;
mod dynamic_tree;
mod errors;
mod mesh;
mod pose;
mod queries;
mod serialize;
mod shape;
mod shapes;
mod world;
mod world_joints;
mod world_queries;
mod world_snapshot;

use pyo3::prelude::*;

/// Carom's Rust core: shapes, poses and their queries.
#[pymodule]
fn _carom(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("CaromError", py.get_type::<errors::CaromError>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add(
        "REAL_BITS",
        std::mem::size_of::<carom_collision::math::Real>() * 8,
    )?;
    m.add_class::<pose::PyPose>()?;
    m.add_class::<shape::PyShape>()?;
    m.add_class::<shapes::PySphere>()?;
    m.add_class::<shapes::PyBox>()?;
    m.add_class::<shapes::PyCapsule>()?;
    m.add_class::<shapes::PyCylinder>()?;
    m.add_class::<shapes::PyCone>()?;
    m.add_class::<shapes::PyTriangle>()?;
    m.add_class::<shapes::PyPlane>()?;
    m.add_class::<composite::PyConvexHull>()?;
    m.add_class::<composite::PyTriMesh>()?;
    m.add_class::<composite::PyHeightField>()?;
    m.add_class::<composite::PyCompound>()?;
    m.add_class::<composite::PyScaled>()?;
    m.add_class::<mesh::PyMeshRayHits>()?;
    queries::register(m)?;
    m.add_function(wrap_pyfunction!(broadphase::overlapping_pairs, m)?)?;
    m.add_class::<broadphase::PyBroadPhase>()?;
    m.add_class::<dynamic_tree::PyDynamicTree>()?;
    collision_world::register(m)?;
    m.add_class::<world::PyWorld>()?;
    m.add_class::<world_queries::PyWorldRayHit>()?;
    m.add_class::<world_queries::PyWorldShapeCastHit>()?;
    m.add_class::<world_queries::PyWorldContacts>()?;
    Ok(())
}
