//! `reconstruct`, `methods` and `evaluate`: the registry's methods and the
//! metrics of conventions.md §4 on arrays. Options go through
//! `MethodConfig::with_options`, the path of `sfp reconstruct --set`, so a
//! method takes exactly the options it declares.

use crate::convert::{
    from_python, image, image_array, normal_map, normals_array, on_own_pool, py_err, to_python,
};
use crate::view::PyView;
use numpy::PyArrayDyn;
use pyo3::exceptions::{PyUserWarning, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use sfp_core::metrics::evaluate as score;
use sfp_core::provenance::ViewRecord;
use sfp_reconstruct::input::Input;
use sfp_reconstruct::methods::{ABOUT, MethodConfig, options_of};
use sfp_reconstruct::registry;
use std::ffi::CString;

/// What `reconstruct` returns.
///
/// `normals`: float32 (H, W, 3) unit normals in the camera frame (zero
/// outside the mask); `height`: float32 (H, W), relative height along +z in
/// pixel units, NaN outside the mask; `info`: what `run.json` holds (the
/// method and every option, time, view, software, the method's record);
/// `metrics`: the figures of `metrics.json` when the view has ground truth,
/// else None.
#[pyclass(name = "Result", module = "polar_sfp", frozen)]
pub struct PyReconstruction {
    #[pyo3(get)]
    normals: Py<PyArrayDyn<f32>>,
    #[pyo3(get)]
    height: Py<PyArrayDyn<f32>>,
    #[pyo3(get)]
    info: Py<PyAny>,
    #[pyo3(get)]
    metrics: Option<Py<PyAny>>,
}

#[pymethods]
impl PyReconstruction {
    fn __repr__(&self, py: Python<'_>) -> String {
        let method = self
            .info
            .bind(py)
            .get_item("config")
            .and_then(|c| c.get_item("method"))
            .map_or("?".into(), |m| m.to_string());
        format!("Result(method={method})")
    }
}

/// reconstruct(view_or_images, mask=None, method="smsfp", **options) -> Result
///
/// Reconstructs normals and height from a View or from images (4, H, W)
/// with an optional bool mask (H, W). Every option of the method is
/// accepted by name (`methods()` lists them); an unknown one raises
/// ValueError. The GIL is released while the method runs, on a thread pool
/// of its own (as large as `RAYON_NUM_THREADS` or the cores). What the
/// method found the data leave undetermined (`info["warnings"]`) is also
/// raised as a `UserWarning` each, as `sfp reconstruct` prints it.
#[pyfunction]
#[pyo3(signature = (view_or_images, mask=None, method="smsfp", **options))]
pub fn reconstruct(
    py: Python<'_>,
    view_or_images: &Bound<'_, PyAny>,
    mask: Option<&Bound<'_, PyAny>>,
    method: &str,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<PyReconstruction> {
    let mask = mask.filter(|m| !m.is_none());
    let view = match view_or_images.cast::<PyView>() {
        Ok(_) if mask.is_some() => {
            return Err(PyValueError::new_err(
                "mask: a View carries its own mask; pass images to give one",
            ));
        }
        Ok(view) => view.clone(),
        Err(_) => Bound::new(py, PyView::py_new(py, view_or_images, mask, None, None)?)?,
    };
    let mut map = serde_json::Map::new();
    if let Some(options) = options {
        for (key, value) in options.iter() {
            let key: String = key.extract()?;
            let value = from_python(&value, &key)?;
            map.insert(key, value);
        }
    }
    let config = configure(method, map)?;
    let v = view.get();
    let (w, h) = v.pol[0].size();
    // Arrays have no folder and no sensor codes to hash.
    let record = v.record.clone().unwrap_or(ViewRecord {
        path: None,
        input_hash: String::new(),
        size: [w, h],
    });
    let scored_mask = v.scored_mask();
    let gt = v.gt.as_ref().zip(scored_mask.as_ref());
    let outcome = py
        .detach(|| {
            on_own_pool(|| {
                let input = Input::new(v.polarimetry()?, v.mask.clone())?;
                registry::reconstruct_scored(&input, &config, gt, Some(record))
            })
        })
        .map_err(py_err)?;
    let metrics = match &outcome.metrics {
        Some(m) => {
            let m = serde_json::to_value(m).expect("metrics serialise");
            Some(to_python(py, &m)?.unbind())
        }
        None => None,
    };
    let mut info = serde_json::to_value(&outcome.record).expect("run record serialises");
    if v.record.is_none() {
        info["view"]["input_hash"] = serde_json::Value::Null;
    }
    let reconstruction = outcome.reconstruction;
    for warning in &reconstruction.run.warnings {
        let message = CString::new(warning.as_str()).expect("a warning has no NUL");
        PyErr::warn(py, py.get_type::<PyUserWarning>().as_any(), &message, 1)?;
    }
    Ok(PyReconstruction {
        normals: normals_array(py, &reconstruction.normals)?.unbind(),
        height: image_array(py, &reconstruction.height)?.unbind(),
        info: to_python(py, &info)?.unbind(),
        metrics,
    })
}

/// The method `name` with `options`; when they are refused, the error names
/// the first option refused alone (serde names a wrong type, not its field).
fn configure(
    name: &str,
    options: serde_json::Map<String, serde_json::Value>,
) -> PyResult<MethodConfig> {
    MethodConfig::with_options(name, options.clone()).map_err(|e| {
        let culprit = options.into_iter().find_map(|(key, value)| {
            let alone = serde_json::Map::from_iter([(key.clone(), value)]);
            MethodConfig::with_options(name, alone)
                .err()
                .map(|e| (key, e))
        });
        match culprit {
            Some((key, e)) => PyValueError::new_err(format!("option {key}: {e}")),
            None => py_err(e),
        }
    })
}

/// methods() -> dict: every method by name with its display name, paper,
/// ablation switches and options (`{name: {"default": …, "doc": …}}`).
#[pyfunction]
pub fn methods(py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
    let all = PyDict::new(py);
    for about in ABOUT {
        let options = PyDict::new(py);
        for o in options_of(about.name).unwrap_or_default() {
            let entry = PyDict::new(py);
            entry.set_item("default", to_python(py, &o.default)?)?;
            entry.set_item("doc", o.doc)?;
            options.set_item(o.name, entry)?;
        }
        let entry = PyDict::new(py);
        entry.set_item("display", about.display)?;
        entry.set_item("paper", about.paper)?;
        let ablations: Vec<&str> = about.ablations.iter().map(|a| a.option).collect();
        entry.set_item("ablations", PyList::new(py, ablations)?)?;
        entry.set_item("options", options)?;
        all.set_item(about.name, entry)?;
    }
    Ok(all)
}

/// frame_fit(normals, mask) -> (as_read, y_negated) or None: how well the
/// normals (H, W, 3) point out of the bool mask (H, W) along its outline,
/// as the mean cosine between their in-plane direction and the outward
/// one, read as they are and with y negated (an occluding contour's
/// normals point outwards; a reader in the wrong y sense shows as a low
/// first figure and a high second one).
#[pyfunction]
pub fn frame_fit(
    normals: &Bound<'_, PyAny>,
    mask: &Bound<'_, PyAny>,
) -> PyResult<Option<(f64, f64)>> {
    let normals = normal_map(normals, "normals")?;
    let mask = image::<bool>(mask, "bool", "mask")?;
    if normals.size() != mask.size() {
        return Err(PyValueError::new_err(format!(
            "normals are {:?} pixels, the mask {:?}",
            normals.size(),
            mask.size()
        )));
    }
    Ok(sfp_core::prediction::frame_fit(&normals, &mask))
}

/// evaluate(normals, gt, mask) -> dict: the angular-error figures of
/// `metrics.json` (conventions.md §4) of normals (H, W, 3) against gt
/// (H, W, 3) over the bool mask (H, W).
#[pyfunction]
pub fn evaluate<'py>(
    py: Python<'py>,
    normals: &Bound<'py, PyAny>,
    gt: &Bound<'py, PyAny>,
    mask: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyAny>> {
    let pred = normal_map(normals, "normals")?;
    let gt = normal_map(gt, "gt")?;
    let mask = image::<bool>(mask, "bool", "mask")?;
    let m = score(&pred, &gt, &mask).map_err(py_err)?;
    to_python(py, &serde_json::to_value(m).expect("metrics serialise"))
}
