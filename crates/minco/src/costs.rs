//! Cost terms of the trajectory objective (paper Sec. III-D, eq. design-of-J), each with its value
//! and analytic gradient, usable on their own.
//!
//! | term | paper | here |
//! |---|---|---|
//! | `H_t = T_Σ` | Flight duration cost | [`time_cost`] |
//! | `H_s` | eq. design-of-Hs | [`TerminalCost`] (smoothed norm, see below) |
//! | `I_o`, moving obstacles | eqs. design-of-Io, gradients-of-Io | [`DynamicObstacleTerm`], [`ddf_violation`] |
//! | `I_o`, static map | — (static part of the world) | [`StaticObstacleTerm`] |
//! | `I_d` | eqs. design-of-Id, gradients-of-Id | [`FeasibilityTerm`] |
//! | `I_e` | eq. design-of-Ie | exact jerk energy of [`crate::MincoS3`] (not sampled) |
//!
//! The sampled terms implement [`Integrand`] and are integrated by [`TrapezoidIntegrator`] (eq.
//! trapezoidal-integration) with the gradients of eqs. dI-a, dI-b and **dI-c**, the coupling of
//! every piece's explicit time dependence (moving obstacles) into all earlier durations.
//! [`PenaltyIntegrand`] fuses them for the optimizer.
//!
//! Deviations from the paper, all documented at the item:
//! - `H_s` uses `√(xᵀKx + ε²) − ε` instead of `‖x‖_K` ([`smoothed_weighted_norm`]);
//! - `I_e` is the exact integral `Σ_i ∫‖jerk‖²` from MINCO's closed form (no trapezoid error);
//! - the DDF violation of a cylinder uses the sphere's signed-squared form of its signed distance
//!   ([`ddf_violation`]); the static-map penalty is linear in the clearance violation (metres).

mod dynamic;
mod feasibility;
mod integrand;
mod integrate;
mod params;
mod penalties;
mod smooth;
mod static_map;
mod terminal;

pub use dynamic::{DynamicObstacleTerm, ddf_violation, swept_box};
pub use feasibility::{FeasibilityTerm, norm_violation};
pub use integrand::{Integrand, SampleGrad, SampleState};
pub use integrate::{PiecewiseView, TrapezoidIntegrator};
pub use params::{
    CostWeights, MAX_SAMPLES_PER_PIECE, MAX_SMOOTHING, MAX_WEIGHT, MIN_TIME_WEIGHT, PenaltyParams,
    TERMINAL_NORM_EPSILON_RANGE,
};
pub use penalties::{BrakingTail, PenaltyIntegrals, PenaltyIntegrand, TAIL_RAMP_MPS};
pub use smooth::{SmoothedL1, smoothed_l1};
pub use static_map::StaticObstacleTerm;
pub use terminal::{
    TerminalCost, final_approach_gain, rest_to_rest_quintic_time, smoothed_weighted_norm,
    terminal_velocity_weight, time_cost,
};
