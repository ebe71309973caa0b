//! Mask pixels with no usable data (saturated, unlit, not finite): counted
//! for every method in `run.json`, a warning above the documented share, a
//! refusal naming the view when none is usable. Before, an all-saturated
//! view gave Atkinson an MAE of 45° as a result, without a word.

use crate::common::*;
use sfp_core::Image;
use sfp_core::io::{read_gray_png, read_png_rgb, write_png16};
use std::path::Path;

/// An analytic 32² view whose polarizer images are clipped at full scale
/// in the columns `x < clipped`.
fn clipped_view(dir: &Path, clipped: usize) -> String {
    let view = dir.join("view");
    let v = view.to_str().unwrap();
    sfp_ok(&["analytic", "--size", "32", "--out", v]);
    for angle in ["000", "045", "090", "135"] {
        let path = view.join(format!("input/pol_{angle}.png"));
        let codes = read_gray_png(&path).unwrap().into_u16();
        let codes = Image::from_fn(32, 32, |x, y| {
            if x < clipped {
                u16::MAX
            } else {
                *codes.get(x, y)
            }
        });
        write_png16(&path, &codes).unwrap();
    }
    v.to_string()
}

#[test]
fn an_all_saturated_view_is_refused_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let v = clipped_view(dir.path(), 32);
    for method in ["atkinson", "smith"] {
        let out = dir.path().join(method);
        let o = sfp(&[
            "reconstruct",
            &v,
            "--method",
            method,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(2), "{method}: {}", stderr(&o));
        assert_clean_failure(&o, "no pixel of the mask has usable data");
        assert_clean_failure(&o, &v);
        assert_clean_failure(&o, "saturated");
        assert!(!out.exists(), "{method}: no result of nothing");
    }
}

#[test]
fn half_a_saturated_mask_is_recorded_and_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    let v = clipped_view(dir.path(), 16);
    for method in ["atkinson", "mahmoud", "smith", "smsfp", "yu2017"] {
        let out = dir.path().join(method);
        let o = sfp(&[
            "reconstruct",
            &v,
            "--method",
            method,
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(o.status.success(), "{method}: {}", stderr(&o));
        let e = stderr(&o);
        assert!(
            e.contains("warning") && e.contains("no usable data"),
            "{method}: {e}"
        );
        let run = read_json(&out.join("run.json"));
        let unusable = &run["unusable"];
        let share = unusable["share"].as_f64().unwrap();
        assert!((0.4..0.6).contains(&share), "{method}: {unusable}");
        assert!(unusable["saturated"].as_u64().unwrap() > 0, "{unusable}");
    }
    // A clean view: nothing saturated, no warning.
    let clean = tempfile::tempdir().unwrap();
    let v = clipped_view(clean.path(), 0);
    let out = clean.path().join("smith");
    let o = sfp_ok(&["reconstruct", &v, "--out", out.to_str().unwrap()]);
    assert!(!stderr(&o).contains("usable"), "{}", stderr(&o));
    // The limb in attached shadow (unlit) is the only unusable part.
    let unusable = &read_json(&out.join("run.json"))["unusable"];
    assert_eq!(unusable["saturated"], 0, "{unusable}");
    assert!(unusable["share"].as_f64().unwrap() < 0.05, "{unusable}");
}

#[test]
fn saturated_pixels_are_drawn_in_their_own_colour_with_a_key() {
    let dir = tempfile::tempdir().unwrap();
    let pol: Vec<String> = (0..4u16)
        .map(|k| {
            let p = dir.path().join(format!("p{k}.png"));
            // The left quarter clipped in every image.
            let img = Image::from_fn(16, 16, |x, _| if x < 4 { 65535 } else { 20000 + k * 100 });
            write_png16(&p, &img).unwrap();
            p.display().to_string()
        })
        .collect();
    let view = dir.path().join("v");
    sfp_ok(&[
        "import",
        "--angles",
        &pol[0],
        &pol[1],
        &pol[2],
        &pol[3],
        "--out",
        view.to_str().unwrap(),
    ]);
    let magenta = [255u8, 0, 255];
    for name in ["intensity", "dop", "aop"] {
        let picture = read_png_rgb(&view.join(format!("preview/{name}.png"))).unwrap();
        assert_eq!(*picture.get(1, 8), magenta, "{name}: a saturated pixel");
        assert_ne!(*picture.get(10, 8), magenta, "{name}: an unsaturated one");
        // The key below the map's own legend names the colour.
        let key = (16..picture.height()).any(|y| *picture.get(4, y) == magenta);
        assert!(key, "{name}: no saturated swatch in the legend");
    }
}
