//! # trust-manager — the multi-branch spatio-temporal trajectory manager of TRUST-Planner
//!
//! [`Manager`] implements Algorithm 1 of the paper (Sec. III-A, "Incremental Planning of
//! TRUST-Planner", Fig. topological-update): a priority queue of up to `N` trajectory branches of
//! distinct spatio-temporal homotopy, ranked by `J = λ_t·H_t + λ_s·H_s + λ_e·I_e` (Table Sim-B-1).
//! Every cycle ([`Manager::step`]) it marches the main branch forward, replans the sub-branches from
//! the current state, explores new branches from the frontend's paths, deduplicates them with the
//! homotopy checker and keeps the `N` best; the main branch is the plan the vehicle flies.
//!
//! It is generic over the three traits of `trust-core` — `Manager<F: PathFrontend,
//! B: TrajectoryBackend, H: HomotopyChecker>` — so the paper's baselines are the same manager with
//! other parts and parameters ([`ManagerParams::single_branch`] with a straight-line or sparse-A*
//! frontend for baselines 1 and 2, [`ManagerParams::multi_branch_without_history`] for baseline 3).
//! Use it to fly any frontend/backend/checker combination, in the simulator (`trust-flight`) or on
//! your own loop: call `step` at the replanning rate with the measured state and the forecasts, fly
//! [`Manager::plan`].
//!
//! Beyond the paper (each documented where it lives; the reasons in `docs/decisions/`):
//! - plans join continuously: the replan start is the committed plan at `now + latency`;
//! - every kept branch passes a safety check each cycle, continuous in time with a proven step
//!   ([`check_trajectory`]), against the static map and the current forecasts, their growth stopped
//!   after [`GROWTH_FRACTION`] of the horizon and mirrored at the walls;
//! - FwdExplore runs every third cycle and warm re-solves are capped in evaluations;
//! - the main branch switches with hysteresis; a branch that reaches the goal outranks every branch
//!   that stops short of it ([`Branch::rank_cmp`]);
//! - a global route ([`Router`], searched in slices), a progress monitor ([`progress`]), and
//!   fallbacks that brake, evade or escape ([`brake_along`], [`escape_maneuvers`],
//!   [`dash_maneuvers`]);
//! - each cycle returns a serializable [`StepReport`] (branches, events, timing split).
//!
//! ```
//! use trust_core::{Aabb, Limits, Scene, State, StaticMap, Vec3};
//! use trust_manager::{Manager, ManagerParams};
//! use trust_minco::UtfMinco;
//! use trust_topo_prm::{StraightLine, Tvd};
//!
//! // Any frontend, backend and checker; the paper's planner is DevPrm, UtfMinco and Tvd.
//! let mut manager = Manager::new(
//!     StraightLine,
//!     UtfMinco::default(),
//!     Tvd::default(),
//!     Limits::default(),
//!     ManagerParams::default(),
//! )?;
//! let map = StaticMap::empty(Aabb::new(Vec3::zeros(), Vec3::new(20.0, 20.0, 10.0))?)?;
//! let scene = Scene::new(&map, &[], 0.0)?;
//! let start = State::at_rest(0.0, Vec3::new(1.0, 1.0, 1.0));
//! let report = manager.step(0.0, &start, &Vec3::new(15.0, 10.0, 2.0), &scene)?;
//! assert!(report.main.is_some());
//! assert_eq!(manager.plan().expect("a plan").t_start(), report.replan_start.t);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(missing_docs)]

pub mod brake;
mod commit;
mod manager;
mod params;
pub mod progress;
mod report;
pub mod retreat;
pub mod routing;
pub mod safety;

pub use brake::{
    brake_along, brake_straight, braking_tail, dash_maneuvers, escape_maneuvers, hermite_quintic,
};
pub use commit::{CommitCheck, committed_stretch};
pub use manager::{Branch, HOLD_CLEARANCE_M, MainDecision, Manager, choose_main};
pub use params::{
    GROWTH_FRACTION, ManagerOverrides, ManagerParams, ProgressOverrides, ProgressParams,
    ReanchorOverrides, ReanchorParams, SOLVE_DEADLINE_FRACTION, SafetyOverrides, SafetyParams,
    StallRule,
};
pub use progress::ProgressMonitor;
pub use report::{
    BranchId, BranchReport, CycleTiming, Event, FallbackKind, FallbackReport, FrontendReport,
    GoalUnreachable, LimitExcess, Origin, RouteReason, STUB_FRACTION, StepReport, SwitchReason,
};
pub use retreat::FlownPath;
pub use routing::{
    IN_CYCLE_CHUNKS, RECHECK_S, ROUTE_DEADLINE_FRACTION, ROUTE_WORK_PER_CYCLE, Router,
};
pub use safety::{Hit, SafetyVerdict, Violation, assess_trajectory, check_trajectory};
/// Why a goal cannot be reached ([`Event::GoalUnreachable`], [`GoalUnreachable`]).
pub use trust_route::UnreachableCause;
