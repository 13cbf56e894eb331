//! The crate's single error type.

use std::fmt;

use thiserror::Error;
use trust_geometry::scale::MAX_COORD_M;

use crate::Vec3;

/// A length for messages: at most six significant digits, trailing zeros dropped (`0.3`, not
/// `0.30000000000000004`); scientific notation outside `[1e-4, 1e6)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Readable(pub f64);

impl fmt::Display for Readable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let v = self.0;
        let a = v.abs();
        if !v.is_finite() || v == 0.0 {
            return write!(f, "{v}");
        }
        if !(1.0e-4..1.0e6).contains(&a) {
            return write!(f, "{v:.5e}");
        }
        // Digits after the point for six significant digits.
        let decimals = (5 - a.log10().floor() as i32).max(0) as usize;
        let s = format!("{v:.decimals$}");
        let s = if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.')
        } else {
            &s
        };
        f.write_str(s)
    }
}

/// A point for messages: `[x, y, z]` with [`Readable`] coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ReadablePoint(pub(crate) Vec3);

impl fmt::Display for ReadablePoint {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let p = self.0;
        write!(
            f,
            "[{}, {}, {}]",
            Readable(p.x),
            Readable(p.y),
            Readable(p.z)
        )
    }
}

/// Why a goal cannot be reached ([`crate::Unreachable`]). Its `Display` is the sentence run logs
/// carry as an `unreachable` outcome's `reason`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum UnreachableCause {
    /// The goal lies outside the map bounds.
    GoalOutsideBounds,
    /// The goal is closer to an obstacle than the vehicle radius (or inside one).
    GoalInsideObstacle {
        /// The goal's signed distance to the nearest obstacle, in metres (negative inside).
        signed_distance_m: f64,
    },
    /// No path keeps the inflated clearance (proved, see the crate docs), and none keeps the
    /// vehicle radius alone either (proved, or none the fine grid resolves): any remaining
    /// opening is narrower than about `2·radius + h` (`h` the fine grid's cell size).
    SealedOff,
    /// No path keeps the inflated clearance (proved, see the crate docs), but one keeps the
    /// vehicle radius: the vehicle would have to give up its safety margin to pass.
    TooNarrow {
        /// The inflated clearance the route must keep, in metres.
        clearance_m: f64,
    },
}

impl fmt::Display for UnreachableCause {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            UnreachableCause::GoalOutsideBounds => {
                f.write_str("the goal lies outside the map bounds")
            }
            UnreachableCause::GoalInsideObstacle { signed_distance_m }
                if signed_distance_m < 0.0 =>
            {
                write!(
                    f,
                    "the goal lies {} m inside an obstacle",
                    Readable(-signed_distance_m)
                )
            }
            UnreachableCause::GoalInsideObstacle { signed_distance_m } => write!(
                f,
                "the goal lies {} m from an obstacle, closer than the vehicle radius",
                Readable(signed_distance_m)
            ),
            UnreachableCause::SealedOff => f.write_str(
                "the goal is sealed off from the start: no opening is as wide as the vehicle",
            ),
            UnreachableCause::TooNarrow { clearance_m } => write!(
                f,
                "every opening toward the goal is too narrow for the vehicle plus its margin \
                 (a clearance of {} m from every wall)",
                Readable(clearance_m)
            ),
        }
    }
}

/// Which end of the route an error is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Endpoint {
    /// The start (the vehicle's position when the route is planned).
    Start,
    /// The goal (the mission's final goal).
    Goal,
}

impl std::fmt::Display for Endpoint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Endpoint::Start => "start",
            Endpoint::Goal => "goal",
        })
    }
}

/// Invalid input, or a search that hit one of its caps or found no route.
///
/// Every variant names the offending field or cap and its value.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum RouteError {
    /// A parameter or argument outside its documented range.
    #[error("{field} = {value} is out of range: expected {expected}")]
    InvalidParam {
        /// Name of the field (e.g. `"route.max_cells"`, `"radius_m"`).
        field: String,
        /// The offending value.
        value: f64,
        /// The accepted range, in words.
        expected: String,
    },
    /// A point (start, goal, route vertex or query position) with a coordinate beyond the scale
    /// policy of `trust_geometry` (`|x| ≤ 1e6` m, [`trust_geometry::scale::MAX_COORD_M`]).
    #[error("{field} = {} is out of range: every coordinate must be within ±{} m", ReadablePoint(*.point), Readable(*.limit_m))]
    PointOutOfScale {
        /// Name of the argument (`"start"`, `"goal"`, `"points[3]"`, `"position"`).
        field: String,
        /// The offending point.
        point: Vec3,
        /// The largest accepted coordinate magnitude, in metres.
        limit_m: f64,
    },
    /// A point (start, goal or query position) with a NaN or infinite coordinate.
    #[error("{field} must be finite, got [{}, {}, {}]", .point.x, .point.y, .point.z)]
    NonFinitePoint {
        /// Name of the argument (`"start"`, `"goal"`, `"position"`).
        field: String,
        /// The offending point.
        point: Vec3,
    },
    /// The start or goal lies outside the map bounds.
    #[error("{which} [{}, {}, {}] lies outside the map bounds", .point.x, .point.y, .point.z)]
    OutsideBounds {
        /// Which end.
        which: Endpoint,
        /// The offending point.
        point: Vec3,
    },
    /// The grid at the coarsest allowed cell size still has more cells than the cap.
    #[error(
        "the route grid needs {cells} cells at cell size {cell_m} m (the coarsest allowed), above \
         the cap route.max_cells = {cap}"
    )]
    TooManyCells {
        /// Cells the grid would need.
        cells: u128,
        /// The cap (`RouteParams::max_cells`).
        cap: usize,
        /// The coarsest cell size allowed, in metres.
        cell_m: f64,
    },
    /// The search expanded `cap` cells without reaching the goal.
    #[error(
        "the route search expanded {cap} cells without reaching the goal (cap route.max_expansions)"
    )]
    ExpansionCap {
        /// The cap (`RouteParams::max_expansions`).
        cap: usize,
    },
    /// The caller's deadline passed during the search.
    #[error("the route search passed its deadline after {expanded} expansions")]
    Deadline {
        /// Cells expanded before the deadline was noticed.
        expanded: usize,
    },
    /// No free grid cell within the snap radius of the start or goal.
    #[error(
        "no free route cell within {} m of the {which} {} (inflated clearance {} m)",
        Readable(*.bound_m), ReadablePoint(*.point), Readable(*.clearance_m)
    )]
    NoFreeCell {
        /// Which end.
        which: Endpoint,
        /// The start or goal.
        point: Vec3,
        /// The search radius, in metres (`snap_radius_factor × clearance`).
        bound_m: f64,
        /// The inflated clearance the cells must keep, in metres.
        clearance_m: f64,
    },
    /// The goal is unreachable at this clearance ([`crate::RouteProgress::Unreachable`] as an
    /// error, from [`crate::RoutePlanner::plan`]).
    #[error("{cause} (inflated clearance {} m, {expanded} cells expanded)", Readable(*.clearance_m))]
    Unreachable {
        /// Cells the start-side search expanded.
        expanded: usize,
        /// The inflated clearance, in metres.
        clearance_m: f64,
        /// Why.
        cause: UnreachableCause,
    },
    /// The grid found no route at the clearance, but its over-approximation of the free space
    /// joins the start and the goal: a passage narrower than `2·clearance_m + cell_m` may keep
    /// the clearance. No verdict.
    #[error(
        "no route at clearance {} m on a grid of {} m cells, but a passage the grid cannot resolve \
         may keep it: no verdict",
        Readable(*.clearance_m),
        Readable(*.cell_m)
    )]
    Unresolved {
        /// The inflated clearance, in metres.
        clearance_m: f64,
        /// The fine grid's cell size, in metres.
        cell_m: f64,
    },
}

/// Which variant a [`RouteError`] is, without its fields: for code that decides by the kind of
/// error (the manager's `route_failed` event, [`RouteError::kind`]) and for logs (serialized as
/// the variant's name in snake case, `"expansion_cap"`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum RouteErrorKind {
    /// [`RouteError::InvalidParam`].
    InvalidParam,
    /// [`RouteError::PointOutOfScale`].
    PointOutOfScale,
    /// [`RouteError::NonFinitePoint`].
    NonFinitePoint,
    /// [`RouteError::OutsideBounds`].
    OutsideBounds,
    /// [`RouteError::TooManyCells`].
    TooManyCells,
    /// [`RouteError::ExpansionCap`].
    ExpansionCap,
    /// [`RouteError::Deadline`].
    Deadline,
    /// [`RouteError::NoFreeCell`].
    NoFreeCell,
    /// [`RouteError::Unreachable`].
    Unreachable,
    /// [`RouteError::Unresolved`].
    Unresolved,
}

impl RouteError {
    /// Which variant this is.
    pub fn kind(&self) -> RouteErrorKind {
        match self {
            RouteError::InvalidParam { .. } => RouteErrorKind::InvalidParam,
            RouteError::PointOutOfScale { .. } => RouteErrorKind::PointOutOfScale,
            RouteError::NonFinitePoint { .. } => RouteErrorKind::NonFinitePoint,
            RouteError::OutsideBounds { .. } => RouteErrorKind::OutsideBounds,
            RouteError::TooManyCells { .. } => RouteErrorKind::TooManyCells,
            RouteError::ExpansionCap { .. } => RouteErrorKind::ExpansionCap,
            RouteError::Deadline { .. } => RouteErrorKind::Deadline,
            RouteError::NoFreeCell { .. } => RouteErrorKind::NoFreeCell,
            RouteError::Unreachable { .. } => RouteErrorKind::Unreachable,
            RouteError::Unresolved { .. } => RouteErrorKind::Unresolved,
        }
    }
}

/// `Ok(value)` if `value` is finite and in `[lo, hi]`, else [`RouteError::InvalidParam`].
pub(crate) fn check_range(field: &str, value: f64, lo: f64, hi: f64) -> Result<f64, RouteError> {
    if value.is_finite() && (lo..=hi).contains(&value) {
        Ok(value)
    } else {
        Err(RouteError::InvalidParam {
            field: field.to_owned(),
            value,
            expected: format!("a finite value in [{lo}, {hi}]"),
        })
    }
}

/// `Ok(p)` if every coordinate of `p` is finite ([`RouteError::NonFinitePoint`] otherwise) and
/// within `±MAX_COORD_M` ([`RouteError::PointOutOfScale`] otherwise).
pub(crate) fn check_point(field: &str, p: &Vec3) -> Result<Vec3, RouteError> {
    if !p.iter().all(|c| c.is_finite()) {
        Err(RouteError::NonFinitePoint {
            field: field.to_owned(),
            point: *p,
        })
    } else if p.amax() > MAX_COORD_M {
        Err(RouteError::PointOutOfScale {
            field: field.to_owned(),
            point: *p,
            limit_m: MAX_COORD_M,
        })
    } else {
        Ok(*p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn readable_numbers_have_six_significant_digits_at_most() {
        assert_eq!(Readable(0.30000000000000004).to_string(), "0.3");
        assert_eq!(Readable(0.1 + 0.2).to_string(), "0.3");
        assert_eq!(Readable(12.3456789).to_string(), "12.3457");
        assert_eq!(Readable(250.0).to_string(), "250");
        assert_eq!(Readable(-0.45).to_string(), "-0.45");
        assert_eq!(Readable(1.0e-7).to_string(), "1.00000e-7");
        assert_eq!(Readable(0.0).to_string(), "0");
    }
}
