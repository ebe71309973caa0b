//! SMSfP's `segments.png` and `regions.png` carry a key like every other
//! picture (how many segments or regions, boundaries, background); a
//! report grid shows the picture without it.

use crate::common::*;
use sfp_core::io::read_png_rgb;

#[test]
fn segments_and_regions_have_a_key() {
    let dir = tempfile::tempdir().unwrap();
    let view = dir.path().join("view");
    sfp_ok(&["analytic", "--size", "48", "--out", view.to_str().unwrap()]);
    let out = dir.path().join("smsfp");
    sfp_ok(&[
        "reconstruct",
        view.to_str().unwrap(),
        "--method",
        "smsfp",
        "--out",
        out.to_str().unwrap(),
    ]);
    let background = sfp_core::colormap::BACKGROUND;
    let text = [235u8, 235, 235];
    for name in ["segments.png", "regions.png"] {
        let picture = read_png_rgb(&out.join(name)).unwrap();
        // The 48² picture above a strip as wide as a legend.
        assert!(picture.height() > 48 && picture.width() >= 256, "{name}");
        let strip: Vec<[u8; 3]> = (48..picture.height())
            .flat_map(|y| (0..picture.width()).map(move |x| (x, y)))
            .map(|(x, y)| *picture.get(x, y))
            .collect();
        assert!(strip.contains(&text), "{name}: no names in the key");
        assert!(strip.contains(&background), "{name}: no background swatch");
    }
}
