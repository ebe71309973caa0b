//! End-to-end checks of the `sfp` binary: real jobs succeed, bad input fails
//! with a message naming the file, never a panic, and a killed `sfp` leaves
//! every folder it was writing whole.

use crate::common::*;
use std::path::Path;
use std::process::Command;

#[test]
fn analytic_inspect_eval_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let view = dir.path().join("view");
    let v = view.to_str().unwrap();
    sfp_ok(&[
        "analytic",
        "--shape",
        "blobs",
        "--size",
        "48",
        "--light",
        "-0.3,0.1,1",
        "--out",
        v,
    ]);
    let o = sfp_ok(&["inspect", v]);
    let summary: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(summary["width"], 48);
    // A reader that stops reading (`sfp inspect VIEW | head`) ends the
    // program quietly, not with a panic in print.
    let mut child = Command::new(env!("CARGO_BIN_EXE_sfp"))
        .args(["inspect", v])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let o = child.wait_with_output().unwrap();
    assert!(
        o.status.success() && !stderr(&o).contains("panicked"),
        "{}",
        stderr(&o)
    );
    // The ground truth scored against itself is perfect.
    let result = dir.path().join("result");
    std::fs::create_dir_all(&result).unwrap();
    std::fs::copy(view.join("gt/normals.exr"), result.join("normals.exr")).unwrap();
    sfp_ok(&["eval", v, result.to_str().unwrap()]);
    let m = read_json(&result.join("metrics.json"));
    assert!(m["mae_deg"].as_f64().unwrap() < 1e-3);
    assert_eq!(m["acc_11_25"], 100.0);
    assert!(Path::new(&result.join("error.png")).is_file());
}

#[test]
fn bad_input_fails_with_the_file_named() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("nothing");
    assert_clean_failure(&sfp(&["inspect", missing.to_str().unwrap()]), "nothing");

    let view = dir.path().join("view");
    let v = view.to_str().unwrap();
    assert!(
        sfp(&["analytic", "--size", "32", "--out", v])
            .status
            .success()
    );
    std::fs::write(view.join("input/pol_000.png"), b"garbage").unwrap();
    assert_clean_failure(&sfp(&["inspect", v]), "pol_000.png");

    let empty = dir.path().join("empty_result");
    std::fs::create_dir_all(&empty).unwrap();
    assert!(
        sfp(&["analytic", "--size", "32", "--out", v])
            .status
            .success()
    );
    assert_clean_failure(&sfp(&["eval", v, empty.to_str().unwrap()]), "normals.exr");

    assert_clean_failure(&sfp(&["analytic", "--eta", "0.5", "--out", v]), "eta");
    assert_clean_failure(
        &sfp(&["analytic", "--eta", "1e155", "--out", v]),
        "must be in (1, 4]",
    );
    // A negative number after a flag is a value to check, not an unknown argument.
    let o = sfp(&["render", "scene.toml", "--spp", "-1", "--out", v]);
    assert_clean_failure(&o, "invalid value '-1' for '--spp");
    assert_eq!(o.status.code(), Some(2));
    // A bad value typed on the command line is blamed on the option, not
    // on a key of the scene file the user did not edit.
    let scene = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../scenes/examples/sphere.toml"
    );
    for (args, needle) in [
        (
            vec!["render", scene, "--spp", "0"],
            "--spp 0: must be at least 1",
        ),
        (
            vec!["render", scene, "--size", "0x64"],
            "--size 0x64: width and height must be between 1 and 16384",
        ),
        (
            vec!["dataset", "builtin", "--size", "0"],
            "--size 0: must be between 1 and 16384",
        ),
        (
            vec!["dataset", "builtin", "--views", "0"],
            "--views 0: must be between 1",
        ),
        (
            vec!["analytic", "--size", "32x24"],
            "32x24: these views are square, give N or NxN",
        ),
        (
            vec!["render", scene, "--size", "wide"],
            "\"wide\" is not a whole number (expected N or WIDTHxHEIGHT",
        ),
    ] {
        let o = sfp(&[&args[..], &["--out", v]].concat());
        assert_clean_failure(&o, needle);
        assert!(!stderr(&o).contains(".toml"), "{}", stderr(&o));
        assert_eq!(o.status.code(), Some(2));
    }

    // One spelling of sizes: N or WIDTHxHEIGHT for every subcommand.
    for args in [
        vec!["render", scene, "--spp", "1", "--size", "20"],
        vec!["analytic", "--size", "20x20"],
    ] {
        let sized = dir.path().join("sized");
        sfp_ok(&[&args[..], &["--out", sized.to_str().unwrap()]].concat());
        let view = sfp_core::view::View::read(&sized).unwrap();
        assert_eq!(view.input.size(), (20, 20));
    }

    // A finite but absurd refractive index used to panic in every method;
    // an option a method does not have used to be ignored.
    let out = dir.path().join("result");
    let r = out.to_str().unwrap();
    for method in ["smith", "atkinson", "mahmoud", "smsfp", "yu2017"] {
        let o = sfp(&[
            "reconstruct",
            v,
            "--method",
            method,
            "--eta",
            "1e155",
            "--out",
            r,
        ]);
        assert_clean_failure(&o, "eta = 1e155 must be in (1, 3]");
    }
    let o = sfp(&[
        "reconstruct",
        v,
        "--method",
        "atkinson",
        "--lambda",
        "0.3",
        "--out",
        r,
    ]);
    assert_clean_failure(&o, "lambda");
}

#[test]
fn dataset_renders_resumes_and_names_missing_files() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("ds");
    let o = out.to_str().unwrap();
    let args = [
        "dataset", "builtin", "--out", o, "--views", "1", "--size", "24", "--spp", "1",
    ];
    let first = sfp(&args);
    assert!(first.status.success(), "{}", stderr(&first));
    let index = read_json(&out.join("dataset.json"));
    assert_eq!(index["views"].as_array().unwrap().len(), 7);
    assert!(out.join("cup_0/meta.json").is_file());
    let again = String::from_utf8_lossy(&sfp(&args).stdout).into_owned();
    assert!(again.contains("0 rendered, 7 already complete"), "{again}");
    // Other settings: every view is rendered again, none is mixed in.
    let mut larger = args;
    larger[7] = "32";
    let text = String::from_utf8_lossy(&sfp(&larger).stdout).into_owned();
    assert!(
        text.contains("7 rendered, 7 of them replacing views rendered with other settings"),
        "{text}"
    );
    let cup = sfp_core::view::View::read(&out.join("cup_0")).unwrap();
    assert_eq!(cup.input.size(), (32, 32));

    assert_clean_failure(&sfp(&["dataset", "nope.toml", "--out", o]), "nope.toml");
}

#[test]
fn reconstruct_a_dataset_with_every_method() {
    let dir = tempfile::tempdir().unwrap();
    let ds = dir.path().join("ds");
    let d = ds.to_str().unwrap();
    let args = [
        "dataset", "builtin", "--out", d, "--views", "1", "--size", "32", "--spp", "4",
    ];
    sfp_ok(&args);
    let index = read_json(&ds.join("dataset.json"));
    let views: Vec<&str> = index["views"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v["folder"].as_str().unwrap())
        .collect();
    let methods = ["atkinson", "mahmoud", "smith", "smsfp", "yu2017"];

    let out = dir.path().join("results");
    // --lambda is an option of smith and smsfp only: a note, not a failure.
    let o = sfp_ok(&[
        "reconstruct",
        d,
        "--method",
        "all",
        "--lambda",
        "0.2",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(stderr(&o).contains("'lambda' not set for atkinson, mahmoud"));
    let stdout = String::from_utf8_lossy(&o.stdout).into_owned();
    for m in methods {
        assert!(stdout.contains(&format!("| mean | {m} |")), "{stdout}");
        for v in &views {
            assert!(
                out.join(v).join(m).join("metrics.json").is_file(),
                "{v}/{m}"
            );
        }
    }

    let csv = std::fs::read_to_string(out.join("summary.csv")).unwrap();
    let rows: Vec<Vec<&str>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    assert_eq!(rows.len(), views.len() * methods.len(), "{csv}");
    for v in &views {
        for m in methods {
            let row = rows
                .iter()
                .find(|r| r[0] == *v && r[2] == m)
                .unwrap_or_else(|| panic!("no row {v}/{m} in {csv}"));
            let mae: f64 = row[3].parse().unwrap();
            assert!((0.0..=90.0).contains(&mae), "{row:?}");
        }
    }

    let md = std::fs::read_to_string(out.join("summary.md")).unwrap();
    let runs = md.split("## Per object").next().unwrap();
    let run_rows = runs
        .lines()
        .filter(|l| views.iter().any(|v| l.starts_with(&format!("| {v} |"))));
    assert_eq!(run_rows.count(), views.len() * methods.len(), "{md}");
    let per_object = md.split("## Per object").nth(1).expect("per-object table");
    for m in methods {
        let mean_rows = per_object
            .lines()
            .filter(|l| l.starts_with(&format!("| mean | {m} |")))
            .count();
        assert_eq!(mean_rows, 1, "{md}");
        // One row per object (the builtin preset names them in dataset.json).
        assert!(per_object.contains(&format!("| cup | {m} |")), "{md}");
    }

    // A broken view is reported and the others still run; exit code 1.
    std::fs::write(ds.join("cup_0/input/pol_000.png"), b"garbage").unwrap();
    let again = dir.path().join("again");
    let o = sfp(&[
        "reconstruct",
        d,
        "--method",
        "smith",
        "--out",
        again.to_str().unwrap(),
    ]);
    assert_clean_failure(&o, "1 of 7 runs failed");
    let md = std::fs::read_to_string(again.join("summary.md")).unwrap();
    assert!(
        md.contains("- cup_0 / smith:") && md.contains("pol_000.png"),
        "{md}"
    );
    assert!(again.join("sphere_0/smith/normals.exr").is_file());

    // Neither a view nor a dataset: named.
    let empty = dir.path().join("empty_folder");
    std::fs::create_dir_all(&empty).unwrap();
    let o = sfp(&[
        "reconstruct",
        empty.to_str().unwrap(),
        "--out",
        again.to_str().unwrap(),
    ]);
    assert_clean_failure(&o, "empty_folder");
}

#[test]
fn outputs_replace_old_folders_whole_and_never_a_views_data() {
    let dir = tempfile::tempdir().unwrap();
    let view = dir.path().join("view");
    let v = view.to_str().unwrap();
    assert!(
        sfp(&["analytic", "--size", "32", "--out", v])
            .status
            .success()
    );
    assert!(view.join("gt").join("normals.exr").is_file());

    // Importing a capture over the old view: its gt/ and mask must not
    // survive, or the capture is scored against the old ground truth.
    let input = view.join("input");
    let angles: Vec<String> = ["000", "045", "090", "135"]
        .iter()
        .map(|a| input.join(format!("pol_{a}.png")).display().to_string())
        .collect();
    let copies = dir.path().join("capture");
    std::fs::create_dir(&copies).unwrap();
    let mut args = vec!["import".to_string(), "--angles".to_string()];
    for (k, a) in angles.iter().enumerate() {
        let copy = copies.join(format!("{k}.png"));
        std::fs::copy(a, &copy).unwrap();
        args.push(copy.display().to_string());
    }
    args.extend(["--out".to_string(), v.to_string()]);
    sfp_ok(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert!(!view.join("gt").exists(), "the old ground truth survived");
    assert!(!input.join("mask.png").exists(), "the old mask survived");

    // A result written into the view's own data, or over the view, is refused.
    assert!(
        sfp(&["analytic", "--size", "32", "--out", v])
            .status
            .success()
    );
    for out in [view.join("gt"), view.join("input").join("r"), view.clone()] {
        let o = sfp(&[
            "reconstruct",
            v,
            "--method",
            "atkinson",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_clean_failure(&o, &out.display().to_string());
    }
    assert!(view.join("gt").join("normals.exr").is_file());
    let o = sfp(&["eval", v, view.join("gt").to_str().unwrap()]);
    assert!(!o.status.success(), "gt/ was overwritten by a result");
}

#[test]
fn reconstruct_needs_only_input_and_evaluates_with_normals_alone() {
    let dir = tempfile::tempdir().unwrap();
    let view = dir.path().join("view");
    let v = view.to_str().unwrap();
    assert!(
        sfp(&["analytic", "--size", "32", "--out", v])
            .status
            .success()
    );
    let gt = view.join("gt");
    let result = dir.path().join("result");
    let reconstruct = || {
        sfp(&[
            "reconstruct",
            v,
            "--method",
            "atkinson",
            "--out",
            result.to_str().unwrap(),
        ])
    };
    // Only normals: evaluated.
    for f in ["depth.exr", "stokes.exr", "albedo.exr"] {
        std::fs::remove_file(gt.join(f)).unwrap();
    }
    let o = reconstruct();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(result.join("metrics.json").is_file());
    // Broken normals: reconstructed, not evaluated, and the file is named.
    std::fs::write(gt.join("normals.exr"), b"not an exr").unwrap();
    let o = reconstruct();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stderr(&o).contains("normals.exr"), "{}", stderr(&o));
    assert!(result.join("normals.exr").is_file() && !result.join("metrics.json").exists());
    assert_clean_failure(&sfp(&["eval", v, result.to_str().unwrap()]), "normals.exr");
}

#[test]
fn results_know_their_view_and_eval_refuses_another() {
    let dir = tempfile::tempdir().unwrap();
    let path = |name: &str| dir.path().join(name).display().to_string();
    let (sphere, blobs, blobs40) = (path("sphere"), path("blobs"), path("blobs40"));
    for (out, shape, size) in [
        (&sphere, "sphere", "32"),
        (&blobs, "blobs", "32"),
        (&blobs40, "blobs", "40"),
    ] {
        sfp_ok(&["analytic", "--shape", shape, "--size", size, "--out", out]);
    }
    let result = path("result");
    sfp_ok(&[
        "reconstruct",
        &sphere,
        "--method",
        "atkinson",
        "--out",
        &result,
    ]);
    let run = read_json(&dir.path().join("result/run.json"));
    assert_eq!(run["view"]["path"], sphere.as_str());
    assert_eq!(run["view"]["input_hash"].as_str().unwrap().len(), 64);
    assert_eq!(run["config"]["method"], "atkinson");
    assert!(run["software"]["commit"].is_string() && run["time"].is_string());
    let metrics = std::fs::read(dir.path().join("result/metrics.json")).unwrap();

    assert!(sfp(&["eval", &sphere, &result]).status.success());
    // Arguments in the other order are named for what they are.
    assert_clean_failure(
        &sfp(&["eval", &result, &sphere]),
        "is a reconstruction folder, not a view",
    );
    assert_clean_failure(
        &sfp(&["inspect", &result]),
        "is a reconstruction folder, not a view",
    );
    assert_clean_failure(&sfp(&["eval", &blobs, &result]), "another view");
    let o = sfp(&["eval", &blobs40, &result]);
    assert_clean_failure(&o, "32×32");
    assert_eq!(o.status.code(), Some(2), "an input error");
    // The system refusing a write is a runtime failure: exit code 1.
    let o = sfp(&["analytic", "--size", "8", "--out", "/dev/null/view"]);
    assert_clean_failure(&o, "/dev/null");
    assert_eq!(o.status.code(), Some(1), "a runtime failure");
    // The refused evaluations left the result's metrics alone.
    assert_eq!(
        std::fs::read(dir.path().join("result/metrics.json")).unwrap(),
        metrics
    );
}

#[test]
fn export_for_python_and_the_per_angle_layout_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let p = |name: &str| dir.path().join(name).display().to_string();
    let (view, result, npy, layout, back) =
        (p("view"), p("result"), p("npy"), p("layout"), p("back"));
    assert!(
        sfp(&["analytic", "--size", "24", "--out", &view])
            .status
            .success()
    );
    sfp_ok(&[
        "reconstruct",
        &view,
        "--method",
        "atkinson",
        "--out",
        &result,
    ]);

    sfp_ok(&["export", &result, "--out", &npy]);
    for f in ["normals.npy", "normals.png", "height.npy", "export.json"] {
        assert!(dir.path().join("npy").join(f).is_file(), "{f}");
    }
    // numpy reads the normals back bit for bit, where python3 has numpy.
    let normals = sfp_core::io::read_normals(&dir.path().join("result/normals.exr")).unwrap();
    let script = "import sys, numpy as np\n\
                  a = np.load(sys.argv[1])\n\
                  assert a.dtype == np.float32 and a.shape == (24, 24, 3), (a.dtype, a.shape)\n\
                  sys.stdout.write(' '.join(str(v.view(np.uint32)) for v in a.reshape(-1)))\n";
    let npy_file = dir.path().join("npy/normals.npy");
    match Command::new("python3")
        .args(["-c", script])
        .arg(&npy_file)
        .output()
    {
        Ok(o) if o.status.success() => {
            let bits: Vec<u32> = String::from_utf8(o.stdout)
                .unwrap()
                .split(' ')
                .map(|v| v.parse().unwrap())
                .collect();
            let want: Vec<u32> = normals
                .data()
                .iter()
                .flatten()
                .map(|v| v.to_bits())
                .collect();
            assert_eq!(bits, want, "numpy.load differs from normals.exr");
        }
        _ => eprintln!("skipped the numpy check: python3 with numpy is not installed"),
    }

    // A view as the per-angle layout and back.
    sfp_ok(&["export", &view, "--out", &layout, "--name", "sphere"]);
    assert!(dir.path().join("layout/pol045/sphere.png").is_file());
    sfp_ok(&["import", "--layout", &layout, "--out", &back]);
    let (a, b) = (
        sfp_core::view::View::read(Path::new(&view)).unwrap(),
        sfp_core::view::View::read(Path::new(&back)).unwrap(),
    );
    assert_eq!(a.input, b.input);
    let (ga, gb) = (a.gt.unwrap().normals, b.gt.unwrap().normals);
    for (x, y) in ga.data().iter().zip(gb.data()) {
        let dot: f32 = x.iter().zip(y).map(|(p, q)| p * q).sum();
        assert!(
            *x == [0.0; 3] && *y == [0.0; 3] || dot > 0.999_999,
            "{x:?} vs {y:?}"
        );
    }
}

#[test]
fn bench_runs_shards_merges_and_names_bad_keys() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = dir.path().join("sweep.toml");
    let text = "seeds = 2\n[[views]]\nanalytic = \"sphere\"\nsize = 32\n\
                [axes]\neta = [1.3, 1.6]\n[[methods]]\nmethod = \"smith\"\n";
    std::fs::write(&sweep, text).unwrap();
    let s = sweep.to_str().unwrap();
    let out = |name: &str| dir.path().join(name).to_str().unwrap().to_string();
    for k in ["1/2", "2/2"] {
        let o = sfp_ok(&[
            "bench",
            s,
            "--out",
            &out(&k.replace('/', "-")),
            "--shard",
            k,
        ]);
        assert!(String::from_utf8_lossy(&o.stdout).contains("2 rows"));
    }
    sfp_ok(&[
        "bench",
        "merge",
        &out("1-2"),
        &out("2-2"),
        "--out",
        &out("merged"),
    ]);
    let csv = std::fs::read_to_string(dir.path().join("merged/results.csv")).unwrap();
    assert_eq!(csv.lines().count(), 5, "{csv}");
    sfp_ok(&["bench", s, "--out", &out("whole")]);
    assert_eq!(
        std::fs::read_to_string(dir.path().join("whole/results.csv")).unwrap(),
        csv
    );

    std::fs::write(&sweep, text.replace("eta = [", "etta = [")).unwrap();
    assert_clean_failure(&sfp(&["bench", s, "--out", &out("bad")]), "axes.etta");
    assert_clean_failure(
        &sfp(&["bench", s, "--out", &out("bad"), "--shard", "3/2"]),
        "K/N",
    );
    assert_clean_failure(
        &sfp(&["bench", "merge", &out("nothing"), "--out", &out("m2")]),
        "sweep.toml",
    );
}

/// When to kill a run of 0.1–0.2 s: from before its first file to its last.
const SHORT_RUN_KILLS_MS: &[u64] = &[2, 5, 9, 14, 20, 30, 45, 70, 110, 160];

/// Kills `args` (an `sfp` command writing `folder`) after each delay and
/// checks that `folder` is then always complete: `valid(folder)` holds for
/// the previous or the new contents, never for a mix or a half.
fn kill_while_writing(
    args: &[&str],
    folder: &Path,
    delays_ms: &[u64],
    valid: &dyn Fn(&Path) -> bool,
) -> usize {
    let mut interrupted = 0;
    for &delay_ms in delays_ms {
        let mut child = Command::new(env!("CARGO_BIN_EXE_sfp"))
            .args(args)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_millis(delay_ms));
        if child.try_wait().unwrap().is_none() {
            interrupted += 1;
        }
        let _ = child.kill(); // SIGKILL
        let _ = child.wait();
        assert!(
            valid(folder),
            "{} after a kill at {delay_ms} ms",
            folder.display()
        );
    }
    interrupted
}

#[test]
fn a_killed_run_leaves_the_previous_or_the_new_folder_whole() {
    use sfp_core::view::View;
    let dir = tempfile::tempdir().unwrap();
    let view = dir.path().join("view");
    let v = view.to_str().unwrap();
    assert!(
        sfp(&["analytic", "--size", "32", "--out", v])
            .status
            .success()
    );
    // A view: 32² sphere before, 160² blobs after, each complete.
    let whole_view = |p: &Path| {
        View::is_complete(p)
            && View::read(p).is_ok_and(|w| {
                let size = w.input.size();
                (size == (32, 32) || size == (160, 160))
                    && w.gt
                        .is_some_and(|gt| gt.stokes.is_some() && gt.albedo.is_some())
            })
    };
    let killed = kill_while_writing(
        &["analytic", "--shape", "blobs", "--size", "160", "--out", v],
        &view,
        SHORT_RUN_KILLS_MS,
        &whole_view,
    );
    assert!(whole_view(&view));

    // A result: every file of a reconstruction, or the previous one.
    assert!(
        sfp(&["analytic", "--size", "96", "--out", v])
            .status
            .success()
    );
    let result = dir.path().join("result");
    let r = result.to_str().unwrap();
    let whole_result = |p: &Path| {
        !p.exists()
            || [
                "normals.exr",
                "normals.png",
                "height.exr",
                "mesh.ply",
                "metrics.json",
                "run.json",
            ]
            .iter()
            .all(|f| p.join(f).is_file())
    };
    let killed_results = kill_while_writing(
        &["reconstruct", v, "--method", "smith", "--out", r],
        &result,
        SHORT_RUN_KILLS_MS,
        &whole_result,
    );
    // Nothing is left beside the folders.
    let stray: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.'))
        .collect();
    println!("killed {killed} view writes and {killed_results} reconstructions; stray {stray:?}");
    assert!(killed + killed_results > 0, "no run was interrupted");
}

/// The same for the other writers: `render` and `import` replace one view
/// folder, `dataset` fills a dataset folder view by view; after a SIGKILL at
/// any point each view folder is the previous complete one or the new one.
#[test]
fn killed_renders_datasets_and_imports_leave_whole_views() {
    use sfp_core::view::View;
    let dir = tempfile::tempdir().unwrap();
    let view_of_size = |p: &Path, sizes: &[(usize, usize)]| {
        View::is_complete(p) && View::read(p).is_ok_and(|w| sizes.contains(&w.input.size()))
    };
    let scene = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../scenes/examples/sphere.toml"
    );

    let rendered = dir.path().join("rendered");
    let r = rendered.to_str().unwrap();
    let small = ["render", scene, "--size", "24x24", "--spp", "2", "--out", r];
    assert!(sfp(&small).status.success());
    let sizes = [(24, 24), (320, 320)];
    let big = [
        "render", scene, "--size", "320x320", "--spp", "64", "--out", r,
    ];
    let killed_renders = kill_while_writing(&big, &rendered, SHORT_RUN_KILLS_MS, &|p| {
        view_of_size(p, &sizes)
    });

    assert!(sfp(&big).status.success());
    assert!(view_of_size(&rendered, &[(320, 320)]));

    // An import of the 320² render's four angle files over a 24² view.
    let source = dir.path().join("source");
    std::fs::rename(&rendered, &source).unwrap();
    assert!(sfp(&small).status.success());
    let files: Vec<String> = ["000", "045", "090", "135"]
        .iter()
        .map(|a| {
            source
                .join(format!("input/pol_{a}.png"))
                .display()
                .to_string()
        })
        .collect();
    let mut import = vec!["import", "--angles"];
    import.extend(files.iter().map(String::as_str));
    import.extend(["--auto-mask", "--out", r]);
    let killed_imports = kill_while_writing(&import, &rendered, SHORT_RUN_KILLS_MS, &|p| {
        view_of_size(p, &sizes)
    });
    assert!(sfp(&import).status.success());
    assert!(view_of_size(&rendered, &[(320, 320)]));

    // A dataset at 24² re-rendered at 40²: every view folder present is one
    // or the other, and dataset.json, when present, is whole.
    let ds = dir.path().join("ds");
    let d = ds.to_str().unwrap();
    let dataset = |size: &'static str| ["dataset", "builtin", "--size", size, "--out", d];
    assert!(sfp(&dataset("24")).status.success());
    let whole_dataset = |p: &Path| {
        let json = p.join("dataset.json");
        (!json.exists()
            || serde_json::from_slice::<serde_json::Value>(&std::fs::read(json).unwrap()).is_ok())
            && std::fs::read_dir(p).unwrap().flatten().all(|e| {
                let name = e.file_name().to_string_lossy().into_owned();
                name.starts_with('.')
                    || name == "dataset.json"
                    || view_of_size(&e.path(), &[(24, 24), (40, 40)])
            })
    };
    let killed_datasets = kill_while_writing(
        &dataset("40"),
        &ds,
        &[10, 40, 90, 150, 250, 400, 600, 900, 1300, 1800],
        &whole_dataset,
    );
    assert!(sfp(&dataset("40")).status.success());
    let views = std::fs::read_dir(&ds)
        .unwrap()
        .flatten()
        .filter(|e| e.path().is_dir() && !e.file_name().to_string_lossy().starts_with('.'))
        .count();
    assert_eq!(views, 14);
    assert!(whole_dataset(&ds));
    println!(
        "killed {killed_renders} renders, {killed_imports} imports, {killed_datasets} datasets"
    );
    assert!(killed_renders > 0 && killed_imports > 0 && killed_datasets > 0);
}
