//! `View`: the polarizer images of one view as float32 in units of the
//! sensor's full scale, its mask, its ground-truth normals and `meta.json`
//! (conventions.md §5), immutable once made.

use crate::convert::{
    array, elements, image, image_array, normal_map, normals_array, numpy, py_err, to_python,
};
use numpy::{PyArrayDyn, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use sfp_core::provenance::ViewRecord;
use sfp_core::stokes::{Polarimetry, stokes_from_four};
use sfp_core::view::{GroundTruth, View};
use sfp_core::{Image, Mask};

/// One polarization view.
///
/// `images`: float32 (4, H, W), the intensities behind the polarizer at 0°,
/// 45°, 90° and 135° (angles from image right, counter-clockwise;
/// conventions.md §1), in units of the sensor's full scale for views read,
/// rendered or imported. `mask`: bool (H, W) object pixels, or None (a
/// reconstruction then takes every lit pixel). `normals`: float32 (H, W, 3)
/// ground-truth unit normals in the camera frame (x right, y up, z towards
/// the camera; zero outside the object), or None. `meta`: the view's
/// `meta.json` as a dict. `colour`: float32 (4, 3, H, W), the R, G, B
/// intensities behind each polarizer of a colour view (its `images` are
/// their Rec. 709 luminance, what the methods read), or None. The arrays
/// are read-only.
#[pyclass(name = "View", module = "polar_sfp", frozen)]
pub struct PyView {
    pub pol: [Image<f32>; 4],
    pub mask: Option<Mask>,
    /// Ground truth: from arrays the normals alone; from a view folder
    /// also what scores a specular labelling.
    pub gt: Option<GroundTruth>,
    /// The view's record in `run.json` (folder, input hash), when it came
    /// from a view of the crates rather than from arrays.
    pub record: Option<ViewRecord>,
    images_array: Py<PyArrayDyn<f32>>,
    mask_array: Option<Py<PyArrayDyn<bool>>>,
    normals_array: Option<Py<PyArrayDyn<f32>>>,
    colour_array: Option<Py<PyArrayDyn<f32>>>,
    meta: Py<PyDict>,
}

impl PyView {
    /// From images, mask and normals checked to agree in size.
    fn build(
        py: Python<'_>,
        pol: [Image<f32>; 4],
        mask: Option<Mask>,
        gt: Option<GroundTruth>,
        meta: Bound<'_, PyDict>,
        record: Option<ViewRecord>,
    ) -> PyResult<PyView> {
        let (w, h) = pol[0].size();
        if w == 0 || h == 0 {
            return Err(PyValueError::new_err("images: the view has no pixels"));
        }
        let sizes = [
            ("mask", mask.as_ref().map(Image::size)),
            ("normals", gt.as_ref().map(|g| g.normals.size())),
        ];
        for (what, size) in sizes {
            if let Some((mw, mh)) = size.filter(|&s| s != (w, h)) {
                return Err(PyValueError::new_err(format!(
                    "{what}: {mh}×{mw} pixels but the images are {h}×{w} (rows × columns)"
                )));
            }
        }
        let data: Vec<f32> = pol.iter().flat_map(|p| p.data().iter().copied()).collect();
        Ok(PyView {
            images_array: numpy(py, data, &[4, h, w])?.unbind(),
            mask_array: mask
                .as_ref()
                .map(|m| image_array(py, m))
                .transpose()?
                .map(Bound::unbind),
            normals_array: gt
                .as_ref()
                .map(|g| normals_array(py, &g.normals))
                .transpose()?
                .map(Bound::unbind),
            colour_array: None,
            meta: meta.unbind(),
            pol,
            mask,
            gt,
            record,
        })
    }

    /// A view of the crates: codes scaled to the full scale as the methods
    /// see them (`ViewInput::polarimetry`), so a reconstruction from these
    /// floats equals one from the folder.
    pub fn from_view(
        py: Python<'_>,
        view: &View,
        extra: &[(&str, serde_json::Value)],
    ) -> PyResult<PyView> {
        let k = 1.0 / view.input.full_scale();
        let pol = view
            .input
            .pol
            .each_ref()
            .map(|p| p.map(|&c| f32::from(c) * k));
        let mut meta = match &view.meta {
            Some(m) => serde_json::to_value(m).expect("meta serialises"),
            None => serde_json::json!({}),
        };
        for (key, value) in extra {
            meta[*key] = value.clone();
        }
        let meta = to_python(py, &meta)?.cast_into::<PyDict>()?;
        let mut built = Self::build(
            py,
            pol,
            view.input.mask.clone(),
            view.gt.clone(),
            meta,
            Some(ViewRecord::of(view)),
        )?;
        if let Some(rgb) = &view.input.colour {
            let (w, h) = view.input.size();
            let data = rgb
                .iter()
                .flat_map(|p| (0..3).flat_map(move |c| p.data().iter().map(move |v| v[c])))
                .map(|v| f32::from(v) * k)
                .collect();
            built.colour_array = Some(numpy(py, data, &[4, 3, h, w])?.unbind());
        }
        Ok(built)
    }

    /// The pixels a reconstruction is scored over: the mask, or the ground
    /// truth's non-zero normals (as `View::scored_mask`).
    pub fn scored_mask(&self) -> Option<Mask> {
        self.gt.as_ref().map(|gt| {
            self.mask
                .clone()
                .unwrap_or_else(|| gt.normals.map(|n| *n != [0.0; 3]))
        })
    }

    /// Stokes `s0, s1, s2` of the four images (conventions.md §2).
    pub fn stokes_images(&self) -> sfp_core::Result<[Image<f32>; 3]> {
        stokes_from_four(&self.pol)
    }

    pub fn polarimetry(&self) -> sfp_core::Result<Polarimetry> {
        Ok(Polarimetry::from_stokes(&self.stokes_images()?))
    }
}

#[pymethods]
impl PyView {
    /// View(images, mask=None, normals=None, meta=None): a view from arrays.
    #[new]
    #[pyo3(signature = (images, mask=None, normals=None, meta=None))]
    pub fn py_new(
        py: Python<'_>,
        images: &Bound<'_, PyAny>,
        mask: Option<&Bound<'_, PyAny>>,
        normals: Option<&Bound<'_, PyAny>>,
        meta: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<PyView> {
        let arr = array::<f32>(images, "float32", 3, "images")?;
        let shape = arr.shape().to_vec();
        if shape[0] != 4 {
            return Err(PyValueError::new_err(format!(
                "images: expected shape (4, H, W) (0°, 45°, 90°, 135°), got {shape:?}"
            )));
        }
        let (h, w) = (shape[1], shape[2]);
        if h == 0 || w == 0 {
            return Err(PyValueError::new_err(format!(
                "images: shape {shape:?} has no pixels (expected (4, H, W) with H, W >= 1)"
            )));
        }
        let data = elements(&arr)?;
        let mut planes = data.chunks_exact(h * w);
        let mut plane = || -> PyResult<Image<f32>> {
            let p = planes.next().unwrap_or(&[]);
            Image::from_vec(w, h, p.to_vec()).map_err(py_err)
        };
        let pol = [plane()?, plane()?, plane()?, plane()?];
        let mask = mask
            .filter(|m| !m.is_none())
            .map(|m| image::<bool>(m, "bool", "mask"))
            .transpose()?;
        let gt = normals
            .filter(|n| !n.is_none())
            .map(|n| normal_map(n, "normals").map(GroundTruth::of_normals))
            .transpose()?;
        let meta = match meta {
            Some(m) => m.copy()?,
            None => PyDict::new(py),
        };
        Self::build(py, pol, mask, gt, meta, None)
    }

    /// float32 (4, H, W): intensities behind the polarizer at 0°, 45°, 90°, 135°.
    #[getter]
    fn images(&self, py: Python<'_>) -> Py<PyArrayDyn<f32>> {
        self.images_array.clone_ref(py)
    }

    /// bool (H, W): the object pixels, or None.
    #[getter]
    fn mask(&self, py: Python<'_>) -> Option<Py<PyArrayDyn<bool>>> {
        self.mask_array.as_ref().map(|m| m.clone_ref(py))
    }

    /// float32 (H, W, 3): ground-truth normals (camera frame), or None.
    #[getter]
    fn normals(&self, py: Python<'_>) -> Option<Py<PyArrayDyn<f32>>> {
        self.normals_array.as_ref().map(|n| n.clone_ref(py))
    }

    /// float32 (4, 3, H, W): R, G, B behind each polarizer of a colour view, or None.
    #[getter]
    fn colour(&self, py: Python<'_>) -> Option<Py<PyArrayDyn<f32>>> {
        self.colour_array.as_ref().map(|c| c.clone_ref(py))
    }

    /// The view's `meta.json` as a dict (empty when it has none).
    #[getter]
    fn meta(&self, py: Python<'_>) -> Py<PyDict> {
        self.meta.clone_ref(py)
    }

    /// float32 (3, H, W): the Stokes images s0, s1, s2 (conventions.md §2).
    fn stokes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
        let s = self.stokes_images().map_err(py_err)?;
        let (w, h) = s[0].size();
        let data = s.iter().flat_map(|p| p.data().iter().copied()).collect();
        numpy(py, data, &[3, h, w])
    }

    /// float32 (H, W): the degree of linear polarization in [0, 1].
    fn dop<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
        image_array(py, &self.polarimetry().map_err(py_err)?.dop)
    }

    /// float32 (H, W): the angle of polarization in [0, π), radians, from
    /// image right counter-clockwise.
    fn aop<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
        image_array(py, &self.polarimetry().map_err(py_err)?.aop)
    }

    fn __repr__(&self) -> String {
        let (w, h) = self.pol[0].size();
        let mask = self.mask.as_ref().map_or("no mask".to_string(), |m| {
            format!("{} mask pixels", m.count())
        });
        let normals = if self.gt.is_some() { "with" } else { "without" };
        let colour = if self.colour_array.is_some() {
            "colour, "
        } else {
            ""
        };
        format!("View({w}×{h}, {colour}{mask}, {normals} ground truth)")
    }
}
