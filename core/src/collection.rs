//! Folders that a command fills with many outputs (a dataset, a sweep, the
//! demo, the reconstructions of a dataset), as opposed to the view and
//! result folders that [`folder::replace`] swaps in whole.
//!
//! Such a folder is written into, not replaced, so two guards apply before
//! the first file: the folder must be new, empty or one of the same kind
//! (a demo written into a view mixed its files with the view's), and only
//! one command may write into it at a time (two shards started on one
//! `--out` lost half their rows). Both live in one hidden file,
//! `.sfp-folder`: it names the kind, and the command holds an exclusive
//! advisory lock on it until it ends (released by the system if it dies).

use crate::folder::{self, Kind};
use crate::{Error, Result};
use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};

/// The hidden file naming a folder's kind, locked by its writer.
pub const MARKER: &str = ".sfp-folder";

/// The most a marker may hold (it holds a kind's name).
const MARKER_MAX: u64 = 4096;

/// The kinds of folder a command writes many outputs into.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Collection {
    /// `sfp dataset`: view folders and `dataset.json`.
    Dataset,
    /// `sfp bench` and `sfp bench merge`: `results.jsonl`, cached views, pictures, report.
    Sweep,
    /// `sfp demo`: views, results, `summary.md`, the report.
    Demo,
    /// `sfp reconstruct DATASET`: `<view>/<method>/` and `summary.md|csv`.
    Reconstructions,
}

impl Collection {
    const ALL: [Collection; 4] = [
        Collection::Dataset,
        Collection::Sweep,
        Collection::Demo,
        Collection::Reconstructions,
    ];

    fn name(self) -> &'static str {
        match self {
            Collection::Dataset => "dataset",
            Collection::Sweep => "sweep",
            Collection::Demo => "demo",
            Collection::Reconstructions => "reconstructions",
        }
    }

    /// The kind of a folder written before the marker existed, by the file
    /// each kind always has.
    fn recognise(dir: &Path) -> Option<Collection> {
        if dir.join("dataset.json").is_file() {
            Some(Collection::Dataset)
        } else if dir.join("plan.txt").is_file() {
            Some(Collection::Sweep)
        } else if dir.join("sweep.toml").is_file() {
            Some(Collection::Demo)
        } else if dir.join("summary.csv").is_file() {
            Some(Collection::Reconstructions)
        } else {
            None
        }
    }
}

/// A folder claimed by this process: the lock is held until it is dropped.
#[derive(Debug)]
pub struct Claim {
    /// The folder written into (a symbolic link followed).
    pub dir: PathBuf,
    _lock: File,
}

/// Claims `dir` for writing outputs of kind `kind`, creating it: refuses a
/// path that is not a folder, a folder inside a view's data, a view, a
/// reconstruction, a folder of another kind or of unrelated files, and a
/// folder another `sfp` is writing into.
pub fn claim(dir: &Path, kind: Collection) -> Result<Claim> {
    let dir = folder::follow_link(dir)?;
    folder::ensure_outside_view_data(&dir)?;
    folder::ensure_folder_or_new(&dir)?;
    let found = existing_kind(&dir, kind)?;
    if let Some(other) = found.filter(|&k| k != kind.name()) {
        return Err(refusal(&dir, &format!("a {other}"), kind));
    }
    std::fs::create_dir_all(&dir).map_err(|e| Error::io(&dir, e))?;
    let path = dir.join(MARKER);
    let mut file = OpenOptions::new()
        .read(true)
        .write(true)
        .create(true)
        .truncate(false)
        .open(&path)
        .map_err(|e| Error::io(&path, e))?;
    match file.try_lock() {
        Ok(()) => {}
        Err(std::fs::TryLockError::WouldBlock) => {
            return Err(Error::file(
                &dir,
                "another sfp command is writing into this folder: wait for it to end, or give \
                 each run (each --shard) its own --out",
            ));
        }
        Err(std::fs::TryLockError::Error(e)) => return Err(Error::io(&path, e)),
    }
    let mut text = String::new();
    (&file)
        .take(MARKER_MAX)
        .read_to_string(&mut text)
        .map_err(|e| Error::io(&path, e))?;
    if text.trim() != kind.name() {
        file.set_len(0)
            .and_then(|()| file.rewind())
            .and_then(|()| file.write_all(format!("{}\n", kind.name()).as_bytes()))
            .map_err(|e| Error::io(&path, e))?;
    }
    Ok(Claim { dir, _lock: file })
}

/// The kind of the existing folder `dir` (`None`: new or empty), or an
/// error when it holds files `sfp` did not write.
fn existing_kind(dir: &Path, kind: Collection) -> Result<Option<&'static str>> {
    let Ok(mut entries) = std::fs::read_dir(dir) else {
        return Ok(None);
    };
    if entries.next().is_none() {
        return Ok(None);
    }
    // What the folder holds outranks its marker: a marker copied or left
    // in a view or a dataset must not let another kind write into it.
    if let Some(single) = Kind::of(dir) {
        return Ok(Some(single.name()));
    }
    if let Some(text) = read_marker(&dir.join(MARKER))? {
        let marked = Collection::ALL.iter().find(|k| k.name() == text.trim());
        return match (marked, Collection::recognise(dir)) {
            (None, _) => Err(Error::file(
                &dir.join(MARKER),
                format!("names no kind of folder ({:?})", text.trim()),
            )),
            (Some(k), Some(Collection::Dataset)) if *k != Collection::Dataset => Err(Error::file(
                &dir.join(MARKER),
                format!(
                    "names a {} folder, but the folder holds a dataset (dataset.json)",
                    k.name()
                ),
            )),
            (Some(k), _) => Ok(Some(k.name())),
        };
    }
    match Collection::recognise(dir) {
        Some(k) => Ok(Some(k.name())),
        None => Err(refusal(dir, "files sfp did not write", kind)),
    }
}

/// The marker's text, `None` when there is none. Only a regular file of
/// at most [`MARKER_MAX`] bytes is read: a FIFO would block the command, a
/// link to a device could be endless, and a dangling link would make
/// claiming create a file wherever it points.
fn read_marker(path: &Path) -> Result<Option<String>> {
    let meta = match std::fs::symlink_metadata(path) {
        Ok(meta) => meta,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => return Err(Error::io(path, e)),
    };
    if !meta.is_file() {
        return Err(Error::file(
            path,
            "is not a regular file (a link, FIFO, device or folder): sfp writes this \
             marker itself; remove it",
        ));
    }
    if meta.len() > MARKER_MAX {
        return Err(Error::file(
            path,
            format!("is {} bytes, more than a marker's {MARKER_MAX}", meta.len()),
        ));
    }
    std::fs::read_to_string(path)
        .map(Some)
        .map_err(|e| Error::read(path, e))
}

fn refusal(dir: &Path, holds: &str, kind: Collection) -> Error {
    Error::file(
        dir,
        format!(
            "refusing to write a {} into this folder: it holds {holds} (give a new or empty \
             folder, or one an earlier `sfp` run of the same kind wrote)",
            kind.name()
        ),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn refused(dir: &Path, kind: Collection, expected: &str) {
        let e = claim(dir, kind).unwrap_err().to_string();
        assert!(
            e.contains(&dir.display().to_string()) && e.contains(expected),
            "{e}"
        );
    }

    #[test]
    fn a_marker_that_is_no_regular_file_is_refused_without_reading_it() {
        let tmp = tempfile::tempdir().unwrap();
        let fifo = tmp.path().join("fifo");
        std::fs::create_dir(&fifo).unwrap();
        let made = std::process::Command::new("mkfifo")
            .arg(fifo.join(MARKER))
            .status()
            .unwrap();
        assert!(made.success());
        refused(&fifo, Collection::Sweep, "not a regular file");
        let zero = tmp.path().join("zero");
        std::fs::create_dir(&zero).unwrap();
        std::os::unix::fs::symlink("/dev/zero", zero.join(MARKER)).unwrap();
        refused(&zero, Collection::Sweep, "not a regular file");
        let big = tmp.path().join("big");
        std::fs::create_dir(&big).unwrap();
        std::fs::write(big.join(MARKER), vec![b' '; 5000]).unwrap();
        refused(&big, Collection::Sweep, "more than a marker");
    }

    #[test]
    fn a_dangling_marker_link_creates_nothing_outside() {
        let tmp = tempfile::tempdir().unwrap();
        let out = tmp.path().join("out");
        std::fs::create_dir(&out).unwrap();
        std::fs::write(out.join("dataset.json"), "{}").unwrap();
        let target = tmp.path().join("elsewhere");
        std::os::unix::fs::symlink(&target, out.join(MARKER)).unwrap();
        refused(&out, Collection::Dataset, "not a regular file");
        assert!(!target.exists());
    }

    #[test]
    fn a_sweep_marker_does_not_open_a_view_or_a_dataset() {
        let tmp = tempfile::tempdir().unwrap();
        let view = tmp.path().join("view");
        std::fs::create_dir_all(view.join("input")).unwrap();
        std::fs::write(view.join("meta.json"), "{}").unwrap();
        std::fs::write(view.join(MARKER), "sweep\n").unwrap();
        refused(&view, Collection::Sweep, "a view");
        let dataset = tmp.path().join("dataset");
        std::fs::create_dir(&dataset).unwrap();
        std::fs::write(dataset.join("dataset.json"), "{}").unwrap();
        std::fs::write(dataset.join(MARKER), "sweep\n").unwrap();
        refused(&dataset, Collection::Sweep, "holds a dataset");
        std::fs::write(dataset.join(MARKER), "dataset\n").unwrap();
        assert!(claim(&dataset, Collection::Dataset).is_ok());
    }
}
