//! Accepted ranges of the parameter fields of this crate, derived from the scale policy
//! (`trust_core::scale`): every params struct's `validate` checks its fields with these helpers, so
//! that an accepted value never makes a later call fail on something else, return NaN, or run for
//! longer than its budgets allow. Errors are [`PlanError::InvalidInput`] naming the
//! field path (`devprm.surface_offset`), the value in readable scientific notation and the range.

use trust_core::scale::{self, Quantity};
use trust_core::{PlanError, Vec3};

/// Smallest accepted resolution of the PRMs (m): the edge threshold and the UVD / shortcut step.
/// Below 1 mm, a query across the scale policy's 1 km-class maps needs more than
/// [`scale::MAX_SAMPLE_COUNT`] steps per path.
pub const MIN_RESOLUTION_M: f64 = 1.0e-3;

/// Largest accepted time budget of a frontend (ms): 10 minutes, above `trust-sim`'s reproducible
/// budget (60 s) and far above a replanning cycle (the paper's 5–20 ms).
pub const MAX_BUDGET_MS: f64 = 600_000.0;

/// Largest accepted count of paths kept or returned (`max_raw_paths`, `keep_raw_paths`,
/// `max_paths`): [`scale::MAX_VERTEX_COUNT`].
pub const MAX_PATH_COUNT: usize = scale::MAX_VERTEX_COUNT;

/// Largest accepted expansion budget of a graph search: [`scale::MAX_SAMPLE_COUNT`].
pub const MAX_EXPANSIONS: usize = scale::MAX_SAMPLE_COUNT;

/// Largest accepted beam width of DEV-PRM's beam search.
pub const MAX_BEAM_WIDTH: usize = 1024;

/// Largest accepted `slices · samples_per_slice` of DEV-PRM's obstacle-aware samples per cone:
/// a tenth of [`scale::MAX_SOLVED_SAMPLE_COUNT`], so that ten cones stay within it.
pub const MAX_SURFACE_SAMPLES: usize = scale::MAX_SOLVED_SAMPLE_COUNT / 10;

/// Largest accepted length ratio (a path this many times the shortest is dropped).
pub const MAX_LENGTH_RATIO: f64 = 1.0e6;

/// Largest accepted work rate (units per ms, [`crate::QueryWork`]).
pub const MAX_WORK_PER_MS: f64 = 1.0e12;

/// A count for [`PlanError::InvalidInput`]'s value: exact up to 10⁹, scientific above.
struct CountValue(usize);

impl std::fmt::Debug for CountValue {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", scale::SciCount(self.0 as u128))
    }
}

/// `x` finite and in `[lo, hi]` (`unit` for the message). The errors are
/// [`PlanError::InvalidInput`] naming `field` (so that callers that re-prefix field paths, such
/// as `trust-sim`'s scenario files, handle them like every other parameter error): "a finite
/// number >= 0" / "> 0" below a lower end of 0 / `MIN_POSITIVE`, the range otherwise.
pub(crate) fn range(
    field: &str,
    x: f64,
    lo: f64,
    hi: f64,
    unit: &'static str,
) -> Result<(), PlanError> {
    if x >= lo && x <= hi {
        return Ok(());
    }
    let below = !x.is_finite() || x < lo;
    let expected = if below && lo == 0.0 {
        "a finite number >= 0".to_owned()
    } else if below && lo == scale::MIN_POSITIVE && x <= 0.0 {
        "a finite number > 0".to_owned()
    } else {
        format!(
            "a number in [{}, {}] {unit} (scale policy, trust_core::scale)",
            scale::Sci(lo),
            scale::Sci(hi)
        )
    };
    Err(PlanError::invalid(field, x, expected))
}

/// `x` finite and in the range of `q`.
pub(crate) fn quantity(field: &str, x: f64, q: Quantity) -> Result<(), PlanError> {
    let (lo, hi) = q.range();
    range(field, x, lo, hi, q.unit())
}

/// Every component of `v` a length (`0 ≤ x ≤ MAX_LENGTH_M`); the field gets `.x`/`.y`/`.z`.
pub(crate) fn lengths(field: &str, v: &Vec3) -> Result<(), PlanError> {
    for (i, axis) in ['x', 'y', 'z'].into_iter().enumerate() {
        quantity(&format!("{field}.{axis}"), v[i], Quantity::Length)?;
    }
    Ok(())
}

/// A count in `[lo, cap]`.
pub(crate) fn count(field: &str, n: usize, lo: usize, cap: usize) -> Result<(), PlanError> {
    if n < lo {
        return Err(PlanError::invalid(field, n, format!(">= {lo}")));
    }
    if n > cap {
        return Err(PlanError::invalid(
            field,
            CountValue(n),
            format!("an integer in [{lo}, {}]", scale::SciCount(cap as u128)),
        ));
    }
    Ok(())
}

/// A time budget in milliseconds: `(0, MAX_BUDGET_MS]`.
pub(crate) fn budget_ms(field: &str, ms: f64) -> Result<(), PlanError> {
    range(field, ms, scale::MIN_POSITIVE, MAX_BUDGET_MS, "ms")
}
