//! `--dark` warnings and code-range checks: a dark frame that wipes out the
//! capture is named, and `--sensor-bits` refuses codes beyond its range
//! with a dark frame as without one.

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
