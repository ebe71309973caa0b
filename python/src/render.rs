//! `render` and `dataset`: the path tracer's views in memory, for notebooks
//! and training loops (the renderer's scene files and presets,
//! scenes/README.md).

use crate::convert::{on_own_pool, py_err};
use crate::view::PyView;
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use serde_json::json;
use sfp_core::Error;
use sfp_renderer::dataset::Dataset;
use sfp_renderer::dataset::PlannedView;
use sfp_renderer::render::{RenderOptions, Rendered, render_until};
use sfp_renderer::scene::Scene;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// How often a render looks for Ctrl-C.
const SIGNAL_POLL: Duration = Duration::from_millis(50);

/// Renders on a thread of its own while this one, holding the GIL between
/// naps, asks Python for pending signals: Ctrl-C (or any signal handler
/// that raises) stops the render within a row and raises here, where a
/// long call into Rust would otherwise let Python see it only at the end.
fn trace(py: Python<'_>, scene: &Scene, options: &RenderOptions) -> PyResult<Rendered> {
    let stop = AtomicBool::new(false);
    std::thread::scope(|s| {
        let worker = s.spawn(|| on_own_pool(|| render_until(scene, options, &|_, _| {}, &stop)));
        while !worker.is_finished() {
            py.detach(|| std::thread::sleep(SIGNAL_POLL));
            if let Err(signal) = py.check_signals() {
                stop.store(true, Ordering::Relaxed);
                // The render ends within a row; its "stopped" error is
                // replaced by the signal's exception.
                let _ = worker.join();
                return Err(signal);
            }
        }
        worker
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
            .map_err(py_err)
    })
}

/// A scene given as a path or as TOML text: a `str` holding `=` or a line
/// break is text, any other `str` or path-like is a file.
fn load_scene(scene: &Bound<'_, PyAny>) -> PyResult<Scene> {
    if let Ok(text) = scene.extract::<String>()
        && (text.contains('=') || text.contains('\n'))
    {
        // Relative file names in the text are relative to the working folder.
        return Scene::from_toml(&text, Path::new("<scene text>")).map_err(|e| match e {
            Error::File { .. } => PyValueError::new_err(e.to_string()),
            other => py_err(other),
        });
    }
    let path: PathBuf = scene
        .extract()
        .map_err(|_| PyValueError::new_err("scene: expected a path or TOML text"))?;
    Scene::load(&path).map_err(py_err)
}

/// The size argument: N for N×N or (width, height).
fn size_of(size: Option<&Bound<'_, PyAny>>) -> PyResult<Option<(usize, usize)>> {
    let Some(size) = size.filter(|s| !s.is_none()) else {
        return Ok(None);
    };
    if let Ok(n) = size.extract::<usize>() {
        return Ok(Some((n, n)));
    }
    size.extract::<(usize, usize)>().map(Some).map_err(|_| {
        PyValueError::new_err(format!("size: expected N or (width, height), got {size}"))
    })
}

/// render(scene, spp=None, seed=None, size=None) -> View
///
/// Path-traces a scene file (a path) or TOML text (scenes/README.md);
/// `spp`, `seed` and `size` (N or (width, height)) override the scene's.
/// The GIL is released while rendering; Ctrl-C stops the render.
#[pyfunction]
#[pyo3(signature = (scene, spp=None, seed=None, size=None))]
pub fn render(
    py: Python<'_>,
    scene: &Bound<'_, PyAny>,
    spp: Option<u32>,
    seed: Option<u64>,
    size: Option<&Bound<'_, PyAny>>,
) -> PyResult<PyView> {
    let mut scene = load_scene(scene)?;
    scene
        .override_settings(spp, seed, size_of(size)?)
        .map_err(py_err)?;
    let rendered = trace(py, &scene, &RenderOptions::default())?;
    PyView::from_view(py, &rendered.view, &[])
}

/// The views of a dataset preset, rendered one at a time as they are asked
/// for (`len()` tells how many). Each view's `meta` adds `name` (its folder
/// name in `sfp dataset`), `object` and `view_index`.
#[pyclass(name = "DatasetViews", module = "polar_sfp")]
pub struct DatasetViews {
    plan: Vec<PlannedView>,
    next: usize,
}

#[pymethods]
impl DatasetViews {
    fn __iter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    fn __len__(&self) -> usize {
        self.plan.len()
    }

    fn __next__(&mut self, py: Python<'_>) -> PyResult<Option<PyView>> {
        let Some(v) = self.plan.get(self.next).cloned() else {
            return Ok(None);
        };
        self.next += 1;
        let options = RenderOptions {
            view_index: v.view_index,
        };
        let rendered = trace(py, &v.scene, &options)?;
        let extra = [
            ("name", json!(v.folder)),
            ("object", json!(v.object)),
            ("view_index", json!(v.view_index)),
        ];
        PyView::from_view(py, &rendered.view, &extra).map(Some)
    }
}

/// dataset(preset, size=None, views=None, seed=None, spp=None, svbrdf=False, textured=False)
///
/// The views of a dataset preset (`builtin`, `a`, `b`, or a preset .toml
/// file) as `sfp dataset` renders them, rendered lazily: iterate it in a
/// training loop. `views` is views per object; `size` the image side.
#[pyfunction]
#[pyo3(signature = (preset, size=None, views=None, seed=None, spp=None, svbrdf=false, textured=false))]
#[allow(clippy::too_many_arguments)]
pub fn dataset(
    preset: &str,
    size: Option<usize>,
    views: Option<usize>,
    seed: Option<u64>,
    spp: Option<u32>,
    svbrdf: bool,
    textured: bool,
) -> PyResult<DatasetViews> {
    let path = Path::new(preset);
    let mut dataset = if path.extension().is_some() {
        Dataset::load(path).map_err(py_err)?
    } else {
        Dataset::preset(preset).map_err(py_err)?
    };
    dataset
        .override_settings(views, size, spp, seed)
        .map_err(py_err)?;
    dataset.desc.dataset.svbrdf |= svbrdf;
    dataset.desc.dataset.textured |= textured;
    let plan = dataset.plan().map_err(|e| match e {
        Error::Io { .. } => PyOSError::new_err(e.to_string()),
        other => py_err(other),
    })?;
    Ok(DatasetViews { plan, next: 0 })
}
