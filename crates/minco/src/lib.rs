//! trust-minco: MINCO trajectories (paper Sec. III-D) for TRUST-Planner.
//!
//! - [`banded`]: banded LU without pivoting and the plain/transposed solves, the O(n) kernel of
//!   MINCO's `C = A⁻¹(T) D` and of the adjoint `A⁻ᵀ ∂I/∂C` (eq. analytical-gradients-I-to-S).
//! - [`minco`]: MINCO with s = 3 (minimum jerk, quintic pieces) — coefficients from head/tail
//!   states, waypoints and durations; the jerk energy (eq. design-of-Ie); propagation of any cost's
//!   gradient to waypoints, durations and the head/tail states (eq. analytical-gradients).
//!
//! Use [`MincoS3`] inside an optimizer's cost evaluation (preallocated, allocation-free), or the
//! free functions ([`jerk_energy`], [`eval_piece`], [`BandedMatrix`]) on their own.
//!
//! # Cost terms and backends
//!
//! - [`costs`]: the terms of the objective `J = λ · [H_t, H_s, I_o, I_d, I_e]` (eq. design-of-J),
//!   each with value and gradient — flight time, the heuristic terminal cost (eq. design-of-Hs),
//!   the moving-obstacle penalty through the dynamic distance field (eqs. design-of-Io,
//!   gradients-of-Io), a static-map penalty, the speed/acceleration penalty (eq. design-of-Id) —
//!   and the trapezoidal integrator (eq. trapezoidal-integration) with the gradients of eqs.
//!   dI-a/b/c, including the time coupling of moving obstacles into every earlier duration.
//! - [`backend`]: [`UtfMinco`] (the paper's uniform-time, terminal-free MINCO) and [`Minco`] (the
//!   original fixed-terminal MINCO, the baseline of Table Sim-A-2), both
//!   [`trust_core::TrajectoryBackend`]s solved with `trust-lbfgs`, and their objectives as
//!   functions of the decision vector ([`UtfMincoObjective`], [`MincoObjective`]).
//! - [`scenes`]: the deterministic E2 scenes (design.md §5) used by the tests, the benchmarks
//!   and `examples/e2_compare.rs`.
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
pub mod scenes;

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
