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
//! - [`scenes`]: the deterministic E2 scenes used by the tests, the benchmarks
//!   and `examples/e2_compare.rs`.
//!
//! # Performance
//!
//! Criterion medians (`cargo bench -p trust-minco --bench backend -- --warm-up-time 2
//! --measurement-time 5`, release, this project's shared 2-core machine, SSE2 code generation).
//! The machine's speed drifts by up to about 1.4× from minute to minute, so "previous" and "now"
//! are the ranges of two interleaved runs of each build; the instruction counts (callgrind,
//! `--dump-instr=no`, one cold solve) do not drift:
//!
//! | benchmark | first version | previous | now | anchor / target |
//! |---|---|---|---|---|
//! | `whole_chain/16` (MINCO coefficients + energy + all gradients) | 3.0 µs | 3.0 µs | 3.0 µs | GCOPTER 4.4 µs |
//! | `cost_eval/representative_16x17_5spheres` | 21.5 µs | 14.2–16.1 µs | 15.6–16.9 µs | GCOPTER 17.2 µs |
//! | `cost_eval/representative_16x17_free` | 17.1 µs | 12.2–13.4 µs | 11.1–12.5 µs | — |
//! | `solve/utf_minco_e2_dynamic` (cold, from the guide) | 27.0 ms | 1.74–2.11 ms | **0.83–0.99 ms** | design ≤ 1 ms; paper 9.7 ms |
//! | `solve/utf_minco_e2_static` (cold) | 16.7 ms | 4.1–4.7 ms | 2.5–3.3 ms | paper 9.0 ms |
//! | `solve/minco_e2_dynamic` (cold) | 17.2 ms | 1.0–1.2 ms | 1.04–1.10 ms | paper 8.5 ms |
//! | `solve/utf_minco_e2_dynamic_warm` (re-solve 0.1 s later) | — | 0.18–0.22 ms | 0.08–0.10 ms | design ≤ 1 ms |
//! | `solve/utf_minco_e2_static_warm` | — | 0.24 ms | 0.16–0.21 ms | — |
//! | `solve/utf_minco_random_dynamic_x8` (8 cold solves) | — | 17.3–19.4 ms | 8.9–9.5 ms | — |
//! | `solve/utf_minco_random_static_x8` (8 cold solves) | — | 26.1–28.0 ms | 14.3–15.9 ms | — |
//! | instructions, one cold E2 dynamic / static solve | — | 24.0 M / 56.2 M | 11.2 M / 31.7 M | — |
//!
//! The last round changed only the work per evaluation, not the optimization: every iterate,
//! cost and result is the same bit for bit (`examples/e2_compare.rs`, before and after: E2
//! static 6.9546 s, `J` 154.096, 722 evaluations; E2 dynamic 7.7340 s, `J` 161.133, 356
//! evaluations; both collision-free, at the goal, within 0.03 % of the limits). Over 60 random
//! E2-like scenes of each kind (`e2_compare --random 60`, [`scenes::random_e2_static`],
//! [`scenes::random_e2_dynamic`]), identical before and after: static mean `J` 163.41, mean
//! duration 7.201 s, 526 evaluations; dynamic mean `J` 176.42, 8.310 s, 371 evaluations; 60/60
//! collision-free, 0 over a limit by more than 1 %, 60/60 within 0.5 m of the goal in both; median
//! CPU time per scene 2.9 → 1.8–2.1 ms (static) and 1.9 → 0.84–0.91 ms (dynamic).
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
//! - **Only the nodes that matter** (last round): the objective integrates its penalties through
//!   a fast path that skips, with conservative filters, every node where no penalty can be
//!   active — whole pieces whose velocity or acceleration Bézier control points are within the
//!   limits, nodes whose speed or acceleration (computed column by column) is below the limit,
//!   nodes farther than the clearance (plus 1 µm) from every obstacle the broad phase keeps — and
//!   evaluates the others exactly as the generic path does (tested equal bit for bit). The
//!   broad phase boxes each piece by its position's Bézier control points instead of its nodes.
//! - **Split solve** (last round): L-BFGS ([`trust_lbfgs::Lbfgs::minimize_split`]) asks for the
//!   gradient (MINCO's adjoint solve, the energy gradient) only at trial points the line search
//!   may accept, and for each trial's cost only up to its acceptance bound: the objective stops
//!   summing its non-negative terms (time and terminal, then energy, then the penalties piece by
//!   piece) once they exceed it. About half of all trials are rejected.
//! - **Warm starts** (the manager's case) converge in about 40–50 evaluations.
//!
//! Evaluations to converge, E2 (cold): UTF-MINCO 356 dynamic / 722 static (was: the 1000 cap in
//! both), MINCO 145 / 235. Tried and dropped: preconditioning L-BFGS with the jerk energy's
//! exact Hessian (Cholesky change of variables; 30–35 % fewer evaluations on static scenes, but
//! worse local minima among moving obstacles — mean `J` 199 vs 158 on random dynamic scenes), a
//! diagonal (Jacobi) scaling (≤ 10 % fewer evaluations), a smoothed initial guess (least-squares
//! energy smoothing of the waypoints plus a time-energy balance for `T_Σ`; no fewer evaluations),
//! a longer initial duration, a larger smoothing width `μ` (faster, but worse minima and speed
//! overshoot), and a branch-free smoothed max (slower). In the last round, measured on E2 and
//! the 60 + 60 random scenes (evaluations E2 static / dynamic, and what got worse):
//! - coarse-to-fine sampling (κ = 8 or 4, then κ = 16 warm-started from it): the coarse stage
//!   needs as many evaluations as the fine one (E2 dynamic 377 at κ = 8), the κ = 16 polish then
//!   120–170 more, and κ = 8 alone ends in collision on 21 of 60 static and 35 of 60 dynamic
//!   scenes; the two-stage mean `J` on dynamic scenes rose to 270 (one bad minimum); κ = 12
//!   alone: 32 of 200 dynamic scenes collide;
//! - stopping earlier once the cost decreases slowly: at the optimum the penalties are active at
//!   the 1e-8 level (limits and obstacles are touched), and the last 15 % of evaluations still
//!   lower `J` by 0.5 % (E2 dynamic: 162.0 after 300 evaluations, 161.13 after 356); a stall
//!   test of 2e-5: 653 / 355 evaluations but E2 static 6.985 s and random mean `J` + 0.4–0.6 %
//!   (200 scenes of each kind);
//! - cubic interpolation in the line search's bracket (prototyped in `trust-lbfgs`, removed):
//!   605 / 343 evaluations but E2 static 6.959 s, random dynamic mean `J` + 0.5 %;
//! - L-BFGS memory 40: 583 / 430 evaluations; 7 m pieces replaced by 6, 8 or 9 m: 760–550 /
//!   420–428 evaluations and mixed quality;
//! - rescaling `τ` or `v_f` in the decision vector (× 0.3 … × 10), a gentler initial speed
//!   profile (`a_max / 3`, `a_max / 5`) or a 1.2–1.3× initial duration: fewer static but more
//!   dynamic evaluations (407–615) and worse minima or collisions on random dynamic scenes;
//! - a tighter per-piece broad phase (Bézier control points of the offset from each obstacle's
//!   moving centre): no fewer candidates on these scenes, 8 % more instructions.
//!
//! What remains: the L-BFGS direction (two-loop recursion over 32 pairs, a latency-bound chain
//! of dot products) is now about 28 % of a dynamic E2 solve's instructions, MINCO's solve about
//! 16 % and the penalties about 33 %. Fewer evaluations would need a better-conditioned
//! formulation (the total duration first grows to about 12 s and then shrinks over some 300
//! evaluations); the attempts above changed the local minima among moving obstacles.
//!
//! Why our own banded LU and L-BFGS: MINCO's system has bandwidth 6. Measured on the reference
//! system for `n = 16` (96 × 96, 3 right-hand sides; `cargo bench -p trust-minco --bench minco --
//! library_lu`, criterion medians): faer's dense partial-pivoting LU, single-threaded, factorizes
//! and solves in 53 µs; our general [`BandedMatrix`] in 4.3 µs (including a copy of the matrix);
//! the structured elimination inside [`MincoS3`] builds *and* solves in about 1.1 µs
//! (`coefficients/16`). nalgebra has no banded solver. The L-BFGS (`trust-lbfgs`) is
//! allocation-free per iteration, returns the best finite point on failure (LBFGS-Lite returns
//! the last trial's possibly-NaN cost), and offers the split cost/gradient solve the backends
//! use; it has not been timed against another Rust L-BFGS.
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
//!
//! # Changelog
//!
//! - Issue 19: UTF-MINCO's terminal pull is raised near the goal by the final-approach gain
//!   ([`costs::final_approach_gain`], `PenaltyParams::goal_settle_m` = 0.02 m) so the free terminal
//!   settles within 2 cm of the goal at any `a_max`; the reported `H_s` is unchanged. The gain
//!   counts the jerk limit (`PenaltyParams::jerk_ramp_s`), and a guide's first guess from rest
//!   takes at least the jerk-limited rest-to-rest time
//!   (`InitialTrajectory::with_jerk_floor`): from rest just short of the goal the plan moves
//!   onto it (it stayed put up to 0.1 m short at a Crazyflie's limits, 0.4 m at E4's).
//! - `backend::guidance_radius(start, goal, horizon_s, &limits)` moved to
//!   `trust_core::guidance_radius(start, goal, horizon_s, v_max)`, shared with DEV-PRM's goal
//!   guidance surface; the Bernstein control points of the fused integration come from
//!   `trust_core::bernstein_points` (same values, bit for bit).
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
