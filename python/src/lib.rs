//! `polar_sfp._native`: the crates' views, renderer, methods and metrics on
//! NumPy arrays for the `polar_sfp` Python package (python/polar_sfp).
//! Every error is a Python exception naming the problem (`convert::py_err`);
//! rendering and reconstruction release the GIL.

mod capture;
mod convert;
mod reconstruct;
mod render;
mod view;

use pyo3::prelude::*;

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // An import error naming what the processor lacks, not a crash later.
    if let Some(refusal) = sfp_core::instruction_set::refusal() {
        return Err(pyo3::exceptions::PyImportError::new_err(refusal));
    }
    m.add_class::<view::PyView>()?;
    m.add_class::<reconstruct::PyReconstruction>()?;
    m.add_class::<render::DatasetViews>()?;
    m.add_function(wrap_pyfunction!(capture::read_view, m)?)?;
    m.add_function(wrap_pyfunction!(capture::read_layout, m)?)?;
    m.add_function(wrap_pyfunction!(capture::import_angles, m)?)?;
    m.add_function(wrap_pyfunction!(capture::import_mosaic, m)?)?;
    m.add_function(wrap_pyfunction!(reconstruct::reconstruct, m)?)?;
    m.add_function(wrap_pyfunction!(reconstruct::methods, m)?)?;
    m.add_function(wrap_pyfunction!(reconstruct::evaluate, m)?)?;
    m.add_function(wrap_pyfunction!(reconstruct::frame_fit, m)?)?;
    m.add_function(wrap_pyfunction!(render::render, m)?)?;
    m.add_function(wrap_pyfunction!(render::dataset, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
