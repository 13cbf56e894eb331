//! The outcome of a solve.

use serde::{Deserialize, Serialize};

/// Why a solve stopped. A value, not an error: every variant comes with a finite point and cost.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[non_exhaustive]
pub enum Termination {
    /// The gradient test held: `‖g‖∞ / max(1, ‖x‖∞) <= g_epsilon`.
    Converged,
    /// The cost-decrease test held: `|f_{k−past} − f_k| / max(1, |f_k|) <= delta`.
    CostStalled,
    /// `max_iterations` iterations were completed.
    MaxIterations,
    /// `max_evaluations` cost evaluations were spent; the best point seen is returned.
    MaxEvaluations,
    /// The [`crate::Monitor`] asked to stop.
    Cancelled,
    /// The line search found no acceptable step; the best point seen is returned.
    LineSearchFailed(LineSearchFailure),
}

impl Termination {
    /// True for [`Termination::Converged`] and [`Termination::CostStalled`], the two outcomes that
    /// mean "the solver believes it has reached a (local) minimum".
    pub fn is_success(self) -> bool {
        matches!(self, Self::Converged | Self::CostStalled)
    }
}

/// Why a line search failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[non_exhaustive]
pub enum LineSearchFailure {
    /// `max_linesearch` trial points were evaluated without meeting both weak-Wolfe conditions.
    TrialLimit,
    /// The next trial step fell below `min_step`.
    StepBelowMin,
    /// The step was doubled past `max_step` a second time (the cost decreases without bound along
    /// the search direction, as far as the solver may look).
    StepAboveMax,
    /// The bracket `[lower, upper]` shrank below floating-point resolution (usually: the cost is
    /// not differentiable, or rounding noise dominates the cost near the minimum).
    BracketCollapsed,
    /// The search direction was not a descent direction, even after falling back to steepest
    /// descent (the gradient is too small to form `−gᵀg < 0` in floating point).
    NotDescent,
}

/// The result of a solve. The solution itself is written into the caller's `x`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Report {
    /// Cost at the returned point (always finite).
    pub cost: f64,
    /// Number of completed iterations (accepted steps).
    pub iteration_count: usize,
    /// Number of cost evaluations, the one at the start point included.
    pub evaluation_count: usize,
    /// Why the solve stopped.
    pub termination: Termination,
    /// `‖g‖∞` at the returned point.
    pub grad_inf_norm: f64,
}
