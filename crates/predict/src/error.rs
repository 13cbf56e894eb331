//! The crate's error type and input checks.

use trust_geometry::Vec3;
use trust_geometry::scale::{self, CountError, Quantity, ScaleError, Sci};

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
    #[error("{field} = {} is out of range: expected {expected}", Sci(*.value))]
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
    #[error(
        "invalid time window [{}, {}]: expected finite t_start <= t_end{hint}",
        Sci(*.t_start),
        Sci(*.t_end)
    )]
    InvalidWindow {
        /// Start of the window (s).
        t_start: f64,
        /// End of the window (s).
        t_end: f64,
        /// Extra explanation (may be empty).
        hint: String,
    },
    /// A filter step went backwards in time.
    #[error(
        "time {} is before the filter time {}: expected t >= filter time",
        Sci(*.t),
        Sci(*.filter_t)
    )]
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
    /// A number outside the scale policy (`trust_geometry::scale`).
    #[error(transparent)]
    Scale(#[from] ScaleError),
    /// A count above its cap (`trust_geometry::scale`).
    #[error(transparent)]
    Count(#[from] CountError),
    /// A quantity computed from valid inputs left the scale policy; `cause` names the inputs that
    /// drove it.
    #[error("{what} = {} exceeds {}: {cause}", Sci(*.value), Sci(*.limit))]
    Derived {
        /// The computed quantity.
        what: String,
        /// Its value.
        value: f64,
        /// The limit it exceeded.
        limit: f64,
        /// Which inputs drove it, and what to change.
        cause: String,
    },
}

pub(crate) fn check_finite(field: &str, value: f64, q: Quantity) -> Result<(), PredictError> {
    if value.is_finite() {
        scale::check(field, value, q)?;
        Ok(())
    } else {
        Err(PredictError::NonFinite {
            field: field.to_owned(),
            value,
        })
    }
}

pub(crate) fn check_vec(field: &str, v: &Vec3, q: Quantity) -> Result<(), PredictError> {
    for (i, axis) in ["x", "y", "z"].into_iter().enumerate() {
        if !v[i].is_finite() {
            return Err(PredictError::NonFinite {
                field: format!("{field}.{axis}"),
                value: v[i],
            });
        }
    }
    scale::check_vec(field, v, q)?;
    Ok(())
}

/// Finite and `> 0`, then within the range of `q`.
pub(crate) fn check_positive(field: &str, value: f64, q: Quantity) -> Result<(), PredictError> {
    if !value.is_finite() {
        return check_finite(field, value, q);
    }
    if value > 0.0 {
        scale::check(field, value, q)?;
        Ok(())
    } else {
        Err(PredictError::OutOfRange {
            field: field.to_owned(),
            value,
            expected: "a finite number > 0",
        })
    }
}

/// Finite and `>= 0`, then within the range of `q`.
pub(crate) fn check_non_negative(field: &str, value: f64, q: Quantity) -> Result<(), PredictError> {
    if !value.is_finite() {
        return check_finite(field, value, q);
    }
    if value >= 0.0 {
        scale::check(field, value, q)?;
        Ok(())
    } else {
        Err(PredictError::OutOfRange {
            field: field.to_owned(),
            value,
            expected: "a finite number >= 0",
        })
    }
}
