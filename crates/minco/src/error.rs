//! The crate's error type.

use thiserror::Error;
use trust_core::scale::Sci;

/// Everything that can go wrong in `trust-minco`: invalid input (named field, index and value) and
/// numerical breakdown of the banded solve (reported instead of producing inf/NaN).
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum MincoError {
    /// More pieces than [`crate::minco::MAX_PIECES`] (the storage is allocated up front).
    #[error("piece count: got {got}, expected at most {max} (scale policy, trust_core::scale)")]
    TooManyPieces {
        /// The piece count that was asked for.
        got: usize,
        /// The cap.
        max: usize,
    },

    /// A trajectory needs at least one piece.
    #[error("piece count: got {got}, expected at least 1")]
    NoPieces {
        /// The piece count that was asked for.
        got: usize,
    },

    /// A slice, list or matrix has the wrong number of entries.
    #[error("{field}: got {got} entries, expected {expected}")]
    LengthMismatch {
        /// Which input (e.g. `"waypoints"`, `"durations"`, `"rhs"`).
        field: &'static str,
        /// How many entries were expected.
        expected: usize,
        /// How many entries were given.
        got: usize,
    },

    /// A scalar input is NaN or infinite.
    #[error("{field}[{index}] = {}: expected a finite number", Sci(*.value))]
    NonFiniteScalar {
        /// Which input.
        field: &'static str,
        /// Index of the offending entry.
        index: usize,
        /// The offending value.
        value: f64,
    },

    /// A 3-vector input has a NaN or infinite component.
    #[error("{field}[{index}] = ({}, {}, {}): expected finite components", Sci(value[0]), Sci(value[1]), Sci(value[2]))]
    NonFiniteVector {
        /// Which input (e.g. `"waypoints"`, `"head"`, `"tail"`; for `head`/`tail` index 0, 1, 2 is
        /// position, velocity, acceleration).
        field: &'static str,
        /// Index of the offending entry.
        index: usize,
        /// The offending vector.
        value: [f64; 3],
    },

    /// A piece duration is not strictly positive (or not finite).
    #[error("durations[{index}] = {}: expected a finite duration > 0 s", Sci(*.value))]
    InvalidDuration {
        /// Index of the piece.
        index: usize,
        /// The offending duration in seconds.
        value: f64,
    },

    /// A banded-matrix entry was addressed outside the matrix or outside its band.
    #[error(
        "banded matrix entry ({row}, {col}) is outside the {size}x{size} matrix with lower bandwidth \
         {lower} and upper bandwidth {upper}"
    )]
    OutOfBand {
        /// Row index.
        row: usize,
        /// Column index.
        col: usize,
        /// Matrix size.
        size: usize,
        /// Lower bandwidth.
        lower: usize,
        /// Upper bandwidth.
        upper: usize,
    },

    /// `solve` was called on a banded matrix that has not been factorized (or was modified since).
    #[error("banded matrix: solve called before a successful factorize")]
    NotFactorized,

    /// LU without pivoting met a zero or non-finite pivot: the matrix is singular or too badly
    /// conditioned (for MINCO: a piece duration too short for f64).
    #[error(
        "banded LU: pivot at row {row} is {value}; expected a finite non-zero pivot (singular or \
         ill-conditioned matrix, e.g. a very short piece duration)"
    )]
    SingularPivot {
        /// Row (= column) of the failing pivot.
        row: usize,
        /// The pivot value.
        value: f64,
    },

    /// A MINCO result was asked for before a successful [`crate::minco::MincoS3::solve`] (or after a
    /// failed one).
    #[error("MINCO: {operation} called before a successful solve")]
    NotSolved {
        /// The operation that needs solved coefficients.
        operation: &'static str,
    },

    /// The solve finished but produced a non-finite number (overflow on an ill-conditioned system).
    #[error(
        "{field} is not finite after the solve (first at index {index}); the system is too \
         ill-conditioned (e.g. a \
         very short piece duration)"
    )]
    NonFiniteResult {
        /// Which output.
        field: &'static str,
        /// Row of the first non-finite entry.
        index: usize,
    },

    /// The JSON input of [`crate::minco::eval_json`] could not be parsed.
    #[error("invalid JSON input: {message}")]
    Json {
        /// The parser's message (with line and column).
        message: String,
    },
}
