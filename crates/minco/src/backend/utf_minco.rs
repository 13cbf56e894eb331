//! The UTF-MINCO backend (paper Sec. III-D): uniform durations, free terminal position and
//! velocity, one total duration.

use std::time::Instant;

use trust_core::{PlanError, Scene, Solution, TrajRequest, TrajectoryBackend, guidance_radius};

use super::init::initial_trajectory;
use super::objective::UtfMincoObjective;
use super::params::UtfMincoParams;
use super::solve::{check_end_time, solve_and_package, validate_request};

/// UTF-MINCO: minimizes `J = λ · [H_t, H_s, I_o, I_d, I_e]` (paper eq. design-of-J) over the
/// inner waypoints, the free terminal position and velocity and the total duration
/// ([`UtfMincoObjective`]) with L-BFGS.
///
/// - Initial guess: [`crate::backend::initial_trajectory`] (guide path resampled by arc length, or
///   a previous trajectory sampled at uniform times).
/// - Budget: `params.solver.max_evaluations` and the request's deadline (checked once per
///   iteration); the status says which stopped the solve.
/// - Receding horizon: with [`TrajRequest::horizon_s`] the terminal is pulled to the goal
///   guidance surface ([`trust_core::guidance_radius`], [`crate::costs::TerminalCost::eval_objective`]) so the
///   trajectory spans about one horizon; the reported `H_s` is the paper's, toward the goal. Once
///   the goal is within the horizon (`r_des = 0`) the terminal-velocity weight is `α = 1`, so the
///   trajectory ends at rest on the goal (the paper ramps `α` only within `d_ε` of the goal, too
///   late to stop from full speed).
/// - The returned trajectory starts at `req.start` (position, velocity, acceleration, time) and
///   is finite; the cost breakdown is evaluated at it, and [`trust_core::Solution::violations`]
///   lists what it violates ([`trust_core::verify_trajectory`]: penetration, bounds, limits).
#[derive(Debug, Clone, Default)]
pub struct UtfMinco {
    params: UtfMincoParams,
}

impl UtfMinco {
    /// A backend with validated parameters.
    ///
    /// # Errors
    /// [`PlanError::InvalidInput`] naming the first invalid field (`params.…`).
    pub fn new(params: UtfMincoParams) -> Result<Self, PlanError> {
        params.validate("params")?;
        Ok(Self { params })
    }

    /// The parameters.
    pub fn params(&self) -> &UtfMincoParams {
        &self.params
    }
}

impl TrajectoryBackend for UtfMinco {
    fn name(&self) -> &str {
        "utf-minco"
    }

    fn optimize(&self, req: &TrajRequest<'_>, scene: &Scene<'_>) -> Result<Solution, PlanError> {
        let started = Instant::now();
        validate_request(req, scene)?;
        let p = &self.params;
        let j_max = p
            .penalty
            .jerk_limit(req.limits.a_max)
            .unwrap_or(f64::INFINITY);
        let init = initial_trajectory(&req.initial, &req.start, &req.limits, &p.pieces)
            .with_jerk_floor(&req.initial, &req.start, &req.limits, j_max);
        init.check_duration(&req.initial, &req.limits)?;
        check_end_time(req, init.total_duration)?;
        let mut f =
            UtfMincoObjective::new(scene, &req.start, req.goal, req.limits, p, init.pieces())?;
        if let Some(horizon) = req.horizon_s {
            let radius = guidance_radius(&req.start.p, &req.goal, horizon, req.limits.v_max);
            if radius > 0.0 {
                f.set_guidance_surface(radius);
            } else {
                // The goal is within reach: end there at rest (full terminal-velocity weight)
                // rather than ramp `α` only over the last `d_ε` metres.
                f.set_terminal_velocity_weight(1.0);
            }
        }
        let mut x = vec![0.0; f.dimension()];
        f.encode(
            &init.waypoints,
            &init.end_position,
            &init.end_velocity,
            init.total_duration,
            &mut x,
        )?;
        solve_and_package(
            self.name(),
            &mut f,
            &mut x,
            &p.solver.capped(req.max_evaluations),
            req,
            scene,
            started,
        )
    }
}
