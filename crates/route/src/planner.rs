//! [`RoutePlanner`]: validates a query and runs a [`RouteSearch`] on it (see the crate docs for
//! the algorithm).

use std::time::Instant;

use trust_geometry::StaticMap;

use crate::Vec3;
use crate::error::{Endpoint, RouteError, UnreachableCause, check_point, check_range};
use crate::params::RouteParams;
use crate::route::GlobalRoute;
use crate::search::{RouteProgress, RouteSearch};

/// Largest vehicle radius accepted, in metres.
const MAX_RADIUS_M: f64 = 1.0e3;
/// Units of work [`RoutePlanner::plan_until`] does between two looks at its deadline.
const DEADLINE_SLICE: usize = 1024;

/// Plans a [`GlobalRoute`] on a [`StaticMap`]; see the crate docs for the algorithm.
///
/// Planning is a pure function of the map, the end points, the radius and the parameters (the
/// optional deadline aside): same input, same route.
#[derive(Debug, Clone)]
pub struct RoutePlanner {
    params: RouteParams,
}

impl RoutePlanner {
    /// A planner with validated parameters.
    pub fn new(params: RouteParams) -> Result<Self, RouteError> {
        params.validate()?;
        Ok(Self { params })
    }

    /// The parameters.
    pub fn params(&self) -> &RouteParams {
        &self.params
    }

    /// Plans a route from `start` to `goal` for a vehicle of radius `radius_m` (see
    /// [`RoutePlanner::plan_until`]), with no deadline: deterministic.
    pub fn plan(
        &self,
        map: &StaticMap,
        start: &Vec3,
        goal: &Vec3,
        radius_m: f64,
    ) -> Result<GlobalRoute, RouteError> {
        self.plan_until(map, start, goal, radius_m, None)
    }

    /// Starts a resumable search from `start` to `goal` for a vehicle of radius `radius_m`;
    /// [`RouteSearch::advance`] does the work, a slice at a time.
    ///
    /// # Errors
    /// Only for invalid input: [`RouteError::InvalidParam`] for a radius outside `[0, 1000]` m,
    /// [`RouteError::NonFinitePoint`] or [`RouteError::PointOutOfScale`] for an end with a
    /// coordinate that is not finite or beyond ±1e6 m, [`RouteError::OutsideBounds`] for a
    /// start outside the map bounds. A goal outside the bounds is a verdict
    /// ([`UnreachableCause::GoalOutsideBounds`]), not an error.
    pub fn start_search(
        &self,
        map: &StaticMap,
        start: &Vec3,
        goal: &Vec3,
        radius_m: f64,
    ) -> Result<RouteSearch, RouteError> {
        let radius = check_range("radius_m", radius_m, 0.0, MAX_RADIUS_M)?;
        let start = check_point("start", start)?;
        let goal = check_point("goal", goal)?;
        if !map.contains(&start) {
            return Err(RouteError::OutsideBounds {
                which: Endpoint::Start,
                point: start,
            });
        }
        Ok(RouteSearch::new(
            self.params.clone(),
            map,
            start,
            goal,
            radius,
        ))
    }

    /// Plans a route from `start` to `goal` for a vehicle of radius `radius_m`, giving up with
    /// [`RouteError::Deadline`] once `deadline` has passed (checked every 1024 units of work):
    /// a [`RouteSearch`] run to its answer.
    ///
    /// * Both ends must be finite, within ±1e6 m, and inside the map bounds.
    /// * If the straight segment is clear at the inflated clearance `c`
    ///   ([`RouteParams::clearance_for`]), the route is that segment (no grid is built); a start
    ///   equal to the goal gives a one-point route of length 0.
    /// * Otherwise A* runs on the grids described in the crate docs. An end at least `c` from
    ///   every obstacle is joined to the nearest free cell it sees with clearance `c`; an end
    ///   inside the inflated obstacles to the nearest free cell it sees with its own clearance
    ///   (the nearest free cell, for an end inside an obstacle), within the snap radius
    ///   ([`GlobalRoute::start_inside_clearance`]). A goal so joined is not part of the route,
    ///   which ends at that cell ([`GlobalRoute::goal_gap_m`]); so is a goal closer to an
    ///   obstacle than the radius (the search's verdict
    ///   [`UnreachableCause::GoalInsideObstacle`], whose route to the nearest free point is
    ///   returned here as the route).
    /// * Errors: [`RouteError::InvalidParam`] for a radius outside `[0, 1000]` m,
    ///   [`RouteError::NonFinitePoint`], [`RouteError::PointOutOfScale`],
    ///   [`RouteError::OutsideBounds`], [`RouteError::TooManyCells`],
    ///   [`RouteError::NoFreeCell`], [`RouteError::ExpansionCap`], [`RouteError::Deadline`],
    ///   [`RouteError::Unreachable`] (with its [`UnreachableCause`]).
    pub fn plan_until(
        &self,
        map: &StaticMap,
        start: &Vec3,
        goal: &Vec3,
        radius_m: f64,
        deadline: Option<Instant>,
    ) -> Result<GlobalRoute, RouteError> {
        let mut search = self.start_search(map, start, goal, radius_m)?;
        if !map.contains(goal) {
            return Err(RouteError::OutsideBounds {
                which: Endpoint::Goal,
                point: *goal,
            });
        }
        loop {
            match search.advance(map, DEADLINE_SLICE) {
                RouteProgress::Found(route) => return Ok(route),
                RouteProgress::Unreachable(u) => {
                    return match (u.cause, u.nearest) {
                        (UnreachableCause::GoalInsideObstacle { .. }, Some(route))
                            if search.reached_target() =>
                        {
                            Ok(route)
                        }
                        (cause, _) => Err(RouteError::Unreachable {
                            expanded: search.expanded_count(),
                            clearance_m: search.clearance_m(),
                            cause,
                        }),
                    };
                }
                RouteProgress::Failed(e) => return Err(e),
                RouteProgress::Pending => {
                    if deadline.is_some_and(|d| Instant::now() >= d) {
                        return Err(RouteError::Deadline {
                            expanded: search.expanded_count(),
                        });
                    }
                }
            }
        }
    }
}
