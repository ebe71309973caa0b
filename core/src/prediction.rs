//! A normal map predicted by any tool, read for scoring: a file in one of
//! the formats learned methods write (`.exr` with R, G, B; `.npy` H×W×3
//! float32 or float64 in C order; `.png` at 8 or 16 bits, decoded
//! `2·v/max − 1`) in one of the common camera frames, turned into the
//! frame of conventions.md §1. `sfp eval` reads predictions through it.

use crate::{Error, Mask, NormalMap, Result, image::Image, io};
use std::path::{Path, PathBuf};

/// The frame a prediction's `(x, y, z)` are given in. Every one has `+x`
/// to image right; they differ in `y` and `z`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axes {
    /// conventions.md §1: `+y` up, `+z` towards the camera.
    Ours,
    /// `+y` down the image rows, `+z` towards the camera (normal-map
    /// pictures in the "DirectX" convention, y-down array code).
    Image,
    /// OpenCV's camera frame: `+y` down, `+z` into the scene (a visible
    /// surface has `n_z < 0`).
    Opencv,
}

impl Axes {
    /// The names `--axes` takes, in order.
    pub const NAMES: [&'static str; 3] = ["ours", "image", "opencv"];

    pub fn parse(name: &str) -> Option<Axes> {
        match name {
            "ours" => Some(Axes::Ours),
            "image" => Some(Axes::Image),
            "opencv" => Some(Axes::Opencv),
            _ => None,
        }
    }

    /// The name [`Axes::parse`] reads.
    pub fn name(self) -> &'static str {
        match self {
            Axes::Ours => "ours",
            Axes::Image => "image",
            Axes::Opencv => "opencv",
        }
    }

    /// What the frame is, for the printed protocol.
    pub fn describe(self) -> &'static str {
        match self {
            Axes::Ours => "x right, y up, z towards the camera (conventions.md §1)",
            Axes::Image => "x right, y down, z towards the camera; y negated",
            Axes::Opencv => "x right, y down, z into the scene (OpenCV); y and z negated",
        }
    }

    /// `n` given in this frame, in ours.
    pub fn to_ours(self, [x, y, z]: [f32; 3]) -> [f32; 3] {
        match self {
            Axes::Ours => [x, y, z],
            Axes::Image => [x, -y, z],
            Axes::Opencv => [x, -y, -z],
        }
    }
}

/// How well `normals` fit each frame's in-plane axes along the outline of
/// `mask`, where an occluding contour's normals point out of the mask: the
/// mean over outline pixels (inside, with a 4-neighbour outside) of the
/// cosine between the normal's in-plane direction in that frame and the
/// outward direction, 1 for a perfect fit, about 0 for the wrong `y` sense
/// (the sides agree, top and bottom disagree). `(ours, image)`: `image` (y
/// down) also stands for OpenCV, which differs from it in `z` only. `None`
/// without outline pixels with a normal.
pub fn frame_fit(normals: &NormalMap, mask: &Mask) -> Option<(f64, f64)> {
    let (w, h) = mask.size();
    let inside = |x: isize, y: isize| {
        x >= 0
            && y >= 0
            && (x as usize) < w
            && (y as usize) < h
            && *mask.get(x as usize, y as usize)
    };
    let (mut ours, mut image, mut count) = (0.0f64, 0.0f64, 0usize);
    for y in 0..h {
        for x in 0..w {
            let n = *normals.get(x, y);
            if !*mask.get(x, y) || n == [0.0; 3] {
                continue;
            }
            // Outward, x right and y up: a missing neighbour below is −y.
            let (xi, yi) = (x as isize, y as isize);
            let mut out = [0.0f32; 2];
            for (dx, dy) in [(1, 0), (-1, 0), (0, 1), (0, -1)] {
                if !inside(xi + dx, yi + dy) {
                    out[0] += dx as f32;
                    out[1] -= dy as f32;
                }
            }
            let (len_n, len_out) = (n[0].hypot(n[1]), out[0].hypot(out[1]));
            if len_out == 0.0 || len_n == 0.0 {
                continue;
            }
            count += 1;
            let cos = |ny: f32| f64::from((n[0] * out[0] + ny * out[1]) / (len_n * len_out));
            ours += cos(n[1]);
            image += cos(-n[1]);
        }
    }
    (count > 0).then(|| (ours / count as f64, image / count as f64))
}

/// The names a prediction file may have inside a result folder, in the
/// order they are looked for.
pub const FILE_NAMES: [&str; 3] = ["normals.exr", "normals.npy", "normals.png"];

/// The prediction file inside the result folder `dir`, if any.
pub fn in_folder(dir: &Path) -> Option<PathBuf> {
    FILE_NAMES.iter().map(|n| dir.join(n)).find(|p| p.is_file())
}

/// Reads the prediction `path` given in `axes`, in our frame. Non-finite
/// values are kept (they count as missing predictions when scored).
pub fn read(path: &Path, axes: Axes) -> Result<NormalMap> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let map = match ext.as_deref() {
        Some("exr") => io::read_rgb_exr(path)?,
        Some("npy") => read_npy(path)?,
        Some("png") => read_png(path)?,
        _ => {
            return Err(Error::file(
                path,
                "not a prediction file: expected .exr (R, G, B), .npy (H×W×3 float) or .png (8/16-bit, 2·v/max − 1)",
            ));
        }
    };
    Ok(map.map(|&n| axes.to_ours(n)))
}

fn read_png(path: &Path) -> Result<NormalMap> {
    // 8-bit files are widened ×257, so v/65535 = v8/255.
    let img = io::read_png_rgb16(path)?;
    Ok(img.map(|p| p.map(|v| 2.0 * f32::from(v) / 65535.0 - 1.0)))
}

fn read_npy(path: &Path) -> Result<NormalMap> {
    let bytes = io::read_bytes(path)?;
    let bad = |why: String| Error::file(path, why);
    let npy = npyz::NpyFile::new(&bytes[..]).map_err(|e| bad(format!("not a .npy file: {e}")))?;
    let shape = npy.shape().to_vec();
    let [h, w, 3] = shape[..] else {
        return Err(bad(format!(
            "array of shape {shape:?}: expected (height, width, 3) normals"
        )));
    };
    if npy.order() != npyz::Order::C {
        return Err(bad(
            "array in Fortran order: save it in C order (numpy's default)".into(),
        ));
    }
    let npyz::DType::Plain(kind) = npy.dtype() else {
        return Err(bad("a structured array: expected float32 or float64".into()));
    };
    let kind = kind.to_string();
    let values: Vec<f32> = if kind.ends_with("f4") {
        npy.into_vec::<f32>()
    } else if kind.ends_with("f8") {
        npy.into_vec::<f64>()
            .map(|v| v.into_iter().map(|x| x as f32).collect())
    } else {
        return Err(bad(format!("dtype {kind}: expected float32 or float64")));
    }
    .map_err(|e| bad(format!("cannot read the array: {e}")))?;
    let (w, h) = (w as usize, h as usize);
    if values.len() != w * h * 3 {
        return Err(bad(format!("{} values for shape {shape:?}", values.len())));
    }
    Image::from_vec(
        w,
        h,
        values.chunks_exact(3).map(|n| [n[0], n[1], n[2]]).collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One normal tilted up-right towards the camera, in each format and
    /// frame, reads back as ours.
    #[test]
    fn every_format_and_frame_reads_back_in_ours() {
        let dir = tempfile::tempdir().unwrap();
        let ours = [0.6f32, 0.0, 0.8];
        let up = [0.0f32, 0.6, 0.8];
        let map = Image::from_vec(2, 1, vec![ours, up]).unwrap();
        for axes in Axes::NAMES.map(|n| Axes::parse(n).unwrap()) {
            assert_eq!(Axes::parse(axes.name()), Some(axes));
            let theirs = map.map(|&n| {
                // Every frame is its own inverse.
                axes.to_ours(n)
            });
            let npy = dir.path().join("p.npy");
            let flat: Vec<f32> = theirs.data().iter().flatten().copied().collect();
            crate::export::write_npy_f32(&npy, &[1, 2, 3], flat).unwrap();
            let exr = dir.path().join("p.exr");
            let channels: Vec<Image<f32>> = (0..3).map(|c| theirs.map(|n| n[c])).collect();
            io::write_exr(
                &exr,
                &[
                    ("R", &channels[0]),
                    ("G", &channels[1]),
                    ("B", &channels[2]),
                ],
            )
            .unwrap();
            let png = dir.path().join("p.png");
            io::write_png_rgb16(
                &png,
                &theirs.map(|n| n.map(|v| ((v + 1.0) / 2.0 * 65535.0).round() as u16)),
            )
            .unwrap();
            for file in [&npy, &exr, &png] {
                let back = read(file, axes).unwrap();
                for (b, want) in back.data().iter().zip([ours, up]) {
                    for k in 0..3 {
                        assert!((b[k] - want[k]).abs() < 1e-4, "{file:?} {axes:?}: {b:?}");
                    }
                }
            }
        }
        // The frames differ: the up normal in OpenCV's frame is down and away.
        assert_eq!(Axes::Opencv.to_ours(up), [0.0, -0.6, -0.8]);
        assert_eq!(Axes::Image.to_ours(up), [0.0, -0.6, 0.8]);
    }

    /// A sphere's normals fit our frame along its outline; flipped in y
    /// they fit the image frame.
    #[test]
    fn the_frame_that_fits_an_outline_is_found() {
        let n = 33;
        let c = (n as f32 - 1.0) / 2.0;
        let normal = |x: usize, y: usize| {
            let (u, v) = ((x as f32 - c) / 15.0, (c - y as f32) / 15.0);
            let r2 = u * u + v * v;
            (r2 < 1.0).then(|| [u, v, (1.0 - r2).sqrt()])
        };
        let normals = Image::from_fn(n, n, |x, y| normal(x, y).unwrap_or([0.0; 3]));
        let mask = Image::from_fn(n, n, |x, y| normal(x, y).is_some());
        let (ours, image) = frame_fit(&normals, &mask).unwrap();
        assert!(ours > 0.8 && image < 0.3, "{ours} {image}");
        let flipped = normals.map(|&m| Axes::Image.to_ours(m));
        let (ours, image) = frame_fit(&flipped, &mask).unwrap();
        assert!(ours < 0.3 && image > 0.8, "{ours} {image}");
    }

    #[test]
    fn wrong_shapes_and_types_are_refused_by_name() {
        let dir = tempfile::tempdir().unwrap();
        let npy = dir.path().join("flat.npy");
        crate::export::write_npy_f32(&npy, &[2, 3], [0.0; 6]).unwrap();
        let e = read(&npy, Axes::Ours).unwrap_err().to_string();
        assert!(
            e.contains("flat.npy") && e.contains("(height, width, 3)"),
            "{e}"
        );
        let txt = dir.path().join("p.txt");
        std::fs::write(&txt, "0 0 1").unwrap();
        let e = read(&txt, Axes::Ours).unwrap_err().to_string();
        assert!(e.contains("p.txt") && e.contains(".npy"), "{e}");
        std::fs::write(&npy, "not numpy").unwrap();
        let e = read(&npy, Axes::Ours).unwrap_err().to_string();
        assert!(e.contains("not a .npy file"), "{e}");
    }
}
