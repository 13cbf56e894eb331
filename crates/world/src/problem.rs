//! [`Problem`]: one finding of scenario validation, and the formatting helpers its messages use.

pub use trust_core::Problem;

/// Formats a number for a message, readably, with at most 6 significant digits: for a magnitude
/// in `[1e-4, 1e6)` Rust's shortest round-trip form (`300`, `0.25`, `NaN`, `inf`), rounded to 6
/// significant digits when it has more (`123457`, `0.3`); otherwise scientific notation rounded
/// the same way (`1e308`, `1.23457e6`, `2e-6`), so that `1e308` never prints as 309 digits.
/// Every number in a [`Problem`] goes through it.
pub fn fmt_num(x: f64) -> String {
    let plain = format!("{x}");
    let a = x.abs();
    if !x.is_finite() || x == 0.0 {
        return plain;
    }
    let digits = plain
        .trim_start_matches('-')
        .replace('.', "")
        .trim_start_matches('0')
        .trim_end_matches('0')
        .len();
    if (1e-4..1e6).contains(&a) {
        if digits <= 6 {
            return plain;
        }
        // 6 significant digits in fixed notation, trailing zeros dropped.
        let decimals = (5 - a.log10().floor() as i32).max(0) as usize;
        let fixed = format!("{x:.decimals$}");
        return if fixed.contains('.') {
            fixed
                .trim_end_matches('0')
                .trim_end_matches('.')
                .to_string()
        } else {
            fixed
        };
    }
    let sci = format!("{x:.5e}");
    match sci.split_once('e') {
        Some((mantissa, exp)) => {
            let mantissa = if mantissa.contains('.') {
                mantissa.trim_end_matches('0').trim_end_matches('.')
            } else {
                mantissa
            };
            format!("{mantissa}e{exp}")
        }
        None => sci,
    }
}

/// A value another crate formatted (`{:?}` of an `f64` or a vector of them:
/// `-1.7976931348623157e308`, `[0.30000000000000004, 2.0]`) with every number of more than 6
/// significant digits or 12 characters written by [`fmt_num`]; other text (and `-5.0`) is kept.
pub fn readable_value(value: &str) -> String {
    let mut out = String::with_capacity(value.len());
    let mut word = String::new();
    let flush = |word: &mut String, out: &mut String| {
        let mantissa = word.split(['e', 'E']).next().unwrap_or("");
        let significant = mantissa
            .chars()
            .filter(char::is_ascii_digit)
            .collect::<String>()
            .trim_matches('0')
            .len();
        match word.parse::<f64>() {
            Ok(x) if significant > 6 || (word.len() > 12 && significant > 0) => {
                out.push_str(&fmt_num(x));
            }
            _ => out.push_str(word),
        }
        word.clear();
    };
    for c in value.chars() {
        if c.is_whitespace() || matches!(c, ',' | '[' | ']' | '(' | ')' | '{' | '}' | ';' | ':') {
            flush(&mut word, &mut out);
            out.push(c);
        } else {
            word.push(c);
        }
    }
    flush(&mut word, &mut out);
    out
}

/// A count for a message: exact up to 10⁹, else scientific ([`fmt_num`]).
pub fn fmt_count(n: u128) -> String {
    if n <= 1_000_000_000 {
        n.to_string()
    } else {
        fmt_num(n as f64)
    }
}

/// Formats a vector as `[x, y, z]`, each number by [`fmt_num`].
pub(crate) fn fmt_vec(v: &[f64]) -> String {
    let parts: Vec<String> = v.iter().map(|x| fmt_num(*x)).collect();
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
            self.push(field, fmt_num(value), "a finite number");
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
            self.push(field, fmt_num(value), "a finite number > 0");
            false
        }
    }

    /// Finite and `>= 0`.
    pub(crate) fn non_negative(&mut self, field: &str, value: f64) -> bool {
        if value.is_finite() && value >= 0.0 {
            true
        } else {
            self.push(field, fmt_num(value), "a finite number >= 0");
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

    /// A finite `value` with `|value| <= max` (the scenario scale policy,
    /// [`crate::scenario::scale`]); non-finite values are left to the other checks. Returns
    /// whether it passes.
    pub(crate) fn within(&mut self, field: &str, value: f64, max: f64, unit: &str) -> bool {
        if value.is_finite() && value.abs() > max {
            self.push(
                field,
                fmt_num(value),
                format!(
                    "a magnitude of at most {} {unit} (scale policy)",
                    fmt_num(max)
                ),
            );
            false
        } else {
            true
        }
    }

    /// [`Problems::within`] for every component of a vector (one problem for the vector).
    pub(crate) fn within_vec(&mut self, field: &str, v: &[f64], max: f64, unit: &str) -> bool {
        if v.iter().any(|x| x.is_finite() && x.abs() > max) {
            self.push(
                field,
                fmt_vec(v),
                format!(
                    "components of magnitude at most {} {unit} (scale policy)",
                    fmt_num(max)
                ),
            );
            false
        } else {
            true
        }
    }

    /// A finite `value` in `[lo, hi]`; non-finite values are left to the other checks.
    pub(crate) fn in_range(
        &mut self,
        field: &str,
        value: f64,
        lo: f64,
        hi: f64,
        unit: &str,
    ) -> bool {
        if value.is_finite() && !(lo..=hi).contains(&value) {
            self.push(
                field,
                fmt_num(value),
                format!(
                    "a value in [{}, {}] {unit} (scale policy)",
                    fmt_num(lo),
                    fmt_num(hi)
                ),
            );
            false
        } else {
            true
        }
    }

    /// A count at most `cap`, checked before anything is allocated or drawn for it.
    pub(crate) fn count(&mut self, field: &str, count: u128, cap: usize, what: &str) -> bool {
        if count > cap as u128 {
            self.push(
                field,
                fmt_count(count),
                format!("at most {} {what} (scale policy)", fmt_count(cap as u128)),
            );
            false
        } else {
            true
        }
    }

    /// A probability in `[0, 1]`.
    pub(crate) fn probability(&mut self, field: &str, value: f64) -> bool {
        if (0.0..=1.0).contains(&value) {
            true
        } else {
            self.push(field, fmt_num(value), "a probability in [0, 1]");
            false
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_from_other_crates_are_made_readable() {
        assert_eq!(readable_value("-1.7976931348623157e308"), "-1.79769e308");
        assert_eq!(
            readable_value("[0.30000000000000004, 2.0, NaN]"),
            "[0.3, 2.0, NaN]"
        );
        assert_eq!(readable_value("15000000000000.0"), "1.5e13");
        assert_eq!(readable_value("-5.0"), "-5.0");
        assert_eq!(readable_value("Some(1e-300)"), "Some(1e-300)");
        assert_eq!(readable_value("\"dev-prm\""), "\"dev-prm\"");
    }

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
    fn numbers_print_readably() {
        for (x, text) in [
            (300.0, "300"),
            (0.25, "0.25"),
            (-12.5, "-12.5"),
            (0.002, "0.002"),
            (123456.0, "123456"),
            (1e308, "1e308"),
            (-1e7, "-1e7"),
            (1e6, "1e6"),
            (1e-6, "1e-6"),
            (1234567.0, "1.23457e6"),
            (0.1 + 0.2, "0.3"),
            (123456.7, "123457"),
            (1.2345678, "1.23457"),
            (f64::MAX, "1.79769e308"),
        ] {
            assert_eq!(fmt_num(x), text, "{x:?}");
        }
        assert_eq!(fmt_count(9_223_372_036_854_775_807), "9.22337e18");
        assert_eq!(fmt_count(1000), "1000");
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
