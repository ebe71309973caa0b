//! Picture grids in the manner of the paper's Figs. 5–7, one pair per
//! (dataset, axis values, seed) with kept pictures: views left to right;
//! `*-normals.png` has the intensity, every method's normal map (MAE and
//! accuracy under each), the ground truth and SMSfP's PARG segmentation;
//! `*-errors.png` every method's angular-error map (viridis over 0–90°)
//! with a colour bar. A picture that cannot be read is drawn as a
//! `missing` placeholder and listed, never skipped silently.

use super::axes;
use super::methods::MethodInfo;
use crate::sheet::{draw_text, fitting_scale, text_width};
use crate::sweep::row::{AxisValue, Row};
use serde::Serialize;
use sfp_core::colormap::{self, BACKGROUND};
use sfp_core::view::{View, read_normals};
use sfp_core::{Image, Result, io};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Largest side of a picture in a grid, pixels.
pub const CELL: usize = 192;
/// Views per grid at most (the first in name order).
pub const MAX_VIEWS: usize = 8;
const GAP: usize = 8;
const CAPTION: usize = 20;
const HEADER: usize = 24;
const TEXT: [u8; 3] = [235, 235, 235];
const CANVAS: [u8; 3] = [0, 0, 0];

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

/// A picture cell: the image (or `None`: missing) and the text under it.
struct Pic {
    image: Option<Image<[u8; 3]>>,
    caption: String,
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

/// The view's intensity: `preview/intensity.png`, else computed from
/// `input/` as the view writer does.
fn intensity(view_dir: &Path, missing: &mut Vec<String>) -> Option<Image<[u8; 3]>> {
    let preview = view_dir.join("preview").join("intensity.png");
    if preview.is_file() {
        return picture(&preview, missing);
    }
    match View::read(view_dir) {
        Ok(view) => {
            let pm = view.input.polarimetry();
            let hi = pm
                .intensity
                .data()
                .iter()
                .copied()
                .fold(0.0f32, f32::max)
                .max(1e-6);
            Some(colormap::scalar_preview(
                &pm.intensity,
                view.input.mask.as_ref(),
                0.0,
                hi,
                colormap::gray,
            ))
        }
        Err(_) => {
            missing.push(preview.display().to_string());
            None
        }
    }
}

/// Ground-truth normals: `preview/normals.png`, else `gt/normals.exr`.
fn ground_truth(view_dir: &Path, missing: &mut Vec<String>) -> Option<Image<[u8; 3]>> {
    let preview = view_dir.join("preview").join("normals.png");
    if preview.is_file() {
        return picture(&preview, missing);
    }
    let exr = view_dir.join("gt").join("normals.exr");
    match read_normals(&exr) {
        Ok(n) => Some(n.map(|&v| colormap::normal_rgb(v))),
        Err(_) => {
            missing.push(exr.display().to_string());
            None
        }
    }
}

/// `img` brought to about `CELL` pixels on its longer side: shrunk by the
/// smallest integer factor that fits (box mean), or enlarged by the largest
/// integer factor that fits (pixels repeated, so small views stay sharp).
fn fit(img: &Image<[u8; 3]>) -> Image<[u8; 3]> {
    let side = img.width().max(img.height()).max(1);
    if side <= CELL {
        let k = CELL / side;
        if k <= 1 {
            return img.clone();
        }
        return Image::from_fn(img.width() * k, img.height() * k, |x, y| {
            *img.get(x / k, y / k)
        });
    }
    let k = side.div_ceil(CELL);
    let (w, h) = (img.width().div_ceil(k), img.height().div_ceil(k));
    Image::from_fn(w, h, |x, y| {
        let mut sum = [0u32; 3];
        let mut n = 0;
        for yy in y * k..((y + 1) * k).min(img.height()) {
            for xx in x * k..((x + 1) * k).min(img.width()) {
                let p = img.get(xx, yy);
                for c in 0..3 {
                    sum[c] += u32::from(p[c]);
                }
                n += 1;
            }
        }
        sum.map(|s| ((s + n / 2) / n) as u8)
    })
}

/// Lays out labelled rows of pictures under a header of column names; an
/// optional colour bar (0–90°) goes at the bottom.
fn compose(columns: &[String], rows: &[(String, Vec<Pic>)], colour_bar: bool) -> Image<[u8; 3]> {
    let fitted: Vec<Vec<Option<Image<[u8; 3]>>>> = rows
        .iter()
        .map(|(_, pics)| pics.iter().map(|p| p.image.as_ref().map(fit)).collect())
        .collect();
    let cw = fitted
        .iter()
        .flatten()
        .flatten()
        .map(Image::width)
        .max()
        .unwrap_or(CELL / 2)
        .max(96);
    // Wide enough for the captions and column names at the larger text
    // size, within reason.
    let texts = columns.iter().map(String::as_str).chain(
        rows.iter()
            .flat_map(|(_, pics)| pics.iter().map(|p| p.caption.as_str())),
    );
    let want = texts.map(|t| text_width(t, 2) + 8).max().unwrap_or(0);
    let cw = cw.max(want.min(CELL + 64));
    let ch = fitted
        .iter()
        .flatten()
        .flatten()
        .map(Image::height)
        .max()
        .unwrap_or(CELL / 2);
    let label_scale = 2;
    let label_w = rows
        .iter()
        .map(|(l, _)| text_width(l, label_scale))
        .max()
        .unwrap_or(0)
        .clamp(64, 16 * 14)
        + 2 * GAP;
    let row_h = ch + CAPTION + GAP;
    let bar_h = if colour_bar { 64 } else { 0 };
    let width = label_w + columns.len().max(1) * (cw + GAP) + GAP;
    let height = HEADER + rows.len() * row_h + bar_h + GAP;
    let mut img = Image::new(width, height, CANVAS);
    let col_x = |c: usize| label_w + GAP + c * (cw + GAP);
    // One text size for all column names and one for all captions: the
    // largest at which every one of them fits its cell with a margin.
    let common = |texts: &mut dyn Iterator<Item = &str>| {
        texts
            .map(|t| fitting_scale(t, cw.saturating_sub(8), 2))
            .min()
            .unwrap_or(2)
    };
    let head_scale = common(&mut columns.iter().map(String::as_str));
    let caption_scale = common(
        &mut rows
            .iter()
            .flat_map(|(_, pics)| pics.iter().map(|p| p.caption.as_str())),
    );
    for (c, name) in columns.iter().enumerate() {
        let s = head_scale;
        let x = col_x(c) + cw.saturating_sub(text_width(name, s)) / 2;
        draw_text(&mut img, x, (HEADER - 8 * s) / 2, name, s, TEXT);
    }
    for (r, ((label, pics), fitted)) in rows.iter().zip(&fitted).enumerate() {
        let y0 = HEADER + r * row_h;
        let s = fitting_scale(label, label_w - 2 * GAP, label_scale);
        draw_text(&mut img, GAP, y0 + ch / 2 - 4 * s, label, s, TEXT);
        for (c, (pic, image)) in pics.iter().zip(fitted).enumerate() {
            let x0 = col_x(c);
            match image {
                Some(p) => {
                    let (ox, oy) = ((cw - p.width()) / 2, (ch - p.height()) / 2);
                    for y in 0..p.height() {
                        for x in 0..p.width() {
                            *img.get_mut(x0 + ox + x, y0 + oy + y) = *p.get(x, y);
                        }
                    }
                }
                None => {
                    for y in 0..ch {
                        for x in 0..cw {
                            *img.get_mut(x0 + x, y0 + y) = BACKGROUND;
                        }
                    }
                    draw_text(
                        &mut img,
                        x0 + 4,
                        y0 + ch / 2 - 4,
                        "missing",
                        1,
                        [255, 90, 90],
                    );
                }
            }
            let s = caption_scale;
            let tx = x0 + cw.saturating_sub(text_width(&pic.caption, s)) / 2;
            draw_text(
                &mut img,
                tx,
                y0 + ch + (CAPTION - 8 * s) / 2,
                &pic.caption,
                s,
                TEXT,
            );
        }
    }
    if colour_bar {
        let y0 = HEADER + rows.len() * row_h + 8;
        // Room for half a tick label on either side of the bar.
        let x0 = col_x(0) + 16;
        let bar_w = width.saturating_sub(x0 + 32).max(90);
        let bar = colormap::colour_bar(bar_w, 16, colormap::viridis);
        for y in 0..bar.height() {
            for x in 0..bar.width() {
                *img.get_mut(x0 + x, y0 + y) = *bar.get(x, y);
            }
        }
        let s = fitting_scale("error (°)", label_w - 2 * GAP, 2);
        draw_text(&mut img, GAP, y0, "error (°)", s, TEXT);
        // Ticks every 15°, or every 30° when the labels would touch.
        let step = if bar_w / 6 >= text_width("90°", 2) + 8 {
            15
        } else {
            30
        };
        for deg in (0..=90).step_by(step) {
            let text = deg.to_string();
            let x = x0 + (bar_w - 1) * deg / 90;
            for y in y0 + 16..y0 + 22 {
                *img.get_mut(x.min(width - 1), y) = TEXT;
            }
            let tw = text_width(&text, 2);
            let tx = x.saturating_sub(tw / 2).min(width - tw);
            draw_text(&mut img, tx, y0 + 26, &text, 2, TEXT);
        }
    }
    img
}

/// `MAE 16.99° 47.6%`-style caption of a row's figures (empty without).
fn figures_caption(r: &Row) -> String {
    match (&r.metrics, &r.error) {
        (Some(m), _) => format!("{:.2}° {:.1}%", m.mae_deg, m.acc_11_25),
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
        let display = |label: &str| {
            methods
                .iter()
                .find(|m| m.label == label)
                .map_or(label.to_string(), MethodInfo::display)
        };
        let method_row =
            |label: &str, file: &str, missing: &mut Vec<String>| -> (String, Vec<Pic>) {
                let pics = views
                    .iter()
                    .map(|v| match find(v, label) {
                        Some(r) => Pic {
                            image: r.pictures.as_ref().and_then(|p| {
                                if r.error.is_some() {
                                    None
                                } else {
                                    picture(&resolve(dir, p).join(file), missing)
                                }
                            }),
                            caption: figures_caption(r),
                        },
                        None => Pic {
                            image: None,
                            caption: "not kept".into(),
                        },
                    })
                    .collect();
                (display(label), pics)
            };
        let mut missing = Vec::new();
        let mut normals = vec![(
            "intensity".to_string(),
            view_dirs
                .iter()
                .map(|d| Pic {
                    image: intensity(d, &mut missing),
                    caption: String::new(),
                })
                .collect(),
        )];
        for label in &labels {
            normals.push(method_row(label, "normals.png", &mut missing));
        }
        let has_truth = members.iter().any(|r| r.metrics.is_some());
        if has_truth {
            normals.push((
                "ground truth".into(),
                view_dirs
                    .iter()
                    .map(|d| Pic {
                        image: ground_truth(d, &mut missing),
                        caption: String::new(),
                    })
                    .collect(),
            ));
        }
        if let Some(reference) = reference.filter(|m| labels.contains(&m.label.as_str())) {
            let (_, pics) = method_row(&reference.label, "segments.png", &mut missing);
            normals.push((
                "PARG segments".into(),
                pics.into_iter()
                    .map(|p| Pic {
                        caption: String::new(),
                        ..p
                    })
                    .collect(),
            ));
        }
        let columns: Vec<String> = views.iter().map(|v| v.to_string()).collect();
        let condition = axes::axes_text(ax);
        let stem = format!(
            "{:02}-{}-{}-seed{seed}",
            g + 1,
            slug(dataset),
            slug(&condition)
        );
        let file = format!("grids/{stem}-normals.png");
        io::write_png_rgb(&dir.join(&file), &compose(&columns, &normals, false))?;
        out.grids.push(Grid {
            file,
            title: format!("{dataset}, {condition}, seed {seed}: normals"),
            caption: format!(
                "From top to bottom: intensity of the noise-free view, each method's normal \
                 map ((n + 1)/2 as RGB) with its MAE and accuracy < 11.25° below it{}{}.",
                if has_truth {
                    ", the ground-truth normals"
                } else {
                    ""
                },
                if normals.last().is_some_and(|(l, _)| l == "PARG segments") {
                    ", SMSfP's PARG segmentation"
                } else {
                    ""
                }
            ),
        });
        if has_truth {
            let errors: Vec<(String, Vec<Pic>)> = labels
                .iter()
                .map(|l| method_row(l, "error.png", &mut missing))
                .collect();
            let file = format!("grids/{stem}-errors.png");
            io::write_png_rgb(&dir.join(&file), &compose(&columns, &errors, true))?;
            out.grids.push(Grid {
                file,
                title: format!("{dataset}, {condition}, seed {seed}: angular error"),
                caption: "Per-pixel angular error of each method (viridis from 0° to 90°, \
                          colour bar at the bottom; pixels a method left without a normal \
                          count as 90°), MAE and accuracy < 11.25° below each map."
                    .into(),
            });
        }
        out.missing.extend(missing);
    }
    out.missing.sort();
    out.missing.dedup();
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pictures_are_fitted_to_the_cell_size() {
        // Small views are enlarged by whole pixels, large ones shrunk by a
        // box mean: both end within one factor of CELL.
        let small = Image::from_fn(48, 32, |x, _| [x as u8, 0, 0]);
        let up = fit(&small);
        assert_eq!(up.size(), (192, 128));
        assert_eq!(*up.get(7, 0), [1, 0, 0]);
        // Shrunk by 3 (500 / 192 rounded up): each box mean of 0, 150, 150.
        let large = Image::from_fn(500, 250, |x, _| if x % 3 == 0 { [0; 3] } else { [150; 3] });
        let down = fit(&large);
        assert_eq!(down.size(), (167, 84));
        assert_eq!(*down.get(10, 10), [100; 3]);
        assert_eq!(fit(&Image::new(CELL, 10, [1u8; 3])).size(), (CELL, 10));
    }

    #[test]
    fn a_missing_picture_is_a_placeholder_and_the_colour_bar_spans_0_to_90() {
        let pic = |image| Pic {
            image,
            caption: "12.00° 50.0%".into(),
        };
        let rows = vec![(
            "smith".to_string(),
            vec![pic(Some(Image::new(96, 96, [255, 0, 0]))), pic(None)],
        )];
        let img = compose(&["a".into(), "b".into()], &rows, true);
        let count = |c: [u8; 3]| img.data().iter().filter(|p| **p == c).count();
        assert_eq!(count([255, 0, 0]), 96 * 96 * 4, "the picture, enlarged 2×");
        // The missing picture's cell is the background with a red label.
        assert!(count(BACKGROUND) >= 192 * 192 - 8 * 64);
        assert!(count([255, 90, 90]) > 0);
        // Both ends of the colour map are in the bar.
        assert!(count(colormap::viridis(0.0)) >= 16);
        assert!(count(colormap::viridis(1.0)) >= 16);
    }
}
