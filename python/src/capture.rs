//! Views from files and from a camera's raw data: `read_view` (a view
//! folder), `read_layout` (the per-angle layout of `sfp export`),
//! `import_angles` and `import_mosaic` (`reconstruct::capture_import`, the
//! import `sfp import` runs, with every option of it).

use crate::convert::{image, on_own_pool, py_err};
use crate::view::PyView;
use pyo3::exceptions::{PyUserWarning, PyValueError};
use pyo3::prelude::*;
use sfp_core::Image;
use sfp_core::capture::angle_frame::AngleFrame;
use sfp_core::capture::frame::Frame;
use sfp_core::capture::import::{ImportOptions, Source};
use sfp_core::capture::mosaic::Demosaic;
use sfp_core::capture::{MaskSource, read_mask};
use sfp_core::export::read_layout as layout;
use sfp_core::prediction::Axes;
use sfp_core::view::View;
use sfp_reconstruct::capture_import;
use std::ffi::CString;
use std::path::PathBuf;

/// read_view(path) -> View: a view folder (conventions.md §5).
#[pyfunction]
pub fn read_view(py: Python<'_>, path: PathBuf) -> PyResult<PyView> {
    let view = py.detach(|| View::read(&path)).map_err(py_err)?;
    PyView::from_view(py, &view, &[])
}

/// read_layout(path, name=None, axes="ours") -> View: one view of a per-angle
/// layout folder (`pol000/ pol045/ pol090/ pol135/`, optional `mask/`,
/// `normal/`) as `sfp export VIEW --out LAYOUT` writes it or SfPUEL
/// publishes it (RGB images read as luminance); `name` (the file name
/// without .png) is needed when it holds several; `axes` is the frame of its
/// normals (`ours`, `image`: y down, `opencv`: y down and z into the scene).
#[pyfunction]
#[pyo3(signature = (path, name=None, axes="ours"))]
pub fn read_layout(
    py: Python<'_>,
    path: PathBuf,
    name: Option<String>,
    axes: &str,
) -> PyResult<PyView> {
    let axes = Axes::parse(axes).ok_or_else(|| {
        PyValueError::new_err(format!("axes {axes:?}: one of {}", Axes::NAMES.join(", ")))
    })?;
    let view = py
        .detach(|| layout(&path, name.as_deref(), axes))
        .map_err(py_err)?;
    for problem in &view.problems {
        let message = CString::new(problem.as_str()).unwrap_or_default();
        PyErr::warn(py, py.get_type::<PyUserWarning>().as_any(), &message, 1)?;
    }
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
                "{what}: expected a uint8 or uint16 array of sensor codes or the path of a \
                 PNG, got {}; float images make a View(images) directly",
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

/// A frame given as the path of a PNG (read, and recorded by its path, as
/// `sfp import` does) or as an array of codes (named `what`).
fn frame(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<Frame> {
    if let Ok(path) = obj.extract::<PathBuf>() {
        return Frame::read(&path).map_err(py_err);
    }
    let (image, bits) = codes(obj, what)?;
    Ok(Frame {
        colour: None,
        path: PathBuf::from(what),
        image,
        bits,
    })
}

fn optional_frame(obj: Option<&Bound<'_, PyAny>>, what: &str) -> PyResult<Option<Frame>> {
    obj.filter(|o| !o.is_none())
        .map(|o| frame(o, what))
        .transpose()
}

/// The mask choice of `sfp import`: a mask (array or PNG path), an
/// intensity window, the automatic mask, or none of them.
fn mask_source(
    mask: Option<&Bound<'_, PyAny>>,
    window: Option<(f64, f64)>,
    auto_mask: bool,
) -> PyResult<MaskSource> {
    let mask = mask.filter(|m| !m.is_none());
    let given =
        usize::from(mask.is_some()) + usize::from(window.is_some()) + usize::from(auto_mask);
    if given > 1 {
        return Err(PyValueError::new_err(
            "give one of mask, window and auto_mask=True",
        ));
    }
    Ok(match (mask, window) {
        (Some(m), _) => match m.extract::<PathBuf>() {
            Ok(path) => MaskSource::File(read_mask(&path).map_err(py_err)?),
            Err(_) => MaskSource::File(image::<bool>(m, "bool", "mask")?),
        },
        (None, Some((low, high))) => MaskSource::Window(low, high),
        (None, None) if auto_mask => MaskSource::Auto,
        (None, None) => MaskSource::All,
    })
}

fn angle_frame(angles_from: &str) -> PyResult<AngleFrame> {
    match angles_from {
        "horizontal-ccw" => Ok(AngleFrame::HorizontalCcw),
        "vertical-cw" => Ok(AngleFrame::VerticalCw),
        other => Err(PyValueError::new_err(format!(
            "angles_from={other:?}: expected \"horizontal-ccw\" or \"vertical-cw\""
        ))),
    }
}

/// The import `sfp import` runs, its warnings raised as `UserWarning`s.
fn import(
    py: Python<'_>,
    source: Source,
    options: ImportOptions,
    out: Option<PathBuf>,
) -> PyResult<PyView> {
    let (imported, warnings) = py
        .detach(|| {
            on_own_pool(|| {
                let mut warnings = Vec::new();
                let mut warn = |w: String| warnings.push(w);
                let imported =
                    capture_import::import(&source, &options, out.as_deref(), &mut warn)?;
                Ok((imported, warnings))
            })
        })
        .map_err(py_err)?;
    for warning in warnings {
        let message = CString::new(warning).expect("a warning has no NUL");
        PyErr::warn(py, py.get_type::<PyUserWarning>().as_any(), &message, 1)?;
    }
    PyView::from_view(py, &imported.view, &[])
}

/// import_angles(i0, i45, i90, i135, mask=None, sensor_bits=None, window=None,
/// auto_mask=False, dark=None, flat=None, angles_from="horizontal-ccw", out=None) -> View
///
/// Four polarizer images (uint8 or uint16 sensor codes, (H, W), or paths
/// of PNGs) labelled 0°, 45°, 90°, 135° in the frame `angles_from`, as
/// `sfp import --angles` takes them, with its options: the object `mask`
/// (array or PNG), an intensity `window` (low, high) or `auto_mask`; a
/// `dark` frame and a `flat` field (arrays or PNGs of each image's size);
/// `sensor_bits`. Saturated pixels leave the mask; the labels are checked
/// against the data (`meta["pattern_check"]`); warnings are `UserWarning`s.
/// `out`: the view folder is written there, as `sfp import --out` writes it.
#[pyfunction]
#[pyo3(signature = (i0, i45, i90, i135, mask=None, sensor_bits=None, window=None,
    auto_mask=false, dark=None, flat=None, angles_from="horizontal-ccw", out=None))]
#[allow(clippy::too_many_arguments)]
pub fn import_angles(
    py: Python<'_>,
    i0: &Bound<'_, PyAny>,
    i45: &Bound<'_, PyAny>,
    i90: &Bound<'_, PyAny>,
    i135: &Bound<'_, PyAny>,
    mask: Option<&Bound<'_, PyAny>>,
    sensor_bits: Option<u8>,
    window: Option<(f64, f64)>,
    auto_mask: bool,
    dark: Option<&Bound<'_, PyAny>>,
    flat: Option<&Bound<'_, PyAny>>,
    angles_from: &str,
    out: Option<PathBuf>,
) -> PyResult<PyView> {
    let mut frames = Vec::with_capacity(4);
    for (obj, what) in [(i0, "i0"), (i45, "i45"), (i90, "i90"), (i135, "i135")] {
        frames.push(frame(obj, what)?);
    }
    let options = ImportOptions {
        angles_from: angle_frame(angles_from)?,
        mask: mask_source(mask, window, auto_mask)?,
        dark: optional_frame(dark, "dark")?,
        flat: optional_frame(flat, "flat")?,
        sensor_bits,
        ..ImportOptions::default()
    };
    let source = Source::Angles(Box::new(frames.try_into().expect("four frames")));
    import(py, source, options, out)
}

/// import_mosaic(raw, pattern="90,45,135,0", demosaic="superpixel", mask=None,
/// sensor_bits=None, window=None, auto_mask=False, dark=None, flat=None,
/// angles_from="horizontal-ccw", out=None) -> View
///
/// The raw frame (uint8 or uint16, (H, W), or the path of a PNG) of a
/// division-of-focal-plane polarization camera, as `sfp import --mosaic`
/// takes it: `pattern` lists the polarizer angles of a 2×2 cell in reading
/// order (the default is the Sony IMX250MZR's), measured in the frame
/// `angles_from`; `demosaic` is `"superpixel"` (half resolution) or
/// `"bilinear"`. A mask must have the size of the demosaiced images; dark
/// frame and flat field the raw frame's. The other options are
/// `import_angles`'.
#[pyfunction]
#[pyo3(signature = (raw, pattern="90,45,135,0", demosaic="superpixel", mask=None,
    sensor_bits=None, window=None, auto_mask=false, dark=None, flat=None,
    angles_from="horizontal-ccw", out=None))]
#[allow(clippy::too_many_arguments)]
pub fn import_mosaic(
    py: Python<'_>,
    raw: &Bound<'_, PyAny>,
    pattern: &str,
    demosaic: &str,
    mask: Option<&Bound<'_, PyAny>>,
    sensor_bits: Option<u8>,
    window: Option<(f64, f64)>,
    auto_mask: bool,
    dark: Option<&Bound<'_, PyAny>>,
    flat: Option<&Bound<'_, PyAny>>,
    angles_from: &str,
    out: Option<PathBuf>,
) -> PyResult<PyView> {
    let demosaic = match demosaic {
        "superpixel" => Demosaic::SuperPixel,
        "bilinear" => Demosaic::Bilinear,
        other => {
            return Err(PyValueError::new_err(format!(
                "demosaic={other:?}: expected \"superpixel\" or \"bilinear\""
            )));
        }
    };
    let options = ImportOptions {
        pattern: pattern.to_string(),
        demosaic,
        angles_from: angle_frame(angles_from)?,
        mask: mask_source(mask, window, auto_mask)?,
        dark: optional_frame(dark, "dark")?,
        flat: optional_frame(flat, "flat")?,
        sensor_bits,
        ..ImportOptions::default()
    };
    import(py, Source::Mosaic(frame(raw, "raw")?), options, out)
}
