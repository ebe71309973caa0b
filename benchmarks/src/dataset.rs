//! A dataset of views on disk (`sfp reconstruct DATASET`, a sweep's folder
//! source): finding its views, and running methods over every one of them
//! into one result folder per view and method (`OUT/<view folder>/<method>/`).
//! Each run gives a [`Row`] and, when it ran, a [`Timing`], the records a
//! sweep keeps, so that the same tables draw them ([`crate::report::summary`]).
//! A run that fails is recorded with its message and the others go on.

use crate::row::{Estimates, Row, Timing};
use sfp_core::folder;
use sfp_core::view::View;
use sfp_core::{Error, Result};
use sfp_reconstruct::input::Input;
use sfp_reconstruct::methods::MethodConfig;
use sfp_reconstruct::registry;
use sfp_renderer::dataset_index::{self, DatasetIndex};
use std::path::{Path, PathBuf};

/// One view of a dataset.
#[derive(Clone, Debug, PartialEq)]
pub struct DatasetView {
    /// Folder name inside the dataset (and of its results under the output).
    pub folder: String,
    /// The object it shows.
    pub object: String,
    pub dir: PathBuf,
}

impl DatasetView {
    /// A lone view folder as a dataset's view, named after the folder
    /// (`view` when the path has no name).
    pub fn lone(dir: &Path) -> DatasetView {
        let folder = std::fs::canonicalize(dir)
            .ok()
            .and_then(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
            .unwrap_or_else(|| "view".to_string());
        DatasetView {
            object: object_of_folder(&folder).to_string(),
            folder,
            dir: dir.to_path_buf(),
        }
    }
}

/// What a path given to `sfp reconstruct` is.
#[derive(Clone, Debug, PartialEq)]
pub enum Target {
    /// A view folder (it has `input/`).
    View,
    /// A dataset: its views, in the order of `dataset.json` or by folder name.
    Dataset(Vec<DatasetView>),
}

/// A folder with `input/` is a view; one with `dataset.json` (conventions.md
/// §5) is a dataset of the views it lists; one holding view folders is a
/// dataset of those. Anything else is an error naming `path`.
pub fn classify(path: &Path) -> Result<Target> {
    if !path.is_dir() {
        return Err(Error::file(
            path,
            "not a folder (expected a view folder with input/ or a dataset folder)",
        ));
    }
    if folder::is_view(path) {
        return Ok(Target::View);
    }
    if path.join(dataset_index::FILE).is_file() {
        return Ok(Target::Dataset(read_index(path)?));
    }
    let mut views = Vec::new();
    let entries = std::fs::read_dir(path).map_err(|e| Error::read(path, e))?;
    for entry in entries {
        let dir = entry.map_err(|e| Error::io(path, e))?.path();
        if folder::is_view(&dir)
            && let Some(folder) = dir.file_name().and_then(|n| n.to_str())
        {
            views.push(DatasetView {
                folder: folder.to_string(),
                object: object_of_folder(folder).to_string(),
                dir: dir.clone(),
            });
        }
    }
    if views.is_empty() {
        return Err(Error::file(
            path,
            "neither a view (no input/) nor a dataset (no dataset.json, no view folders with input/)",
        ));
    }
    views.sort_by(|a, b| a.folder.cmp(&b.folder));
    Ok(Target::Dataset(views))
}

/// The views listed in `dataset.json` (`views[].folder`, `views[].object`).
fn read_index(root: &Path) -> Result<Vec<DatasetView>> {
    let index = DatasetIndex::read(root)?;
    let views = index
        .views
        .into_iter()
        .map(|v| DatasetView {
            object: v
                .object
                .unwrap_or_else(|| object_of_folder(&v.folder).to_string()),
            dir: root.join(&v.folder),
            folder: v.folder,
        })
        .collect();
    Ok(views)
}

/// The object of a view folder named `<object>_<k>`: the name without a
/// trailing `_` and digits (the whole name when there is none).
pub fn object_of_folder(folder: &str) -> &str {
    match folder.rsplit_once('_') {
        Some((object, k))
            if !object.is_empty() && !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit()) =>
        {
            object
        }
        _ => folder,
    }
}

/// What [`run_all`] gave: one row per (view, method) in that order, and the
/// times of the runs that ran.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Runs {
    pub rows: Vec<Row>,
    pub timings: Vec<Timing>,
}

/// Runs every method on every view of `dataset`, writing
/// `out/<view folder>/<method>/`, and calls `progress(done, total, what)`
/// before each run and once at the end. A view that cannot be read fails all
/// its runs with that message.
pub fn run_all(
    dataset: &str,
    views: &[DatasetView],
    methods: &[MethodConfig],
    out: &Path,
    progress: &dyn Fn(usize, usize, &str),
) -> Runs {
    let total = views.len() * methods.len();
    let mut runs = Runs::default();
    for v in views {
        // Read and prepared once for every method.
        let view = View::read(&v.dir)
            .and_then(|view| Input::from_view(&view.input).map(|input| (view, input)));
        for method in methods {
            progress(
                runs.rows.len(),
                total,
                &format!("{}: {}", v.folder, method.name()),
            );
            let key = format!("{}/{}", v.folder, method.name());
            let dir = out.join(&v.folder).join(method.name());
            let outcome = view
                .as_ref()
                .map_err(|e| e.to_string())
                .and_then(|(view, input)| {
                    registry::run_with_input(view, input, method, &dir).map_err(|e| e.to_string())
                });
            let (metrics, estimates, error) = match outcome {
                Ok(outcome) => {
                    let meta = view.as_ref().ok().and_then(|(v, _)| v.meta.as_ref());
                    let estimates = Estimates::of(&outcome.reconstruction.run, meta);
                    runs.timings.push(Timing {
                        key: key.clone(),
                        method: method.name().to_string(),
                        pixels: outcome.pixels,
                        noise_seconds: 0.0,
                        reconstruct_seconds: outcome.seconds,
                        overhead_seconds: 0.0,
                    });
                    (outcome.metrics, estimates, None)
                }
                Err(e) => (None, None, Some(e)),
            };
            runs.rows.push(Row {
                key: key.clone(),
                dataset: dataset.to_string(),
                view: v.folder.clone(),
                object: v.object.clone(),
                axes: Default::default(),
                method: method.name().to_string(),
                config: method.to_value(),
                seed: 0,
                metrics,
                estimates,
                exit_status: None,
                stderr_tail: None,
                pictures: error.is_none().then_some(key),
                error,
                view_dir: v.dir.display().to_string(),
            });
        }
    }
    progress(total, total, "done");
    runs
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn objects_are_folder_names_without_the_view_number() {
        assert_eq!(object_of_folder("cup_0"), "cup");
        assert_eq!(object_of_folder("bunny_head_012"), "bunny_head");
        assert_eq!(object_of_folder("plain"), "plain");
        assert_eq!(object_of_folder("a_b"), "a_b");
        assert_eq!(object_of_folder("_3"), "_3");
    }

    #[test]
    fn neither_view_nor_dataset_is_an_error_naming_the_path() {
        let dir = tempfile::tempdir().unwrap();
        let empty = dir.path().join("empty_thing");
        std::fs::create_dir(&empty).unwrap();
        let err = classify(&empty).unwrap_err().to_string();
        assert!(
            err.contains("empty_thing") && err.contains("dataset"),
            "{err}"
        );
        std::fs::create_dir_all(empty.join("v_1/input")).unwrap();
        std::fs::create_dir_all(empty.join("v_0/input")).unwrap();
        match classify(&empty).unwrap() {
            Target::Dataset(views) => {
                let names: Vec<_> = views.iter().map(|v| (&*v.folder, &*v.object)).collect();
                assert_eq!(names, [("v_0", "v"), ("v_1", "v")]);
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(classify(&empty.join("v_0")).unwrap(), Target::View);
    }
}
