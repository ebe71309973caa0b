//! Colour captures: a rendered colour view's IMX250MYR mosaic (2×2
//! polarizer cells 90° 45° / 135° 0°, each cell under one filter, the cells
//! in RGGB order) imports back with `--colour rggb` to the view it came
//! from within the demosaicing error; four RGB polarizer images import as
//! a colour view.

use crate::common::*;
use sfp_core::Image;
use sfp_core::view::{View, ViewInput};
use std::path::Path;

/// A colour render of the example sphere, `size`², with its raw mosaic.
fn colour_render(dir: &Path, size: usize) -> View {
    let scene = dir.join("colour.toml");
    let text = include_str!("../../../scenes/examples/sphere.toml")
        .replace("width = 128", &format!("width = {size}"))
        .replace("height = 128", &format!("height = {size}"))
        .replace("max_depth = 1", "max_depth = 1\ncolour = true")
        .replace("eta = 1.5", "eta = 1.5, tint = [1.0, 0.6, 0.25]")
        .replace("noise = false", "noise = false\nmosaic = true");
    std::fs::write(&scene, text).unwrap();
    let view = dir.join("view");
    sfp_ok(&[
        "render",
        scene.to_str().unwrap(),
        "--out",
        view.to_str().unwrap(),
    ]);
    View::read(&view).unwrap()
}

/// Mean |Δs0| (of full scale), |ΔDoP| over `mask` and the three channels,
/// and mean |ΔAoP| (degrees) where `b`'s DoP is at least 0.05 (below, the
/// AoP is hardly defined).
fn errors(a: &[Image<[u16; 3]>; 4], b: &[Image<[u16; 3]>; 4], mask: &[bool]) -> [f64; 3] {
    let channels = |rgb: &[Image<[u16; 3]>; 4]| {
        ViewInput::of_colour(rgb.clone(), 16, None).channel_polarimetry()
    };
    let (pa, pb) = (channels(a).unwrap(), channels(b).unwrap());
    let mut sum = [0.0; 3];
    let (mut n, mut polarized) = (0.0, 0.0);
    for c in 0..3 {
        let (p, q) = (&pa[c], &pb[c]);
        for i in (0..mask.len()).filter(|&i| mask[i]) {
            n += 1.0;
            sum[0] += f64::from(2.0 * (p.intensity.data()[i] - q.intensity.data()[i])).abs();
            sum[1] += f64::from(p.dop.data()[i] - q.dop.data()[i]).abs();
            if q.dop.data()[i] >= 0.05 {
                polarized += 1.0;
                let d =
                    f64::from(p.aop.data()[i] - q.aop.data()[i]).rem_euclid(std::f64::consts::PI);
                sum[2] += d.min(std::f64::consts::PI - d).to_degrees();
            }
        }
    }
    [sum[0] / n, sum[1] / n, sum[2] / polarized]
}

#[test]
fn a_colour_mosaic_imports_back_within_the_demosaicing_error() {
    let dir = tempfile::tempdir().unwrap();
    let view = colour_render(dir.path(), 96);
    let rgb = view.input.colour.as_ref().unwrap();
    let mask = view.input.mask.as_ref().unwrap();
    let raw = dir.path().join("view/input/raw.png");
    let (w, h) = mask.size();
    // Masks: the view's, and for the superpixel demosaic its 4×4 blocks
    // wholly inside the object.
    let whole: Vec<bool> = (0..(w / 4) * (h / 4))
        .map(|i| {
            let (bx, by) = (i % (w / 4), i / (w / 4));
            (0..16).all(|j| *mask.get(4 * bx + j % 4, 4 * by + j / 4))
        })
        .collect();
    let masks = dir.path().join("masks");
    std::fs::create_dir_all(&masks).unwrap();
    let full_mask = masks.join("bilinear.png");
    sfp_core::io::write_png8(&full_mask, &mask.map(|&m| if m { 255 } else { 0 })).unwrap();
    let block_mask = masks.join("superpixel.png");
    let blocks_image = Image::from_vec(w / 4, h / 4, whole.clone()).unwrap();
    sfp_core::io::write_png8(&block_mask, &blocks_image.map(|&m| if m { 255 } else { 0 })).unwrap();
    let import = |method: &str| {
        let out = dir.path().join(method);
        let mask = masks.join(format!("{method}.png"));
        sfp_ok(&[
            "import",
            "--mosaic",
            raw.to_str().unwrap(),
            "--colour",
            "rggb",
            "--demosaic",
            method,
            "--mask",
            mask.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        View::read(&out).unwrap()
    };
    // Bilinear: full resolution, against the view itself, inside the
    // object away from its outline (3 pixels: the tent's reach).
    let bilinear = import("bilinear");
    let inner: Vec<bool> = (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as isize, (i / w) as isize);
            (-3..=3).all(|dy| {
                (-3..=3).all(|dx| {
                    let (sx, sy) = (x + dx, y + dy);
                    (0..w as isize).contains(&sx)
                        && (0..h as isize).contains(&sy)
                        && *mask.get(sx as usize, sy as usize)
                })
            })
        })
        .collect();
    let b = errors(bilinear.input.colour.as_ref().unwrap(), rgb, &inner);
    // Superpixel: one pixel per 4×4 block, against the block's mean.
    let superpixel = import("superpixel");
    let blocks: [Image<[u16; 3]>; 4] = std::array::from_fn(|k| {
        Image::from_fn(w / 4, h / 4, |bx, by| {
            std::array::from_fn(|c| {
                let sum: u32 = (0..16)
                    .map(|j| u32::from(rgb[k].get(4 * bx + j % 4, 4 * by + j / 4)[c]))
                    .sum();
                ((sum + 8) / 16) as u16
            })
        })
    });
    let s = errors(superpixel.input.colour.as_ref().unwrap(), &blocks, &whole);
    eprintln!(
        "IMX250MYR round trip, mean over the object and R, G, B: bilinear |Δs0| {:.4} of full \
         scale, |ΔDoP| {:.4}, |ΔAoP| {:.2}°; superpixel |Δs0| {:.4}, |ΔDoP| {:.4}, |ΔAoP| {:.2}°",
        b[0], b[1], b[2], s[0], s[1], s[2]
    );
    // The errors of interpolation: a plane's photosites lie 4 pixels apart
    // (bilinear), a superpixel's four angles 1 pixel apart and its colours
    // 2 (false polarization where the shading changes fast).
    assert!(b[0] < 0.005 && b[1] < 0.02 && b[2] < 8.0, "bilinear {b:?}");
    assert!(s[0] < 0.02 && s[1] < 0.1 && s[2] < 25.0, "superpixel {s:?}");
    let meta = read_json(&dir.path().join("bilinear/meta.json"));
    assert_eq!(meta["capture"]["colour"], "rggb", "{meta}");
    // Another order reads other colours: red and blue swapped.
    let out = dir.path().join("bggr");
    sfp_ok(&[
        "import",
        "--mosaic",
        raw.to_str().unwrap(),
        "--colour",
        "bggr",
        "--mask",
        block_mask.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    let swapped = View::read(&out).unwrap().input.colour.unwrap();
    let sp = superpixel.input.colour.as_ref().unwrap();
    assert_eq!(swapped[0].get(12, 12), &{
        let p = sp[0].get(12, 12);
        [p[2], p[1], p[0]]
    });
    let o = sfp(&[
        "import",
        "--mosaic",
        raw.to_str().unwrap(),
        "--colour",
        "rgbg",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_clean_failure(&o, "rggb, bggr, grbg or gbrg");
}

/// The colour capture `four_angles/{0,45,90,135}_1.png` (16-bit RGB, one
/// image per polarizer angle) of `SFP_REAL_DIR`, or of `../shared/real`
/// beside the repository; `None`, said, when neither holds it.
fn four_angles() -> Option<[String; 4]> {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let dir = std::env::var_os("SFP_REAL_DIR")
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| repo.join("../shared/real"))
        .join("four_angles");
    let files = ["0", "45", "90", "135"].map(|a| dir.join(format!("{a}_1.png")));
    if files.iter().all(|f| f.is_file()) {
        Some(files.map(|f| f.display().to_string()))
    } else {
        println!(
            "SKIPPED: no colour capture at {} (set SFP_REAL_DIR to a folder with \
             four_angles/{{0,45,90,135}}_1.png)",
            dir.display()
        );
        None
    }
}

#[test]
fn four_rgb_polarizer_images_import_as_a_colour_view() {
    let Some(files) = four_angles() else { return };
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("v");
    let mut args = vec!["import", "--angles"];
    args.extend(files.iter().map(String::as_str));
    args.extend(["--out", out.to_str().unwrap()]);
    let o = sfp_ok(&args);
    assert!(!stderr(&o).contains("not at the angles"), "{}", stderr(&o));
    let view = View::read(&out).unwrap();
    let rgb = view.input.colour.as_ref().expect("a colour view");
    assert_eq!((view.input.bits, rgb[0].size()), (16, (1024, 768)));
    // Methods read the luminance; the channels differ (a colour capture).
    let p = *rgb[0].get(512, 384);
    let lum = 0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2]);
    assert_eq!(*view.input.pol[0].get(512, 384), lum.round() as u16);
    assert!(rgb[0].data().iter().any(|p| p[0] != p[2]));
    // Mixed with a grey image, the import names it.
    let grey = dir.path().join("grey.png");
    sfp_core::io::write_png16(&grey, &view.input.pol[1]).unwrap();
    let mixed = dir.path().join("mixed");
    let mut args = vec!["import", "--angles", &files[0], grey.to_str().unwrap()];
    args.extend([files[2].as_str(), files[3].as_str()]);
    args.extend(["--out", mixed.to_str().unwrap()]);
    assert_clean_failure(&sfp(&args), "grey.png: a grey image, but the other");
}
