//! The scenario's `[planner]` section ([`PlannerSpec`]): a preset by name plus overrides, the
//! closed serde enums that name each part ([`FrontendSpec`], [`BackendSpec`], [`CheckerSpec`]),
//! and the planner with every part chosen ([`ResolvedPlanner`]).
//!
//! Overrides replace parts of the preset: `frontend = { kind = "v-prm", budget_ms = 20 }`
//! replaces the frontend (the fields are that kind's `…Params`, unspecified ones at their
//! defaults), likewise `backend` and `checker`; `[planner.manager]` fields replace single fields
//! of the preset's `ManagerParams` (`trust_manager::ManagerOverrides`, derived from
//! `ManagerParams` itself), so `name = "baseline1"` with `manager.horizon_s = 3` stays
//! single-branch.

use serde::{Deserialize, Serialize};
use trust_core::{Overridable, PlanError};
use trust_manager::{ManagerOverrides, ManagerParams};
use trust_minco::{CostWeights, MincoParams, PenaltyParams, PieceParams, UtfMincoParams};
use trust_route::{RouteError, RouteParams};
use trust_topo_prm::{
    DevPrm, DevPrmParams, SparseAStar, SparseAStarParams, StraightLine, Tvd, TvdParams, Uvd,
    UvdParams, Vprm, VprmParams,
};

use crate::any::{AnyBackend, AnyChecker, AnyFrontend};
use crate::error::Problem;
use crate::tuned::{closed_loop_backend, preset_dev_prm};
use trust_minco::{Minco, UtfMinco};

/// Collects the problems of a section.
#[derive(Debug, Default)]
struct Problems {
    list: Vec<Problem>,
}

impl Problems {
    /// `value` must be finite and `>= 0`.
    fn non_negative(&mut self, field: &str, value: f64) {
        if !(value.is_finite() && value >= 0.0) {
            self.list
                .push(Problem::new(field, value, "a finite number >= 0"));
        }
    }
}

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

    /// The frontend alone (experiment E1 runs it without a manager). [`build`](crate::build) applies the
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

    /// The backend alone (experiment E2 runs it without a manager). [`build`](crate::build) applies the
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

    pub(crate) fn weights_mut(&mut self) -> &mut CostWeights {
        match self {
            BackendSpec::UtfMinco(x) => &mut x.weights,
            BackendSpec::Minco(x) => &mut x.weights,
        }
    }

    pub(crate) fn pieces_mut(&mut self) -> &mut PieceParams {
        match self {
            BackendSpec::UtfMinco(x) => &mut x.pieces,
            BackendSpec::Minco(x) => &mut x.pieces,
        }
    }

    pub(crate) fn penalty_mut(&mut self) -> &mut PenaltyParams {
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
                // The planning crates write the value with `{:?}` (17 digits); the scenario checks
                // make it readable.
                value,
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

/// Scenario section `[planner]`: a preset by name plus optional overrides ([`crate::assemble`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PlannerSpec {
    /// The preset. Default `trust`.
    pub name: PlannerPreset,
    /// Switch wall-clock budgets off for machine-independent runs ([`crate::assemble`]). Default `true`.
    pub reproducible: bool,
    /// Margin (m) of the backend's static clearance beyond the vehicle radius ([`crate::assemble`]).
    /// Default 0.1 m: the backends' own default static clearance.
    pub clearance_margin_m: f64,
    /// Tracking margin `m` (m): how far the true vehicle may stray from its plan. The manager's
    /// safety check (and with it the braking fallback) keeps `r + e + m` from the static map and
    /// `m` beyond every forecast; the backend's penalties and the frontends' clearances are
    /// raised to at least that ([`crate::assemble`]). Default `None`: [`crate::tracking_margin_for`] the
    /// vehicle's `a_max`.
    pub tracking_margin_m: Option<f64>,
    /// Acceleration headroom `h`: the planner plans and checks with `a_max·(1 − h)`, leaving the
    /// rest of the vehicle's `a_max` to its controller ([`crate::assemble`]). Default `None`:
    /// [`crate::DEFAULT_ACCEL_HEADROOM`].
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

/// A planner with every part chosen, before the vehicle-dependent adjustments of [`crate::effective`].
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
    /// The backend is the preset's (not replaced by the scenario): [`crate::effective`] sets its piece
    /// length to [`crate::PRESET_PIECE_DURATION_S`]` · v_max`.
    #[serde(default)]
    pub preset_backend: bool,
    /// The route planner's parameters when the route is on ([`PlannerSpec::route`]); `None`
    /// flies the paper's setting (every query aims at the final goal).
    pub route: Option<RouteParams>,
}

impl PlannerSpec {
    /// The preset with the overrides applied (typed: [`Overridable::apply`] of
    /// [`ManagerOverrides`]).
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
            manager.apply(m);
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
                value: h.to_string(),
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
            value: value.to_string(),
            expected,
        },
        other => Problem::new("planner.route.params", other, "valid route parameters"),
    }
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
