//! Planners assembled by name: the paper's TRUST-Planner and baselines 1–3 (Sec. IV-D), or any
//! combination of frontend, backend, homotopy checker and manager mode.
//!
//! Style rule 4: the concrete types are chosen once, here, from closed serde enums
//! ([`FrontendSpec`], [`BackendSpec`], [`CheckerSpec`]); everything below is generic
//! (`trust_manager::Manager<F, B, H>`). [`AnyFrontend`], [`AnyBackend`] and [`AnyChecker`] are
//! closed enums that implement the `trust-core` traits by delegation, so a planner of any
//! combination is one type, [`AnyManager`].
//!
//! | preset (`planner.name`) | frontend | backend | checker | manager |
//! |---|---|---|---|---|
//! | `trust` | DEV-PRM | UTF-MINCO | TVD | [`ManagerParams::trust`] |
//! | `baseline1` | straight line | UTF-MINCO | TVD | [`ManagerParams::single_branch`] |
//! | `baseline2` | sparse A* | UTF-MINCO | TVD | [`ManagerParams::single_branch`] |
//! | `baseline3` | DEV-PRM | UTF-MINCO | TVD | [`ManagerParams::multi_branch_without_history`] |
//!
//! Every preset's UTF-MINCO uses [`closed_loop_backend`]: the library defaults with the time and
//! terminal weights raised from GCOPTER's 20 / our 50 to 60 / 60, the jerk energy's weight
//! lowered from 1 to [`PRESET_ENERGY_WEIGHT`] and a jerk limit ([`PRESET_JERK_RAMP_S`]).
//!
//! Overrides in the scenario's `[planner]` section replace parts of the preset:
//! `frontend = { kind = "v-prm", budget_ms = 20 }` replaces the frontend (the fields are that
//! kind's `…Params`, unspecified ones at their defaults), likewise `backend` and `checker`;
//! `[planner.manager]` fields replace single fields of the preset's `ManagerParams`
//! ([`ManagerOverrides::apply`]), so
//! `name = "baseline1"` with `manager.horizon_s = 3` stays single-branch.
//!
//! # Clearances (set by [`effective`], from the vehicle radius `r`)
//!
//! Forecasts already hold the vehicle radius in their `r_safe` ([`crate::sensing`]), so the
//! moving-obstacle clearances of the parts stay as given. The static map holds the obstacles
//! themselves, so:
//!
//! * the manager's `safety.static_clearance_m ≥ r + e + m`, where `e` is how much the planner's
//!   map may overestimate a distance (0 for analytic shapes; see
//!   [`crate::World::static_map_error_m`]) and `m` the tracking margin
//!   ([`PlannerSpec::tracking_margin_m`]) — a branch the safety check passes keeps the true
//!   vehicle's body off the true static obstacles although it strays from its plan by up to
//!   `m`; likewise `safety.dynamic_clearance_m ≥ m` beyond every forecast. The braking
//!   fallback is checked with the same parameters;
//! * the backend's `penalty.static_clearance_m ≥ r + max(clearance_margin_m, m) + e` and
//!   `penalty.dynamic_clearance_m ≥ m`: the optimizer aims for at least what the safety check
//!   requires (its penalty is soft and sampled);
//! * DEV-PRM's and V-PRM's `clearance ≥ r + m` (samples closer than that to an obstacle are
//!   useless guides; DEV-PRM's `surface_offset` is raised with it, as it must be `≥
//!   clearance`), sparse A*'s `clearance ≥ r + m`.
//!
//! Each is a lower bound: a larger value in the scenario is kept.
//!
//! # Reproducible studies
//!
//! With `planner.reproducible = true` (the default) wall-clock budgets are switched off: the
//! manager does not pass its cycle deadline to the backend (`enforce_budget = false`), DEV-PRM and
//! V-PRM keep their `budget_ms` only as a deterministic work budget (`wall_clock_budget = false`:
//! `budget_ms · work_per_ms` units of estimated query time on the development machine, see
//! `trust_topo_prm::DevPrmParams::work_per_ms`), and sparse A* gets a budget of
//! [`REPRODUCIBLE_BUDGET_MS`] so that only its expansion cap ends a search. A run then depends
//! only on the seeds, not on how loaded the machine is; wall-clock budgets make runs
//! machine-dependent (a slower machine draws fewer samples). CPU times are still measured and
//! reported. Set `reproducible = false` to study the real-time behaviour under the budgets (the
//! work budgets then stay, backed by the clock).

use serde::{Deserialize, Serialize};
use trust_core::RankingWeights;
use trust_core::{
    Curve, HomotopyChecker, Limits, PathFrontend, PathQuery, PlanError, Rng, Scene, SearchResult,
    Solution, TrajRequest, TrajectoryBackend,
};
use trust_manager::{Manager, ManagerParams, ProgressParams, ReanchorParams, Router, SafetyParams};
use trust_minco::{Minco, MincoParams, UtfMinco, UtfMincoParams};
use trust_route::{RouteError, RouteParams};
use trust_topo_prm::{
    DevPrm, DevPrmParams, SparseAStar, SparseAStarParams, StraightLine, Tvd, TvdParams, Uvd,
    UvdParams, Vprm, VprmParams,
};

use crate::error::WorldError;
use crate::problem::Problem;
use crate::problem::Problems;

/// Search budget (ms) given to sparse A* in reproducible mode: one minute, far beyond what its
/// expansion cap needs, so that the cap ends every search.
pub const REPRODUCIBLE_BUDGET_MS: f64 = 60_000.0;

/// DEV-PRM's budget in the presets (ms): [`DevPrmParams::default`] with `budget_ms` raised from
/// Fast-Planner's 5 ms, so that a search does `PRESET_DEV_PRM_BUDGET_MS · work_per_ms` work units
/// (about that many ms on the development machine) and leaves the rest of the manager's 50 ms
/// cycle to the cold solves.
pub const PRESET_DEV_PRM_BUDGET_MS: f64 = 15.0;

/// DEV-PRM as the presets fly it: [`DevPrmParams::default`] with [`PRESET_DEV_PRM_BUDGET_MS`].
pub fn preset_dev_prm() -> DevPrmParams {
    DevPrmParams {
        budget_ms: PRESET_DEV_PRM_BUDGET_MS,
        ..DevPrmParams::default()
    }
}

/// A frontend of any supported kind, implementing [`PathFrontend`] by delegation.
#[derive(Debug, Clone)]
pub enum AnyFrontend {
    /// DEV-PRM (`"dev-prm"`).
    DevPrm(DevPrm),
    /// V-PRM (`"v-prm"`).
    Vprm(Vprm),
    /// The straight line of baseline 1 (`"straight-line"`).
    StraightLine(StraightLine),
    /// Sparse A* of baseline 2 (`"sparse-a-star"`).
    SparseAStar(SparseAStar),
}

impl PathFrontend for AnyFrontend {
    fn name(&self) -> &str {
        match self {
            AnyFrontend::DevPrm(f) => f.name(),
            AnyFrontend::Vprm(f) => f.name(),
            AnyFrontend::StraightLine(f) => f.name(),
            AnyFrontend::SparseAStar(f) => f.name(),
        }
    }

    fn search(
        &self,
        query: &PathQuery,
        scene: &Scene<'_>,
        rng: &mut Rng,
    ) -> Result<SearchResult, PlanError> {
        match self {
            AnyFrontend::DevPrm(f) => f.search(query, scene, rng),
            AnyFrontend::Vprm(f) => f.search(query, scene, rng),
            AnyFrontend::StraightLine(f) => f.search(query, scene, rng),
            AnyFrontend::SparseAStar(f) => f.search(query, scene, rng),
        }
    }
}

/// A backend of any supported kind, implementing [`TrajectoryBackend`] by delegation.
#[derive(Debug, Clone)]
pub enum AnyBackend {
    /// UTF-MINCO (`"utf-minco"`).
    UtfMinco(UtfMinco),
    /// The original fixed-terminal MINCO (`"minco"`).
    Minco(Minco),
}

impl TrajectoryBackend for AnyBackend {
    fn name(&self) -> &str {
        match self {
            AnyBackend::UtfMinco(b) => b.name(),
            AnyBackend::Minco(b) => b.name(),
        }
    }

    fn optimize(&self, req: &TrajRequest<'_>, scene: &Scene<'_>) -> Result<Solution, PlanError> {
        match self {
            AnyBackend::UtfMinco(b) => b.optimize(req, scene),
            AnyBackend::Minco(b) => b.optimize(req, scene),
        }
    }
}

/// A homotopy checker of any supported kind, implementing [`HomotopyChecker`] by delegation.
#[derive(Debug, Clone)]
pub enum AnyChecker {
    /// Temporal visibility deformation (`"tvd"`).
    Tvd(Tvd),
    /// Uniform visibility deformation (`"uvd"`).
    Uvd(Uvd),
}

impl HomotopyChecker for AnyChecker {
    fn name(&self) -> &str {
        match self {
            AnyChecker::Tvd(c) => c.name(),
            AnyChecker::Uvd(c) => c.name(),
        }
    }

    fn equivalent(
        &self,
        a: &dyn Curve,
        b: &dyn Curve,
        scene: &Scene<'_>,
    ) -> Result<bool, PlanError> {
        match self {
            AnyChecker::Tvd(c) => c.equivalent(a, b, scene),
            AnyChecker::Uvd(c) => c.equivalent(a, b, scene),
        }
    }
}

/// The manager of any planner this module assembles.
pub type AnyManager = Manager<AnyFrontend, AnyBackend, AnyChecker>;

/// Parameters of the straight-line frontend: none (the empty table rejects unknown fields).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StraightLineParams {}

/// Which frontend, with its parameters (scenario key `planner.frontend`, tagged by `kind`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum FrontendSpec {
    /// `{ kind = "dev-prm", ...DevPrmParams }`.
    DevPrm(DevPrmParams),
    /// `{ kind = "v-prm", ...VprmParams }`.
    VPrm(VprmParams),
    /// `{ kind = "straight-line" }`.
    StraightLine(StraightLineParams),
    /// `{ kind = "sparse-a-star", ...SparseAStarParams }` (alias `"sparse-astar"`, the
    /// frontend's report name).
    #[serde(rename = "sparse-a-star", alias = "sparse-astar")]
    SparseAStar(SparseAStarParams),
}

impl FrontendSpec {
    /// The scenario name of this kind.
    pub fn kind_name(&self) -> &'static str {
        match self {
            FrontendSpec::DevPrm(_) => "dev-prm",
            FrontendSpec::VPrm(_) => "v-prm",
            FrontendSpec::StraightLine(_) => "straight-line",
            FrontendSpec::SparseAStar(_) => "sparse-a-star",
        }
    }

    fn check(&self, p: &mut Problems) {
        let r = match self {
            FrontendSpec::DevPrm(x) => x.validate().map_err(|e| (e, "devprm")),
            FrontendSpec::VPrm(x) => x.validate().map_err(|e| (e, "vprm")),
            FrontendSpec::StraightLine(_) => Ok(()),
            FrontendSpec::SparseAStar(x) => x.validate().map_err(|e| (e, "sparse_astar")),
        };
        if let Err((e, prefix)) = r {
            p.list.push(plan_problem(e, prefix, "planner.frontend"));
        }
    }

    /// The frontend alone (experiment E1 runs it without a manager). [`build`] applies the
    /// vehicle-dependent adjustments first; this does not.
    ///
    /// # Errors
    /// [`PlanError::InvalidInput`] naming the invalid parameter.
    pub fn build(&self) -> Result<AnyFrontend, PlanError> {
        Ok(match self {
            FrontendSpec::DevPrm(x) => AnyFrontend::DevPrm(DevPrm::new(x.clone())?),
            FrontendSpec::VPrm(x) => AnyFrontend::Vprm(Vprm::new(x.clone())?),
            FrontendSpec::StraightLine(_) => AnyFrontend::StraightLine(StraightLine),
            FrontendSpec::SparseAStar(x) => AnyFrontend::SparseAStar(SparseAStar::new(x.clone())?),
        })
    }
}

/// Which backend, with its parameters (scenario key `planner.backend`, tagged by `kind`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum BackendSpec {
    /// `{ kind = "utf-minco", weights = {..}, penalty = {..}, pieces = {..}, solver = {..} }`.
    UtfMinco(UtfMincoParams),
    /// `{ kind = "minco", ... }` with the same fields.
    Minco(MincoParams),
}

impl BackendSpec {
    /// The scenario name of this kind.
    pub fn kind_name(&self) -> &'static str {
        match self {
            BackendSpec::UtfMinco(_) => "utf-minco",
            BackendSpec::Minco(_) => "minco",
        }
    }

    fn check(&self, p: &mut Problems) {
        let r = match self {
            BackendSpec::UtfMinco(x) => x.validate("planner.backend"),
            BackendSpec::Minco(x) => x.validate("planner.backend"),
        };
        if let Err(e) = r {
            p.list.push(plan_problem(e, "", "planner.backend"));
        }
    }

    /// The backend alone (experiment E2 runs it without a manager). [`build`] applies the
    /// vehicle-dependent adjustments first; this does not.
    ///
    /// # Errors
    /// [`PlanError::InvalidInput`] naming the invalid parameter.
    pub fn build(&self) -> Result<AnyBackend, PlanError> {
        Ok(match self {
            BackendSpec::UtfMinco(x) => AnyBackend::UtfMinco(UtfMinco::new(x.clone())?),
            BackendSpec::Minco(x) => AnyBackend::Minco(Minco::new(x.clone())?),
        })
    }

    fn weights_mut(&mut self) -> &mut trust_minco::CostWeights {
        match self {
            BackendSpec::UtfMinco(x) => &mut x.weights,
            BackendSpec::Minco(x) => &mut x.weights,
        }
    }

    fn pieces_mut(&mut self) -> &mut trust_minco::PieceParams {
        match self {
            BackendSpec::UtfMinco(x) => &mut x.pieces,
            BackendSpec::Minco(x) => &mut x.pieces,
        }
    }

    fn penalty_mut(&mut self) -> &mut trust_minco::PenaltyParams {
        match self {
            BackendSpec::UtfMinco(x) => &mut x.penalty,
            BackendSpec::Minco(x) => &mut x.penalty,
        }
    }
}

/// Which homotopy checker, with its parameters (scenario key `planner.checker`, tagged by
/// `kind`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum CheckerSpec {
    /// `{ kind = "tvd", dt_s = 0.05, clearance = 0 }`.
    Tvd(TvdParams),
    /// `{ kind = "uvd", ...UvdParams }`.
    Uvd(UvdParams),
}

impl CheckerSpec {
    /// The scenario name of this kind.
    pub fn kind_name(&self) -> &'static str {
        match self {
            CheckerSpec::Tvd(_) => "tvd",
            CheckerSpec::Uvd(_) => "uvd",
        }
    }

    fn check(&self, p: &mut Problems) {
        let r = match self {
            CheckerSpec::Tvd(x) => x.validate().map_err(|e| (e, "tvd")),
            CheckerSpec::Uvd(x) => x.validate().map_err(|e| (e, "uvd")),
        };
        if let Err((e, prefix)) = r {
            p.list.push(plan_problem(e, prefix, "planner.checker"));
        }
    }

    /// The checker alone.
    ///
    /// # Errors
    /// [`PlanError::InvalidInput`] naming the invalid parameter.
    pub fn build(&self) -> Result<AnyChecker, PlanError> {
        Ok(match self {
            CheckerSpec::Tvd(x) => AnyChecker::Tvd(Tvd::new(x.clone())?),
            CheckerSpec::Uvd(x) => AnyChecker::Uvd(Uvd::new(x.clone())?),
        })
    }
}

/// A [`PlanError`] as a [`Problem`] whose field path starts with `to` instead of the component's
/// own prefix `from` (`devprm.budget_ms` → `planner.frontend.budget_ms`).
fn plan_problem(e: PlanError, from: &str, to: &str) -> Problem {
    match e {
        PlanError::InvalidInput {
            field,
            value,
            expected,
        } => {
            let rest = if from.is_empty() {
                field.clone()
            } else {
                field
                    .strip_prefix(from)
                    .map(|r| format!("{to}{r}"))
                    .unwrap_or_else(|| format!("{to}.{field}"))
            };
            Problem {
                field: rest,
                // The planning crates write the value with `{:?}` (17 digits).
                value: crate::problem::readable_value(&value),
                expected,
            }
        }
        other => Problem::new(to, other, "valid parameters"),
    }
}

/// The paper's planners by name (scenario key `planner.name`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PlannerPreset {
    /// TRUST-Planner: DEV-PRM + UTF-MINCO + TVD, multi-branch with history.
    #[default]
    Trust,
    /// Baseline 1: straight line + UTF-MINCO + TVD, single branch.
    Baseline1,
    /// Baseline 2: sparse A* + UTF-MINCO + TVD, single branch.
    Baseline2,
    /// Baseline 3: DEV-PRM + UTF-MINCO + TVD, multi-branch without history.
    Baseline3,
}

impl PlannerPreset {
    /// The scenario name (`"trust"`, `"baseline1"`, …).
    pub fn name(&self) -> &'static str {
        match self {
            PlannerPreset::Trust => "trust",
            PlannerPreset::Baseline1 => "baseline1",
            PlannerPreset::Baseline2 => "baseline2",
            PlannerPreset::Baseline3 => "baseline3",
        }
    }

    /// All presets, in the paper's order.
    pub const ALL: [PlannerPreset; 4] = [
        PlannerPreset::Trust,
        PlannerPreset::Baseline1,
        PlannerPreset::Baseline2,
        PlannerPreset::Baseline3,
    ];

    /// The preset's parts (module table).
    pub fn parts(&self) -> (FrontendSpec, BackendSpec, CheckerSpec, ManagerParams) {
        let backend = BackendSpec::UtfMinco(closed_loop_backend());
        let checker = CheckerSpec::Tvd(TvdParams::default());
        match self {
            PlannerPreset::Trust => (
                FrontendSpec::DevPrm(preset_dev_prm()),
                backend,
                checker,
                ManagerParams::trust(),
            ),
            PlannerPreset::Baseline1 => (
                FrontendSpec::StraightLine(StraightLineParams {}),
                backend,
                checker,
                ManagerParams::single_branch(),
            ),
            PlannerPreset::Baseline2 => (
                FrontendSpec::SparseAStar(SparseAStarParams::default()),
                backend,
                checker,
                ManagerParams::single_branch(),
            ),
            PlannerPreset::Baseline3 => (
                FrontendSpec::DevPrm(preset_dev_prm()),
                backend,
                checker,
                ManagerParams::multi_branch_without_history(),
            ),
        }
    }
}

/// Scenario section `[planner.manager]`: fields that replace the preset's [`ManagerParams`] one
/// by one (meanings and defaults: `trust_manager::ManagerParams`); `[planner.manager.safety]` and
/// `[planner.manager.reanchor]` replace single fields of those sub-structs. Unknown fields are
/// errors naming the field. `seed` is not an override: the planner's random stream is seeded from
/// the trial ([`crate::seeds::Seeds::planner`], set by [`effective`]), so `seed` here is an
/// unknown-field error instead of a value that would be silently replaced.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ManagerOverrides {
    /// Replaces `ManagerParams::max_branches`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_branches: Option<usize>,
    /// Replaces `ManagerParams::history`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub history: Option<bool>,
    /// Replaces `ManagerParams::max_explored_paths`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_explored_paths: Option<usize>,
    /// Replaces `ManagerParams::straight_guide_when_empty`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub straight_guide_when_empty: Option<bool>,
    /// Replaces `ManagerParams::warm_max_evaluations`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub warm_max_evaluations: Option<usize>,
    /// Replaces `ManagerParams::sub_branch_max_evaluations`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sub_branch_max_evaluations: Option<usize>,
    /// Replaces `ManagerParams::cold_max_evaluations`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cold_max_evaluations: Option<usize>,
    /// Replaces `ManagerParams::cold_solves_per_cycle`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cold_solves_per_cycle: Option<usize>,
    /// Replaces `ManagerParams::background`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub background: Option<bool>,
    /// Replaces `ManagerParams::merge_max_evaluations`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub merge_max_evaluations: Option<usize>,
    /// Replaces `ManagerParams::explore_period_cycles`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub explore_period_cycles: Option<usize>,
    /// Replaces `ManagerParams::repair_margin_m`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub repair_margin_m: Option<f64>,
    /// Replaces `ManagerParams::ranking`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ranking: Option<RankingWeights>,
    /// Replaces `ManagerParams::horizon_s`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub horizon_s: Option<f64>,
    /// Replaces `ManagerParams::brake_hold_s`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub brake_hold_s: Option<f64>,
    /// Replaces `ManagerParams::cycle_budget_ms`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cycle_budget_ms: Option<f64>,
    /// Replaces `ManagerParams::enforce_budget`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub enforce_budget: Option<bool>,
    /// Replaces `ManagerParams::latency_s`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub latency_s: Option<f64>,
    /// Replaces `ManagerParams::reanchor`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reanchor: Option<ReanchorOverrides>,
    /// Replaces `ManagerParams::hysteresis`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hysteresis: Option<f64>,
    /// Replaces `ManagerParams::safety`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub safety: Option<SafetyOverrides>,
    /// Replaces `ManagerParams::goal_reached_m`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub goal_reached_m: Option<f64>,
    /// Replaces `ManagerParams::progress` (fields not given take their defaults).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub progress: Option<ProgressParams>,
    /// Replaces `ManagerParams::wall_images`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub wall_images: Option<bool>,
    /// Replaces `ManagerParams::forecast_growth_s` (`inf`: the paper's growth for ever).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub forecast_growth_s: Option<f64>,
}

impl ManagerOverrides {
    /// No field is given.
    pub fn is_empty(&self) -> bool {
        *self == ManagerOverrides::default()
    }

    /// Writes the given fields onto `p`; the others keep their value.
    pub fn apply(&self, p: &mut ManagerParams) {
        if let Some(v) = self.max_branches {
            p.max_branches = v;
        }
        if let Some(v) = self.history {
            p.history = v;
        }
        if let Some(v) = self.max_explored_paths {
            p.max_explored_paths = v;
        }
        if let Some(v) = self.straight_guide_when_empty {
            p.straight_guide_when_empty = v;
        }
        if let Some(v) = self.warm_max_evaluations {
            p.warm_max_evaluations = Some(v);
        }
        if let Some(v) = self.sub_branch_max_evaluations {
            p.sub_branch_max_evaluations = Some(v);
        }
        if let Some(v) = self.cold_max_evaluations {
            p.cold_max_evaluations = Some(v);
        }
        if let Some(v) = self.cold_solves_per_cycle {
            p.cold_solves_per_cycle = Some(v);
        }
        if let Some(v) = self.background {
            p.background = v;
        }
        if let Some(v) = self.merge_max_evaluations {
            p.merge_max_evaluations = Some(v);
        }
        if let Some(v) = self.explore_period_cycles {
            p.explore_period_cycles = v;
        }
        if let Some(v) = self.repair_margin_m {
            p.repair_margin_m = v;
        }
        if let Some(v) = self.ranking {
            p.ranking = Some(v);
        }
        if let Some(v) = self.horizon_s {
            p.horizon_s = v;
        }
        if let Some(v) = self.brake_hold_s {
            p.brake_hold_s = Some(v);
        }
        if let Some(v) = self.goal_reached_m {
            p.goal_reached_m = v;
        }
        if let Some(v) = self.progress {
            p.progress = v;
        }
        if let Some(v) = self.wall_images {
            p.wall_images = v;
        }
        if let Some(v) = self.forecast_growth_s {
            p.forecast_growth_s = Some(v);
        }
        if let Some(v) = self.cycle_budget_ms {
            p.cycle_budget_ms = v;
        }
        if let Some(v) = self.enforce_budget {
            p.enforce_budget = v;
        }
        if let Some(v) = self.latency_s {
            p.latency_s = Some(v);
        }
        if let Some(o) = &self.reanchor {
            o.apply(&mut p.reanchor);
        }
        if let Some(v) = self.hysteresis {
            p.hysteresis = v;
        }
        if let Some(o) = &self.safety {
            o.apply(&mut p.safety);
        }
    }
}

/// `[planner.manager.reanchor]`: fields replacing the preset's `trust_manager::ReanchorParams`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReanchorOverrides {
    /// Replaces `ReanchorParams::position_m`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub position_m: Option<f64>,
    /// Replaces `ReanchorParams::velocity_mps`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub velocity_mps: Option<f64>,
}

impl ReanchorOverrides {
    /// Writes the given fields onto `p`; the others keep their value.
    pub fn apply(&self, p: &mut ReanchorParams) {
        if let Some(v) = self.position_m {
            p.position_m = v;
        }
        if let Some(v) = self.velocity_mps {
            p.velocity_mps = v;
        }
    }
}

/// `[planner.manager.safety]`: fields replacing the preset's `trust_manager::SafetyParams`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SafetyOverrides {
    /// Replaces `SafetyParams::max_step_s`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_step_s: Option<f64>,
    /// Replaces `SafetyParams::min_step_s`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub min_step_s: Option<f64>,
    /// Replaces `SafetyParams::static_clearance_m`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub static_clearance_m: Option<f64>,
    /// Replaces `SafetyParams::dynamic_clearance_m`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dynamic_clearance_m: Option<f64>,
    /// Replaces `SafetyParams::limit_tolerance`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub limit_tolerance: Option<f64>,
    /// Replaces `SafetyParams::braking_tail`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub braking_tail: Option<bool>,
    /// Replaces `SafetyParams::rest_hold_s`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rest_hold_s: Option<f64>,
}

impl SafetyOverrides {
    /// Writes the given fields onto `p`; the others keep their value.
    pub fn apply(&self, p: &mut SafetyParams) {
        if let Some(v) = self.max_step_s {
            p.max_step_s = v;
        }
        if let Some(v) = self.min_step_s {
            p.min_step_s = v;
        }
        if let Some(v) = self.static_clearance_m {
            p.static_clearance_m = v;
        }
        if let Some(v) = self.dynamic_clearance_m {
            p.dynamic_clearance_m = v;
        }
        if let Some(v) = self.limit_tolerance {
            p.limit_tolerance = v;
        }
        if let Some(v) = self.braking_tail {
            p.braking_tail = v;
        }
        if let Some(v) = self.rest_hold_s {
            p.rest_hold_s = v;
        }
    }
}

/// Scenario section `[planner]`: a preset by name plus optional overrides (module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PlannerSpec {
    /// The preset. Default `trust`.
    pub name: PlannerPreset,
    /// Switch wall-clock budgets off for machine-independent runs (module docs). Default `true`.
    pub reproducible: bool,
    /// Margin (m) of the backend's static clearance beyond the vehicle radius (module docs).
    /// Default 0.1 m: the backends' own default static clearance.
    pub clearance_margin_m: f64,
    /// Tracking margin `m` (m): how far the true vehicle may stray from its plan. The manager's
    /// safety check (and with it the braking fallback) keeps `r + e + m` from the static map and
    /// `m` beyond every forecast; the backend's penalties and the frontends' clearances are
    /// raised to at least that (module docs). Default `None`: [`tracking_margin_for`] the
    /// vehicle's `a_max`.
    pub tracking_margin_m: Option<f64>,
    /// Acceleration headroom `h`: the planner plans and checks with `a_max·(1 − h)`, leaving the
    /// rest of the vehicle's `a_max` to its controller (module docs). Default `None`:
    /// [`DEFAULT_ACCEL_HEADROOM`].
    pub accel_headroom: Option<f64>,
    /// Replaces the preset's frontend.
    pub frontend: Option<FrontendSpec>,
    /// Replaces the preset's backend.
    pub backend: Option<BackendSpec>,
    /// Replaces the preset's homotopy checker.
    pub checker: Option<CheckerSpec>,
    /// Replaces single fields of the preset's manager parameters.
    pub manager: Option<ManagerOverrides>,
    /// The global route (`[planner.route]`, beyond the paper; [`RouteSpec`]). On by default.
    pub route: RouteSpec,
}

/// Scenario section `[planner.route]`: whether the manager plans and follows a global route on
/// the known static map (`trust_manager::routing`), and the route planner's parameters
/// (`[planner.route.params]`, `trust_route::RouteParams`; every length there is relative to the
/// vehicle radius). The paper has no route: every query aims at the final goal, which is what
/// `enabled = false` flies — and what the E4 study flies unless given `--variant route`, so
/// that the paper's comparison stays the paper's.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RouteSpec {
    /// Plan and follow a global route. Default `true`.
    pub enabled: bool,
    /// The route planner's parameters. Default `RouteParams::default()`.
    pub params: RouteParams,
}

impl Default for RouteSpec {
    fn default() -> Self {
        RouteSpec {
            enabled: true,
            params: RouteParams::default(),
        }
    }
}

impl Default for PlannerSpec {
    fn default() -> Self {
        PlannerSpec {
            name: PlannerPreset::Trust,
            reproducible: true,
            clearance_margin_m: 0.1,
            tracking_margin_m: None,
            accel_headroom: None,
            frontend: None,
            backend: None,
            checker: None,
            manager: None,
            route: RouteSpec::default(),
        }
    }
}

/// A planner with every part chosen, before the vehicle-dependent adjustments of [`effective`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ResolvedPlanner {
    /// For reports and the run log: the preset name, followed by the overridden parts in
    /// brackets (`trust`, `trust[frontend=v-prm]`, `baseline1[manager]`).
    pub label: String,
    /// The frontend.
    pub frontend: FrontendSpec,
    /// The backend.
    pub backend: BackendSpec,
    /// The homotopy checker.
    pub checker: CheckerSpec,
    /// The manager's parameters.
    pub manager: ManagerParams,
    /// See [`PlannerSpec::reproducible`].
    pub reproducible: bool,
    /// See [`PlannerSpec::clearance_margin_m`].
    pub clearance_margin_m: f64,
    /// See [`PlannerSpec::tracking_margin_m`].
    pub tracking_margin_m: Option<f64>,
    /// See [`PlannerSpec::accel_headroom`].
    pub accel_headroom: Option<f64>,
    /// The backend is the preset's (not replaced by the scenario): [`effective`] sets its piece
    /// length to [`PRESET_PIECE_DURATION_S`]` · v_max`.
    #[serde(default)]
    pub preset_backend: bool,
    /// The route planner's parameters when the route is on ([`PlannerSpec::route`]); `None`
    /// flies the paper's setting (every query aims at the final goal).
    pub route: Option<RouteParams>,
}

impl PlannerSpec {
    /// The preset with the overrides applied (typed: [`ManagerOverrides::apply`]).
    pub fn resolve(&self) -> ResolvedPlanner {
        let (mut frontend, mut backend, mut checker, mut manager) = self.name.parts();
        let mut overridden = Vec::new();
        if let Some(f) = &self.frontend {
            frontend = f.clone();
            overridden.push(format!("frontend={}", f.kind_name()));
        }
        if let Some(b) = &self.backend {
            backend = b.clone();
            overridden.push(format!("backend={}", b.kind_name()));
        }
        if let Some(c) = &self.checker {
            checker = c.clone();
            overridden.push(format!("checker={}", c.kind_name()));
        }
        if let Some(m) = &self.manager
            && !m.is_empty()
        {
            m.apply(&mut manager);
            overridden.push("manager".to_string());
        }
        let label = if overridden.is_empty() {
            self.name.name().to_string()
        } else {
            format!("{}[{}]", self.name.name(), overridden.join(","))
        };
        ResolvedPlanner {
            label,
            frontend,
            backend,
            checker,
            manager,
            reproducible: self.reproducible,
            clearance_margin_m: self.clearance_margin_m,
            tracking_margin_m: self.tracking_margin_m,
            accel_headroom: self.accel_headroom,
            preset_backend: self.backend.is_none(),
            route: self.route.enabled.then(|| self.route.params.clone()),
        }
    }

    /// Every problem with this section: names are checked by serde when the file is read; this
    /// checks the margin, the merged manager parameters and each part's own `validate()`, with
    /// field paths under `planner.`.
    pub fn problems(&self) -> Vec<Problem> {
        let mut p = Problems::default();
        p.non_negative("planner.clearance_margin_m", self.clearance_margin_m);
        if let Some(m) = self.tracking_margin_m {
            p.non_negative("planner.tracking_margin_m", m);
        }
        if let Some(h) = self.accel_headroom
            && !(0.0..=0.5).contains(&h)
        {
            p.list.push(Problem {
                field: "planner.accel_headroom".into(),
                value: crate::problem::fmt_num(h),
                expected: "a fraction in [0, 0.5]".into(),
            });
        }
        let r = self.resolve();
        r.frontend.check(&mut p);
        r.backend.check(&mut p);
        r.checker.check(&mut p);
        if let Err(e) = r.manager.validate() {
            p.list.push(plan_problem(e, "manager", "planner.manager"));
        }
        if let Err(e) = self.route.params.validate() {
            p.list.push(route_problem(e));
        }
        p.list
    }
}

/// The default tracking margin (m) for a vehicle with acceleration limit `a_max` (m/s²):
/// `0.01 + 0.0015·a_max` — 14.5 mm at a Crazyflie's 3 m/s², 32.5 mm at E4's 15 m/s².
///
/// Measured on the default quadrotor model (`trust_vehicle`, SE(3) controller at 500 Hz): the
/// largest deviation from the plan is 1.1 / 7.3 mm on the gentle / aggressive figure-eight
/// (4 / 9.5 m/s, 4.1 / 12.8 m/s²; `trust_vehicle` docs) and, worst, during the manager's
/// braking manoeuvre from `v_max` (`crates/flight/tests/braking.rs`): 6.9 mm at 1 m/s and
/// 3 m/s², 13.5 mm at 5 m/s and 8 m/s², 21.8 mm at 10 m/s and 15 m/s² — it grows with the
/// deceleration's ramp (`a_max` over 0.2 s), i.e. with `a_max`. The rule stays 1.5–2.1 times
/// above every measurement; the braking test asserts it.
pub fn tracking_margin_for(a_max: f64) -> f64 {
    0.01 + 0.0015 * a_max
}

/// The presets' backend at the vehicle's scale (every other backend parameter is already
/// relative, or an absolute justified where it is defined):
///
/// | parameter | rule | 1 m/s, 3 m/s² | E4: 10 m/s, 15 m/s² |
/// |---|---|---|---|
/// | terminal weight `λ_s` | `λ_t · (10 m/s) / v_max` | 600 | 60 |
/// | piece length | [`PRESET_PIECE_DURATION_S`]` · v_max` | 0.7 m | 7 m |
/// | `d_ε` (`goal_radius_m`) | three braking distances, `1.5 v_max²/a_max` | 0.5 m | 10 m |
/// | guidance smoothing | `0.1 s · v_max` | 0.1 m | 1 m |
/// | jerk energy weight `λ_e` | absolute, [`PRESET_ENERGY_WEIGHT`] (set by [`closed_loop_backend`]) | 0.1 | 0.1 |
///
/// `λ_t/λ_s` is the speed below which standing still costs less than flying toward the aim: with
/// the fixed 60 / 60 (1 m/s) a vehicle with `v_max` ≤ 0.8 m/s stayed at the start in an empty
/// room (the optimizer returned 0.04 s stubs), and one at 1 m/s crawled across a hall at 3× the
/// ideal time. Scaled, it is `v_max / 10` at every scale; at E4's limits every value is the one
/// measured there.
fn scale_preset_backend(backend: &mut BackendSpec, limits: &Limits) {
    let v = limits.v_max;
    let weights = backend.weights_mut();
    weights.terminal = weights.time * PRESET_TERMINAL_SPEED_M_S / v;
    backend.pieces_mut().target_piece_length_m = PRESET_PIECE_DURATION_S * v;
    let penalty = backend.penalty_mut();
    penalty.goal_radius_m = 1.5 * v * v / limits.a_max;
    penalty.guidance_smoothing_m = 0.1 * v;
}

/// `λ_s = λ_t · 10 m/s / v_max` in the presets ([`effective`] scales the preset backend): E4's
/// measured 60 / 60 at 10 m/s.
pub const PRESET_TERMINAL_SPEED_M_S: f64 = 10.0;

/// Duration (s) of one backend piece at `v_max` in the presets: [`effective`] sets the preset
/// backend's `pieces.target_piece_length_m` to `0.7 s · v_max` — E4's measured 7 m at 10 m/s
/// (`trust_minco::PieceParams`), 0.7 m at a Crazyflie's 1 m/s. With 7 m pieces a 4 m room
/// horizon was one piece, too stiff to pass between people.
pub const PRESET_PIECE_DURATION_S: f64 = 0.7;

/// The default acceleration headroom: the planner plans and checks with `0.9·a_max`.
///
/// The controller needs acceleration beyond the plan's to correct its tracking error while the
/// attitude catches up with a swing of the planned acceleration: on the default quadrotor a
/// reversal of `±0.9 a_max` at the presets' jerk limit ([`PRESET_JERK_RAMP_S`]) peaks at 0.96
/// `a_max` (3 m/s²) and 0.93 `a_max` (15 m/s²) (`crates/flight/tests/accel_headroom.rs`); at the
/// full `a_max` the rooms with people reached 1.14 `a_max`. A fraction of `a_max`, hence
/// scale-free.
pub const DEFAULT_ACCEL_HEADROOM: f64 = 0.1;

/// The limits the planner plans and checks with: `a_max·(1 − headroom)`, `v_max` unchanged.
pub fn planning_limits(limits: Limits, headroom: f64) -> Limits {
    Limits {
        v_max: limits.v_max,
        a_max: limits.a_max * (1.0 - headroom.clamp(0.0, 0.5)),
    }
}

/// A route-parameter error as a problem under `planner.route.params`.
fn route_problem(e: RouteError) -> Problem {
    match e {
        RouteError::InvalidParam {
            field,
            value,
            expected,
        } => Problem {
            field: format!(
                "planner.route.params.{}",
                field.strip_prefix("route.").unwrap_or(&field)
            ),
            value: crate::problem::fmt_num(value),
            expected,
        },
        other => Problem::new("planner.route.params", other, "valid route parameters"),
    }
}

/// What the assembly needs to know about the vehicle and the trial.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlannerContext {
    /// The vehicle's limits.
    pub limits: Limits,
    /// The vehicle's radius (m).
    pub vehicle_radius_m: f64,
    /// How much the planner's static map may overestimate a distance (m):
    /// [`crate::World::static_map_error_m`].
    pub static_map_error_m: f64,
    /// Seed of the planner's random stream (`ManagerParams::seed`), usually
    /// [`crate::Seeds::planner`].
    pub seed: u64,
}

/// The parameters actually used: `resolved` with the clearances raised to the vehicle's
/// (module docs), a preset's backend scaled to the vehicle's limits (terminal weight
/// `λ_t·`[`PRESET_TERMINAL_SPEED_M_S`]`/v_max`, piece length [`PRESET_PIECE_DURATION_S`]` ·
/// v_max`, `d_ε = 1.5 v_max²/a_max`, guidance smoothing `0.1 s · v_max`: E4's measured values at
/// 10 m/s and 15 m/s²), the reproducible-mode budgets applied, and `manager.seed = ctx.seed`.
///
/// # Errors
/// [`WorldError::Input`] for a negative or non-finite radius or map error.
pub fn effective(
    resolved: &ResolvedPlanner,
    ctx: &PlannerContext,
) -> Result<ResolvedPlanner, WorldError> {
    let r = ctx.vehicle_radius_m;
    if !(r.is_finite() && r >= 0.0) {
        return Err(WorldError::input(
            "vehicle.radius_m",
            r,
            "a finite number >= 0",
        ));
    }
    let e = ctx.static_map_error_m;
    if !(e.is_finite() && e >= 0.0) {
        return Err(WorldError::input(
            "static_map_error_m",
            e,
            "a finite number >= 0",
        ));
    }
    let mut out = resolved.clone();
    let m = out
        .tracking_margin_m
        .unwrap_or_else(|| tracking_margin_for(ctx.limits.a_max));
    match &mut out.frontend {
        FrontendSpec::DevPrm(x) => {
            x.clearance = x.clearance.max(r + m);
            x.surface_offset = x.surface_offset.max(x.clearance);
            if out.reproducible {
                x.wall_clock_budget = false;
            }
        }
        FrontendSpec::VPrm(x) => {
            x.clearance = x.clearance.max(r + m);
            if out.reproducible {
                x.wall_clock_budget = false;
            }
        }
        FrontendSpec::SparseAStar(x) => {
            x.clearance = x.clearance.max(r + m);
            if out.reproducible {
                x.budget_ms = x.budget_ms.max(REPRODUCIBLE_BUDGET_MS);
            }
        }
        FrontendSpec::StraightLine(_) => {}
    }
    if out.preset_backend {
        scale_preset_backend(&mut out.backend, &ctx.limits);
    }
    let penalty = out.backend.penalty_mut();
    penalty.static_clearance_m = penalty
        .static_clearance_m
        .max(r + out.clearance_margin_m.max(m) + e);
    penalty.dynamic_clearance_m = penalty.dynamic_clearance_m.max(m);
    let safety = &mut out.manager.safety;
    safety.static_clearance_m = safety.static_clearance_m.max(r + e + m);
    safety.dynamic_clearance_m = safety.dynamic_clearance_m.max(m);
    if out.reproducible {
        out.manager.enforce_budget = false;
    }
    out.manager.seed = ctx.seed;
    Ok(out)
}

/// UTF-MINCO as the presets fly it: [`UtfMincoParams::default`] with the time weight `λ_t` and
/// the terminal weight `λ_s` at 60 (library defaults: GCOPTER's 20 and our 50; `λ_s` must stay
/// above `λ_t / v` for the free terminal to reach the goal, see `trust_minco::CostWeights`).
/// With 20 / 50 the vehicle flew E4 at ~8 m/s on average. E4 seeds 0–7 (every flight arrived):
///
/// | `λ_t` / `λ_s` | flight times (s) | mean | E3 branches, seeds 0–9 |
/// |---|---|---|---|
/// | 20 / 50 | 30.9 29.1 36.3 32.3 29.7 32.9 30.4 28.3 | 31.2 | 2 1 1 3 2 2 4 2 4 3 |
/// | 60 / 60 | 28.1 28.2 29.0 28.4 28.2 28.1 32.5 27.5 | 28.7 | 2 1 1 3 3 2 4 2 4 3 |
/// | 150 / 150 | 27.7 28.0 28.3 27.3 27.3 28.3 27.2 26.8 | 27.6 | 2 1 1 3 2 0 4 2 4 3 |
///
/// (paper: 29.4 s; distance / `v_max` = 24.6 s). Above 60 the cold solves of E3 stall above
/// `v_max` more often (seed 5 kept no branch at 150 / 150); 300 / 300 also let E4's speed
/// overshoot `v_max` by 0.2 % (the feasibility penalty is soft).
///
/// The jerk energy weighs [`PRESET_ENERGY_WEIGHT`] instead of GCOPTER's 1 (the table above was
/// measured with 1), and jerk above `a_max /` [`PRESET_JERK_RAMP_S`] is penalized.
///
/// A scenario's `backend = { kind = "utf-minco", … }` starts from the library defaults, not from
/// these: give `weights` there to keep them.
pub fn closed_loop_backend() -> UtfMincoParams {
    let mut p = UtfMincoParams::default();
    p.weights.time = 60.0;
    p.weights.terminal = 60.0;
    p.weights.energy = PRESET_ENERGY_WEIGHT;
    p.penalty.jerk_ramp_s = PRESET_JERK_RAMP_S;
    p
}

/// The presets' jerk energy weight `λ_e` (GCOPTER and the library: 1).
///
/// With 1 the energy, not the limits, shaped every start from rest: the plan reached `0.9 v_max`
/// only after 3.1–3.6 `v_max/a_max` (planning `a_max`), using 0.34–0.40 of it, at a Crazyflie
/// room's 1.3 m/s and at E4's 10 m/s alike, and every trip started and ended about 0.5 s (room) to
/// 1 s (E4) late. The presets' jerk limit already keeps the plan trackable, so the energy only
/// needs to regularize. With 0.1 the start is limited by the jerk limit and the piece length
/// (0.9 `v_max` after 1.8–2.4 `v_max/a_max`; `tests/start_from_rest.rs`). Measured (issue 19,
/// seed 7300 for E4, every flight arrived, no collision):
///
/// | `λ_e` | E4, 8 trials: mean (s) | suite, 55 flights: mean `T/(d/v_max)` | 7 room files × 3: above 1.3 |
/// |---|---|---|---|
/// | 1 | 29.2 | 1.76 | 10 of 21 |
/// | 0.1 | 27.3 | 1.51 | 5 of 21 |
/// | 0.03 | 27.1 | – | 4 of 21 |
///
/// 0.3 kept 7 of the 21 rooms above 1.3; below 0.1 the gain is small and E4's peak acceleration
/// rises (8 → 11 m/s² of 15). An absolute weight (units m⁻²s⁵ against `λ_t`'s s⁻¹): from 1 to
/// 10 m/s the start is limited by the jerk limit at 0.1, not by the energy.
pub const PRESET_ENERGY_WEIGHT: f64 = 0.1;

/// The presets' jerk limit as a ramp time: UTF-MINCO penalizes jerk above `a_max / 0.3 s`
/// (`trust_minco::PenaltyParams::jerk_ramp_s`). The quadrotor's attitude lags a fast swing of the
/// planned acceleration and its true acceleration overshoots: a reversal of `±0.9 a_max` peaks at
/// 1.17 / 1.03 / 0.96 `a_max` with a ramp of 0.1 / 0.2 / 0.3 s at 3 m/s², 1.07 / 0.99 / 0.93 at
/// 15 m/s² (`crates/flight/tests/accel_headroom.rs`). MINCO's time-optimal branches swung in well
/// under 0.1 s (rooms with people: 1.2 `a_max`). 0.2 s kept the accelerations within 5 % too,
/// but the rooms with people had more failures (19 against 13 of 120 flights, seeds 100–119 of
/// six room files) and up to 1.06 `a_max`; E4 flies a little faster with it.
pub const PRESET_JERK_RAMP_S: f64 = 0.3;

/// Builds the manager of `resolved` for a vehicle and trial ([`effective`] parameters).
///
/// # Errors
/// [`WorldError::Input`] as [`effective`]; [`WorldError::Plan`] naming the invalid field of a part.
pub fn build(resolved: &ResolvedPlanner, ctx: &PlannerContext) -> Result<AnyManager, WorldError> {
    let eff = effective(resolved, ctx)?;
    let frontend = eff.frontend.build()?;
    let backend = eff.backend.build()?;
    let checker = eff.checker.build()?;
    let limits = planning_limits(
        ctx.limits,
        eff.accel_headroom.unwrap_or(DEFAULT_ACCEL_HEADROOM),
    );
    let mut manager = Manager::new(frontend, backend, checker, limits, eff.manager)?;
    if let Some(params) = eff.route {
        manager.set_router(Some(Router::new(params, ctx.vehicle_radius_m)?));
    }
    Ok(manager)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plan_problems_are_reprefixed() {
        let e = PlanError::invalid("devprm.budget_ms", -1.0, "a finite number > 0");
        let p = plan_problem(e, "devprm", "planner.frontend");
        assert_eq!(p.field, "planner.frontend.budget_ms");
        let e = PlanError::invalid("planner.backend.pieces.min_pieces", 0, ">= 1");
        assert_eq!(
            plan_problem(e, "", "planner.backend").field,
            "planner.backend.pieces.min_pieces"
        );
    }

    #[test]
    fn manager_overrides_merge_onto_the_preset() {
        let spec: PlannerSpec =
            toml::from_str("name = \"baseline1\"\n[manager]\nhorizon_s = 3.0\nwall_images = false\nforecast_growth_s = inf\n[manager.safety]\nmax_step_s = 0.02\nrest_hold_s = 1.5\n")
                .unwrap();
        let r = spec.resolve();
        assert_eq!(r.manager.max_branches, 1);
        assert_eq!(r.manager.horizon_s, 3.0);
        assert!(!r.manager.wall_images);
        assert_eq!(r.manager.forecast_growth(), f64::INFINITY);
        assert_eq!(r.manager.safety.rest_hold_s, 1.5);
        assert_eq!(r.manager.safety.max_step_s, 0.02);
        assert_eq!(r.manager.safety.min_step_s, 1e-3);
        assert_eq!(r.label, "baseline1[manager]");
        let e = toml::from_str::<PlannerSpec>("[manager]\nbranches = 3\n").unwrap_err();
        assert!(e.to_string().contains("branches"), "{e}");
        // The planner's seed comes from the trial: overriding it is an error, not a no-op.
        let e = toml::from_str::<PlannerSpec>("[manager]\nseed = 3\n").unwrap_err();
        assert!(e.to_string().contains("unknown field `seed`"), "{e}");
        let e = toml::from_str::<PlannerSpec>("[manager.safety]\nmax_step = 0.1\n").unwrap_err();
        assert!(e.to_string().contains("max_step"), "{e}");
    }
}
