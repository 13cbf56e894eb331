//! [`Problem`]: one finding of scenario validation, and the formatting helpers its messages use.

use serde::Serialize;

/// One problem found in a scenario: the field path, the offending value and what was expected.
///
/// Displays as `field.path: value — expected ...`, e.g.
/// `mission.goal: [300, 10, 5] — expected a point inside world.bounds [0, 0, 0]..[250, 75, 20]`.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Problem {
    /// Dotted path of the field in the scenario file (`obstacles[3].radius_m`,
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

/// Formats a vector as `[x, y, z]` with each number as Rust's shortest round-trip `Display`
/// (`300`, `0.25`, `NaN`, `inf`).
pub(crate) fn fmt_vec(v: &[f64]) -> String {
    let parts: Vec<String> = v.iter().map(|x| format!("{x}")).collect();
    format!("[{}]", parts.join(", "))
}

/// Formats bounds as `[x0, y0, z0]..[x1, y1, z1]`.
pub(crate) fn fmt_bounds(min: &[f64], max: &[f64]) -> String {
    format!("{}..{}", fmt_vec(min), fmt_vec(max))
}

/// Collects problems; the small checks every section uses.
#[derive(Debug, Default)]
pub(crate) struct Problems {
    pub(crate) list: Vec<Problem>,
}

impl Problems {
    pub(crate) fn push(
        &mut self,
        field: impl Into<String>,
        value: impl std::fmt::Display,
        expected: impl Into<String>,
    ) {
        self.list.push(Problem::new(field, value, expected));
    }

    /// `value` must be finite; returns whether it is.
    pub(crate) fn finite(&mut self, field: &str, value: f64) -> bool {
        if value.is_finite() {
            true
        } else {
            self.push(field, value, "a finite number");
            false
        }
    }

    /// Every component finite; returns whether they are.
    pub(crate) fn finite_vec(&mut self, field: &str, v: &[f64]) -> bool {
        if v.iter().all(|x| x.is_finite()) {
            true
        } else {
            self.push(field, fmt_vec(v), "finite numbers");
            false
        }
    }

    /// Finite and `> 0`.
    pub(crate) fn positive(&mut self, field: &str, value: f64) -> bool {
        if value.is_finite() && value > 0.0 {
            true
        } else {
            self.push(field, value, "a finite number > 0");
            false
        }
    }

    /// Finite and `>= 0`.
    pub(crate) fn non_negative(&mut self, field: &str, value: f64) -> bool {
        if value.is_finite() && value >= 0.0 {
            true
        } else {
            self.push(field, value, "a finite number >= 0");
            false
        }
    }

    /// A range `[lo, hi]` with finite ends, `lo <= hi`, and `lo > 0` (`positive`) or `lo >= 0`.
    pub(crate) fn range(&mut self, field: &str, r: [f64; 2], positive: bool) -> bool {
        let ok = r[0].is_finite()
            && r[1].is_finite()
            && r[0] <= r[1]
            && if positive { r[0] > 0.0 } else { r[0] >= 0.0 };
        if !ok {
            self.push(
                field,
                fmt_vec(&r),
                if positive {
                    "[lo, hi] with finite 0 < lo <= hi"
                } else {
                    "[lo, hi] with finite 0 <= lo <= hi"
                },
            );
        }
        ok
    }

    /// A probability in `[0, 1]`.
    pub(crate) fn probability(&mut self, field: &str, value: f64) -> bool {
        if (0.0..=1.0).contains(&value) {
            true
        } else {
            self.push(field, value, "a probability in [0, 1]");
            false
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn displays_field_value_and_expectation() {
        let p = Problem::new(
            "mission.goal",
            fmt_vec(&[300.0, 10.0, 5.0]),
            format!(
                "a point inside world.bounds {}",
                fmt_bounds(&[0.0, 0.0, 0.0], &[250.0, 75.0, 20.0])
            ),
        );
        assert_eq!(
            p.to_string(),
            "mission.goal: [300, 10, 5] — expected a point inside world.bounds [0, 0, 0]..[250, 75, 20]"
        );
        assert_eq!(
            fmt_vec(&[f64::NAN, 0.25, f64::INFINITY]),
            "[NaN, 0.25, inf]"
        );
    }

    #[test]
    fn checks_collect_every_problem() {
        let mut p = Problems::default();
        assert!(!p.positive("a", 0.0));
        assert!(!p.non_negative("b", -1.0));
        assert!(!p.finite("c", f64::NAN));
        assert!(!p.range("d", [2.0, 1.0], false));
        assert!(!p.probability("e", 1.5));
        assert!(p.range("f", [0.0, 1.0], false));
        assert!(!p.range("g", [0.0, 1.0], true));
        assert_eq!(p.list.len(), 6);
    }
}
