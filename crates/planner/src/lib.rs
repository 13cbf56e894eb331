//! # trust-planner — TRUST-Planner and its baselines, assembled by name
//!
//! The planner as flown: the paper's TRUST-Planner and baselines 1–3 (Sec. IV-D), or any
//! combination of frontend, backend, homotopy checker and manager mode, chosen once from closed
//! serde enums and assembled into one generic `trust_manager::Manager` ([`AnyManager`]; style
//! rule 4). It holds the scenario's `[planner]` section ([`PlannerSpec`]: a preset plus
//! overrides), the presets, the tuned constants behind them ([`closed_loop_backend`],
//! [`tracking_margin_for`], …), the vehicle-dependent adjustments ([`effective`]) and [`build`].
//!
//! Use it to fly the paper's planners in your own loop: parse a `[planner]` table, resolve it,
//! and build its manager for your vehicle. The simulator reads the section as part of a scenario
//! file (`trust_world::Scenario<PlannerSpec>`, composed in `trust_flight::scenario`); the world
//! crate never names these types.
//!
//! | preset (`name`) | frontend | backend | checker | manager |
//! |---|---|---|---|---|
//! | `trust` | DEV-PRM | UTF-MINCO | TVD | `ManagerParams::trust` |
//! | `baseline1` | straight line | UTF-MINCO | TVD | `ManagerParams::single_branch` |
//! | `baseline2` | sparse A* | UTF-MINCO | TVD | `ManagerParams::single_branch` |
//! | `baseline3` | DEV-PRM | UTF-MINCO | TVD | `ManagerParams::multi_branch_without_history` |
//!
//! Every preset's UTF-MINCO is [`closed_loop_backend`] ([`tuned`] has each constant with its
//! measurement); `[planner.manager]` replaces single fields of the preset's `ManagerParams`
//! through `trust_manager::ManagerOverrides`, derived from `ManagerParams` itself ([`spec`]); the
//! clearances follow the vehicle radius and reproducible runs have no wall-clock budgets
//! ([`assemble`]). Invalid parameters are [`Problem`]s or [`PlannerError`]s naming the field,
//! the value and what was expected.
//!
//! ```
//! use trust_core::{Limits, PathFrontend};
//! use trust_planner::{PlannerContext, PlannerSpec, build};
//!
//! let spec: PlannerSpec = toml::from_str("name = \"baseline1\"\n[manager]\nhorizon_s = 3.0\n")?;
//! assert!(spec.problems().is_empty());
//! let resolved = spec.resolve();
//! assert_eq!(resolved.label, "baseline1[manager]");
//! let ctx = PlannerContext {
//!     limits: Limits::default(),
//!     vehicle_radius_m: 0.1,
//!     static_map_error_m: 0.0,
//!     seed: 7,
//! };
//! assert_eq!(resolved.frontend.build()?.name(), "straight-line");
//! let manager = build(&resolved, &ctx)?;
//! assert_eq!(manager.params().max_branches, 1, "still single-branch");
//! assert_eq!(manager.params().horizon_s, 3.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(missing_docs)]

pub mod any;
pub mod assemble;
pub mod error;
pub mod spec;
pub mod tuned;

pub use any::{AnyBackend, AnyChecker, AnyFrontend, AnyManager};
pub use assemble::{PlannerContext, build, effective};
pub use error::{PlannerError, Problem};
pub use spec::{
    BackendSpec, CheckerSpec, FrontendSpec, PlannerPreset, PlannerSpec, ResolvedPlanner, RouteSpec,
    StraightLineParams,
};
/// The `[planner.manager]` overrides ([`PlannerSpec::manager`]), derived from `ManagerParams`.
pub use trust_manager::ManagerOverrides;
pub use tuned::{
    DEFAULT_ACCEL_HEADROOM, PRESET_DEV_PRM_BUDGET_MS, PRESET_ENERGY_WEIGHT, PRESET_JERK_RAMP_S,
    PRESET_PIECE_DURATION_S, PRESET_TERMINAL_SPEED_M_S, REPRODUCIBLE_BUDGET_MS,
    closed_loop_backend, planning_limits, preset_dev_prm, tracking_margin_for,
};
