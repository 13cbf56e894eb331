//! What both backends share around the objective: request validation, the L-BFGS run with its
//! budgets, and the mapping of the solver's outcome to a [`SolveStatus`].

use std::time::Instant;

use trust_core::scale::Sci;
use trust_core::{
    InitialGuess, PlanError, Scene, Solution, SolveStats, SolveStatus, TrajRequest, check_finite,
    check_finite_vec, verify_trajectory,
};
use trust_lbfgs::{Deadline, Lbfgs, Report, SplitObjective, Termination};

use super::objective::SplitCost;
use super::params::SolverParams;

/// Maps an L-BFGS [`Termination`] to the planner's [`SolveStatus`]:
/// `Converged → Converged`, `CostStalled → Stalled`, `MaxIterations → IterationLimit`,
/// `MaxEvaluations → EvaluationLimit`, `Cancelled → TimeLimit` (the backends cancel only on the
/// request's deadline), `LineSearchFailed(_) → LineSearchFailed` (also for any future variant).
pub fn solve_status(termination: Termination) -> SolveStatus {
    match termination {
        Termination::Converged => SolveStatus::Converged,
        Termination::CostStalled => SolveStatus::Stalled,
        Termination::MaxIterations => SolveStatus::IterationLimit,
        Termination::MaxEvaluations => SolveStatus::EvaluationLimit,
        Termination::Cancelled => SolveStatus::TimeLimit,
        _ => SolveStatus::LineSearchFailed,
    }
}

/// Checks a trajectory request against a scene, as both backends do before optimizing:
/// every number finite (fields named `request.…`, `scene.…`), every forecast valid, start and
/// goal inside the map bounds ([`PlanError::OutOfBounds`]), the start not inside a static
/// obstacle ([`PlanError::InCollision`]). A start inside a moving obstacle's forecast is allowed
/// (the optimizer pushes the trajectory out as fast as the limits allow).
pub fn validate_request(req: &TrajRequest<'_>, scene: &Scene<'_>) -> Result<(), PlanError> {
    req.validate()?;
    check_finite("scene.t0", scene.t0)?;
    for (i, f) in scene.forecasts.iter().enumerate() {
        f.validate().map_err(|e| PlanError::InvalidInput {
            field: format!("scene.forecasts[{i}]"),
            value: e.to_string(),
            expected: "a valid forecast".into(),
        })?;
    }
    match req.initial {
        InitialGuess::Guide(path) => {
            if path.points.is_empty() {
                return Err(PlanError::invalid(
                    "request.initial.points",
                    "[]",
                    "at least one point",
                ));
            }
            for (i, p) in path.points.iter().enumerate() {
                check_finite_vec(&format!("request.initial.points[{i}]"), p)?;
            }
        }
        // `PolyTraj` is validated when built or deserialized.
        InitialGuess::WarmStart(_) => {}
    }
    scene.check_in_bounds("request.start.p", &req.start.p)?;
    scene.check_in_bounds("request.goal", &req.goal)?;
    scene.check_static_free("request.start.p", &req.start.p, 0.0)?;
    Ok(())
}

/// Runs L-BFGS on `objective` from `x` with the evaluation budget of `solver` and the optional
/// deadline. The solve is split ([`Lbfgs::minimize_split`]): the gradient (MINCO's adjoint
/// solve, the energy gradient) is computed only at trial points the line search may accept, and
/// the penalties of a rejected trial only until its cost is seen to exceed the line search's
/// bound — with the same iterates as a fused solve.
pub(crate) fn run_lbfgs<O: SplitCost>(
    component: &str,
    objective: &mut O,
    x: &mut [f64],
    solver: &SolverParams,
    deadline: Option<Instant>,
) -> Result<Report, PlanError> {
    let wrap = |e: trust_lbfgs::LbfgsError| PlanError::Component {
        component: component.into(),
        source: Box::new(e),
    };
    let mut lbfgs = Lbfgs::new(x.len(), solver.effective_lbfgs()).map_err(wrap)?;
    let mut split = Split(objective);
    match deadline {
        Some(at) => lbfgs.minimize_split(x, &mut split, &mut Deadline::new(at)),
        None => lbfgs.minimize_split(x, &mut split, &mut ()),
    }
    .map_err(wrap)
}

/// Runs [`run_lbfgs`] from `x`, re-evaluates at the returned point (the breakdown and the
/// trajectory belong to it), verifies the trajectory against the request's scene and limits
/// ([`verify_trajectory`]) and packages the [`Solution`] with its statistics since `started`.
pub(crate) fn solve_and_package<O: SplitCost>(
    component: &str,
    objective: &mut O,
    x: &mut [f64],
    solver: &SolverParams,
    req: &TrajRequest<'_>,
    scene: &Scene<'_>,
    started: Instant,
) -> Result<Solution, PlanError> {
    let report = run_lbfgs(component, objective, x, solver, req.deadline)?;
    let mut g = vec![0.0; x.len()];
    objective.eval(x, &mut g);
    let traj = objective
        .trajectory()
        .map_err(|e| blame_start_time(e, req))?;
    let violations = verify_trajectory(&traj, scene, &req.limits);
    Ok(Solution {
        traj,
        costs: objective.breakdown(),
        stats: SolveStats {
            iteration_count: report.iteration_count,
            evaluation_count: report.evaluation_count + 1,
            elapsed: started.elapsed(),
            status: solve_status(report.termination),
        },
        violations,
    })
}

/// Checks that a trajectory of `duration` seconds from `req.start.t` ends inside the scale
/// policy's times (`≤ 1e7` s); otherwise the culprit is `request.start.t`.
pub(crate) fn check_end_time(req: &TrajRequest<'_>, duration: f64) -> Result<(), PlanError> {
    let t_end = req.start.t + duration;
    if t_end <= trust_core::scale::MAX_TIME_S {
        return Ok(());
    }
    Err(blame_start_time(
        PlanError::Scale(trust_core::scale::ScaleError {
            field: "traj.t_end".into(),
            value: t_end,
            lo: -trust_core::scale::MAX_TIME_S,
            hi: trust_core::scale::MAX_TIME_S,
            unit: "s",
        }),
        req,
    ))
}

/// A trajectory whose end time leaves the scale policy (`|t| ≤ 1e7` s) was started too close to
/// the limit: the culprit is `request.start.t`, not the internal `traj.t_end`.
pub(crate) fn blame_start_time(e: PlanError, req: &TrajRequest<'_>) -> PlanError {
    match e {
        PlanError::Scale(s) if s.field == "traj.t_end" => {
            let duration = s.value - req.start.t;
            PlanError::Scale(trust_core::scale::ScaleError {
                field: format!(
                    "request.start.t (the trajectory lasts {} s and would end at {} s)",
                    Sci(duration),
                    Sci(s.value)
                ),
                value: req.start.t,
                lo: s.lo,
                hi: s.hi - duration,
                unit: "s",
            })
        }
        other => other,
    }
}

/// An objective as a [`SplitObjective`]: a gradient that cannot be computed is reported to the
/// solver as NaN, which makes it reject the trial point exactly as the fused `eval`'s `+∞` does.
struct Split<'o, O>(&'o mut O);

impl<O: SplitCost> SplitObjective for Split<'_, O> {
    fn cost(&mut self, x: &[f64], bound: f64) -> f64 {
        self.0.cost(x, bound)
    }

    fn gradient(&mut self, g: &mut [f64]) {
        if self.0.gradient(g).is_err() {
            g.fill(f64::NAN);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use trust_lbfgs::LineSearchFailure;

    #[test]
    fn statuses_map_one_to_one() {
        assert_eq!(solve_status(Termination::Converged), SolveStatus::Converged);
        assert_eq!(solve_status(Termination::CostStalled), SolveStatus::Stalled);
        assert_eq!(
            solve_status(Termination::MaxIterations),
            SolveStatus::IterationLimit
        );
        assert_eq!(
            solve_status(Termination::MaxEvaluations),
            SolveStatus::EvaluationLimit
        );
        assert_eq!(solve_status(Termination::Cancelled), SolveStatus::TimeLimit);
        assert_eq!(
            solve_status(Termination::LineSearchFailed(LineSearchFailure::TrialLimit)),
            SolveStatus::LineSearchFailed
        );
    }
}
