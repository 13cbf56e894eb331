//! The one error type of the replay.

use std::path::PathBuf;

/// Why a replay could not be made or checked. Every variant names the file involved.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReplayError {
    /// The run log cannot be read, or is not a run log (the message has the file and line).
    #[error(transparent)]
    Log(#[from] trust_runlog::LogError),
    /// The log's static points file cannot be read.
    #[error("static points of the log: {message}")]
    Points {
        /// The reader's message (file and line).
        message: String,
    },
    /// A parameter is unusable.
    #[error("replay parameter {field} = {value} is invalid; expected {expected}")]
    InvalidParam {
        /// The parameter.
        field: &'static str,
        /// Its value.
        value: String,
        /// What would be accepted.
        expected: &'static str,
    },
    /// An output file or folder cannot be written.
    #[error("cannot write {}: {source}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// The GIF could not be drawn.
    #[error(transparent)]
    Plot(#[from] trust_plot::PlotError),
    /// The headless browser could not be run, or the page failed its check in it.
    #[error("browser check of {}: {message}", page.display())]
    Browser {
        /// The page.
        page: PathBuf,
        /// What went wrong.
        message: String,
    },
}
