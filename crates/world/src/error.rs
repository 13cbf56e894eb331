//! The world crate's one error type.
//!
//! Every variant names what was wrong and where: the file (for anything read from disk), the field
//! path and the offending value (for invalid input). Planning *failures* are not errors; they are
//! reported by the manager's step reports and the run log.

use std::path::PathBuf;

use crate::problem::Problem;
use trust_vehicle::VehicleError;

/// Why a scenario could not be loaded, a world built, or a simulator component created.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum WorldError {
    /// A file could not be read.
    #[error("cannot read {}: {source}", path.display())]
    Read {
        /// The file.
        path: PathBuf,
        /// The operating system's reason.
        source: std::io::Error,
    },
    /// A path the scenario reads is not a regular file (a folder, a device such as `/dev/zero`,
    /// a pipe): only regular files are read ([`crate::files`]).
    #[error("cannot read {}: not a regular file", path.display())]
    NotAFile {
        /// The path.
        path: PathBuf,
    },
    /// A file is larger than the cap for its kind ([`crate::files`]); nothing beyond
    /// the cap was read.
    #[error("cannot read {}: larger than the cap of {limit} for {what}", path.display())]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// The cap exceeded (`16 MiB`; for one line, `line 7: 67108864 bytes a line`).
        limit: String,
        /// What kind of file (`"a scenario file"`, `"a track file"`, `"a points file"`).
        what: &'static str,
    },
    /// A scenario file is not valid TOML or does not match the scenario format (syntax error,
    /// wrong type, unknown field, unknown name). `message` is toml's own message, with the line,
    /// the column and the offending snippet.
    #[error("{}: {message}", path.display())]
    Parse {
        /// The scenario file (`<string>` when parsed from memory).
        path: PathBuf,
        /// toml's message, including `line N, column M`.
        message: String,
    },
    /// A points file has a line that is not three finite numbers.
    #[error("{}:{line}: {message}", path.display())]
    PointsFile {
        /// The points file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong with the line, quoting it.
        message: String,
    },
    /// A scenario parsed but failed semantic validation; `problems` holds every problem found, not
    /// just the first.
    #[error("{}: {} problem{}:\n{}", path.display(), problems.len(),
        if problems.len() == 1 { "" } else { "s" },
        problems.iter().map(|p| format!("  - {p}")).collect::<Vec<_>>().join("\n"))]
    Invalid {
        /// The scenario file (`<string>` when parsed from memory).
        path: PathBuf,
        /// Every problem, in the order the checks ran (file order, roughly).
        problems: Vec<Problem>,
    },
    /// One invalid input to a simulator component (a field path, its value and what was expected).
    #[error("{0}")]
    Input(Problem),
    /// Invalid input reported by a planning crate (shapes, forecasts, parameters).
    #[error(transparent)]
    Plan(#[from] trust_core::PlanError),
    /// Invalid geometry (a map or an ESDF that could not be built).
    #[error(transparent)]
    Geometry(#[from] trust_geometry::GeometryError),
    /// Invalid input to the obstacle tracker.
    #[error(transparent)]
    Predict(#[from] trust_predict::PredictError),
    /// Invalid input to a vehicle model or controller.
    #[error(transparent)]
    Vehicle(#[from] VehicleError),
}

/// `4 MiB` for whole mebibytes, else bytes.
pub(crate) fn fmt_bytes(n: u64) -> String {
    if n >= 1 << 20 && n.is_multiple_of(1 << 20) {
        format!("{} MiB", n >> 20)
    } else {
        format!("{n} bytes")
    }
}

/// The errors of the one line reader, [`trust_runlog::files::BoundedLines`] (a track or points
/// file read line by line), as the world's: a line that is not UTF-8 is a
/// [`WorldError::PointsFile`] naming it (docs/decisions/0041-one-line-reader.md).
impl From<trust_runlog::LogError> for WorldError {
    fn from(e: trust_runlog::LogError) -> Self {
        use trust_runlog::LogError;
        match e {
            LogError::Io { path, source } => WorldError::Read { path, source },
            LogError::NotAFile { path, .. } => WorldError::NotAFile { path },
            LogError::TooLarge { path, what, limit } => WorldError::TooLarge { path, limit, what },
            LogError::Parse {
                path,
                line,
                message,
            } => WorldError::PointsFile {
                path,
                line,
                message,
            },
            other => WorldError::Read {
                path: PathBuf::new(),
                source: std::io::Error::other(other.to_string()),
            },
        }
    }
}

impl WorldError {
    /// `value` if `problems` is empty, else [`WorldError::Invalid`] with them for the file at
    /// `path`.
    pub fn unless_problems<T>(
        value: T,
        path: &std::path::Path,
        problems: Vec<Problem>,
    ) -> Result<T, WorldError> {
        if problems.is_empty() {
            Ok(value)
        } else {
            Err(WorldError::Invalid {
                path: path.to_path_buf(),
                problems,
            })
        }
    }

    /// Shorthand for [`WorldError::Input`].
    pub fn input(
        field: impl Into<String>,
        value: impl std::fmt::Display,
        expected: impl Into<String>,
    ) -> Self {
        WorldError::Input(Problem::new(field, value, expected))
    }

    /// The validation problems, if this is [`WorldError::Invalid`] (or [`WorldError::Input`], as one
    /// problem); empty otherwise.
    pub fn problems(&self) -> Vec<Problem> {
        match self {
            WorldError::Invalid { problems, .. } => problems.clone(),
            WorldError::Input(p) => vec![p.clone()],
            _ => Vec::new(),
        }
    }
}
