//! Write → read round trips of a view and the errors bad views must give.

use sfp_core::Image;
use sfp_core::analytic::{AnalyticScene, Shape};
use sfp_core::io;
use sfp_core::view::{View, ViewInput};
use std::path::Path;

fn sample_view() -> View {
    AnalyticScene {
        shape: Shape::Blobs,
        size: 40,
        light: [0.2, 0.4, 1.0],
        ..AnalyticScene::default()
    }
    .render()
    .unwrap()
}

fn written(dir: &Path) -> View {
    let view = sample_view();
    view.write(dir).unwrap();
    view
}

#[test]
fn round_trip_is_bit_exact() {
    let dir = tempfile::tempdir().unwrap();
    let view = written(dir.path());
    assert!(View::is_complete(dir.path()));
    let back = View::read(dir.path()).unwrap();
    assert_eq!(back.input, view.input);
    assert_eq!(back.meta, view.meta);
    let (a, b) = (back.gt.unwrap(), view.gt.unwrap());
    let bits = |i: &Image<f32>| i.data().iter().map(|v| v.to_bits()).collect::<Vec<_>>();
    assert_eq!(a.normals, b.normals);
    assert_eq!(
        bits(a.depth.as_ref().unwrap()),
        bits(b.depth.as_ref().unwrap()),
        "depth holds NaN outside the mask"
    );
    let (sa, sb) = (a.stokes.unwrap(), b.stokes.unwrap());
    for k in 0..3 {
        assert_eq!(bits(&sa[k]), bits(&sb[k]));
    }
    assert_eq!(a.albedo, b.albedo);
    for p in ["intensity", "dop", "aop", "normals"] {
        assert!(
            dir.path()
                .join("preview")
                .join(format!("{p}.png"))
                .is_file()
        );
    }
    // No temporary files are left behind.
    for sub in ["", "input", "gt", "preview"] {
        for e in std::fs::read_dir(dir.path().join(sub)).unwrap() {
            let name = e.unwrap().file_name().into_string().unwrap();
            assert!(!name.ends_with(".tmp"), "{name}");
        }
    }
}

fn read_err(dir: &Path) -> String {
    View::read(dir).unwrap_err().to_string()
}

/// The view reads (a reconstruction needs only `input/`); its ground-truth
/// problems, joined.
fn gt_problems(dir: &Path) -> (View, String) {
    let view = View::read(dir).unwrap();
    let problems = view.problems.join("\n");
    (view, problems)
}

#[test]
fn truncated_or_corrupted_files_are_named() {
    let dir = tempfile::tempdir().unwrap();
    written(dir.path());
    let pol = dir.path().join("input/pol_045.png");
    let bytes = std::fs::read(&pol).unwrap();
    std::fs::write(&pol, &bytes[..bytes.len() / 3]).unwrap();
    let e = read_err(dir.path());
    assert!(e.contains("pol_045.png"), "{e}");

    let dir = tempfile::tempdir().unwrap();
    written(dir.path());
    std::fs::write(dir.path().join("gt/normals.exr"), b"not an exr").unwrap();
    let (view, e) = gt_problems(dir.path());
    assert!(view.gt.is_none() && e.contains("normals.exr"), "{e}");

    let dir = tempfile::tempdir().unwrap();
    written(dir.path());
    std::fs::write(dir.path().join("meta.json"), b"{ \"eta\": \"x\" ").unwrap();
    let e = read_err(dir.path());
    assert!(e.contains("meta.json"), "{e}");
}

#[test]
fn missing_file_and_missing_channel_are_named() {
    let dir = tempfile::tempdir().unwrap();
    written(dir.path());
    std::fs::remove_file(dir.path().join("input/pol_090.png")).unwrap();
    assert!(read_err(dir.path()).contains("pol_090.png"));

    let dir = tempfile::tempdir().unwrap();
    written(dir.path());
    io::write_exr(
        &dir.path().join("gt/stokes.exr"),
        &[("S0", &Image::new(40, 40, 1.0))],
    )
    .unwrap();
    let (view, e) = gt_problems(dir.path());
    assert!(e.contains("stokes.exr") && e.contains("S1"), "{e}");
    // The normals still evaluate; only the broken layer is dropped.
    let gt = view.gt.unwrap();
    assert!(gt.stokes.is_none() && gt.depth.is_some());
}

#[test]
fn mixed_bit_depth_and_size_mismatch_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    written(dir.path());
    io::write_png8(
        &dir.path().join("input/pol_135.png"),
        &Image::new(40, 40, 9u8),
    )
    .unwrap();
    let e = read_err(dir.path());
    assert!(e.contains("pol_135.png") && e.contains("8-bit"), "{e}");

    let dir = tempfile::tempdir().unwrap();
    written(dir.path());
    io::write_png16(
        &dir.path().join("input/pol_135.png"),
        &Image::new(41, 40, 9u16),
    )
    .unwrap();
    let e = read_err(dir.path());
    assert!(e.contains("pol_135.png") && e.contains("size"), "{e}");
}

#[test]
fn empty_mask_and_impossible_dop_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    written(dir.path());
    io::write_png8(&dir.path().join("input/mask.png"), &Image::new(40, 40, 0u8)).unwrap();
    let e = read_err(dir.path());
    assert!(e.contains("mask.png") && e.contains("empty"), "{e}");

    // Swapping 0° and 45° for a bright constant pattern makes the DoP exceed 1.
    let dir = tempfile::tempdir().unwrap();
    written(dir.path());
    let input = dir.path().join("input");
    for (f, v) in [
        ("pol_000.png", 60000u16),
        ("pol_045.png", 60000),
        ("pol_090.png", 0),
        ("pol_135.png", 0),
    ] {
        io::write_png16(&input.join(f), &Image::new(40, 40, v)).unwrap();
    }
    let e = read_err(dir.path());
    assert!(e.contains("DoP exceeds 1"), "{e}");
}

#[test]
fn non_finite_ground_truth_normals_are_reported() {
    let dir = tempfile::tempdir().unwrap();
    written(dir.path());
    let mut r = Image::new(40, 40, 0.0f32);
    *r.get_mut(3, 4) = f32::NAN;
    let z = Image::new(40, 40, 1.0f32);
    io::write_exr(
        &dir.path().join("gt/normals.exr"),
        &[("R", &r), ("G", &z), ("B", &z)],
    )
    .unwrap();
    let (view, e) = gt_problems(dir.path());
    assert!(
        view.gt.is_none() && e.contains("normals.exr") && e.contains("column 3, row 4"),
        "{e}"
    );
}

#[test]
fn a_view_without_meta_or_mask_still_reads() {
    let dir = tempfile::tempdir().unwrap();
    written(dir.path());
    std::fs::remove_file(dir.path().join("meta.json")).unwrap();
    std::fs::remove_file(dir.path().join("input/mask.png")).unwrap();
    std::fs::remove_dir_all(dir.path().join("gt")).unwrap();
    let v = View::read(dir.path()).unwrap();
    assert!(v.meta.is_none() && v.input.mask.is_none() && v.gt.is_none());
}

#[test]
fn geometric_normals_and_specular_round_trip_when_present() {
    let dir = tempfile::tempdir().unwrap();
    let mut view = sample_view();
    let gt = view.gt.as_mut().unwrap();
    let geometric = gt.normals.map(|n| [n[1], n[0], n[2]]);
    let specular = gt.normals.map(|n| n[2] * 0.5);
    gt.geometric_normals = Some(geometric.clone());
    gt.specular = Some(specular.clone());
    view.write(dir.path()).unwrap();
    let back = View::read(dir.path()).unwrap().gt.unwrap();
    assert_eq!(back.geometric_normals, Some(geometric));
    assert_eq!(back.specular, Some(specular));
    // Views without them (all views before these layers existed) read as before.
    let plain = tempfile::tempdir().unwrap();
    written(plain.path());
    let gt = View::read(plain.path()).unwrap().gt.unwrap();
    assert!(gt.geometric_normals.is_none() && gt.specular.is_none());
    assert!(!plain.path().join("gt/specular.exr").exists());
}

#[test]
fn ground_truth_of_normals_alone_reads() {
    // Views from other tools often have only gt/normals.exr.
    let dir = tempfile::tempdir().unwrap();
    let view = written(dir.path());
    for f in ["depth.exr", "stokes.exr", "albedo.exr"] {
        std::fs::remove_file(dir.path().join("gt").join(f)).unwrap();
    }
    let back = View::read(dir.path()).unwrap();
    assert!(back.problems.is_empty(), "{:?}", back.problems);
    let gt = back.gt.unwrap();
    assert_eq!(gt.normals, view.gt.unwrap().normals);
    assert!(gt.depth.is_none() && gt.stokes.is_none() && gt.albedo.is_none());
}

/// The sample view in colour: each polarizer's channels are its grey codes
/// scaled by a tint, the ground truth's channel Stokes likewise.
fn colour_view() -> View {
    let mut view = sample_view();
    let tint = [0.9f32, 0.5, 0.2];
    let rgb = view
        .input
        .pol
        .each_ref()
        .map(|p| p.map(|&v| tint.map(|t| (f32::from(v) * t).round() as u16)));
    view.input = ViewInput::of_colour(rgb, view.input.bits, view.input.mask.clone());
    let gt = view.gt.as_mut().unwrap();
    let grey = gt.stokes.clone().unwrap();
    gt.channel_stokes = Some(tint.map(|t| grey.each_ref().map(|s| s.map(|&v| v * t))));
    view
}

#[test]
fn a_colour_view_round_trips_and_reads_as_its_luminance() {
    let dir = tempfile::tempdir().unwrap();
    let view = colour_view();
    view.write(dir.path()).unwrap();
    let back = View::read(dir.path()).unwrap();
    assert_eq!(back.input, view.input);
    let rgb = back.input.colour.as_ref().unwrap();
    // Methods read `pol`: the Rec. 709 luminance of the channels.
    let p = *rgb[1].get(20, 20);
    let want = (0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2]))
        .round() as u16;
    assert_eq!(*back.input.pol[1].get(20, 20), want);
    assert!(p[0] > p[1] && p[1] > p[2], "{p:?}");
    assert_eq!(
        back.gt.as_ref().unwrap().channel_stokes,
        view.gt.as_ref().unwrap().channel_stokes
    );
    // Per channel, DoP and AoP of a tinted grey view are the grey one's.
    let channels = back.input.channel_polarimetry().unwrap();
    let grey = back.input.polarimetry();
    let i = back.input.pol[0].index(20, 20);
    for c in &channels {
        assert!((c.dop.data()[i] - grey.dop.data()[i]).abs() < 0.01);
    }
    // The intensity preview is in colour.
    let picture = io::read_png_rgb(&dir.path().join("preview/intensity.png")).unwrap();
    assert!(
        picture.data().iter().any(|p| p[0] > p[1] + 20),
        "a grey picture"
    );
    // The grey view of the same input writes grey PNGs.
    let grey_dir = tempfile::tempdir().unwrap();
    View {
        input: back.input.to_grey(),
        ..back.clone()
    }
    .write(grey_dir.path())
    .unwrap();
    let grey_back = View::read(grey_dir.path()).unwrap();
    assert_eq!(
        (grey_back.input.colour, &grey_back.input.pol),
        (None, &back.input.pol)
    );
}

#[test]
fn grey_and_colour_polarizer_images_do_not_mix() {
    let dir = tempfile::tempdir().unwrap();
    colour_view().write(dir.path()).unwrap();
    io::write_png16(
        &dir.path().join("input/pol_090.png"),
        &Image::new(40, 40, 9u16),
    )
    .unwrap();
    let e = read_err(dir.path());
    assert!(
        e.contains("pol_090.png") && e.contains("grey") && e.contains("colour"),
        "{e}"
    );
}
