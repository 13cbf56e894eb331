//! The scale policy: which magnitudes the public entry points of every TRUST-Planner crate accept.
//!
//! A drone planner works in metres and seconds over a city at most. Accepting any finite `f64`
//! instead lets a caller pass `1e300` and get `inf` or NaN out of a product, an infinite loop
//! count, or an assertion deep inside a collision library. So every public constructor and
//! validator checks its inputs against the limits below, and every internal computation on
//! accepted inputs provably stays finite (the largest intermediate products are far below
//! `f64::MAX ≈ 1.8e308`).
//!
//! | quantity | accepted | constant |
//! |---|---|---|
//! | position component (m) | `|x| ≤ 1e6` | [`MAX_COORD_M`] |
//! | length, size, radius, clearance, margin, resolution (m) | `0 ≤ s ≤ 1e6` | [`MAX_LENGTH_M`] |
//! | speed component or speed limit, growth rate `mu` (m/s) | `|v| ≤ 1e4` | [`MAX_SPEED_M_S`] |
//! | acceleration component or limit (m/s²) | `|a| ≤ 1e5` | [`MAX_ACCEL_M_S2`] |
//! | absolute time, duration, horizon, time step (s) | `|t| ≤ 1e7` | [`MAX_TIME_S`] |
//! | smallest strictly positive limit, duration, step or resolution | `≥ 1e-9` | [`MIN_POSITIVE`] |
//! | samples or points a call generates (trajectory samples, resampled points) | `≤ 1e6` | [`MAX_SAMPLE_COUNT`] |
//! | samples that each need an iterative solve (cone surface samples) | `≤ 1e5` | [`MAX_SOLVED_SAMPLE_COUNT`] |
//! | vertices of a path, pieces of a trajectory | `≤ 1e5` | [`MAX_VERTEX_COUNT`] |
//!
//! Derived bounds (why nothing overflows): a forecast centre `p0 + v0·(t − t0)` stays below
//! `1e6 + 1e4 · 2e7 = 2e11` m, its radius the same; squares of such numbers (`4e22`) and sums of a
//! million of them stay finite. Trajectory coefficients are bounded so that every derivative over a
//! piece stays finite (see `trust_core::PolyTraj`).
//!
//! Out-of-range input is a [`ScaleError`] naming the field, the value (in readable scientific
//! notation, [`Sci`]) and the accepted range. Query methods that return a plain number or boolean
//! (distances, line of sight) answer conservatively for points outside the policy: distances are
//! still computed where they are finite, and line-of-sight tests report "not clear".

use std::fmt;

use crate::Vec3;

/// Largest accepted absolute value of a position component (m).
pub const MAX_COORD_M: f64 = 1.0e6;
/// Largest accepted length, size, radius, clearance, margin or resolution (m).
pub const MAX_LENGTH_M: f64 = 1.0e6;
/// Largest accepted absolute value of a velocity component, speed limit or growth rate (m/s).
pub const MAX_SPEED_M_S: f64 = 1.0e4;
/// Largest accepted absolute value of an acceleration component or limit (m/s²).
pub const MAX_ACCEL_M_S2: f64 = 1.0e5;
/// Largest accepted absolute time, duration, horizon or time step (s).
pub const MAX_TIME_S: f64 = 1.0e7;
/// Smallest accepted value of a quantity that must be strictly positive (a limit, a duration, a
/// time step, a resolution): below it, quotients by it overflow the other limits.
pub const MIN_POSITIVE: f64 = 1.0e-9;
/// Largest number of samples or points one call may generate.
pub const MAX_SAMPLE_COUNT: usize = 1_000_000;
/// Largest number of samples one call may generate when each needs an iterative solve (the
/// surface samples of a predictive directional cone).
pub const MAX_SOLVED_SAMPLE_COUNT: usize = 100_000;
/// Largest number of vertices of a path or pieces of a trajectory.
pub const MAX_VERTEX_COUNT: usize = 100_000;

/// Largest coordinate magnitude at which the free distance functions (`sphere_sdf`, `box_sdf`,
/// cone distances, ...) still answer: far beyond the policy, but small enough that squared
/// distances stay finite. Beyond it (or for a non-finite point) they return `(-inf, 0)`: "not free",
/// the convention of [`crate::StaticMap::distance_and_gradient`] for non-finite queries.
pub const QUERY_LIMIT: f64 = 1.0e100;

/// True if every argument is finite with magnitude at most [`QUERY_LIMIT`].
#[inline]
pub fn queryable(values: &[f64]) -> bool {
    values.iter().all(|v| v.abs() <= QUERY_LIMIT)
}

/// The kind of a checked number, which fixes its accepted range.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// A position component: `|x| ≤ MAX_COORD_M`.
    Position,
    /// A non-negative length: `0 ≤ s ≤ MAX_LENGTH_M`.
    Length,
    /// A strictly positive length: `MIN_POSITIVE ≤ s ≤ MAX_LENGTH_M`.
    PositiveLength,
    /// A velocity component: `|v| ≤ MAX_SPEED_M_S`.
    Velocity,
    /// A non-negative rate (m/s), e.g. an uncertainty growth rate: `0 ≤ v ≤ MAX_SPEED_M_S`.
    Rate,
    /// A strictly positive speed limit: `MIN_POSITIVE ≤ v ≤ MAX_SPEED_M_S`.
    PositiveSpeed,
    /// An acceleration component: `|a| ≤ MAX_ACCEL_M_S2`.
    Acceleration,
    /// A strictly positive acceleration limit: `MIN_POSITIVE ≤ a ≤ MAX_ACCEL_M_S2`.
    PositiveAcceleration,
    /// An absolute time: `|t| ≤ MAX_TIME_S`.
    Time,
    /// A non-negative duration: `0 ≤ d ≤ MAX_TIME_S`.
    Duration,
    /// A strictly positive duration or time step: `MIN_POSITIVE ≤ d ≤ MAX_TIME_S`.
    PositiveDuration,
}

impl Quantity {
    /// The accepted closed range `[lo, hi]`.
    pub fn range(self) -> (f64, f64) {
        match self {
            Quantity::Position => (-MAX_COORD_M, MAX_COORD_M),
            Quantity::Length => (0.0, MAX_LENGTH_M),
            Quantity::PositiveLength => (MIN_POSITIVE, MAX_LENGTH_M),
            Quantity::Velocity => (-MAX_SPEED_M_S, MAX_SPEED_M_S),
            Quantity::Rate => (0.0, MAX_SPEED_M_S),
            Quantity::PositiveSpeed => (MIN_POSITIVE, MAX_SPEED_M_S),
            Quantity::Acceleration => (-MAX_ACCEL_M_S2, MAX_ACCEL_M_S2),
            Quantity::PositiveAcceleration => (MIN_POSITIVE, MAX_ACCEL_M_S2),
            Quantity::Time => (-MAX_TIME_S, MAX_TIME_S),
            Quantity::Duration => (0.0, MAX_TIME_S),
            Quantity::PositiveDuration => (MIN_POSITIVE, MAX_TIME_S),
        }
    }

    /// The unit, for messages.
    pub fn unit(self) -> &'static str {
        match self {
            Quantity::Position | Quantity::Length | Quantity::PositiveLength => "m",
            Quantity::Velocity | Quantity::Rate | Quantity::PositiveSpeed => "m/s",
            Quantity::Acceleration | Quantity::PositiveAcceleration => "m/s²",
            Quantity::Time | Quantity::Duration | Quantity::PositiveDuration => "s",
        }
    }

    /// True if `value` lies in [`Quantity::range`] (false for NaN).
    pub fn accepts(self, value: f64) -> bool {
        let (lo, hi) = self.range();
        value >= lo && value <= hi
    }
}

/// A number for messages: plain decimal for ordinary magnitudes, scientific notation with at least
/// one decimal (`1.0e300`, `-2.5e-12`) for very large or very small ones, never 300 digits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sci(pub f64);

impl fmt::Display for Sci {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let v = self.0;
        let a = v.abs();
        if !v.is_finite() || v == 0.0 || (1.0e-6..1.0e6).contains(&a) {
            return write!(f, "{v}");
        }
        let s = format!("{v:e}");
        match s.split_once('e') {
            Some((mantissa, exp)) if !mantissa.contains('.') => write!(f, "{mantissa}.0e{exp}"),
            _ => f.write_str(&s),
        }
    }
}

/// A count for messages: exact up to 10⁹, scientific notation above (`3.2e31`, never 31 digits).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SciCount(pub u128);

impl fmt::Display for SciCount {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.0 <= 1_000_000_000 {
            write!(f, "{}", self.0)
        } else {
            // Rounded to the f64 nearest the count: these counts are far above any cap.
            write!(f, "{}", Sci(self.0 as f64))
        }
    }
}

/// A number outside the scale policy (see the [module documentation](self)).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("`{field}` = {value} is outside the accepted range [{lo}, {hi}] {unit} (scale policy, trust_geometry::scale)", value = Sci(*.value), lo = Sci(*.lo), hi = Sci(*.hi))]
pub struct ScaleError {
    /// Name of the field (vector components as `field.x` etc.).
    pub field: String,
    /// The offending value (may be NaN or infinite).
    pub value: f64,
    /// Lower end of the accepted range.
    pub lo: f64,
    /// Upper end of the accepted range.
    pub hi: f64,
    /// The unit of the range.
    pub unit: &'static str,
}

/// A count (of samples, points, pieces, ...) above its cap.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("`{field}` = {} exceeds the cap of {} (scale policy, trust_geometry::scale)", SciCount(*.count), SciCount(*.cap as u128))]
pub struct CountError {
    /// Name of the count.
    pub field: String,
    /// The requested count (saturated at `u128::MAX`).
    pub count: u128,
    /// The cap.
    pub cap: usize,
}

/// Checks `value` against the range of `quantity`.
///
/// # Errors
/// A [`ScaleError`] naming `field` if `value` is NaN, infinite or outside the range.
pub fn check(field: &str, value: f64, quantity: Quantity) -> Result<f64, ScaleError> {
    if quantity.accepts(value) {
        Ok(value)
    } else {
        let (lo, hi) = quantity.range();
        Err(ScaleError {
            field: field.to_owned(),
            value,
            lo,
            hi,
            unit: quantity.unit(),
        })
    }
}

/// Checks `value` against an explicit closed range `[lo, hi]` in `unit`, for parameters whose unit
/// is none of [`Quantity`]'s (a noise density in m²/s³, a dimensionless factor): the error has the
/// same form as [`check`]'s.
///
/// # Errors
/// A [`ScaleError`] naming `field` if `value` is NaN, infinite or outside `[lo, hi]`.
pub fn check_range(
    field: &str,
    value: f64,
    lo: f64,
    hi: f64,
    unit: &'static str,
) -> Result<f64, ScaleError> {
    if value >= lo && value <= hi {
        Ok(value)
    } else {
        Err(ScaleError {
            field: field.to_owned(),
            value,
            lo,
            hi,
            unit,
        })
    }
}

/// Checks every component of `v` against the range of `quantity`; the field name gets
/// `.x`/`.y`/`.z` appended.
///
/// # Errors
/// A [`ScaleError`] naming the first offending component.
pub fn check_vec(field: &str, v: &Vec3, quantity: Quantity) -> Result<(), ScaleError> {
    for (i, axis) in ['x', 'y', 'z'].into_iter().enumerate() {
        if !quantity.accepts(v[i]) {
            check(&format!("{field}.{axis}"), v[i], quantity)?;
        }
    }
    Ok(())
}

/// Checks that `count ≤ cap`.
///
/// # Errors
/// A [`CountError`] naming `field` otherwise.
pub fn check_count(field: &str, count: u128, cap: usize) -> Result<usize, CountError> {
    if count <= cap as u128 {
        // `count ≤ cap` fits in usize.
        Ok(count as usize)
    } else {
        Err(CountError {
            field: field.to_owned(),
            count,
            cap,
        })
    }
}

/// True if every component of `p` is a position inside the policy (`|x| ≤ MAX_COORD_M`).
pub fn position_in_scale(p: &Vec3) -> bool {
    p.iter().all(|&c| Quantity::Position.accepts(c))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sci_is_readable() {
        assert_eq!(Sci(1e300).to_string(), "1.0e300");
        assert_eq!(Sci(-2.5e-12).to_string(), "-2.5e-12");
        assert_eq!(Sci(1.5).to_string(), "1.5");
        assert_eq!(Sci(0.0).to_string(), "0");
        assert_eq!(Sci(f64::NAN).to_string(), "NaN");
        assert_eq!(Sci(f64::MAX).to_string(), "1.7976931348623157e308");
        assert_eq!(SciCount(1_000_000_000).to_string(), "1000000000");
        assert_eq!(SciCount(10u128.pow(31)).to_string(), "1.0e31");
        assert_eq!(SciCount(u128::MAX).to_string(), "3.402823669209385e38");
    }

    #[test]
    fn count_errors_have_no_31_digit_integers() {
        // Issue 18: a UVD point count of 1e30 was printed as a 31-digit integer.
        let e = check_count("uvd matched points", 10u128.pow(30), MAX_SAMPLE_COUNT).unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains("1.0e30"), "{msg}");
        assert!(!msg.contains("1000000000000"), "{msg}");
    }

    #[test]
    fn errors_name_field_value_and_range() {
        let e = check("sphere.radius", 1e300, Quantity::Length).unwrap_err();
        let msg = e.to_string();
        assert!(msg.contains("sphere.radius"), "{msg}");
        assert!(msg.contains("1.0e300"), "{msg}");
        assert!(msg.contains("[0, 1.0e6] m"), "{msg}");
        assert!(check("t", f64::NAN, Quantity::Time).is_err());
        assert!(check("t", -1e7, Quantity::Time).is_ok());
        assert!(check("dt", 1e-12, Quantity::PositiveDuration).is_err());
        let e = check_vec("p", &Vec3::new(0.0, 0.0, -1e7), Quantity::Position).unwrap_err();
        assert_eq!(e.field, "p.z");
        assert!(check_count("n", 10, 10).is_ok());
        assert!(check_count("n", 11, 10).is_err());
    }
}
