//! A killed `sfp` leaves every folder it was writing whole: the previous
//! contents or the new ones, never a mix or a half.

mod common;

use common::*;
use std::path::Path;
use std::process::Command;

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
