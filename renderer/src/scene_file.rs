//! The scene file as the parts of a scene see it: an error names the file
//! and the key it is about, and a file the scene names (mesh, texture,
//! environment map) is found relative to the scene file, or as `@name` in the
//! `SFP_MESH_DIR` directory.

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
/// `@name` in `SFP_MESH_DIR`. Existence is checked on load.
pub fn resolve(source: &Path, file: &str) -> Result<PathBuf> {
    match file.strip_prefix('@') {
        Some(name) => {
            let dir = std::env::var_os(MESH_DIR_VAR).ok_or_else(|| {
                Error::file(
                    source,
                    format!(
                        "`{file}`: `@` references need the {MESH_DIR_VAR} environment variable"
                    ),
                )
            })?;
            Ok(PathBuf::from(dir).join(name))
        }
        None => Ok(source.parent().unwrap_or(Path::new(".")).join(file)),
    }
}
