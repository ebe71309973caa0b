//! The scene file as the parts of a scene see it: an error names the file
//! and the key it is about, and a file the scene names (mesh, texture,
//! environment map) is found relative to the scene file, or as `@name` in the
//! `SFP_MESH_DIR` directory or among the shipped meshes.

use crate::shipped_meshes;
use sfp_core::{Error, Result};
use std::path::{Path, PathBuf};

/// Environment variable naming the directory of `@name` mesh references.
pub const MESH_DIR_VAR: &str = "SFP_MESH_DIR";

/// One table of a scene file (`light[0]`, `object[2].material`): what a
/// scene kind validates and builds from.
#[derive(Clone, Debug)]
pub struct Table<'a> {
    source: &'a Path,
    key: String,
}

impl<'a> Table<'a> {
    /// The table `key` of the scene file `source`.
    pub fn new(source: &'a Path, key: impl Into<String>) -> Table<'a> {
        Table {
            source,
            key: key.into(),
        }
    }

    /// An error about `field` of this table: `` `key.field`: message ``.
    pub fn err(&self, field: &str, message: impl std::fmt::Display) -> Error {
        Error::file(self.source, format!("`{}.{field}`: {message}", self.key))
    }

    /// A file named in this table, resolved as [`resolve`] does.
    pub fn path(&self, file: &str) -> Result<PathBuf> {
        resolve(self.source, file)
    }
}

/// Resolves a file entry of the scene file `source`: relative to it, or
/// `@name` in `SFP_MESH_DIR` when that folder holds it, else the shipped
/// file of that name. Existence is checked on load.
pub fn resolve(source: &Path, file: &str) -> Result<PathBuf> {
    let Some(name) = file.strip_prefix('@') else {
        return Ok(source.parent().unwrap_or(Path::new(".")).join(file));
    };
    let in_dir = std::env::var_os(MESH_DIR_VAR).map(|dir| PathBuf::from(dir).join(name));
    match (in_dir, shipped_meshes::path(name)) {
        (Some(p), Some(shipped)) if !p.exists() => Ok(shipped),
        (Some(p), _) => Ok(p),
        (None, Some(shipped)) => Ok(shipped),
        (None, None) => Err(Error::file(
            source,
            format!(
                "`{file}` is not one of the shipped meshes (scenes/meshes.md); other `@` \
                 references are looked up in the folder the {MESH_DIR_VAR} environment \
                 variable names, which is not set"
            ),
        )),
    }
}

/// Whether `path` (as [`resolve`] gives it) is a file: a shipped one or one
/// on disk.
pub fn is_file(path: &Path) -> bool {
    shipped_meshes::bytes(path).is_some() || path.is_file()
}

/// The content of the file at `path` (as [`resolve`] gives it).
pub fn read(path: &Path) -> Result<Vec<u8>> {
    match shipped_meshes::bytes(path) {
        Some(bytes) => Ok(bytes.to_vec()),
        None => std::fs::read(path).map_err(|e| Error::read(path, e)),
    }
}
