//! A reconstruction written as its folder ([`ResultFolder`], conventions.md
//! §5): normals, height, mesh, the method's pictures, the evaluation when the
//! view has ground truth, and the run record last, so that its presence
//! marks a complete result; the folder is swapped into place whole
//! ([`folder::replace`]).

use crate::method::{Picture, Reconstruction};
use crate::run_record::RunRecord;
use rayon::prelude::*;
use sfp_core::folder::{self, Kind};
use sfp_core::legend::{Legend, with_legend};
use sfp_core::metrics::Metrics;
use sfp_core::result_folder::ResultFolder;
use sfp_core::view::{GroundTruth, Job};
use sfp_core::{Image, Mask, Result, io};
use std::path::Path;

/// Writes `rec` (computed over `mask`) with its `record` as the folder
/// `dir`, replacing a previous result there as a whole, with its
/// `metrics` against the ground truth (over the ground-truth mask) when
/// the view has one.
pub fn write_result(
    dir: &Path,
    rec: &Reconstruction,
    record: &RunRecord,
    mask: &Mask,
    scored: Option<((&GroundTruth, &Mask), &Metrics)>,
) -> Result<()> {
    folder::replace(dir, Kind::Result, |d| {
        write_files(d, rec, record, mask, scored)
    })
}

/// The result's files. They are independent: encoded concurrently (the
/// 1024² sphere's 35 MB of EXR, PLY and PNG took 0.7 s one after another),
/// `run.json` last.
fn write_files(
    dir: &Path,
    rec: &Reconstruction,
    record: &RunRecord,
    mask: &Mask,
    scored: Option<((&GroundTruth, &Mask), &Metrics)>,
) -> Result<()> {
    let out = ResultFolder::new(dir);
    let out = &out;
    let mut jobs: Vec<Job> = vec![
        Box::new(|| out.write_normals(&rec.normals)),
        Box::new(|| out.write_height(&rec.height)),
        Box::new(|| out.write_mesh(&rec.height, mask)),
    ];
    for picture in &rec.pictures {
        jobs.push(Box::new(move || match picture {
            Picture::Rgb(name, image) => io::write_png_rgb(&out.picture_path(name), image),
            Picture::Gray16(name, image) => io::write_png16(&out.picture_path(name), image),
        }));
    }
    if let Some(specular) = &rec.specular {
        jobs.push(Box::new(move || {
            io::write_png_rgb(
                &out.picture_path(ResultFolder::SPECULAR),
                &specular_picture(&specular.turned, mask),
            )
        }));
        jobs.push(Box::new(move || {
            io::write_exr(
                &out.picture_path(ResultFolder::SPECULAR_SHARE),
                &[("Y", &specular.share)],
            )
        }));
    }
    if let Some(((gt, gt_mask), metrics)) = scored {
        jobs.push(Box::new(move || {
            out.write_evaluation(&rec.normals, &gt.normals, gt_mask, metrics)
        }));
    }
    jobs.into_par_iter().try_for_each(|job| job())?;
    out.write_run(record)
}

/// Colour of a pixel read as diffuse, and of one read as specular.
const DIFFUSE: [u8; 3] = [90, 90, 90];
const SPECULAR: [u8; 3] = [255, 140, 0];

fn two_colours(v: f32) -> [u8; 3] {
    if v < 0.5 { DIFFUSE } else { SPECULAR }
}

/// `specular.png`: the object's pixels grey where read as diffuse, orange
/// where read as specular (AoP turned by 90°), with its key.
fn specular_picture(specular: &Mask, mask: &Mask) -> Image<[u8; 3]> {
    let picture = Image::from_fn(mask.width(), mask.height(), |x, y| {
        match (*mask.get(x, y), *specular.get(x, y)) {
            (false, _) => [0, 0, 0],
            (true, s) => two_colours(if s { 1.0 } else { 0.0 }),
        }
    });
    let legend = Legend::Bar {
        name: "read as specular (0 no, 1 yes)",
        lo: 0.0,
        hi: 1.0,
        unit: "",
        map: two_colours,
    };
    with_legend(&picture, &legend)
}
