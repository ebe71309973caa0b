//! A view whose four images are not one polarization measurement is
//! refused by `sfp reconstruct`, naming the view; a rendered or analytic
//! view reads as before. Before, four unrelated images gave normals and
//! exit code 0.

use crate::common::*;
use sfp_core::Image;
use sfp_core::io::write_png16;

#[test]
fn unrelated_images_are_refused_naming_the_view() {
    let dir = tempfile::tempdir().unwrap();
    let view = dir.path().join("view");
    let v = view.to_str().unwrap();
    sfp_ok(&["analytic", "--size", "32", "--out", v]);
    let out = dir.path().join("out").display().to_string();
    sfp_ok(&["reconstruct", v, "--method", "smith", "--out", &out]);
    let mut state = 7u64;
    for angle in ["000", "045", "090", "135"] {
        let noise = Image::from_fn(32, 32, |_, _| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (5_000 + (state >> 33) % 50_000) as u16
        });
        write_png16(&view.join(format!("input/pol_{angle}.png")), &noise).unwrap();
    }
    let o = sfp(&["reconstruct", v, "--method", "smith", "--out", &out]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert_clean_failure(&o, "I0 + I90");
    assert!(stderr(&o).contains(v), "{}", stderr(&o));
}

#[test]
fn an_empty_or_zero_mfcp_scale_is_refused_not_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let v = small_view(dir.path());
    let out = dir.path().join("out").display().to_string();
    for scales in ["[]", "[0]"] {
        let set = format!("mfcp_params={{scales={scales}}}");
        let o = sfp(&[
            "reconstruct",
            &v,
            "--method",
            "smsfp",
            "--set",
            &set,
            "--out",
            &out,
        ]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert_clean_failure(&o, "mfcp_params.scales");
    }
}
