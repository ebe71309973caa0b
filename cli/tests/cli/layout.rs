//! `sfp import --layout` checks what it reads as the other imports do: the
//! polarizer images against their labels, one bit depth, a non-empty mask,
//! ground-truth normals that are unit vectors facing the camera, a plain
//! view name, and `--angles-from`.

use crate::common::*;
use sfp_core::Image;
use std::path::Path;

/// A layout of one analytic view named `v` under `dir/layout`.
fn layout(dir: &Path) -> String {
    let view = dir.join("view").display().to_string();
    let layout = dir.join("layout").display().to_string();
    sfp_ok(&["analytic", "--size", "32", "--out", &view]);
    sfp_ok(&["export", &view, "--out", &layout, "--name", "v"]);
    layout
}

fn import(layout: &str, out: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec!["import", "--layout", layout, "--out", out.to_str().unwrap()];
    args.extend(extra);
    sfp(&args)
}

#[test]
fn bad_ground_truth_normals_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let l = layout(dir.path());
    let normal = Path::new(&l).join("normal/v.png");
    let good = sfp_core::io::read_png_rgb16(&normal).unwrap();
    let (w, h) = good.size();
    for (what, picture, needle) in [
        ("grey", Image::new(w, h, [32768u16; 3]), "no unit normal"),
        ("black", Image::new(w, h, [1u16; 3]), "no unit normal"),
        ("none", Image::new(w, h, [0u16; 3]), "holds no normal"),
        (
            "back-facing",
            good.map(|p| {
                if *p == [0; 3] {
                    *p
                } else {
                    [p[0], p[1], 65535 - p[2]]
                }
            }),
            "face away",
        ),
    ] {
        sfp_core::io::write_png_rgb16(&normal, &picture).unwrap();
        let o = import(&l, &dir.path().join(what), &[]);
        assert_eq!(o.status.code(), Some(2), "{what}: {}", stderr(&o));
        assert_clean_failure(&o, needle);
        assert!(!dir.path().join(what).exists());
    }
}

#[test]
fn the_images_are_checked_like_any_capture() {
    let dir = tempfile::tempdir().unwrap();
    let l = layout(dir.path());
    let pol = |a: &str| Path::new(&l).join(a).join("v.png");
    let read = |a: &str| sfp_core::io::read_gray_png(&pol(a)).unwrap().into_u16();
    // Swapped 45° and 135°: a warning naming the order that fits.
    let (p45, p135) = (read("pol045"), read("pol135"));
    let eight = |img: &Image<u16>| img.map(|&v| v.min(255) as u8);
    sfp_core::io::write_png16(&pol("pol045"), &p135).unwrap();
    sfp_core::io::write_png16(&pol("pol135"), &p45).unwrap();
    let o = import(&l, &dir.path().join("swapped"), &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("fits the data"), "{}", stderr(&o));
    // The same images read as measured from the vertical, clockwise: the
    // labels are turned, so the meta records the frame.
    let o = import(
        &l,
        &dir.path().join("cw"),
        &["--angles-from", "vertical-cw"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let meta = read_json(&dir.path().join("cw/meta.json"));
    assert_eq!(meta["capture"]["angles_from"], "vertical-cw", "{meta}");
    let a = sfp_core::view::View::read(&dir.path().join("swapped")).unwrap();
    let b = sfp_core::view::View::read(&dir.path().join("cw")).unwrap();
    assert_ne!(a.input.pol, b.input.pol, "--angles-from was ignored");
    // Mixed bit depths.
    let p90 = read("pol090");
    sfp_core::io::write_png8(&pol("pol090"), &eight(&p90)).unwrap();
    let o = import(&l, &dir.path().join("mixed"), &[]);
    assert_clean_failure(&o, "must come from one capture");
    sfp_core::io::write_png16(&pol("pol090"), &p90).unwrap();
    // An empty mask.
    let mask = Path::new(&l).join("mask/v.png");
    let (w, h) = read("pol000").size();
    sfp_core::io::write_png8(&mask, &Image::new(w, h, 0u8)).unwrap();
    let o = import(&l, &dir.path().join("empty"), &[]);
    assert_clean_failure(&o, "mask is empty");
    // All saturated.
    std::fs::remove_file(&mask).unwrap();
    for a in ["pol000", "pol045", "pol090", "pol135"] {
        sfp_core::io::write_png16(&pol(a), &Image::new(w, h, 65535u16)).unwrap();
    }
    let o = import(&l, &dir.path().join("saturated"), &[]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    // A name that is a path reads nothing outside the layout.
    let o = import(&l, &dir.path().join("x"), &["--name", "../layout/pol000/v"]);
    assert_clean_failure(&o, "--name");
}

/// `sfp dataset --layout sfpuel` writes the views into the layout `sfp
/// export` writes, the same bytes as exporting the rendered view folders;
/// two shards share one layout, and a rerun renders nothing.
#[test]
fn a_dataset_renders_straight_into_a_layout_in_shards() {
    let dir = tempfile::tempdir().unwrap();
    let layout = dir.path().join("layout");
    let l = layout.to_str().unwrap();
    let base = [
        "dataset", "builtin", "--size", "16", "--spp", "2", "--views", "1",
    ];
    for shard in ["1/2", "2/2"] {
        let o = sfp_ok(
            &[
                &base[..],
                &["--layout", "sfpuel", "--shard", shard, "--out", l],
            ]
            .concat(),
        );
        let text = String::from_utf8_lossy(&o.stdout).into_owned();
        assert!(
            text.contains(&format!("shard {shard}")) && text.contains("views a minute"),
            "{text}"
        );
    }
    let names: Vec<String> = std::fs::read_dir(layout.join("pol000"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names.len(), 7, "{names:?}");
    let o = sfp(&[&base[..], &["--layout", "sfpuel", "--out", l]].concat());
    assert!(
        String::from_utf8_lossy(&o.stdout).contains("(0 rendered"),
        "{}",
        stderr(&o)
    );
    // The same as rendering view folders and exporting one.
    let views = dir.path().join("views");
    sfp_ok(&[&base[..], &["--out", views.to_str().unwrap()]].concat());
    let exported = dir.path().join("exported");
    let view = views.join("torus_0");
    sfp_ok(&[
        "export",
        view.to_str().unwrap(),
        "--out",
        exported.to_str().unwrap(),
    ]);
    for file in [
        "pol045/torus_0.png",
        "mask/torus_0.png",
        "normal/torus_0.npy",
    ] {
        let a = std::fs::read(layout.join(file)).unwrap();
        assert_eq!(a, std::fs::read(exported.join(file)).unwrap(), "{file}");
    }
    assert_clean_failure(
        &sfp(&[&base[..], &["--layout", "deepsfp", "--out", l]].concat()),
        "sfpuel",
    );
}

/// SfPUEL publishes its data in the per-angle folders with RGB polarizer
/// PNGs and no `layout.json`: read as their Rec. 709 luminance, a view
/// tinted yellow (blue 0) imports with the DoP and AoP of its grey original.
#[test]
fn a_colour_layout_without_a_sidecar_is_read_as_its_luminance() {
    let dir = tempfile::tempdir().unwrap();
    let l = layout(dir.path());
    let layout = Path::new(&l);
    std::fs::remove_file(layout.join("layout.json")).unwrap();
    for folder in ["pol000", "pol045", "pol090", "pol135"] {
        let path = layout.join(folder).join("v.png");
        let grey = sfp_core::io::read_gray_png(&path).unwrap().into_u16();
        let tinted = grey.map(|&c| [c, c, 0]);
        sfp_core::io::write_png_rgb16(&path, &tinted).unwrap();
    }
    let out = dir.path().join("imported");
    let o = import(&l, &out, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    let original = sfp_core::view::View::read(&dir.path().join("view")).unwrap();
    let imported = sfp_core::view::View::read(&out).unwrap();
    let (a, b) = (original.input.polarimetry(), imported.input.polarimetry());
    let mask = original.input.mask.unwrap();
    let mut worst: (f32, f32) = (0.0, 0.0);
    for i in (0..mask.len()).filter(|&i| mask.data()[i]) {
        worst.0 = worst.0.max((a.dop.data()[i] - b.dop.data()[i]).abs());
        let turn = (a.aop.data()[i] - b.aop.data()[i]).abs();
        worst.1 = worst.1.max(turn.min(std::f32::consts::PI - turn));
    }
    assert!(worst.0 < 1e-3 && worst.1 < 1e-2, "{worst:?}");
    assert!(imported.gt.is_some());
}

/// Normals stored with y down (image rows) are named as such along the
/// mask's outline, and `--axes image` reads them into our frame.
#[test]
fn normals_in_another_frame_are_named_and_read_with_axes() {
    let dir = tempfile::tempdir().unwrap();
    let l = layout(dir.path());
    let normal = Path::new(&l).join("normal/v.png");
    let ours = sfp_core::io::read_png_rgb16(&normal).unwrap();
    let flipped = ours.map(|p| {
        if *p == [0; 3] {
            *p
        } else {
            [p[0], 65535 - p[1], p[2]]
        }
    });
    sfp_core::io::write_png_rgb16(&normal, &flipped).unwrap();
    let out = dir.path().join("as-is");
    let o = import(&l, &out, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("--axes image"), "{}", stderr(&o));
    let out = dir.path().join("image");
    let o = import(&l, &out, &["--axes", "image"]);
    assert!(
        o.status.success() && !stderr(&o).contains("--axes"),
        "{}",
        stderr(&o)
    );
    let original = sfp_core::view::View::read(&dir.path().join("view")).unwrap();
    let read = sfp_core::view::View::read(&out).unwrap();
    let (a, b) = (original.gt.unwrap().normals, read.gt.unwrap().normals);
    let worst = a
        .data()
        .iter()
        .zip(b.data())
        .map(|(p, q)| (0..3).map(|k| (p[k] - q[k]).abs()).fold(0.0f32, f32::max))
        .fold(0.0f32, f32::max);
    assert!(worst < 1e-3, "{worst}");
    // OpenCV's normals face away in our frame: the refusal names the option.
    let backwards = ours.map(|p| {
        if *p == [0; 3] {
            *p
        } else {
            [p[0], 65535 - p[1], 65535 - p[2]]
        }
    });
    sfp_core::io::write_png_rgb16(&normal, &backwards).unwrap();
    assert_clean_failure(&import(&l, &dir.path().join("x"), &[]), "--axes opencv");
    let o = import(&l, &dir.path().join("cv"), &["--axes", "opencv"]);
    assert!(o.status.success(), "{}", stderr(&o));
}

/// A third-party SfPUEL folder built from a colour render: RGB 8-bit
/// polarizer PNGs, 16-bit normals, no `layout.json`. It imports as the
/// colour view it came from, its ground truth the PNG's decoded normals;
/// the same folder with its normals' y flipped draws the warning naming
/// the frame that fits.
#[test]
fn a_colour_sfpuel_folder_imports_as_the_colour_view_it_came_from() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("colour.toml");
    let text = include_str!("../../../scenes/examples/sphere.toml")
        .replace("width = 128", "width = 40")
        .replace("height = 128", "height = 40")
        .replace("max_depth = 1", "max_depth = 1\ncolour = true")
        .replace("eta = 1.5", "eta = 1.5, tint = [1.0, 0.6, 0.25]")
        .replace("bits = 16", "bits = 8");
    std::fs::write(&scene, text).unwrap();
    let view = dir.path().join("view");
    sfp_ok(&[
        "render",
        scene.to_str().unwrap(),
        "--out",
        view.to_str().unwrap(),
    ]);
    let layout = dir.path().join("sfpuel");
    let l = layout.to_str().unwrap();
    sfp_ok(&["export", view.to_str().unwrap(), "--out", l, "--name", "v"]);
    std::fs::remove_file(layout.join("layout.json")).unwrap();
    std::fs::remove_file(layout.join("normal/v.npy")).unwrap();
    let png = sfp_core::io::read_polarizer_png(&layout.join("pol045/v.png")).unwrap();
    assert!(
        matches!(png, sfp_core::io::PolarizerPng::Colour { bits: 8, .. }),
        "{png:?}"
    );
    let out = dir.path().join("imported");
    let o = import(l, &out, &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains("--axes"), "{}", stderr(&o));
    let rendered = sfp_core::view::View::read(&view).unwrap();
    let imported = sfp_core::view::View::read(&out).unwrap();
    assert!(imported.input.colour.is_some(), "the colour was lost");
    assert_eq!(imported.input.colour, rendered.input.colour);
    assert_eq!(imported.input.pol, rendered.input.pol);
    assert_eq!(imported.input.mask, rendered.input.mask);
    // The ground truth is the PNG's normals, 2·v/65535 − 1.
    let decoded = sfp_core::io::read_png_rgb16(&layout.join("normal/v.png")).unwrap();
    let gt = imported.gt.as_ref().unwrap();
    let mut worst = 0.0f64;
    for (p, n) in decoded.data().iter().zip(gt.normals.data()) {
        if *p == [0; 3] {
            continue;
        }
        for k in 0..3 {
            let v = 2.0 * f64::from(p[k]) / 65535.0 - 1.0;
            worst = worst.max((v - f64::from(n[k])).abs());
        }
    }
    assert!(worst < 2e-3, "ground truth differs from the PNG by {worst}");
    // Flipped normals (y down, as image-frame tools write them).
    let flipped = decoded.map(|p| {
        if *p == [0; 3] {
            *p
        } else {
            [p[0], 65535 - p[1], p[2]]
        }
    });
    sfp_core::io::write_png_rgb16(&layout.join("normal/v.png"), &flipped).unwrap();
    let o = import(l, &dir.path().join("flipped"), &[]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("y axis looks reversed") && stderr(&o).contains("--axes image"),
        "{}",
        stderr(&o)
    );
}
