//! One rule for colour PNGs given as sensor images (`--mosaic`, `--angles`,
//! a layout's, `--dark`): grey saved as RGB (equal channels) is read
//! exactly; an RGB picture is refused as such, with what to give instead,
//! where a frame has one value per pixel (a mosaic, a dark frame) or among
//! grey polarizer images (four RGB ones make a colour view, `colour.rs`).
//! Before, a colour picture as a mosaic was averaged and imported silently,
//! or refused later as a DoP above 1.

use crate::common::*;
use sfp_core::Image;
use sfp_core::io::{read_gray_png, write_png_rgb, write_png_rgb16, write_png8};

#[test]
fn an_rgb_picture_as_a_mosaic_is_refused_as_rgb() {
    let dir = tempfile::tempdir().unwrap();
    let raw = dir.path().join("photo.png");
    // A smooth colour picture: as a mean of channels, a plausible frame.
    let photo = Image::from_fn(32, 32, |x, y| [120 + x as u8, 100 + y as u8, 90]);
    write_png_rgb(&raw, &photo).unwrap();
    let out = dir.path().join("v");
    let o = sfp(&[
        "import",
        "--mosaic",
        raw.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert_clean_failure(&o, "photo.png: an RGB picture");
    assert_clean_failure(&o, "grayscale PNG");
    assert!(!out.exists());
    // The same for one of four polarizer images, and for a dark frame.
    let grey: Vec<String> = (0..4)
        .map(|k| {
            let p = dir.path().join(format!("p{k}.png"));
            write_png8(&p, &Image::from_fn(32, 32, |x, _| 100 + (x as u8) * k)).unwrap();
            p.display().to_string()
        })
        .collect();
    let r = raw.to_str().unwrap();
    for args in [
        vec!["--angles", &grey[0], r, &grey[2], &grey[3]],
        vec![
            "--angles", &grey[0], &grey[1], &grey[2], &grey[3], "--dark", r,
        ],
    ] {
        let mut all = vec!["import"];
        all.extend(args);
        all.extend(["--out", out.to_str().unwrap()]);
        let o = sfp(&all);
        assert_eq!(o.status.code(), Some(2), "{all:?}: {}", stderr(&o));
        assert_clean_failure(&o, "photo.png: an RGB picture");
    }
}

#[test]
fn grey_saved_as_rgb_is_read_exactly_and_colour_masks_work() {
    let dir = tempfile::tempdir().unwrap();
    let view = dir.path().join("view");
    sfp_ok(&["analytic", "--size", "32", "--out", view.to_str().unwrap()]);
    let mut as_rgb = Vec::new();
    for angle in ["000", "045", "090", "135"] {
        let codes = read_gray_png(&view.join(format!("input/pol_{angle}.png")))
            .unwrap()
            .into_u16();
        let p = dir.path().join(format!("rgb_{angle}.png"));
        write_png_rgb16(&p, &codes.map(|&c| [c; 3])).unwrap();
        as_rgb.push(p.display().to_string());
    }
    // A mask drawn in red.
    let mask = read_gray_png(&view.join("input/mask.png"))
        .unwrap()
        .into_u16();
    let red = dir.path().join("red.png");
    write_png_rgb(
        &red,
        &mask.map(|&m| if m > 0 { [255, 0, 0] } else { [0; 3] }),
    )
    .unwrap();
    let out = dir.path().join("imported");
    sfp_ok(&[
        "import",
        "--angles",
        &as_rgb[0],
        &as_rgb[1],
        &as_rgb[2],
        &as_rgb[3],
        "--mask",
        red.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    for angle in ["000", "045", "090", "135"] {
        let read = |v: &std::path::Path| {
            read_gray_png(&v.join(format!("input/pol_{angle}.png")))
                .unwrap()
                .into_u16()
        };
        assert_eq!(read(&out), read(&view), "pol_{angle}");
    }
    let back = read_gray_png(&out.join("input/mask.png"))
        .unwrap()
        .into_u16();
    assert_eq!(back.map(|&m| m > 0), mask.map(|&m| m > 0));
}
