//! The crate's single error type.

use thiserror::Error;

use crate::scale::{self, CountError, Quantity, ScaleError, Sci, SciCount};

/// Invalid input to a constructor or builder of this crate.
///
/// Every variant names the offending field and value and says what was expected.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum GeometryError {
    /// A number that must be finite was NaN or infinite.
    #[error("{field} must be finite, got {}", Sci(*.value))]
    NonFinite {
        /// Name of the field (e.g. `"sphere.center.x"`).
        field: String,
        /// The offending value.
        value: f64,
    },
    /// A size (radius, half-height, clearance, …) was negative.
    #[error("{field} must be >= 0, got {}", Sci(*.value))]
    Negative {
        /// Name of the field.
        field: String,
        /// The offending value.
        value: f64,
    },
    /// A quantity that must be strictly positive (e.g. a voxel resolution) was zero or negative.
    #[error("{field} must be > 0, got {}", Sci(*.value))]
    NonPositive {
        /// Name of the field.
        field: String,
        /// The offending value.
        value: f64,
    },
    /// A box whose minimum exceeds its maximum along some axis.
    #[error("{field}: min.{axis} = {} exceeds max.{axis} = {}; expected min <= max", Sci(*.min), Sci(*.max))]
    InvertedBox {
        /// Name of the box (e.g. `"bounds"`).
        field: String,
        /// The axis (`'x'`, `'y'` or `'z'`).
        axis: char,
        /// Minimum along that axis.
        min: f64,
        /// Maximum along that axis.
        max: f64,
    },
    /// Bounds with zero extent along some axis (zero volume) where a volume is required.
    #[error(
        "{field}: zero extent along {axis} (min = max = {}); expected a positive volume",
        Sci(*.value)
    )]
    EmptyBounds {
        /// Name of the box (e.g. `"bounds"`).
        field: String,
        /// The axis (`'x'`, `'y'` or `'z'`).
        axis: char,
        /// The common min/max value along that axis.
        value: f64,
    },
    /// A voxel grid would exceed [`crate::MAX_VOXELS`] voxels.
    #[error(
        "voxel grid of {} x {} x {} = {} voxels exceeds the limit of {}; \
         use a coarser resolution or smaller bounds",
        SciCount(*.nx as u128),
        SciCount(*.ny as u128),
        SciCount(*.nz as u128),
        SciCount(*.count),
        SciCount(*.limit as u128)
    )]
    GridTooLarge {
        /// Voxels along x.
        nx: usize,
        /// Voxels along y.
        ny: usize,
        /// Voxels along z.
        nz: usize,
        /// Their product (saturating).
        count: u128,
        /// The limit.
        limit: usize,
    },
    /// Voxel grid data whose length does not match its dimensions.
    #[error(
        "{field} has length {}, expected {} (= nx * ny * nz)",
        SciCount(*.len as u128),
        SciCount(*.expected as u128)
    )]
    LengthMismatch {
        /// Name of the field.
        field: String,
        /// Its length.
        len: usize,
        /// The expected length.
        expected: usize,
    },
    /// A number outside the scale policy ([`crate::scale`]).
    #[error(transparent)]
    Scale(#[from] ScaleError),
    /// A count above its cap ([`crate::scale`]).
    #[error(transparent)]
    Count(#[from] CountError),
}

impl GeometryError {
    pub(crate) fn non_finite(field: impl Into<String>, value: f64) -> Self {
        Self::NonFinite {
            field: field.into(),
            value,
        }
    }
}

/// Checks that `value` is finite.
pub(crate) fn check_finite(field: &str, value: f64) -> Result<f64, GeometryError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(GeometryError::non_finite(field, value))
    }
}

/// Checks that `value` is a length: finite, `>= 0` and within the scale policy.
pub(crate) fn check_non_negative(field: &str, value: f64) -> Result<f64, GeometryError> {
    check_finite(field, value)?;
    if value < 0.0 {
        Err(GeometryError::Negative {
            field: field.into(),
            value,
        })
    } else {
        Ok(scale::check(field, value, Quantity::Length)?)
    }
}

/// Checks that `value` is a strictly positive length: finite, `> 0` and within the scale policy.
pub(crate) fn check_positive(field: &str, value: f64) -> Result<f64, GeometryError> {
    check_finite(field, value)?;
    if value > 0.0 {
        Ok(scale::check(field, value, Quantity::PositiveLength)?)
    } else {
        Err(GeometryError::NonPositive {
            field: field.into(),
            value,
        })
    }
}

/// Checks that every component of `v` is a finite position within the scale policy; the field
/// name gets `.x`/`.y`/`.z` appended.
pub(crate) fn check_vec(field: &str, v: &crate::Vec3) -> Result<(), GeometryError> {
    for (i, axis) in ['x', 'y', 'z'].into_iter().enumerate() {
        if !v[i].is_finite() {
            return Err(GeometryError::non_finite(format!("{field}.{axis}"), v[i]));
        }
    }
    Ok(scale::check_vec(field, v, Quantity::Position)?)
}

/// Checks that `value` is a finite position coordinate within the scale policy.
pub(crate) fn check_coord(field: &str, value: f64) -> Result<f64, GeometryError> {
    check_finite(field, value)?;
    Ok(scale::check(field, value, Quantity::Position)?)
}
