//! The crate's single error type.

use thiserror::Error;

use crate::Vec3;

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
        "no free route cell within {bound_m} m of the {which} [{}, {}, {}] (inflated clearance \
         {clearance_m} m)",
        .point.x, .point.y, .point.z
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
    /// The search exhausted every reachable free cell: the goal is unreachable at this clearance.
    #[error(
        "the goal is unreachable at clearance {clearance_m} m: the search exhausted all {expanded} \
         reachable cells"
    )]
    Unreachable {
        /// Cells expanded (every free cell reachable from the start).
        expanded: usize,
        /// The inflated clearance, in metres.
        clearance_m: f64,
    },
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

/// `Ok(p)` if every coordinate of `p` is finite, else [`RouteError::NonFinitePoint`].
pub(crate) fn check_point(field: &str, p: &Vec3) -> Result<Vec3, RouteError> {
    if p.iter().all(|c| c.is_finite()) {
        Ok(*p)
    } else {
        Err(RouteError::NonFinitePoint {
            field: field.to_owned(),
            point: *p,
        })
    }
}
