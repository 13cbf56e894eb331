//! Assembling a planner for a vehicle and a trial: [`effective`] adjusts a resolved planner to
//! the vehicle (clearances, the preset backend's scale, reproducible budgets, the seed) and
//! [`build`] makes its manager.
//!
//! # Clearances (set by [`effective`], from the vehicle radius `r`)
//!
//! Forecasts already hold the vehicle radius in their `r_safe` (`trust_world::sensing`), so the
//! moving-obstacle clearances of the parts stay as given. The static map holds the obstacles
//! themselves, so:
//!
//! * the manager's `safety.static_clearance_m ≥ r + e + m`, where `e` is how much the planner's
//!   map may overestimate a distance (0 for analytic shapes; see
//!   `trust_world::World::static_map_error_m`) and `m` the tracking margin
//!   ([`crate::PlannerSpec::tracking_margin_m`]) — a branch the safety check passes keeps the true
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
//! [`crate::REPRODUCIBLE_BUDGET_MS`] so that only its expansion cap ends a search. A run then depends
//! only on the seeds, not on how loaded the machine is; wall-clock budgets make runs
//! machine-dependent (a slower machine draws fewer samples). CPU times are still measured and
//! reported. Set `reproducible = false` to study the real-time behaviour under the budgets (the
//! work budgets then stay, backed by the clock).

use trust_core::Limits;
use trust_manager::{Manager, Router};

use crate::any::AnyManager;
use crate::error::PlannerError;
use crate::spec::{BackendSpec, FrontendSpec, ResolvedPlanner};
use crate::tuned::{
    DEFAULT_ACCEL_HEADROOM, PRESET_PIECE_DURATION_S, PRESET_TERMINAL_SPEED_M_S,
    REPRODUCIBLE_BUDGET_MS, planning_limits, tracking_margin_for,
};

/// The presets' backend at the vehicle's scale (every other backend parameter is already
/// relative, or an absolute justified where it is defined):
///
/// | parameter | rule | 1 m/s, 3 m/s² | E4: 10 m/s, 15 m/s² |
/// |---|---|---|---|
/// | terminal weight `λ_s` | `λ_t · (10 m/s) / v_max` | 600 | 60 |
/// | piece length | [`PRESET_PIECE_DURATION_S`]` · v_max` | 0.7 m | 7 m |
/// | `d_ε` (`goal_radius_m`) | three braking distances, `1.5 v_max²/a_max` | 0.5 m | 10 m |
/// | guidance smoothing | `0.1 s · v_max` | 0.1 m | 1 m |
/// | jerk energy weight `λ_e` | absolute, [`crate::PRESET_ENERGY_WEIGHT`] (set by [`crate::closed_loop_backend`]) | 0.1 | 0.1 |
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

/// What the assembly needs to know about the vehicle and the trial.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlannerContext {
    /// The vehicle's limits.
    pub limits: Limits,
    /// The vehicle's radius (m).
    pub vehicle_radius_m: f64,
    /// How much the planner's static map may overestimate a distance (m):
    /// `trust_world::World::static_map_error_m`.
    pub static_map_error_m: f64,
    /// Seed of the planner's random stream (`ManagerParams::seed`), usually
    /// `trust_world::Seeds::planner`.
    pub seed: u64,
}

/// The parameters actually used: `resolved` with the clearances raised to the vehicle's
/// (the module docs), a preset's backend scaled to the vehicle's limits (terminal weight
/// `λ_t·`[`PRESET_TERMINAL_SPEED_M_S`]`/v_max`, piece length [`PRESET_PIECE_DURATION_S`]` ·
/// v_max`, `d_ε = 1.5 v_max²/a_max`, guidance smoothing `0.1 s · v_max`: E4's measured values at
/// 10 m/s and 15 m/s²), the reproducible-mode budgets applied, and `manager.seed = ctx.seed`.
///
/// # Errors
/// [`PlannerError::Input`] for a negative or non-finite radius or map error.
pub fn effective(
    resolved: &ResolvedPlanner,
    ctx: &PlannerContext,
) -> Result<ResolvedPlanner, PlannerError> {
    let r = ctx.vehicle_radius_m;
    if !(r.is_finite() && r >= 0.0) {
        return Err(PlannerError::input(
            "vehicle.radius_m",
            r,
            "a finite number >= 0",
        ));
    }
    let e = ctx.static_map_error_m;
    if !(e.is_finite() && e >= 0.0) {
        return Err(PlannerError::input(
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

/// Builds the manager of `resolved` for a vehicle and trial ([`effective`] parameters).
///
/// # Errors
/// [`PlannerError::Input`] as [`effective`]; [`PlannerError::Plan`] naming the invalid field of
/// a part.
pub fn build(resolved: &ResolvedPlanner, ctx: &PlannerContext) -> Result<AnyManager, PlannerError> {
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
