//! Messages that say what is wrong and what to do: each was unhelpful
//! before (a serde variant list, a missing hint, a clap parse of `-0.1` as
//! a flag).

use crate::common::*;
use std::path::Path;

#[test]
fn messages_name_the_problem_and_the_fix() {
    let dir = tempfile::tempdir().unwrap();
    let view = small_view(dir.path());
    let v = view.as_str();
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
    assert_clean_failure(&o, "sfp eval VIEW PREDICTION");
    // A negative window value is a value, not a flag: the window is checked.
    let pol: Vec<String> = (0..4)
        .map(|k| {
            Path::new(&view)
                .join(format!("input/pol_{:03}.png", k * 45))
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

/// The second round: each message below was unhelpful on the binary of the
/// first round.
#[test]
fn messages_of_the_second_round() {
    let dir = tempfile::tempdir().unwrap();
    let view = small_view(dir.path());
    let v = view.as_str();
    let out = dir.path().join("x").display().to_string();
    let reconstruct = |extra: &[&str]| {
        let mut args = vec!["reconstruct", v, "--out", &out];
        args.extend(extra);
        sfp(&args)
    };
    // A λ that drowns the data is refused with its range, not "singular:
    // a larger --lambda smooths over them".
    let o = reconstruct(&["--lambda", "1e308"]);
    assert_eq!(o.status.code(), Some(2));
    assert_clean_failure(&o, "lambda 1e308 is outside [0, 1e6]");
    assert!(!stderr(&o).contains("larger --lambda"), "{}", stderr(&o));
    // A flag the method has no option for names the flag and the methods
    // that have it, not "unknown field `light`".
    let o = reconstruct(&["--method", "atkinson", "--ambient"]);
    assert_clean_failure(&o, "--ambient: atkinson has no `light` option");
    assert_clean_failure(&o, "mahmoud, smith, smsfp");
    // A negative seed is named as negative, not "invalid digit".
    let o = reconstruct(&["--seed", "-1"]);
    assert_clean_failure(&o, "is negative: a whole number ≥ 0 is expected");
    // A huge bad key is not echoed whole: each line is cut.
    let bad = dir.path().join("bad.toml");
    std::fs::write(&bad, format!("{} = 1\n", "k".repeat(1_000_000))).unwrap();
    for args in [
        vec!["render", bad.to_str().unwrap(), "--out", &out],
        vec![
            "reconstruct",
            v,
            "--config",
            bad.to_str().unwrap(),
            "--out",
            &out,
        ],
    ] {
        let o = sfp(&args);
        assert_clean_failure(&o, "more characters)");
        assert!(o.stderr.len() < 4000, "{args:?}: {} bytes", o.stderr.len());
    }
    // A layout without the view --name names: --name and the views there.
    let layout = dir.path().join("layout");
    let l = layout.to_str().unwrap();
    assert!(sfp(&["export", v, "--out", l]).status.success());
    let o = sfp(&["import", "--layout", l, "--name", "nope", "--out", &out]);
    assert_clean_failure(&o, "--name nope: no such view; the layout holds 1 (view)");
    // A refused write names the --out given, never the hidden staging
    // folder beside it (`/proc/.x.partial-PID`).
    let o = sfp(&["analytic", "--size", "8", "--out", "/proc/x"]);
    assert_clean_failure(&o, "/proc/x:");
    assert!(!stderr(&o).contains("partial"), "{}", stderr(&o));
    // `reconstruct --help` lists every method's options.
    let help = String::from_utf8_lossy(&sfp(&["reconstruct", "--help"]).stdout).into_owned();
    for option in [
        "window_radius",
        "lambda = 0.1",
        "parg = true",
        "ablation switches",
    ] {
        assert!(help.contains(option), "--help lacks {option}");
    }
    // A folder that is no layout says so and how one is made.
    let o = sfp(&["import", "--layout", v, "--out", &out]);
    assert_clean_failure(&o, "not a per-angle layout");
    assert_clean_failure(&o, "sfp export VIEW --out DIR");
}

/// `--textured` and `--svbrdf` say which preset objects they change: every
/// object of the shipped presets with an `albedo_texture` is named.
#[test]
fn dataset_help_names_the_objects_its_material_flags_change() {
    let o = sfp(&["dataset", "--help"]);
    let help = String::from_utf8_lossy(&o.stdout).into_owned();
    let presets = concat!(env!("CARGO_MANIFEST_DIR"), "/../scenes/datasets");
    for entry in std::fs::read_dir(presets).unwrap() {
        let text = std::fs::read_to_string(entry.unwrap().path()).unwrap();
        let table: toml::Table = toml::from_str(&text).unwrap();
        let objects = table["object"].as_array().unwrap();
        // A preset that draws each view's material has no per-object one.
        let drawn = table["dataset"].get("vary").is_some();
        for object in objects {
            let name = object["name"].as_str().unwrap();
            if object.get("albedo_texture").is_some() {
                assert!(
                    help.contains(name),
                    "--textured does not name {name}: {help}"
                );
            }
            assert!(
                drawn || object.get("svbrdf").is_some(),
                "{name} has no svbrdf table"
            );
        }
    }
    assert!(help.contains("every preset object has one") && help.contains("scenes/README.md"));
    assert!(help.contains("glossy"), "{help}");
}
