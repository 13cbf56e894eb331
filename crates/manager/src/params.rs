//! Parameters of the [`crate::Manager`] and of its safety check.

use serde::{Deserialize, Serialize};
use trust_core::{
    Limits, Overridable, PlanError, RankingWeights, check_non_negative, check_positive,
};

/// The default time the forecasts' uncertainty grows, as a fraction of the planning horizon
/// ([`ManagerParams::forecast_growth`]): 1/16, 0.25 s at `T_h` = 4 s. Measured against 1/4 (the
/// earlier default) and 1/8 on the scenario suite, its variants, the room files with people
/// and two holdout sets (ARCHITECTURE.md, "Forecasts stop growing"): 1/16 arrives in every
/// flight, none collides, and the rooms with people are the fastest of the three.
pub const GROWTH_FRACTION: f64 = 1.0 / 16.0;

/// How the manager keeps and selects branches, its timing and its safety margins.
///
/// The three planner configurations of the paper's comparison (Sec. IV-D) differ only here and in
/// the frontend: TRUST-Planner (`max_branches = 5`, `history = true`), baseline 3 (`max_branches =
/// 5`, `history = false`), baselines 1 and 2 (`max_branches = 1`, `history = false`, one explored
/// path per cycle). See [`ManagerParams::trust`], [`ManagerParams::multi_branch_without_history`]
/// and [`ManagerParams::single_branch`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Overridable)]
#[serde(deny_unknown_fields, default)]
pub struct ManagerParams {
    /// `N`, the most branches kept (Algorithm 1's `PopBack` beyond it). Paper: five
    /// homotopy-distinct trajectories in Table Sim-B-1.
    pub max_branches: usize,
    /// Keep branches from cycle to cycle (Algorithm 1: `FwdMarch` of the main branch, `BwdReplan`
    /// of the sub-branches). `false`: every cycle starts from fresh frontend paths only (the
    /// paper's baseline 3 and, with one branch, baselines 1 and 2).
    pub history: bool,
    /// Most frontend paths optimized per cycle (`FwdExplore`); the frontend's first paths (its
    /// best) are taken. Ours: 5, DEV-PRM's own cap on selected paths is 6.
    pub max_explored_paths: usize,
    /// When the frontend returns no path, explore the straight guide toward the goal (truncated to
    /// `T_h·v_max`) instead (beyond the paper). DEV-PRM's predictive cones are conservative — an
    /// obstacle's whole sweep over the horizon — so in crowded moments it can find no path while a
    /// trajectory passing behind an obstacle exists in space-time. Default `true`.
    pub straight_guide_when_empty: bool,
    /// Forecast the moving obstacles as staying inside the map's bounds: each cycle the manager
    /// adds the mirror images of every forecast at the bounds' walls over twice the horizon
    /// ([`trust_predict::wall_images`]), so a person walking at a room's wall is expected back
    /// along the reflected line (beyond the paper). A constant-velocity forecast walks them through
    /// the wall, and a vehicle crossing behind them meets them on their way back. A forecast
    /// that knows the box its obstacle stays inside ([`trust_predict::Forecast::walls`], e.g. a
    /// scenario's obstacle region) is mirrored at that box's walls instead. Default `true`.
    pub wall_images: bool,
    /// How long each forecast's uncertainty grows before it stops (s, beyond the paper;
    /// [`trust_predict::Forecast::with_growth_for`]); `None`: [`GROWTH_FRACTION`] of the
    /// horizon (0.25 s at `T_h` = 4 s, a few cycles: the time a plan is committed to before the
    /// next cycle judges it against new observations); `f64::INFINITY` (`inf` in TOML): the
    /// paper's growth for ever. Every part of the cycle — frontend cones, backend penalty,
    /// safety check, fallback — sees the capped forecasts. Grown for the whole horizon a
    /// person's forecast (0.56 m/s with the simulated sensor) covers a small room: in the rooms
    /// with people the vehicle waited or backed off. Capped at 1 s (six room files, seeds
    /// 100–119) room_penetration took 8.1 s instead of 15.9 s on average, room_people 7.0
    /// instead of 11.2 s; at 0.25 s every one of those 120 flights arrives, and people faster
    /// than the vehicle no longer trap it; see ARCHITECTURE.md for the rest.
    pub forecast_growth_s: Option<f64>,
    /// Evaluation budget (cost evaluations) of a warm-started re-solve (FwdMarch, BwdReplan);
    /// `None`: the backend's own. The branch is refined again next cycle, so a re-solve need not
    /// converge fully. Default 100 (beyond the paper): flight times as without a cap at about
    /// half the median cycle, while 50 costs flight time (measurements in ARCHITECTURE.md,
    /// "Exploration period and warm budget").
    pub warm_max_evaluations: Option<usize>,
    /// Evaluation budget of a sub-branch's re-solve (BwdReplan); `None`: the same as
    /// [`ManagerParams::warm_max_evaluations`]. A sub-branch is refined again every cycle and only
    /// needs to be good enough to challenge the main branch, so it can take a smaller share of
    /// the cycle than the main branch's FwdMarch, which the vehicle flies.
    /// Default 50 (beyond the paper): a shorter cycle for about 1 % more flight time
    /// (measurements in ARCHITECTURE.md, "Exploration period and warm budget").
    pub sub_branch_max_evaluations: Option<usize>,
    /// Evaluation budget of a cold solve from a frontend path (FwdExplore, and a repair's
    /// re-solve); `None`: the backend's own (1000 for the presets). Default 400 with history
    /// (beyond the paper): a new branch is re-solved again every cycle (BwdReplan) and need not
    /// converge in its first solve; cold solves were 70 % of TRUST-Planner's evaluations on E4
    /// (a median 553 each, stopping on a stalled cost). 300 let the pacing person of
    /// `room_penetration_pacing_person` (seed 26) hit the vehicle. `None` for the presets
    /// without history (baselines 1–3), which keep nothing to refine (decision record 0045).
    pub cold_max_evaluations: Option<usize>,
    /// Cold solves per cycle (with history): an exploring cycle solves the first this many of
    /// its guide paths and keeps the rest, each following cycle solves the next this many from
    /// its own start (the guide's part behind the vehicle dropped), until the next exploration
    /// replaces them. `None`: every path in the exploring cycle (the paper's Algorithm 1).
    /// Default 2 (beyond the paper): an exploring cycle no longer pays for all its cold solves
    /// at once, which made it the worst cycle (E4: 10–16 solves, 2–3× the 50 ms budget).
    pub cold_solves_per_cycle: Option<usize>,
    /// Take the sub-branches' re-solves (BwdReplan) and FwdExplore (the frontend and its cold
    /// solves) off the cycle's critical path (beyond the paper): as a cycle ends they start on a
    /// worker thread from the next cycle's replan start as predicted by the committed plan, and
    /// the next cycle merges them (waiting for them if need be, so a seed still gives one
    /// flight) while it re-solves only the main branch itself. A merged branch that would become
    /// the main branch is checked again against the newer forecasts first. The next cycle solves
    /// everything itself when its start is not the predicted one (re-anchored, another period),
    /// when its aim moved, and always without history or without a shared map
    /// ([`crate::Manager::share_map`]). Default `true`: the paper's exploring cycle (frontend and
    /// cold solves, 20–40 ms on E4's point-cloud ESDF) was the cycle's tail.
    pub background: bool,
    /// Evaluation budget of the main branch's re-solve in a cycle that merged the worker's job
    /// ([`ManagerParams::background`]); `None`: [`ManagerParams::warm_max_evaluations`]. The
    /// worker has re-solved the main branch from this cycle's start already (FwdMarch with
    /// [`ManagerParams::worker_march_max_evaluations`], against the previous cycle's forecasts),
    /// so the cycle's own re-solve starts
    /// from that and only takes in the newest forecasts; a converged start stops early. Default
    /// `None`: 30 evaluations flew E4 as well, but in the rooms with people the less refined
    /// main branch collided (`room_penetration_pacing_person`, seed 26) or took twice as long
    /// (`room_penetration_small_fast_people`, seed 202: 24.8 s against 10.1 s).
    pub merge_max_evaluations: Option<usize>,
    /// Evaluation budget of the worker's re-solve of the main branch (FwdMarch off the cycle,
    /// [`ManagerParams::background`]); `None`: [`ManagerParams::warm_max_evaluations`]. The
    /// cycle then re-solves from the worker's result with the newest forecasts, and a converged
    /// start stops early, so what the worker leaves unconverged lands on the cycle. Default 200
    /// (beyond the paper): on E4 the main branch's re-solve seldom converges within the warm
    /// budget, so with 100 here the cycle's own re-solve ran on for a median 98 evaluations;
    /// with 200 off the cycle it stops after a median 21 (`trust-sim run scenarios/e4.toml
    /// --seed 9401`), and flight times and the suite's outcomes stay as they were.
    pub worker_march_max_evaluations: Option<usize>,
    /// Run FwdExplore (the frontend and the cold solves) every this many cycles, and in every cycle
    /// that starts with fewer than two kept branches or without a main branch. 1: every cycle (the
    /// paper's Algorithm 1). At least 1. Default 3 (beyond the paper): the kept branches carry
    /// the explored classes from cycle to cycle, so exploring every third cycle costs little
    /// flight time while most cycles skip the frontend, which on E4's point-cloud ESDF is most of
    /// an exploring cycle (measurements in ARCHITECTURE.md, "Exploration period and warm
    /// budget"). With history off every cycle explores.
    pub explore_period_cycles: usize,
    /// A trajectory (kept branch or new candidate) that fails the safety check by at most this
    /// much (m) — or only on the speed and acceleration limits — is re-solved once, warm-started
    /// from itself with the cold budget ([`ManagerParams::cold_max_evaluations`]); the re-solve
    /// replaces it if it passes (a narrowly unsafe trajectory is repaired rather than dropped).
    /// The penalties are soft and a solve may stop on its budget, so a few millimetres of
    /// violation are common in cold solves (E3). `0` switches repairs off. Default 0.05 m.
    pub repair_margin_m: f64,
    /// Weights of the ranking cost `J = λ_t·H_t + λ_s·H_s + λ_e·I_e`; `None` uses the paper's rule
    /// (Table Sim-B-1: `λ_t = 1`, `λ_s = 1/v_max`, `λ_e = 1e-4`) with the vehicle's `v_max`.
    pub ranking: Option<RankingWeights>,
    /// Planning horizon `T_h` (s): the frontend's cones and goal guidance surface, and the
    /// backend's terminal surface (`r_des = ‖p_s − p_g‖ − T_h·v_max`). Default 4 s: the paper's
    /// Fig. Sim-A-1-1(a) has `r_des = 25 m` for a goal 65 m away at `v_max = 10 m/s`.
    pub horizon_s: f64,
    /// How long the braking fallback holds still after it has stopped (s): the plan the vehicle
    /// flies while every branch is unsafe ends this long after the stop. `None`: the planning
    /// horizon [`ManagerParams::horizon_s`] (the stop is then planned as far ahead as any branch).
    pub brake_hold_s: Option<f64>,
    /// Time budget of one cycle (ms). With [`ManagerParams::enforce_budget`] every trajectory
    /// solve of the cycle gets the deadline `cycle start + SOLVE_DEADLINE_FRACTION · budget`
    /// ([`trust_core::TrajRequest`]; the rest is for the safety pass and the commit that follow
    /// the solves). Default 50 ms: half of the 10 Hz replanning period.
    pub cycle_budget_ms: f64,
    /// Pass the cycle's deadline to the backend. `false` makes a cycle's result independent of
    /// machine load (only evaluation budgets bind): use it for reproducible studies.
    pub enforce_budget: bool,
    /// Latency (s) between the measured state and the moment a new plan takes effect; the plan
    /// starts from the committed trajectory at `now + latency` so consecutive plans join
    /// continuously. `None`: the cycle budget.
    pub latency_s: Option<f64>,
    /// How the cycles take back the route search's slices between cycles ([`crate::routing`]).
    /// `None` (default): each cycle waits for the slice, so a seed is one flight. `Some(x)`: the
    /// flight runs in real time on a computer `x` times slower than this one (the simulator's
    /// real-time mode): a slice's answer takes effect only at the first cycle by which its
    /// measured time × `x` has passed since it was sent away, on the flight's clock (`now`), as
    /// on a vehicle whose planning cycle never blocks on the route's thread.
    pub real_time_scale: Option<f64>,
    /// When the measured state has drifted this far from the committed trajectory, the replan
    /// starts from the measured state instead ([`ReanchorParams`]).
    pub reanchor: ReanchorParams,
    /// Hysteresis factor `h ∈ (0, 1]` of the main-branch switch: a challenger replaces the
    /// incumbent main branch only if its excess cost `J − J*` is below `h` times the incumbent's
    /// (`J* = min(λ_s, λ_t/v_max)·‖p_s − p_g‖`, a lower bound of `J` for any trajectory within the
    /// speed limit), or if the incumbent became infeasible. 1 switches to any better branch.
    /// Default 0.75: the factor of de Groot et al.'s T-MPC / guidance_planner.
    pub hysteresis: f64,
    /// A branch whose trajectory ends within this distance (m) of the goal reaches it, and ranks
    /// before every branch that does not, whatever their `J` ([`crate::Branch::rank_cmp`]).
    /// Default 0.05 m (beyond the paper; absolute, justified): the backend ends a trajectory
    /// whose goal is within reach at the goal at rest, to within the smoothing `ε` of its
    /// terminal norm (a few millimetres), and 0.05 m is a third of the smallest goal tolerance
    /// we fly (0.15 m, the Crazyflie room), so a branch that "reaches" also arrives.
    pub goal_reached_m: f64,
    /// The progress monitor's thresholds ([`crate::progress`]).
    pub progress: ProgressParams,
    /// The safety check every kept branch passes each cycle.
    pub safety: SafetyParams,
    /// Seed of the manager's random number generator (handed to the frontend every cycle). Not
    /// overridable: a trial seeds it ([`ManagerOverrides`] has no `seed`, so a scenario that
    /// sets one gets an unknown-field error instead of a value silently replaced).
    #[overrides(skip)]
    pub seed: u64,
}

impl Default for ManagerParams {
    fn default() -> Self {
        Self::trust()
    }
}

impl ManagerParams {
    /// TRUST-Planner: five branches with history (Algorithm 1), exploring every third cycle
    /// with warm re-solves capped at 100 evaluations for the main branch and 50 for each
    /// sub-branch, cold solves at 400 (our defaults, see the fields). Algorithm 1 exactly as
    /// written: `explore_period_cycles = 1`, `warm_max_evaluations = None`,
    /// `sub_branch_max_evaluations = None`, `cold_max_evaluations = None` (`trust-sim ablate
    /// --variant explore=1` for the exploration period).
    pub fn trust() -> Self {
        ManagerParams {
            max_branches: 5,
            history: true,
            max_explored_paths: 5,
            straight_guide_when_empty: true,
            wall_images: true,
            forecast_growth_s: None,
            warm_max_evaluations: Some(100),
            sub_branch_max_evaluations: Some(50),
            cold_max_evaluations: Some(400),
            cold_solves_per_cycle: Some(2),
            background: true,
            merge_max_evaluations: None,
            worker_march_max_evaluations: Some(200),
            explore_period_cycles: 3,
            repair_margin_m: 0.05,
            ranking: None,
            horizon_s: 4.0,
            brake_hold_s: None,
            cycle_budget_ms: 50.0,
            enforce_budget: true,
            latency_s: None,
            real_time_scale: None,
            reanchor: ReanchorParams::default(),
            hysteresis: 0.75,
            goal_reached_m: 0.05,
            progress: ProgressParams::default(),
            safety: SafetyParams::default(),
            seed: 0,
        }
    }

    /// Baseline 3 of the paper: multi-branch from fresh frontend paths each cycle, no history.
    pub fn multi_branch_without_history() -> Self {
        ManagerParams {
            history: false,
            cold_solves_per_cycle: None,
            cold_max_evaluations: None,
            ..Self::trust()
        }
    }

    /// Baselines 1 and 2 of the paper: one branch from the frontend's first path each cycle.
    pub fn single_branch() -> Self {
        ManagerParams {
            max_branches: 1,
            history: false,
            max_explored_paths: 1,
            cold_solves_per_cycle: None,
            cold_max_evaluations: None,
            ..Self::trust()
        }
    }

    /// The braking fallback's hold in use (s): [`ManagerParams::brake_hold_s`], else the
    /// planning horizon.
    pub fn brake_hold(&self) -> f64 {
        self.brake_hold_s.unwrap_or(self.horizon_s)
    }

    /// How long the forecasts' uncertainty grows (s): [`ManagerParams::forecast_growth_s`],
    /// else [`GROWTH_FRACTION`] of the planning horizon.
    pub fn forecast_growth(&self) -> f64 {
        self.forecast_growth_s
            .unwrap_or(GROWTH_FRACTION * self.horizon_s)
    }

    /// The latency in use (s).
    pub fn latency(&self) -> f64 {
        self.latency_s.unwrap_or(self.cycle_budget_ms * 1e-3)
    }

    /// The ranking weights in use for a vehicle with `limits`.
    pub fn ranking_weights(&self, limits: &Limits) -> RankingWeights {
        self.ranking.unwrap_or(RankingWeights {
            lambda_t: 1.0,
            lambda_s: 1.0 / limits.v_max,
            lambda_e: 1e-4,
        })
    }

    /// Checks every field; errors name `manager.{field}`.
    pub fn validate(&self) -> Result<(), PlanError> {
        if self.max_branches == 0 {
            return Err(PlanError::invalid(
                "manager.max_branches",
                self.max_branches,
                "an integer >= 1",
            ));
        }
        if self.cold_solves_per_cycle == Some(0) {
            return Err(PlanError::invalid(
                "manager.cold_solves_per_cycle",
                0,
                "at least 1 solve per cycle, or none (all in the exploring cycle)",
            ));
        }
        if self.max_explored_paths == 0 {
            return Err(PlanError::invalid(
                "manager.max_explored_paths",
                self.max_explored_paths,
                "an integer >= 1",
            ));
        }
        for (field, v) in [
            ("manager.warm_max_evaluations", self.warm_max_evaluations),
            (
                "manager.sub_branch_max_evaluations",
                self.sub_branch_max_evaluations,
            ),
            ("manager.cold_max_evaluations", self.cold_max_evaluations),
            ("manager.merge_max_evaluations", self.merge_max_evaluations),
            (
                "manager.worker_march_max_evaluations",
                self.worker_march_max_evaluations,
            ),
        ] {
            if v == Some(0) {
                return Err(PlanError::invalid(
                    field,
                    0,
                    "at least 1 evaluation, or none",
                ));
            }
        }
        if self.explore_period_cycles == 0 {
            return Err(PlanError::invalid(
                "manager.explore_period_cycles",
                0,
                "an integer >= 1",
            ));
        }
        check_non_negative("manager.repair_margin_m", self.repair_margin_m)?;
        if let Some(w) = &self.ranking {
            check_non_negative("manager.ranking.lambda_t", w.lambda_t)?;
            check_non_negative("manager.ranking.lambda_s", w.lambda_s)?;
            check_non_negative("manager.ranking.lambda_e", w.lambda_e)?;
        }
        check_positive("manager.horizon_s", self.horizon_s)?;
        if let Some(hold) = self.brake_hold_s {
            check_positive("manager.brake_hold_s", hold)?;
        }
        if let Some(g) = self.forecast_growth_s
            && (g.is_nan() || g <= 0.0)
        {
            return Err(PlanError::invalid(
                "manager.forecast_growth_s",
                g,
                "a number of seconds > 0 (inf: growth for ever)",
            ));
        }
        check_non_negative("manager.goal_reached_m", self.goal_reached_m)?;
        self.progress.validate()?;
        check_positive("manager.cycle_budget_ms", self.cycle_budget_ms)?;
        if let Some(x) = self.real_time_scale {
            check_positive("manager.real_time_scale", x)?;
        }
        if let Some(l) = self.latency_s {
            check_non_negative("manager.latency_s", l)?;
        }
        self.reanchor.validate()?;
        if !(self.hysteresis > 0.0 && self.hysteresis <= 1.0) {
            return Err(PlanError::invalid(
                "manager.hysteresis",
                self.hysteresis,
                "a factor in (0, 1]",
            ));
        }
        self.safety.validate()
    }
}

/// When the replan starts from the measured state instead of the committed trajectory.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Overridable)]
#[serde(deny_unknown_fields, default)]
pub struct ReanchorParams {
    /// Position drift (m) beyond which the manager re-anchors.
    pub position_m: f64,
    /// Velocity drift (m/s) beyond which the manager re-anchors.
    pub velocity_mps: f64,
}

impl Default for ReanchorParams {
    /// Ours: 0.5 m and 1.5 m/s, several times the tracking error of the simulator's SE(3)
    /// controller at the paper's speeds, so that re-anchoring (which gives up continuity of
    /// acceleration between plans) happens only after a disturbance.
    fn default() -> Self {
        ReanchorParams {
            position_m: 0.5,
            velocity_mps: 1.5,
        }
    }
}

impl ReanchorParams {
    /// Checks every field.
    pub fn validate(&self) -> Result<(), PlanError> {
        check_positive("manager.reanchor.position_m", self.position_m)?;
        check_positive("manager.reanchor.velocity_mps", self.velocity_mps)
    }
}

/// The safety check of a trajectory against the static map and the current forecasts
/// ([`crate::check_trajectory`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Overridable)]
#[serde(deny_unknown_fields, default)]
pub struct SafetyParams {
    /// Largest time step (s) between checked instants where the clearance does not prove a larger
    /// one safe: the check always uses the proven step (the clearance divided by a bound on how
    /// fast it can shrink) and never exceeds this. Default 0.05 s.
    pub max_step_s: f64,
    /// Smallest step (s): where the clearance is within `min_step_s` of reaching zero the check
    /// samples at this step (bounded work; at 10 m/s a 1 ms step moves 1 cm).
    pub min_step_s: f64,
    /// Clearance (m) required from the static map (the vehicle's radius: the map holds the
    /// obstacles themselves). Default 0: set it to the vehicle radius.
    pub static_clearance_m: f64,
    /// Clearance (m) required from each forecast obstacle beyond its forecast radius (which holds
    /// `r_safe`, usually the vehicle radius plus a margin). Default 0.
    pub dynamic_clearance_m: f64,
    /// A branch is infeasible if its speed or acceleration exceeds the limits by more than this
    /// fraction. Default 0.1 (the backends' soft penalties overshoot by well under 1 %).
    pub limit_tolerance: f64,
    /// Also check the straight braking manoeuvre ([`crate::braking_tail`], at 0.9·`a_max`) that
    /// follows a trajectory ending in motion: the vehicle must be able to stop safely after the plan ends. Default `true`
    /// (beyond the paper: UTF-MINCO's free terminal velocity otherwise lets a branch end at full
    /// speed in front of an obstacle).
    pub braking_tail: bool,
    /// A trajectory that ends slowly (below a tenth of `v_max`) ends in a resting place: where
    /// the vehicle comes to rest (its end, or where its braking tail stops) it must stay clear
    /// of the forecasts' motion for this long after (s), their growth held after this long;
    /// `0` switches the hold off. Default 0.5 s, an eighth of the default horizon (beyond the
    /// paper): a plan that slowed to rest on an oncoming obstacle's line, just outside its
    /// forecast at the plan's end, passed the check and was run over half a second later
    /// (holdout head-on corridors: 8 collisions in 18 flights, 0 with the hold). A 1 s hold, or
    /// one after every end, blocked the resting places near people's paths (rooms with people:
    /// 21 time-outs in 120 flights, 6 with the default).
    pub rest_hold_s: f64,
}

impl Default for SafetyParams {
    fn default() -> Self {
        SafetyParams {
            max_step_s: 0.05,
            min_step_s: 1e-3,
            static_clearance_m: 0.0,
            dynamic_clearance_m: 0.0,
            limit_tolerance: 0.1,
            braking_tail: true,
            rest_hold_s: 0.5,
        }
    }
}

impl SafetyParams {
    /// Checks every field.
    pub fn validate(&self) -> Result<(), PlanError> {
        check_positive("manager.safety.max_step_s", self.max_step_s)?;
        check_positive("manager.safety.min_step_s", self.min_step_s)?;
        if self.min_step_s > self.max_step_s {
            return Err(PlanError::invalid(
                "manager.safety.min_step_s",
                self.min_step_s,
                format!("at most max_step_s ({})", self.max_step_s),
            ));
        }
        check_non_negative("manager.safety.static_clearance_m", self.static_clearance_m)?;
        check_non_negative(
            "manager.safety.dynamic_clearance_m",
            self.dynamic_clearance_m,
        )?;
        check_non_negative("manager.safety.limit_tolerance", self.limit_tolerance)?;
        check_non_negative("manager.safety.rest_hold_s", self.rest_hold_s)
    }
}

/// Fraction of [`ManagerParams::cycle_budget_ms`] the trajectory solves may use when the budget
/// is enforced (0.7): the safety pass, the repairs, the homotopy checks and the commit run after
/// the solves. With the deadline at the whole budget E4's real-time cycles (seed 11) ended up to
/// 5 ms over it; at 0.8, 6 of 284 cycles of a computer three times slower (`--real-time 3`)
/// were 1–16 % over it.
pub const SOLVE_DEADLINE_FRACTION: f64 = 0.7;

/// The thresholds of the progress monitor ([`crate::progress`]), relative to the vehicle and the
/// horizon.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Overridable)]
#[serde(deny_unknown_fields, default)]
pub struct ProgressParams {
    /// The window as a fraction of the planning horizon `T_h`. Default 0.5 (beyond the paper):
    /// long enough that braking and turning (each well under `T_h/2` at the limits) are not
    /// stalls, short enough to react within one horizon.
    pub window_horizon_fraction: f64,
    /// The least progress rate, as a fraction of `v_max`, that is not a stall. Default 0.05
    /// (beyond the paper): the E4 stall of seed 7301 progressed 0 m/s; a flight that weaves
    /// among obstacles keeps well above 5 % of its top speed.
    pub stall_speed_fraction: f64,
}

impl Default for ProgressParams {
    fn default() -> Self {
        Self {
            window_horizon_fraction: 0.5,
            stall_speed_fraction: 0.05,
        }
    }
}

impl ProgressParams {
    /// Checks every field; errors name `manager.progress.{field}`.
    pub fn validate(&self) -> Result<(), PlanError> {
        check_positive(
            "manager.progress.window_horizon_fraction",
            self.window_horizon_fraction,
        )?;
        check_positive(
            "manager.progress.stall_speed_fraction",
            self.stall_speed_fraction,
        )
    }

    /// The rule for a vehicle with `limits` and horizon `horizon_s` (s).
    pub fn rule(&self, limits: &Limits, horizon_s: f64) -> StallRule {
        let window_s = self.window_horizon_fraction * horizon_s;
        let min_rate_mps = self.stall_speed_fraction * limits.v_max;
        StallRule {
            window_s,
            min_rate_mps,
            min_progress_m: min_rate_mps * window_s,
        }
    }
}

/// The stall rule in absolute units ([`ProgressParams::rule`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StallRule {
    /// The window (s).
    pub window_s: f64,
    /// The least progress rate (m/s) that is not a stall.
    pub min_rate_mps: f64,
    /// `min_rate_mps · window_s` (m): the progress that ends a stall, and the distance to the goal
    /// within which there is no stall.
    pub min_progress_m: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_are_valid_and_differ_where_the_paper_says() {
        for p in [
            ManagerParams::trust(),
            ManagerParams::multi_branch_without_history(),
            ManagerParams::single_branch(),
        ] {
            p.validate().unwrap();
        }
        assert!(ManagerParams::trust().history);
        assert!(!ManagerParams::multi_branch_without_history().history);
        assert_eq!(ManagerParams::single_branch().max_branches, 1);
        // Only a planner with history refines its new branches: only it caps their cold solves.
        assert_eq!(ManagerParams::trust().cold_max_evaluations, Some(400));
        assert_eq!(
            ManagerParams::multi_branch_without_history().cold_max_evaluations,
            None
        );
        assert_eq!(ManagerParams::single_branch().cold_max_evaluations, None);
    }

    #[test]
    fn validation_names_the_field() {
        let mut p = ManagerParams {
            hysteresis: 1.5,
            ..ManagerParams::default()
        };
        let e = p.validate().unwrap_err().to_string();
        assert!(e.contains("manager.hysteresis"), "{e}");
        p.hysteresis = 0.75;
        p.safety.min_step_s = 1.0;
        let e = p.validate().unwrap_err().to_string();
        assert!(e.contains("manager.safety.min_step_s"), "{e}");
        p.safety = SafetyParams::default();
        p.max_branches = 0;
        let e = p.validate().unwrap_err().to_string();
        assert!(e.contains("manager.max_branches"), "{e}");
        p.max_branches = 5;
        p.latency_s = Some(f64::NAN);
        let e = p.validate().unwrap_err().to_string();
        assert!(e.contains("manager.latency_s"), "{e}");
        p.latency_s = None;
        p.repair_margin_m = -0.1;
        let e = p.validate().unwrap_err().to_string();
        assert!(e.contains("manager.repair_margin_m"), "{e}");
        p.repair_margin_m = 0.05;
        p.sub_branch_max_evaluations = Some(0);
        let e = p.validate().unwrap_err().to_string();
        assert!(e.contains("manager.sub_branch_max_evaluations"), "{e}");
    }

    #[test]
    fn ranking_follows_the_papers_rule() {
        let limits = Limits::new(8.0, 10.0).unwrap();
        let w = ManagerParams::default().ranking_weights(&limits);
        assert_eq!(w.lambda_s, 1.0 / 8.0);
        assert_eq!(w.lambda_t, 1.0);
        assert_eq!(w.lambda_e, 1e-4);
    }

    #[test]
    fn deserializes_strictly_with_defaults() {
        let p: ManagerParams = toml::from_str("max_branches = 3\nhistory = false\n").unwrap();
        assert_eq!(p.max_branches, 3);
        assert_eq!(p.horizon_s, 4.0);
        assert!(toml::from_str::<ManagerParams>("branches = 3\n").is_err());
    }

    #[test]
    fn the_brake_hold_defaults_to_the_horizon_and_is_validated() {
        let mut p = ManagerParams::default();
        assert_eq!(p.brake_hold(), p.horizon_s);
        p.brake_hold_s = Some(1.5);
        assert_eq!(p.brake_hold(), 1.5);
        p.validate().unwrap();
        p.brake_hold_s = Some(0.0);
        let e = p.validate().unwrap_err().to_string();
        assert!(e.contains("manager.brake_hold_s"), "{e}");
    }
    #[test]
    fn overrides_are_derived_field_by_field_and_keep_the_rest() {
        let o: ManagerOverrides = toml::from_str(
            "horizon_s = 3.0\nwarm_max_evaluations = 20\nforecast_growth_s = inf\n\
             [safety]\nrest_hold_s = 1.5\n[progress]\nwindow_horizon_fraction = 0.25\n",
        )
        .unwrap();
        let mut p = ManagerParams::single_branch();
        p.apply(&o);
        assert_eq!(p.horizon_s, 3.0);
        assert_eq!(p.warm_max_evaluations, Some(20));
        assert_eq!(p.forecast_growth_s, Some(f64::INFINITY));
        assert_eq!(p.safety.rest_hold_s, 1.5);
        assert_eq!(p.safety.max_step_s, SafetyParams::default().max_step_s);
        assert_eq!(p.progress.window_horizon_fraction, 0.25);
        assert_eq!(p.max_branches, 1, "the preset's other fields stay");
        assert!(ManagerOverrides::default().is_empty() && !o.is_empty());
        // Unknown keys, and the seed a trial sets, are errors naming the key.
        let e = toml::from_str::<ManagerOverrides>("seed = 3\n").unwrap_err();
        assert!(e.to_string().contains("unknown field `seed`"), "{e}");
        let e = toml::from_str::<ManagerOverrides>("[safety]\nmax_step = 0.1\n").unwrap_err();
        assert!(e.to_string().contains("unknown field `max_step`"), "{e}");
        // Written back, only the given fields appear.
        let text = toml::to_string(&o).unwrap();
        assert!(
            text.contains("horizon_s = 3.0") && !text.contains("max_branches"),
            "{text}"
        );
    }
}
