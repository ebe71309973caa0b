//! One error type for all of `core`: every message names the file it is about,
//! so a user who feeds a bad view learns which file to look at.

use std::path::{Path, PathBuf};

/// Errors of reading, writing and validating data.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The operating system refused a read or write.
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// A file exists but its content is unusable (wrong format, size, channel, value).
    #[error("{}: {message}", path.display())]
    File { path: PathBuf, message: String },
    /// Bad arguments or data not tied to one file.
    #[error("{0}")]
    Invalid(String),
}

impl Error {
    pub fn io(path: &Path, source: std::io::Error) -> Self {
        Error::Io {
            path: path.to_path_buf(),
            source,
        }
    }

    pub fn file(path: &Path, message: impl Into<String>) -> Self {
        Error::File {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }

    pub fn invalid(message: impl Into<String>) -> Self {
        Error::Invalid(message.into())
    }
}

pub type Result<T> = std::result::Result<T, Error>;
