//! # trust-minco — MINCO trajectories and the UTF-MINCO backend of TRUST-Planner
//!
//! The trajectory-optimization half of the planner (paper Sec. III-D): minimum-jerk polynomial
//! trajectories parameterized by waypoints and durations (MINCO, s = 3), the cost terms of the
//! objective with their analytic gradients, and two [`trust_core::TrajectoryBackend`]s solved with
//! `trust-lbfgs`.
//!
//! - [`banded`]: banded LU without pivoting and the plain/transposed solves, the O(n) kernel of
//!   MINCO's `C = A⁻¹(T) D` and of the adjoint `A⁻ᵀ ∂I/∂C` (eq. analytical-gradients-I-to-S).
//! - [`minco`]: [`MincoS3`] — coefficients from head/tail states, waypoints and durations; the jerk
//!   energy (eq. design-of-Ie); any cost's gradient propagated to waypoints, durations and the
//!   head/tail states (eq. analytical-gradients).
//! - [`costs`]: the terms of `J = λ · [H_t, H_s, I_o, I_d, I_e]` (eq. design-of-J) — flight time, the
//!   terminal cost (eq. design-of-Hs), the moving-obstacle penalty through the dynamic distance field
//!   (eqs. design-of-Io, gradients-of-Io), a static-map penalty, the speed/acceleration penalty (eq.
//!   design-of-Id) — and the trapezoidal integrator (eq. trapezoidal-integration) with the gradients
//!   of eqs. dI-a/b/c, including the time coupling of moving obstacles into every earlier duration.
//! - [`backend`]: [`UtfMinco`] (the paper's uniform-time, terminal-free MINCO) and [`Minco`] (the
//!   original fixed-terminal MINCO, the baseline of Table Sim-A-2), and their objectives as functions
//!   of the decision vector ([`UtfMincoObjective`], [`MincoObjective`]).
//! - [`scenes`]: the deterministic E2 scenes of the tests, benches and `examples/e2_compare.rs`.
//!
//! Use a backend through the trait (the manager does); use [`MincoS3`] inside your own optimizer's
//! cost evaluation (preallocated, allocation-free), or the free functions ([`jerk_energy`],
//! [`eval_piece`], [`BandedMatrix`]) on their own.
//!
//! Beyond the paper (each documented where it lives): UTF-MINCO also penalizes the obstacles along
//! the braking manoeuvre after a terminal reached in motion ([`costs::PenaltyIntegrand`]), jerk above
//! a limit when the presets ask for it, and raises the terminal pull near the goal
//! ([`costs::final_approach_gain`]). The objective skips integration nodes that provably carry no
//! penalty (bit-identical to evaluating every node) and is solved with the split cost/gradient
//! L-BFGS. Why our own banded LU, and what the evaluation-cost work measured and rejected:
//! `docs/decisions/0001` and `0011`; benchmarks: `cargo bench -p trust-minco`.
//!
//! ```
//! use trust_core::{InitialGuess, TrajRequest, TrajectoryBackend};
//! use trust_minco::{UtfMinco, scenes::e2_dynamic};
//!
//! let case = e2_dynamic();
//! let guide = case.guide();
//! let req = TrajRequest {
//!     start: case.start,
//!     goal: case.goal,
//!     limits: case.limits,
//!     initial: InitialGuess::Guide(&guide),
//!     deadline: None,
//!     horizon_s: None,
//!     max_evaluations: None,
//! };
//! let scene = case.scene();
//! let solution = UtfMinco::default().optimize(&req, &scene)?;
//! // Clear of the moving obstacles at every sampled time.
//! solution.traj.for_each_sample(0.01, |t, s| assert!(scene.clearance(&s.p, t) >= 0.0))?;
//! # Ok::<(), trust_core::PlanError>(())
//! ```
#![warn(missing_docs)]

pub mod backend;
pub mod banded;
pub mod costs;
pub mod error;
pub mod minco;

/// The deterministic and random E2 scenes (`trust-scenes`, re-exported: the tests, benches and
/// `examples/e2_compare.rs` fly them).
pub mod scenes {
    pub use trust_scenes::e2::*;
}

pub use backend::{
    Minco, MincoObjective, MincoParams, PieceParams, SolverParams, UtfMinco, UtfMincoObjective,
    UtfMincoParams,
};
pub use banded::{BandRhs, BandedMatrix};
pub use costs::{CostWeights, PenaltyParams};
pub use error::MincoError;
pub use minco::{
    BoundaryState, MincoGrad, MincoS3, PieceDerivatives, accumulate_jerk_energy_grad,
    basis_derivatives, eval_json, eval_piece, jerk_energy, piece_jerk, piece_jerk_energy,
};
