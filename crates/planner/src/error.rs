//! The planner crate's error type and the problems its checks report.

use serde::Serialize;
use trust_core::PlanError;

/// One problem with a `[planner]` section: the field path (under `planner.`), the offending value
/// and what was expected. Displays as `field.path: value — expected ...`, like a scenario's
/// problems; numbers this crate writes are plain (`-1`, `0.25`), values the planning crates
/// report keep their `{:?}` form (the scenario checks make both readable).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Problem {
    /// Dotted path of the field in the scenario file (`planner.frontend.budget_ms`).
    pub field: String,
    /// The offending value, formatted.
    pub value: String,
    /// What would have been accepted, in words.
    pub expected: String,
}

impl Problem {
    /// A problem with `field`, `value` (formatted with `Display`) and `expected`.
    pub fn new(
        field: impl Into<String>,
        value: impl std::fmt::Display,
        expected: impl Into<String>,
    ) -> Self {
        Problem {
            field: field.into(),
            value: value.to_string(),
            expected: expected.into(),
        }
    }
}

impl std::fmt::Display for Problem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}: {} — expected {}",
            self.field, self.value, self.expected
        )
    }
}

/// Why a planner could not be assembled.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PlannerError {
    /// A value the assembly needs is invalid (`vehicle.radius_m`, `static_map_error_m`): the
    /// field, its value and what was expected.
    #[error("{0}")]
    Input(Problem),
    /// A part (frontend, backend, checker, manager, route) rejected its parameters, naming the
    /// field.
    #[error(transparent)]
    Plan(#[from] PlanError),
}

impl PlannerError {
    /// Shorthand for [`PlannerError::Input`].
    pub fn input(
        field: impl Into<String>,
        value: impl std::fmt::Display,
        expected: impl Into<String>,
    ) -> Self {
        PlannerError::Input(Problem::new(field, value, expected))
    }
}
