//! [`Problem`]: one finding of an input check that names the field, the value and what was
//! expected (a scenario's validation, a planner section's checks).

use serde::Serialize;

/// One problem found in an input file: the field path, the offending value and what was
/// expected.
///
/// Displays as `field.path: value — expected ...`, e.g.
/// `mission.goal: [300, 10, 5] — expected a point inside world.bounds [0, 0, 0]..[250, 75, 20]`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Problem {
    /// Dotted path of the field in the file (`obstacles[3].radius_m`,
    /// `planner.frontend.budget_ms`, `world.generator`).
    pub field: String,
    /// The offending value, formatted (numbers as in the file; vectors as `[x, y, z]`).
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_problem_names_the_field_the_value_and_what_was_expected() {
        let p = Problem::new("planner.frontend.budget_ms", -1, "a finite number > 0");
        assert_eq!(
            p.to_string(),
            "planner.frontend.budget_ms: -1 — expected a finite number > 0"
        );
    }
}
