//! The L-BFGS driver: start checks, search directions, line searches, stopping tests.

use crate::error::first_non_finite;
use crate::line_search::{
    BestPoint, Evaluate, Evaluator, Fused, SearchOutcome, SearchStart, Split, SplitObjective,
    lewis_overton,
};
use crate::memory::CorrectionMemory;
use crate::vector::{all_finite, dot, inf_norm, negate_into, norm2};
use crate::{LbfgsError, LbfgsParams, LineSearchFailure, Monitor, Progress, Report, Termination};

/// An L-BFGS solver for one problem size, with every buffer allocated up front.
///
/// Build it once with [`Lbfgs::new`] and call [`Lbfgs::minimize`] as often as needed: a solve
/// allocates nothing. Each solve starts from an empty memory, so results do not depend on
/// earlier solves.
#[derive(Debug, Clone)]
pub struct Lbfgs {
    params: LbfgsParams,
    dimension: usize,
    memory: CorrectionMemory,
    /// Gradient at the current point (after a solve: at the returned point).
    g: Vec<f64>,
    /// Point and gradient at the start of the current line search.
    x_prev: Vec<f64>,
    g_prev: Vec<f64>,
    /// Search direction.
    d: Vec<f64>,
    best: BestPoint,
    /// `past_costs[k % past]` holds the cost after iteration `k` (index 0 starts with f₀).
    past_costs: Vec<f64>,
}

impl Lbfgs {
    /// A solver for `dimension` variables; validates `params` and allocates
    /// `(2·memory + 6)·dimension + 3·memory + past` floats.
    ///
    /// # Errors
    /// [`LbfgsError::InvalidParam`] for invalid `params`, [`LbfgsError::ZeroDimension`],
    /// [`LbfgsError::DimensionTooLarge`] above [`crate::MAX_DIMENSION`] variables, and
    /// [`LbfgsError::WorkspaceTooLarge`] when the buffers would exceed
    /// [`crate::MAX_WORKSPACE_FLOATS`] — checked before anything is allocated.
    pub fn new(dimension: usize, params: LbfgsParams) -> Result<Self, LbfgsError> {
        params.validate()?;
        check_workspace(dimension, &params)?;
        Ok(Self {
            memory: CorrectionMemory::new(dimension, params.memory),
            g: vec![0.0; dimension],
            x_prev: vec![0.0; dimension],
            g_prev: vec![0.0; dimension],
            d: vec![0.0; dimension],
            best: BestPoint::new(dimension),
            past_costs: vec![0.0; params.past],
            dimension,
            params,
        })
    }

    /// Number of variables.
    pub fn dimension(&self) -> usize {
        self.dimension
    }

    /// The (validated) parameters.
    pub fn params(&self) -> &LbfgsParams {
        &self.params
    }

    /// Gradient at the point returned by the last solve (zeros before the first solve).
    pub fn gradient(&self) -> &[f64] {
        &self.g
    }

    /// Minimizes `f` starting from `x`, leaving the solution in `x`.
    ///
    /// `f(x, g)` returns the cost at `x` and writes its gradient into `g`, which is zero-filled
    /// before every call (so terms may be accumulated with `+=`). A cost or gradient that is NaN or
    /// infinite at a trial point is treated as "too far" and the step shrinks.
    ///
    /// `monitor` is called once per iteration; pass `&mut ()` for none.
    ///
    /// Returns `Err` only for misuse: `x.len()` differs from [`Lbfgs::dimension`], `x` is not
    /// finite, or the cost or gradient at `x` is not finite. Otherwise the [`Report`] says why the
    /// solve stopped; in every case `x` holds the lowest-cost point the solver knows of, with
    /// `report.cost` its finite cost and [`Lbfgs::gradient`] its gradient.
    pub fn minimize<F>(
        &mut self,
        x: &mut [f64],
        f: F,
        monitor: &mut dyn Monitor,
    ) -> Result<Report, LbfgsError>
    where
        F: FnMut(&[f64], &mut [f64]) -> f64,
    {
        self.run(x, Fused(f), monitor)
    }

    /// [`Lbfgs::minimize`] for an objective that computes its gradient on demand after its cost
    /// ([`SplitObjective`]): the same iterates, costs, gradients and report as `minimize` with the
    /// fused function `|x, g| { let c = objective.cost(x, f64::INFINITY); objective.gradient(g);
    /// c }`, but the gradient is computed only at trial points that pass the sufficient-decrease
    /// test (or improve on the best point seen), and the cost of the other trials only as far as
    /// the objective needs to see that it exceeds the bound it is given. Worth it when the
    /// gradient is a large part of an evaluation and line searches often backtrack.
    ///
    /// # Errors
    /// As [`Lbfgs::minimize`].
    pub fn minimize_split<O>(
        &mut self,
        x: &mut [f64],
        objective: &mut O,
        monitor: &mut dyn Monitor,
    ) -> Result<Report, LbfgsError>
    where
        O: SplitObjective + ?Sized,
    {
        self.run(x, Split(objective), monitor)
    }

    /// The solve behind [`Lbfgs::minimize`] and [`Lbfgs::minimize_split`].
    fn run<E: Evaluate>(
        &mut self,
        x: &mut [f64],
        eval: E,
        monitor: &mut dyn Monitor,
    ) -> Result<Report, LbfgsError> {
        self.check_start(x)?;
        let mut evaluator = Evaluator::new(eval, self.params.max_evaluations);
        let start_cost = self.evaluate_start(x, &mut evaluator)?;
        let end = self.iterate(x, &mut evaluator, start_cost, monitor);
        Ok(Report {
            cost: end.cost,
            iteration_count: end.iteration_count,
            evaluation_count: evaluator.count(),
            termination: end.termination,
            grad_inf_norm: inf_norm(&self.g),
        })
    }

    /// Iterates from the evaluated start (`x`, `cost`, `self.g`) until a stopping test holds.
    /// On return `x` and `self.g` hold the final point.
    fn iterate<E: Evaluate>(
        &mut self,
        x: &mut [f64],
        evaluator: &mut Evaluator<E>,
        mut cost: f64,
        monitor: &mut dyn Monitor,
    ) -> End {
        self.memory.clear();
        if let Some(first) = self.past_costs.first_mut() {
            *first = cost;
        }
        let mut iteration_count = 0;
        let end = |cost, iteration_count, termination| End {
            cost,
            iteration_count,
            termination,
        };
        if self.gradient_converged(x) {
            return end(cost, iteration_count, Termination::Converged);
        }
        loop {
            if evaluator.exhausted() {
                return end(cost, iteration_count, Termination::MaxEvaluations);
            }
            let Some(initial_step) = self.search_direction() else {
                let not_descent = Termination::LineSearchFailed(LineSearchFailure::NotDescent);
                return end(cost, iteration_count, not_descent);
            };
            let step = match self.line_search(x, evaluator, cost, initial_step) {
                SearchOutcome::Accepted {
                    step,
                    cost: new_cost,
                } => {
                    cost = new_cost;
                    step
                }
                SearchOutcome::Stopped { cost, termination } => {
                    return end(cost, iteration_count, termination);
                }
            };
            iteration_count += 1;
            let cautious_factor = self.params.cautious_factor;
            self.memory
                .push_if_cautious(x, &self.x_prev, &self.g, &self.g_prev, cautious_factor);

            let keep_going = monitor.keep_going(&Progress {
                iteration: iteration_count,
                evaluation_count: evaluator.count(),
                cost,
                grad_inf_norm: inf_norm(&self.g),
                step,
                x,
                gradient: &self.g,
            });
            if let Some(termination) = self.stopping_test(x, iteration_count, cost, keep_going) {
                return end(cost, iteration_count, termination);
            }
        }
    }

    fn check_start(&self, x: &[f64]) -> Result<(), LbfgsError> {
        if x.len() != self.dimension {
            return Err(LbfgsError::DimensionMismatch {
                len: x.len(),
                expected: self.dimension,
            });
        }
        match first_non_finite(x) {
            Some((index, value)) => Err(LbfgsError::NonFiniteStart { index, value }),
            None => Ok(()),
        }
    }

    /// Evaluates the start point into `self.g`; its cost and gradient must be finite.
    fn evaluate_start<E: Evaluate>(
        &mut self,
        x: &[f64],
        evaluator: &mut Evaluator<E>,
    ) -> Result<f64, LbfgsError> {
        let cost = evaluator.evaluate(x, &mut self.g);
        if !cost.is_finite() {
            return Err(LbfgsError::NonFiniteStartCost { value: cost });
        }
        match first_non_finite(&self.g) {
            Some((index, value)) => Err(LbfgsError::NonFiniteStartGradient { index, value }),
            None => Ok(cost),
        }
    }

    /// Saves the current point as the line-search start and searches along `self.d`; `x` and
    /// `self.g` receive the accepted (or best) point.
    fn line_search<E: Evaluate>(
        &mut self,
        x: &mut [f64],
        evaluator: &mut Evaluator<E>,
        cost: f64,
        initial_step: f64,
    ) -> SearchOutcome {
        self.x_prev.copy_from_slice(x);
        self.g_prev.copy_from_slice(&self.g);
        let start = SearchStart {
            x: &self.x_prev,
            cost,
            gradient: &self.g_prev,
            direction: &self.d,
        };
        lewis_overton(
            evaluator,
            &start,
            initial_step,
            &self.params,
            x,
            &mut self.g,
            &mut self.best,
        )
    }

    /// The tests after an accepted step, in priority order: gradient, cost stall, cancellation,
    /// iteration budget. (The evaluation budget is checked before the next line search.)
    fn stopping_test(
        &mut self,
        x: &[f64],
        iteration_count: usize,
        cost: f64,
        keep_going: bool,
    ) -> Option<Termination> {
        let max_iterations = self.params.max_iterations;
        if self.gradient_converged(x) {
            Some(Termination::Converged)
        } else if self.cost_stalled(iteration_count, cost) {
            Some(Termination::CostStalled)
        } else if !keep_going {
            Some(Termination::Cancelled)
        } else if max_iterations != 0 && iteration_count >= max_iterations {
            Some(Termination::MaxIterations)
        } else {
            None
        }
    }

    /// The gradient test `‖g‖∞ / max(1, ‖x‖∞) <= g_epsilon`.
    fn gradient_converged(&self, x: &[f64]) -> bool {
        inf_norm(&self.g) <= self.params.g_epsilon * inf_norm(x).max(1.0)
    }

    /// The cost-decrease test `|f_{k−past} − f_k| / max(1, |f_k|) <= delta` after iteration `k`
    /// (never true before `past` iterations); also records `f_k`.
    fn cost_stalled(&mut self, iteration: usize, cost: f64) -> bool {
        let past = self.params.past;
        if past == 0 {
            return false;
        }
        let slot = iteration % past;
        let stalled = iteration >= past
            && (self.past_costs[slot] - cost).abs() / cost.abs().max(1.0) <= self.params.delta;
        self.past_costs[slot] = cost;
        stalled
    }

    /// Writes the search direction `d = −H·g` and returns the first trial step: 1 with a
    /// non-empty memory, `1/‖g‖₂` for steepest descent. If the quasi-Newton direction is not a
    /// finite descent direction (rounding), the memory is dropped and steepest descent used.
    /// Returns `None` if even `−g` is not a descent direction in floating point.
    fn search_direction(&mut self) -> Option<f64> {
        negate_into(&self.g, &mut self.d);
        if !self.memory.is_empty() {
            self.memory.apply_inverse_hessian(&mut self.d);
            if is_descent(&self.d, &self.g) {
                return Some(1.0);
            }
            self.memory.clear();
            negate_into(&self.g, &mut self.d);
        }
        is_descent(&self.d, &self.g).then(|| 1.0 / norm2(&self.d))
    }
}

/// How an iteration loop ended; `x` and the solver's gradient hold the final point.
struct End {
    cost: f64,
    iteration_count: usize,
    termination: Termination,
}

/// True if `d` is finite and `gᵀd < 0`.
fn is_descent(d: &[f64], g: &[f64]) -> bool {
    let slope = dot(g, d);
    slope < 0.0 && slope.is_finite() && all_finite(d)
}

/// Checks `dimension` against [`crate::MAX_DIMENSION`] and the workspace of a solver for it
/// against [`crate::MAX_WORKSPACE_FLOATS`] (`params` already validated).
fn check_workspace(dimension: usize, params: &LbfgsParams) -> Result<(), LbfgsError> {
    if dimension == 0 {
        return Err(LbfgsError::ZeroDimension);
    }
    if dimension > crate::MAX_DIMENSION {
        return Err(LbfgsError::DimensionTooLarge {
            dimension,
            cap: crate::MAX_DIMENSION,
        });
    }
    // In f64: exact for these magnitudes (memory ≤ 1024, past ≤ 65 536, dimension ≤ 1e6).
    let (n, m) = (dimension as f64, params.memory as f64);
    let floats = (2.0 * m + 6.0) * n + 3.0 * m + params.past as f64;
    if floats > crate::MAX_WORKSPACE_FLOATS as f64 {
        return Err(LbfgsError::WorkspaceTooLarge {
            dimension,
            memory: params.memory,
            past: params.past,
            floats,
            cap: crate::MAX_WORKSPACE_FLOATS,
        });
    }
    Ok(())
}

/// Minimizes `f` from `x` with `params`, leaving the solution in `x`: a one-shot
/// [`Lbfgs::new`] + [`Lbfgs::minimize`] without a monitor. Allocates the solver's buffers; reuse an
/// [`Lbfgs`] instead when solving many problems of the same size.
pub fn minimize<F>(x: &mut [f64], f: F, params: &LbfgsParams) -> Result<Report, LbfgsError>
where
    F: FnMut(&[f64], &mut [f64]) -> f64,
{
    Lbfgs::new(x.len(), params.clone())?.minimize(x, f, &mut ())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cost_stall_compares_with_the_cost_past_iterations_ago() {
        let params = LbfgsParams {
            past: 3,
            delta: 1e-3,
            ..LbfgsParams::default()
        };
        let mut solver = Lbfgs::new(1, params).unwrap();
        solver.past_costs[0] = 10.0; // f₀
        // f₁..f₃ decrease fast: f₃ vs f₀ is a big change.
        assert!(!solver.cost_stalled(1, 5.0));
        assert!(!solver.cost_stalled(2, 4.0));
        assert!(!solver.cost_stalled(3, 3.0));
        // f₄ vs f₁ = 5: big change. f₅ vs f₂ = 4: big change.
        assert!(!solver.cost_stalled(4, 3.0));
        assert!(!solver.cost_stalled(5, 3.0));
        // f₆ vs f₃ = 3: relative change 0.5e-3 / 3 <= 1e-3.
        assert!(solver.cost_stalled(6, 3.0 - 0.5e-3));
    }

    #[test]
    fn cost_stall_is_disabled_by_past_zero() {
        let params = LbfgsParams {
            past: 0,
            ..LbfgsParams::default()
        };
        let mut solver = Lbfgs::new(1, params).unwrap();
        for k in 1..10 {
            assert!(!solver.cost_stalled(k, 1.0));
        }
    }

    #[test]
    fn first_direction_is_steepest_descent_with_step_one_over_gradient_norm() {
        let mut solver = Lbfgs::new(2, LbfgsParams::default()).unwrap();
        solver.g.copy_from_slice(&[3.0, -4.0]);
        assert_eq!(solver.search_direction(), Some(0.2));
        assert_eq!(solver.d, [-3.0, 4.0]);
    }

    #[test]
    fn direction_with_memory_starts_with_unit_step() {
        let mut solver = Lbfgs::new(2, LbfgsParams::default()).unwrap();
        // One pair from f = x² + 2y² (Hessian diag(2, 4)).
        assert!(solver.memory.push_if_cautious(
            &[1.0, 1.0],
            &[0.0, 0.0],
            &[2.0, 4.0],
            &[0.0, 0.0],
            1e-6
        ));
        solver.g.copy_from_slice(&[2.0, 4.0]);
        assert_eq!(solver.search_direction(), Some(1.0));
        // The secant equation H·y = s with y = g gives d = −s.
        approx::assert_relative_eq!(solver.d[0], -1.0, epsilon = 1e-12);
        approx::assert_relative_eq!(solver.d[1], -1.0, epsilon = 1e-12);
    }

    #[test]
    fn underflowing_gradient_is_not_a_descent_direction() {
        let mut solver = Lbfgs::new(1, LbfgsParams::default()).unwrap();
        solver.g[0] = 1e-200; // gᵀg underflows to 0
        assert_eq!(solver.search_direction(), None);
        assert!(!is_descent(&[f64::NAN], &[1.0]));
        assert!(!is_descent(&[1.0], &[1.0]));
        assert!(is_descent(&[-1.0], &[1.0]));
    }

    #[test]
    fn zero_gradient_tolerance_stops_only_at_exact_zero() {
        let params = LbfgsParams {
            g_epsilon: 0.0,
            ..LbfgsParams::default()
        };
        let mut solver = Lbfgs::new(1, params).unwrap();
        let mut x = [2.0];
        let report = solver
            .minimize(
                &mut x,
                |x: &[f64], g: &mut [f64]| {
                    g[0] = 2.0 * (x[0] - 2.0);
                    (x[0] - 2.0).powi(2)
                },
                &mut (),
            )
            .unwrap();
        assert_eq!(report.termination, Termination::Converged);
        assert_eq!(report.evaluation_count, 1);
    }
}
