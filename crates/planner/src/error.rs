//! The planner crate's error type and the problems its checks report.

use trust_core::PlanError;

pub use trust_core::Problem;

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
