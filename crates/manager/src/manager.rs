//! [`Manager`]: Algorithm 1 of the paper, one cycle per [`Manager::step`].

use std::sync::Arc;
use std::time::{Duration, Instant};

use rand::SeedableRng;
use rayon::prelude::*;
use trust_core::{
    Forecast, GuidePath, HomotopyChecker, InitialGuess, Limits, PathFrontend, PathQuery, PlanError,
    PolyTraj, RankingWeights, Rng, Scene, Solution, State, StaticMap, TrajRequest,
    TrajectoryBackend, Vec3, check_finite, check_finite_vec, straight_end,
};

use crate::ManagerParams;
use crate::brake::{brake_along, brake_straight, dash_maneuvers, escape_maneuvers};
use crate::params::SOLVE_DEADLINE_FRACTION;
use crate::progress::ProgressMonitor;
use crate::report::{
    BranchId, BranchReport, CycleTiming, Event, FallbackKind, FallbackReport, FrontendReport,
    LimitExcess, Origin, STUB_FRACTION, StepReport, SwitchReason,
};
use crate::safety::{
    SafetyVerdict, assess_trajectory, check_trajectory, forecasts_near, window_bounds,
};
use trust_route::{GlobalRoute, RoutePoint, RouteProgress, UnreachableCause};

use crate::report::RouteReason;
use crate::routing::{
    BLOCKED_REROUTE_S, ROUTE_DEADLINE_FRACTION, Router, SearchSlot, TakenBack, rerouted,
};

mod worker;
use worker::{Job, JobInput, JobOutput};

/// One kept trajectory branch.
#[derive(Debug, Clone, PartialEq)]
pub struct Branch {
    /// Stable id ([`BranchId`]).
    pub id: BranchId,
    /// The backend's solution (trajectory, cost terms, statistics).
    pub solution: Solution,
    /// Ranking cost `J`.
    pub j: f64,
    /// Whether the trajectory ends at the goal (within [`ManagerParams::goal_reached_m`]). Ranks
    /// before `J`: a branch that reaches the goal always outranks one that stops short
    /// ([`Branch::outranks`]).
    pub reaches_goal: bool,
    /// Distance (m) from the trajectory's end to the goal: how short of the goal it stops. While
    /// the flight is stalled ([`crate::progress`]) it ranks before `J`.
    pub shortfall_m: f64,
    /// How the trajectory was made in the last cycle.
    pub origin: Origin,
    /// Whether that solve was warm-started.
    pub warm_started: bool,
    /// Its safety check in the last cycle.
    pub verdict: SafetyVerdict,
}

impl Branch {
    /// The branch's trajectory.
    pub fn traj(&self) -> &PolyTraj {
        &self.solution.traj
    }

    /// The ranking order: branches that reach the goal first, then (`by_progress`, while the
    /// flight is stalled) those ending nearer the goal, then ascending `J`, then id.
    ///
    /// `J = λ_t·H_t + λ_s·H_s + λ_e·I_e` alone cannot decide between a branch that reaches the
    /// goal and one that stops short: with the paper's `λ_s = 1/v_max` a branch standing still
    /// `d` metres short costs `J ≈ d/v_max`, while any branch flying there costs at least as much
    /// (`H_t ≥ d/v_max` plus the time to speed up and brake). The stopped branch then wins every
    /// cycle and the hysteresis protects it: E4, seed 7301, hovered 12.8 m before the goal for
    /// 30 s. Reaching the goal therefore ranks first.
    pub fn rank_cmp(&self, other: &Branch, by_progress: bool) -> std::cmp::Ordering {
        let progress = match by_progress {
            true => self.shortfall_m.total_cmp(&other.shortfall_m),
            false => std::cmp::Ordering::Equal,
        };
        other
            .reaches_goal
            .cmp(&self.reaches_goal)
            .then(progress)
            .then(self.j.total_cmp(&other.j))
            .then(self.id.cmp(&other.id))
    }

    /// Whether `self` ranks strictly before `other`, ignoring ids ([`Branch::rank_cmp`]).
    pub fn outranks(&self, other: &Branch, by_progress: bool) -> bool {
        match (self.reaches_goal, other.reaches_goal) {
            (true, false) => true,
            (false, true) => false,
            (false, false) if by_progress && self.shortfall_m != other.shortfall_m => {
                self.shortfall_m < other.shortfall_m
            }
            _ => self.j < other.j,
        }
    }

    fn report(&self, main: bool) -> BranchReport {
        BranchReport {
            id: self.id,
            main,
            origin: self.origin,
            j: self.j,
            costs: self.solution.costs,
            status: self.solution.stats.status,
            solve_ms: ms(self.solution.stats.elapsed),
            evaluation_count: self.solution.stats.evaluation_count,
            warm_started: self.warm_started,
            min_margin_m: self.verdict.min_margin_m(),
            duration_s: self.solution.traj.duration(),
        }
    }
}

/// A solved (or failed) candidate of this cycle.
struct Candidate {
    result: Result<(Solution, SafetyVerdict), PlanError>,
    check_time: Duration,
    /// The other solve of a repair attempt ([`ManagerParams::repair_margin_m`]): the narrowly
    /// unsafe first solve when the re-solve passed and replaced it, the failed re-solve when it
    /// did not. Its solve time, evaluations and check time count in the cycle's timing.
    other_solve: Option<(Duration, usize, Duration)>,
    /// The re-solve of a repair attempt passed and is this candidate.
    repaired: bool,
}

/// A route vertex turning by more than this (60°, over [`CORNER_SPAN_S`]) is aimed at before the
/// route's local goal
/// ([`trust_route::GlobalRoute::first_sharp_turn`]; beyond the paper).
const SHARP_TURN_RAD: f64 = std::f64::consts::FRAC_PI_3;

/// The span over which a route's turn is measured for [`SHARP_TURN_RAD`] (s of flight at
/// `v_max`): the route's direction 0.4 s before a vertex against 0.4 s after it. A turn that
/// tight, within about one of the presets' 0.7 s trajectory pieces, is one the local planner
/// cuts.
const CORNER_SPAN_S: f64 = 0.4;

/// What a vehicle at `from` (arc length `s0` on `route`) aims at when the route turns sharply
/// at `corner` before the aim `ahead`: the farthest route point up to `ahead` in sight at
/// `clearance` when that lies more than `reach` past the corner, else the corner itself (the
/// corner hides the route beyond it: a shaft's entrance).
#[allow(clippy::too_many_arguments)]
fn aim_past_corner(
    route: &GlobalRoute,
    map: &StaticMap,
    from: &Vec3,
    s0: f64,
    corner: RoutePoint,
    ahead: RoutePoint,
    clearance: f64,
    reach: f64,
) -> RoutePoint {
    let seen = route.last_in_sight(map, from, s0, ahead, clearance);
    // A point short of `ahead` was checked in sight; `ahead` itself may come back unseen when
    // the vehicle is off its route.
    let in_sight = seen.s < ahead.s || map.segment_clear(from, &seen.point, clearance);
    if seen.s > corner.s + reach && in_sight {
        seen
    } else {
        corner
    }
}

/// Whether `v` failed by at most `margin` (m) of clearance, or only on the limits.
fn narrowly_unsafe(v: &SafetyVerdict, margin: f64) -> bool {
    !v.safe
        && match &v.violation {
            Some(x) => x.margin_m >= -margin,
            None => true,
        }
}

/// How long every main branch may be refused by the commit check with the vehicle at rest
/// before the flight counts as stalled, as a fraction of the progress monitor's window: ¼
/// (0.5 s at E4's 4 s horizon).
const REFUSED_STALL_FRACTION: f64 = 0.25;

/// The multi-branch spatio-temporal trajectory manager (paper Sec. III-A, Algorithm 1), generic
/// over the frontend `F`, the backend `B` and the homotopy checker `H`.
///
/// It keeps up to `N` branches of distinct spatio-temporal homotopy sorted by the ranking cost
/// `J = λ_t·H_t + λ_s·H_s + λ_e·I_e` — after whether they reach the goal, which ranks first
/// ([`Branch::rank_cmp`], beyond the paper) — and commits the main branch as the plan the vehicle
/// flies. Each [`Manager::step`] is one cycle:
///
/// 0. **Progress.** The progress monitor ([`crate::progress`]) reports `Stalled` when the
///    vehicle's progress toward the goal stays below its threshold away from the goal, and
///    `Escaped` when it moves on; while stalled, FwdExplore runs every cycle with twice
///    [`ManagerParams::max_explored_paths`], branches ending nearer the goal rank first, and the
///    best-ranked branch leads without hysteresis (beyond the paper).
/// 1. **Replan start.** The new trajectories start from the state the vehicle will be in when they
///    take effect: the committed plan at `now + latency` (so consecutive plans join with continuous
///    position, velocity and acceleration). If the measured state has drifted from the committed
///    plan by more than [`crate::ReanchorParams`], the replan starts instead from the measured state
///    propagated over the latency at constant acceleration (`Reanchored` event): continuity is then
///    given up in favour of the truth.
/// 2. **FwdMarch** of the main branch and **BwdReplan** of every sub-branch: warm-started re-solves
///    from the replan start (the main branch's free terminal moves on toward the goal as the goal
///    guidance surface shrinks), run in parallel with **FwdExplore**: the frontend's paths from the
///    replan start, each solved cold. With `history = false` only FwdExplore runs.
/// 3. **Safety.** Every result is checked continuously in time ([`check_trajectory`]) against the
///    static map, the bounds and the *current* forecasts, and against the limits; a failing branch
///    is dropped (`DroppedCollision`).
/// 4. **Distinct classes.** Re-solved branches that slid into the same class as a better one are
///    merged (`MergedEquivalent`); then **AddNewBranch** for each explored trajectory, in the frontend's order: if the checker finds
///    it equivalent to a kept branch ranked at least as well it is discarded; if it is equivalent
///    only to worse branches it replaces the best-ranked of them (which keeps its id); otherwise it
///    is added. Beyond `N` branches the worst is dropped (`PopBack`), never the main branch.
/// 5. **Main branch.** The incumbent stays main unless a challenger's excess cost is below the
///    hysteresis factor times the incumbent's, or the incumbent was dropped, or it stops short of
///    the goal while a branch reaches it (the hysteresis compares branches of one tier only).
/// 6. **Fallback.** With no feasible branch the plan is a braking trajectory ([`crate::brake`]):
///    along the committed plan (or along a rejected trajectory of this cycle, or straight), the first
///    that passes the safety check against the current forecasts, else the one with the largest
///    margin. The report says which and whether it is collision-free; it is collision-free for as
///    long as the forecasts hold only in the first case.
///
/// Optimizations of one cycle run in parallel on the current rayon pool; results are merged in a
/// fixed order (warm branches by rank, then explored paths by the frontend's order), so the outcome
/// does not depend on the number of threads or their timing as long as no time budget binds (set
/// [`ManagerParams::enforce_budget`] to `false` and give the frontend count-based budgets for
/// bit-reproducible runs).
pub struct Manager<F, B, H> {
    frontend: Arc<F>,
    backend: Arc<B>,
    checker: H,
    limits: Limits,
    params: ManagerParams,
    rng: Rng,
    branches: Vec<Branch>,
    main: Option<BranchId>,
    committed: Option<PolyTraj>,
    /// The kind of fallback [`Manager::committed`] is, if it is one (`None` once a branch is
    /// committed): the next fallback may continue it ([`Manager::fallback_options`]).
    committed_fallback: Option<FallbackKind>,
    /// The path the vehicle flew ([`crate::retreat`]).
    flown: crate::FlownPath,
    /// Since when (the replan start's time) every main branch has been refused by the commit
    /// check with the vehicle at rest.
    refused_since: Option<f64>,
    next_id: BranchId,
    cycle_count: u64,
    progress: ProgressMonitor,
    route: Option<GlobalRoute>,
    router: Option<Router>,
    /// The goal the last route was planned toward (planned or failed), so a failing plan is not
    /// retried every cycle.
    routed_goal: Option<Vec3>,
    /// When the last route was planned (or failed), s.
    routed_at: f64,
    /// The standing verdict that the goal cannot be reached ([`crate::GoalUnreachable`]).
    unreachable: Option<crate::GoalUnreachable>,
    /// Guide paths of the last exploration still to be solved
    /// ([`ManagerParams::cold_solves_per_cycle`]).
    deferred_guides: Vec<GuidePath>,
    /// The route search under way, why it started, and where it is (here, or away for a slice
    /// between cycles).
    route_search: Option<(RouteReason, SearchSlot)>,
    /// The map the search under way runs on when its commit check gives one
    /// ([`crate::CommitCheck::route_map`]; else the scene's).
    route_map: Option<Arc<StaticMap>>,
    /// The static map the scenes are built on, shared with the worker
    /// ([`Manager::share_map`]).
    shared_map: Option<Arc<StaticMap>>,
    /// The worker's job under way ([`ManagerParams::background`]).
    job: Option<Job>,
    /// The time of the last cycle (s): the next cycle is predicted one period later.
    last_now: Option<f64>,
    /// What the committed part of a plan must pass beyond the safety check
    /// ([`Manager::set_commit_check`]).
    commit_check: Option<Arc<dyn crate::CommitCheck>>,
}

impl<F, B, H> std::fmt::Debug for Manager<F, B, H> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Manager")
            .field("limits", &self.limits)
            .field("params", &self.params)
            .field("branches", &self.branches.len())
            .field("main", &self.main)
            .finish_non_exhaustive()
    }
}

impl<F: PathFrontend + 'static, B: TrajectoryBackend + 'static, H: HomotopyChecker>
    Manager<F, B, H>
{
    /// A manager with no branches and no plan yet.
    ///
    /// # Errors
    /// [`PlanError::InvalidInput`] naming the invalid field of `limits` or `params`.
    pub fn new(
        frontend: F,
        backend: B,
        checker: H,
        limits: Limits,
        params: ManagerParams,
    ) -> Result<Self, PlanError> {
        limits.validate()?;
        params.validate()?;
        Ok(Manager {
            frontend: Arc::new(frontend),
            backend: Arc::new(backend),
            checker,
            limits,
            rng: Rng::seed_from_u64(params.seed),
            params,
            branches: Vec::new(),
            main: None,
            committed: None,
            committed_fallback: None,
            flown: crate::FlownPath::default(),
            refused_since: None,
            next_id: 0,
            progress: ProgressMonitor::default(),
            route: None,
            router: None,
            routed_goal: None,
            routed_at: f64::NEG_INFINITY,
            unreachable: None,
            deferred_guides: Vec::new(),
            route_search: None,
            route_map: None,
            cycle_count: 0,
            shared_map: None,
            job: None,
            last_now: None,
            commit_check: None,
        })
    }

    /// Shares the static map every scene of this flight is built on, so that the worker of
    /// [`ManagerParams::background`] can read it after the cycle that started it has returned.
    /// A cycle whose scene is built on another map solves everything itself.
    pub fn share_map(&mut self, map: Arc<StaticMap>) {
        self.shared_map = Some(map);
    }

    /// Sets (or with `None` clears) the check the committed part of every plan must pass beyond
    /// the safety check (FASTER's rule for a sensed map: what the vehicle commits to fly lies in
    /// observed free space, [`crate::CommitCheck`]). Without one, every cycle is as before.
    pub fn set_commit_check(&mut self, check: Option<Arc<dyn crate::CommitCheck>>) {
        self.commit_check = check;
    }

    /// The parameters.
    pub fn params(&self) -> &ManagerParams {
        &self.params
    }

    /// The vehicle's limits.
    pub fn limits(&self) -> &Limits {
        &self.limits
    }

    /// The kept branches, in ranking order ([`Branch::rank_cmp`]).
    pub fn branches(&self) -> &[Branch] {
        &self.branches
    }

    /// The main branch's id (`None` before the first plan and while braking).
    pub fn main(&self) -> Option<BranchId> {
        self.main
    }

    /// The committed plan: the main branch's trajectory or the braking fallback.
    pub fn plan(&self) -> Option<&PolyTraj> {
        self.committed.as_ref()
    }

    /// Sets (or with `None` clears) the global route the branches follow (issue 19, beyond the
    /// paper). With a route, the frontend's query, the straight guide and the backend's terminal
    /// cost aim at the route's local goal — where the route leaves the ball of radius
    /// `T_h·v_max` around the replan start's projection on it — instead of the final goal, and
    /// progress is measured along the route; near the route's end the aim is the final goal.
    /// Without a route every cycle is exactly as before (the paper's setting).
    pub fn set_route(&mut self, route: Option<GlobalRoute>) {
        self.route = route;
    }

    /// Gives the manager a route planner (or with `None` takes it away): it then plans its own
    /// route before the first cycle toward a goal and again on a stall ([`crate::routing`]),
    /// replacing any route given with [`Manager::set_route`] at those moments.
    pub fn set_router(&mut self, router: Option<Router>) {
        self.router = router;
        self.routed_goal = None;
        self.route_search = None;
        self.unreachable = None;
    }

    /// The route planner, if any ([`Manager::set_router`]).
    pub fn router(&self) -> Option<&Router> {
        self.router.as_ref()
    }

    /// The global route, if any ([`Manager::set_route`]).
    pub fn route(&self) -> Option<&GlobalRoute> {
        self.route.as_ref()
    }

    /// Where this cycle's branches aim from `from`: the route's local goal
    /// ([`Manager::set_route`]), or a sharp corner before it that hides the route beyond
    /// ([`aim_past_corner`]), or `goal` without a route, near the route's end, or when the
    /// route cannot be queried. While `stalled`, the farthest route point before it that is in
    /// sight from `from` ([`trust_route::GlobalRoute::last_in_sight`]). Sight is judged on the
    /// route's own map when the sensed map's policy gave it one ([`crate::CommitCheck::route_map`]:
    /// a rolling window forgets the walls it has left, the route's map remembers them), else on
    /// `map`.
    fn aim(&self, from: &Vec3, goal: &Vec3, stalled: bool, map: &StaticMap) -> Vec3 {
        let Some(route) = &self.route else {
            return *goal;
        };
        let map = self.route_map.as_deref().unwrap_or(map);
        let horizon_m = self.params.horizon_s * self.limits.v_max;
        let Ok(s0) = route.progress(from) else {
            return *goal;
        };
        let Ok(local) = route.local_goal_from(s0, horizon_m) else {
            return *goal;
        };
        let ahead = if route.length() - local.s > 1e-9 {
            local
        } else {
            RoutePoint {
                s: route.length(),
                point: *goal,
            }
        };
        // A sharp corner before the local goal is aimed at first when it hides what lies
        // beyond (a shaft entrance: the pieces of a trajectory aimed beyond it cut through the
        // slab). The vehicle is at the corner once within its clearance of it; then the aim
        // moves on. A corner that hides nothing — the route beyond it is in sight at the
        // safety clearance — is not: aimed at, the plan ended at rest on it (a forest's route
        // turning by 61° stopped the vehicle there, 10 m/s to 1.4 m/s).
        let reach = route.clearance_m().max(self.params.goal_reached_m);
        // The turn is measured over the distance flown in `CORNER_SPAN_S`: a hairpin of short
        // segments (a sensed U-trap's route out of its pocket) is a corner too.
        let span = (CORNER_SPAN_S * self.limits.v_max).max(reach);
        let target = match route.first_sharp_turn(s0 + reach, ahead.s, SHARP_TURN_RAD, span) {
            Some(corner) => aim_past_corner(
                route,
                map,
                from,
                s0,
                corner,
                ahead,
                self.params.safety.static_clearance_m,
                reach,
            ),
            None => ahead,
        };
        if !stalled {
            return target.point;
        }
        // Stalled: a gentler corner can hide the aim too. An 18 m/s vehicle at rest 62 m before
        // a building corner turning by 29° aimed 10 m past it along the face, every trajectory
        // cut the building, and it hovered 15–60 s (holdout, a 900 m trip).
        let sight = 0.5 * self.params.safety.static_clearance_m;
        route.last_in_sight(map, from, s0, target, sight).point
    }

    /// The route from `from`'s projection on it to the aim ([`Manager::aim`]) as a guide path
    /// starting at `from`; `None` without a route.
    fn route_guide(&self, from: &Vec3, aim: &Vec3) -> Option<GuidePath> {
        let route = self.route.as_ref()?;
        let s0 = route.progress(from).ok()?;
        let mut points = vec![*from];
        let mut s = 0.0;
        for w in route.points().windows(2) {
            s += (w[1] - w[0]).norm();
            if s <= s0 {
                continue;
            }
            if (w[1] - from).norm() >= (aim - from).norm() || (w[1] - aim).norm() < 1e-9 {
                break;
            }
            points.push(w[1]);
        }
        points.push(*aim);
        points.dedup_by(|a, b| (*a - *b).norm() < 1e-9);
        GuidePath::new(points).ok()
    }

    /// Progress toward `goal` at `p` (m; larger is nearer): the arc length along the route, or
    /// minus the distance to the goal without a route.
    fn progress_at(&self, p: &Vec3, goal: &Vec3) -> f64 {
        match self.route.as_ref().map(|r| r.progress(p)) {
            Some(Ok(s)) => s,
            _ => -(p - goal).norm(),
        }
    }

    /// Forgets every branch and the plan (a new flight); the random stream continues.
    pub fn reset(&mut self) {
        // A job under way is left to finish on its own; its results are not merged.
        self.job = None;
        self.last_now = None;
        self.cycle_count = 0;
        self.progress.reset();
        self.routed_goal = None;
        self.route_search = None;
        self.unreachable = None;
        self.deferred_guides.clear();
        self.branches.clear();
        self.main = None;
        self.committed = None;
        self.committed_fallback = None;
        self.flown.clear();
        self.refused_since = None;
    }

    /// Runs one cycle of Algorithm 1 at time `now` with the measured vehicle state (taken at
    /// `now`), toward `goal`, seeing `scene` (the static map and the current forecasts).
    ///
    /// Planning failures are reported in the [`StepReport`] (events, fallback); the committed plan
    /// afterwards is [`Manager::plan`].
    ///
    /// A goal outside the map bounds or inside a static obstacle is not an error: the report's
    /// [`StepReport::goal_unreachable`] says why, and the vehicle holds a stop short of it
    /// (the farthest point toward it in sight, [`HOLD_CLEARANCE_M`] from the static map).
    ///
    /// # Errors
    /// Only for invalid input: non-finite `now`, state or goal (named).
    pub fn step(
        &mut self,
        now: f64,
        measured: &State,
        goal: &Vec3,
        scene: &Scene<'_>,
    ) -> Result<StepReport, PlanError> {
        let mut spans = Spans::start();
        check_step_input(now, measured, goal)?;
        let seen = self.planned_forecasts(now, scene);
        let planned = Scene {
            forecasts: &seen,
            ..*scene
        };
        let scene = &planned;
        let mut cycle = self.begin_toward(now, measured, goal, scene, &mut spans);
        let target = cycle.goal;
        let goal = &target;

        // Algorithm 1, lines 5–8: FwdMarch of the main branch and BwdReplan of the sub-branches,
        // in parallel with FwdExplore.
        let warm = self.warm_branches();
        let mut aim = self.aim(&cycle.start.p, goal, cycle.stalled, scene.map);
        let merged = self.merge_job(&mut cycle, &mut aim, &mut spans);
        let from_worker = merged.is_some();
        let (mut explored, resolved) = match merged {
            Some(out) => self.solve_main_with(out, &cycle, &aim, scene, &warm, &mut spans),
            None => self.solve_in_parallel(&cycle, &aim, scene, &warm, &mut spans),
        };
        self.deferred_guides = std::mem::take(&mut explored.deferred);
        if let Some(error) = explored.frontend_error {
            cycle.events.push(Event::frontend_failed(&error));
        }

        // The safety pass over the re-solved branches, then one branch per homotopy class.
        let kept = self.keep_resolved(warm, resolved, &mut cycle, scene, &mut spans);
        let mut kept = spans.time(Span::Checks, || self.dedupe(kept, scene, &mut cycle.events));

        // Algorithm 1, line 9: AddNewBranch (with PopBack) for each explored trajectory that
        // passes the safety pass.
        for cand in explored.candidates {
            self.explored_branch(&mut kept, cand, &mut cycle, scene, &mut spans);
        }

        // The main branch (hysteresis), PopBack protecting it, and the fallback without one.
        let main = self.select_checked_main(&mut kept, &mut cycle, scene, from_worker, &mut spans);
        pop_back(&mut kept, self.params.max_branches, main, &mut cycle.events);
        let fallback = self.commit(main, &kept, &mut cycle, scene, &mut spans);
        self.branches = kept;
        let worker_started = self.start_job(now, &cycle, scene);
        let route_away = self.send_route_away(now, &spans, scene);
        Ok(StepReport {
            t: now,
            replan_start: cycle.start,
            main: self.main,
            branches: self
                .branches
                .iter()
                .map(|b| b.report(Some(b.id) == self.main))
                .collect(),
            events: cycle.events,
            frontend: explored.frontend,
            straight_guide: explored.straight_guide,
            aim: [aim.x, aim.y, aim.z],
            timing: spans.finish(),
            fallback,
            goal_unreachable: self.unreachable.clone(),
            worker_started: worker_started || route_away,
        })
    }

    /// Starts the cycle toward `goal`: the verdict on a goal outside the bounds or inside a
    /// static obstacle, the route, and the point the cycle aims at ([`Cycle::goal`]: the goal,
    /// the held stop short of an unreachable one, or the vehicle's own place while it waits for
    /// its first route).
    fn begin_toward(
        &mut self,
        now: f64,
        measured: &State,
        goal: &Vec3,
        scene: &Scene<'_>,
        spans: &mut Spans,
    ) -> Cycle {
        // A goal outside the bounds or inside a static obstacle is a verdict, checked every
        // cycle: the vehicle holds a stop short of it (no route search is needed to know).
        let invalid_goal = invalid_goal_cause(goal, scene);
        let newly_invalid = match &invalid_goal {
            Some(cause) => self.hold_short_of_invalid_goal(cause, measured, goal, scene),
            None => {
                if self.router.is_none() {
                    // Without a router the only verdict is an invalid goal's.
                    self.unreachable = None;
                }
                false
            }
        };
        // With a standing verdict that the goal cannot be reached, the cycle plans toward the
        // reachable point nearest it (a held stop); the route keeps being re-checked.
        let target = self.target(goal);
        let mut cycle = self.begin_cycle(now, measured, &target, spans.started);
        if let Some(u) = self.unreachable.as_ref().filter(|_| newly_invalid) {
            cycle.events.push(Event::GoalUnreachable {
                cause: u.cause,
                held_at: u.held_at,
            });
        }
        if invalid_goal.is_none() {
            self.update_route(&mut cycle, measured, goal, scene, spans);
        }
        // A vehicle at rest waits where it is for its first route toward a new goal (a few
        // cycles): flown toward the goal meanwhile it would head into the trap the route is
        // for. It still plans (to hold its place), so it still gets out of a moving obstacle's
        // way.
        let target = if self.awaiting_first_route(measured) {
            cycle.events.push(Event::AwaitingRoute);
            measured.p
        } else {
            target
        };
        cycle.goal = target;
        cycle
    }

    /// The forecasts a cycle at `now` plans against: `scene`'s with their growth stopped after
    /// `forecast_growth_s`, and their mirror images at the walls.
    fn planned_forecasts(&self, now: f64, scene: &Scene<'_>) -> Vec<Forecast> {
        let growth_s = self.params.forecast_growth();
        let seen: Vec<Forecast> = scene
            .forecasts
            .iter()
            .map(|f| f.with_growth_for(growth_s))
            .collect();
        if self.params.wall_images {
            with_wall_images(
                seen,
                scene.map.bounds(),
                now,
                now + 2.0 * self.params.horizon_s,
            )
        } else {
            seen
        }
    }

    /// Whether the vehicle is at rest and its first route toward the goal is being searched.
    fn awaiting_first_route(&self, measured: &State) -> bool {
        self.route.is_none()
            && matches!(self.route_search, Some((RouteReason::First, _)))
            && self.at_rest(measured)
    }

    /// Whether the vehicle is at rest ([`REST_SPEED_FRACTION`] of its top speed).
    fn at_rest(&self, measured: &State) -> bool {
        measured.v.norm() <= REST_SPEED_FRACTION * self.limits.v_max
    }

    /// Sets the verdict for a goal outside the bounds or inside a static obstacle (kept with its
    /// first time and hold point while the goal stays the same): the hold point is the farthest
    /// point toward the goal (clipped into the bounds) that the vehicle sees from where it is and
    /// that keeps [`HOLD_CLEARANCE_M`] from the static map. Returns whether the verdict is new.
    fn hold_short_of_invalid_goal(
        &mut self,
        cause: &UnreachableCause,
        measured: &State,
        goal: &Vec3,
        scene: &Scene<'_>,
    ) -> bool {
        let cause = *cause;
        let same = self.routed_goal.is_some_and(|g| (g - goal).norm() <= 1e-9)
            && self.unreachable.as_ref().is_some_and(|u| u.cause == cause);
        if same {
            return false;
        }
        self.route_search = None;
        self.routed_goal = Some(*goal);
        self.routed_at = measured.t;
        let held = hold_point_toward(&measured.p, goal, scene);
        self.unreachable = Some(crate::GoalUnreachable {
            cause,
            held_at: Some([held.x, held.y, held.z]),
            since_t: measured.t,
        });
        true
    }

    /// Where the cycle plans to: `goal`, or while the goal is held unreachable
    /// ([`crate::GoalUnreachable`]) the reachable point nearest it.
    fn target(&self, goal: &Vec3) -> Vec3 {
        match &self.unreachable {
            Some(u) if self.routed_goal.is_some_and(|g| (g - goal).norm() <= 1e-9) => {
                u.held_at.map_or(*goal, |p| Vec3::new(p[0], p[1], p[2]))
            }
            _ => *goal,
        }
    }

    /// The global route ([`crate::routing`]): a search starts when there is no route toward
    /// this goal yet, when the progress monitor has just declared a stall, every horizon while
    /// the stall lasts, and every re-check period while the goal is held unreachable; a search
    /// under way gets the router's slice of work per cycle and the vehicle flies the previous
    /// route (or toward the goal) meanwhile. Its answer is a new route (the progress monitor is
    /// carried over to its arc length), a verdict that the goal cannot be reached (the route
    /// then leads to the reachable point nearest it), or a failure (the previous route stays).
    fn update_route(
        &mut self,
        cycle: &mut Cycle,
        measured: &State,
        goal: &Vec3,
        scene: &Scene<'_>,
        spans: &mut Spans,
    ) {
        // A search sent away for a slice between cycles comes back first; an answer it found
        // is taken below, in place of a slice.
        let mut away_answer = self.take_route_back(measured.t, spans);
        let Some(router) = &self.router else {
            return;
        };
        let goal = *goal;
        let new_goal = self.routed_goal.is_none_or(|g| (g - goal).norm() > 1e-9);
        let searching = self.route_search.is_some();
        // While the stall lasts the route is planned again every horizon (a route that failed,
        // or one that leads into a dead end, is not kept for the rest of the flight); a verdict
        // is re-checked every re-check period (the map and the obstacles change).
        let since = measured.t - self.routed_at;
        let again = cycle.stalled && since >= self.params.horizon_s;
        let recheck = self.unreachable.is_some() && since >= router.recheck_s();
        let reason = if new_goal {
            Some(RouteReason::First)
        } else if searching {
            None
        } else if cycle.newly_stalled || again {
            Some(RouteReason::Stalled)
        } else if recheck {
            Some(RouteReason::Recheck)
        } else if since >= BLOCKED_REROUTE_S && self.route_blocked_ahead(measured, scene, router) {
            Some(RouteReason::Blocked)
        } else {
            None
        };
        let started_now = reason.is_some();
        if let Some(reason) = reason {
            if new_goal {
                self.unreachable = None;
            }
            self.routed_goal = Some(goal);
            self.routed_at = measured.t;
            away_answer = None;
            // A sensed map's policy may search the route on a map of its own (unseen space the
            // sensor cannot look into from here is blocked, `CommitCheck::route_map`).
            self.route_map = self
                .commit_check
                .as_ref()
                .and_then(|c| c.route_map(&measured.p, &goal));
            let map = self.route_map.as_deref().unwrap_or(scene.map);
            match router.start(map, &measured.p, &goal) {
                Ok(search) => {
                    self.route_search = Some((reason, SearchSlot::Here(Box::new(search))))
                }
                Err(e) => {
                    self.route_search = None;
                    cycle.events.push(Event::route_failed(reason, &e));
                    return;
                }
            }
        }
        let off_cycle = self.route_off_cycle(scene);
        let at_rest = self.at_rest(measured);
        let Some((reason, SearchSlot::Here(search))) = self.route_search.as_mut() else {
            return;
        };
        let reason = *reason;
        // A vehicle at rest waiting for its first route loses nothing by waiting one cycle
        // more: with a map the threads can read, even the first slice is done between cycles.
        let first_at_rest = reason == RouteReason::First && at_rest;
        let answer = match away_answer {
            Some(answer) => answer,
            // The cycle that starts a search in flight does its first slice (most routes are
            // found there, before the vehicle has flown a cycle on the old one); with a map
            // the threads can read, the later slices are done between cycles (sent away as
            // the cycle ends), else each cycle does a slice itself.
            None if !off_cycle || (started_now && !first_at_rest) => {
                let deadline = deadline_at(spans.started, &self.params, ROUTE_DEADLINE_FRACTION);
                let map = self.route_map.as_deref().unwrap_or(scene.map);
                match spans.time(Span::Route, || router.slice_in_cycle(search, map, deadline)) {
                    RouteProgress::Pending => return,
                    answer => answer,
                }
            }
            None => return,
        };
        self.route_search = None;
        // No route on the sensed policy's own map (its blocks of unseen space may close every
        // way from here) is no verdict: the search starts again on the scene's map.
        if !matches!(answer, RouteProgress::Found(_)) && self.route_map.take().is_some() {
            match router.start(scene.map, &measured.p, &goal) {
                Ok(search) => {
                    self.route_search = Some((reason, SearchSlot::Here(Box::new(search))))
                }
                Err(e) => cycle.events.push(Event::route_failed(reason, &e)),
            }
            return;
        }
        self.apply_route_answer(cycle, measured, &goal, reason, answer);
    }

    /// Whether the route ahead of the vehicle (from its projection on it) runs into an
    /// obstacle of `scene`'s map at the route's clearance: with a sensed map
    /// ([`Manager::set_commit_check`]), an obstacle seen since the route was planned.
    fn route_blocked_ahead(&self, measured: &State, scene: &Scene<'_>, router: &Router) -> bool {
        if self.commit_check.is_none() {
            return false;
        }
        let Some(route) = self.route.as_ref() else {
            return false;
        };
        let Ok(s) = route.progress(&measured.p) else {
            return false;
        };
        let clearance = router.params().clearance_for(router.radius_m());
        route.is_blocked(scene.map, clearance, s).unwrap_or(false)
    }

    /// Takes back the route search sent away for a slice between cycles (waiting for it, so a
    /// seed is one flight; in real time taking its answer only once due,
    /// [`ManagerParams::real_time_scale`]); returns the slice's answer, if it found one.
    fn take_route_back(&mut self, now: f64, spans: &mut Spans) -> Option<RouteProgress> {
        let (reason, slot) = self.route_search.take()?;
        let waiting = Instant::now();
        let joined = matches!(slot, SearchSlot::Away { .. });
        let back = slot.take_back(now, self.params.real_time_scale);
        if joined {
            spans.timing.waited_ms += ms(waiting.elapsed());
        }
        match back {
            TakenBack::Here(search) => {
                self.route_search = Some((reason, SearchSlot::Here(search)));
                None
            }
            TakenBack::Sliced(slice) => {
                spans.timing.route_worker_ms += ms(slice.elapsed);
                self.route_search = Some((reason, SearchSlot::Here(slice.search)));
                Some(slice.progress).filter(|p| !matches!(p, RouteProgress::Pending))
            }
            TakenBack::NotYet(slot) => {
                self.route_search = Some((reason, slot));
                None
            }
            // A slice that panicked loses the search, as a job that panicked is dropped: the
            // next stall or re-check starts another.
            TakenBack::Lost => None,
        }
    }

    /// A route search's answer: a new route (the progress monitor is carried over to its arc
    /// length), a verdict that the goal cannot be reached (the route then leads to the reachable
    /// point nearest it), or a failure (the previous route stays).
    fn apply_route_answer(
        &mut self,
        cycle: &mut Cycle,
        measured: &State,
        goal: &Vec3,
        reason: RouteReason,
        answer: RouteProgress,
    ) {
        let goal = *goal;
        let new_route = match answer {
            RouteProgress::Found(route) => {
                self.unreachable = None;
                cycle.events.push(rerouted(reason, &route));
                Some(route)
            }
            RouteProgress::Unreachable(verdict) => {
                let held_at = verdict
                    .nearest
                    .as_ref()
                    .and_then(|r| r.points().last().copied());
                let since_t = self.unreachable.as_ref().map_or(measured.t, |u| u.since_t);
                let cause = verdict.cause;
                cycle.events.push(Event::GoalUnreachable {
                    cause,
                    held_at: held_at.map(|p| [p.x, p.y, p.z]),
                });
                self.unreachable = Some(crate::GoalUnreachable {
                    cause,
                    held_at: held_at.map(|p| [p.x, p.y, p.z]),
                    since_t,
                });
                verdict.nearest
            }
            RouteProgress::Failed(e) => {
                cycle.events.push(Event::route_failed(reason, &e));
                None
            }
            // A future kind of answer: keep the previous route.
            _ => None,
        };
        if let Some(route) = new_route {
            let before = self.progress_at(&measured.p, &goal);
            self.route = Some(route);
            let after = self.progress_at(&measured.p, &goal);
            self.progress.rebase(after - before);
        }
    }

    /// The cycle's starting point: the replan start, the ranking weights, the deadline and
    /// whether FwdExplore runs this cycle.
    fn begin_cycle(&mut self, now: f64, measured: &State, goal: &Vec3, started: Instant) -> Cycle {
        let mut events = Vec::new();
        let (start, reanchored) = self.replan_start(now, measured, &mut events);
        let rule = self
            .params
            .progress
            .rule(&self.limits, self.params.horizon_s);
        let distance = (measured.p - goal).norm();
        self.flown.record(&measured.p);
        let progress = self.progress_at(&measured.p, goal);
        let mut stall_event = self.progress.update(now, progress, distance, &rule);
        // Refused at rest for a quarter of the stall window: no plan will take it on from
        // here, and waiting out the window only wastes it (`crate::retreat`).
        if stall_event.is_none()
            && self
                .refused_since
                .is_some_and(|since| start.t - since >= REFUSED_STALL_FRACTION * rule.window_s)
        {
            stall_event = self.progress.declare_stalled(now, progress, distance);
        }
        let newly_stalled = matches!(stall_event, Some(Event::Stalled { .. }));
        events.extend(stall_event);
        let stalled = self.progress.stalled();
        let explore = self.explores(stalled);
        self.cycle_count += 1;
        Cycle {
            start,
            goal: *goal,
            stalled,
            newly_stalled,
            reanchored,
            weights: self.params.ranking_weights(&self.limits),
            deadline: deadline_from(started, &self.params),
            explore,
            events,
            rejected: Vec::new(),
        }
    }

    /// Whether the next cycle runs FwdExplore ([`ManagerParams::explore_period_cycles`]): every
    /// period, while stalled, without history, and with fewer than two branches or no main one.
    fn explores(&self, stalled: bool) -> bool {
        stalled
            || !self.params.history
            || self
                .cycle_count
                .is_multiple_of(self.params.explore_period_cycles as u64)
            || self.branches.len() < 2
            || self.main.is_none()
    }

    /// The solver of this cycle's trajectories: from its replan start toward `aim`.
    fn solver<'s, 'a>(
        &'s self,
        cycle: &Cycle,
        aim: &Vec3,
        scene: &'s Scene<'a>,
    ) -> Solver<'s, 'a, B> {
        Solver::new(
            &*self.backend,
            scene,
            (cycle.start, *aim, self.limits),
            &self.params,
            cycle.deadline,
            cycle.stalled,
            self.route_guide(&cycle.start.p, aim),
        )
    }

    /// The worker's job, if one is under way, waited for; its results if they apply to this
    /// cycle — solved from this cycle's replan start toward its aim, with the same stall state
    /// (the start and the aim are then taken from the job: equal to within rounding) — else
    /// `None`, and the cycle solves everything itself as if there had been no job.
    fn merge_job(
        &mut self,
        cycle: &mut Cycle,
        aim: &mut Vec3,
        spans: &mut Spans,
    ) -> Option<JobOutput> {
        /// Rounding of the predicted start time (s) and of positions (m).
        const SAME_S: f64 = 1e-6;
        const SAME_M: f64 = 1e-9;
        let job = self.job.take()?;
        let waiting = Instant::now();
        // A job that panicked is dropped like a stale one (the cycle solves it all itself).
        let out = job.handle.join().ok();
        spans.timing.waited_ms += ms(waiting.elapsed());
        let applies = !cycle.reanchored
            && job.stalled == cycle.stalled
            && (job.start.t - cycle.start.t).abs() <= SAME_S
            && (job.start.p - cycle.start.p).norm() <= SAME_M
            && (job.aim - *aim).norm() <= SAME_M;
        let out = out.filter(|_| applies)?;
        cycle.start = job.start;
        *aim = job.aim;
        self.rng = out.rng.clone();
        Some(out)
    }

    /// The cycle's solves with the worker's results: the main branch is re-solved here against
    /// this cycle's forecasts, from the worker's re-solve of it with
    /// [`ManagerParams::merge_max_evaluations`] (from its own trajectory with the warm budget if
    /// the worker's failed; a repair with the warm budget), the sub-branches come re-solved by the worker (re-solved here if one is
    /// missing), and the explored candidates are the worker's; in `warm`'s order as
    /// [`Manager::solve_in_parallel`].
    fn solve_main_with(
        &self,
        out: JobOutput,
        cycle: &Cycle,
        aim: &Vec3,
        scene: &Scene<'_>,
        warm: &[(BranchId, Origin, PolyTraj)],
        spans: &mut Spans,
    ) -> (Explored, Vec<Candidate>) {
        let solver = self.solver(cycle, aim, scene);
        let mut subs = out.subs;
        if let Some(main) = &out.main {
            // The worker's re-solve counts in this cycle's work.
            spans.solved(main, false);
        }
        let marched = out.main.and_then(|c| c.result.ok()).map(|(s, _)| s.traj);
        let budget = self
            .params
            .merge_max_evaluations
            .or(self.params.warm_max_evaluations);
        let resolved = warm
            .iter()
            .map(|(id, origin, traj)| {
                if *origin == Origin::Marched {
                    let warm = self.params.warm_max_evaluations;
                    let cand = match &marched {
                        Some(from) => solver.solve_with(InitialGuess::WarmStart(from), budget),
                        None => solver.solve_with(InitialGuess::WarmStart(traj), warm),
                    };
                    // On the critical path a repair gets the warm budget, not the cold one.
                    return solver.repaired_within(cand, warm);
                }
                match subs.iter().position(|(s, _)| s == id) {
                    Some(i) => subs.swap_remove(i).1,
                    None => solver.bwd_replan(traj),
                }
            })
            .collect();
        spans.timing.frontend_ms += out.frontend_ms;
        spans.timing.worker_ms += ms(out.elapsed);
        (out.explored, resolved)
    }

    /// The static map shared with the threads that work between cycles, if `scene` is built on
    /// it ([`Manager::share_map`]).
    fn shared_map_for(&self, scene: &Scene<'_>) -> Option<Arc<StaticMap>> {
        self.shared_map
            .clone()
            .filter(|m| std::ptr::eq(Arc::as_ptr(m), scene.map))
    }

    /// Whether a route search under way goes on between cycles ([`crate::routing`]): with
    /// [`ManagerParams::background`] and the scene built on the shared map.
    fn route_off_cycle(&self, scene: &Scene<'_>) -> bool {
        self.params.background && self.shared_map_for(scene).is_some()
    }

    /// As a cycle ends, sends the route search under way away for a slice of
    /// [`Router::work_off_cycle`] units between cycles ([`Manager::route_off_cycle`]); the next
    /// cycle takes it back. Returns whether it did.
    fn send_route_away(&mut self, now: f64, spans: &Spans, scene: &Scene<'_>) -> bool {
        let (Some(router), Some(shared)) = (&self.router, self.shared_map_for(scene)) else {
            return false;
        };
        let map = self.route_map.clone().unwrap_or(shared);
        if !self.params.background {
            return false;
        }
        let work = router.work_off_cycle();
        // The slice starts as this cycle ends: on the flight's clock, its charged time later.
        let sent_at = now
            + self
                .params
                .real_time_scale
                .map_or(0.0, |x| spans.started.elapsed().as_secs_f64() * x);
        match self.route_search.take() {
            Some((reason, SearchSlot::Here(search))) => {
                match SearchSlot::away(search, map, work, sent_at) {
                    Some(slot) => {
                        self.route_search = Some((reason, slot));
                        true
                    }
                    None => false,
                }
            }
            other => {
                self.route_search = other;
                false
            }
        }
    }

    /// Starts the worker on the next cycle's sub-branch re-solves and exploration
    /// ([`ManagerParams::background`]), from the next cycle's replan start as the committed plan
    /// predicts it one period (the last cycle interval) ahead; whether it started one.
    fn start_job(&mut self, now: f64, cycle: &Cycle, scene: &Scene<'_>) -> bool {
        // Before a second cycle the period is unknown: the budget is half of it
        // ([`ManagerParams::cycle_budget_ms`]); a wrong guess only makes the job stale.
        let period = self
            .last_now
            .replace(now)
            .map_or(2.0 * self.params.cycle_budget_ms * 1e-3, |last| now - last);
        // Without a main branch (braking, evading) the next cycle plans on the newest
        // forecasts only: a job would explore and re-solve against this cycle's.
        if !self.params.background || !self.params.history || self.main.is_none() {
            return false;
        }
        let shared = self.shared_map_for(scene);
        let period = Some(period).filter(|p| p.is_finite() && *p > 0.0);
        let (Some(map), Some(period), Some(plan)) = (shared, period, self.committed.as_ref())
        else {
            return false;
        };
        let t_eff = now + period + self.params.latency();
        let mut start = plan.state(t_eff);
        start.t = t_eff;
        let stalled = self.progress.stalled();
        let aim = self.aim(&start.p, &cycle.goal, stalled, scene.map);
        let input = JobInput {
            frontend: Arc::clone(&self.frontend),
            backend: Arc::clone(&self.backend),
            map,
            forecasts: scene.forecasts.to_vec(),
            t0: scene.t0,
            start,
            aim,
            limits: self.limits,
            params: self.params.clone(),
            explore: self.explores(stalled),
            stalled,
            main: self
                .main
                .and_then(|id| self.branches.iter().find(|b| b.id == id))
                .map(|b| b.solution.traj.clone()),
            subs: self
                .branches
                .iter()
                .filter(|b| Some(b.id) != self.main)
                .map(|b| (b.id, b.solution.traj.clone()))
                .collect(),
            deferred: self.deferred_guides.clone(),
            route_guide: self.route_guide(&start.p, &aim),
            rng: self.rng.clone(),
        };
        let spawned = std::thread::Builder::new()
            .name("trust-manager-worker".into())
            .spawn(move || worker::run(input));
        match spawned {
            Ok(handle) => {
                self.job = Some(Job {
                    start,
                    aim,
                    stalled,
                    handle,
                });
                true
            }
            Err(_) => false,
        }
    }

    /// The main branch ([`Manager::select_main`]). With the worker's results merged, a leading
    /// branch other than the marched main one was checked against the previous cycle's
    /// forecasts: it is checked again against this cycle's first, and dropped if it fails.
    fn select_checked_main(
        &self,
        kept: &mut Vec<Branch>,
        cycle: &mut Cycle,
        scene: &Scene<'_>,
        from_worker: bool,
        spans: &mut Spans,
    ) -> Option<BranchId> {
        let mut confirmed: Vec<BranchId> = Vec::new();
        loop {
            let mut events = Vec::new();
            let (start, goal) = (cycle.start, cycle.goal);
            let main = self.select_main(kept, &start, &goal, cycle.stalled, &mut events);
            let unconfirmed = main.filter(|_| from_worker).and_then(|id| {
                kept.iter()
                    .position(|b| b.id == id && b.origin != Origin::Marched)
                    .filter(|_| !confirmed.contains(&id))
            });
            let Some(i) = unconfirmed else {
                cycle.events.extend(events);
                return main;
            };
            let traj = kept[i].traj();
            let verdict = spans.time(Span::Checks, || {
                check_trajectory(
                    traj,
                    scene,
                    start.t,
                    traj.t_end(),
                    &self.limits,
                    &self.params.safety,
                )
            });
            if verdict.safe {
                confirmed.push(kept[i].id);
                kept[i].verdict = verdict;
            } else {
                let dropped = kept.remove(i);
                cycle
                    .events
                    .push(dropped_collision(Some(dropped.id), &verdict, &self.limits));
                cycle
                    .rejected
                    .push((FallbackKind::Branch, dropped.solution.traj));
            }
        }
    }

    /// The kept branches to re-solve, in rank order: the main branch marches forward, the others
    /// are replanned; none without history.
    fn warm_branches(&self) -> Vec<(BranchId, Origin, PolyTraj)> {
        if !self.params.history {
            return Vec::new();
        }
        self.branches
            .iter()
            .map(|b| {
                let origin = if Some(b.id) == self.main {
                    Origin::Marched
                } else {
                    Origin::Replanned
                };
                (b.id, origin, b.solution.traj.clone())
            })
            .collect()
    }

    /// Runs [`Solver::fwd_march`] / [`Solver::bwd_replan`] on every `warm` branch (in parallel)
    /// alongside [`fwd_explore`] when the cycle explores; the re-solves come back in `warm`'s
    /// order.
    fn solve_in_parallel(
        &mut self,
        cycle: &Cycle,
        goal: &Vec3,
        scene: &Scene<'_>,
        warm: &[(BranchId, Origin, PolyTraj)],
        spans: &mut Spans,
    ) -> (Explored, Vec<Candidate>) {
        let query = PathQuery {
            start: cycle.start,
            goal: *goal,
            limits: self.limits,
            horizon_s: self.params.horizon_s,
            exploration: if cycle.stalled { 2.0 } else { 1.0 },
        };
        let pending = std::mem::take(&mut self.deferred_guides);
        // The random stream is lent to the frontend while the solver borrows the manager.
        let mut rng = std::mem::replace(&mut self.rng, Rng::seed_from_u64(0));
        let solver = self.solver(cycle, goal, scene);
        let out = rayon::join(
            || match cycle.explore {
                true => fwd_explore(&*self.frontend, &mut rng, &query, &solver, spans),
                false => solve_deferred(pending, &solver),
            },
            || {
                warm.par_iter()
                    .map(|(_, origin, traj)| match origin {
                        Origin::Marched => solver.fwd_march(traj),
                        _ => solver.bwd_replan(traj),
                    })
                    .collect()
            },
        );
        self.rng = rng;
        out
    }

    /// The safety pass over one solved trajectory: its statistics go to the cycle's timing; a
    /// solve error (`SolveFailed`) or a failed safety check (`DroppedCollision`, the trajectory
    /// kept in `cycle.rejected` for the fallback) drops it, otherwise it is returned. `id` is the
    /// re-solved branch, `None` for an explored candidate (a cold solve).
    fn safety_pass(
        &self,
        cand: Candidate,
        id: Option<BranchId>,
        cycle: &mut Cycle,
        spans: &mut Spans,
    ) -> Option<(Solution, SafetyVerdict)> {
        spans.solved(&cand, id.is_none());
        if cand.repaired {
            cycle.events.push(Event::Repaired { id });
        }
        match cand.result {
            Err(e) => {
                cycle.events.push(Event::solve_failed(id, &e));
                None
            }
            Ok((solution, _)) if self.is_stub(&solution.traj, &cycle.goal) => {
                cycle.events.push(Event::DroppedStub {
                    id,
                    duration_s: solution.traj.duration(),
                });
                None
            }
            Ok((solution, verdict)) if verdict.safe => Some((solution, verdict)),
            Ok((solution, verdict)) => {
                cycle
                    .events
                    .push(dropped_collision(id, &verdict, &self.limits));
                let kind = if id.is_some() {
                    FallbackKind::Branch
                } else {
                    FallbackKind::Candidate
                };
                cycle.rejected.push((kind, solution.traj));
                None
            }
        }
    }

    /// The re-solved branches that pass the safety pass, in ranking order; a main branch whose
    /// re-solve failed keeps its committed trajectory if that still passes
    /// ([`Manager::keep_committed`]), unless the replan was re-anchored.
    fn keep_resolved(
        &self,
        warm: Vec<(BranchId, Origin, PolyTraj)>,
        resolved: Vec<Candidate>,
        cycle: &mut Cycle,
        scene: &Scene<'_>,
        spans: &mut Spans,
    ) -> Vec<Branch> {
        let mut kept: Vec<Branch> = Vec::new();
        for ((id, origin, _), cand) in warm.into_iter().zip(resolved) {
            match self.safety_pass(cand, Some(id), cycle, spans) {
                Some((solution, verdict)) => kept.push(Branch {
                    id,
                    j: solution.costs.ranking_cost(&cycle.weights),
                    reaches_goal: self.reaches(&solution.traj, &cycle.goal),
                    shortfall_m: shortfall(&solution.traj, &cycle.goal),
                    solution,
                    origin,
                    warm_started: true,
                    verdict,
                }),
                None if origin == Origin::Marched && !cycle.reanchored => {
                    let (start, weights, goal) = (cycle.start, cycle.weights, cycle.goal);
                    let previous = spans.time(Span::Checks, || {
                        self.keep_committed(id, &start, &goal, scene, &weights)
                    });
                    if let Some(b) = previous {
                        cycle.events.push(Event::KeptCommitted { id });
                        kept.push(b);
                    }
                }
                None => {}
            }
        }
        sort_by_rank(&mut kept, cycle.stalled);
        kept
    }

    /// One explored trajectory through the safety pass and, if it passes, AddNewBranch (whose
    /// PopBack protects the incumbent main branch).
    fn explored_branch(
        &mut self,
        kept: &mut Vec<Branch>,
        cand: Candidate,
        cycle: &mut Cycle,
        scene: &Scene<'_>,
        spans: &mut Spans,
    ) {
        let Some((solution, verdict)) = self.safety_pass(cand, None, cycle, spans) else {
            return;
        };
        let new = Branch {
            id: 0,
            j: solution.costs.ranking_cost(&cycle.weights),
            reaches_goal: self.reaches(&solution.traj, &cycle.goal),
            shortfall_m: shortfall(&solution.traj, &cycle.goal),
            solution,
            origin: Origin::Explored,
            warm_started: false,
            verdict,
        };
        let incumbent = self.main.filter(|_| self.params.history);
        let by_progress = cycle.stalled;
        spans.time(Span::Checks, || {
            self.add_new_branch(kept, new, scene, incumbent, by_progress, &mut cycle.events);
        });
    }

    /// Commits the main branch, or with none the braking fallback ([`Manager::fallback`]).
    fn commit(
        &mut self,
        main: Option<BranchId>,
        kept: &[Branch],
        cycle: &mut Cycle,
        scene: &Scene<'_>,
        spans: &mut Spans,
    ) -> Option<FallbackReport> {
        let mut retreat = false;
        if let Some(main) = main.and_then(|id| kept.iter().find(|b| b.id == id)) {
            match self.outside_known_free(&main.solution.traj, cycle) {
                None => {
                    self.committed = Some(main.solution.traj.clone());
                    self.committed_fallback = None;
                    self.main = Some(main.id);
                    self.refused_since = None;
                    return None;
                }
                Some(t) => {
                    cycle
                        .events
                        .push(Event::NotKnownFree { branch: main.id, t });
                    retreat = cycle.stalled;
                    if !self.at_rest(&cycle.start) {
                        self.refused_since = None;
                    } else if self.refused_since.is_none() {
                        self.refused_since = Some(cycle.start.t);
                    }
                }
            }
        }
        let (start, reanchored) = (cycle.start, cycle.reanchored);
        let report = spans.time(Span::Checks, || {
            self.fallback(
                &start,
                reanchored,
                &cycle.rejected,
                retreat,
                scene,
                &mut cycle.events,
            )
        });
        self.main = None;
        report
    }

    /// With a commit check ([`Manager::set_commit_check`]), the first instant of `traj`'s
    /// committed stretch ([`crate::committed_stretch`]) outside the space it accepts; `None` if
    /// it passes or without a check. The committed part lasts until the next plan takes effect
    /// (the last cycle period, or twice the cycle budget before a second cycle, plus the
    /// latency).
    fn outside_known_free(&self, traj: &PolyTraj, cycle: &Cycle) -> Option<f64> {
        let check = self.commit_check.as_ref()?;
        let until = self.next_plan_at(cycle.start.t);
        let points = crate::committed_stretch(traj, cycle.start.t, until, self.limits.a_max);
        points
            .windows(2)
            .find(|w| !check.segment_free(&w[0].1, &w[1].1))
            .map(|w| w[0].0)
    }

    /// When the plan after one starting at `start_t` takes effect: the last cycle period (or
    /// twice the cycle budget before a second cycle) plus the latency later.
    fn next_plan_at(&self, start_t: f64) -> f64 {
        let period = self
            .last_now
            .map(|last| start_t - self.params.latency() - last)
            .filter(|p| p.is_finite() && *p > 0.0)
            .unwrap_or(2.0 * self.params.cycle_budget_ms * 1e-3);
        start_t + period + self.params.latency()
    }

    /// The state the new plan starts from, and whether it was re-anchored on the measurement.
    fn replan_start(&self, now: f64, measured: &State, events: &mut Vec<Event>) -> (State, bool) {
        let latency = self.params.latency();
        let t_eff = now + latency;
        if let Some(plan) = &self.committed {
            let expected = plan.state(now);
            let dp = (measured.p - expected.p).norm();
            let dv = (measured.v - expected.v).norm();
            if dp <= self.params.reanchor.position_m && dv <= self.params.reanchor.velocity_mps {
                let mut s = plan.state(t_eff);
                s.t = t_eff;
                return (s, false);
            }
            events.push(Event::Reanchored {
                position_drift_m: dp,
                velocity_drift_mps: dv,
            });
        }
        let l = latency;
        let start = State {
            t: t_eff,
            p: measured.p + measured.v * l + measured.a * (0.5 * l * l),
            v: measured.v + measured.a * l,
            a: measured.a,
        };
        (start, self.committed.is_some())
    }

    /// The main branch with its previous (committed) trajectory, if that still passes the safety
    /// check from the replan start under the current forecasts: a re-solve that fails (pushed into
    /// a squeeze, or out of budget) must not throw away a plan that is still good.
    fn keep_committed(
        &self,
        id: BranchId,
        start: &State,
        goal: &Vec3,
        scene: &Scene<'_>,
        weights: &RankingWeights,
    ) -> Option<Branch> {
        let plan = self.committed.as_ref()?;
        let previous = self.branches.iter().find(|b| b.id == id)?;
        if previous.solution.traj != *plan || plan.t_end() <= start.t || self.is_stub(plan, goal) {
            return None;
        }
        let verdict = check_trajectory(
            plan,
            scene,
            start.t,
            plan.t_end(),
            &self.limits,
            &self.params.safety,
        );
        verdict.safe.then(|| Branch {
            id,
            j: previous.solution.costs.ranking_cost(weights),
            reaches_goal: self.reaches(plan, goal),
            shortfall_m: shortfall(plan, goal),
            solution: previous.solution.clone(),
            origin: Origin::Kept,
            warm_started: false,
            verdict,
        })
    }

    /// Keeps the re-solved branches homotopy-distinct: a warm re-solve can slide into another
    /// branch's class, and the queue must hold one branch per class. Walking in `J` order, a
    /// branch equivalent to an already kept one is dropped (`MergedEquivalent`).
    fn dedupe(
        &self,
        sorted: Vec<Branch>,
        scene: &Scene<'_>,
        events: &mut Vec<Event>,
    ) -> Vec<Branch> {
        let mut out: Vec<Branch> = Vec::with_capacity(sorted.len());
        'branches: for b in sorted {
            for k in &out {
                match self.equivalent(&b.solution.traj, &k.solution.traj, scene) {
                    Ok(true) => {
                        events.push(Event::MergedEquivalent {
                            dropped: b.id,
                            kept: k.id,
                        });
                        continue 'branches;
                    }
                    Ok(false) => {}
                    Err(e) => events.push(Event::checker_failed(&e)),
                }
            }
            out.push(b);
        }
        out
    }

    /// AddNewBranch of Algorithm 1 (see the type's docs), then PopBack beyond `N` protecting the
    /// incumbent main branch.
    fn add_new_branch(
        &mut self,
        kept: &mut Vec<Branch>,
        mut new: Branch,
        scene: &Scene<'_>,
        incumbent: Option<BranchId>,
        by_progress: bool,
        events: &mut Vec<Event>,
    ) {
        let mut worse_equivalent = None;
        for (i, b) in kept.iter().enumerate() {
            match self.equivalent(&new.solution.traj, &b.solution.traj, scene) {
                Ok(true) if !new.outranks(b, by_progress) => {
                    events.push(Event::DiscardedEquivalent {
                        equivalent_to: b.id,
                    });
                    return;
                }
                Ok(true) => {
                    worse_equivalent.get_or_insert(i);
                }
                Ok(false) => {}
                Err(e) => events.push(Event::checker_failed(&e)),
            }
        }
        match worse_equivalent {
            Some(i) => {
                new.id = kept[i].id;
                events.push(Event::Replaced {
                    id: new.id,
                    j_old: kept[i].j,
                    j_new: new.j,
                });
                kept[i] = new;
            }
            None => {
                new.id = self.next_id;
                self.next_id += 1;
                events.push(Event::Added { id: new.id });
                kept.push(new);
            }
        }
        sort_by_rank(kept, by_progress);
        pop_back(kept, self.params.max_branches, incumbent, events);
    }

    /// Whether `traj` ends within [`ManagerParams::goal_reached_m`] of `goal`.
    /// A stub ([`Event::DroppedStub`]): shorter than [`STUB_FRACTION`] of the horizon, not
    /// reaching the goal, which is farther from its start than that time at `v_max`.
    fn is_stub(&self, traj: &PolyTraj, goal: &Vec3) -> bool {
        let short = STUB_FRACTION * self.params.horizon_s;
        traj.duration() < short
            && !self.reaches(traj, goal)
            && (traj.position(traj.t_start()) - goal).norm() > short * self.limits.v_max
    }

    fn reaches(&self, traj: &PolyTraj, goal: &Vec3) -> bool {
        shortfall(traj, goal) <= self.params.goal_reached_m
    }

    /// The checker on a scene restricted to the forecasts that can reach the two trajectories.
    fn equivalent(&self, a: &PolyTraj, b: &PolyTraj, scene: &Scene<'_>) -> Result<bool, PlanError> {
        let from = a.t_start().min(b.t_start());
        let until = a.t_end().max(b.t_end());
        let (_, box_a) = window_bounds(a, from, until);
        let (_, box_b) = window_bounds(b, from, until);
        let mut indices = Vec::new();
        forecasts_near(scene, &box_a.union(&box_b), from, until, 0.0, &mut indices);
        let near: Vec<Forecast> = indices.iter().map(|&i| scene.forecasts[i]).collect();
        let sub = Scene {
            map: scene.map,
            forecasts: &near,
            t0: scene.t0,
        };
        self.checker.equivalent(a, b, &sub)
    }

    /// The new main branch (hysteresis), with its event.
    fn select_main(
        &self,
        kept: &[Branch],
        start: &State,
        goal: &Vec3,
        stalled: bool,
        events: &mut Vec<Event>,
    ) -> Option<BranchId> {
        let weights = self.params.ranking_weights(&self.limits);
        let ideal =
            weights.lambda_s.min(weights.lambda_t / self.limits.v_max) * (start.p - goal).norm();
        // The hysteresis compares `J` only among branches of the best one's tier: a branch that
        // reaches the goal replaces an incumbent that stops short, however their `J` compare.
        // While stalled the best-ranked branch (by progress) leads at once, without hysteresis.
        let tier = kept.first()?.reaches_goal;
        let ranked: Vec<(BranchId, f64)> = kept
            .iter()
            .filter(|b| b.reaches_goal == tier)
            .take(if stalled { 1 } else { kept.len() })
            .map(|b| (b.id, b.j))
            .collect();
        let incumbent = self.main.filter(|_| self.params.history);
        let incumbent_short =
            tier && incumbent.is_some_and(|id| kept.iter().any(|b| b.id == id && !b.reaches_goal));
        let decision = choose_main(&ranked, incumbent, ideal, self.params.hysteresis)?;
        if decision.switched && self.params.history {
            let reason = match (incumbent, decision.incumbent_kept) {
                (None, _) => SwitchReason::First,
                (Some(_), true) => SwitchReason::Better,
                (Some(_), false) if incumbent_short => SwitchReason::ReachesGoal,
                (Some(id), false) if stalled && kept.iter().any(|b| b.id == id) => {
                    SwitchReason::Progress
                }
                (Some(_), false) => SwitchReason::IncumbentDropped,
            };
            events.push(Event::SwitchedMain {
                from: self.main,
                to: decision.main,
                reason,
            });
        }
        Some(decision.main)
    }

    /// Builds the braking fallback, commits it and reports it: the options
    /// ([`Manager::fallback_options`]), the first admissible one clear of the held forecasts or
    /// else the best-ranked ([`Manager::first_clear_fallback`]), and when none is clear, the one
    /// with the widest margin against the obstacles' likely motion
    /// ([`Manager::widest_likely_fallback`]).
    fn fallback(
        &mut self,
        start: &State,
        reanchored: bool,
        rejected: &[(FallbackKind, PolyTraj)],
        retreat: bool,
        scene: &Scene<'_>,
        events: &mut Vec<Event>,
    ) -> Option<FallbackReport> {
        let hold_s = self.params.brake_hold();
        let (mut options, mut continued) =
            self.fallback_options(start, reanchored, rejected, hold_s);
        if retreat {
            let back = self.retreat_options(start, reanchored, hold_s);
            continued = continued.map(|i| i + back.len());
            options.splice(0..0, back);
        }
        // The options are judged against the forecasts grown for at most a quarter of the
        // horizon (the scene's forecasts already stop growing after `forecast_growth`, 0.25 s
        // by default; this cap matters when that is longer, e.g. the paper's growth for ever)
        // and then held: the fallback is chosen again next cycle from new observations, and against
        // an uncertainty growing without end every option collides at last, so the latest
        // collision won — fleeing along a person's path instead of stepping out of it.
        let grow_for = FALLBACK_GROWTH_FRACTION * self.params.horizon_s;
        let held: Vec<Forecast> = scene
            .forecasts
            .iter()
            .map(|f| f.growth_held_after(grow_for))
            .collect();
        let judged = Scene {
            forecasts: &held,
            ..*scene
        };
        // Whether each option lies in known free space, asked only of the options it decides.
        // Braking along the committed plan stays in the stretch its commit check passed.
        let memo: Vec<std::cell::OnceCell<bool>> = vec![std::cell::OnceCell::new(); options.len()];
        let known = |i: usize| {
            *memo[i].get_or_init(|| {
                options[i].0 == FallbackKind::Committed
                    || self.known_free_committed(&options[i].1, start)
            })
        };
        let (mut best, verdicts) = self.first_clear_fallback(&options, &known, start, &judged);
        if best.as_ref().is_some_and(|(_, v)| v.violation.is_some())
            && let Some(i) =
                self.widest_likely_fallback(&options, &known, &verdicts, start, scene, continued)
        {
            // Reported against the forecasts (its shortfall is theirs).
            best = Some((i, verdicts[i]));
        }
        let (i, verdict) = best?;
        let (along, traj) = options.swap_remove(i);
        let collision_free = verdict.violation.is_none();
        let stop_time = traj.t_end() - hold_s;
        events.push(Event::Fallback {
            along,
            collision_free,
            min_margin_m: verdict.min_margin_m(),
        });
        self.committed = Some(traj);
        self.committed_fallback = Some(along);
        Some(FallbackReport {
            along,
            collision_free,
            min_margin_m: verdict.min_margin_m(),
            shortfall_m: if collision_free {
                0.0
            } else {
                (-verdict.min_margin_m()).max(0.0)
            },
            stop_time,
        })
    }

    /// The fallback's options, in the order they are tried: braking along the committed plan
    /// (unless re-anchored) and along each rejected trajectory, braking straight, the committed
    /// evade, escape or dash flown on (unless re-anchored; its index is returned too), the
    /// rejected trajectories flown as they are (evade), then the escapes and the dashes.
    fn fallback_options(
        &self,
        start: &State,
        reanchored: bool,
        rejected: &[(FallbackKind, PolyTraj)],
        hold_s: f64,
    ) -> (Vec<(FallbackKind, PolyTraj)>, Option<usize>) {
        let a_max = self.limits.a_max;
        let mut options: Vec<(FallbackKind, PolyTraj)> = Vec::new();
        if let Some(plan) = self.committed.as_ref().filter(|_| !reanchored)
            && let Ok(b) = brake_along(plan, start.t, a_max, hold_s)
        {
            options.push((FallbackKind::Committed, b));
        }
        for (kind, traj) in rejected {
            if let Ok(b) = brake_along(traj, start.t, a_max, hold_s) {
                options.push((*kind, b));
            }
        }
        if let Ok(b) = brake_straight(start, a_max, hold_s) {
            options.push((FallbackKind::Straight, b));
        }
        // The manoeuvre the last fallback chose, flown on: chosen afresh every cycle from a
        // new start, the options alternated (dash, evade, escape in turn in a room with a
        // pacing person) and the vehicle went nowhere while the person came on.
        let mut continued = None;
        if let (Some(kind), Some(plan)) = (
            self.committed_fallback,
            self.committed.as_ref().filter(|_| !reanchored),
        ) && matches!(
            kind,
            FallbackKind::Evade | FallbackKind::Escape | FallbackKind::Dash
        ) && plan.t_end() > start.t
        {
            continued = Some(options.len());
            options.push((kind, plan.clone()));
        }
        // Beyond the paper: the rejected trajectories flown as they are. Braking is the answer
        // to an obstacle ahead, not to one walking into a vehicle at rest (the suite's rooms with
        // people: the stopped vehicle was run into); a trajectory that keeps moving stays clear
        // longer there, and the next cycle replans from it. Only taken when no braking option is
        // collision-free and it is clear for longer than every one of them.
        for (_, traj) in rejected {
            options.push((FallbackKind::Evade, traj.clone()));
        }
        // And short escapes to rest in eight horizontal directions and up and down, a quarter of
        // the horizon's reach at v_max away (scales with the vehicle: 1 m at 1 m/s, 10 m at
        // 10 m/s): out of the way of an obstacle that the rejected trajectories, all aimed at the
        // goal, cross.
        let reach = 0.25 * self.params.horizon_s * self.limits.v_max;
        let directions: Vec<Vec3> = (0..8)
            .map(|k| {
                let a = k as f64 * std::f64::consts::FRAC_PI_4;
                Vec3::new(a.cos(), a.sin(), 0.0)
            })
            .chain([Vec3::z(), -Vec3::z()])
            .collect();
        if let Ok(escapes) = escape_maneuvers(start, &directions, reach, &self.limits, hold_s) {
            options.extend(escapes.into_iter().map(|t| (FallbackKind::Escape, t)));
        }
        // And dashes in the same directions: 0.9 v_max reached at once, held for a quarter of the
        // horizon, then braking (a person walking at the vehicle's own speed reaches a vehicle
        // that escapes to rest before it is out of the way).
        let cruise_s = 0.25 * self.params.horizon_s;
        if let Ok(dashes) = dash_maneuvers(start, &directions, cruise_s, &self.limits, hold_s) {
            options.extend(dashes.into_iter().map(|t| (FallbackKind::Dash, t)));
        }
        (options, continued)
    }

    /// The fallback's first options for a vehicle stalled before space its commit check
    /// refuses ([`crate::retreat`]): the retreat under way flown on (unless re-anchored), then
    /// manoeuvres to rest at the points back along the flown path `d` and `d/2` from it
    /// horizontally ([`crate::CommitCheck::retreat_m`]). None without a check or a retreat
    /// distance.
    fn retreat_options(
        &self,
        start: &State,
        reanchored: bool,
        hold_s: f64,
    ) -> Vec<(FallbackKind, PolyTraj)> {
        let Some(d) = self.commit_check.as_ref().and_then(|c| c.retreat_m()) else {
            return Vec::new();
        };
        let mut options = Vec::new();
        if let (Some(FallbackKind::Retreat), Some(plan)) = (
            self.committed_fallback,
            self.committed.as_ref().filter(|_| !reanchored),
        ) && plan.t_end() - hold_s > start.t
        {
            options.push((FallbackKind::Retreat, plan.clone()));
        }
        for share in [1.0, 0.5] {
            let Some(to) = self.flown.behind(&start.p, share * d) else {
                continue;
            };
            let away = to - start.p;
            let distance = away.norm();
            if distance < crate::FlownPath::STEP_M {
                continue;
            }
            if let Ok(mut back) = escape_maneuvers(start, &[away], distance, &self.limits, hold_s) {
                options.extend(back.drain(..).map(|t| (FallbackKind::Retreat, t)));
            }
        }
        options
    }

    /// The safety verdict on a fallback option from `start` to its end.
    fn assess_fallback(&self, traj: &PolyTraj, start: &State, scene: &Scene<'_>) -> SafetyVerdict {
        assess_trajectory(
            traj,
            scene,
            start.t,
            traj.t_end(),
            &self.limits,
            &self.params.safety,
        )
    }

    /// Whether a fallback option may be flown at all. A rejected trajectory that breaks the
    /// speed or acceleration limits is no way out (without this, one rejected only for its
    /// limits passed as "collision-free" and the vehicle flew it: up to 1.08 a_max in the rooms
    /// with people).
    fn admissible_fallback(&self, kind: FallbackKind, traj: &PolyTraj, v: &SafetyVerdict) -> bool {
        let jerk_limit = self.limits.a_max / crate::brake::RAMP_S;
        kind != FallbackKind::Evade || !(v.over_limits || max_jerk(traj) > jerk_limit)
    }

    /// With a commit check, whether the stretch of `traj` committed from `start` (as for a
    /// plan: until the next plan takes effect, and braking along it) lies in the space it
    /// accepts; true without one.
    fn known_free_committed(&self, traj: &PolyTraj, start: &State) -> bool {
        let Some(check) = self.commit_check.as_ref() else {
            return true;
        };
        let until = self.next_plan_at(start.t);
        let points = crate::committed_stretch(traj, start.t, until, self.limits.a_max);
        points
            .windows(2)
            .all(|w| check.segment_free(&w[0].1, &w[1].1))
    }

    /// The first admissible option clear of `judged`'s forecasts and in known free space
    /// (`known`, by option), else the first clear one; else, clear of the static map and the
    /// bounds before all (they are known, the forecasts are guesses: a vehicle that dodged a
    /// person into a door frame hit it), then in known free space, the one that collides
    /// latest, then least deeply. Also every verdict computed, by option (up to the chosen
    /// clear one).
    fn first_clear_fallback(
        &self,
        options: &[(FallbackKind, PolyTraj)],
        known: &dyn Fn(usize) -> bool,
        start: &State,
        judged: &Scene<'_>,
    ) -> (Option<(usize, SafetyVerdict)>, Vec<SafetyVerdict>) {
        let rank = |i: usize, v: &SafetyVerdict| {
            (
                u8::from(v.min_static_margin_m >= 0.0),
                u8::from(known(i)),
                v.violation.map_or(f64::INFINITY, |x| x.t),
                v.min_margin_m(),
            )
        };
        let mut best: Option<(usize, SafetyVerdict)> = None;
        let mut first_clear: Option<(usize, SafetyVerdict)> = None;
        let mut verdicts = Vec::with_capacity(options.len());
        for (i, (kind, traj)) in options.iter().enumerate() {
            let v = self.assess_fallback(traj, start, judged);
            verdicts.push(v);
            if !self.admissible_fallback(*kind, traj, &v) {
                continue;
            }
            if v.violation.is_none() {
                if known(i) {
                    return (Some((i, v)), verdicts);
                }
                first_clear.get_or_insert((i, v));
                continue;
            }
            if first_clear.is_none()
                && best.as_ref().is_none_or(|(j, b)| {
                    rank(i, &v).partial_cmp(&rank(*j, b)) == Some(std::cmp::Ordering::Greater)
                })
            {
                best = Some((i, v));
            }
        }
        (first_clear.or(best), verdicts)
    }

    /// Nothing clear of the forecasts: of the options that stay clear of the obstacles' likely
    /// motion — the forecasts without their growth, else without any margin beyond the
    /// obstacle's own size — and of the static map, the one with the widest margin there: in
    /// known free space (`known`, by option) if any is clear, else anywhere.
    /// "Collides latest" alone fled along a faster person's path, where the person catches up,
    /// instead of stepping out of it, which the forecasts' margins (some 0.4 m on each side of a
    /// person's lane) had ruled out (a holdout room with a person pacing across it: 16 of 60
    /// flights collided, 11 with this alone, 3 with the EKF's lag compensation too).
    fn widest_likely_fallback(
        &self,
        options: &[(FallbackKind, PolyTraj)],
        known: &dyn Fn(usize) -> bool,
        verdicts: &[SafetyVerdict],
        start: &State,
        scene: &Scene<'_>,
        continued: Option<usize>,
    ) -> Option<usize> {
        let likely: [Vec<Forecast>; 2] = [
            scene
                .forecasts
                .iter()
                .map(|f| f.growth_held_after(0.0))
                .collect(),
            scene
                .forecasts
                .iter()
                .map(|f| Forecast {
                    r_safe: 0.0,
                    mu: 0.0,
                    ..*f
                })
                .collect(),
        ];
        // Known free space first; then, if nothing there is clear, any.
        for (known_only, forecasts) in [true, false]
            .into_iter()
            .flat_map(|k| likely.iter().map(move |f| (k, f)))
        {
            let level = Scene {
                forecasts,
                ..*scene
            };
            // The clear option with the widest margin (the first clear one braked to rest
            // 3 cm outside a person's likely lane, and the person was not quite there).
            let clear: Vec<(usize, f64)> = options
                .iter()
                .enumerate()
                .filter(|(i, (kind, traj))| self.admissible_fallback(*kind, traj, &verdicts[*i]))
                .filter_map(|(i, (_, traj))| {
                    let v = self.assess_fallback(traj, start, &level);
                    v.violation.is_none().then(|| (i, v.min_margin_m()))
                })
                .filter(|(i, _)| !known_only || known(*i))
                .collect();
            let widest = clear
                .iter()
                .copied()
                .fold(None, |acc: Option<(usize, f64)>, (i, m)| match acc {
                    Some((_, best)) if best >= m => acc,
                    _ => Some((i, m)),
                });
            // Hysteresis: the manoeuvre under way stays while it is nearly as wide.
            let kept = continued.and_then(|c| clear.iter().find(|(i, _)| *i == c).copied());
            if let (Some((c, mc)), Some((_, mw))) = (kept, widest)
                && mc >= mw - FALLBACK_HYSTERESIS_M
            {
                return Some(c);
            }
            if let Some((i, _)) = widest {
                return Some(i);
            }
        }
        None
    }
}

/// How much narrower (m) than the widest option the fallback manoeuvre under way may be and
/// still be flown on ([`Manager`]'s fallback): about what a person walking at 1 m/s covers in
/// one 0.1 s cycle.
const FALLBACK_HYSTERESIS_M: f64 = 0.1;

/// The fallback judges its options against the forecasts grown for this fraction of the horizon
/// (1 s at 4 s) and then held ([`Manager`]'s fallback).
const FALLBACK_GROWTH_FRACTION: f64 = 0.25;

/// Largest jerk norm of `traj` (m/s³), 16 samples per piece.
fn max_jerk(traj: &PolyTraj) -> f64 {
    let mut worst = 0.0_f64;
    let mut t = traj.t_start();
    for d in traj.durations() {
        for k in 0..=16 {
            worst = worst.max(traj.jerk(t + d * k as f64 / 16.0).norm());
        }
        t += d;
    }
    worst
}

/// `forecasts` followed by their mirror images over `[from, until]`
/// ([`trust_predict::wall_images`]) at the walls of the box each obstacle is known to stay
/// inside ([`Forecast::walls`]), or else at the map's `bounds`.
fn with_wall_images(
    mut forecasts: Vec<Forecast>,
    bounds: &trust_predict::Aabb,
    from: f64,
    until: f64,
) -> Vec<Forecast> {
    let images: Vec<Forecast> = forecasts
        .iter()
        .flat_map(|f| {
            trust_predict::wall_images(f, f.walls.as_ref().unwrap_or(bounds), from, until)
        })
        .collect();
    forecasts.extend(images);
    forecasts
}

/// Checks the inputs of [`Manager::step`].
fn check_step_input(now: f64, measured: &State, goal: &Vec3) -> Result<(), PlanError> {
    check_finite("now", now)?;
    measured.validate("state")?;
    check_finite_vec("goal", goal)
}

/// Clearance (m) from the static map of the stop held short of a goal outside the bounds or
/// inside a static obstacle ([`Manager::step`]).
pub const HOLD_CLEARANCE_M: f64 = 0.5;

/// Why a (finite) goal cannot be reached whatever the route: outside the map bounds, or inside a
/// static obstacle (signed distance below zero).
fn invalid_goal_cause(goal: &Vec3, scene: &Scene<'_>) -> Option<UnreachableCause> {
    if scene.check_in_bounds("goal", goal).is_err() {
        return Some(UnreachableCause::GoalOutsideBounds);
    }
    let signed_distance_m = scene.static_clearance(goal);
    (signed_distance_m < 0.0).then_some(UnreachableCause::GoalInsideObstacle { signed_distance_m })
}

/// The farthest point of the segment from `from` toward `goal` (clipped into the map bounds) that
/// `from` sees and that keeps [`HOLD_CLEARANCE_M`] from the static map, on a grid of 64 steps;
/// `from` when there is none.
fn hold_point_toward(from: &Vec3, goal: &Vec3, scene: &Scene<'_>) -> Vec3 {
    let b = scene.map.bounds();
    let aim = Vec3::new(
        goal.x.clamp(b.min.x, b.max.x),
        goal.y.clamp(b.min.y, b.max.y),
        goal.z.clamp(b.min.z, b.max.z),
    );
    const STEPS: u32 = 64;
    (1..=STEPS)
        .rev()
        .map(|k| from + (aim - from) * (f64::from(k) / f64::from(STEPS)))
        .find(|q| {
            b.contains(q)
                && scene.static_clearance(q) >= HOLD_CLEARANCE_M
                && scene.map.segment_clear(from, q, 0.0)
        })
        .unwrap_or(*from)
}

/// A vehicle slower than this fraction of `v_max` is at rest for
/// [`Manager::awaiting_first_route`] (2 %: a hover's tracking jitter, not a flight).
const REST_SPEED_FRACTION: f64 = 0.02;

/// What one cycle carries from step to step of [`Manager::step`].
struct Cycle {
    /// The replan start ([`Manager::replan_start`]).
    start: State,
    /// The goal the branches are ranked against ([`Branch::reaches_goal`]).
    goal: Vec3,
    /// The flight is stalled ([`crate::progress`]): explore with more paths and rank by progress.
    stalled: bool,
    /// The stall began this cycle (the router, if any, re-plans the route).
    newly_stalled: bool,
    /// Whether the replan start was re-anchored on the measured state.
    reanchored: bool,
    /// The ranking weights of `J`.
    weights: RankingWeights,
    /// The solves' deadline ([`ManagerParams::enforce_budget`]).
    deadline: Option<Instant>,
    /// Whether FwdExplore runs this cycle ([`ManagerParams::explore_period_cycles`]).
    explore: bool,
    /// The cycle's events, in order.
    events: Vec<Event>,
    /// Trajectories dropped by the safety pass, with what they were (a branch or a candidate):
    /// the fallback may brake along them.
    rejected: Vec<(FallbackKind, PolyTraj)>,
}

/// What [`fwd_explore`] found (empty when the cycle does not explore).
#[derive(Default)]
struct Explored {
    /// The explored trajectories, solved cold and checked, in the frontend's order.
    candidates: Vec<Candidate>,
    /// The frontend's report (`None` if it failed or did not run).
    frontend: Option<FrontendReport>,
    /// The frontend's error, if it failed.
    frontend_error: Option<PlanError>,
    /// Whether the straight guide was explored ([`ManagerParams::straight_guide_when_empty`]).
    straight_guide: bool,
    /// Guide paths left for the following cycles ([`ManagerParams::cold_solves_per_cycle`]).
    deferred: Vec<GuidePath>,
}

/// FwdExplore (Algorithm 1, line 8): the frontend's paths from the replan start (its first
/// [`ManagerParams::max_explored_paths`]), each solved cold from the path and checked, in
/// parallel.
fn fwd_explore<F: PathFrontend, B: TrajectoryBackend>(
    frontend: &F,
    rng: &mut Rng,
    query: &PathQuery,
    solver: &Solver<'_, '_, B>,
    spans: &mut Spans,
) -> Explored {
    let params = solver.params;
    let mut explored = Explored::default();
    let search = spans.time(Span::Frontend, || frontend.search(query, solver.scene, rng));
    let mut paths = match search {
        Ok(mut result) => {
            let path_count = result.paths.len();
            result.paths.truncate(solver.explored_paths);
            explored.frontend = Some(FrontendReport {
                name: frontend.name().to_string(),
                path_count,
                explored_count: result.paths.len(),
                stats: result.stats,
            });
            result.paths
        }
        Err(e) => {
            explored.frontend_error = Some(e);
            Vec::new()
        }
    };
    if let Some(guide) = &solver.route_guide {
        // With a route, always explore along it: the frontend's sampling box and the straight
        // guide cannot see around an obstacle wider than the box (a wide wall, a U-trap).
        paths.push(guide.clone());
    }
    if paths.is_empty() && params.straight_guide_when_empty {
        // Beyond the paper: never explore empty-handed. The frontend's cones are conservative (an
        // obstacle's whole sweep over the horizon), so in crowded moments it may find no path
        // while a trajectory that passes behind an obstacle exists; the straight guide lets the
        // backend look for it in time.
        let reach = query.horizon_s * query.limits.v_max;
        let end = straight_end(&query.start.p, &query.goal, reach);
        if let Ok(g) = GuidePath::new(vec![query.start.p, end]) {
            paths.push(g);
            explored.straight_guide = true;
        }
    }
    if let Some(k) = params.cold_solves_per_cycle.filter(|_| params.history) {
        explored.deferred = paths.split_off(k.min(paths.len()));
    }
    explored.candidates = solve_cold(&paths, solver);
    explored
}

/// The cold solves of `paths` (in parallel), each repaired if narrowly unsafe.
fn solve_cold<B: TrajectoryBackend>(
    paths: &[GuidePath],
    solver: &Solver<'_, '_, B>,
) -> Vec<Candidate> {
    paths
        .par_iter()
        .map(|p| {
            let cold =
                solver.solve_with(InitialGuess::Guide(p), solver.params.cold_max_evaluations);
            solver.repaired(cold)
        })
        .collect()
}

/// A cycle that does not explore solves the next [`ManagerParams::cold_solves_per_cycle`] of
/// the guide paths the last exploration left, each from this cycle's start: the part of the
/// guide behind its point nearest the start is dropped and the start put in front.
fn solve_deferred<B: TrajectoryBackend>(
    mut pending: Vec<GuidePath>,
    solver: &Solver<'_, '_, B>,
) -> Explored {
    let k = solver.params.cold_solves_per_cycle.unwrap_or(usize::MAX);
    let rest = pending.split_off(k.min(pending.len()));
    let paths: Vec<GuidePath> = pending
        .iter()
        .filter_map(|g| rebased_guide(g, &solver.start.p))
        .collect();
    Explored {
        candidates: solve_cold(&paths, solver),
        deferred: rest,
        ..Explored::default()
    }
}

/// `guide` from `from`: `from`, then the guide from its point nearest `from` on (`None` if the
/// guide does not lead anywhere from there).
fn rebased_guide(guide: &GuidePath, from: &Vec3) -> Option<GuidePath> {
    let pts = &guide.points;
    let mut best = (f64::INFINITY, 0, *from);
    for (i, w) in pts.windows(2).enumerate() {
        let d = w[1] - w[0];
        let len2 = d.norm_squared();
        let t = if len2 > 0.0 {
            ((from - w[0]).dot(&d) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let q = w[0] + d * t;
        let dist = (q - from).norm();
        if dist < best.0 {
            best = (dist, i + 1, q);
        }
    }
    let mut points = vec![*from];
    points.extend(pts.get(best.1..).unwrap_or(&[]).iter().copied());
    points.dedup_by(|a, b| (*a - *b).norm() <= 1e-9);
    (points.len() >= 2)
        .then(|| GuidePath::new(points).ok())
        .flatten()
}

/// The named spans of a cycle that [`Spans`] times.
#[derive(Debug, Clone, Copy)]
enum Span {
    /// The frontend search ([`CycleTiming::frontend_ms`]).
    Frontend,
    /// Planning the global route ([`CycleTiming::route_ms`]).
    Route,
    /// Homotopy checks, safety checks outside the parallel solves, and the fallback's
    /// ([`CycleTiming::checker_ms`]).
    Checks,
}

/// The span recorder of one cycle: the one place [`Manager::step`]'s [`CycleTiming`] is filled,
/// from named spans timed here and from the solves' own statistics (each parallel solve measures
/// its solve and safety check, carried in its [`Candidate`]).
struct Spans {
    started: Instant,
    timing: CycleTiming,
}

impl Spans {
    fn start() -> Self {
        Spans {
            started: Instant::now(),
            timing: CycleTiming::default(),
        }
    }

    /// Runs `f`, adding its wall time to `span`.
    fn time<T>(&mut self, span: Span, f: impl FnOnce() -> T) -> T {
        let t = Instant::now();
        let out = f();
        let elapsed = ms(t.elapsed());
        match span {
            Span::Frontend => self.timing.frontend_ms += elapsed,
            Span::Route => self.timing.route_ms += elapsed,
            Span::Checks => self.timing.checker_ms += elapsed,
        }
        out
    }

    /// Adds one solved candidate (both solves of a repair attempt); `cold`: a solve from a
    /// frontend path.
    fn solved(&mut self, cand: &Candidate, cold: bool) {
        let timing = &mut self.timing;
        timing.checker_ms += ms(cand.check_time);
        if cand.repaired {
            timing.repair_count += 1;
        }
        let other = cand.other_solve.map(|(solve, evaluations, check)| {
            timing.checker_ms += ms(check);
            (solve, evaluations)
        });
        let this = cand
            .result
            .as_ref()
            .ok()
            .map(|(s, _)| (s.stats.elapsed, s.stats.evaluation_count));
        for (solve, evaluations) in other.into_iter().chain(this) {
            timing.backend_ms += ms(solve);
            timing.solve_count += 1;
            timing.evaluations += evaluations;
            if cold {
                timing.cold_backend_ms += ms(solve);
                timing.cold_solve_count += 1;
            }
        }
    }

    /// The cycle's timing, with the wall time since [`Spans::start`].
    fn finish(mut self) -> CycleTiming {
        self.timing.wall_ms = ms(self.started.elapsed());
        self.timing
    }
}

/// The event of a trajectory dropped by the safety check with `verdict`.
fn dropped_collision(id: Option<BranchId>, verdict: &SafetyVerdict, limits: &Limits) -> Event {
    Event::DroppedCollision {
        id,
        violation: verdict.violation,
        braking_tail: verdict.braking_tail_violated,
        over_limits: verdict.over_limits.then_some(LimitExcess {
            max_speed_mps: verdict.max_speed,
            v_max: limits.v_max,
            max_accel_mps2: verdict.max_accel,
            a_max: limits.a_max,
        }),
    }
}

/// The solves' deadline of work started at `started` ([`ManagerParams::enforce_budget`]).
fn deadline_from(started: Instant, params: &ManagerParams) -> Option<Instant> {
    deadline_at(started, params, SOLVE_DEADLINE_FRACTION)
}

/// `started` plus `fraction` of the cycle budget, with [`ManagerParams::enforce_budget`].
fn deadline_at(started: Instant, params: &ManagerParams, fraction: f64) -> Option<Instant> {
    params
        .enforce_budget
        .then(|| started + Duration::from_secs_f64(fraction * params.cycle_budget_ms * 1e-3))
}

/// Everything a parallel solve needs, shared read-only.
struct Solver<'s, 'a, B> {
    backend: &'s B,
    scene: &'s Scene<'a>,
    start: State,
    goal: Vec3,
    limits: Limits,
    horizon_s: f64,
    deadline: Option<Instant>,
    params: &'s ManagerParams,
    /// Most frontend paths to optimize this cycle: [`ManagerParams::max_explored_paths`], twice
    /// that while the flight is stalled.
    explored_paths: usize,
    /// The route from the replan start to the local goal ([`Manager::set_route`]), explored as a
    /// guide path every exploring cycle.
    route_guide: Option<GuidePath>,
}

impl<'s, 'a, B: TrajectoryBackend> Solver<'s, 'a, B> {
    /// The solver from `start` toward `goal`; `stalled` doubles the explored paths.
    fn new(
        backend: &'s B,
        scene: &'s Scene<'a>,
        (start, goal, limits): (State, Vec3, Limits),
        params: &'s ManagerParams,
        deadline: Option<Instant>,
        stalled: bool,
        route_guide: Option<GuidePath>,
    ) -> Self {
        Solver {
            backend,
            scene,
            start,
            goal,
            limits,
            horizon_s: params.horizon_s,
            deadline,
            params,
            explored_paths: params.max_explored_paths * if stalled { 2 } else { 1 },
            route_guide,
        }
    }

    /// FwdMarch (Algorithm 1, line 6): the main branch re-solved from the replan start,
    /// warm-started from its trajectory (its free terminal moves on toward the goal as the goal
    /// guidance surface shrinks), with [`ManagerParams::warm_max_evaluations`].
    fn fwd_march(&self, traj: &PolyTraj) -> Candidate {
        self.fwd_march_within(traj, self.params.warm_max_evaluations)
    }

    /// [`Solver::fwd_march`] with its evaluation budget given.
    fn fwd_march_within(&self, traj: &PolyTraj, max_evaluations: Option<usize>) -> Candidate {
        self.repaired(self.solve_with(InitialGuess::WarmStart(traj), max_evaluations))
    }

    /// BwdReplan (Algorithm 1, line 7): a sub-branch re-anchored at the replan start,
    /// warm-started from its trajectory, with [`ManagerParams::sub_branch_max_evaluations`].
    fn bwd_replan(&self, traj: &PolyTraj) -> Candidate {
        let budget = (self.params.sub_branch_max_evaluations).or(self.params.warm_max_evaluations);
        self.repaired(self.solve_with(InitialGuess::WarmStart(traj), budget))
    }

    /// `cand` again, warm-started from its own trajectory, if it failed the safety check by at
    /// most `repair_margin_m` and the re-solve passes; otherwise `cand` unchanged.
    fn repaired(&self, cand: Candidate) -> Candidate {
        // With the cold budget: a repair is rare and its first solve stopped short of clean.
        self.repaired_within(cand, self.params.cold_max_evaluations)
    }

    /// [`Solver::repaired`] with the repair's evaluation budget given.
    fn repaired_within(&self, cand: Candidate, max_evaluations: Option<usize>) -> Candidate {
        let margin = self.params.repair_margin_m;
        let first = match &cand.result {
            Ok((first, verdict)) if margin > 0.0 && narrowly_unsafe(verdict, margin) => first,
            _ => return cand,
        };
        let again = self.solve_with(InitialGuess::WarmStart(&first.traj), max_evaluations);
        let spent = |c: &Candidate| {
            c.result
                .as_ref()
                .ok()
                .map(|(s, _)| (s.stats.elapsed, s.stats.evaluation_count, c.check_time))
        };
        match &again.result {
            Ok((_, verdict)) if verdict.safe => Candidate {
                other_solve: spent(&cand),
                repaired: true,
                ..again
            },
            _ => Candidate {
                other_solve: spent(&again),
                ..cand
            },
        }
    }

    fn solve_with(&self, initial: InitialGuess<'_>, max_evaluations: Option<usize>) -> Candidate {
        let req = TrajRequest {
            start: self.start,
            goal: self.goal,
            limits: self.limits,
            initial,
            deadline: self.deadline,
            horizon_s: Some(self.horizon_s),
            max_evaluations,
        };
        match self.backend.optimize(&req, self.scene) {
            Err(e) => Candidate {
                result: Err(e),
                check_time: Duration::ZERO,
                other_solve: None,
                repaired: false,
            },
            Ok(solution) => {
                let t = Instant::now();
                let traj = &solution.traj;
                let verdict = check_trajectory(
                    traj,
                    self.scene,
                    self.start.t,
                    traj.t_end(),
                    &self.limits,
                    &self.params.safety,
                );
                Candidate {
                    check_time: t.elapsed(),
                    result: Ok((solution, verdict)),
                    other_solve: None,
                    repaired: false,
                }
            }
        }
    }
}

/// The outcome of [`choose_main`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MainDecision {
    /// The main branch.
    pub main: BranchId,
    /// Whether it differs from the incumbent (or there was none).
    pub switched: bool,
    /// Whether the incumbent is still among the ranked branches.
    pub incumbent_kept: bool,
}

/// The main-branch rule with hysteresis, on branches `ranked` by ascending `J` (`(id, J)`): the
/// incumbent stays unless the best branch's excess cost `J − ideal` is below `hysteresis` times the
/// incumbent's, or the incumbent is gone; without an incumbent the best branch is chosen. `None`
/// for no branches.
pub fn choose_main(
    ranked: &[(BranchId, f64)],
    incumbent: Option<BranchId>,
    ideal: f64,
    hysteresis: f64,
) -> Option<MainDecision> {
    let &(best, best_j) = ranked.first()?;
    let excess = |j: f64| (j - ideal).max(0.0);
    let kept = incumbent.and_then(|id| ranked.iter().find(|(i, _)| *i == id));
    Some(match kept {
        Some(&(inc, inc_j)) => {
            let switch = inc != best && excess(best_j) < hysteresis * excess(inc_j);
            MainDecision {
                main: if switch { best } else { inc },
                switched: switch,
                incumbent_kept: true,
            }
        }
        None => MainDecision {
            main: best,
            switched: true,
            incumbent_kept: false,
        },
    })
}

/// Sorts `branches` in ranking order ([`Branch::rank_cmp`]).
fn sort_by_rank(branches: &mut [Branch], by_progress: bool) {
    branches.sort_by(|a, b| a.rank_cmp(b, by_progress));
}

/// Distance (m) from the end of `traj` to `goal` ([`Branch::shortfall_m`]).
fn shortfall(traj: &PolyTraj, goal: &Vec3) -> f64 {
    (traj.position(traj.t_end()) - goal).norm()
}

/// Drops the worst branches beyond `n`, never `protect`.
fn pop_back(kept: &mut Vec<Branch>, n: usize, protect: Option<BranchId>, events: &mut Vec<Event>) {
    while kept.len() > n {
        let Some(i) = kept.iter().rposition(|b| Some(b.id) != protect) else {
            return;
        };
        let b = kept.remove(i);
        events.push(Event::DroppedPopBack { id: b.id });
    }
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_rebased_guide_starts_at_the_new_start_and_drops_what_lies_behind() {
        let g = GuidePath::new(vec![
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(10.0, 0.0, 1.0),
            Vec3::new(10.0, 10.0, 1.0),
        ])
        .unwrap();
        let r = rebased_guide(&g, &Vec3::new(3.0, 0.5, 1.0)).unwrap();
        assert_eq!(
            r.points,
            vec![
                Vec3::new(3.0, 0.5, 1.0),
                Vec3::new(10.0, 0.0, 1.0),
                Vec3::new(10.0, 10.0, 1.0)
            ]
        );
        // Past the corner: the second leg only.
        let r = rebased_guide(&g, &Vec3::new(10.5, 4.0, 1.0)).unwrap();
        assert_eq!(r.points.len(), 2);
        assert_eq!(r.points[1], Vec3::new(10.0, 10.0, 1.0));
        // At the guide's end: nothing left to follow.
        assert!(rebased_guide(&g, &Vec3::new(10.0, 10.0, 1.0)).is_none());
        // A one-point guide (start on the goal) leads nowhere.
        let one = GuidePath::new(vec![Vec3::new(1.0, 1.0, 1.0)]).unwrap();
        assert!(
            rebased_guide(&one, &Vec3::new(0.0, 0.0, 1.0)).is_some_and(|r| r.points.len() == 2)
        );
    }

    #[test]
    fn only_narrow_failures_are_repaired() {
        let verdict = |safe: bool, margin: Option<f64>| SafetyVerdict {
            safe,
            min_static_margin_m: f64::INFINITY,
            min_dynamic_margin_m: margin.unwrap_or(f64::INFINITY),
            violation: margin.map(|m| crate::safety::Violation {
                t: 1.0,
                with: crate::safety::Hit::Bounds,
                margin_m: m,
            }),
            escaping: false,
            max_speed: 1.0,
            max_accel: 1.0,
            over_limits: margin.is_none() && !safe,
            braking_tail_violated: false,
            sample_count: 10,
        };
        assert!(!narrowly_unsafe(&verdict(true, None), 0.05));
        assert!(narrowly_unsafe(&verdict(false, Some(-0.004)), 0.05));
        assert!(!narrowly_unsafe(&verdict(false, Some(-0.2)), 0.05));
        assert!(narrowly_unsafe(&verdict(false, None), 0.05), "limits only");
        assert!(!narrowly_unsafe(&verdict(false, Some(f64::NAN)), 0.05));
    }

    #[test]
    fn a_sharp_corner_is_aimed_at_only_while_it_hides_the_route_beyond() {
        use trust_core::Aabb;
        use trust_geometry::{AaBox, Shape};
        let v = Vec3::new;
        let slab = |min: Vec3, max: Vec3| Shape::AaBox(AaBox { min, max });
        let bounds = Aabb::new(v(-1.0, -5.0, 0.0), v(20.0, 15.0, 10.0)).unwrap();
        // A route along x turning by 90° at (10, 0, 2) to +y; the vehicle at (4, 0, 2).
        let route = GlobalRoute::from_points(vec![
            v(0.0, 0.0, 2.0),
            v(10.0, 0.0, 2.0),
            v(10.0, 10.0, 2.0),
        ])
        .unwrap();
        let corner = RoutePoint {
            s: 10.0,
            point: v(10.0, 0.0, 2.0),
        };
        let ahead = RoutePoint {
            s: 16.0,
            point: v(10.0, 6.0, 2.0),
        };
        let from = v(4.0, 0.0, 2.0);
        let aim = |map: &StaticMap, s0: f64| {
            aim_past_corner(&route, map, &from, s0, corner, ahead, 0.3, 0.3)
        };
        // Nothing hides the route beyond the corner: aim past it, at `ahead`.
        let open = StaticMap::empty(bounds).unwrap();
        assert_eq!(aim(&open, 4.0).point, ahead.point);
        // The route turns round the end of a wall along its left: the corner first.
        let wall = StaticMap::from_shapes(bounds, vec![slab(v(-1.0, 0.5, 0.0), v(9.5, 1.0, 10.0))])
            .unwrap();
        assert_eq!(aim(&wall, 4.0).point, corner.point);
        // Off the route (its point at `s0` behind a wall, so `last_in_sight` gives up and
        // returns `ahead`, which the wall hides from the vehicle): still the corner.
        let off = wall
            .clone()
            .with_shapes(vec![slab(v(2.0, -5.0, 0.0), v(3.0, 0.4, 10.0))])
            .unwrap();
        assert_eq!(aim(&off, 0.5).point, corner.point);
        // A shaft through a slab at z ∈ [4, 5] above the corner: the aim is what is in sight
        // past the corner, up to the slab's hole, not the hidden shaft above it.
        let shaft_route =
            GlobalRoute::from_points(vec![v(0.0, 0.0, 2.0), v(10.0, 0.0, 2.0), v(10.0, 0.0, 9.0)])
                .unwrap();
        let shaft = StaticMap::from_shapes(
            bounds,
            vec![
                slab(v(-1.0, -5.0, 4.0), v(9.0, 15.0, 5.0)),
                slab(v(11.0, -5.0, 4.0), v(20.0, 15.0, 5.0)),
                slab(v(9.0, -5.0, 4.0), v(11.0, -1.0, 5.0)),
                slab(v(9.0, 1.0, 4.0), v(11.0, 15.0, 5.0)),
            ],
        )
        .unwrap();
        let up = RoutePoint {
            s: 16.0,
            point: v(10.0, 0.0, 8.0),
        };
        let a = aim_past_corner(&shaft_route, &shaft, &from, 4.0, corner, up, 0.3, 0.3);
        assert!(a.s > corner.s && a.point.z < 4.5, "{a:?}");
        assert!(shaft.segment_clear(&from, &a.point, 0.3));
    }

    #[test]
    fn hysteresis_keeps_the_incumbent_unless_clearly_beaten() {
        // Ideal 20: excesses 1.0 (incumbent 7) and 0.8 (challenger 3).
        let ranked = [(3, 20.8), (7, 21.0)];
        let keep = choose_main(&ranked, Some(7), 20.0, 0.75).unwrap();
        assert_eq!((keep.main, keep.switched), (7, false));
        // Without hysteresis the better one wins.
        let switch = choose_main(&ranked, Some(7), 20.0, 1.0).unwrap();
        assert_eq!((switch.main, switch.switched), (3, true));
        // A clear win (excess 0.5 < 0.75) switches even with hysteresis.
        let ranked = [(3, 20.5), (7, 21.0)];
        let d = choose_main(&ranked, Some(7), 20.0, 0.75).unwrap();
        assert_eq!((d.main, d.switched, d.incumbent_kept), (3, true, true));
        // A dropped incumbent is replaced by the best.
        let d = choose_main(&ranked, Some(9), 20.0, 0.75).unwrap();
        assert_eq!((d.main, d.switched, d.incumbent_kept), (3, true, false));
        // First plan; no branches.
        assert_eq!(choose_main(&ranked, None, 20.0, 0.75).unwrap().main, 3);
        assert!(choose_main(&[], Some(1), 0.0, 0.75).is_none());
        // An incumbent at the ideal cost cannot be beaten by a better-ranked tie.
        let ranked = [(1, 20.0), (2, 20.0)];
        assert_eq!(choose_main(&ranked, Some(2), 20.0, 0.75).unwrap().main, 2);
    }
}
