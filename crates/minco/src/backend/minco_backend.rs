//! The original MINCO backend (fixed terminal state, per-piece durations): the paper's baseline in
//! Table Sim-A-2.

use std::time::Instant;

use trust_core::{InitialGuess, PlanError, Scene, Solution, TrajRequest, TrajectoryBackend};

use super::init::initial_trajectory;
use super::objective::MincoObjective;
use super::params::MincoParams;
use super::solve::{check_end_time, solve_and_package, validate_request};

/// MINCO (Wang et al., 2022) as the paper compares it: the trajectory ends **at rest at the end
/// of the guide** (or of the warm-start trajectory); the inner waypoints and every piece duration
/// are free ([`MincoObjective`]). Same costs, budgets and guarantees as
/// [`crate::backend::UtfMinco`]; a guess that ends outside the map bounds is rejected
/// ([`PlanError::OutOfBounds`] naming `request.initial…`), since the fixed terminal would be
/// there.
#[derive(Debug, Clone, Default)]
pub struct Minco {
    params: MincoParams,
}

impl Minco {
    /// A backend with validated parameters.
    ///
    /// # Errors
    /// [`PlanError::InvalidInput`] naming the first invalid field (`params.…`).
    pub fn new(params: MincoParams) -> Result<Self, PlanError> {
        params.validate("params")?;
        Ok(Self { params })
    }

    /// The parameters.
    pub fn params(&self) -> &MincoParams {
        &self.params
    }
}

impl TrajectoryBackend for Minco {
    fn name(&self) -> &str {
        "minco"
    }

    fn optimize(&self, req: &TrajRequest<'_>, scene: &Scene<'_>) -> Result<Solution, PlanError> {
        let started = Instant::now();
        validate_request(req, scene)?;
        let p = &self.params;
        let init = initial_trajectory(&req.initial, &req.start, &req.limits, &p.pieces);
        init.check_duration(&req.initial, &req.limits)?;
        check_end_time(req, init.total_duration)?;
        // MINCO's terminal is fixed: a guess that ends outside the map asks for a trajectory
        // that must leave it (issue 18: a warm start outside the map returned `Ok` 30 m out).
        let terminal_field = match req.initial {
            InitialGuess::Guide(path) => {
                format!(
                    "request.initial.points[{}] (MINCO's fixed terminal)",
                    path.points.len().saturating_sub(1)
                )
            }
            InitialGuess::WarmStart(_) => {
                "request.initial (warm start) end (MINCO's fixed terminal)".to_string()
            }
        };
        scene.check_in_bounds(&terminal_field, &init.end_position)?;
        let n = init.pieces();
        let mut f = MincoObjective::new(
            scene,
            &req.start,
            init.end_position,
            req.goal,
            req.limits,
            p,
            n,
        )?;
        let mut x = vec![0.0; f.dimension()];
        let durations = vec![init.total_duration / n as f64; n];
        f.encode(&init.waypoints, &durations, &mut x)?;
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
