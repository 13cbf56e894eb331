//! The vehicle's error type and input checks.

use trust_core::Vec3;

/// Invalid input to a vehicle, its parameters or its controller. Every message names the offending
/// field, its value and what was expected.
///
/// A vehicle that is merely pushed to its limits (saturated thrust, torque or body rate) or handed a
/// non-finite reference does not fail: that is reported in [`StepInfo`](super::StepInfo). `Err` is
/// for misuse (invalid parameters, a non-positive time step, a non-finite command).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum VehicleError {
    /// A number was NaN or infinite.
    #[error("`{field}` must be finite, got {value}")]
    NonFinite {
        /// Dotted name of the offending field (vector components as `field.x` etc.).
        field: String,
        /// The offending value.
        value: f64,
    },
    /// A number was outside its valid range.
    #[error("`{field}` = {value} is out of range: expected {expected}")]
    OutOfRange {
        /// Dotted name of the offending field.
        field: String,
        /// The offending value.
        value: f64,
        /// The valid range, in words.
        expected: String,
    },
}

pub(crate) fn check_finite(field: &str, value: f64) -> Result<(), VehicleError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(VehicleError::NonFinite {
            field: field.to_owned(),
            value,
        })
    }
}

/// Names each component `field.x` etc.; allocates only on error (it runs every physics step).
pub(crate) fn check_finite_vec(field: &str, v: &Vec3) -> Result<(), VehicleError> {
    for (axis, x) in ["x", "y", "z"].iter().zip(v.iter()) {
        if !x.is_finite() {
            return check_finite(&format!("{field}.{axis}"), *x);
        }
    }
    Ok(())
}

/// Finite and strictly positive.
pub(crate) fn check_positive(field: &str, value: f64) -> Result<(), VehicleError> {
    check_finite(field, value)?;
    if value > 0.0 {
        Ok(())
    } else {
        Err(out_of_range(field, value, "a finite number > 0"))
    }
}

/// Finite and non-negative.
pub(crate) fn check_non_negative(field: &str, value: f64) -> Result<(), VehicleError> {
    check_finite(field, value)?;
    if value >= 0.0 {
        Ok(())
    } else {
        Err(out_of_range(field, value, "a finite number >= 0"))
    }
}

pub(crate) fn check_positive_vec(field: &str, v: &Vec3) -> Result<(), VehicleError> {
    for (axis, x) in ["x", "y", "z"].iter().zip(v.iter()) {
        check_positive(&format!("{field}.{axis}"), *x)?;
    }
    Ok(())
}

pub(crate) fn out_of_range(field: &str, value: f64, expected: impl Into<String>) -> VehicleError {
    VehicleError::OutOfRange {
        field: field.to_owned(),
        value,
        expected: expected.into(),
    }
}

/// A time step must be finite and strictly positive.
pub(crate) fn check_dt(dt: f64) -> Result<(), VehicleError> {
    check_finite("dt", dt)?;
    if dt > 0.0 {
        Ok(())
    } else {
        Err(out_of_range("dt", dt, "a time step > 0 s"))
    }
}
