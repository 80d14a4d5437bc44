//! [`FileError`]: a file or folder that could not be read or written, named. Every stage that
//! touches files reports this one error as its `Io` variant.

use thiserror::Error;

/// A file or folder that could not be read or written: its path and the I/O error.
#[derive(Debug, Error)]
#[error("{path}: {source}")]
pub struct FileError {
    /// The file or folder concerned.
    pub path: String,
    /// The underlying error.
    #[source]
    pub source: std::io::Error,
}
