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
//! # Performance
//!
//! Criterion medians (`cargo bench -p trust-minco`, release, this project's shared 2-core
//! machine, SSE2 code generation):
//!
//! | benchmark | before tuning | now | anchor / target |
//! |---|---|---|---|
//! | `whole_chain/16` (MINCO coefficients + energy + all gradients) | 3.0 µs | 3.0 µs | GCOPTER 4.4 µs |
//! | `cost_eval/representative_16x17_5spheres` | 21.5 µs | 16.8 µs | GCOPTER 17.2 µs |
//! | `cost_eval/representative_16x17_free` | 17.1 µs | 13.2 µs | — |
//! | `solve/utf_minco_e2_dynamic` (cold, from the guide) | 27.0 ms | 2.1 ms | design ≤ 1 ms; paper 9.7 ms |
//! | `solve/utf_minco_e2_static` (cold) | 16.7 ms | 4.9 ms | paper 9.0 ms |
//! | `solve/minco_e2_dynamic` (cold) | 17.2 ms | 1.2 ms | paper 8.5 ms |
//! | `solve/utf_minco_e2_dynamic_warm` (re-solve 0.1 s later) | — | 0.19 ms | design ≤ 1 ms |
//! | `solve/utf_minco_e2_static_warm` | — | 0.30 ms | — |
//!
//! What changed, and why (numbers from `examples/e2_compare.rs` and Monte Carlo runs over random
//! E2-like scenes, recorded at [`PieceParams`] and [`SolverParams`]):
//! - **Fewer, longer pieces** (7 m instead of 3 m, [`PieceParams::target_piece_length_m`]): the
//!   jerk energy's conditioning degrades steeply with the piece count, so about half the
//!   evaluations to converge, each about half as expensive, and better local minima among
//!   moving obstacles (E2 dynamic: 7.7 s to the goal in 356 evaluations instead of 8.3 s ending
//!   4 m short after the 1000-evaluation cap).
//! - **Stopping** at a relative cost decrease of 1e-5 over 3 iterations (10–15 % fewer
//!   evaluations, durations within 0.4 %).
//! - **Evaluation cost**: node values and `∂I/∂c` through per-piece moments over a table of node
//!   fractions ([`costs::TrapezoidIntegrator`]), no division per sample
//!   ([`costs::SmoothedL1`]), exact squared-distance rejection before every obstacle's signed
//!   distance, inlined closed forms.
//! - **Warm starts** (the manager's case) converge in about 40–50 evaluations.
//!
//! Evaluations to converge, E2 (cold): UTF-MINCO 356 dynamic / 722 static (was: the 1000 cap in
//! both), MINCO 145 / 235. Tried and dropped: preconditioning L-BFGS with the jerk energy's
//! exact Hessian (Cholesky change of variables; 30–35 % fewer evaluations on static scenes, but
//! worse local minima among moving obstacles — mean `J` 199 vs 158 on random dynamic scenes), a
//! diagonal (Jacobi) scaling (≤ 10 % fewer evaluations), a smoothed initial guess (least-squares
//! energy smoothing of the waypoints plus a time-energy balance for `T_Σ`; no fewer evaluations),
//! a longer initial duration, a larger smoothing width `μ` (faster, but worse minima and speed
//! overshoot), and a branch-free smoothed max (slower).
//!
//! Why our own banded LU and L-BFGS: MINCO's system has bandwidth 6, and the structured
//! elimination ([`MincoS3`]) does the whole MINCO chain for `n = 16` in 3.0 µs, below the C++
//! anchor, with no allocation; a general dense LU is `O(n³)`. The L-BFGS (`trust-lbfgs`) is
//! allocation-free per iteration, returns the best finite point on failure, and its direction
//! computation is about 14 % of a static E2 solve's instructions (callgrind: 8.8 M of 62.5 M).
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
