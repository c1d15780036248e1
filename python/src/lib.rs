//! `thickness_collision._native`: the library's checker for Python (docs/python.md). The Python
//! package (`python/python/thickness_collision/`) re-exports it with the OMPL helpers beside it.

use pyo3::prelude::*;

mod checker;
mod errors;
mod geometry;
mod positions;
mod report;
mod scene_msgs;

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("Error", m.py().get_type::<errors::Error>())?;
    m.add_class::<checker::Checker>()?;
    m.add_class::<report::Report>()?;
    m.add_class::<report::Contact>()?;
    m.add_class::<report::Clearance>()?;
    m.add_class::<geometry::Scene>()?;
    m.add_function(wrap_pyfunction!(geometry::areas, m)?)?;
    Ok(())
}
