//! A lean L-BFGS minimizer with the Lewis–Overton weak-Wolfe line search, following the semantics
//! and defaults of LBFGS-Lite (Zhepei Wang's header-only library used by GCOPTER).
//!
//! TRUST-Planner transcribes trajectory planning into an unconstrained problem over waypoints and
//! durations (paper §III-D, eq. "unconstrained optimization") and solves it with L-BFGS
//! (Liu and Nocedal, 1989). This crate is that solver; it depends on none of the planner's crates
//! and can be used on its own for any smooth (or mildly nonsmooth) unconstrained problem whose cost
//! and gradient come from one fused function `FnMut(&[f64], &mut [f64]) -> f64`.
//!
//! What it does, per iteration:
//! - direction `d = −H·g` from the two-loop recursion over the last `memory` correction pairs,
//!   with cautious updates (a pair is stored only if `yᵀs > ε·‖s‖²·‖g_prev‖`);
//! - first trial step `1/‖g‖₂` for a steepest-descent direction, 1 otherwise;
//! - Lewis–Overton line search: bisection once bracketed, doubling before, steps within
//!   `[min_step, max_step]`; a NaN or infinite cost or gradient at a trial point shrinks the step;
//! - stops on the relative gradient test, on relative cost decrease over `past` iterations, on
//!   iteration or evaluation budgets, or when a [`Monitor`] cancels.
//!
//! For an objective whose gradient is much more expensive than its cost, [`Lbfgs::minimize_split`]
//! takes a [`SplitObjective`] (cost, then gradient on demand) and runs the very same iterations,
//! computing the gradient only at trial points the line search may accept and telling the cost a
//! bound above which it may stop summing (a rejected trial needs no exact cost).
//!
//! Failing to converge is a [`Termination`] value in the [`Report`], never an `Err`; on any
//! failure the best point seen is returned with its own finite cost (LBFGS-Lite returns the last
//! trial's cost, which can be NaN). `Err(`[`LbfgsError`]`)` means misuse: invalid parameters, a
//! wrong-length or non-finite start, or a non-finite cost or gradient at the start.
//!
//! Differences from LBFGS-Lite, all deliberate: non-finite trial values shrink the step instead of
//! aborting; a pair rejected by the cautious test leaves the memory as it is (LBFGS-Lite falls back
//! to steepest descent for that iteration); the stopping tests use `<=` so that a zero tolerance
//! means "exactly"; there is an evaluation budget; the gradient buffer is zero-filled before each
//! call.
//!
//! # Example
//!
//! ```
//! use trust_lbfgs::{Lbfgs, LbfgsParams, Termination};
//!
//! // f(x, y) = (x − 1)² + 10·(y + 2)², cost and gradient in one function.
//! let f = |x: &[f64], g: &mut [f64]| {
//!     g[0] = 2.0 * (x[0] - 1.0);
//!     g[1] = 20.0 * (x[1] + 2.0);
//!     (x[0] - 1.0).powi(2) + 10.0 * (x[1] + 2.0).powi(2)
//! };
//!
//! let mut solver = Lbfgs::new(2, LbfgsParams::default())?;
//! let mut x = [5.0, 5.0];
//! let report = solver.minimize(&mut x, f, &mut ())?;
//!
//! assert_eq!(report.termination, Termination::Converged);
//! assert!((x[0] - 1.0).abs() < 1e-5 && (x[1] + 2.0).abs() < 1e-5);
//! assert!(report.cost < 1e-9);
//! # Ok::<(), trust_lbfgs::LbfgsError>(())
//! ```
#![warn(missing_docs)]

mod error;
mod line_search;
mod memory;
mod monitor;
mod params;
mod report;
mod solver;
pub mod test_functions;
mod vector;

pub use error::LbfgsError;
pub use line_search::SplitObjective;
pub use monitor::{Deadline, FnMonitor, Monitor, Progress, monitor_fn};
pub use params::{LbfgsParams, MAX_DIMENSION, MAX_MEMORY, MAX_PAST, MAX_WORKSPACE_FLOATS};
pub use report::{LineSearchFailure, Report, Termination};
pub use solver::{Lbfgs, minimize};
