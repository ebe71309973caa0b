//! Messages that say what is wrong and what to do: each was unhelpful
//! before (a serde variant list, a missing hint, a clap parse of `-0.1` as
//! a flag).

use crate::common::*;

#[test]
fn messages_name_the_problem_and_the_fix() {
    let dir = tempfile::tempdir().unwrap();
    let view = dir.path().join("view");
    let v = view.to_str().unwrap();
    assert!(
        sfp(&["analytic", "--size", "16", "--out", v])
            .status
            .success()
    );
    let out = dir.path().join("x").display().to_string();
    // A non-finite number is refused at the flag, not as JSON null.
    let o = sfp(&[
        "reconstruct",
        v,
        "--method",
        "smith",
        "--eta",
        "nan",
        "--out",
        &out,
    ]);
    assert_clean_failure(&o, "not a finite number");
    // The argument order of eval.
    let o = sfp(&["eval", v, v]);
    assert_clean_failure(&o, "sfp eval VIEW RESULT");
    // A negative window value is a value, not a flag: the window is checked.
    let pol: Vec<String> = (0..4)
        .map(|k| {
            view.join(format!("input/pol_{:03}.png", k * 45))
                .display()
                .to_string()
        })
        .collect();
    let mut args: Vec<&str> = vec!["import", "--angles"];
    args.extend(pol.iter().map(String::as_str));
    args.extend(["--window", "-0.1,0.5", "--out", &out]);
    assert_clean_failure(&sfp(&args), "intensity window -0.1,0.5");
    // An automatic mask that finds nothing says so (not "0 pixels saturated").
    let black = dir.path().join("black.png");
    sfp_core::io::write_png16(&black, &sfp_core::Image::new(16, 16, 0u16)).unwrap();
    let b = black.to_str().unwrap();
    let o = sfp(&[
        "import",
        "--angles",
        b,
        b,
        b,
        b,
        "--auto-mask",
        "--out",
        &out,
    ]);
    assert_clean_failure(&o, "--auto-mask found no object");
    // A raw-frame mask beside a superpixel import: halve it.
    let raw = dir.path().join("raw.png");
    sfp_core::io::write_png16(&raw, &sfp_core::Image::new(32, 32, 1000u16)).unwrap();
    let mask = dir.path().join("mask.png");
    sfp_core::io::write_png8(&mask, &sfp_core::Image::new(32, 32, 255u8)).unwrap();
    let o = sfp(&[
        "import",
        "--mosaic",
        raw.to_str().unwrap(),
        "--mask",
        mask.to_str().unwrap(),
        "--out",
        &out,
    ]);
    assert_clean_failure(&o, "halve the mask");
    // A material map of no form lists the forms.
    let scene = dir.path().join("scene.toml");
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../scenes/examples/sphere.toml"
    ))
    .unwrap()
    .replace(
        "{ type = \"diffuse_polarized\", albedo = 0.8, eta = 1.5 }",
        "{ type = \"svbrdf\", eta = 1.5, albedo = \"bright\" }",
    );
    std::fs::write(&scene, text).unwrap();
    let o = sfp(&["render", scene.to_str().unwrap(), "--out", &out]);
    assert_clean_failure(&o, "expected a number, { texture");
}
