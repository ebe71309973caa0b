//! A sweep file is checked whole when it is read: a wrong method option,
//! command method or axis value ends `sfp bench` with exit code 2 before
//! anything renders.

use crate::common::*;

#[test]
fn bad_method_options_and_axis_values_stop_the_sweep_before_any_render() {
    let dir = tempfile::tempdir().unwrap();
    let base = "[[views]]\nanalytic = \"sphere\"\nsize = 16\n[axes]\neta = [1.3, 1.6]\n\
                [[methods]]\nmethod = \"atkinson\"\n[[methods]]\nmethod = \"smith\"\n";
    for (i, (text, key)) in [
        (format!("{base}lambda = -1\n"), "lambda"),
        (format!("{base}eta = 3.5\n"), "eta = 3.5"),
        (format!("{base}lamda = 1\n"), "lamda"),
        (
            base.replace("eta = [1.3", "method_eta = [3.5"),
            "axes.method_eta",
        ),
        (base.replace("eta = [1.3", "wobble = [1.3"), "known: "),
        // One's own method: a command, named apart from the built-in ones.
        (
            format!("{base}[[methods]]\nname = \"mine\"\ncommand = []\n"),
            "methods[2].command",
        ),
        (
            format!("{base}[[methods]]\nname = \"smith\"\ncommand = [\"predict\"]\n"),
            "methods[2].name",
        ),
    ]
    .into_iter()
    .enumerate()
    {
        let sweep = dir.path().join(format!("bad{i}.toml"));
        std::fs::write(&sweep, text).unwrap();
        let out = dir.path().join(format!("out{i}"));
        let o = sfp(&[
            "bench",
            sweep.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_eq!(o.status.code(), Some(2), "{key}: {}", stderr(&o));
        assert_clean_failure(&o, key);
        assert!(
            stderr(&o).contains(&format!("bad{i}.toml")),
            "{}",
            stderr(&o)
        );
        assert!(!out.join("views").exists(), "{key}: a view was rendered");
    }
}

#[test]
fn the_old_specular_axis_runs_as_specular_weight_with_a_note() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = dir.path().join("old.toml");
    std::fs::write(
        &sweep,
        "[[views]]\npreset = \"builtin\"\nobjects = [\"sphere\"]\nviews = 1\nsize = 16\nspp = 1\n\
         [axes]\nspecular = [0.0]\n[[methods]]\nmethod = \"atkinson\"\n",
    )
    .unwrap();
    let out = dir.path().join("out");
    let o = sfp_ok(&[
        "bench",
        sweep.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    let e = stderr(&o);
    assert!(
        e.contains("note: ") && e.contains("old.toml") && e.contains("axes.specular_weight"),
        "{e}"
    );
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    assert!(header.contains("specular_weight"), "{header}");
}
