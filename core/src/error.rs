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
    /// Not enough memory (or address space) for the work: the system's
    /// limit, not the input's fault; the message says what was needed.
    #[error("{0}")]
    Memory(String),
}

impl Error {
    pub fn io(path: &Path, source: std::io::Error) -> Self {
        Error::Io {
            path: path.to_path_buf(),
            source,
        }
    }

    /// A failed read of an input: a path that does not exist or is of the
    /// wrong type is the user's mistake ([`Error::File`], exit code 2), any
    /// other failure the system's ([`Error::Io`], worth a retry).
    pub fn read(path: &Path, source: std::io::Error) -> Self {
        use std::io::ErrorKind::{InvalidFilename, IsADirectory, NotADirectory, NotFound};
        match source.kind() {
            NotFound => Error::file(path, "does not exist"),
            IsADirectory => Error::file(path, "is a folder, not a file"),
            NotADirectory => {
                Error::file(path, "is not a folder (or a folder on its path is a file)")
            }
            InvalidFilename => Error::file(path, "is not a valid file name"),
            _ => Error::io(path, source),
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

    pub fn memory(message: impl Into<String>) -> Self {
        Error::Memory(message.into())
    }
}

pub type Result<T> = std::result::Result<T, Error>;
