//! The manager's own global route (beyond the paper): searched on the known static map toward a
//! goal, and again when the progress monitor declares a stall or, while the goal is held
//! unreachable, every re-check period.
//!
//! [`Router`] pairs a [`RoutePlanner`] with the vehicle radius it inflates the map by and the
//! work it may do per cycle. Given to the manager with [`crate::Manager::set_router`], it makes
//! the manager route itself, from the measured position (a vehicle pushed off its route by
//! traffic gets a route from where it is):
//!
//! * a search ([`trust_route::RouteSearch`]) starts on the first cycle toward a goal (and
//!   whenever the goal moves), on a stall, and on a re-check;
//! * the cycle that starts a search does its first slice, at most [`Router::work_per_cycle`]
//!   units (most routes are found there), cut short at [`ROUTE_DEADLINE_FRACTION`] of the
//!   cycle budget under a wall-clock deadline ([`Router::slice_in_cycle`]); a vehicle at rest
//!   waiting for its first route leaves even that slice to the thread below (it holds its
//!   place meanwhile, and a first cycle on a large map stays within its budget); a search
//!   that needs more goes on off the cycle's
//!   critical path: as a cycle ends the manager hands it to a thread of its own for
//!   [`Router::work_off_cycle`] units, and the next cycle takes it back (it waits for it, so a
//!   seed is one flight; the answer never depends on the slicing; in real time it takes the
//!   answer only once due, [`crate::ManagerParams::real_time_scale`]). Without a shared map
//!   ([`crate::Manager::share_map`]) or with [`crate::ManagerParams::background`] off, each
//!   cycle does [`Router::work_per_cycle`] units itself. Meanwhile the vehicle flies the previous
//!   route, or toward the goal without one;
//! * its answer is reported as [`crate::Event::Rerouted`] (why, length, vertices),
//!   [`crate::Event::GoalUnreachable`] (the cause; the manager then plans toward the reachable
//!   point nearest the goal and holds a stop there, [`crate::StepReport::goal_unreachable`]) or
//!   [`crate::Event::RouteFailed`] (a cap, no free cell: the previous route stays).
//!
//! The work's time is the cycle's `route_ms` ([`crate::CycleTiming::route_ms`]), or for a slice
//! done between cycles `route_worker_ms` ([`crate::CycleTiming::route_worker_ms`]) of the cycle
//! that took it back.

use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use trust_core::{PlanError, Vec3};
use trust_geometry::StaticMap;
use trust_route::{GlobalRoute, RouteError, RouteParams, RoutePlanner, RouteProgress, RouteSearch};

use crate::report::{Event, RouteReason};

/// A route planner and the vehicle radius it plans for ([`crate::Manager::set_router`]).
#[derive(Debug, Clone)]
pub struct Router {
    planner: RoutePlanner,
    radius_m: f64,
    work_per_cycle: usize,
    work_off_cycle: usize,
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
        Ok(Self {
            planner,
            radius_m,
            work_per_cycle: ROUTE_WORK_PER_CYCLE,
            work_off_cycle: ROUTE_WORK_OFF_CYCLE,
        })
    }

    /// The route planner's parameters.
    pub fn params(&self) -> &RouteParams {
        self.planner.params()
    }

    /// The vehicle radius (m).
    pub fn radius_m(&self) -> f64 {
        self.radius_m
    }

    /// Plans a route from `start` to `goal` on `map` in one call (no work bound).
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

    /// Starts a resumable search from `start` to `goal` on `map` ([`RoutePlanner::start_search`]).
    ///
    /// # Errors
    /// The route planner's typed [`RouteError`] for invalid input.
    pub fn start(
        &self,
        map: &StaticMap,
        start: &Vec3,
        goal: &Vec3,
    ) -> Result<RouteSearch, RouteError> {
        self.planner.start_search(map, start, goal, self.radius_m)
    }

    /// Units of route-search work per planning cycle ([`trust_route::RouteSearch::advance`]).
    pub fn work_per_cycle(&self) -> usize {
        self.work_per_cycle
    }

    /// Sets [`Router::work_per_cycle`] (at least 1).
    pub fn with_work_per_cycle(mut self, work: usize) -> Self {
        self.work_per_cycle = work.max(1);
        self
    }

    /// A cycle's own slice of `search`: [`Router::work_per_cycle`] units, or with a wall-clock
    /// `deadline` (real time, [`crate::ManagerParams::enforce_budget`]) the same work in
    /// [`IN_CYCLE_CHUNKS`] chunks, stopping after the first chunk that ends past it. The search
    /// resumes where it stopped (its answer never depends on the slicing), so the deadline only
    /// moves work to the next slice; without one the work is the same on every machine.
    pub fn slice_in_cycle(
        &self,
        search: &mut RouteSearch,
        map: &StaticMap,
        deadline: Option<Instant>,
    ) -> RouteProgress {
        let work = self.work_per_cycle;
        let Some(deadline) = deadline else {
            return search.advance(map, work);
        };
        let chunk = work.div_ceil(IN_CYCLE_CHUNKS).max(1);
        let mut left = work;
        loop {
            let step = chunk.min(left);
            let progress = search.advance(map, step);
            left -= step;
            if !matches!(progress, RouteProgress::Pending)
                || left == 0
                || Instant::now() >= deadline
            {
                return progress;
            }
        }
    }

    /// Units of route-search work done between two cycles, off the cycle's critical path.
    pub fn work_off_cycle(&self) -> usize {
        self.work_off_cycle
    }

    /// Sets [`Router::work_off_cycle`] (at least 1).
    pub fn with_work_off_cycle(mut self, work: usize) -> Self {
        self.work_off_cycle = work.max(1);
        self
    }

    /// How often a verdict that the goal cannot be reached is re-checked (s).
    pub fn recheck_s(&self) -> f64 {
        RECHECK_S
    }
}

/// Default [`Router::work_per_cycle`]: 8 000 units (distance queries, line-of-sight queries by
/// length, and expansions). A unit costs 1–3 µs (`cargo run --release -p trust-route --example
/// route_timing`), so a slice takes about 8–25 ms of the 50 ms cycle budget; the suite's U-trap
/// route arrives in about 8 cycles, a goal sealed in a 30 × 20 × 6 m box gets its verdict in
/// about 10 (decision 0019).
pub const ROUTE_WORK_PER_CYCLE: usize = 8_000;

/// The chunks a cycle's own slice is cut into under a wall-clock deadline
/// ([`Router::slice_in_cycle`]): 32, so the deadline is overrun by at most one chunk (250 units,
/// 0.25–0.75 ms at 1–3 µs a unit, when the thread is not descheduled).
pub const IN_CYCLE_CHUNKS: usize = 32;

/// The share of the cycle budget a cycle's own route slice may take under a wall-clock
/// deadline ([`crate::ManagerParams::enforce_budget`]): the route comes first in a cycle, the
/// frontend and the solves need the rest ([`crate::SOLVE_DEADLINE_FRACTION`] of it).
pub const ROUTE_DEADLINE_FRACTION: f64 = 0.3;

/// Default [`Router::work_off_cycle`]: 24 000 units, 15–70 ms on a thread of its own between two
/// cycles of a 100 ms period (a unit costs 0.6–3 µs), so a search never makes a cycle late at
/// `cpu_scale` 1; a goal sealed in an E4-sized box gets its verdict in about 0.6 s instead of
/// 1.5 s with the in-cycle slices alone (decision 0019).
pub const ROUTE_WORK_OFF_CYCLE: usize = 24_000;

/// How often a standing verdict that the goal cannot be reached is re-checked (s): a new search
/// from the vehicle's position, in case the map or the obstacles changed.
pub const RECHECK_S: f64 = 2.0;

/// Least time between two route searches started because an obstacle seen since blocks the
/// route ahead (s): a sensed map changes every scan, and a route that grazes a noisy surface
/// would otherwise be searched again every cycle.
pub const BLOCKED_REROUTE_S: f64 = 0.5;

/// Where a search under way is: with the manager, on a thread doing a slice of it between two
/// cycles, or back from a slice whose answer is not due yet
/// ([`crate::ManagerParams::real_time_scale`]).
pub(crate) enum SearchSlot {
    /// With the manager, between slices (boxed: a search is large, a handle small).
    Here(Box<RouteSearch>),
    /// On its thread since the flight time `sent_at` (s).
    Away {
        handle: JoinHandle<Slice>,
        sent_at: f64,
    },
    /// Back from its thread, its answer due at the flight time `due` (s).
    Done { slice: Slice, due: f64 },
}

/// A slice done between cycles: the search, its progress and the slice's wall time.
pub(crate) struct Slice {
    pub(crate) search: Box<RouteSearch>,
    pub(crate) progress: RouteProgress,
    pub(crate) elapsed: Duration,
}

/// What [`SearchSlot::take_back`] found.
pub(crate) enum TakenBack {
    /// The search was here.
    Here(Box<RouteSearch>),
    /// A slice done away, its answer due by now.
    Sliced(Slice),
    /// A slice whose answer is not due yet: the slot to keep.
    NotYet(SearchSlot),
    /// The slice panicked: the search is lost (the next stall or re-check starts another).
    Lost,
}

impl SearchSlot {
    /// Sends `search` to a thread of its own for `work` units on `map` at the flight time
    /// `sent_at`; `None` if the thread could not be started (the search is then lost: the next
    /// stall or re-check starts another).
    pub(crate) fn away(
        mut search: Box<RouteSearch>,
        map: Arc<StaticMap>,
        work: usize,
        sent_at: f64,
    ) -> Option<Self> {
        std::thread::Builder::new()
            .name("trust-manager-route".into())
            .spawn(move || {
                let started = Instant::now();
                let progress = search.advance(&map, work);
                Slice {
                    search,
                    progress,
                    elapsed: started.elapsed(),
                }
            })
            .ok()
            .map(|handle| SearchSlot::Away { handle, sent_at })
    }

    /// Takes the search back at the flight time `now`, waiting for a slice done away. With a
    /// real-time scale `x` ([`crate::ManagerParams::real_time_scale`]) a slice's answer is due
    /// `x` times its wall time after it was sent away; without one it is due at once.
    pub(crate) fn take_back(self, now: f64, real_time_scale: Option<f64>) -> TakenBack {
        let slice = match self {
            SearchSlot::Here(search) => return TakenBack::Here(search),
            SearchSlot::Done { slice, due } => return Self::when_due(slice, due, now),
            SearchSlot::Away { handle, sent_at } => match handle.join() {
                Ok(slice) => (slice, sent_at),
                Err(_) => return TakenBack::Lost,
            },
        };
        let (slice, sent_at) = slice;
        let due = real_time_scale.map_or(f64::NEG_INFINITY, |x| {
            sent_at + slice.elapsed.as_secs_f64() * x
        });
        Self::when_due(slice, due, now)
    }

    fn when_due(slice: Slice, due: f64, now: f64) -> TakenBack {
        if due <= now {
            TakenBack::Sliced(slice)
        } else {
            TakenBack::NotYet(SearchSlot::Done { slice, due })
        }
    }
}

/// The event for a new route.
pub(crate) fn rerouted(reason: RouteReason, route: &GlobalRoute) -> Event {
    Event::Rerouted {
        reason,
        length_m: route.length(),
        vertex_count: route.points().len(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use trust_route::scenes::{E4_START_GOAL, e4_like};

    fn ends() -> (Vec3, Vec3) {
        let [s, g] = E4_START_GOAL;
        (Vec3::from(s), Vec3::from(g))
    }

    fn finish(search: &mut RouteSearch, map: &StaticMap) -> RouteProgress {
        loop {
            match search.advance(map, ROUTE_WORK_OFF_CYCLE) {
                RouteProgress::Pending => continue,
                answer => return answer,
            }
        }
    }

    #[test]
    fn a_passed_deadline_stops_the_slice_after_one_chunk_and_changes_no_answer() {
        let map = e4_like(3, true).unwrap();
        let (s, g) = ends();
        let router = Router::new(RouteParams::default(), 0.3).unwrap();
        let chunk = router.work_per_cycle().div_ceil(IN_CYCLE_CHUNKS);

        let mut cut = router.start(&map, &s, &g).unwrap();
        let first = router.slice_in_cycle(&mut cut, &map, Some(Instant::now()));
        assert_eq!(first, RouteProgress::Pending);
        assert_eq!(cut.work_done(), chunk);

        let mut whole = router.start(&map, &s, &g).unwrap();
        let unguarded = router.slice_in_cycle(&mut whole, &map, None);
        if unguarded == RouteProgress::Pending {
            assert_eq!(whole.work_done(), router.work_per_cycle());
        }
        let (a, b) = (finish(&mut cut, &map), finish(&mut whole, &map));
        assert!(matches!(a, RouteProgress::Found(_)), "{a:?}");
        assert_eq!(a, b);
        assert_eq!(cut.work_done(), whole.work_done());
    }

    #[test]
    fn a_far_deadline_does_the_whole_slice() {
        let map = e4_like(3, true).unwrap();
        let (s, g) = ends();
        let router = Router::new(RouteParams::default(), 0.3)
            .unwrap()
            .with_work_per_cycle(3_000);
        let far = Instant::now() + Duration::from_secs(3600);
        let mut guarded = router.start(&map, &s, &g).unwrap();
        let mut plain = router.start(&map, &s, &g).unwrap();
        let a = router.slice_in_cycle(&mut guarded, &map, Some(far));
        let b = router.slice_in_cycle(&mut plain, &map, None);
        assert_eq!(a, b);
        assert_eq!(guarded.work_done(), plain.work_done());
    }
}
