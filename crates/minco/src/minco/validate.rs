//! Input checks shared by the MINCO entry points: each names the field, index and value.

use nalgebra::Vector3;

use crate::error::MincoError;

/// `got == expected`, else [`MincoError::LengthMismatch`] naming `field`.
#[inline]
pub(crate) fn check_len(
    field: &'static str,
    expected: usize,
    got: usize,
) -> Result<(), MincoError> {
    if expected == got {
        Ok(())
    } else {
        Err(MincoError::LengthMismatch {
            field,
            expected,
            got,
        })
    }
}

/// Every duration finite and `> 0`.
#[inline]
pub(crate) fn check_durations(durations: &[f64]) -> Result<(), MincoError> {
    match durations.iter().position(|t| !(t.is_finite() && *t > 0.0)) {
        None => Ok(()),
        Some(index) => Err(MincoError::InvalidDuration {
            index,
            value: durations[index],
        }),
    }
}

/// Index of the first vector with a NaN or infinite component. The common all-finite case is a
/// branch-free pass (non-short-circuit `|`), so it vectorizes; only a failure searches.
#[inline]
pub(crate) fn first_non_finite(vectors: &[Vector3<f64>]) -> Option<usize> {
    let mut bad = false;
    for v in vectors {
        bad |= !v.x.is_finite() | !v.y.is_finite() | !v.z.is_finite();
    }
    if bad {
        vectors
            .iter()
            .position(|v| !(v.x.is_finite() && v.y.is_finite() && v.z.is_finite()))
    } else {
        None
    }
}

/// Every vector has finite components.
#[inline]
pub(crate) fn check_vectors(
    field: &'static str,
    vectors: &[Vector3<f64>],
) -> Result<(), MincoError> {
    match first_non_finite(vectors) {
        None => Ok(()),
        Some(index) => {
            let v = vectors[index];
            Err(MincoError::NonFiniteVector {
                field,
                index,
                value: [v.x, v.y, v.z],
            })
        }
    }
}

/// Every scalar finite.
#[inline]
pub(crate) fn check_scalars(field: &'static str, values: &[f64]) -> Result<(), MincoError> {
    match values.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(index) => Err(MincoError::NonFiniteScalar {
            field,
            index,
            value: values[index],
        }),
    }
}
