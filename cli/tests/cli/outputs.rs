//! Nothing outside `--out` is touched: special files and symbolic links as
//! `--out`, folder-writing commands over foreign folders, two writers on one
//! sweep folder, merges into the wrong place, rows a resumed sweep must not
//! trust, and `sfp export --name`.

use crate::common::*;
use std::os::unix::fs::FileTypeExt;
use std::path::{Path, PathBuf};

/// Every name under `dir` with its size, to tell that nothing changed.
fn snapshot(dir: &Path) -> Vec<(PathBuf, u64)> {
    let mut all = Vec::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let meta = std::fs::symlink_metadata(e.path()).unwrap();
            if meta.is_dir() {
                todo.push(e.path());
            }
            all.push((e.path(), meta.len()));
        }
    }
    all.sort();
    all
}

const SPHERE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../scenes/examples/sphere.toml"
);

fn analytic(out: &Path) {
    sfp_ok(&["analytic", "--size", "32", "--out", out.to_str().unwrap()]);
}

/// A tiny sweep file (4 rows: 2 η × 2 seeds of one analytic view).
fn tiny_sweep(dir: &Path) -> String {
    let sweep = dir.join("sweep.toml");
    std::fs::write(
        &sweep,
        "seeds = 2\n[[views]]\nanalytic = \"sphere\"\nsize = 32\n\
         [axes]\neta = [1.3, 1.6]\n[[methods]]\nmethod = \"atkinson\"\n",
    )
    .unwrap();
    sweep.to_str().unwrap().to_string()
}

#[test]
fn a_special_file_as_out_is_refused_and_left_in_place() {
    let dir = tempfile::tempdir().unwrap();
    let view = dir.path().join("view");
    analytic(&view);
    let v = view.to_str().unwrap();
    let fifo = dir.path().join("fifo");
    assert!(
        std::process::Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success()
    );
    let f = fifo.to_str().unwrap();
    let pol: Vec<String> = (0..4)
        .map(|i| {
            view.join("input")
                .join(format!("pol_{:03}.png", i * 45))
                .display()
                .to_string()
        })
        .collect();
    for args in [
        vec!["analytic", "--size", "32", "--out", f],
        vec!["reconstruct", v, "--method", "atkinson", "--out", f],
        vec!["render", SPHERE, "--size", "16", "--spp", "1", "--out", f],
        vec![
            "import", "--angles", &pol[0], &pol[1], &pol[2], &pol[3], "--out", f,
        ],
        vec!["demo", "--size", "16", "--out", f],
        vec!["dataset", "builtin", "--size", "16", "--out", f],
        vec!["export", v, "--out", f],
    ] {
        let o = sfp(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert_clean_failure(&o, "not a folder");
        let meta = std::fs::symlink_metadata(&fifo).unwrap();
        assert!(meta.file_type().is_fifo(), "{args:?} replaced the FIFO");
    }
    let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().flatten().collect();
    assert_eq!(names.len(), 2, "left beside: {names:?}");
}

#[test]
fn a_symlinked_out_is_followed_and_the_link_kept() {
    let dir = tempfile::tempdir().unwrap();
    let view = dir.path().join("view");
    analytic(&view);
    std::fs::write(view.join("old_only"), "x").unwrap();
    let link = dir.path().join("link");
    std::os::unix::fs::symlink(&view, &link).unwrap();
    analytic(&link);
    assert!(std::fs::symlink_metadata(&link).unwrap().is_symlink());
    assert!(view.join("meta.json").is_file() && !view.join("old_only").exists());
    // A link to nothing is refused by name.
    let dangling = dir.path().join("dangling");
    std::os::unix::fs::symlink(dir.path().join("gone"), &dangling).unwrap();
    let o = sfp(&["analytic", "--out", dangling.to_str().unwrap()]);
    assert_clean_failure(&o, "symbolic link");
    assert!(!dir.path().join("gone").exists());
}

#[test]
fn folder_writing_commands_refuse_views_results_and_other_collections() {
    let dir = tempfile::tempdir().unwrap();
    let view = dir.path().join("view");
    analytic(&view);
    let v = view.to_str().unwrap();
    let result = dir.path().join("result");
    sfp_ok(&[
        "reconstruct",
        v,
        "--method",
        "atkinson",
        "--out",
        result.to_str().unwrap(),
    ]);
    let r = result.to_str().unwrap();
    let papers = dir.path().join("papers");
    std::fs::create_dir(&papers).unwrap();
    std::fs::write(papers.join("thesis.pdf"), "x").unwrap();
    let p = papers.to_str().unwrap();
    let sweep = tiny_sweep(dir.path());
    let before: Vec<_> = [&view, &result, &papers].map(|d| snapshot(d)).into();
    for (args, holds) in [
        (vec!["demo", "--size", "16", "--out", v], "a view"),
        (vec!["demo", "--size", "16", "--out", r], "a reconstruction"),
        (vec!["demo", "--size", "16", "--out", p], "did not write"),
        (vec!["bench", &sweep, "--out", v], "a view"),
        (
            vec!["dataset", "builtin", "--size", "16", "--out", v],
            "a view",
        ),
        (
            vec!["dataset", "builtin", "--size", "16", "--out", r],
            "a reconstruction",
        ),
        (
            vec!["reconstruct", v, "--method", "all", "--out", r],
            "a reconstruction",
        ),
        (
            vec!["reconstruct", v, "--method", "all", "--out", p],
            "did not write",
        ),
    ] {
        let o = sfp(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert_clean_failure(&o, holds);
    }
    let after: Vec<_> = [&view, &result, &papers].map(|d| snapshot(d)).into();
    assert_eq!(before, after);
    // A sweep folder is no dataset and no demo.
    let s = dir.path().join("sweep_out");
    sfp_ok(&["bench", &sweep, "--out", s.to_str().unwrap()]);
    let o = sfp(&["demo", "--size", "16", "--out", s.to_str().unwrap()]);
    assert_clean_failure(&o, "a sweep");
}

#[test]
fn a_second_writer_on_one_sweep_folder_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = tiny_sweep(dir.path());
    let out = dir.path().join("out");
    std::fs::create_dir(&out).unwrap();
    // Another `sfp` holding the folder: its lock on the marker.
    let marker = std::fs::File::create(out.join(".sfp-folder")).unwrap();
    std::fs::write(out.join(".sfp-folder"), "sweep\n").unwrap();
    marker.lock().unwrap();
    let o = sfp(&[
        "bench",
        &sweep,
        "--out",
        out.to_str().unwrap(),
        "--shard",
        "2/2",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert_clean_failure(&o, "another sfp command is writing into this folder");
    assert!(!out.join("results.jsonl").exists());
    drop(marker);
    sfp_ok(&[
        "bench",
        &sweep,
        "--out",
        out.to_str().unwrap(),
        "--shard",
        "2/2",
    ]);
}

#[test]
fn a_merge_goes_only_into_a_new_folder_or_an_earlier_merge() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = tiny_sweep(dir.path());
    let path = |n: &str| dir.path().join(n).to_str().unwrap().to_string();
    for k in ["1", "2"] {
        sfp_ok(&[
            "bench",
            &sweep,
            "--out",
            &path(k),
            "--shard",
            &format!("{k}/2"),
        ]);
    }
    let whole = path("whole");
    assert!(sfp(&["bench", &sweep, "--out", &whole]).status.success());
    let view = dir.path().join("view");
    analytic(&view);
    let shard_before = snapshot(Path::new(&path("1")));
    let whole_before = snapshot(Path::new(&whole));
    for (into, why) in [
        (whole.clone(), "not an earlier merge"),
        (path("2"), "outside its inputs"),
        (view.display().to_string(), "a view"),
        (format!("{}/merged", path("1")), "outside its inputs"),
    ] {
        let o = sfp(&["bench", "merge", &path("1"), &path("2"), "--out", &into]);
        assert_eq!(o.status.code(), Some(2), "{into}: {}", stderr(&o));
        assert_clean_failure(&o, why);
    }
    assert_eq!(snapshot(Path::new(&path("1"))), shard_before);
    assert_eq!(snapshot(Path::new(&whole)), whole_before);
    // A merge again into its own folder is fine.
    for _ in 0..2 {
        sfp_ok(&[
            "bench",
            "merge",
            &path("1"),
            &path("2"),
            "--out",
            &path("m"),
        ]);
    }
    // A shard's provenance that cannot be read no longer lets another shard in.
    std::fs::write(dir.path().join("1/provenance.json"), "garbage").unwrap();
    let o = sfp(&["bench", &sweep, "--out", &path("1"), "--shard", "2/2"]);
    assert_clean_failure(&o, "provenance.json");
}

#[test]
fn a_resumed_sweep_redoes_rows_it_cannot_trust() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = tiny_sweep(dir.path());
    let out = dir.path().join("out");
    let o_ = out.to_str().unwrap();
    assert!(sfp(&["bench", &sweep, "--out", o_]).status.success());
    let jsonl = out.join("results.jsonl");
    let clean = std::fs::read_to_string(&jsonl).unwrap();
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    let lines: Vec<&str> = clean.lines().collect();
    assert_eq!(lines.len(), 4);
    let mut row: serde_json::Value = serde_json::from_str(lines[1]).unwrap();
    // A repeated line, another row under the first one's key, a row of no
    // plan, and a row the full disk failed.
    let mut conflicting: serde_json::Value = serde_json::from_str(lines[0]).unwrap();
    conflicting["metrics"]["mae_deg"] = 99.0.into();
    let mut stray = row.clone();
    stray["key"] = "not-planned".into();
    row["metrics"] = serde_json::Value::Null;
    row["error"] = "views/x/pol_000.png: No space left on device (os error 28)".into();
    let edited = [
        lines[0].to_string(),
        conflicting.to_string(),
        row.to_string(),
        lines[2].to_string(),
        lines[2].to_string(),
        lines[3].to_string(),
        stray.to_string(),
    ]
    .join("\n")
        + "\n";
    std::fs::write(&jsonl, edited).unwrap();
    let o = sfp_ok(&["bench", &sweep, "--out", o_]);
    assert!(stderr(&o).contains("rows of"), "{}", stderr(&o));
    assert!(
        String::from_utf8_lossy(&o.stdout).contains("(2 computed now"),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    assert_eq!(std::fs::read_to_string(&jsonl).unwrap(), clean);
    assert_eq!(
        std::fs::read_to_string(out.join("results.csv")).unwrap(),
        csv
    );
}

#[test]
fn export_names_stay_inside_out_and_replace_their_old_files() {
    let dir = tempfile::tempdir().unwrap();
    let view = dir.path().join("view");
    analytic(&view);
    let v = view.to_str().unwrap();
    let layout = dir.path().join("sub").join("layout");
    let l = layout.to_str().unwrap();
    for name in ["../../victim", "", ".", "..", "a/b", ".hidden"] {
        let o = sfp(&["export", v, "--out", l, "--name", name]);
        assert_eq!(o.status.code(), Some(2), "{name:?}: {}", stderr(&o));
        assert_clean_failure(&o, "--name");
        let o = sfp(&["import", "--layout", l, "--name", name, "--out", "unused"]);
        assert_eq!(o.status.code(), Some(2), "{name:?}: {}", stderr(&o));
    }
    assert!(!dir.path().join("victim").exists() && !layout.exists());
    // Exported again without ground truth: the old normal/x.png is gone.
    sfp_ok(&["export", v, "--out", l, "--name", "x"]);
    assert!(layout.join("normal/x.png").is_file());
    std::fs::remove_dir_all(view.join("gt")).unwrap();
    sfp_ok(&["export", v, "--out", l, "--name", "x"]);
    assert!(!layout.join("normal/x.png").exists());
    // Never into a view or a result folder.
    let other = dir.path().join("other");
    analytic(&other);
    let before = snapshot(&other);
    let o = sfp(&["export", v, "--out", other.to_str().unwrap()]);
    assert_clean_failure(&o, "is a view");
    assert_eq!(snapshot(&other), before);
}
