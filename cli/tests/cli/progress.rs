//! Where stderr is no terminal (a log, a cluster job), progress is printed
//! as plain lines: the bar would draw nothing.

use crate::common::*;

#[test]
fn progress_shows_as_lines_in_a_log() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = dir.path().join("sweep.toml");
    std::fs::write(
        &sweep,
        "[[views]]\nanalytic = \"sphere\"\nsize = 16\n[[methods]]\nmethod = \"atkinson\"\n",
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
    assert!(e.contains("progress: 0/1 rows"), "{e}");
    assert!(e.contains("progress: 1/1 rows done"), "{e}");
    let view = dir.path().join("view");
    let o = sfp_ok(&[
        "render",
        concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../scenes/examples/sphere.toml"
        ),
        "--size",
        "8",
        "--spp",
        "1",
        "--out",
        view.to_str().unwrap(),
    ]);
    assert!(
        stderr(&o).contains("progress: 8/8 image rows"),
        "{}",
        stderr(&o)
    );
}

/// One view, one method: each step the method enters is a line in a log,
/// with the time since the start (a 1224×1024 capture takes 15–23 s).
#[test]
fn a_reconstruction_names_its_steps_in_a_log() {
    let dir = tempfile::tempdir().unwrap();
    let view = small_view(dir.path());
    let out = dir.path().join("result");
    let o = sfp_ok(&[
        "reconstruct",
        &view,
        "--method",
        "smsfp",
        "--out",
        out.to_str().unwrap(),
    ]);
    let e = stderr(&o);
    for step in [
        "reading the polarization",
        "η search and light",
        "segmentation",
        "solving",
        "stitching",
        "scoring",
        "writing the result",
    ] {
        assert!(e.contains(&format!("smsfp: {view}: {step}")), "{step}: {e}");
    }
    assert!(e.contains(" s]"), "{e}");
}
