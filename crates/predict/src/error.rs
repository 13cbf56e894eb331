//! The crate's error type and input checks.

use trust_geometry::Vec3;

/// Invalid input to trust-predict. Every message names the offending field, its value and what was
/// expected.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum PredictError {
    /// A number was NaN or infinite.
    #[error("{field} must be finite, got {value}")]
    NonFinite {
        /// Name of the offending field (vector components as `field.x` etc.).
        field: String,
        /// The offending value.
        value: f64,
    },
    /// A number was outside its valid range.
    #[error("{field} = {value} is out of range: expected {expected}")]
    OutOfRange {
        /// Name of the offending field.
        field: String,
        /// The offending value.
        value: f64,
        /// The valid range, in words.
        expected: &'static str,
    },
    /// A time window `[t_start, t_end]` was empty (`t_end < t_start`) or started before the
    /// forecast time.
    #[error("invalid time window [{t_start}, {t_end}]: expected finite t_start <= t_end{hint}")]
    InvalidWindow {
        /// Start of the window (s).
        t_start: f64,
        /// End of the window (s).
        t_end: f64,
        /// Extra explanation (may be empty).
        hint: String,
    },
    /// A filter step went backwards in time.
    #[error("time {t} is before the filter time {filter_t}: expected t >= filter time")]
    TimeWentBackwards {
        /// The requested time (s).
        t: f64,
        /// The filter's current time (s).
        filter_t: f64,
    },
    /// A numerical step failed (only possible with extreme inputs).
    #[error("numerical failure: {what}")]
    Numerical {
        /// What failed.
        what: String,
    },
}

pub(crate) fn check_finite(field: &str, value: f64) -> Result<(), PredictError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(PredictError::NonFinite {
            field: field.to_owned(),
            value,
        })
    }
}

pub(crate) fn check_vec(field: &str, v: &Vec3) -> Result<(), PredictError> {
    for (i, axis) in ["x", "y", "z"].into_iter().enumerate() {
        if !v[i].is_finite() {
            return Err(PredictError::NonFinite {
                field: format!("{field}.{axis}"),
                value: v[i],
            });
        }
    }
    Ok(())
}

pub(crate) fn check_positive(field: &str, value: f64) -> Result<(), PredictError> {
    check_finite(field, value)?;
    if value > 0.0 {
        Ok(())
    } else {
        Err(PredictError::OutOfRange {
            field: field.to_owned(),
            value,
            expected: "a finite number > 0",
        })
    }
}

pub(crate) fn check_non_negative(field: &str, value: f64) -> Result<(), PredictError> {
    check_finite(field, value)?;
    if value >= 0.0 {
        Ok(())
    } else {
        Err(PredictError::OutOfRange {
            field: field.to_owned(),
            value,
            expected: "a finite number >= 0",
        })
    }
}
