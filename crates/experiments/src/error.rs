//! The experiments crate's one error type.

use std::path::PathBuf;

use trust_world::scenario::Problem;

/// Why a study or an experiment could not run or its outputs not be written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ExperimentError {
    /// One invalid input (a field path, its value and what was expected).
    #[error("{0}")]
    Input(Problem),
    /// The scenario, the world or the planner could not be set up.
    #[error(transparent)]
    World(#[from] trust_world::WorldError),
    /// A flight could not be set up or its log not written.
    #[error(transparent)]
    Flight(#[from] trust_flight::FlightError),
    /// Invalid input reported by a planning crate.
    #[error(transparent)]
    Plan(#[from] trust_core::PlanError),
    /// A figure could not be written.
    #[error(transparent)]
    Plot(#[from] trust_plot::PlotError),
    /// A run log could not be read.
    #[error(transparent)]
    Log(#[from] trust_runlog::LogError),
    /// An experiment's example printed JSON that does not match its type (the message names the
    /// missing, unknown or mistyped field).
    #[error("example {example} printed JSON that does not match its type: {source}")]
    ExampleOutput {
        /// The example's name.
        example: &'static str,
        /// serde_json's reason, naming the field.
        source: serde_json::Error,
    },
    /// A file could not be read or written.
    #[error("cannot write {}: {source}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// The operating system's reason.
        source: std::io::Error,
    },
}

impl ExperimentError {
    /// Shorthand for [`ExperimentError::Input`].
    pub fn input(
        field: impl Into<String>,
        value: impl std::fmt::Display,
        expected: impl Into<String>,
    ) -> Self {
        ExperimentError::Input(Problem::new(field, value, expected))
    }
}
