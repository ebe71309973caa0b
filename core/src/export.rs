//! Exports for other tools: results as NumPy arrays and 16-bit PNGs, and a
//! view as the per-angle folder layout that learning-based SfP code reads
//! (`pol000/ pol045/ pol090/ pol135/ normal/ mask/`, one image per view in
//! each), read back by [`read_layout`]. Every export carries a sidecar JSON
//! stating the axis convention, since other code bases differ in it.

use crate::folder;
use crate::prediction::{self, Axes};
use crate::result_folder::ResultFolder;
use crate::view::{GroundTruth, View, ViewInput};
use crate::{Error, Image, NormalMap, Result, io};
use serde_json::json;
use std::path::{Path, PathBuf};

/// Axis convention of every exported normal (conventions.md §1).
pub const AXES: &str = "camera frame: x right, y up, z towards the camera; \
                        images row-major from the top row; PNG normals store (n + 1) / 2";

/// Files of an exported result, each named once for its writer and for the
/// sidecar that describes it.
const NORMALS_NPY: &str = "normals.npy";
const NORMALS_PNG: &str = "normals.png";
const HEIGHT_NPY: &str = "height.npy";

/// Folders of the per-angle layout, in the order of `POL_FILES`.
pub const LAYOUT_POL: [&str; 4] = ["pol000", "pol045", "pol090", "pol135"];

/// Writes a little-endian float32 `.npy` array of `shape` (C order).
pub fn write_npy_f32(
    path: &Path,
    shape: &[u64],
    data: impl IntoIterator<Item = f32>,
) -> Result<()> {
    use npyz::WriterBuilder;
    let mut bytes = Vec::new();
    let mut writer = npyz::WriteOptions::new()
        .default_dtype()
        .shape(shape)
        .writer(&mut bytes)
        .begin_nd()
        .map_err(|e| Error::io(path, e))?;
    writer.extend(data).map_err(|e| Error::io(path, e))?;
    writer.finish().map_err(|e| Error::io(path, e))?;
    io::write_atomic(path, &bytes)
}

/// A normal map as 16-bit RGB, `(n + 1) / 2` (pixels without a normal: 0).
pub fn normals_png16(normals: &NormalMap) -> Image<[u16; 3]> {
    normals.map(|n| {
        if *n == [0.0; 3] {
            [0; 3]
        } else {
            n.map(|c| {
                ((f64::from(c) + 1.0) * 0.5 * 65535.0)
                    .round()
                    .clamp(0.0, 65535.0) as u16
            })
        }
    })
}

/// Inverse of [`normals_png16`], renormalised.
fn normals_from_png16(img: &Image<[u16; 3]>) -> NormalMap {
    img.map(|p| {
        if *p == [0; 3] {
            return [0.0; 3];
        }
        let v = p.map(|c| f64::from(c) / 65535.0 * 2.0 - 1.0);
        let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        if len > 0.0 {
            v.map(|c| (c / len) as f32)
        } else {
            [0.0; 3]
        }
    })
}

/// Exports the reconstruction folder `result` into `out`: `normals.npy`
/// (H×W×3 float32, zero where no normal), `normals.png` (16-bit),
/// `height.npy` (H×W float32, NaN outside the reconstruction) and
/// `export.json`.
pub fn export_result(result: &Path, out: &Path) -> Result<()> {
    check_out(out)?;
    let folder = ResultFolder::new(result);
    let normals = folder.read_normals()?;
    let height = folder.read_height()?;
    let (w, h) = normals.size();
    if height.size() != (w, h) {
        return Err(Error::file(
            &folder.height_path(),
            format!(
                "is {:?} pixels but normals.exr is {:?}",
                height.size(),
                (w, h)
            ),
        ));
    }
    let shape3 = [h as u64, w as u64, 3];
    write_npy_f32(
        &out.join(NORMALS_NPY),
        &shape3,
        normals.data().iter().flatten().copied(),
    )?;
    io::write_png_rgb16(&out.join(NORMALS_PNG), &normals_png16(&normals))?;
    write_npy_f32(
        &out.join(HEIGHT_NPY),
        &[h as u64, w as u64],
        height.data().iter().copied(),
    )?;
    sidecar(
        &out.join("export.json"),
        json!({
            "source": result.display().to_string(),
            "axes": AXES,
            NORMALS_NPY: "float32 [height, width, 3], unit normals, 0 where the method gave none",
            NORMALS_PNG: "16-bit RGB, (n + 1) / 2 · 65535, black where no normal",
            HEIGHT_NPY: "float32 [height, width], relative height along +z in pixel units, NaN outside",
        }),
    )
}

/// Exports `view` (named `name`) into the per-angle layout under `out`:
/// `pol000/NAME.png` … `pol135/NAME.png` (the polarizer images as stored),
/// `mask/NAME.png` (8-bit, 255 = object) and, with ground truth,
/// `normal/NAME.png` (16-bit) and `normal/NAME.npy`; `layout.json` states
/// the convention.
pub fn export_layout(view: &View, name: &str, out: &Path) -> Result<()> {
    check_out(out)?;
    check_layout_name(name)?;
    // A view exported again under its name loses what the new one lacks
    // (an old normal/NAME.png beside a view without ground truth).
    for folder in LAYOUT_POL.iter().chain(&["mask", "normal"]) {
        for ext in ["png", "npy"] {
            let old = out.join(folder).join(format!("{name}.{ext}"));
            if old.is_file() {
                std::fs::remove_file(&old).map_err(|e| Error::io(&old, e))?;
            }
        }
    }
    for (k, folder) in LAYOUT_POL.iter().enumerate() {
        let path = out.join(folder).join(format!("{name}.png"));
        match &view.input.colour {
            Some(rgb) => io::write_png_rgb_codes(&path, &rgb[k], view.input.bits)?,
            None if view.input.bits <= 8 => {
                io::write_png8(&path, &view.input.pol[k].map(|&v| v.min(255) as u8))?
            }
            None => io::write_png16(&path, &view.input.pol[k])?,
        }
    }
    if let Some(mask) = &view.input.mask {
        io::write_png8(
            &out.join("mask").join(format!("{name}.png")),
            &mask.map(|&m| if m { 255 } else { 0 }),
        )?;
    }
    if let Some(gt) = &view.gt {
        let (w, h) = gt.normals.size();
        io::write_png_rgb16(
            &out.join("normal").join(format!("{name}.png")),
            &normals_png16(&gt.normals),
        )?;
        write_npy_f32(
            &out.join("normal").join(format!("{name}.npy")),
            &[h as u64, w as u64, 3],
            gt.normals.data().iter().flatten().copied(),
        )?;
    }
    sidecar(
        &out.join("layout.json"),
        json!({
            "axes": AXES,
            "polarizer_angles_deg": [0, 45, 90, 135],
            "angle_reference": "polarizer angle measured from the image x axis (horizontal), counter-clockwise as seen by the camera",
            "bits": view.input.bits,
            "folders": {
                "pol000": "intensity behind the polarizer at 0°, one PNG per view",
                "pol045": "45°", "pol090": "90°", "pol135": "135°",
                "mask": "8-bit PNG, 255 = object",
                "normal": "ground-truth normals: 16-bit RGB PNG (n + 1) / 2 and float32 .npy [height, width, 3]",
            },
        }),
    )
}

/// Refuses an export into a path that is not a folder, into a view's data,
/// or into a view or reconstruction folder (its `normals.png` would be
/// overwritten).
fn check_out(out: &Path) -> Result<()> {
    folder::ensure_outside_view_data(out)?;
    folder::ensure_folder_or_new(out)?;
    match folder::Kind::of(out) {
        Some(kind) => Err(Error::file(
            out,
            format!(
                "is a {}: export into a new folder, not over another kind of output",
                kind.name()
            ),
        )),
        None => Ok(()),
    }
}

/// A view's name in a layout is one file name: not empty, no path
/// separator, not `.` or `..` (`--name ../../x` wrote outside `--out`).
pub fn check_layout_name(name: &str) -> Result<()> {
    let plain = !name.is_empty()
        && name != "."
        && name != ".."
        && !name.contains(['/', '\\', '\0'])
        && !name.starts_with('.');
    if plain {
        Ok(())
    } else {
        Err(Error::invalid(format!(
            "--name {name:?} is not a view name: give a plain file name (letters, digits, \
             '-', '_'), without '/' or a leading '.'"
        )))
    }
}

/// The name of the view to read from the layout `dir`: `name` when given
/// (checked to be a plain file name), else the layout's only view.
pub fn layout_name(dir: &Path, name: Option<&str>) -> Result<String> {
    if let Some(n) = name {
        check_layout_name(n)?;
    }
    let first = dir.join(LAYOUT_POL[0]);
    if !first.is_dir() {
        return Err(Error::file(
            dir,
            format!(
                "not a per-angle layout: it has no {}/ folder (`sfp export VIEW --out DIR` writes one)",
                LAYOUT_POL[0]
            ),
        ));
    }
    let mut names: Vec<String> = std::fs::read_dir(&first)
        .map_err(|e| Error::read(&first, e))?
        .flatten()
        .filter_map(|e| {
            e.file_name()
                .to_str()?
                .strip_suffix(".png")
                .map(String::from)
        })
        .collect();
    names.sort();
    let some = |names: &[String]| {
        let shown = names[..names.len().min(3)].join(", ");
        if names.len() > 3 {
            format!("{shown}…")
        } else {
            shown
        }
    };
    match (name, names.len()) {
        (Some(n), _) if names.iter().any(|m| m == n) => Ok(n.to_string()),
        (Some(n), 0) => Err(Error::file(
            &first,
            format!("--name {n}: the layout holds no .png view"),
        )),
        (Some(n), k) => Err(Error::file(
            &first,
            format!(
                "--name {n}: no such view; the layout holds {k} ({})",
                some(&names)
            ),
        )),
        (None, 1) => Ok(names.remove(0)),
        (None, 0) => Err(Error::file(&first, "holds no .png view")),
        (None, k) => Err(Error::file(
            &first,
            format!(
                "holds {k} views ({}): name the one to import with --name",
                some(&names)
            ),
        )),
    }
}

/// The four polarizer files of the view `name` in the layout `dir`.
pub fn layout_files(dir: &Path, name: &str) -> [PathBuf; 4] {
    LAYOUT_POL.map(|folder| dir.join(folder).join(format!("{name}.png")))
}

/// The view `name` of a per-angle layout folder (as [`export_layout`] writes
/// it, or as SfPUEL publishes its data: the same folders with RGB PNGs and
/// no `layout.json`; `mask/` and `normal/` optional), without `name` the
/// layout's only view. Colour polarizer images make a colour view (methods
/// read their Rec. 709 luminance, [`ViewInput::of_colour`]). The four
/// images must share one bit depth and be all grey or all colour, and ground-truth normals must decode to unit vectors facing
/// the camera once read in frame `axes` (conventions.md §1 for `Ours`).
/// When the normals fit the other `y` sense clearly better along the mask's
/// outline ([`prediction::frame_fit`]), `problems` says so and which
/// `axes` to read them with.
pub fn read_layout(dir: &Path, name: Option<&str>, axes: Axes) -> Result<View> {
    let name = layout_name(dir, name)?;
    let file = |folder: &str| -> PathBuf { dir.join(folder).join(format!("{name}.png")) };
    let mut pngs = Vec::with_capacity(4);
    let mut bits = None;
    for folder in LAYOUT_POL {
        let png = io::read_polarizer_png(&file(folder))?;
        let colour = |p: &io::PolarizerPng| matches!(p, io::PolarizerPng::Colour { .. });
        if let Some(first) = pngs.first()
            && colour(first) != colour(&png)
        {
            return Err(Error::file(
                &file(folder),
                format!(
                    "is {} but {} is {}: the four images must come from one capture",
                    if colour(&png) { "colour" } else { "grey" },
                    file(LAYOUT_POL[0]).display(),
                    if colour(first) { "colour" } else { "grey" },
                ),
            ));
        }
        if bits.is_some_and(|b| b != png.bits()) {
            return Err(Error::file(
                &file(folder),
                format!(
                    "is {}-bit but {} is {}-bit: the four images must come from one capture",
                    png.bits(),
                    file(LAYOUT_POL[0]).display(),
                    bits.unwrap_or_default()
                ),
            ));
        }
        bits = Some(png.bits());
        pngs.push(png);
    }
    let bits = bits.unwrap_or(8);
    let pngs: [io::PolarizerPng; 4] = pngs.try_into().expect("four polarizer images");
    let size = pngs[0].size();
    let mask = if file("mask").is_file() {
        let m = io::read_mask_png(&file("mask"))?;
        if m.size() != size {
            return Err(Error::file(
                &file("mask"),
                format!("is {:?} pixels, not {size:?}", m.size()),
            ));
        }
        Some(m)
    } else {
        None
    };
    let mut problems = Vec::new();
    let gt = if file("normal").is_file() {
        let png = io::read_png_rgb16(&file("normal"))?;
        check_normals_png(&png, &file("normal"), axes)?;
        let normals = normals_from_png16(&png).map(|&n| axes.to_ours(n));
        if normals.size() != size {
            return Err(Error::file(
                &file("normal"),
                format!("is {:?} pixels, not {size:?}", normals.size()),
            ));
        }
        let fit = mask
            .as_ref()
            .and_then(|m| prediction::frame_fit(&normals, m));
        if let Some((read, flipped)) = fit.filter(|(read, flipped)| flipped > &(read + 0.5)) {
            let other = match axes {
                Axes::Ours => "image (or opencv, whose z points into the scene)",
                Axes::Image | Axes::Opencv => "ours",
            };
            problems.push(format!(
                "{}: the normals' y axis looks reversed: along the mask's outline they point \
                 outwards with y negated (mean cosine {flipped:.2}) but not as read in frame \
                 {} ({read:.2}); read them with --axes {other}",
                file("normal").display(),
                axes.name(),
            ));
        }
        Some(GroundTruth::of_normals(normals))
    } else {
        None
    };
    for (folder, img) in LAYOUT_POL.iter().zip(&pngs) {
        if img.size() != size {
            return Err(Error::file(
                &file(folder),
                format!("is {:?} pixels, not {size:?}", img.size()),
            ));
        }
    }
    let input = match &pngs[0] {
        io::PolarizerPng::Colour { .. } => ViewInput::of_colour(
            pngs.map(|p| p.into_colour().expect("colour images")),
            bits,
            mask,
        ),
        io::PolarizerPng::Grey(_) => ViewInput::grey(pngs.map(|p| p.luminance()), bits, mask),
    };
    Ok(View {
        input,
        gt,
        meta: None,
        problems,
        source: Some(dir.to_path_buf()),
    })
}

/// Largest share of the encoded normals that may be off (not unit length,
/// or facing away from the camera) before the picture is refused.
const MAX_BAD_NORMALS: f64 = 0.01;

/// Refuses a normal picture that is no `(n + 1) / 2` encoding of unit
/// normals facing the camera (`n_z ≥ 0`, conventions.md §1): a grey or
/// all-black picture, an 8-bit photo, back-facing normals.
fn check_normals_png(img: &Image<[u16; 3]>, path: &Path, axes: Axes) -> Result<()> {
    let (mut given, mut not_unit, mut back) = (0usize, 0usize, 0usize);
    for p in img.data().iter().filter(|p| **p != [0; 3]) {
        given += 1;
        let v = p.map(|c| f64::from(c) / 65535.0 * 2.0 - 1.0);
        let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        not_unit += usize::from((len - 1.0).abs() > 0.05);
        let z = axes.to_ours(v.map(|c| c as f32))[2];
        back += usize::from(z < -0.05);
    }
    let share = |n: usize| n as f64 / given.max(1) as f64;
    if given == 0 {
        return Err(Error::file(path, "holds no normal (every pixel is 0)"));
    }
    if share(not_unit) > MAX_BAD_NORMALS {
        return Err(Error::file(
            path,
            format!(
                "{not_unit} of {given} pixels are no unit normal encoded as (n + 1) / 2 · 65535 \
                 (a grey, black or photographic picture?)"
            ),
        ));
    }
    if share(back) > MAX_BAD_NORMALS {
        return Err(Error::file(
            path,
            format!(
                "{back} of {given} normals face away from the camera in frame {} (n_z < 0; the \
                 project's normals have +z towards the camera, conventions.md §1; OpenCV's \
                 point into the scene: --axes opencv)",
                axes.name()
            ),
        ));
    }
    Ok(())
}

fn sidecar(path: &Path, value: serde_json::Value) -> Result<()> {
    let text = serde_json::to_vec_pretty(&value).expect("sidecar serialises");
    io::write_atomic(path, &text)
}
