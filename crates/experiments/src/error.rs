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

/// Checks a study's planner list (named `option` in the errors): one or more presets, each at
/// most once.
pub(crate) fn check_planner_list(
    option: &str,
    planners: &[trust_planner::PlannerPreset],
) -> Result<(), ExperimentError> {
    if planners.is_empty() {
        return Err(ExperimentError::input(
            option,
            "(empty)",
            "one or more of trust, baseline1, baseline2, baseline3",
        ));
    }
    for (i, p) in planners.iter().enumerate() {
        if planners[..i].contains(p) {
            return Err(ExperimentError::input(
                option,
                p.name(),
                "each planner at most once",
            ));
        }
    }
    Ok(())
}

/// Checks a `--time-limit` replacing the scenario's: a positive, finite number of seconds.
pub(crate) fn check_time_limit(time_limit_s: Option<f64>) -> Result<(), ExperimentError> {
    match time_limit_s {
        Some(t) if !(t.is_finite() && t > 0.0) => Err(ExperimentError::input(
            "--time-limit",
            t,
            "a positive number of seconds",
        )),
        _ => Ok(()),
    }
}
