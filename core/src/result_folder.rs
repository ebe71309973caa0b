//! A reconstruction folder on disk (conventions.md §5), as `View` is a view
//! folder: the one place that knows its file names, for the method that
//! writes it and for `sfp eval`, `sfp export` and the report that read it.
//!
//! ```text
//! <result>/
//!   normals.exr    float RGB = (n_x, n_y, n_z), 0 where the method gave none
//!   normals.png    the normals for people, (n+1)/2 as RGB, with the key
//!   height.exr     float Z, integrated height
//!   mesh.ply       the height as a triangle mesh
//!   segments.png   a method's own pictures (SMSfP's, named below)
//!   metrics.json   figures of §4, when the view has ground truth
//!   error.png      the angular error per pixel, same condition
//!   run.json       the run record, written last: a complete result
//! ```
//!
//! Putting a whole new folder in place of an old one is `folder::replace`'s
//! job; this type writes and reads the files inside.

use crate::legend::{Legend, with_legend};
use crate::metrics::{ERROR_LEGEND, Metrics, error_map};
use crate::{Error, Image, Mask, NormalMap, Result, colormap, io, ply};
use serde::Serialize;
use serde::de::DeserializeOwned;
use std::path::{Path, PathBuf};

const NORMALS: &str = "normals.exr";
const NORMALS_PICTURE: &str = "normals.png";
const HEIGHT: &str = "height.exr";
const MESH: &str = "mesh.ply";
const METRICS: &str = "metrics.json";
const ERROR_PICTURE: &str = "error.png";
const RUN: &str = "run.json";

/// The reconstruction folder at a path (which need not exist yet).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ResultFolder {
    dir: PathBuf,
}

impl ResultFolder {
    /// SMSfP's segmentation over the intensity, the picture the report and
    /// the demo show beside the normals.
    pub const SEGMENTS: &'static str = "segments.png";
    /// SMSfP's segment ids as 16-bit values.
    pub const LABELS: &'static str = "labels.png";
    /// SMSfP's solve regions over the intensity.
    pub const REGIONS: &'static str = "regions.png";
    /// The pixels a method read as specular (the `specular` option).
    pub const SPECULAR: &'static str = "specular.png";
    /// The specular share of `s0` per pixel a method estimated (float EXR,
    /// channel `Y`).
    pub const SPECULAR_SHARE: &'static str = "specular.exr";

    pub fn new(dir: impl Into<PathBuf>) -> ResultFolder {
        ResultFolder { dir: dir.into() }
    }

    /// True when `dir` holds a reconstruction, complete or not: its
    /// `run.json` or its `normals.exr` exists.
    pub fn is_result(dir: &Path) -> bool {
        dir.join(RUN).is_file() || dir.join(NORMALS).is_file()
    }

    pub fn normals_path(&self) -> PathBuf {
        self.dir.join(NORMALS)
    }

    pub fn height_path(&self) -> PathBuf {
        self.dir.join(HEIGHT)
    }

    pub fn mesh_path(&self) -> PathBuf {
        self.dir.join(MESH)
    }

    pub fn run_path(&self) -> PathBuf {
        self.dir.join(RUN)
    }

    /// A method's own picture, by one of the names above.
    pub fn picture_path(&self, name: &str) -> PathBuf {
        self.dir.join(name)
    }

    /// Writes `normals.exr` and its picture `normals.png`.
    pub fn write_normals(&self, normals: &NormalMap) -> Result<()> {
        io::write_normals(&self.normals_path(), normals)?;
        io::write_png_rgb(
            &self.dir.join(NORMALS_PICTURE),
            &with_legend(
                &normals.map(|&n| colormap::normal_rgb(n)),
                &Legend::NormalKey,
            ),
        )
    }

    pub fn read_normals(&self) -> Result<NormalMap> {
        io::read_normals(&self.normals_path())
    }

    pub fn write_height(&self, height: &Image<f32>) -> Result<()> {
        io::write_exr(&self.height_path(), &[("Z", height)])
    }

    pub fn read_height(&self) -> Result<Image<f32>> {
        Ok(io::read_exr(&self.height_path(), &["Z"])?.remove(0))
    }

    /// Writes `mesh.ply`: the height over `mask` as a triangle mesh.
    pub fn write_mesh(&self, height: &Image<f32>, mask: &Mask) -> Result<()> {
        ply::write_height_mesh(&self.mesh_path(), height, mask)
    }

    /// Writes the `metrics` of `pred` against `gt` over `mask` as
    /// `metrics.json`, and `error.png` (each pixel's angular error, viridis
    /// over 0–90°, with its colour bar).
    pub fn write_evaluation(
        &self,
        pred: &NormalMap,
        gt: &NormalMap,
        mask: &Mask,
        metrics: &Metrics,
    ) -> Result<()> {
        let json = serde_json::to_vec_pretty(metrics).expect("metrics serialise");
        io::write_atomic(&self.dir.join(METRICS), &json)?;
        let errors = error_map(pred, gt, mask)?;
        let picture = colormap::scalar_preview(&errors, Some(mask), 0.0, 90.0, colormap::viridis);
        io::write_png_rgb(
            &self.dir.join(ERROR_PICTURE),
            &with_legend(&picture, &ERROR_LEGEND),
        )
    }

    /// Writes `run.json`; the last file of a result, since its presence
    /// marks the folder complete.
    pub fn write_run<T: Serialize>(&self, run: &T) -> Result<()> {
        let path = self.run_path();
        let json = serde_json::to_vec_pretty(run)
            .map_err(|e| Error::file(&path, format!("run record not written: {e}")))?;
        io::write_atomic(&path, &json)
    }

    /// The run record, or `None` when the folder has no `run.json` (a
    /// result written by another tool); a `run.json` that cannot be read or
    /// parsed is an error.
    pub fn read_run<T: DeserializeOwned>(&self) -> Result<Option<T>> {
        let path = self.run_path();
        let bytes = match std::fs::read(&path) {
            Ok(bytes) => bytes,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(Error::read(&path, e)),
        };
        serde_json::from_slice(&bytes)
            .map(Some)
            .map_err(|e| Error::file(&path, format!("invalid run.json: {e}")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::metrics::evaluate;

    #[test]
    fn what_is_written_is_read_back_and_marks_a_result() {
        let tmp = tempfile::tempdir().unwrap();
        let folder = ResultFolder::new(tmp.path());
        assert!(!ResultFolder::is_result(tmp.path()));
        assert_eq!(folder.read_run::<serde_json::Value>().unwrap(), None);
        let normals = Image::from_vec(2, 1, vec![[0.0, 0.0, 1.0], [0.0; 3]]).unwrap();
        folder.write_normals(&normals).unwrap();
        assert!(ResultFolder::is_result(tmp.path()));
        assert_eq!(folder.read_normals().unwrap(), normals);
        let height = Image::from_vec(2, 1, vec![1.5, f32::NAN]).unwrap();
        folder.write_height(&height).unwrap();
        assert_eq!(folder.read_height().unwrap().data()[0], 1.5);
        let run = serde_json::json!({ "method": "x" });
        folder.write_run(&run).unwrap();
        assert_eq!(folder.read_run().unwrap(), Some(run));
        std::fs::write(folder.run_path(), "{").unwrap();
        let e = folder
            .read_run::<serde_json::Value>()
            .unwrap_err()
            .to_string();
        assert!(e.contains("invalid run.json"), "{e}");
    }

    #[test]
    fn an_evaluation_writes_its_figures_and_picture() {
        let tmp = tempfile::tempdir().unwrap();
        let folder = ResultFolder::new(tmp.path());
        let gt = Image::new(2, 2, [0.0f32, 0.0, 1.0]);
        let mask = Image::new(2, 2, true);
        let m = evaluate(&gt, &gt, &mask).unwrap();
        folder.write_evaluation(&gt, &gt, &mask, &m).unwrap();
        assert_eq!((m.mae_deg, m.pixels), (0.0, 4));
        let json: Metrics =
            serde_json::from_slice(&std::fs::read(tmp.path().join(METRICS)).unwrap()).unwrap();
        assert_eq!(json, m);
        assert!(tmp.path().join(ERROR_PICTURE).is_file());
    }
}
