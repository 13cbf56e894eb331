//! The crate's single error type.

use thiserror::Error;
use trust_geometry::{GeometryError, Sci};

/// Invalid input to a sensor, the online map or one of their parameter structs.
///
/// Every variant names the offending field and value and says what was expected.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum SensingError {
    /// A number that must be finite was NaN or infinite.
    #[error("{field} must be finite, got {}", Sci(*.value))]
    NonFinite {
        /// Name of the field (e.g. `"pose.position.x"`).
        field: String,
        /// The offending value.
        value: f64,
    },
    /// A number outside its accepted range.
    #[error("{field} = {} is out of range; expected {expected}", Sci(*.value))]
    OutOfRange {
        /// Name of the field (e.g. `"camera.hfov_rad"`).
        field: String,
        /// The offending value.
        value: f64,
        /// The accepted range, in words (e.g. `"in (0, π)"`).
        expected: &'static str,
    },
    /// A count outside its accepted range (pixels, channels, voxels per axis).
    #[error("{field} = {value} is out of range; expected {expected}")]
    Count {
        /// Name of the field (e.g. `"camera.width"`).
        field: String,
        /// The offending count.
        value: u64,
        /// The accepted range, in words.
        expected: &'static str,
    },
    /// A scan whose rays do not match what the map expects.
    #[error("{field}: {problem}")]
    Scan {
        /// Name of the field (e.g. `"scan.rays[3].direction"`).
        field: String,
        /// What is wrong with it.
        problem: String,
    },
    /// An error from `trust-geometry` (building an `Esdf` or a `StaticMap`).
    #[error(transparent)]
    Geometry(#[from] GeometryError),
}

/// Checks that `value` is finite.
pub(crate) fn check_finite(field: &str, value: f64) -> Result<f64, SensingError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(SensingError::NonFinite {
            field: field.into(),
            value,
        })
    }
}

/// Checks that `value` is finite and lies in `[lo, hi]` (`open_lo`: `(lo, hi]`).
pub(crate) fn check_range(
    field: &str,
    value: f64,
    lo: f64,
    hi: f64,
    open_lo: bool,
    expected: &'static str,
) -> Result<f64, SensingError> {
    check_finite(field, value)?;
    let above = if open_lo { value > lo } else { value >= lo };
    if above && value <= hi {
        Ok(value)
    } else {
        Err(SensingError::OutOfRange {
            field: field.into(),
            value,
            expected,
        })
    }
}

/// Checks that `value` lies in `[lo, hi]`.
pub(crate) fn check_count(
    field: &str,
    value: usize,
    lo: usize,
    hi: usize,
    expected: &'static str,
) -> Result<usize, SensingError> {
    if (lo..=hi).contains(&value) {
        Ok(value)
    } else {
        Err(SensingError::Count {
            field: field.into(),
            value: value as u64,
            expected,
        })
    }
}
