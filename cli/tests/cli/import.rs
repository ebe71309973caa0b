//! End-to-end checks of `sfp import`: mosaics and polarizer images become
//! views, their labels are checked against the data, and the options for
//! real cameras do what they say.

use crate::common::*;

#[test]
fn import_a_mosaic_and_reconstruct_it() {
    use sfp_core::capture::mosaic::{Pattern, mosaic};
    use sfp_core::io::{read_gray_png, write_png16};
    let dir = tempfile::tempdir().unwrap();
    let view = dir.path().join("view");
    sfp_ok(&["analytic", "--size", "64", "--out", view.to_str().unwrap()]);
    let input = view.join("input");
    let pol: [_; 4] = ["000", "045", "090", "135"].map(|a| {
        read_gray_png(&input.join(format!("pol_{a}.png")))
            .unwrap()
            .into_u16()
    });
    let raw = dir.path().join("raw.png");
    write_png16(&raw, &mosaic(&pol, Pattern::SONY)).unwrap();

    // Full resolution with the view's mask: the Stokes pipeline and Smith run.
    let imported = dir.path().join("imported");
    let mask = input.join("mask.png");
    let o = sfp_ok(&[
        "import",
        "--mosaic",
        raw.to_str().unwrap(),
        "--demosaic",
        "bilinear",
        "--mask",
        mask.to_str().unwrap(),
        "--out",
        imported.to_str().unwrap(),
    ]);
    let summary: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(
        (summary["width"].as_u64(), summary["bits"].as_u64()),
        (Some(64), Some(16))
    );
    // The right pattern: the AoP follows the outline.
    assert!(
        summary["silhouette_aop_agreement"].as_f64().unwrap() > 0.3,
        "{summary}"
    );
    let result = dir.path().join("result");
    sfp_ok(&[
        "reconstruct",
        imported.to_str().unwrap(),
        "--method",
        "smith",
        "--out",
        result.to_str().unwrap(),
    ]);
    assert!(result.join("normals.exr").is_file());

    // Bilinear without a mask: values interpolated across the limb give a
    // DoP above 1; those pixels leave the mask, counted, and the view reads.
    let unmasked = dir.path().join("unmasked");
    let o = sfp_ok(&[
        "import",
        "--mosaic",
        raw.to_str().unwrap(),
        "--demosaic",
        "bilinear",
        "--out",
        unmasked.to_str().unwrap(),
    ]);
    let summary: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(
        summary["dop_above_one_pixels"].as_u64().unwrap() > 0,
        "{summary}"
    );
    sfp_ok(&["inspect", unmasked.to_str().unwrap()]);

    // A valid but wrong pattern (0° and 90° swapped) keeps I0 + I90 =
    // I45 + I135; the AoP along the silhouette gives it away, and the
    // warning names the pattern that fits.
    let wrong = dir.path().join("wrong");
    let o = sfp_ok(&[
        "import",
        "--mosaic",
        raw.to_str().unwrap(),
        "--pattern",
        "0,135,45,90",
        "--demosaic",
        "bilinear",
        "--mask",
        mask.to_str().unwrap(),
        "--out",
        wrong.to_str().unwrap(),
    ]);
    assert!(
        stderr(&o).contains("--pattern 90,45,135,0 fits the data"),
        "{}",
        stderr(&o)
    );
    let summary: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert!(
        summary["silhouette_aop_agreement"].as_f64().unwrap() < -0.3,
        "{summary}"
    );

    // Super-pixel: half size, each value a photosite of the raw frame.
    let half = dir.path().join("half");
    sfp_ok(&[
        "import",
        "--mosaic",
        raw.to_str().unwrap(),
        "--out",
        half.to_str().unwrap(),
    ]);
    let p90 = read_gray_png(&half.join("input/pol_090.png"))
        .unwrap()
        .into_u16();
    assert_eq!(p90.size(), (32, 32));
    assert_eq!(p90.get(5, 7), pol[2].get(10, 14));

    // Four separate images come back unchanged; the window masks the dark
    // background (code 0) out.
    let four = dir.path().join("four");
    let files: Vec<String> = ["000", "045", "090", "135"]
        .iter()
        .map(|a| {
            input
                .join(format!("pol_{a}.png"))
                .to_str()
                .unwrap()
                .to_string()
        })
        .collect();
    let mut args = vec!["import", "--angles"];
    args.extend(files.iter().map(String::as_str));
    args.extend(["--window", "0.001,1", "--out", four.to_str().unwrap()]);
    let o = sfp_ok(&args);
    let back = read_gray_png(&four.join("input/pol_045.png"))
        .unwrap()
        .into_u16();
    assert!(back == pol[1]);
    let summary: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let inside = read_gray_png(&mask)
        .unwrap()
        .into_u16()
        .data()
        .iter()
        .filter(|&&m| m > 0)
        .count();
    let window = summary["mask_pixels"].as_u64().unwrap() as usize;
    assert!(
        window <= inside && window * 10 > inside * 9,
        "{window} of {inside}"
    );

    // Bad input: a wrong pattern, images of different sizes, a missing file.
    let o = sfp(&[
        "import",
        "--mosaic",
        raw.to_str().unwrap(),
        "--pattern",
        "90,45,135",
        "--out",
        half.to_str().unwrap(),
    ]);
    assert_clean_failure(&o, "mosaic pattern");
    let small = dir.path().join("small.png");
    write_png16(&small, &sfp_core::Image::new(8, 8, 100u16)).unwrap();
    let p0 = input.join("pol_000.png");
    let (p0, small) = (p0.to_str().unwrap(), small.to_str().unwrap());
    let o = sfp(&[
        "import",
        "--angles",
        p0,
        p0,
        p0,
        small,
        "--out",
        half.to_str().unwrap(),
    ]);
    assert_clean_failure(&o, "small.png");
    let o = sfp(&[
        "import",
        "--angles",
        p0,
        p0,
        p0,
        "absent.png",
        "--out",
        half.to_str().unwrap(),
    ]);
    assert_clean_failure(&o, "absent.png");
}

/// The labels of a capture are checked against the data: on an analytic
/// sphere and a path-traced one, every wrong order of four angle files and
/// every wrong mosaic pattern gets a warning naming the order or pattern
/// that fits, the right ones none; the figures are in meta.json.
#[test]
fn import_names_the_labels_that_fit_a_capture() {
    use sfp_core::capture::mosaic::{Pattern, mosaic};
    use sfp_core::capture::pattern_check::AngleOrder;
    use sfp_core::io::{read_gray_png, write_png16};
    let dir = tempfile::tempdir().unwrap();
    let analytic = dir.path().join("analytic");
    sfp_ok(&[
        "analytic",
        "--size",
        "64",
        "--out",
        analytic.to_str().unwrap(),
    ]);
    let rendered = dir.path().join("rendered");
    sfp_ok(&[
        "render",
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../scenes/examples/sphere.toml"
        ),
        "--size",
        "48x48",
        "--spp",
        "4",
        "--out",
        rendered.to_str().unwrap(),
    ]);
    let out = dir.path().join("out");
    let o_str = out.to_str().unwrap();
    for view in [&analytic, &rendered] {
        let input = view.join("input");
        let files: Vec<String> = ["000", "045", "090", "135"]
            .iter()
            .map(|a| input.join(format!("pol_{a}.png")).display().to_string())
            .collect();
        let mask = input.join("mask.png").display().to_string();
        for order in AngleOrder::all() {
            // File k of the command line holds the image at angle order.0[k].
            let mut args = vec!["import", "--angles"];
            args.extend(order.0.iter().map(|&a| files[a].as_str()));
            args.extend(["--mask", &mask, "--out", o_str]);
            let o = sfp_ok(&args);
            let meta = read_json(&out.join("meta.json"));
            let fits = meta["pattern_check"]["labelled_fits"].as_bool().unwrap();
            assert_eq!(fits, order == AngleOrder::LABELLED, "{order:?}: {meta}");
            if order == AngleOrder::LABELLED {
                assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));
            } else {
                let fix = format!("--angles {} fits the data", files.join(" "));
                assert!(stderr(&o).contains(&fix), "{order:?}: {}", stderr(&o));
            }
        }
    }

    // The case without a mask: 90° and 135° swapped. The pairing is
    // found; which of the two orders of that pairing closest to the given
    // one is right needs an outline, and the warning says so.
    let input = analytic.join("input");
    let file = |a: &str| input.join(format!("pol_{a}.png")).display().to_string();
    let (p0, p45, p90, p135) = (file("000"), file("045"), file("090"), file("135"));
    let o = sfp_ok(&["import", "--angles", &p0, &p45, &p135, &p90, "--out", o_str]);
    let e = stderr(&o);
    assert!(
        e.contains("I0 + I90 differs from I45 + I135")
            && e.contains(&format!("--angles {p0} {p45} {p90} {p135}"))
            && e.contains("unchecked"),
        "{e}"
    );
    // With the automatic mask the outline decides: one order is named.
    let o = sfp(&[
        "import",
        "--angles",
        &p0,
        &p45,
        &p135,
        &p90,
        "--auto-mask",
        "--out",
        o_str,
    ]);
    let e = stderr(&o);
    assert!(
        e.contains(&format!("--angles {p0} {p45} {p90} {p135} fits the data"))
            && !e.contains(" or ")
            && !e.contains("unchecked"),
        "{e}"
    );

    // Every mosaic pattern over a Sony raw frame.
    let pol: [_; 4] = ["000", "045", "090", "135"].map(|a| {
        read_gray_png(&input.join(format!("pol_{a}.png")))
            .unwrap()
            .into_u16()
    });
    let raw = dir.path().join("raw.png");
    write_png16(&raw, &mosaic(&pol, Pattern::SONY)).unwrap();
    let mask = input.join("mask.png").display().to_string();
    for order in AngleOrder::all() {
        let pattern = Pattern::SONY.relabel(|k| order.0[k]).to_string();
        let o = sfp(&[
            "import",
            "--mosaic",
            raw.to_str().unwrap(),
            "--pattern",
            &pattern,
            "--demosaic",
            "bilinear",
            "--mask",
            &mask,
            "--out",
            o_str,
        ]);
        assert!(o.status.success(), "{pattern}: {}", stderr(&o));
        if order == AngleOrder::LABELLED {
            assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));
        } else {
            assert!(
                stderr(&o).contains("--pattern 90,45,135,0 fits the data"),
                "{pattern}: {}",
                stderr(&o)
            );
        }
    }
}

/// `--angles-from vertical-cw`, `--auto-mask`, `--dark`/`--flat` and an
/// odd-sized mosaic, end to end.
#[test]
fn import_options_for_real_cameras() {
    use sfp_core::capture::mosaic::{Pattern, mosaic};
    use sfp_core::io::{read_gray_png, write_png8, write_png16};
    use sfp_core::view::View;
    let dir = tempfile::tempdir().unwrap();
    let view = dir.path().join("view");
    sfp_ok(&["analytic", "--size", "64", "--out", view.to_str().unwrap()]);
    let input = view.join("input");
    let file = |a: &str| input.join(format!("pol_{a}.png")).display().to_string();
    let original = View::read(&view).unwrap();
    let out = dir.path().join("out");
    let o_str = out.to_str().unwrap();

    // Angles measured from the vertical, clockwise: the file labelled 0°
    // is the project's 90°, the one labelled 90° its 0°. Same images, same
    // AoP, no warning.
    let o = sfp_ok(&[
        "import",
        "--angles",
        &file("090"),
        &file("045"),
        &file("000"),
        &file("135"),
        "--angles-from",
        "vertical-cw",
        "--out",
        o_str,
    ]);
    assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));
    let imported = View::read(&out).unwrap();
    assert!(imported.input.pol == original.input.pol);
    // The same for a mosaic whose pattern is written in that frame.
    let raw = dir.path().join("raw.png");
    write_png16(&raw, &mosaic(&original.input.pol, Pattern::SONY)).unwrap();
    let r = raw.to_str().unwrap();
    sfp_ok(&[
        "import",
        "--mosaic",
        r,
        "--pattern",
        "0,45,135,90",
        "--angles-from",
        "vertical-cw",
        "--out",
        o_str,
    ]);
    let half = View::read(&out).unwrap();
    assert_eq!(
        half.input.pol[0].get(5, 7),
        original.input.pol[0].get(11, 15)
    );
    assert_eq!(
        half.input.pol[2].get(5, 7),
        original.input.pol[2].get(10, 14)
    );

    // The automatic mask finds the sphere on its black background: all but
    // the unlit rim, where no rule on light can see it (the head-on light
    // leaves the limb below 4% of full scale).
    sfp_ok(&[
        "import",
        "--angles",
        &file("000"),
        &file("045"),
        &file("090"),
        &file("135"),
        "--auto-mask",
        "--out",
        o_str,
    ]);
    let found = View::read(&out).unwrap().input.mask.unwrap();
    let truth = original.input.mask.clone().unwrap();
    for y in 0..64 {
        for x in 0..64 {
            let level = original
                .input
                .pol
                .iter()
                .map(|p| f64::from(*p.get(x, y)))
                .sum::<f64>()
                / 4.0
                / 65535.0;
            let (f, t) = (*found.get(x, y), *truth.get(x, y));
            assert!(f == t || (t && level < 0.04), "{x},{y}: {f} {t} {level}");
        }
    }
    assert!(
        found.count() * 100 > truth.count() * 95,
        "{} of {}",
        found.count(),
        truth.count()
    );
    let meta = read_json(&out.join("meta.json"));
    assert!(
        meta["auto_mask"]["intensity_threshold"].is_number()
            && meta["auto_mask"]["polarization_threshold"].is_number(),
        "{meta}"
    );
    // A diffuse sphere: next to nothing beyond the diffuse model, and its
    // limb polarized across the outline.
    assert!(
        meta["beyond_diffuse"]["share"].as_f64().unwrap() < 0.01,
        "{meta}"
    );
    assert!(meta["limb"]["alignment"].as_f64().unwrap() > 0.9, "{meta}");
    // Every polarizer image named 90° from its angle: each AoP turned by
    // 90°, as specular reflection turns it. The import says so.
    let turned = dir.path().join("turned");
    let o = sfp_ok(&[
        "import",
        "--angles",
        &file("090"),
        &file("135"),
        &file("000"),
        &file("045"),
        "--auto-mask",
        "--out",
        turned.to_str().unwrap(),
    ]);
    assert!(
        stderr(&o).contains("polarized along the outline"),
        "{}",
        stderr(&o)
    );
    let meta = read_json(&turned.join("meta.json"));
    assert!(meta["limb"]["alignment"].as_f64().unwrap() < -0.9, "{meta}");
    // The sphere's core cancels its polarization; the same sphere with a
    // quarter of its light polarized in one direction (a compact light off
    // rough facets) does not, and the import says so.
    let core = &meta["core_polarization"];
    assert!(core["net"].as_f64().unwrap() < core["bound"].as_f64().unwrap());
    let reflected = dir.path().join("reflected");
    std::fs::create_dir_all(&reflected).unwrap();
    let pol = &original.input.pol;
    let s0 = |x: usize, y: usize| pol.iter().map(|p| f64::from(*p.get(x, y))).sum::<f64>() / 2.0;
    let mut files = Vec::new();
    for (k, angle) in ["000", "045", "090", "135"].iter().enumerate() {
        let theta = (45.0 * k as f64).to_radians();
        let light = (2.0 * (theta - 15f64.to_radians())).cos();
        let image = sfp_core::Image::from_fn(64, 64, |x, y| {
            let v = f64::from(*pol[k].get(x, y)) + 0.5 * s0(x, y) * 0.25 * light;
            v.round().clamp(0.0, 65535.0) as u16
        });
        let path = reflected.join(format!("pol_{angle}.png"));
        write_png16(&path, &image).unwrap();
        files.push(path.display().to_string());
    }
    let mask = input.join("mask.png").display().to_string();
    let seen = dir.path().join("seen");
    let o = sfp_ok(&[
        "import",
        "--angles",
        &files[0],
        &files[1],
        &files[2],
        &files[3],
        "--mask",
        &mask,
        "--out",
        seen.to_str().unwrap(),
    ]);
    assert!(stderr(&o).contains("deepest tenth"), "{}", stderr(&o));

    // Dark frame and flat field: an offset and a gain added to a capture
    // are taken out again (to a code); frames that do not fit are named.
    let offset = 300u16;
    let gain = |x: usize| if x.is_multiple_of(2) { 0.9 } else { 0.7 };
    let raw16 = mosaic(&original.input.pol, Pattern::SONY);
    let biased = sfp_core::Image::from_fn(64, 64, |x, y| {
        (f64::from(*raw16.get(x, y)) * gain(x)).round() as u16 + offset
    });
    write_png16(&raw, &biased).unwrap();
    let dark = dir.path().join("dark.png");
    write_png16(&dark, &sfp_core::Image::new(64, 64, offset)).unwrap();
    let flat = dir.path().join("flat.png");
    let flat_img = sfp_core::Image::from_fn(64, 64, |x, _| (20000.0 * gain(x)) as u16 + offset);
    write_png16(&flat, &flat_img).unwrap();
    let (d, f) = (dark.to_str().unwrap(), flat.to_str().unwrap());
    sfp_ok(&[
        "import", "--mosaic", r, "--dark", d, "--flat", f, "--out", o_str,
    ]);
    let corrected = read_gray_png(&out.join("input/pol_045.png"))
        .unwrap()
        .into_u16();
    let plain = read_gray_png(&input.join("pol_045.png"))
        .unwrap()
        .into_u16();
    // Mean gain 0.8: every code comes back as 0.8 × the original, ± 1.
    for y in 0..32 {
        for x in 0..32 {
            let want = 0.8 * f64::from(*plain.get(2 * x + 1, 2 * y));
            let got = f64::from(*corrected.get(x, y));
            assert!((got - want).abs() <= 1.0, "{x},{y}: {got} vs {want}");
        }
    }
    let small = dir.path().join("small_dark.png");
    write_png16(&small, &sfp_core::Image::new(32, 64, 0u16)).unwrap();
    let eight = dir.path().join("flat8.png");
    write_png8(&eight, &sfp_core::Image::new(64, 64, 200u8)).unwrap();
    for (flag, frame, needle) in [
        (
            "--dark",
            &small,
            "small_dark.png: the dark frame is 32×64, but the capture is 64×64",
        ),
        (
            "--flat",
            &eight,
            "flat8.png: the flat field is 8-bit, but the capture is 16-bit",
        ),
    ] {
        let frame = frame.to_str().unwrap();
        let o = sfp(&["import", "--mosaic", r, flag, frame, "--out", o_str]);
        assert_clean_failure(&o, needle);
        assert_eq!(o.status.code(), Some(2));
    }

    // An odd last column is reported, not silently dropped.
    let odd = dir.path().join("odd.png");
    write_png16(&odd, &raw16.crop(0, 0, 63, 64)).unwrap();
    let o = sfp_ok(&["import", "--mosaic", odd.to_str().unwrap(), "--out", o_str]);
    assert!(stderr(&o).contains("odd last column"), "{}", stderr(&o));
    let meta = read_json(&out.join("meta.json"));
    assert_eq!(meta["capture"]["unused_edge"]["columns"], 1, "{meta}");
    assert_eq!(meta["capture"]["unused_edge"]["rows"], 0, "{meta}");
}
