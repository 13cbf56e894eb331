//! The manager's own global route (issue 19, beyond the paper): planned on the known static map
//! before the first cycle toward a goal, and again when the progress monitor declares a stall.
//!
//! [`Router`] pairs a [`RoutePlanner`] with the vehicle radius it inflates the map by. Given to
//! the manager with [`crate::Manager::set_router`], it makes the manager plan its route itself:
//!
//! * on the first cycle toward a goal (and whenever the goal moves), from the measured position;
//! * when the progress monitor reports [`crate::Event::Stalled`], from the measured position —
//!   a vehicle pushed off its route by traffic gets a route from where it is, not a projection
//!   onto a corridor it left.
//!
//! Each plan is reported as [`crate::Event::Rerouted`] (why, length, vertices) or, when
//! the route planner fails (unreachable goal, a cap), [`crate::Event::RouteFailed`] with the
//! typed error's message; the manager then keeps the previous route, or flies without one (the
//! paper's setting: every query aims at the final goal). The planning time is the cycle's
//! `route_ms` ([`crate::CycleTiming::route_ms`]).

use trust_core::{PlanError, Vec3};
use trust_geometry::StaticMap;
use trust_route::{GlobalRoute, RouteError, RouteParams, RoutePlanner};

/// A route planner and the vehicle radius it plans for ([`crate::Manager::set_router`]).
#[derive(Debug, Clone)]
pub struct Router {
    planner: RoutePlanner,
    radius_m: f64,
}

impl Router {
    /// A router planning with `params` for a vehicle of radius `radius_m`.
    ///
    /// # Errors
    /// [`PlanError::InvalidInput`] naming the invalid field of `params` (`route.<field>`) or a
    /// radius that is negative or not finite (`route.radius_m`).
    pub fn new(params: RouteParams, radius_m: f64) -> Result<Self, PlanError> {
        if !(radius_m.is_finite() && radius_m >= 0.0) {
            return Err(PlanError::invalid(
                "route.radius_m",
                radius_m,
                "a finite number >= 0",
            ));
        }
        let planner = RoutePlanner::new(params).map_err(|e| match e {
            RouteError::InvalidParam {
                field,
                value,
                expected,
            } => PlanError::invalid(&field, value, &expected),
            other => PlanError::invalid("route", other.to_string(), "valid route parameters"),
        })?;
        Ok(Self { planner, radius_m })
    }

    /// The route planner's parameters.
    pub fn params(&self) -> &RouteParams {
        self.planner.params()
    }

    /// The vehicle radius (m).
    pub fn radius_m(&self) -> f64 {
        self.radius_m
    }

    /// Plans a route from `start` to `goal` on `map`.
    ///
    /// # Errors
    /// The route planner's typed [`RouteError`].
    pub fn plan(
        &self,
        map: &StaticMap,
        start: &Vec3,
        goal: &Vec3,
    ) -> Result<GlobalRoute, RouteError> {
        self.planner.plan(map, start, goal, self.radius_m)
    }
}

/// Why the manager planned a route ([`crate::Event::Rerouted`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum RouteReason {
    /// No route yet toward this goal.
    First,
    /// The progress monitor declared a stall.
    Stalled,
}

impl RouteReason {
    pub(crate) fn as_str(self) -> &'static str {
        match self {
            RouteReason::First => "first",
            RouteReason::Stalled => "stalled",
        }
    }
}

/// Plans with `router` and reports the result as an event; the new route on success.
pub(crate) fn plan_route(
    router: &Router,
    map: &StaticMap,
    from: &Vec3,
    goal: &Vec3,
    reason: RouteReason,
) -> (Option<GlobalRoute>, crate::Event) {
    match router.plan(map, from, goal) {
        Ok(route) => {
            let event = crate::Event::Rerouted {
                reason: reason.as_str().to_owned(),
                length_m: route.length(),
                vertex_count: route.points().len(),
            };
            (Some(route), event)
        }
        Err(e) => (
            None,
            crate::Event::RouteFailed {
                reason: reason.as_str().to_owned(),
                error: e.to_string(),
            },
        ),
    }
}
