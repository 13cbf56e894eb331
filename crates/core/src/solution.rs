//! What a [`crate::TrajectoryBackend`] returns: the trajectory, its cost breakdown and solve statistics.

use std::time::Duration;

use serde::{Deserialize, Serialize};

use crate::{PolyTraj, Violation};

/// The unweighted cost terms of paper eq. design-of-J and the weighted objective the backend minimized.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct CostBreakdown {
    /// Flight duration `H_t = T_Σ` (s).
    pub ht: f64,
    /// Heuristic terminal cost `H_s` (paper eq. design-of-Hs).
    pub hs: f64,
    /// Obstacle penalty `I_o` (dynamic distance field plus static map; eq. design-of-Io).
    pub io: f64,
    /// Dynamic feasibility penalty `I_d` (speed and acceleration; eq. design-of-Id).
    pub id: f64,
    /// Control effort `I_e = ∫‖jerk‖²` (eq. design-of-Ie).
    pub ie: f64,
    /// The weighted objective `J = λ · [H_t, H_s, I_o, I_d, I_e]` that the backend minimized.
    pub total: f64,
}

impl CostBreakdown {
    /// The branch-ranking cost of Algorithm 1: `J = λ_t·H_t + λ_s·H_s + λ_e·I_e`.
    pub fn ranking_cost(&self, w: &RankingWeights) -> f64 {
        w.lambda_t * self.ht + w.lambda_s * self.hs + w.lambda_e * self.ie
    }
}

/// Weights of the branch-ranking cost `J = λ_t·H_t + λ_s·H_s + λ_e·I_e` (paper Sec. III-A).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RankingWeights {
    /// λ_t.
    pub lambda_t: f64,
    /// λ_s.
    pub lambda_s: f64,
    /// λ_e.
    pub lambda_e: f64,
}

impl Default for RankingWeights {
    /// Paper Sec. IV-C (Table Sim-B-1): `λ_t = 1`, `λ_s = 1/v_max` with `v_max = 10 m/s`, `λ_e = 1e-4`.
    fn default() -> Self {
        RankingWeights {
            lambda_t: 1.0,
            lambda_s: 0.1,
            lambda_e: 1e-4,
        }
    }
}

/// How an optimization ended. Not converging is a status, not an error.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[non_exhaustive]
pub enum SolveStatus {
    /// The gradient test passed.
    Converged,
    /// The cost stopped decreasing (relative decrease over the last few iterations below tolerance).
    Stalled,
    /// The iteration budget ran out.
    IterationLimit,
    /// The evaluation budget ran out.
    EvaluationLimit,
    /// The time budget or deadline ran out.
    TimeLimit,
    /// The line search failed; the best point seen was returned.
    LineSearchFailed,
}

impl SolveStatus {
    /// Whether the optimizer stopped at a (local) optimum rather than on a budget or failure.
    pub fn is_optimal(self) -> bool {
        matches!(self, SolveStatus::Converged | SolveStatus::Stalled)
    }
}

/// Statistics of one optimization.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SolveStats {
    /// Optimizer iterations.
    pub iteration_count: usize,
    /// Cost-and-gradient evaluations.
    pub evaluation_count: usize,
    /// Wall-clock time of the whole `optimize` call (monotonic clock).
    pub elapsed: Duration,
    /// How it ended.
    pub status: SolveStatus,
}

/// The result of [`crate::TrajectoryBackend::optimize`].
///
/// `Ok(Solution)` means the backend ran on valid input and returns a finite trajectory from the
/// request's start; it does **not** mean the trajectory is safe or feasible. What it violates is
/// in [`Solution::violations`] (see the [contract](crate#the-backend-contract)).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Solution {
    /// The optimized trajectory (starts at the request's start state).
    pub traj: PolyTraj,
    /// Cost breakdown at the returned trajectory.
    pub costs: CostBreakdown,
    /// Solve statistics.
    pub stats: SolveStats,
    /// What the trajectory violates, from [`crate::verify_trajectory`] on the request's scene
    /// and limits: empty when it keeps out of every obstacle and inside the bounds and limits at
    /// every checked instant. (Added in issue 18; absent in older serialized solutions, which
    /// deserialize with an empty list.)
    #[serde(default)]
    pub violations: Vec<Violation>,
}

impl Solution {
    /// True if the post-solve verification found nothing: no penetration, inside the bounds,
    /// within the limits at every checked instant.
    pub fn is_clean(&self) -> bool {
        self.violations.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn ranking_cost_uses_only_ht_hs_ie() {
        let c = CostBreakdown {
            ht: 4.39,
            hs: 25.26,
            io: 1e9,
            id: 1e9,
            ie: 1.29e3,
            total: 0.0,
        };
        // Paper Table Sim-B-1, row τ0: J = 7.04.
        assert_relative_eq!(
            c.ranking_cost(&RankingWeights::default()),
            7.04,
            epsilon = 0.01
        );
    }
}
