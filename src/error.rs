//! Error type of the library: every failure names the file (or source) and the cause.

use std::path::PathBuf;

/// Everything that can go wrong while loading, validating, baking or reading hair meshes.
#[derive(Debug, thiserror::Error)]
pub enum HairError {
    /// Reading or writing a file failed. The OS message is part of this error's text (not a
    /// separate source), so `{:#}` chains print it once.
    #[error("{}: {error}", path.display())]
    Io {
        /// The file involved.
        path: PathBuf,
        /// The underlying I/O error.
        error: std::io::Error,
    },
    /// The input is malformed or inconsistent; `what` says where (line, face, vertex) and why.
    #[error("{source_name}: {what}")]
    Invalid {
        /// File name or other description of the input.
        source_name: String,
        /// One-line description of the problem, with its location.
        what: String,
    },
}

impl HairError {
    /// Build an [`HairError::Invalid`] for input `source_name`.
    pub fn invalid(source_name: impl Into<String>, what: impl Into<String>) -> Self {
        HairError::Invalid {
            source_name: source_name.into(),
            what: what.into(),
        }
    }

    /// Build an [`HairError::Io`] for `path`.
    pub fn io(path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        HairError::Io {
            path: path.into(),
            error: source,
        }
    }
}

/// Result alias of the library.
pub type Result<T> = std::result::Result<T, HairError>;
