//! The crate's single error type.

use thiserror::Error;

/// Misuse of the solver: invalid parameters or an invalid start.
///
/// Every variant names the offending field (or vector entry) and value and says what was expected.
/// A solve that merely fails to converge is *not* an error: it returns a [`crate::Report`] whose
/// [`crate::Termination`] says why it stopped.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum LbfgsError {
    /// A field of [`crate::LbfgsParams`] is out of its valid range.
    #[error("invalid LbfgsParams: {field} = {}, expected {expected}", Readable(*.value))]
    InvalidParam {
        /// Name of the field (e.g. `"memory"`).
        field: &'static str,
        /// The offending value (integer fields are shown as their exact `f64` value).
        value: f64,
        /// What the field must satisfy (e.g. `"an integer >= 1"`).
        expected: &'static str,
    },
    /// A solver was requested for a problem with no variables.
    #[error("dimension = 0, expected at least 1 variable")]
    ZeroDimension,
    /// A solver was requested for more variables than [`crate::MAX_DIMENSION`].
    #[error(
        "dimension = {}, expected at most {} variables (MAX_DIMENSION)",
        ReadableCount(*.dimension),
        ReadableCount(*.cap)
    )]
    DimensionTooLarge {
        /// The requested dimension.
        dimension: usize,
        /// The cap, [`crate::MAX_DIMENSION`].
        cap: usize,
    },
    /// The buffers a solver allocates up front, `(2·memory + 6)·dimension + 3·memory + past`
    /// floats, would exceed [`crate::MAX_WORKSPACE_FLOATS`]: the dimension is accepted, but not with
    /// this many correction pairs.
    #[error(
        "dimension = {} with LbfgsParams memory = {} and past = {} needs {} floats of workspace, \
         expected at most {} (MAX_WORKSPACE_FLOATS); lower memory or the dimension",
        ReadableCount(*.dimension),
        ReadableCount(*.memory),
        ReadableCount(*.past),
        Readable(*.floats),
        ReadableCount(*.cap)
    )]
    WorkspaceTooLarge {
        /// The requested dimension.
        dimension: usize,
        /// [`crate::LbfgsParams::memory`].
        memory: usize,
        /// [`crate::LbfgsParams::past`].
        past: usize,
        /// The floats the buffers would take (as `f64`: the product may exceed `usize`).
        floats: f64,
        /// The cap, [`crate::MAX_WORKSPACE_FLOATS`].
        cap: usize,
    },
    /// The start point has a different length than the dimension the solver was built for.
    #[error(
        "x has length {}, expected {} (the solver's dimension)",
        ReadableCount(*.len),
        ReadableCount(*.expected)
    )]
    DimensionMismatch {
        /// Length of the `x` passed to `minimize`.
        len: usize,
        /// Dimension the solver was built for.
        expected: usize,
    },
    /// An entry of the start point is NaN or infinite.
    #[error("start point x[{index}] = {}, expected a finite number", Readable(*.value))]
    NonFiniteStart {
        /// Index of the first non-finite entry.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// The cost function returned NaN or an infinity at the start point.
    #[error("cost at the start point = {}, expected a finite number", Readable(*.value))]
    NonFiniteStartCost {
        /// The returned cost.
        value: f64,
    },
    /// The cost function wrote NaN or an infinity into the gradient at the start point.
    #[error(
        "gradient at the start point g[{index}] = {}, expected a finite number",
        Readable(*.value)
    )]
    NonFiniteStartGradient {
        /// Index of the first non-finite gradient entry.
        index: usize,
        /// Its value.
        value: f64,
    },
}

/// Index and value of the first non-finite entry of `v`, if any.
pub(crate) fn first_non_finite(v: &[f64]) -> Option<(usize, f64)> {
    v.iter()
        .copied()
        .enumerate()
        .find(|(_, value)| !value.is_finite())
}

/// A number for messages: plain for ordinary magnitudes, scientific notation (`1e300`) for huge or
/// tiny ones, so that a message never carries a 300-digit decimal. (This crate depends on nothing
/// of the planner's, so it does not use `trust_geometry::scale::Sci`.)
pub(crate) struct Readable(pub(crate) f64);

impl std::fmt::Display for Readable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let a = self.0.abs();
        if !self.0.is_finite() || a == 0.0 || (1e-6..1e6).contains(&a) {
            write!(f, "{}", self.0)
        } else {
            write!(f, "{:e}", self.0)
        }
    }
}

/// A count for messages: exact up to a billion, scientific notation above (never 20 digits).
pub(crate) struct ReadableCount(pub(crate) usize);

impl std::fmt::Display for ReadableCount {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.0 <= 1_000_000_000 {
            write!(f, "{}", self.0)
        } else {
            write!(f, "{:e}", self.0 as f64)
        }
    }
}
