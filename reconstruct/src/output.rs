//! A reconstruction written as its folder ([`ResultFolder`], conventions.md
//! §5): normals, height, mesh, the method's pictures, the evaluation when the
//! view has ground truth, and the run record last, so that its presence
//! marks a complete result; the folder is swapped into place whole
//! ([`folder::replace`]).

use crate::integrate::write_ply;
use crate::method::{Picture, Reconstruction};
use crate::run_record::RunRecord;
use sfp_core::folder::{self, Kind};
use sfp_core::metrics::Metrics;
use sfp_core::result_folder::ResultFolder;
use sfp_core::view::GroundTruth;
use sfp_core::{Mask, Result, io};
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
    let out = ResultFolder::new(dir);
    out.write_normals(&rec.normals)?;
    out.write_height(&rec.height)?;
    write_ply(&out.mesh_path(), &rec.height, mask)?;
    for picture in &rec.pictures {
        match picture {
            Picture::Rgb(name, image) => io::write_png_rgb(&out.picture_path(name), image)?,
            Picture::Gray16(name, image) => io::write_png16(&out.picture_path(name), image)?,
        }
    }
    let metrics = match gt {
        Some((gt, gt_mask)) => Some(out.write_evaluation(&rec.normals, &gt.normals, gt_mask)?),
        None => None,
    };
    out.write_run(record)?;
    Ok(metrics)
}
