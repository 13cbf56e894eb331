//! The one error type of the plotting toolkit.

use std::io;
use std::path::{Path, PathBuf};

/// Why a figure could not be written. Every variant names the file (or the base path
/// `dir/name` when the problem is in the data, before any file exists) and the cause.
///
/// Data problems that only affect single items (a NaN sample, a polyline vertex at infinity) are not
/// errors: those items are skipped and counted in [`Written::skipped_count`](super::Written).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PlotError {
    /// The figure has nothing to draw (after skipping non-finite values).
    #[error("figure {}: nothing to draw: {what}", path.display())]
    NoData {
        /// Base path of the figure (`dir/name`, without extension).
        path: PathBuf,
        /// What was missing.
        what: String,
    },
    /// A parameter that defines the figure (bounds, an explicit axis range, a size) is unusable.
    #[error("figure {}: {field} = {value} is invalid; expected {expected}", path.display())]
    InvalidInput {
        /// Base path of the figure (`dir/name`, without extension).
        path: PathBuf,
        /// The offending field.
        field: String,
        /// Its value, formatted.
        value: String,
        /// What would have been accepted.
        expected: String,
    },
    /// The base name is empty, contains a path separator, or is `.`/`..`.
    #[error(
        "figure base name {name:?} is invalid; expected a plain file name without extension or path separators"
    )]
    InvalidName {
        /// The rejected name.
        name: String,
    },
    /// The output directory exists but is a file.
    #[error("output directory {} exists but is not a directory", path.display())]
    NotADirectory {
        /// The path given as output directory.
        path: PathBuf,
    },
    /// The output directory did not exist and could not be created.
    #[error("cannot create output directory {}: {source}", path.display())]
    CreateDir {
        /// The directory.
        path: PathBuf,
        /// The operating system's reason.
        source: io::Error,
    },
    /// A figure file could not be written.
    #[error("cannot write {}: {source}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// The operating system's reason.
        source: io::Error,
    },
    /// plotters failed while drawing or encoding the file (for PNG this includes failing to save it).
    #[error("drawing {} failed: {message}", path.display())]
    Render {
        /// The file being drawn.
        path: PathBuf,
        /// plotters' message.
        message: String,
    },
    /// The bundled font could not be registered with plotters (a corrupt asset; never expected).
    #[error("the bundled font DejaVu Sans could not be registered with plotters")]
    Font,
}

/// A data problem found before any file is touched; becomes a [`PlotError`] once the path is known.
#[derive(Debug)]
pub(crate) enum InputError {
    NoData(String),
    Invalid {
        field: String,
        value: String,
        expected: &'static str,
    },
}

impl InputError {
    pub(crate) fn invalid(
        field: impl Into<String>,
        value: impl std::fmt::Debug,
        expected: &'static str,
    ) -> Self {
        Self::Invalid {
            field: field.into(),
            value: format!("{value:?}"),
            expected,
        }
    }

    pub(crate) fn at(self, base_path: &Path) -> PlotError {
        match self {
            Self::NoData(what) => PlotError::NoData {
                path: base_path.to_path_buf(),
                what,
            },
            Self::Invalid {
                field,
                value,
                expected,
            } => PlotError::InvalidInput {
                path: base_path.to_path_buf(),
                field,
                value,
                expected: expected.to_string(),
            },
        }
    }
}

/// A plotters failure while drawing, reduced to its message.
#[derive(Debug)]
pub(crate) struct DrawError(pub(crate) String);

impl<E: std::error::Error + Send + Sync> From<plotters::drawing::DrawingAreaErrorKind<E>>
    for DrawError
{
    fn from(e: plotters::drawing::DrawingAreaErrorKind<E>) -> Self {
        Self(e.to_string())
    }
}
