//! What an import of a capture reports: a dark frame that wipes out the
//! capture is named, `--sensor-bits` refuses codes beyond its range with a
//! dark frame as without one, and `inspect` counts the saturated pixels the
//! import left out of the mask.

use crate::common::*;
use sfp_core::Image;
use sfp_core::io::write_png16;

fn four(dir: &std::path::Path, value: u16) -> Vec<String> {
    (0..4)
        .map(|k| {
            let p = dir.join(format!("p{k}.png"));
            write_png16(&p, &Image::new(16, 16, value + k as u16 * 10)).unwrap();
            p.display().to_string()
        })
        .collect()
}

#[test]
fn a_dark_frame_that_wipes_out_the_capture_is_named_and_codes_are_checked() {
    let dir = tempfile::tempdir().unwrap();
    let pol = four(dir.path(), 1000);
    let dark = dir.path().join("dark.png");
    write_png16(&dark, &Image::new(16, 16, 3000u16)).unwrap();
    let d = dark.to_str().unwrap();
    let out = dir.path().join("v");
    let mut args = vec![
        "import", "--angles", &pol[0], &pol[1], &pol[2], &pol[3], "--dark", d,
    ];
    args.extend(["--out", out.to_str().unwrap()]);
    let o = sfp(&args);
    let e = stderr(&o);
    assert!(
        e.contains("dark.png: subtracting this dark frame leaves"),
        "{e}"
    );
    // Codes above 12 bits in files said to hold 12-bit data: refused with a
    // dark frame too (the correction clipped them to full scale).
    let pol = four(dir.path(), 5000);
    write_png16(&dark, &Image::new(16, 16, 10u16)).unwrap();
    for with_dark in [false, true] {
        let mut args = vec!["import", "--angles", &pol[0], &pol[1], &pol[2], &pol[3]];
        if with_dark {
            args.extend(["--dark", d]);
        }
        args.extend(["--sensor-bits", "12", "--out", out.to_str().unwrap()]);
        let o = sfp(&args);
        assert_eq!(o.status.code(), Some(2), "dark {with_dark}: {}", stderr(&o));
        assert_clean_failure(&o, "exceeds");
    }
}

#[test]
fn saturated_pixels_left_out_of_the_mask_are_counted() {
    let dir = tempfile::tempdir().unwrap();
    let pol: Vec<String> = (0..4)
        .map(|k| {
            let p = dir.path().join(format!("p{k}.png"));
            // The left quarter of the frame clipped in every image.
            let img = Image::from_fn(
                16,
                16,
                |x, _| if x < 4 { 65535 } else { 20000 + k as u16 * 100 },
            );
            write_png16(&p, &img).unwrap();
            p.display().to_string()
        })
        .collect();
    let out = dir.path().join("v");
    let o = out.to_str().unwrap();
    let i = sfp(&[
        "import", "--angles", &pol[0], &pol[1], &pol[2], &pol[3], "--out", o,
    ]);
    assert!(i.status.success(), "{}", stderr(&i));
    let s = sfp(&["inspect", o]);
    assert!(s.status.success(), "{}", stderr(&s));
    let summary: serde_json::Value = serde_json::from_slice(&s.stdout).unwrap();
    assert_eq!(summary["saturated_fraction"], 0.25, "{summary}");
}
