//! A reconstruction folder on disk (conventions.md §5): `normals.exr`,
//! `normals.png`, `height.exr`, `mesh.ply`, `run.json` and, when the view has
//! ground truth, `metrics.json` and `error.png`. `run.json` is written last, so
//! its presence marks a complete result, and the folder is swapped into
//! place whole ([`folder::replace`]).

use crate::integrate::write_ply;
use crate::method::{Picture, Reconstruction};
use crate::run_record::RunRecord;
use sfp_core::folder::{self, Kind};
use sfp_core::legend::{Legend, with_legend};
use sfp_core::metrics::{Metrics, write_evaluation};
use sfp_core::view::{GroundTruth, write_normals};
use sfp_core::{Mask, Result, colormap, io};
use std::path::Path;

/// Writes `rec` (computed over `mask`) with its `record` as the folder
/// `dir`, replacing a previous result there as a whole; evaluates it
/// against `gt` over the ground-truth mask when given and returns the
/// metrics.
pub fn write_result(
    dir: &Path,
    rec: &Reconstruction,
    record: &RunRecord,
    mask: &Mask,
    gt: Option<(&GroundTruth, &Mask)>,
) -> Result<Option<Metrics>> {
    let mut metrics = None;
    folder::replace(dir, Kind::Result, |d| {
        metrics = write_files(d, rec, record, mask, gt)?;
        Ok(())
    })?;
    Ok(metrics)
}

fn write_files(
    dir: &Path,
    rec: &Reconstruction,
    record: &RunRecord,
    mask: &Mask,
    gt: Option<(&GroundTruth, &Mask)>,
) -> Result<Option<Metrics>> {
    write_normals(&dir.join("normals.exr"), &rec.normals)?;
    io::write_png_rgb(
        &dir.join("normals.png"),
        &with_legend(
            &rec.normals.map(|&n| colormap::normal_rgb(n)),
            &Legend::NormalKey,
        ),
    )?;
    io::write_exr(&dir.join("height.exr"), &[("Z", &rec.height)])?;
    write_ply(&dir.join("mesh.ply"), &rec.height, mask)?;
    for picture in &rec.pictures {
        match picture {
            Picture::Rgb(name, image) => io::write_png_rgb(&dir.join(name), image)?,
            Picture::Gray16(name, image) => io::write_png16(&dir.join(name), image)?,
        }
    }
    let metrics = match gt {
        Some((gt, gt_mask)) => Some(write_evaluation(dir, &rec.normals, &gt.normals, gt_mask)?),
        None => None,
    };
    io::write_atomic(&dir.join("run.json"), &record.to_json())?;
    Ok(metrics)
}
