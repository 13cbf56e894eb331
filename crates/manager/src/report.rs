//! What one cycle of the manager did ([`StepReport`]), for logs, tests and studies.

use serde::{Deserialize, Serialize};
use trust_core::{CostBreakdown, PlanError, PlanErrorKind, SearchStats, SolveStatus, State};
use trust_route::{RouteError, RouteErrorKind};

use crate::safety::Violation;

/// Stable identifier of a branch: it keeps its id while it is marched, replanned or replaced by an
/// equivalent better trajectory; new branches get fresh ids in increasing order.
pub type BranchId = u64;

/// How a branch's current trajectory was made this cycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Origin {
    /// `FwdMarch`: the main branch re-solved from the replan start, warm-started.
    Marched,
    /// `BwdReplan`: a sub-branch re-anchored at the replan start, warm-started.
    Replanned,
    /// `FwdExplore`: a new trajectory from a frontend path (cold start).
    Explored,
    /// The main branch's previous trajectory, kept because its re-solve failed while it still
    /// passed the safety check (beyond the paper).
    Kept,
}

/// One kept branch after the cycle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BranchReport {
    /// Stable id.
    pub id: BranchId,
    /// Whether it is the main branch (the one the vehicle flies).
    pub main: bool,
    /// How its trajectory was made this cycle.
    pub origin: Origin,
    /// Ranking cost `J = λ_t·H_t + λ_s·H_s + λ_e·I_e`.
    pub j: f64,
    /// The backend's cost terms.
    pub costs: CostBreakdown,
    /// How the solve ended.
    pub status: SolveStatus,
    /// Solve time (ms).
    pub solve_ms: f64,
    /// Cost evaluations of the solve.
    pub evaluation_count: usize,
    /// Whether the solve was warm-started from the branch's previous trajectory.
    pub warm_started: bool,
    /// Smallest clearance margin found by the safety check (m).
    pub min_margin_m: f64,
    /// Trajectory duration (s).
    pub duration_s: f64,
}

/// Something the manager did or decided this cycle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "event", rename_all = "snake_case")]
pub enum Event {
    /// The replan started from the measured state: it had drifted from the committed trajectory.
    Reanchored {
        /// Position drift (m).
        position_drift_m: f64,
        /// Velocity drift (m/s).
        velocity_drift_mps: f64,
    },
    /// The main branch's re-solve failed; its previous trajectory (the committed plan) still passed
    /// the safety check and was kept.
    KeptCommitted {
        /// The main branch.
        id: BranchId,
    },
    /// A new homotopy class joined the branch set.
    Added {
        /// Its id.
        id: BranchId,
    },
    /// An equivalent (same-class) branch was replaced by a better new trajectory.
    Replaced {
        /// The branch that got the new trajectory.
        id: BranchId,
        /// Its old `J`.
        j_old: f64,
        /// The new `J`.
        j_new: f64,
    },
    /// A new trajectory was equivalent to a kept branch at least as good, and discarded.
    DiscardedEquivalent {
        /// The kept branch.
        equivalent_to: BranchId,
    },
    /// Two re-solved branches had become equivalent; the worse was dropped.
    MergedEquivalent {
        /// The dropped branch.
        dropped: BranchId,
        /// The branch it was equivalent to (kept, lower `J`).
        kept: BranchId,
    },
    /// A branch (or a new candidate, `id = None`) failed the safety check and was dropped: a
    /// collision (with the static map, the map bounds or a forecast), a braking tail that is not
    /// clear, or a speed or acceleration beyond the limits — the fields say which. Despite its
    /// name it covers all three.
    DroppedCollision {
        /// The branch, or `None` for a candidate from the frontend.
        id: Option<BranchId>,
        /// The first violation (`None` when only the limits were exceeded).
        violation: Option<Violation>,
        /// The trajectory itself was clear; braking straight after its end was not
        /// ([`crate::SafetyParams::braking_tail`]).
        braking_tail: bool,
        /// Its largest speed and acceleration, when they exceeded the vehicle's limits by more
        /// than [`crate::SafetyParams::limit_tolerance`] (`None` otherwise).
        #[serde(default)]
        over_limits: Option<LimitExcess>,
    },
    /// A trajectory failed the safety check narrowly and passed after one more warm re-solve
    /// ([`crate::ManagerParams::repair_margin_m`]).
    Repaired {
        /// The branch, or `None` for a candidate from the frontend.
        id: Option<BranchId>,
    },
    /// A safe trajectory was dropped as a stub (beyond the paper): shorter than
    /// [`STUB_FRACTION`] of the horizon, not reaching the goal although the goal is farther than
    /// that time at `v_max`. The optimizer returns one when every way toward the aim violates a
    /// forecast; ranked by `J` it beats every real branch (it costs no time and keeps the
    /// terminal cost), and the vehicle hovered while a person walked into it. Without a branch
    /// the fallback moves it out of the way instead.
    DroppedStub {
        /// The branch, or `None` for a candidate from the frontend.
        id: Option<BranchId>,
        /// Its duration (s).
        duration_s: f64,
    },
    /// A branch fell off the end of the queue (more than `N`).
    DroppedPopBack {
        /// The branch.
        id: BranchId,
    },
    /// A solve returned an error (invalid input for the backend) and its branch was dropped.
    SolveFailed {
        /// The branch, or `None` for a candidate.
        id: Option<BranchId>,
        /// The error message (the error's `Display`).
        error: String,
        /// Which error it was ([`PlanError::kind`]), to decide on.
        cause: PlanErrorKind,
    },
    /// The frontend returned an error; the cycle went on with the kept branches.
    FrontendFailed {
        /// The error message (the error's `Display`).
        error: String,
        /// Which error it was ([`PlanError::kind`]), to decide on.
        cause: PlanErrorKind,
    },
    /// A homotopy check returned an error; the pair was treated as distinct.
    CheckerFailed {
        /// The error message (the error's `Display`).
        error: String,
        /// Which error it was ([`PlanError::kind`]), to decide on.
        cause: PlanErrorKind,
    },
    /// The main branch changed.
    SwitchedMain {
        /// The previous main branch (`None` on the first plan or without history).
        from: Option<BranchId>,
        /// The new one.
        to: BranchId,
        /// Why.
        reason: SwitchReason,
    },
    /// The vehicle's progress toward the goal stayed below the threshold over the window away
    /// from the goal ([`crate::progress`]): the manager escalates until [`Event::Escaped`].
    Stalled {
        /// Progress rate over the window (m/s).
        progress_mps: f64,
        /// The window (s).
        window_s: f64,
        /// Distance from the vehicle to the goal (m).
        distance_to_goal_m: f64,
    },
    /// The manager planned its global route ([`crate::routing`]): `reason` is `"first"` (no
    /// route yet toward this goal) or `"stalled"` (after [`Event::Stalled`]).
    Rerouted {
        /// Why the route was planned.
        reason: RouteReason,
        /// Its length (m).
        length_m: f64,
        /// Its vertices, start and goal included.
        vertex_count: usize,
    },
    /// The route planner failed (unreachable goal, a cap); the manager keeps its previous route,
    /// or aims at the final goal without one.
    RouteFailed {
        /// Why the route was planned.
        reason: RouteReason,
        /// The route planner's error message (the error's `Display`).
        error: String,
        /// Which error it was ([`RouteError::kind`]: a cap, no free cell, ...), to decide on.
        cause: RouteErrorKind,
    },
    /// The vehicle is at rest and its first route toward the goal is still being searched: it
    /// holds its place meanwhile ([`crate::routing`]).
    AwaitingRoute,
    /// The main branch was safe on the planner's map but its committed part or braking tail
    /// leaves the space the sensors observed free ([`crate::CommitCheck`]): it was not
    /// committed, the fallback was.
    NotKnownFree {
        /// The branch that was not committed.
        branch: BranchId,
        /// The first instant (s) of the checked stretch outside known free space (the braking
        /// tail's time when it is there).
        t: f64,
    },
    /// The route planner proved the goal cannot be reached ([`GoalUnreachable`]); the manager
    /// holds a stop at the reachable point nearest the goal and re-checks.
    GoalUnreachable {
        /// Why (sealed off, narrower than the vehicle plus its margin, ...); its `Display` is
        /// the sentence.
        cause: trust_route::UnreachableCause,
        /// The reachable point nearest the goal the manager now aims at, if any.
        #[serde(default)]
        held_at: Option<[f64; 3]>,
    },
    /// The vehicle progressed again after [`Event::Stalled`] (or came near the goal).
    Escaped {
        /// How long the stall lasted (s).
        stalled_s: f64,
        /// Distance from the vehicle to the goal (m).
        distance_to_goal_m: f64,
    },
    /// No branch was feasible: the plan is a braking fallback.
    Fallback {
        /// What it brakes along, or which way out it takes.
        along: FallbackKind,
        /// Whether it passed the safety check against the current forecasts.
        collision_free: bool,
        /// Its smallest clearance margin (m).
        min_margin_m: f64,
    },
}

/// What a braking fallback brakes along, or which way out it takes ([`Event::Fallback`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FallbackKind {
    /// The committed plan.
    Committed,
    /// A kept branch the safety pass rejected.
    Branch,
    /// An explored candidate the safety pass rejected.
    Candidate,
    /// The current velocity direction.
    Straight,
    /// A rejected trajectory flown as it is: it stays clear longer than every braking option
    /// (an obstacle coming at a vehicle at rest).
    Evade,
    /// A short manoeuvre to rest out of the way ([`crate::escape_maneuvers`]).
    Escape,
    /// A dash at 0.9 `v_max` out of the way, then braking ([`crate::dash_maneuvers`]).
    Dash,
    /// Back along the flown path to look at space the commit check refused ([`crate::retreat`]).
    Retreat,
}

impl FallbackKind {
    /// The log's word for it (`"committed"`, `"evade"`, ...).
    pub fn as_str(self) -> &'static str {
        match self {
            FallbackKind::Committed => "committed",
            FallbackKind::Branch => "branch",
            FallbackKind::Candidate => "candidate",
            FallbackKind::Straight => "straight",
            FallbackKind::Evade => "evade",
            FallbackKind::Escape => "escape",
            FallbackKind::Dash => "dash",
            FallbackKind::Retreat => "retreat",
        }
    }
}

impl std::fmt::Display for FallbackKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Why the main branch changed ([`Event::SwitchedMain`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SwitchReason {
    /// The first main branch (or one chosen without history).
    First,
    /// It beat the incumbent by the hysteresis factor.
    Better,
    /// It reaches the goal while the incumbent stops short of it.
    ReachesGoal,
    /// The incumbent was dropped.
    IncumbentDropped,
    /// While the flight is stalled, the kept branch that makes the most progress.
    Progress,
}

impl SwitchReason {
    /// The log's word for it (`"first"`, `"better"`, ...).
    pub fn as_str(self) -> &'static str {
        match self {
            SwitchReason::First => "first",
            SwitchReason::Better => "better",
            SwitchReason::ReachesGoal => "reaches_goal",
            SwitchReason::IncumbentDropped => "incumbent_dropped",
            SwitchReason::Progress => "progress",
        }
    }
}

impl std::fmt::Display for SwitchReason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Why the manager planned a route ([`Event::Rerouted`], [`Event::RouteFailed`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RouteReason {
    /// No route yet toward this goal.
    First,
    /// The progress monitor declared a stall.
    Stalled,
    /// The goal is held unreachable: the verdict is checked again.
    Recheck,
    /// An obstacle seen since (a sensed map) blocks the route ahead.
    Blocked,
}

impl RouteReason {
    /// The log's word for it (`"first"`, `"stalled"`, `"recheck"`, `"blocked"`).
    pub fn as_str(self) -> &'static str {
        match self {
            RouteReason::First => "first",
            RouteReason::Stalled => "stalled",
            RouteReason::Recheck => "recheck",
            RouteReason::Blocked => "blocked",
        }
    }
}

/// A trajectory shorter than this fraction of the planning horizon that does not reach the goal
/// is a stub ([`Event::DroppedStub`]): 0.2 s at the default 4 s.
pub const STUB_FRACTION: f64 = 0.05;

impl Event {
    /// A short tag for logs (`"switched"`, `"fallback"`, ...).
    pub fn tag(&self) -> &'static str {
        match self {
            Event::Reanchored { .. } => "reanchored",
            Event::KeptCommitted { .. } => "kept_committed",
            Event::Added { .. } => "added",
            Event::Replaced { .. } => "replaced",
            Event::DiscardedEquivalent { .. } => "discarded_equivalent",
            Event::MergedEquivalent { .. } => "merged_equivalent",
            Event::DroppedCollision { .. } => "dropped_collision",
            Event::Repaired { .. } => "repaired",
            Event::DroppedStub { .. } => "dropped_stub",
            Event::DroppedPopBack { .. } => "dropped_popback",
            Event::SolveFailed { .. } => "solve_failed",
            Event::FrontendFailed { .. } => "frontend_failed",
            Event::CheckerFailed { .. } => "checker_failed",
            Event::SwitchedMain { .. } => "switched",
            Event::Fallback { .. } => "fallback",
            Event::Stalled { .. } => "stalled",
            Event::Escaped { .. } => "escaped",
            Event::Rerouted { .. } => "rerouted",
            Event::RouteFailed { .. } => "route_failed",
            Event::GoalUnreachable { .. } => "goal_unreachable",
            Event::AwaitingRoute => "awaiting_route",
            Event::NotKnownFree { .. } => "not_known_free",
        }
    }
}

impl Event {
    /// [`Event::SolveFailed`] for `error`.
    pub fn solve_failed(id: Option<BranchId>, error: &PlanError) -> Self {
        Event::SolveFailed {
            id,
            error: error.to_string(),
            cause: error.kind(),
        }
    }

    /// [`Event::FrontendFailed`] for `error`.
    pub fn frontend_failed(error: &PlanError) -> Self {
        Event::FrontendFailed {
            error: error.to_string(),
            cause: error.kind(),
        }
    }

    /// [`Event::CheckerFailed`] for `error`.
    pub fn checker_failed(error: &PlanError) -> Self {
        Event::CheckerFailed {
            error: error.to_string(),
            cause: error.kind(),
        }
    }

    /// [`Event::RouteFailed`] for `error`, a search started for `reason`.
    pub fn route_failed(reason: RouteReason, error: &RouteError) -> Self {
        Event::RouteFailed {
            reason,
            error: error.to_string(),
            cause: error.kind(),
        }
    }
}

/// How far a dropped trajectory went beyond the vehicle's limits: the values reached and the
/// limits they were checked against.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LimitExcess {
    /// Largest speed along the trajectory (m/s).
    pub max_speed_mps: f64,
    /// The speed limit `v_max` (m/s).
    pub v_max: f64,
    /// Largest acceleration along the trajectory (m/s²).
    pub max_accel_mps2: f64,
    /// The acceleration limit `a_max` (m/s²).
    pub a_max: f64,
}

/// The frontend's part of a cycle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FrontendReport {
    /// The frontend's name.
    pub name: String,
    /// Paths it returned.
    pub path_count: usize,
    /// Paths optimized (at most `max_explored_paths`).
    pub explored_count: usize,
    /// Its counters.
    pub stats: SearchStats,
}

/// Where a cycle's time went (ms, monotonic clock).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct CycleTiming {
    /// The whole `step` call.
    pub wall_ms: f64,
    /// The frontend search.
    pub frontend_ms: f64,
    /// Sum of all trajectory solves (CPU time across threads).
    pub backend_ms: f64,
    /// Sum of homotopy checks and safety checks (CPU time across threads).
    pub checker_ms: f64,
    /// Planning the global route ([`crate::routing`]); 0 in the cycles that do not plan one.
    #[serde(default)]
    pub route_ms: f64,
    /// Trajectories optimized this cycle.
    pub solve_count: usize,
    /// The part of `backend_ms` spent on cold solves from frontend paths (FwdExplore); the rest
    /// went to warm re-solves of kept branches (FwdMarch, BwdReplan).
    #[serde(default)]
    pub cold_backend_ms: f64,
    /// The part of `solve_count` that were cold solves.
    #[serde(default)]
    pub cold_solve_count: usize,
    /// Objective evaluations (cost and gradient) summed over every solve of the cycle.
    #[serde(default)]
    pub evaluations: usize,
    /// Solves that failed the safety check narrowly and passed after one more warm re-solve
    /// ([`crate::ManagerParams::repair_margin_m`]). Every repair attempt's re-solve, passed or
    /// not, is in `solve_count` and the times.
    #[serde(default)]
    pub repair_count: usize,
    /// Time the cycle waited for the worker's results ([`crate::ManagerParams::background`]);
    /// part of `wall_ms`. A flight in real time would not have waited if the worker had
    /// finished by the cycle's start: the simulator charges `wall_ms − waited_ms` plus any
    /// lateness of the worker (`worker_ms` after it started) instead.
    #[serde(default)]
    pub waited_ms: f64,
    /// Wall time of the worker's job merged this cycle (started at the end of the previous
    /// cycle, off the cycle's critical path); 0 when none was merged. Its frontend and solve
    /// times are in `frontend_ms`, `backend_ms` and `checker_ms`.
    #[serde(default)]
    pub worker_ms: f64,
    /// Wall time of the route-search slice taken back this cycle (done between the previous
    /// cycle and this one on a thread of its own, off the critical path; [`crate::routing`]);
    /// 0 when none. The slices a cycle does itself are in `route_ms`.
    #[serde(default)]
    pub route_worker_ms: f64,
}

impl CycleTiming {
    /// Mean solve time per trajectory (ms), 0 without solves.
    pub fn solve_ms_per_trajectory(&self) -> f64 {
        if self.solve_count == 0 {
            0.0
        } else {
            self.backend_ms / self.solve_count as f64
        }
    }

    /// CPU time of the cycle per trajectory optimized, frontend and checks included (ms): the
    /// paper's "CPU time per trajectory" (Fig. baseline-test-3 (c)).
    pub fn cpu_ms_per_trajectory(&self) -> f64 {
        let cpu = self.frontend_ms + self.backend_ms + self.checker_ms;
        cpu / self.solve_count.max(1) as f64
    }
}

/// The braking fallback in use.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FallbackReport {
    /// What it brakes along (see [`Event::Fallback`]).
    pub along: FallbackKind,
    /// Whether it passed the safety check against the current forecasts.
    pub collision_free: bool,
    /// Its smallest clearance margin (m).
    pub min_margin_m: f64,
    /// How far it fails to keep the required clearance (m): `max(0, −min_margin_m)` when it is
    /// not collision-free, 0 when it is. A fallback that cannot stop clear says by how much.
    pub shortfall_m: f64,
    /// Time (s) at which it is at rest.
    pub stop_time: f64,
}

/// What one [`crate::Manager::step`] did.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StepReport {
    /// The cycle's time (s).
    pub t: f64,
    /// The state the new plan starts from (at `t + latency`).
    pub replan_start: State,
    /// The main branch, or `None` when the plan is a fallback.
    pub main: Option<BranchId>,
    /// The kept branches, in ranking order ([`crate::Branch::rank_cmp`]): those reaching the goal
    /// first, then by `J`.
    pub branches: Vec<BranchReport>,
    /// What happened, in order.
    pub events: Vec<Event>,
    /// The frontend's part (`None` if it failed or did not run this cycle).
    pub frontend: Option<FrontendReport>,
    /// Whether the straight guide toward the goal was explored because the frontend found no path
    /// ([`crate::ManagerParams::straight_guide_when_empty`]).
    pub straight_guide: bool,
    /// Where the cycle's branches aimed: the route's local goal, a corner of the route that
    /// hides what lies beyond, or the goal (`Manager`'s aim, see [`crate::Manager::step`]).
    #[serde(default = "zero_aim")]
    pub aim: [f64; 3],
    /// Where the time went.
    pub timing: CycleTiming,
    /// The braking fallback, when no branch was feasible.
    pub fallback: Option<FallbackReport>,
    /// The manager's standing verdict that the goal cannot be reached, while it holds.
    #[serde(default)]
    pub goal_unreachable: Option<GoalUnreachable>,
    /// Whether the cycle handed the next cycle's sub-branch re-solves and exploration to the
    /// worker thread as it ended ([`crate::ManagerParams::background`]); the next cycle merges
    /// them.
    #[serde(default)]
    pub worker_started: bool,
}

/// The manager's verdict that the goal cannot be reached (beyond the paper): the route planner
/// proved it ([`trust_route::RouteProgress::Unreachable`]); it stands until a re-check finds a
/// route or the goal changes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GoalUnreachable {
    /// Why; its `Display` is the sentence (a run log's `unreachable` outcome `reason`).
    pub cause: trust_route::UnreachableCause,
    /// The reachable point nearest the goal, where the manager holds a stop (`None`: where the
    /// vehicle is).
    pub held_at: Option<[f64; 3]>,
    /// When the verdict was first reached (s).
    pub since_t: f64,
}

fn zero_aim() -> [f64; 3] {
    [0.0; 3]
}

impl StepReport {
    /// The event tags in order (the run log's `events`).
    pub fn event_tags(&self) -> Vec<&'static str> {
        self.events.iter().map(Event::tag).collect()
    }

    /// The standing verdict that the goal cannot be reached, if any.
    pub fn goal_unreachable(&self) -> Option<&GoalUnreachable> {
        self.goal_unreachable.as_ref()
    }

    /// Whether the main branch changed this cycle.
    pub fn switched(&self) -> bool {
        self.events
            .iter()
            .any(|e| matches!(e, Event::SwitchedMain { .. }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failure_events_keep_the_message_and_name_the_cause() {
        let e = PlanError::invalid("start.v", f64::NAN, "a finite vector");
        let event = Event::solve_failed(Some(3), &e);
        assert!(matches!(
            event,
            Event::SolveFailed {
                cause: PlanErrorKind::InvalidInput,
                ..
            }
        ));
        // The message is the error's text, as before; the cause is added beside it.
        let json = serde_json::to_string(&event).unwrap();
        let message = serde_json::to_string(&e.to_string()).unwrap();
        assert_eq!(
            json,
            format!(
                r#"{{"event":"solve_failed","id":3,"error":{message},"cause":"invalid_input"}}"#
            )
        );
        assert_eq!(serde_json::from_str::<Event>(&json).unwrap(), event);

        let r = RouteError::ExpansionCap { cap: 50 };
        let event = Event::route_failed(RouteReason::Stalled, &r);
        let json = serde_json::to_string(&event).unwrap();
        assert!(
            json.starts_with(&format!(
                r#"{{"event":"route_failed","reason":"stalled","error":{}"#,
                serde_json::to_string(&r.to_string()).unwrap()
            )),
            "{json}"
        );
        assert!(json.ends_with(r#","cause":"expansion_cap"}"#), "{json}");
        assert_eq!(serde_json::from_str::<Event>(&json).unwrap(), event);
        assert_eq!(
            Event::checker_failed(&e),
            Event::CheckerFailed {
                error: e.to_string(),
                cause: PlanErrorKind::InvalidInput
            }
        );
        assert_eq!(Event::frontend_failed(&e).tag(), "frontend_failed");
    }
}
