//! Cost evaluation with a budget, and the Lewis–Overton weak-Wolfe line search.

use crate::vector::{all_finite, dot, step_from};
use crate::{LbfgsParams, LineSearchFailure, Termination};

/// LBFGS-Lite's `machine_prec`: the line search gives up once the bracket `[lower, upper]` is
/// narrower than this fraction of `upper`.
const BRACKET_RELATIVE_WIDTH: f64 = 1e-16;

/// How the solver gets costs and gradients: either both at once from a fused function
/// ([`Fused`]) or the gradient on demand after the cost ([`Split`]).
pub(crate) trait Evaluate {
    /// The cost at `x`, exact if it is `<= bound`, otherwise any value `> bound` (see
    /// [`SplitObjective::cost`]). A fused evaluation is always exact and also writes the gradient
    /// into `g` (zero-filled first); a split one leaves `g` alone.
    fn cost(&mut self, x: &[f64], g: &mut [f64], bound: f64) -> f64;

    /// Makes `g` hold the gradient at the point of the last [`Evaluate::cost`] call (a no-op for
    /// a fused evaluation, which wrote it already).
    fn gradient(&mut self, g: &mut [f64]);
}

/// A fused `FnMut(&[f64], &mut [f64]) -> f64` cost-and-gradient function.
pub(crate) struct Fused<F>(pub(crate) F);

impl<F> Evaluate for Fused<F>
where
    F: FnMut(&[f64], &mut [f64]) -> f64,
{
    #[inline]
    fn cost(&mut self, x: &[f64], g: &mut [f64], _bound: f64) -> f64 {
        g.fill(0.0);
        (self.0)(x, g)
    }

    #[inline]
    fn gradient(&mut self, _g: &mut [f64]) {}
}

/// A [`SplitObjective`]: the gradient is computed only when the solver needs it.
pub(crate) struct Split<'a, O: ?Sized>(pub(crate) &'a mut O);

impl<O> Evaluate for Split<'_, O>
where
    O: SplitObjective + ?Sized,
{
    #[inline]
    fn cost(&mut self, x: &[f64], _g: &mut [f64], bound: f64) -> f64 {
        self.0.cost(x, bound)
    }

    #[inline]
    fn gradient(&mut self, g: &mut [f64]) {
        g.fill(0.0);
        self.0.gradient(g);
    }
}

/// An objective whose gradient can be computed after its cost, for
/// [`crate::Lbfgs::minimize_split`]: the line search then asks for the gradient only at trial
/// points that pass the sufficient-decrease (Armijo) test or improve on the best point seen,
/// which saves the gradient work of every rejected trial.
pub trait SplitObjective {
    /// The cost at `x`. A NaN or infinite cost counts as "too far" (the step shrinks).
    ///
    /// `bound` says how much the solver needs: the exact cost if it is `<= bound`; otherwise
    /// only that it exceeds `bound`, so an objective that is a sum of non-negative terms may stop
    /// summing and return any value `> bound` (and need not be able to give the gradient there,
    /// which the solver will not ask for). `bound` is `+∞` where the exact cost is needed (the
    /// start point); in a line search it is the larger of the sufficient-decrease threshold and
    /// the best cost seen. Returning the exact cost always is correct.
    fn cost(&mut self, x: &[f64], bound: f64) -> f64;

    /// Writes the gradient at the point of the **last** [`SplitObjective::cost`] call into `g`,
    /// which is zero-filled before the call (so terms may be accumulated with `+=`).
    fn gradient(&mut self, g: &mut [f64]);
}

/// Wraps an [`Evaluate`]: counts cost evaluations and enforces the evaluation budget.
pub(crate) struct Evaluator<E> {
    eval: E,
    count: usize,
    /// Maximum number of calls; 0 means unlimited.
    limit: usize,
}

impl<E: Evaluate> Evaluator<E> {
    pub(crate) fn new(eval: E, limit: usize) -> Self {
        Self {
            eval,
            count: 0,
            limit,
        }
    }

    /// Number of cost evaluations so far.
    pub(crate) fn count(&self) -> usize {
        self.count
    }

    /// True if the budget allows no further call.
    pub(crate) fn exhausted(&self) -> bool {
        self.limit != 0 && self.count >= self.limit
    }

    /// Evaluates the cost and the gradient at `x`, writing the gradient into `g`.
    pub(crate) fn evaluate(&mut self, x: &[f64], g: &mut [f64]) -> f64 {
        let cost = self.cost(x, g, f64::INFINITY);
        self.eval.gradient(g);
        cost
    }

    /// Evaluates the cost at `x` (exact up to `bound`, see [`SplitObjective::cost`]); call
    /// [`Evaluator::gradient`] before reading `g`.
    pub(crate) fn cost(&mut self, x: &[f64], g: &mut [f64], bound: f64) -> f64 {
        self.count += 1;
        self.eval.cost(x, g, bound)
    }

    /// Makes `g` hold the gradient at the point of the last [`Evaluator::cost`] call.
    pub(crate) fn gradient(&mut self, g: &mut [f64]) {
        self.eval.gradient(g);
    }
}

/// Where a line search starts: the current iterate, its cost and gradient, and the direction.
pub(crate) struct SearchStart<'a> {
    pub(crate) x: &'a [f64],
    pub(crate) cost: f64,
    pub(crate) gradient: &'a [f64],
    pub(crate) direction: &'a [f64],
}

/// Scratch space holding the best trial point of the current line search.
#[derive(Debug, Clone)]
pub(crate) struct BestPoint {
    x: Vec<f64>,
    gradient: Vec<f64>,
}

impl BestPoint {
    pub(crate) fn new(dimension: usize) -> Self {
        Self {
            x: vec![0.0; dimension],
            gradient: vec![0.0; dimension],
        }
    }
}

/// The result of one line search. In both cases the caller's `x` and `g` hold the returned point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum SearchOutcome {
    /// A step meeting both weak-Wolfe conditions.
    Accepted { step: f64, cost: f64 },
    /// No acceptable step: `x`, `g` were restored to the lowest-cost point seen (the start or a
    /// trial point) and `cost` is its (finite) cost.
    Stopped { cost: f64, termination: Termination },
}

/// Lewis–Overton weak-Wolfe line search along `start.direction`, as in LBFGS-Lite's
/// `line_search_lewisoverton`, with two changes: a trial point whose cost or gradient is not finite
/// counts as an Armijo failure (the step shrinks) instead of aborting, and on failure the best
/// point seen is restored together with its own cost.
///
/// Trial `t`: `x = x₀ + t·d`. If `f(x) > f₀ + c₁·t·g₀ᵀd` (Armijo fails) `t` becomes the upper
/// bracket; else if `g(x)ᵀd < c₂·g₀ᵀd` (curvature fails) it becomes the lower bracket; else `t` is
/// accepted. The next trial is the bracket midpoint once an upper bracket exists, otherwise `2t`;
/// trials stay within `[min_step, max_step]` (`max_step` itself may be tried once).
///
/// `start.direction` must be a descent direction (`g₀ᵀd < 0`); `x` and `g` receive the trials.
pub(crate) fn lewis_overton<E: Evaluate>(
    evaluator: &mut Evaluator<E>,
    start: &SearchStart<'_>,
    initial_step: f64,
    params: &LbfgsParams,
    x: &mut [f64],
    g: &mut [f64],
    best: &mut BestPoint,
) -> SearchOutcome {
    let slope0 = dot(start.gradient, start.direction);
    debug_assert!(slope0 < 0.0, "line search needs a descent direction");
    let armijo_slope = params.f_dec_coeff * slope0;
    let curvature_slope = params.s_curv_coeff * slope0;

    let mut best_cost = start.cost;
    let mut best_is_trial = false;
    let mut lower = 0.0;
    let mut upper = params.max_step;
    let mut bracketed = false;
    let mut tried_max_step = false;
    let mut step = initial_step.clamp(params.min_step, params.max_step);
    let mut trials = 0;

    let failure = loop {
        if evaluator.exhausted() {
            break Termination::MaxEvaluations;
        }
        step_from(start.x, step, start.direction, x);
        // The exact cost and the gradient matter only if the trial may be accepted or become the
        // best point; a split evaluation may stop early above this bound and computes the
        // gradient only when needed (the decisions are the same either way).
        let armijo_bound = start.cost + step * armijo_slope;
        let cost = evaluator.cost(x, g, armijo_bound.max(best_cost));
        trials += 1;

        let armijo = cost <= armijo_bound;
        let finite = if cost.is_finite() && (armijo || cost < best_cost) {
            evaluator.gradient(g);
            all_finite(g)
        } else {
            false
        };
        if finite && cost < best_cost {
            best_cost = cost;
            best_is_trial = true;
            best.x.copy_from_slice(x);
            best.gradient.copy_from_slice(g);
        }
        if !finite || !armijo {
            upper = step;
            bracketed = true;
        } else if dot(g, start.direction) < curvature_slope {
            lower = step;
        } else {
            return SearchOutcome::Accepted { step, cost };
        }

        if trials >= params.max_linesearch {
            break Termination::LineSearchFailed(LineSearchFailure::TrialLimit);
        }
        if bracketed && upper - lower < BRACKET_RELATIVE_WIDTH * upper {
            break Termination::LineSearchFailed(LineSearchFailure::BracketCollapsed);
        }
        step = if bracketed {
            0.5 * (lower + upper)
        } else {
            2.0 * step
        };
        if step < params.min_step {
            break Termination::LineSearchFailed(LineSearchFailure::StepBelowMin);
        }
        if step > params.max_step {
            if tried_max_step {
                break Termination::LineSearchFailed(LineSearchFailure::StepAboveMax);
            }
            tried_max_step = true;
            step = params.max_step;
        }
    };

    if best_is_trial {
        x.copy_from_slice(&best.x);
        g.copy_from_slice(&best.gradient);
    } else {
        x.copy_from_slice(start.x);
        g.copy_from_slice(start.gradient);
    }
    SearchOutcome::Stopped {
        cost: best_cost,
        termination: failure,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs a 1-D line search from x₀ = 0 along d = 1 on `f`.
    fn search_1d(
        f: impl FnMut(&[f64], &mut [f64]) -> f64,
        params: &LbfgsParams,
        initial_step: f64,
    ) -> (SearchOutcome, f64, usize) {
        let mut evaluator = Evaluator::new(Fused(f), params.max_evaluations);
        let mut g0 = [0.0];
        let f0 = evaluator.evaluate(&[0.0], &mut g0);
        let start = SearchStart {
            x: &[0.0],
            cost: f0,
            gradient: &g0,
            direction: &[1.0],
        };
        let (mut x, mut g) = ([0.0], [0.0]);
        let mut best = BestPoint::new(1);
        let outcome = lewis_overton(
            &mut evaluator,
            &start,
            initial_step,
            params,
            &mut x,
            &mut g,
            &mut best,
        );
        (outcome, x[0], evaluator.count())
    }

    fn parabola(x: &[f64], g: &mut [f64]) -> f64 {
        g[0] = 2.0 * (x[0] - 1.0);
        (x[0] - 1.0).powi(2)
    }

    #[test]
    fn unit_step_on_parabola_is_accepted_at_once() {
        let (outcome, x, count) = search_1d(parabola, &LbfgsParams::default(), 1.0);
        assert_eq!(
            outcome,
            SearchOutcome::Accepted {
                step: 1.0,
                cost: 0.0
            }
        );
        assert_eq!((x, count), (1.0, 2));
    }

    #[test]
    fn short_step_doubles_until_curvature_holds() {
        // g₀ᵀd = −2, so curvature needs g(t) = 2(t − 1) >= 0.9·(−2), i.e. t >= 0.1: steps 1/64,
        // 1/32, 1/16 become lower brackets, 1/8 is accepted.
        let (outcome, x, count) = search_1d(parabola, &LbfgsParams::default(), 1.0 / 64.0);
        assert_eq!(
            outcome,
            SearchOutcome::Accepted {
                step: 0.125,
                cost: 0.765625
            }
        );
        assert_eq!((x, count), (0.125, 5));
    }

    #[test]
    fn long_step_bisects_back() {
        // Armijo needs f(t) <= 1 − 2e-4·t. Step 4 (f = 9) and its midpoint 2 (f = 1) fail it;
        // the next midpoint, 1, is accepted.
        let (outcome, x, _) = search_1d(parabola, &LbfgsParams::default(), 4.0);
        assert_eq!(
            outcome,
            SearchOutcome::Accepted {
                step: 1.0,
                cost: 0.0
            }
        );
        assert_eq!(x, 1.0);
    }

    #[test]
    fn nan_beyond_a_wall_shrinks_the_step() {
        let f = |x: &[f64], g: &mut [f64]| if x[0] > 1.5 { f64::NAN } else { parabola(x, g) };
        let (outcome, x, _) = search_1d(f, &LbfgsParams::default(), 8.0);
        assert!(
            matches!(outcome, SearchOutcome::Accepted { .. }),
            "{outcome:?}"
        );
        assert!(x <= 1.5);
    }

    #[test]
    fn unbounded_direction_stops_at_max_step_with_best_point() {
        // f = −x decreases forever; max_step is tried once, then the search gives up.
        let params = LbfgsParams {
            max_step: 1e3,
            ..LbfgsParams::default()
        };
        let f = |x: &[f64], g: &mut [f64]| {
            g[0] = -1.0;
            -x[0]
        };
        let (outcome, x, _) = search_1d(f, &params, 1.0);
        assert_eq!(
            outcome,
            SearchOutcome::Stopped {
                cost: -1e3,
                termination: Termination::LineSearchFailed(LineSearchFailure::StepAboveMax),
            }
        );
        assert_eq!(x, 1e3);
    }

    #[test]
    fn all_nan_trials_restore_the_start() {
        let params = LbfgsParams {
            max_linesearch: 5,
            ..LbfgsParams::default()
        };
        let f = |x: &[f64], g: &mut [f64]| {
            if x[0] == 0.0 {
                parabola(x, g)
            } else {
                f64::NAN
            }
        };
        let (outcome, x, count) = search_1d(f, &params, 1.0);
        assert_eq!(
            outcome,
            SearchOutcome::Stopped {
                cost: 1.0,
                termination: Termination::LineSearchFailed(LineSearchFailure::TrialLimit),
            }
        );
        assert_eq!((x, count), (0.0, 6));
    }

    #[test]
    fn budget_stops_the_search_and_keeps_the_best_trial() {
        // One evaluation for the start, two trials (steps 1/64 and 1/32), then the budget is out.
        let params = LbfgsParams {
            max_evaluations: 3,
            ..LbfgsParams::default()
        };
        let (outcome, x, count) = search_1d(parabola, &params, 1.0 / 64.0);
        assert_eq!(count, 3);
        assert_eq!(x, 1.0 / 32.0);
        assert_eq!(
            outcome,
            SearchOutcome::Stopped {
                cost: (1.0f64 - 1.0 / 32.0).powi(2),
                termination: Termination::MaxEvaluations
            }
        );
    }

    #[test]
    fn gradient_is_zero_filled_before_each_call() {
        let mut evaluator = Evaluator::new(
            Fused(|x: &[f64], g: &mut [f64]| {
                g[0] += 2.0 * x[0];
                x[0] * x[0]
            }),
            0,
        );
        let mut g = [123.0];
        evaluator.evaluate(&[1.0], &mut g);
        assert_eq!(g, [2.0]);
        evaluator.evaluate(&[1.0], &mut g);
        assert_eq!(g, [2.0]);
        assert_eq!(evaluator.count(), 2);
    }
}
