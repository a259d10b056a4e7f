use pyo3::prelude::*;
#[pymodule]
fn _carom(_m: &Bound<'_, PyModule>) -> PyResult<()> {
    Ok(())
}
