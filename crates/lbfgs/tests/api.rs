//! Public-API tests of trust-lbfgs: convergence on standard problems, robustness to NaN and kinks,
//! budgets, monitors, typed errors and determinism.

use std::cell::Cell;
use std::time::{Duration, Instant};

use approx::assert_relative_eq;
use proptest::prelude::*;
use trust_lbfgs::test_functions::{rosenbrock, rosenbrock_start};
use trust_lbfgs::{
    Deadline, Lbfgs, LbfgsError, LbfgsParams, Progress, Report, SplitObjective, Termination,
    minimize, monitor_fn,
};

/// Parameters that stop only on a tight gradient test, for accuracy checks.
fn tight() -> LbfgsParams {
    LbfgsParams {
        g_epsilon: 1e-10,
        past: 0,
        ..LbfgsParams::default()
    }
}

/// Asserts the invariants every solve must keep: finite point, and a reported cost and gradient
/// that are those of the returned point.
fn assert_consistent(
    solver: &Lbfgs,
    x: &[f64],
    report: &Report,
    mut f: impl FnMut(&[f64], &mut [f64]) -> f64,
) {
    assert!(x.iter().all(|v| v.is_finite()), "non-finite x: {x:?}");
    assert!(report.cost.is_finite(), "non-finite cost: {report:?}");
    let mut g = vec![0.0; x.len()];
    let cost = f(x, &mut g);
    assert_eq!(
        cost.to_bits(),
        report.cost.to_bits(),
        "report.cost is not f(x)"
    );
    assert_eq!(g, solver.gradient(), "solver.gradient() is not g(x)");
    let inf = g.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert_eq!(inf, report.grad_inf_norm);
}

fn solve(
    x: &mut [f64],
    params: LbfgsParams,
    f: impl FnMut(&[f64], &mut [f64]) -> f64 + Copy,
) -> (Lbfgs, Report) {
    let mut solver = Lbfgs::new(x.len(), params).expect("valid params");
    let report = solver.minimize(x, f, &mut ()).expect("valid start");
    assert_consistent(&solver, x, &report, f);
    (solver, report)
}

// ---------------------------------------------------------------------------------------------
// Convergence

#[test]
fn rosenbrock_2d_default_params_reach_the_minimum_cost() {
    let mut x = rosenbrock_start(2);
    let (_, report) = solve(&mut x, LbfgsParams::default(), rosenbrock);
    assert!(report.termination.is_success(), "{report:?}");
    assert!(report.cost < 1e-6, "{report:?}");
}

#[test]
fn rosenbrock_2d_tight_params_reach_the_minimizer() {
    let mut x = rosenbrock_start(2);
    let (_, report) = solve(&mut x, tight(), rosenbrock);
    assert_eq!(report.termination, Termination::Converged, "{report:?}");
    for xi in &x {
        assert!((xi - 1.0).abs() < 1e-6, "{x:?}");
    }
}

#[test]
fn rosenbrock_high_dimensional_reaches_the_minimizer() {
    for n in [10, 30, 100] {
        let mut x = rosenbrock_start(n);
        let (_, report) = solve(&mut x, LbfgsParams::default(), rosenbrock);
        assert!(report.termination.is_success(), "n = {n}: {report:?}");
        assert!(report.cost < 1e-6, "n = {n}: {report:?}");

        let mut x = rosenbrock_start(n);
        let (_, report) = solve(&mut x, tight(), rosenbrock);
        assert_eq!(
            report.termination,
            Termination::Converged,
            "n = {n}: {report:?}"
        );
        let worst = x.iter().fold(0.0f64, |m, xi| m.max((xi - 1.0).abs()));
        assert!(worst < 1e-6, "n = {n}: max |x − 1| = {worst}");
    }
}

#[test]
fn one_dimensional_problem() {
    let f = |x: &[f64], g: &mut [f64]| {
        g[0] = 4.0 * (x[0] - 3.0).powi(3) + 2.0 * (x[0] - 3.0);
        (x[0] - 3.0).powi(4) + (x[0] - 3.0).powi(2)
    };
    let mut x = [-10.0];
    let (_, report) = solve(&mut x, tight(), f);
    assert_eq!(report.termination, Termination::Converged);
    assert_relative_eq!(x[0], 3.0, epsilon = 1e-9);
}

#[test]
fn start_at_the_optimum_converges_with_one_evaluation() {
    let calls = Cell::new(0);
    let f = |x: &[f64], g: &mut [f64]| {
        calls.set(calls.get() + 1);
        g[0] = 2.0 * (x[0] - 1.0);
        g[1] = 2.0 * (x[1] + 1.0);
        (x[0] - 1.0).powi(2) + (x[1] + 1.0).powi(2)
    };
    let mut x = [1.0, -1.0];
    let report = minimize(&mut x, f, &LbfgsParams::default()).unwrap();
    assert_eq!(
        report,
        Report {
            cost: 0.0,
            iteration_count: 0,
            evaluation_count: 1,
            termination: Termination::Converged,
            grad_inf_norm: 0.0,
        }
    );
    assert_eq!(calls.get(), 1);
    assert_eq!(x, [1.0, -1.0]);
}

/// A random SPD quadratic `½xᵀAx − bᵀx` with `A = BᵀB + 0.1·I`, `B` and `b` with entries in
/// [−1, 1]; returns `(A, b)` row-major.
fn spd_problem() -> impl Strategy<Value = (usize, Vec<f64>, Vec<f64>)> {
    (2usize..=20).prop_flat_map(|n| {
        (
            Just(n),
            prop::collection::vec(-1.0..1.0f64, n * n),
            prop::collection::vec(-1.0..1.0f64, n),
        )
            .prop_map(|(n, b_mat, b)| {
                let mut a = vec![0.0; n * n];
                for i in 0..n {
                    for j in 0..n {
                        a[i * n + j] = (0..n).map(|k| b_mat[k * n + i] * b_mat[k * n + j]).sum();
                    }
                    a[i * n + i] += 0.1;
                }
                (n, a, b)
            })
    })
}

/// Solves `A·x = b` for SPD `A` (row-major) by Cholesky.
fn cholesky_solve(n: usize, a: &[f64], b: &[f64]) -> Vec<f64> {
    let mut l = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..=i {
            let sum: f64 = (0..j).map(|k| l[i * n + k] * l[j * n + k]).sum();
            l[i * n + j] = if i == j {
                (a[i * n + i] - sum).sqrt()
            } else {
                (a[i * n + j] - sum) / l[j * n + j]
            };
        }
    }
    let mut z = vec![0.0; n];
    for i in 0..n {
        z[i] = (b[i] - (0..i).map(|k| l[i * n + k] * z[k]).sum::<f64>()) / l[i * n + i];
    }
    let mut x = vec![0.0; n];
    for i in (0..n).rev() {
        x[i] = (z[i] - (i + 1..n).map(|k| l[k * n + i] * x[k]).sum::<f64>()) / l[i * n + i];
    }
    x
}

fn quadratic(n: usize, a: &[f64], b: &[f64], x: &[f64], g: &mut [f64]) -> f64 {
    let mut cost = 0.0;
    for i in 0..n {
        let ax: f64 = (0..n).map(|j| a[i * n + j] * x[j]).sum();
        g[i] = ax - b[i];
        cost += 0.5 * x[i] * ax - b[i] * x[i];
    }
    cost
}

proptest! {
    #[test]
    fn random_convex_quadratics_reach_the_known_minimum(
        (n, a, b) in spd_problem(),
        start in prop::collection::vec(-5.0..5.0f64, 20),
    ) {
        let x_star = cholesky_solve(n, &a, &b);
        let mut scratch = vec![0.0; n];
        let f_star = quadratic(n, &a, &b, &x_star, &mut scratch);
        let f = |x: &[f64], g: &mut [f64]| quadratic(n, &a, &b, x, g);

        // Default parameters: the cost is within 1e-5 (relative) of the minimum. The cost-stall
        // test (relative decrease <= delta = 1e-6 over 3 iteration_count) can stop a few `delta` short:
        // the largest gap over 1000 cases was 2.8e-6.
        let mut x = start[..n].to_vec();
        let (_, report) = solve(&mut x, LbfgsParams::default(), f);
        prop_assert!(report.termination.is_success(), "{:?}", report);
        let gap = (report.cost - f_star) / f_star.abs().max(1.0);
        prop_assert!(gap <= 1e-5, "gap {:e}: {:?}", gap, report);

        // Tight gradient test: the minimizer itself, to 1e-6 (relative to its size). Rounding may
        // end the solve in a line-search failure just before the gradient test; the point must
        // still be accurate.
        let mut x = start[..n].to_vec();
        let (_, report) = solve(&mut x, tight(), f);
        let scale = x_star.iter().fold(1.0f64, |m, v| m.max(v.abs()));
        for i in 0..n {
            prop_assert!((x[i] - x_star[i]).abs() <= 1e-6 * scale,
                "i = {}: {} vs {} ({:?})", i, x[i], x_star[i], report);
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Robustness

/// LBFGS-Lite's / GCOPTER's smoothed L1 penalty (C²) with width `mu`, and its derivative.
fn smoothed_l1(x: f64, mu: f64) -> (f64, f64) {
    if x <= 0.0 {
        (0.0, 0.0)
    } else if x < mu {
        let r = x / mu;
        (mu * (r.powi(3) - 0.5 * r.powi(4)), r * r * (3.0 - 2.0 * r))
    } else {
        (x - 0.5 * mu, 1.0)
    }
}

#[test]
fn smoothed_l1_penalty_problem_converges_to_the_known_minimizer() {
    // f = Σ (x_i − 2)² + 10·Σ smoothed_l1(x_i − 1): each minimizer sits inside the smoothing band
    // just above 1, where 2(x − 2) + 10·slope = 0.
    let mu = 1e-2;
    let f = move |x: &[f64], g: &mut [f64]| {
        let mut cost = 0.0;
        for i in 0..x.len() {
            let (p, dp) = smoothed_l1(x[i] - 1.0, mu);
            cost += (x[i] - 2.0).powi(2) + 10.0 * p;
            g[i] = 2.0 * (x[i] - 2.0) + 10.0 * dp;
        }
        cost
    };
    // The 1-D minimizer by bisection on the derivative.
    let (mut lo, mut hi) = (1.0, 1.0 + mu);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        let slope = 2.0 * (mid - 2.0) + 10.0 * smoothed_l1(mid - 1.0, mu).1;
        if slope < 0.0 { lo = mid } else { hi = mid }
    }
    let mut x = [-3.0, 0.0, 4.0, 10.0, 1.5];
    let (_, report) = solve(&mut x, tight(), f);
    for xi in x {
        assert!(
            (xi - lo).abs() < 1e-6,
            "x = {x:?}, expected {lo}: {report:?}"
        );
    }
}

#[test]
fn kinked_penalty_ends_at_a_finite_point_near_the_kink() {
    // f = Σ (x_i − 2)² + 10·Σ max(0, x_i − 1): nonsmooth, minimizer exactly at the kink x_i = 1.
    let f = |x: &[f64], g: &mut [f64]| {
        let mut cost = 0.0;
        for i in 0..x.len() {
            let over = x[i] - 1.0;
            cost += (x[i] - 2.0).powi(2) + 10.0 * over.max(0.0);
            g[i] = 2.0 * (x[i] - 2.0) + if over > 0.0 { 10.0 } else { 0.0 };
        }
        cost
    };
    let mut x = [-3.0, 0.0, 4.0, 10.0];
    let mut g0 = [0.0; 4];
    let f0 = f(&x, &mut g0);
    let (_, report) = solve(&mut x, LbfgsParams::default(), f);
    assert!(report.cost < f0);
    for xi in x {
        assert!((xi - 1.0).abs() < 1e-3, "x = {x:?}: {report:?}");
    }
}

#[test]
fn nan_outside_a_ball_returns_the_best_finite_point() {
    // Defined only inside ‖x‖ < 2; the unconstrained minimizer (3, 3, 3) lies outside.
    let f = |x: &[f64], g: &mut [f64]| {
        if x.iter().map(|v| v * v).sum::<f64>() >= 4.0 {
            return f64::NAN;
        }
        let mut cost = 0.0;
        for i in 0..x.len() {
            g[i] = 2.0 * (x[i] - 3.0);
            cost += (x[i] - 3.0).powi(2);
        }
        cost
    };
    let mut x = [0.0, 0.5, -0.5];
    let mut g0 = [0.0; 3];
    let f0 = f(&x, &mut g0);
    let (_, report) = solve(&mut x, LbfgsParams::default(), f);
    assert!(report.cost < f0, "{report:?}");
    assert!(x.iter().map(|v| v * v).sum::<f64>() < 4.0);
}

/// Regression for GCOPTER's LBFGS-Lite copy: on a line-search failure it restores x but returns
/// the last trial's cost, here NaN.
#[test]
fn line_search_failure_after_a_nan_trial_returns_the_best_point_and_its_cost() {
    let f = |x: &[f64], g: &mut [f64]| {
        if x[0] != 0.0 {
            return f64::NAN;
        }
        g[0] = -1.0;
        g[1] = 0.0;
        7.0
    };
    let params = LbfgsParams {
        max_linesearch: 1,
        ..LbfgsParams::default()
    };
    let mut x = [0.0, 0.0];
    let (solver, report) = solve(&mut x, params, f);
    assert_eq!(
        report.termination,
        Termination::LineSearchFailed(trust_lbfgs::LineSearchFailure::TrialLimit)
    );
    assert_eq!(report.cost, 7.0);
    assert_eq!(x, [0.0, 0.0]);
    assert_eq!(solver.gradient(), [-1.0, 0.0]);
}

#[test]
fn nan_gradient_with_finite_cost_is_avoided() {
    // The cost is finite everywhere but the gradient is NaN for x > 0.5.
    let f = |x: &[f64], g: &mut [f64]| {
        g[0] = if x[0] > 0.5 {
            f64::NAN
        } else {
            2.0 * (x[0] - 1.0)
        };
        (x[0] - 1.0).powi(2)
    };
    let mut x = [-1.0];
    let (solver, report) = solve(&mut x, LbfgsParams::default(), f);
    assert!(x[0] <= 0.5);
    assert!(solver.gradient()[0].is_finite());
    assert!(report.grad_inf_norm.is_finite());
}

#[test]
fn unbounded_cost_stops_with_a_line_search_failure_and_finite_cost() {
    let f = |x: &[f64], g: &mut [f64]| {
        g[0] = -1.0;
        g[1] = 2.0 * x[1];
        -x[0] + x[1] * x[1]
    };
    let mut x = [0.0, 1.0];
    let (_, report) = solve(&mut x, LbfgsParams::default(), f);
    assert!(
        matches!(report.termination, Termination::LineSearchFailed(_)),
        "{report:?}"
    );
    assert!(report.cost.is_finite() && report.cost < -1e10, "{report:?}");
}

// ---------------------------------------------------------------------------------------------
// Budgets and monitors

proptest! {
    #[test]
    fn evaluation_budget_is_never_exceeded(budget in 1usize..80, n in 2usize..12) {
        let calls = Cell::new(0usize);
        let f = |x: &[f64], g: &mut [f64]| {
            calls.set(calls.get() + 1);
            rosenbrock(x, g)
        };
        let params = LbfgsParams { max_evaluations: budget, ..tight() };
        let mut x = rosenbrock_start(n);
        let mut solver = Lbfgs::new(n, params).unwrap();
        let report = solver.minimize(&mut x, f, &mut ()).unwrap();
        prop_assert!(calls.get() <= budget);
        prop_assert_eq!(report.evaluation_count, calls.get());
        if report.termination != Termination::Converged {
            prop_assert_eq!(report.termination, Termination::MaxEvaluations);
            prop_assert_eq!(calls.get(), budget);
        }
        let mut g = vec![0.0; n];
        prop_assert_eq!(rosenbrock(&x, &mut g), report.cost);
        let x0 = rosenbrock_start(n);
        prop_assert!(report.cost <= rosenbrock(&x0, &mut g));
    }
}

#[test]
fn iteration_budget_is_respected() {
    let mut x = rosenbrock_start(2);
    let params = LbfgsParams {
        max_iterations: 5,
        ..LbfgsParams::default()
    };
    let (_, report) = solve(&mut x, params, rosenbrock);
    assert_eq!(report.termination, Termination::MaxIterations);
    assert_eq!(report.iteration_count, 5);
}

#[test]
fn closure_monitor_cancels_and_sees_every_iteration() {
    let mut seen = Vec::new();
    let mut monitor = monitor_fn(|p: &Progress<'_>| {
        let mut g = [0.0; 2];
        assert_eq!(rosenbrock(p.x, &mut g), p.cost);
        assert_eq!(p.gradient, g);
        assert!(p.step > 0.0);
        seen.push((p.iteration, p.evaluation_count, p.cost));
        p.iteration < 3
    });
    let mut solver = Lbfgs::new(2, LbfgsParams::default()).unwrap();
    let mut x = rosenbrock_start(2);
    let report = solver.minimize(&mut x, rosenbrock, &mut monitor).unwrap();
    assert_eq!(report.termination, Termination::Cancelled);
    assert_eq!(report.iteration_count, 3);
    assert_eq!(seen.len(), 3);
    assert_eq!(seen.iter().map(|s| s.0).collect::<Vec<_>>(), vec![1, 2, 3]);
    assert_eq!(seen[2].1, report.evaluation_count);
    assert_eq!(seen[2].2, report.cost);
    assert!(
        seen.windows(2).all(|w| w[1].2 < w[0].2),
        "costs must decrease: {seen:?}"
    );
}

#[test]
fn monitor_is_called_once_per_iteration_until_convergence() {
    let mut calls = 0;
    let mut monitor = monitor_fn(|_: &Progress<'_>| {
        calls += 1;
        true
    });
    let mut solver = Lbfgs::new(10, LbfgsParams::default()).unwrap();
    let mut x = rosenbrock_start(10);
    let report = solver.minimize(&mut x, rosenbrock, &mut monitor).unwrap();
    assert!(report.termination.is_success());
    assert_eq!(calls, report.iteration_count);
}

#[test]
fn expired_deadline_cancels_after_one_iteration() {
    let mut deadline = Deadline::new(Instant::now());
    let mut solver = Lbfgs::new(2, LbfgsParams::default()).unwrap();
    let mut x = rosenbrock_start(2);
    let report = solver.minimize(&mut x, rosenbrock, &mut deadline).unwrap();
    assert_eq!(report.termination, Termination::Cancelled);
    assert_eq!(report.iteration_count, 1);

    let mut generous = Deadline::after(Duration::from_secs(3600));
    let mut x = rosenbrock_start(2);
    let report = solver.minimize(&mut x, rosenbrock, &mut generous).unwrap();
    assert!(report.termination.is_success());
}

// ---------------------------------------------------------------------------------------------
// Misuse

#[test]
fn invalid_params_are_rejected_with_the_field_named() {
    let params = LbfgsParams {
        s_curv_coeff: 1e-5,
        ..LbfgsParams::default()
    };
    let err = Lbfgs::new(3, params).unwrap_err();
    assert_eq!(
        err,
        LbfgsError::InvalidParam {
            field: "s_curv_coeff",
            value: 1e-5,
            expected: "a number in (f_dec_coeff, 1)"
        }
    );
    assert!(err.to_string().contains("s_curv_coeff = 0.00001"), "{err}");

    let mut x = [0.0];
    let params = LbfgsParams {
        memory: 0,
        ..LbfgsParams::default()
    };
    assert!(matches!(
        minimize(&mut x, rosenbrock, &params),
        Err(LbfgsError::InvalidParam {
            field: "memory",
            ..
        })
    ));
}

#[test]
fn invalid_inputs_are_typed_errors() {
    assert_eq!(
        Lbfgs::new(0, LbfgsParams::default()).unwrap_err(),
        LbfgsError::ZeroDimension
    );

    let mut solver = Lbfgs::new(3, LbfgsParams::default()).unwrap();
    let mut short = [0.0; 2];
    assert_eq!(
        solver
            .minimize(&mut short, rosenbrock, &mut ())
            .unwrap_err(),
        LbfgsError::DimensionMismatch {
            len: 2,
            expected: 3
        }
    );

    let mut x = [0.0, f64::INFINITY, f64::NAN];
    let err = solver.minimize(&mut x, rosenbrock, &mut ()).unwrap_err();
    assert_eq!(
        err,
        LbfgsError::NonFiniteStart {
            index: 1,
            value: f64::INFINITY
        }
    );
    assert_eq!(
        err.to_string(),
        "start point x[1] = inf, expected a finite number"
    );

    let mut x = [0.0; 3];
    let nan_cost = |_: &[f64], _: &mut [f64]| f64::NAN;
    assert!(matches!(
        solver.minimize(&mut x, nan_cost, &mut ()),
        Err(LbfgsError::NonFiniteStartCost { value }) if value.is_nan()
    ));

    let nan_gradient = |_: &[f64], g: &mut [f64]| {
        g[2] = f64::NEG_INFINITY;
        1.0
    };
    assert_eq!(
        solver.minimize(&mut x, nan_gradient, &mut ()).unwrap_err(),
        LbfgsError::NonFiniteStartGradient {
            index: 2,
            value: f64::NEG_INFINITY
        }
    );
    assert_eq!(x, [0.0; 3], "x must be untouched on error");
}

// ---------------------------------------------------------------------------------------------
// Determinism

#[test]
fn solves_are_bit_identical_and_independent_of_earlier_solves() {
    let run = |solver: &mut Lbfgs| {
        let mut x = rosenbrock_start(100);
        let report = solver.minimize(&mut x, rosenbrock, &mut ()).unwrap();
        (x.iter().map(|v| v.to_bits()).collect::<Vec<_>>(), report)
    };
    let mut first = Lbfgs::new(100, LbfgsParams::default()).unwrap();
    let mut second = Lbfgs::new(100, LbfgsParams::default()).unwrap();
    let a = run(&mut first);
    let b = run(&mut second);
    assert_eq!(a.0, b.0);
    assert_eq!(a.1.cost.to_bits(), b.1.cost.to_bits());
    assert_eq!(a.1, b.1);

    // A reused solver (after an unrelated solve of the same size) gives the same answer.
    let mut other = vec![3.0; 100];
    first
        .minimize(
            &mut other,
            |x: &[f64], g: &mut [f64]| {
                g.copy_from_slice(x);
                0.5 * x.iter().map(|v| v * v).sum::<f64>()
            },
            &mut (),
        )
        .unwrap();
    let c = run(&mut first);
    assert_eq!(a.0, c.0);
    assert_eq!(a.1, c.1);
}

// ---------------------------------------------------------------------------------------------
// Split objectives (gradient on demand)

/// A fused function as a [`SplitObjective`] that records how often each half is called and
/// checks that every gradient is requested at the point of the last cost call.
struct Recording<F> {
    f: F,
    last_x: Vec<f64>,
    cost_count: usize,
    gradient_count: usize,
    /// Evaluations whose cost exceeded the bound.
    cut_count: usize,
}

impl<F: FnMut(&[f64], &mut [f64]) -> f64> Recording<F> {
    fn new(f: F) -> Self {
        Self {
            f,
            last_x: Vec::new(),
            cost_count: 0,
            gradient_count: 0,
            cut_count: 0,
        }
    }
}

impl<F: FnMut(&[f64], &mut [f64]) -> f64> SplitObjective for Recording<F> {
    /// Above the bound, reports a deliberately wrong value (the bound's successor, or twice it):
    /// the solver must not depend on it.
    fn cost(&mut self, x: &[f64], bound: f64) -> f64 {
        self.cost_count += 1;
        self.last_x = x.to_vec();
        let mut g = vec![0.0; x.len()];
        let cost = (self.f)(x, &mut g);
        if cost > bound {
            self.cut_count += 1;
            if bound.is_finite() {
                bound.next_up().max(2.0 * bound)
            } else {
                cost
            }
        } else {
            cost
        }
    }

    fn gradient(&mut self, g: &mut [f64]) {
        assert!(g.iter().all(|v| *v == 0.0), "g is zero-filled");
        self.gradient_count += 1;
        let x = self.last_x.clone();
        (self.f)(&x, g);
    }
}

/// `minimize_split` must follow `minimize` exactly (same iterates bit for bit, same report) on
/// problems with backtracking line searches, NaN regions and kinks, while skipping the gradient
/// of rejected trials and ignoring the cost reported above the bound.
#[test]
fn split_objective_gives_the_same_solve_with_fewer_gradients() {
    let nan_outside = |x: &[f64], g: &mut [f64]| {
        if x.iter().map(|v| v * v).sum::<f64>() >= 4.0 {
            return f64::NAN;
        }
        let mut cost = 0.0;
        for i in 0..x.len() {
            g[i] = 2.0 * (x[i] - 3.0);
            cost += (x[i] - 3.0).powi(2);
        }
        cost
    };
    let kinked = |x: &[f64], g: &mut [f64]| {
        let (v, s) = smoothed_l1(x[0] - 1.0, 1e-3);
        g[0] = 2.0 * x[0] + 1e4 * s;
        g[1] = 2.0 * (x[1] + 0.5);
        x[0] * x[0] + (x[1] + 0.5).powi(2) + 1e4 * v
    };
    type Problem = (Vec<f64>, LbfgsParams, fn(&[f64], &mut [f64]) -> f64);
    let problems: Vec<Problem> = vec![
        (rosenbrock_start(10), LbfgsParams::default(), rosenbrock),
        (vec![0.0, 0.5, -0.5], LbfgsParams::default(), nan_outside),
        (vec![3.0, 2.0], tight(), kinked),
        (
            rosenbrock_start(6),
            LbfgsParams {
                max_evaluations: 17,
                ..LbfgsParams::default()
            },
            rosenbrock,
        ),
    ];
    let (mut skipped, mut cut) = (0, 0);
    for (start, params, f) in problems {
        let mut fused_x = start.clone();
        let mut fused = Lbfgs::new(start.len(), params.clone()).unwrap();
        let fused_report = fused.minimize(&mut fused_x, f, &mut ()).unwrap();

        let mut split_x = start.clone();
        let mut split = Lbfgs::new(start.len(), params).unwrap();
        let mut objective = Recording::new(f);
        let split_report = split
            .minimize_split(&mut split_x, &mut objective, &mut ())
            .unwrap();

        assert_eq!(split_report, fused_report);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&split_x), bits(&fused_x));
        assert_eq!(bits(split.gradient()), bits(fused.gradient()));
        assert_eq!(objective.cost_count, split_report.evaluation_count);
        assert!(objective.gradient_count <= objective.cost_count);
        skipped += objective.cost_count - objective.gradient_count;
        cut += objective.cut_count;
    }
    assert!(
        skipped > 0,
        "some rejected trial must have skipped its gradient"
    );
    assert!(cut > 0, "some trial must have exceeded its bound");
}

#[test]
fn split_objective_errors_like_the_fused_one() {
    struct NanStart;
    impl SplitObjective for NanStart {
        fn cost(&mut self, _: &[f64], _: f64) -> f64 {
            f64::NAN
        }
        fn gradient(&mut self, _: &mut [f64]) {}
    }
    let mut solver = Lbfgs::new(2, LbfgsParams::default()).unwrap();
    let err = solver
        .minimize_split(&mut [0.0, 0.0], &mut NanStart, &mut ())
        .unwrap_err();
    assert!(
        matches!(err, LbfgsError::NonFiniteStartCost { .. }),
        "{err}"
    );
    let err = solver
        .minimize_split(&mut [0.0], &mut NanStart, &mut ())
        .unwrap_err();
    assert!(matches!(err, LbfgsError::DimensionMismatch { .. }), "{err}");
}

#[test]
fn report_and_params_round_trip_through_json() {
    let mut x = rosenbrock_start(2);
    let report = minimize(&mut x, rosenbrock, &LbfgsParams::default()).unwrap();
    let json = serde_json::to_string(&report).unwrap();
    assert_eq!(serde_json::from_str::<Report>(&json).unwrap(), report);

    let failed = Termination::LineSearchFailed(trust_lbfgs::LineSearchFailure::TrialLimit);
    let json = serde_json::to_string(&failed).unwrap();
    assert_eq!(serde_json::from_str::<Termination>(&json).unwrap(), failed);

    let params = LbfgsParams {
        memory: 16,
        max_evaluations: 500,
        ..LbfgsParams::default()
    };
    let json = serde_json::to_string(&params).unwrap();
    assert_eq!(serde_json::from_str::<LbfgsParams>(&json).unwrap(), params);
}
