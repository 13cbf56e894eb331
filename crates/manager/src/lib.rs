//! # trust-manager — the multi-branch spatio-temporal trajectory manager of TRUST-Planner
//!
//! [`Manager`] implements Algorithm 1 of the paper (Sec. III-A, "Incremental Planning of
//! TRUST-Planner", Fig. topological-update): a priority queue of up to `N` trajectory branches of
//! distinct spatio-temporal homotopy, ranked by `J = λ_t·H_t + λ_s·H_s + λ_e·I_e` (Table Sim-B-1).
//! Every cycle it marches the main branch forward, replans the sub-branches from the current
//! state, explores new branches from the frontend's paths, deduplicates them with the homotopy
//! checker and keeps the `N` best; the main branch is the plan the vehicle flies.
//!
//! It is generic over the three traits of `trust-core` — `Manager<F: PathFrontend,
//! B: TrajectoryBackend, H: HomotopyChecker>` — so the paper's baselines are the same manager with
//! other parts and parameters ([`ManagerParams::single_branch`] with a straight-line or sparse-A*
//! frontend for baselines 1 and 2, [`ManagerParams::multi_branch_without_history`] for baseline 3).
//!
//! Beyond the paper (each documented where it lives):
//! - plans join continuously: the replan starts from the committed plan at `now + latency`;
//! - every kept branch passes a safety check each cycle, continuous in time with a proven step
//!   ([`check_trajectory`]), against the static map and the current forecasts;
//! - the main branch switches with hysteresis ([`ManagerParams::hysteresis`]);
//! - a branch that reaches the goal outranks every branch that stops short of it, whatever their
//!   `J` ([`Branch::rank_cmp`]: with `λ_s = 1/v_max` standing still `d` short costs about `d/v_max`,
//!   less than flying there);
//! - a progress monitor reports `stalled` / `escaped` and escalates while stalled
//!   ([`progress`]);
//! - with no feasible branch the plan is a braking fallback along the last safe trajectory
//!   ([`brake_along`]), and the report says whether it is collision-free under the forecasts;
//! - each cycle returns a serializable [`StepReport`] (branches, events, timing split).
//!
//! ```
//! use trust_core::{Aabb, Limits, Scene, State, StaticMap, Vec3};
//! use trust_manager::{Manager, ManagerParams};
//! # use trust_core::*;
//! # struct Line;
//! # impl PathFrontend for Line {
//! #     fn name(&self) -> &str { "line" }
//! #     fn search(&self, q: &PathQuery, _: &Scene<'_>, _: &mut Rng) -> Result<SearchResult, PlanError> {
//! #         Ok(SearchResult { paths: vec![GuidePath::new(vec![q.start.p, q.goal])?], ..Default::default() })
//! #     }
//! # }
//! # struct Hold;
//! # impl TrajectoryBackend for Hold {
//! #     fn name(&self) -> &str { "hold" }
//! #     fn optimize(&self, r: &TrajRequest<'_>, _: &Scene<'_>) -> Result<Solution, PlanError> {
//! #         Ok(Solution { traj: PolyTraj::hold(r.start.t, r.start.p, 1.0)?, costs: CostBreakdown::default(),
//! #             stats: SolveStats { iteration_count: 0, evaluation_count: 0, elapsed: Default::default(), status: SolveStatus::Converged }, violations: Vec::new() })
//! #     }
//! # }
//! # struct Never;
//! # impl HomotopyChecker for Never {
//! #     fn name(&self) -> &str { "never" }
//! #     fn equivalent(&self, _: &dyn Curve, _: &dyn Curve, _: &Scene<'_>) -> Result<bool, PlanError> { Ok(false) }
//! # }
//! // Any frontend, backend and checker (here toy ones; in practice DevPrm, UtfMinco, Tvd).
//! let mut manager = Manager::new(Line, Hold, Never, Limits::default(), ManagerParams::default())?;
//! let map = StaticMap::empty(Aabb::new(Vec3::zeros(), Vec3::new(20.0, 20.0, 10.0))?)?;
//! let scene = Scene::new(&map, &[], 0.0)?;
//! let report = manager.step(0.0, &State::at_rest(0.0, Vec3::new(1.0, 1.0, 1.0)), &Vec3::new(15.0, 10.0, 2.0), &scene)?;
//! assert!(report.main.is_some());
//! let plan = manager.plan().expect("a plan");
//! assert_eq!(plan.t_start(), report.replan_start.t);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # Changelog
//!
//! - Issue 19 (beyond the paper): [`Manager::set_router`] gives the manager a [`Router`]; it plans
//!   its global route on the first cycle toward a goal and after a stall (events `Rerouted`,
//!   `RouteFailed`; [`CycleTiming::route_ms`]) and aims at the route's local goal or a sharp corner
//!   before it that hides the route beyond (else the farthest route point in sight past it). The fallback also weighs rejected trajectories flown as they are (`evade`) and
//!   [`escape_maneuvers`] (`escape`), and reports `FallbackReport::shortfall_m`.
//! - `Manager::step` follows Algorithm 1 step by step (`fwd_march`, `bwd_replan`, `fwd_explore`,
//!   the safety pass, `add_new_branch` with `pop_back`, the main-branch choice and the fallback);
//!   FwdExplore's cold solves now start as soon as the frontend returns, in parallel with the warm
//!   re-solves, instead of after them. Results, events and their order are unchanged (the run logs
//!   of `trust-sim run` are byte-identical); [`CycleTiming`] keeps its fields and meaning.
//! - `safety::bernstein_points` moved to `trust_core::bernstein_points` (arrays in, arrays out);
//!   `safety::piece_speed_bound`, `piece_box`, `window_bounds` and `forecasts_near` are now
//!   internal (they were public only for tests).
//! - The manager's homotopy checks and the safety check share one nearby-forecast filter; a
//!   forecast whose swept box cannot be computed (a non-finite window, which neither caller
//!   produces) now counts as near in both.
#![warn(missing_docs)]

pub mod brake;
mod manager;
mod params;
pub mod progress;
mod report;
pub mod routing;
pub mod safety;

pub use brake::{
    brake_along, brake_straight, braking_tail, dash_maneuvers, escape_maneuvers, hermite_quintic,
};
pub use manager::{Branch, MainDecision, Manager, choose_main};
pub use params::{
    GROWTH_FRACTION, ManagerParams, ReanchorParams, SOLVE_DEADLINE_FRACTION, SafetyParams,
};
pub use progress::{ProgressMonitor, ProgressParams, StallRule};
pub use report::{
    BranchId, BranchReport, CycleTiming, Event, FallbackReport, FrontendReport, GoalUnreachable,
    LimitExcess, Origin, STUB_FRACTION, StepReport,
};
pub use routing::{RECHECK_S, ROUTE_WORK_PER_CYCLE, Router};
pub use safety::{Hit, SafetyVerdict, Violation, assess_trajectory, check_trajectory};
