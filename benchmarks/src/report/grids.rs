//! Picture grids in the manner of the paper's Figs. 5–7, one pair per
//! (dataset, axis values, seed) with kept pictures: views left to right;
//! `*-normals.png` has the intensity, every method's normal map (MAE and
//! accuracy under each), the ground truth and SMSfP's PARG segmentation;
//! `*-errors.png` every method's angular-error map (viridis over 0–90°)
//! with a colour bar. A picture that cannot be read is drawn as a
//! `missing` placeholder and listed, never skipped silently.

use super::axes;
use super::methods::MethodInfo;
use crate::row::{AxisValue, Row};
use crate::sheet::{self, Cell, labelled_sheet};
use serde::Serialize;
use sfp_core::colormap;
use sfp_core::io::read_normals;
use sfp_core::legend::picture_part;
use sfp_core::metrics::error_map;
use sfp_core::result_folder::ResultFolder;
use sfp_core::view::View;
use sfp_core::{Image, Result, io};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Views per grid at most (the first in name order).
pub const MAX_VIEWS: usize = 8;

/// One written grid picture.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Grid {
    /// Path relative to the report folder (`grids/…png`).
    pub file: String,
    pub title: String,
    pub caption: String,
}

/// What [`write`] produced.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Grids {
    pub grids: Vec<Grid>,
    /// Pictures that should have been there (paths as looked for).
    pub missing: Vec<String>,
    /// Views left out of a grid (more than [`MAX_VIEWS`]).
    pub dropped_views: usize,
}

/// Which picture of a result a grid row shows.
#[derive(Clone, Copy)]
enum Kind {
    Normals,
    Error,
    Segments,
}

/// `path` relative to `dir` unless absolute.
fn resolve(dir: &Path, path: &str) -> PathBuf {
    let p = Path::new(path);
    if p.is_absolute() {
        p.to_path_buf()
    } else {
        dir.join(p)
    }
}

/// Reads an RGB picture, recording it as missing when it cannot be read.
fn picture(path: &Path, missing: &mut Vec<String>) -> Option<Image<[u8; 3]>> {
    match io::read_png_rgb(path) {
        Ok(img) => Some(img),
        Err(_) => {
            missing.push(path.display().to_string());
            None
        }
    }
}

/// The views' intensities, computed from `input/` (the view's
/// `preview/intensity.png` carries a legend a grid cell has no room for),
/// on one grey scale for the row: black at 0, white at the brightest pixel
/// of any of them, which is returned (units of full scale).
fn intensities(
    views: &[Option<View>],
    view_dirs: &[PathBuf],
    missing: &mut Vec<String>,
) -> (Vec<Option<Image<[u8; 3]>>>, f32) {
    let read: Vec<_> = views
        .iter()
        .map(|v| {
            v.as_ref()
                .map(|v| (v.input.polarimetry().intensity, v.input.mask.as_ref()))
        })
        .collect();
    let hi = read
        .iter()
        .flatten()
        .flat_map(|(i, _)| i.data().iter().copied())
        .fold(0.0f32, f32::max)
        .max(1e-6);
    let pictures = read
        .iter()
        .zip(view_dirs)
        .map(|(r, dir)| match r {
            Some((i, mask)) => Some(colormap::scalar_preview(i, *mask, 0.0, hi, colormap::gray)),
            None => {
                missing.push(dir.join("input").display().to_string());
                None
            }
        })
        .collect();
    (pictures, hi)
}

/// Normals as `(n + 1)/2` RGB from an EXR normal map.
fn normal_picture(exr: &Path, missing: &mut Vec<String>) -> Option<Image<[u8; 3]>> {
    match read_normals(exr) {
        Ok(n) => Some(n.map(|&v| colormap::normal_rgb(v))),
        Err(_) => {
            missing.push(exr.display().to_string());
            None
        }
    }
}

/// A result's angular-error map against its view's ground truth (viridis
/// over 0–90°; the grid has one colour bar for all).
fn error(
    result: &ResultFolder,
    view: Option<&View>,
    view_dir: &Path,
    missing: &mut Vec<String>,
) -> Option<Image<[u8; 3]>> {
    let exr = result.normals_path();
    let Ok(pred) = read_normals(&exr) else {
        missing.push(exr.display().to_string());
        return None;
    };
    let (Some(gt), Some(mask)) = (
        view.and_then(|v| v.gt.as_ref()),
        view.and_then(View::scored_mask),
    ) else {
        missing.push(view_dir.join("gt").display().to_string());
        return None;
    };
    match error_map(&pred, &gt.normals, &mask) {
        Ok(e) => Some(colormap::scalar_preview(
            &e,
            Some(&mask),
            0.0,
            90.0,
            colormap::viridis,
        )),
        Err(_) => {
            missing.push(exr.display().to_string());
            None
        }
    }
}

/// `MAE 16.99° 47.6%`-style caption of a row's figures (empty without).
fn figures_caption(r: &Row) -> String {
    match (&r.metrics, &r.error) {
        (Some(m), _) => sheet::figures_caption(m),
        (None, Some(_)) => "failed".into(),
        (None, None) => String::new(),
    }
}

/// File-name-safe slug.
fn slug(text: &str) -> String {
    let s: String = text
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '.' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    s.chars().take(80).collect()
}

type GroupKey<'a> = (&'a str, &'a BTreeMap<String, AxisValue>, u64);

/// Writes the grids of every (dataset, axis values, seed) that has rows with
/// pictures into `dir/grids/`.
pub fn write(
    dir: &Path,
    rows: &[Row],
    methods: &[MethodInfo],
    reference: Option<&MethodInfo>,
) -> Result<Grids> {
    let mut out = Grids::default();
    let with_pictures: Vec<&Row> = rows.iter().filter(|r| r.pictures.is_some()).collect();
    let mut groups: Vec<GroupKey> = with_pictures
        .iter()
        .map(|r| (r.dataset.as_str(), &r.axes, r.seed))
        .collect();
    groups.sort_by(|a, b| {
        a.0.cmp(b.0)
            .then_with(|| axes::cmp_axes(a.1, b.1))
            .then(a.2.cmp(&b.2))
    });
    groups.dedup();
    let rank = |label: &str| methods.iter().position(|m| m.label == label);
    for (g, &(dataset, ax, seed)) in groups.iter().enumerate() {
        let members: Vec<&Row> = with_pictures
            .iter()
            .copied()
            .filter(|r| r.dataset == dataset && &r.axes == ax && r.seed == seed)
            .collect();
        let mut views: Vec<&str> = members.iter().map(|r| r.view.as_str()).collect();
        views.sort();
        views.dedup();
        out.dropped_views += views.len().saturating_sub(MAX_VIEWS);
        views.truncate(MAX_VIEWS);
        let mut labels: Vec<&str> = members.iter().map(|r| r.method.as_str()).collect();
        labels.sort_by_key(|l| (rank(l), *l));
        labels.dedup();
        let find = |view: &str, label: &str| {
            members
                .iter()
                .copied()
                .find(|r| r.view == view && r.method == label)
        };
        let view_dirs: Vec<PathBuf> = views
            .iter()
            .map(|v| {
                let r = members
                    .iter()
                    .find(|r| r.view == *v)
                    .expect("view has a row");
                resolve(dir, &r.view_dir)
            })
            .collect();
        // Each view is read once for all the pictures of its column.
        let read_views: Vec<Option<View>> = view_dirs.iter().map(|d| View::read(d).ok()).collect();
        let display = |label: &str| {
            methods
                .iter()
                .find(|m| m.label == label)
                .map_or(label.to_string(), MethodInfo::display)
        };
        let method_row =
            |label: &str, kind: Kind, missing: &mut Vec<String>| -> (String, Vec<Cell>) {
                let pics = views
                    .iter()
                    .zip(view_dirs.iter().zip(&read_views))
                    .map(|(v, (view_dir, view))| match find(v, label) {
                        Some(r) => Cell {
                            image: r.pictures.as_ref().and_then(|p| {
                                let result = ResultFolder::new(resolve(dir, p));
                                match (r.error.is_some(), kind) {
                                    (true, _) => None,
                                    (_, Kind::Normals) => {
                                        normal_picture(&result.normals_path(), missing)
                                    }
                                    (_, Kind::Error) => {
                                        error(&result, view.as_ref(), view_dir, missing)
                                    }
                                    // The picture above its key (the view's size).
                                    (_, Kind::Segments) => picture(
                                        &result.picture_path(ResultFolder::SEGMENTS),
                                        missing,
                                    )
                                    .map(|p| match view {
                                        Some(v) => picture_part(&p, v.input.size()),
                                        None => p,
                                    }),
                                }
                            }),
                            caption: figures_caption(r),
                        },
                        None => Cell {
                            image: None,
                            caption: "not kept".into(),
                        },
                    })
                    .collect();
                (display(label), pics)
            };
        let mut missing = Vec::new();
        let (intensity, brightest) = intensities(&read_views, &view_dirs, &mut missing);
        let mut normals = vec![(
            "intensity".to_string(),
            intensity
                .into_iter()
                .map(|image| Cell {
                    image,
                    caption: String::new(),
                })
                .collect(),
        )];
        for label in &labels {
            normals.push(method_row(label, Kind::Normals, &mut missing));
        }
        let has_truth = members.iter().any(|r| r.metrics.is_some());
        if has_truth {
            normals.push((
                "ground truth".into(),
                view_dirs
                    .iter()
                    .zip(&read_views)
                    .map(|(d, view)| Cell {
                        image: match view.as_ref().and_then(|v| v.gt.as_ref()) {
                            Some(gt) => Some(gt.normals.map(|&n| colormap::normal_rgb(n))),
                            None => {
                                missing.push(View::gt_normals_path(d).display().to_string());
                                None
                            }
                        },
                        caption: String::new(),
                    })
                    .collect(),
            ));
        }
        if let Some(reference) = reference.filter(|m| labels.contains(&m.label.as_str())) {
            let (_, pics) = method_row(&reference.label, Kind::Segments, &mut missing);
            normals.push((
                "PARG segments".into(),
                pics.into_iter()
                    .map(|p| Cell {
                        caption: String::new(),
                        ..p
                    })
                    .collect(),
            ));
        }
        let columns: Vec<String> = views.iter().map(|v| v.to_string()).collect();
        let condition = axes::axes_text(ax);
        // A sweep without axes has no condition to name.
        let named = if ax.is_empty() {
            format!("{dataset}, seed {seed}")
        } else {
            format!("{dataset}, {condition}, seed {seed}")
        };
        let stem = format!(
            "{:02}-{}-{}-seed{seed}",
            g + 1,
            slug(dataset),
            slug(&condition)
        );
        let file = format!("grids/{stem}-normals.png");
        io::write_png_rgb(&dir.join(&file), &labelled_sheet(&columns, &normals, false))?;
        out.grids.push(Grid {
            file,
            title: format!("{named}: normals"),
            caption: format!(
                "From top to bottom: intensity of the noise-free view (one grey scale for \
                 the row: black 0, white {:.1} % of full scale, its brightest pixel), each \
                 method's normal map ((n + 1)/2 as RGB) with its MAE and accuracy < 11.25° \
                 below it{}{}. Every tile is drawn at one scale (a pixel is as large in \
                 each); click a grid for full size.",
                100.0 * brightest,
                if has_truth {
                    ", the ground-truth normals"
                } else {
                    ""
                },
                if normals.last().is_some_and(|(l, _)| l == "PARG segments") {
                    ", SMSfP's PARG segmentation (a colour per segment, darkened at \
                     boundaries, over the intensity)"
                } else {
                    ""
                }
            ),
        });
        if has_truth {
            let errors: Vec<(String, Vec<Cell>)> = labels
                .iter()
                .map(|l| method_row(l, Kind::Error, &mut missing))
                .collect();
            let file = format!("grids/{stem}-errors.png");
            io::write_png_rgb(&dir.join(&file), &labelled_sheet(&columns, &errors, true))?;
            out.grids.push(Grid {
                file,
                title: format!("{named}: angular error"),
                caption: "Per-pixel angular error of each method, one colour range for every \
                          tile (viridis from 0° to 90°, colour bar at the bottom; pixels a \
                          method left without a normal count as 90°), MAE and accuracy < \
                          11.25° below each map; every tile at one scale."
                    .into(),
            });
        }
        out.missing.extend(missing);
    }
    out.missing.sort();
    out.missing.dedup();
    Ok(out)
}
