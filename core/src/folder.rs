//! Output folders replaced as a whole (conventions.md §5 folders: views and
//! reconstructions).
//!
//! Writing file by file into an existing folder kept whatever the previous
//! run left there: an import over an old view kept its `gt/`, so the new
//! capture was scored against the old ground truth. And a run killed while
//! writing left new files beside the old completion marker. So a folder is
//! written complete under a temporary sibling name and swapped into place in
//! one step: a reader sees the whole previous folder or the whole new one.

use crate::result_folder::ResultFolder;
use crate::{Error, Result};
use std::path::{Path, PathBuf};

/// The one rule of what a view folder is (conventions.md §5): a folder
/// with `input/`. Every command that asks "is this a view?" asks this;
/// [`View::is_complete`](crate::view::View::is_complete) adds `meta.json`,
/// written last.
pub fn is_view(dir: &Path) -> bool {
    dir.join("input").is_dir()
}

/// What a folder holds, so that replacing it cannot destroy something else
/// (a result written over a view, a view over a dataset).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A view ([`is_view`]).
    View,
    /// A reconstruction ([`ResultFolder`]).
    Result,
}

impl Kind {
    pub fn name(self) -> &'static str {
        match self {
            Kind::View => "view",
            Kind::Result => "reconstruction",
        }
    }

    /// The kind of folder `dir` holds, if it is a view or a reconstruction.
    pub fn of(dir: &Path) -> Option<Kind> {
        [Kind::View, Kind::Result]
            .into_iter()
            .find(|k| k.holds(dir))
    }

    /// Whether the existing folder `dir` is one of this kind.
    fn holds(self, dir: &Path) -> bool {
        match self {
            Kind::View => is_view(dir),
            Kind::Result => ResultFolder::is_result(dir),
        }
    }
}

/// Writes a folder of `kind` at `dir` with `write` (given the folder to fill)
/// and puts it in place of whatever `dir` held, atomically where the file
/// system can exchange two names (Linux), else by two renames.
///
/// Refuses, before writing anything, a `dir` that exists and is neither
/// empty nor a folder of `kind`, that is not a folder at all (a file, a
/// device, a FIFO: never moved aside), and a `dir` inside a view's `input/`,
/// `gt/` or `preview/` (an output there would replace the data it is judged
/// by). A symbolic link is followed: the folder it points to is replaced and
/// the link kept.
pub fn replace(dir: &Path, kind: Kind, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    let dir = &follow_link(dir)?;
    check_target(dir, kind)?;
    let parent = match dir.parent().filter(|p| !p.as_os_str().is_empty()) {
        Some(p) => p.to_path_buf(),
        None => PathBuf::from("."),
    };
    std::fs::create_dir_all(&parent).map_err(|e| Error::io(&parent, e))?;
    remove_stale(dir, &parent);
    let staging = sibling(dir, &format!("partial-{}", std::process::id()));
    if staging.exists() {
        std::fs::remove_dir_all(&staging).map_err(|e| Error::io(&staging, e))?;
    }
    // Named by the output, not by its hidden staging name.
    std::fs::create_dir(&staging).map_err(|e| {
        Error::io(
            dir,
            std::io::Error::new(e.kind(), format!("cannot create a folder beside it ({e})")),
        )
    })?;
    if let Err(e) = write(&staging) {
        let _ = std::fs::remove_dir_all(&staging);
        return Err(e);
    }
    swap_into_place(&staging, dir)
}

/// Refuses `dir` inside a view's `input/`, `gt/` or `preview/`: output
/// written there would replace or pollute the data the view is judged by.
pub fn ensure_outside_view_data(dir: &Path) -> Result<()> {
    let absolute = std::path::absolute(dir).map_err(|e| Error::io(dir, e))?;
    for ancestor in absolute.ancestors() {
        let name = ancestor.file_name().and_then(|n| n.to_str());
        if let (Some(name @ ("input" | "gt" | "preview")), Some(view)) = (name, ancestor.parent())
            && Kind::View.holds(view)
        {
            return Err(Error::file(
                dir,
                format!(
                    "is inside the {name}/ folder of the view {}: writing there would change the view's own data; choose an output folder outside the view",
                    view.display()
                ),
            ));
        }
    }
    Ok(())
}

/// `dir`, or the path a symbolic link at `dir` points to (refused when it
/// points to nothing).
pub fn follow_link(dir: &Path) -> Result<PathBuf> {
    match std::fs::symlink_metadata(dir) {
        Ok(m) if m.file_type().is_symlink() => dir.canonicalize().map_err(|e| {
            Error::file(
                dir,
                format!("is a symbolic link to nothing usable ({e}): give a folder"),
            )
        }),
        _ => Ok(dir.to_path_buf()),
    }
}

/// Refuses an existing `dir` that is not a folder: a file, a device, a FIFO
/// or a socket is never moved aside, replaced or written into.
pub fn ensure_folder_or_new(dir: &Path) -> Result<()> {
    let Ok(meta) = std::fs::metadata(dir) else {
        return Ok(());
    };
    if meta.is_dir() {
        return Ok(());
    }
    let what = if meta.is_file() {
        "a file"
    } else {
        "a device, FIFO or socket"
    };
    Err(Error::file(
        dir,
        format!("is {what}, not a folder: give a new or empty folder as the output"),
    ))
}

fn check_target(dir: &Path, kind: Kind) -> Result<()> {
    ensure_outside_view_data(dir)?;
    ensure_folder_or_new(dir)?;
    if dir.is_dir() && !kind.holds(dir) {
        let mut entries = std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))?;
        if entries.next().is_some() {
            let other = Kind::of(dir).map_or("files that are not".to_string(), |k| {
                format!("a {}, not", k.name())
            });
            return Err(Error::file(
                dir,
                format!(
                    "refusing to replace this folder: it holds {other} a {} (give a new or empty folder, or an old {} to replace)",
                    kind.name(),
                    kind.name()
                ),
            ));
        }
    }
    Ok(())
}

/// `.NAME.TAG` beside `dir`.
fn sibling(dir: &Path, tag: &str) -> PathBuf {
    let name = dir.file_name().unwrap_or_default().to_string_lossy();
    dir.with_file_name(format!(".{name}.{tag}"))
}

/// Staging and swapped-out folders of `dir` left by runs that were killed.
fn remove_stale(dir: &Path, parent: &Path) {
    let name = dir.file_name().unwrap_or_default().to_string_lossy();
    let prefixes = [format!(".{name}.partial-"), format!(".{name}.old-")];
    let Ok(entries) = std::fs::read_dir(parent) else {
        return;
    };
    for entry in entries.flatten() {
        let file = entry.file_name();
        let file = file.to_string_lossy();
        if prefixes.iter().any(|p| file.starts_with(p.as_str())) {
            let _ = std::fs::remove_dir_all(entry.path());
        }
    }
}

fn swap_into_place(staging: &Path, dir: &Path) -> Result<()> {
    if !dir.exists() {
        return std::fs::rename(staging, dir).map_err(|e| Error::io(dir, e));
    }
    if exchange(staging, dir) {
        // `staging` now holds the previous folder.
        return std::fs::remove_dir_all(staging).map_err(|e| Error::io(staging, e));
    }
    let old = sibling(dir, &format!("old-{}", std::process::id()));
    std::fs::rename(dir, &old).map_err(|e| Error::io(dir, e))?;
    std::fs::rename(staging, dir).map_err(|e| Error::io(dir, e))?;
    std::fs::remove_dir_all(&old).map_err(|e| Error::io(&old, e))
}

/// Exchanges the names `a` and `b` in one step; false where the system or
/// file system cannot.
#[cfg(target_os = "linux")]
fn exchange(a: &Path, b: &Path) -> bool {
    use rustix::fs::{CWD, RenameFlags, renameat_with};
    renameat_with(CWD, a, CWD, b, RenameFlags::EXCHANGE).is_ok()
}

#[cfg(not(target_os = "linux"))]
fn exchange(_: &Path, _: &Path) -> bool {
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write_view<'a>(files: &'a [&'a str]) -> impl FnOnce(&Path) -> Result<()> + 'a {
        move |d: &Path| {
            std::fs::create_dir_all(d.join("input")).unwrap();
            for f in files {
                std::fs::write(d.join(f), f).unwrap();
            }
            Ok(())
        }
    }

    #[test]
    fn a_view_is_a_folder_with_input_and_complete_with_meta_json() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        // meta.json alone is no view; input/ makes one; meta.json completes it.
        std::fs::write(d.join("meta.json"), "{}").unwrap();
        assert!(!is_view(d) && !crate::view::View::is_complete(d));
        assert_eq!(Kind::of(d), None);
        std::fs::create_dir(d.join("input")).unwrap();
        assert!(is_view(d) && crate::view::View::is_complete(d));
        assert_eq!(Kind::of(d), Some(Kind::View));
        std::fs::remove_file(d.join("meta.json")).unwrap();
        assert!(is_view(d) && !crate::view::View::is_complete(d));
    }

    #[test]
    fn a_folder_is_replaced_whole_and_nothing_is_left_beside_it() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().join("view");
        replace(&dir, Kind::View, write_view(&["meta.json", "old_only"])).unwrap();
        replace(&dir, Kind::View, write_view(&["meta.json"])).unwrap();
        assert!(dir.join("meta.json").is_file());
        assert!(
            !dir.join("old_only").exists(),
            "a file of the previous run survived"
        );
        let names: Vec<_> = std::fs::read_dir(tmp.path()).unwrap().flatten().collect();
        assert_eq!(names.len(), 1, "staging or old folders left: {names:?}");
    }

    #[test]
    fn a_failed_write_keeps_the_previous_folder() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().join("view");
        replace(&dir, Kind::View, write_view(&["meta.json", "first"])).unwrap();
        let failed = replace(&dir, Kind::View, |d| {
            std::fs::write(d.join("half"), "x").unwrap();
            Err(Error::invalid("killed"))
        });
        assert!(failed.is_err());
        assert!(dir.join("first").is_file() && !dir.join("half").exists());
        // A killed run's staging folder is cleared by the next run.
        std::fs::create_dir(tmp.path().join(".view.partial-1")).unwrap();
        replace(&dir, Kind::View, write_view(&["meta.json"])).unwrap();
        assert!(!tmp.path().join(".view.partial-1").exists());
    }

    #[test]
    fn other_folders_and_view_data_are_refused_by_name() {
        let tmp = tempfile::tempdir().unwrap();
        let view = tmp.path().join("view");
        replace(&view, Kind::View, write_view(&["meta.json"])).unwrap();
        std::fs::create_dir(view.join("gt")).unwrap();
        // A result over the view itself, or inside its gt/ or input/.
        for target in [view.clone(), view.join("gt"), view.join("input").join("r")] {
            let e = replace(&target, Kind::Result, |_| Ok(()))
                .unwrap_err()
                .to_string();
            assert!(e.contains(&target.display().to_string()), "{e}");
        }
        assert!(view.join("meta.json").is_file() && view.join("gt").is_dir());
        // A folder of unrelated files is not replaced; an empty one is.
        let other = tmp.path().join("papers");
        std::fs::create_dir(&other).unwrap();
        std::fs::write(other.join("thesis.pdf"), "x").unwrap();
        let e = replace(&other, Kind::View, |_| Ok(()))
            .unwrap_err()
            .to_string();
        assert!(e.contains("refusing to replace"), "{e}");
        assert!(other.join("thesis.pdf").is_file());
        let empty = tmp.path().join("empty");
        std::fs::create_dir(&empty).unwrap();
        replace(&empty, Kind::Result, |d| {
            ResultFolder::new(d).write_run(&serde_json::json!({}))
        })
        .unwrap();
        assert!(ResultFolder::is_result(&empty));
    }
}
