//! Between Python and the crates: errors as Python exceptions, JSON values
//! as Python objects and back, and NumPy arrays as images.

use numpy::{Element, PyArray1, PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::{PyMemoryError, PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use serde_json::{Map, Number, Value};
use sfp_core::{Error, Image};
use sfp_reconstruct::solver::memory;

/// A crate error as a Python exception: `OSError` for a file that could not
/// be read or written or holds unusable data, `ValueError` for bad input,
/// `MemoryError` for work too large for the memory there is.
pub fn py_err(e: Error) -> PyErr {
    match e {
        Error::Io { .. } | Error::File { .. } => PyOSError::new_err(e.to_string()),
        Error::Invalid(_) => PyValueError::new_err(e.to_string()),
        Error::Memory(_) => PyMemoryError::new_err(e.to_string()),
    }
}

/// Runs `work` on a rayon pool of its own, as large as the global one
/// (`RAYON_NUM_THREADS`, else the cores) or as fits the address space:
/// calls from several Python threads then run side by side instead of
/// queueing on the one global pool.
pub fn on_own_pool<T: Send>(
    work: impl FnOnce() -> sfp_core::Result<T> + Send,
) -> sfp_core::Result<T> {
    // As many threads as fit the address space (`memory`).
    let threads = memory::fit_to_address_space(rayon::current_num_threads());
    match rayon::ThreadPoolBuilder::new().num_threads(threads).build() {
        Ok(pool) => pool.install(work),
        // No threads to be had: the global pool still works.
        Err(_) => work(),
    }
}

/// A JSON value as the Python object `json.loads` would give.
pub fn to_python<'py>(py: Python<'py>, value: &Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match value {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => PyBool::new(py, *b).to_owned().into_any(),
        Value::Number(n) => match (n.as_i64(), n.as_u64()) {
            (Some(i), _) => i.into_pyobject(py)?.into_any(),
            (None, Some(u)) => u.into_pyobject(py)?.into_any(),
            _ => PyFloat::new(py, n.as_f64().unwrap_or(f64::NAN)).into_any(),
        },
        Value::String(s) => PyString::new(py, s).into_any(),
        Value::Array(items) => {
            let items: Vec<_> = items
                .iter()
                .map(|v| to_python(py, v))
                .collect::<PyResult<_>>()?;
            PyList::new(py, items)?.into_any()
        }
        Value::Object(map) => {
            let dict = PyDict::new(py);
            for (k, v) in map {
                dict.set_item(k, to_python(py, v)?)?;
            }
            dict.into_any()
        }
    })
}

/// Deepest nesting of lists and dicts an option may have: far beyond any
/// method's options, and far below what would exhaust the stack.
pub const MAX_DEPTH: usize = 64;

/// A Python value (number, bool, string, `None`, list, tuple, dict with
/// string keys, or a NumPy array or scalar) as JSON; `name` names the
/// option in errors. A list or dict that contains itself, or nests deeper
/// than [`MAX_DEPTH`], is a `ValueError`.
pub fn from_python(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Value> {
    from_python_within(obj, name, &mut Vec::new())
}

/// [`from_python`] with `open`, the containers being converted around
/// `obj` (outermost first), to find cycles and bound the depth.
fn from_python_within(
    obj: &Bound<'_, PyAny>,
    name: &str,
    open: &mut Vec<*mut pyo3::ffi::PyObject>,
) -> PyResult<Value> {
    if obj.is_none() {
        return Ok(Value::Null);
    }
    // bool before int: Python's bool is an int.
    if obj.is_instance_of::<PyBool>() {
        return Ok(Value::Bool(obj.extract()?));
    }
    if obj.is_instance_of::<PyInt>() {
        return match obj.extract::<i64>() {
            Ok(i) => Ok(i.into()),
            Err(_) => Err(PyValueError::new_err(format!(
                "{name}: {obj} does not fit a 64-bit integer"
            ))),
        };
    }
    if obj.is_instance_of::<PyFloat>() {
        let x: f64 = obj.extract()?;
        return Number::from_f64(x)
            .map(Value::Number)
            .ok_or_else(|| PyValueError::new_err(format!("{name}: {x} is not a finite number")));
    }
    if obj.is_instance_of::<PyString>() {
        return Ok(Value::String(obj.extract()?));
    }
    let is_sequence = obj.is_instance_of::<PyList>() || obj.is_instance_of::<PyTuple>();
    let dict = obj.cast::<PyDict>().ok();
    if is_sequence || dict.is_some() {
        if open.contains(&obj.as_ptr()) {
            return Err(PyValueError::new_err(format!("{name}: contains itself")));
        }
        if open.len() >= MAX_DEPTH {
            return Err(PyValueError::new_err(format!(
                "{name}: nested deeper than {MAX_DEPTH} levels"
            )));
        }
        open.push(obj.as_ptr());
        let value = match dict {
            Some(dict) => dict_from_python(dict, name, open),
            None => list_from_python(obj, name, open),
        };
        open.pop();
        return value;
    }
    // NumPy arrays and scalars: their Python equivalent.
    if obj.hasattr("tolist")? {
        return from_python_within(&obj.call_method0("tolist")?, name, open);
    }
    Err(PyValueError::new_err(format!(
        "{name}: a {} is not a number, bool, string, list or dict",
        obj.get_type().name()?
    )))
}

fn list_from_python(
    obj: &Bound<'_, PyAny>,
    name: &str,
    open: &mut Vec<*mut pyo3::ffi::PyObject>,
) -> PyResult<Value> {
    let mut items = Vec::new();
    for (i, item) in obj.try_iter()?.enumerate() {
        items.push(from_python_within(&item?, &format!("{name}[{i}]"), open)?);
    }
    Ok(Value::Array(items))
}

fn dict_from_python(
    dict: &Bound<'_, PyDict>,
    name: &str,
    open: &mut Vec<*mut pyo3::ffi::PyObject>,
) -> PyResult<Value> {
    let mut map = Map::new();
    for (k, v) in dict.iter() {
        let key: String = k
            .extract()
            .map_err(|_| PyValueError::new_err(format!("{name}: key {k} is not a string")))?;
        let value = from_python_within(&v, &format!("{name}.{key}"), open)?;
        map.insert(key, value);
    }
    Ok(Value::Object(map))
}

/// `obj` as a C-contiguous NumPy array of `dtype` (`float32`, `bool`,
/// `uint16`) with `ndim` dimensions; `what` names it in errors.
pub fn array<'py, T: Element>(
    obj: &Bound<'py, PyAny>,
    dtype: &str,
    ndim: usize,
    what: &str,
) -> PyResult<Bound<'py, PyArrayDyn<T>>> {
    let numpy = obj.py().import("numpy")?;
    let converted = numpy
        .call_method1("ascontiguousarray", (obj, dtype))
        .map_err(|e| PyValueError::new_err(format!("{what}: not an array of numbers: {e}")))?;
    let arr = converted.cast_into::<PyArrayDyn<T>>()?;
    if arr.ndim() != ndim {
        return Err(PyValueError::new_err(format!(
            "{what}: expected {ndim} dimensions, got shape {:?}",
            arr.shape()
        )));
    }
    Ok(arr)
}

/// The elements of a C-contiguous array.
pub fn elements<T: Element + Copy>(arr: &Bound<'_, PyArrayDyn<T>>) -> PyResult<Vec<T>> {
    arr.to_vec()
        .map_err(|e| PyValueError::new_err(format!("array not contiguous: {e}")))
}

/// `data` (row-major) as a read-only NumPy array of `shape`.
pub fn numpy<'py, T: Element>(
    py: Python<'py>,
    data: Vec<T>,
    shape: &[usize],
) -> PyResult<Bound<'py, PyArrayDyn<T>>> {
    let arr = PyArray1::from_vec(py, data).reshape(shape)?;
    let kwargs = PyDict::new(py);
    kwargs.set_item("write", false)?;
    arr.call_method("setflags", (), Some(&kwargs))?;
    Ok(arr)
}

/// An image as a read-only (H, W) array.
pub fn image_array<'py, T: Element + Copy>(
    py: Python<'py>,
    img: &Image<T>,
) -> PyResult<Bound<'py, PyArrayDyn<T>>> {
    numpy(py, img.data().to_vec(), &[img.height(), img.width()])
}

/// A normal map as a read-only (H, W, 3) array.
pub fn normals_array<'py>(
    py: Python<'py>,
    normals: &sfp_core::NormalMap,
) -> PyResult<Bound<'py, PyArrayDyn<f32>>> {
    let data = normals.data().iter().flatten().copied().collect();
    numpy(py, data, &[normals.height(), normals.width(), 3])
}

/// A (H, W, 3) array as a normal map; `what` names it in errors.
pub fn normal_map(obj: &Bound<'_, PyAny>, what: &str) -> PyResult<sfp_core::NormalMap> {
    let arr = array::<f32>(obj, "float32", 3, what)?;
    let shape = arr.shape().to_vec();
    if shape[2] != 3 {
        return Err(PyValueError::new_err(format!(
            "{what}: expected shape (H, W, 3), got {shape:?}"
        )));
    }
    let data = elements(&arr)?;
    let pixels = data.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    Image::from_vec(shape[1], shape[0], pixels).map_err(py_err)
}

/// A (H, W) array as an image of `dtype`; `what` names it in errors.
pub fn image<T: Element + Copy>(
    obj: &Bound<'_, PyAny>,
    dtype: &str,
    what: &str,
) -> PyResult<Image<T>> {
    let arr = array::<T>(obj, dtype, 2, what)?;
    let shape = arr.shape().to_vec();
    Image::from_vec(shape[1], shape[0], elements(&arr)?).map_err(py_err)
}
