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
    let o = sfp(&[
        "bench",
        sweep.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let e = stderr(&o);
    assert!(e.contains("progress: 0/1 rows"), "{e}");
    assert!(e.contains("progress: 1/1 rows done"), "{e}");
    let view = dir.path().join("view");
    let o = sfp(&[
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
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("progress: 8/8 image rows"),
        "{}",
        stderr(&o)
    );
}
