//! Views from files and from a camera's raw data: `read_view` (a view
//! folder), `read_layout` (the per-angle layout of `sfp export`),
//! `import_angles` and `import_mosaic` (`core::capture`, `core::mosaic`, as
//! `sfp import` does).

use crate::convert::{image, py_err};
use crate::view::PyView;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use serde_json::json;
use sfp_core::Image;
use sfp_core::capture::{MaskSource, view_from_images};
use sfp_core::export::read_layout as layout;
use sfp_core::capture::mosaic::{Demosaic, Pattern, demosaic as split};
use sfp_core::view::{Meta, View};
use std::path::PathBuf;

/// read_view(path) -> View: a view folder (conventions.md §5).
#[pyfunction]
pub fn read_view(py: Python<'_>, path: PathBuf) -> PyResult<PyView> {
    let view = py.detach(|| View::read(&path)).map_err(py_err)?;
    PyView::from_view(py, &view, &[])
}

/// read_layout(path, name=None) -> View: one view of a per-angle layout
/// folder (`pol000/ pol045/ pol090/ pol135/`, optional `mask/`, `normal/`)
/// as `sfp export VIEW --out LAYOUT` writes it; `name` (the file name
/// without .png) is needed when it holds several.
#[pyfunction]
#[pyo3(signature = (path, name=None))]
pub fn read_layout(py: Python<'_>, path: PathBuf, name: Option<String>) -> PyResult<PyView> {
    let view = py
        .detach(|| layout(&path, name.as_deref()))
        .map_err(py_err)?;
    PyView::from_view(py, &view, &[])
}

/// Sensor codes: a uint8 or uint16 array (H, W) and its bit depth.
fn codes(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<(Image<u16>, u8)> {
    let dtype = obj
        .getattr("dtype")
        .and_then(|d| d.getattr("name"))
        .and_then(|n| n.extract::<String>())
        .unwrap_or_default();
    let bits = match dtype.as_str() {
        "uint8" => 8,
        "uint16" => 16,
        other => {
            return Err(PyValueError::new_err(format!(
                "{what}: expected a uint8 or uint16 array of sensor codes, got {}; \
                 float images make a View(images) directly",
                if other.is_empty() {
                    "no NumPy array"
                } else {
                    other
                }
            )));
        }
    };
    Ok((image::<u16>(obj, "uint16", what)?, bits))
}

fn mask_source(mask: Option<&Bound<'_, PyAny>>) -> PyResult<MaskSource> {
    Ok(match mask.filter(|m| !m.is_none()) {
        Some(m) => MaskSource::File(image::<bool>(m, "bool", "mask")?),
        None => MaskSource::All,
    })
}

/// The view of four polarizer images, checked as `sfp import` checks them.
fn import(
    py: Python<'_>,
    pol: [Image<u16>; 4],
    bits: u8,
    sensor_bits: Option<u8>,
    mask: MaskSource,
    record: serde_json::Value,
) -> PyResult<PyView> {
    let mut meta = Meta::new("polar_sfp import");
    meta.extra.insert("capture".into(), record);
    if let Some(b) = sensor_bits {
        meta.extra.insert("sensor_bits".into(), json!(b));
    }
    let (view, _) = py
        .detach(|| view_from_images(pol, bits, sensor_bits, &mask, meta))
        .map_err(py_err)?;
    PyView::from_view(py, &view, &[])
}

/// import_angles(i0, i45, i90, i135, mask=None, sensor_bits=None) -> View
///
/// Four polarizer images (uint8 or uint16 sensor codes, (H, W), polarizer
/// at 0°, 45°, 90°, 135° from image right counter-clockwise). Saturated
/// pixels leave the mask; the labels are checked against the data (the
/// figures in `meta["pattern_check"]`).
#[pyfunction]
#[pyo3(signature = (i0, i45, i90, i135, mask=None, sensor_bits=None))]
#[allow(clippy::too_many_arguments)]
pub fn import_angles(
    py: Python<'_>,
    i0: &Bound<'_, PyAny>,
    i45: &Bound<'_, PyAny>,
    i90: &Bound<'_, PyAny>,
    i135: &Bound<'_, PyAny>,
    mask: Option<&Bound<'_, PyAny>>,
    sensor_bits: Option<u8>,
) -> PyResult<PyView> {
    let mut pol = Vec::with_capacity(4);
    let mut depth = None;
    for (obj, what) in [(i0, "i0"), (i45, "i45"), (i90, "i90"), (i135, "i135")] {
        let (img, bits) = codes(obj, what)?;
        if depth.is_some_and(|d| d != bits) {
            return Err(PyValueError::new_err(format!(
                "{what}: {bits}-bit codes, but i0 holds {}-bit codes",
                depth.unwrap_or(bits)
            )));
        }
        depth = Some(bits);
        pol.push(img);
    }
    let pol: [Image<u16>; 4] = pol.try_into().expect("four images");
    let bits = depth.unwrap_or(16);
    import(
        py,
        pol,
        bits,
        sensor_bits,
        mask_source(mask)?,
        json!({ "angles": "arrays" }),
    )
}

/// import_mosaic(raw, pattern="90,45,135,0", demosaic="superpixel", mask=None, sensor_bits=None) -> View
///
/// The raw frame (uint8 or uint16, (H, W)) of a division-of-focal-plane
/// polarization camera: `pattern` lists the polarizer angles of a 2×2 cell
/// in reading order (the default is the Sony IMX250MZR's); `demosaic` is
/// `"superpixel"` (half resolution) or `"bilinear"`. A mask must have the
/// size of the demosaiced images.
#[pyfunction]
#[pyo3(signature = (raw, pattern="90,45,135,0", demosaic="superpixel", mask=None, sensor_bits=None))]
pub fn import_mosaic(
    py: Python<'_>,
    raw: &Bound<'_, PyAny>,
    pattern: &str,
    demosaic: &str,
    mask: Option<&Bound<'_, PyAny>>,
    sensor_bits: Option<u8>,
) -> PyResult<PyView> {
    let (frame, bits) = codes(raw, "raw")?;
    let cell = Pattern::parse(pattern).map_err(py_err)?;
    let method = match demosaic {
        "superpixel" => Demosaic::SuperPixel,
        "bilinear" => Demosaic::Bilinear,
        other => {
            return Err(PyValueError::new_err(format!(
                "demosaic={other:?}: expected \"superpixel\" or \"bilinear\""
            )));
        }
    };
    let pol = split(&frame, cell, method).map_err(py_err)?;
    let record = json!({ "mosaic": "array", "pattern": pattern, "demosaic": demosaic });
    import(py, pol, bits, sensor_bits, mask_source(mask)?, record)
}
