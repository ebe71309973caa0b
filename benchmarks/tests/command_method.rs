//! One's own method in a sweep: a `[[methods]]` entry with a `command`,
//! run beside a built-in method on one small analytic view, scored like
//! it, shown in the report beside it, and counted failed (with its exit
//! status and stderr) when it exits non-zero, runs past its timeout or
//! leaves no usable prediction.

use sfp_benchmarks::report;
use sfp_benchmarks::row::Row;
use sfp_benchmarks::sweep::command_method::WORK;
use sfp_benchmarks::sweep::file::Sweep;
use sfp_benchmarks::sweep::results::{
    RESULTS_CSV, RESULTS_JSONL, TIMINGS_CSV, read_rows, read_timings,
};
use sfp_benchmarks::sweep::shard::Shard;
use sfp_benchmarks::sweep::{self};
use sfp_core::NormalMap;
use sfp_core::analytic::{AnalyticScene, Shape};
use sfp_core::export::write_npy_f32;
use sfp_core::prediction::Axes;
use std::path::Path;
use std::time::Instant;

const SIZE: usize = 32;

/// The command methods: `$1` is the view folder, `$2` the result folder;
/// they run in the sweep file's folder.
const SWEEP: &str = r#"
[[views]]
analytic = "sphere"
size = 32

[[methods]]
method = "smith"

# The perfect prediction, after checking what it is given.
[[methods]]
name = "perfect"
command = ["sh", "-c", """
test -f "$1/input/pol_000.png" && test -f "$1/input/mask.png" || exit 3
test ! -e "$1/gt" && test ! -e "$1/meta.json" && test ! -e "$1/preview" || exit 4
test "$SFP_VIEW" = "$1" && test "$SFP_OUT" = "$2" || exit 5
test -z "$CARGO_MANIFEST_DIR" || exit 6
test -z "$(ls -A "$2")" || exit 7
cp perfect.npy "$2/normals.npy"
""", "sh", "{view}", "{out}"]

# The same normals in OpenCV's frame.
[[methods]]
name = "perfect-opencv"
command = ["sh", "-c", "cp opencv.npy \"$SFP_OUT/normals.npy\""]
axes = "opencv"

[[methods]]
name = "broken"
command = ["sh", "-c", """
i=1
while [ $i -le 25 ]; do echo "line $i" >&2; i=$((i + 1)); done
exit 1
"""]

# Starts a process of its own, which the timeout must kill too.
[[methods]]
name = "slow"
command = ["sh", "-c", "sleep 30 & echo $! > \"$1/pid\"; wait", "sh", "{out}"]
timeout_s = 1

[[methods]]
name = "silent"
command = ["true"]

[[methods]]
name = "small"
command = ["sh", "-c", "cp small.npy \"$SFP_OUT/normals.npy\""]
"#;

fn write_npy(path: &Path, normals: &NormalMap) {
    let (w, h) = normals.size();
    let flat: Vec<f32> = normals.data().iter().flatten().copied().collect();
    write_npy_f32(path, &[h as u64, w as u64, 3], flat).unwrap();
}

fn row<'r>(rows: &'r [Row], method: &str) -> &'r Row {
    rows.iter()
        .find(|r| r.method == method)
        .unwrap_or_else(|| panic!("no {method} row"))
}

#[test]
fn a_command_method_is_scored_and_reported_beside_a_built_in_one() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    let truth = AnalyticScene {
        shape: Shape::Sphere,
        size: SIZE,
        ..AnalyticScene::default()
    }
    .render()
    .unwrap()
    .gt
    .unwrap()
    .normals;
    write_npy(&dir.join("perfect.npy"), &truth);
    // Every frame is its own inverse.
    write_npy(
        &dir.join("opencv.npy"),
        &truth.map(|&n| Axes::Opencv.to_ours(n)),
    );
    write_npy(&dir.join("small.npy"), &truth.crop(0, 0, 16, 16));
    let file = dir.join("sweep.toml");
    std::fs::write(&file, SWEEP).unwrap();
    let sweep = Sweep::load(&file).unwrap();
    let out = dir.join("out");
    let start = Instant::now();
    let summary = sweep::run(&sweep, &out, Shard::ALL, &|_| {}).unwrap();
    let seconds = start.elapsed().as_secs_f64();
    assert_eq!((summary.rows, summary.failed), (7, 4), "{summary:?}");
    assert!(seconds < 10.0, "{seconds} s");
    let (rows, _) = read_rows(&out.join(RESULTS_JSONL), true).unwrap();

    // Scored as smith is: over the same mask, MAE ≈ 0 in either frame.
    let smith = row(&rows, "smith").metrics.clone().unwrap();
    for name in ["perfect", "perfect-opencv"] {
        let r = row(&rows, name);
        assert_eq!(
            (&r.error, r.exit_status, &r.stderr_tail),
            (&None, Some(0), &None)
        );
        let m = r.metrics.as_ref().unwrap();
        assert!(m.mae_deg < 0.01 && m.missing == 0, "{name}: {m:?}");
        assert_eq!(m.pixels, smith.pixels);
        assert_eq!(
            r.config["axes"],
            name.strip_prefix("perfect-").unwrap_or("ours")
        );
    }
    // Its result is kept for the grids in our frame; its work folder is gone.
    let perfect = row(&rows, "perfect");
    let pictures = out.join(perfect.pictures.as_ref().unwrap());
    assert!(pictures.join("normals.exr").is_file() && pictures.join("error.png").is_file());
    assert!(!out.join(WORK).join(&perfect.key).exists());

    // Failures are rows without figures, with what the command said.
    let broken = row(&rows, "broken");
    assert!(
        broken.metrics.is_none() && broken.exit_status == Some(1),
        "{broken:?}"
    );
    assert!(
        broken.error.as_ref().unwrap().contains("status 1"),
        "{broken:?}"
    );
    let tail: Vec<&str> = broken.stderr_tail.as_ref().unwrap().lines().collect();
    assert_eq!((tail.len(), tail[0], tail[19]), (20, "line 6", "line 25"));
    assert!(out.join(WORK).join(&broken.key).join("view/input").is_dir());

    let slow = row(&rows, "slow");
    assert!(
        slow.metrics.is_none() && slow.exit_status.is_none(),
        "{slow:?}"
    );
    assert!(
        slow.error.as_ref().unwrap().contains("timeout_s = 1"),
        "{slow:?}"
    );
    let timing = read_timings(&out.join(TIMINGS_CSV))
        .into_iter()
        .find(|t| t.key == slow.key)
        .unwrap();
    assert!(
        (1.0..2.0).contains(&timing.reconstruct_seconds),
        "{timing:?}"
    );
    // What it started was killed with it.
    let pid = std::fs::read_to_string(out.join(WORK).join(&slow.key).join("out/pid")).unwrap();
    let stat = std::fs::read_to_string(format!("/proc/{}/stat", pid.trim())).unwrap_or_default();
    assert!(
        stat.is_empty() || stat.contains(") Z "),
        "the command's child lives on: {stat}"
    );

    for (name, needle) in [("silent", "no prediction"), ("small", "16×16")] {
        let r = row(&rows, name);
        assert!(r.metrics.is_none(), "{r:?}");
        assert!(r.error.as_ref().unwrap().contains(needle), "{r:?}");
    }

    let csv = std::fs::read_to_string(out.join(RESULTS_CSV)).unwrap();
    assert!(
        csv.lines()
            .next()
            .unwrap()
            .ends_with(",error,exit_status,stderr_tail")
    );
    assert!(csv.lines().any(|l| l.contains(",perfect,0,")), "{csv}");

    // The report lists it beside smith, and its failures with their stderr.
    report::write(&out).unwrap();
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    let table = md
        .lines()
        .filter(|l| l.starts_with('|'))
        .collect::<Vec<_>>()
        .join("\n");
    for name in ["Smith", "perfect", "perfect-opencv"] {
        assert!(table.contains(&format!("| {name} |")), "{name}:\n{md}");
    }
    assert!(md.contains("stderr ends: line 25"), "{md}");
    let html = std::fs::read_to_string(out.join("index.html")).unwrap();
    assert!(html.contains("perfect-opencv"));
}
