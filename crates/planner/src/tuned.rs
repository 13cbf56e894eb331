//! The tuned constants of the presets, each with the measurement behind it: DEV-PRM's budget,
//! the closed-loop UTF-MINCO ([`closed_loop_backend`]: weights, jerk energy and jerk limit), the
//! scale rules of the preset backend, the tracking margin and the acceleration headroom. The
//! scale-free table in ARCHITECTURE.md lists what they give at a Crazyflie's and at E4's limits.

use trust_core::Limits;
use trust_minco::UtfMincoParams;
use trust_topo_prm::DevPrmParams;

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

/// `λ_s = λ_t · 10 m/s / v_max` in the presets ([`crate::effective`] scales the preset backend): E4's
/// measured 60 / 60 at 10 m/s.
pub const PRESET_TERMINAL_SPEED_M_S: f64 = 10.0;

/// Duration (s) of one backend piece at `v_max` in the presets: [`crate::effective`] sets the preset
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
