//! The three plugin traits and their request/result types.
//!
//! Each trait has one required method that does the work and `name()` for reports; inputs are borrowed,
//! a result struct comes out; all are object safe and `Send + Sync` so that a manager can run them from
//! a thread pool and `sim` can hold them as `Box<dyn …>` when it must.

use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

use crate::error::{check_positive, check_scaled, check_scaled_vec};
use crate::{Curve, GuidePath, Limits, PlanError, PolyTraj, Rng, Scene, Solution, State, Vec3};
use trust_geometry::scale::Quantity;

/// A request for guide paths.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathQuery {
    /// Current vehicle state (the paths start at `start.p`).
    pub start: State,
    /// Global goal.
    pub goal: Vec3,
    /// Dynamic limits (DEV-PRM's goal guidance surface uses `v_max`).
    pub limits: Limits,
    /// Planning horizon `T_h` (s): predictive directional cones and the goal guidance surface use it.
    pub horizon_s: f64,
    /// How widely to explore, `1` normally: a sampling frontend multiplies its sampling region's
    /// inflation, its sample budgets and its time budget by it (DEV-PRM, V-PRM); frontends
    /// without a sampling region ignore it. The manager passes 2 while the flight is stalled.
    /// Accepted: `[1, MAX_EXPLORATION]`.
    pub exploration: f64,
}

/// The largest accepted [`PathQuery::exploration`]: sixteen times the sampling region and the
/// budgets is already a search over a different problem.
pub const MAX_EXPLORATION: f64 = 16.0;

impl PathQuery {
    /// Checks every field.
    pub fn validate(&self) -> Result<(), PlanError> {
        self.start.validate("query.start")?;
        check_scaled_vec("query.goal", &self.goal, Quantity::Position)?;
        self.limits.validate()?;
        check_positive("query.horizon_s", self.horizon_s)?;
        check_scaled(
            "query.horizon_s",
            self.horizon_s,
            Quantity::PositiveDuration,
        )?;
        if !(1.0..=MAX_EXPLORATION).contains(&self.exploration) {
            return Err(PlanError::invalid(
                "query.exploration",
                self.exploration,
                format!("a factor in [1, {MAX_EXPLORATION}]"),
            ));
        }
        Ok(())
    }
}

/// What a frontend found, with statistics for benchmarks.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SearchResult {
    /// Homotopy-distinct guide paths, best (shortest) first. Empty when none was found: that is a
    /// planning outcome, not an error.
    pub paths: Vec<GuidePath>,
    /// Counters of the search.
    pub stats: SearchStats,
}

/// Counters of one frontend search.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct SearchStats {
    /// Samples drawn (random plus obstacle-aware).
    pub sample_count: usize,
    /// Roadmap nodes kept (guards and connectors), or expanded nodes for graph searches.
    pub node_count: usize,
    /// Raw paths found before shortcutting and pruning.
    pub raw_path_count: usize,
    /// Wall-clock time (monotonic).
    pub elapsed: Duration,
    /// Whether the time or sample budget stopped the roadmap construction.
    pub budget_exhausted: bool,
    /// Whether sampling stopped because the roadmap stopped growing (DEV-PRM's `stall_samples`
    /// rule) rather than on a budget.
    pub stalled: bool,
}

/// Finds homotopy-distinct guide paths from the start toward the goal (paper Sec. III-B).
///
/// # Example
///
/// A frontend that proposes the straight segment when it is free of static obstacles:
///
/// ```
/// use trust_core::{PathFrontend, PathQuery, SearchResult, Scene, GuidePath, PlanError, Rng};
///
/// struct Direct;
///
/// impl PathFrontend for Direct {
///     fn name(&self) -> &str {
///         "direct"
///     }
///
///     fn search(&self, q: &PathQuery, scene: &Scene<'_>, _rng: &mut Rng) -> Result<SearchResult, PlanError> {
///         q.validate()?;
///         let mut result = SearchResult::default();
///         if scene.map.segment_clear(&q.start.p, &q.goal, 0.0) {
///             result.paths.push(GuidePath::new(vec![q.start.p, q.goal])?);
///         }
///         Ok(result)
///     }
/// }
/// # let _: &dyn PathFrontend = &Direct;
/// ```
pub trait PathFrontend: Send + Sync {
    /// Short name for reports (`"dev-prm"`, `"v-prm"`, ...).
    fn name(&self) -> &str;

    /// Searches for guide paths. All randomness comes from `rng`: the same seed gives the same paths.
    fn search(
        &self,
        query: &PathQuery,
        scene: &Scene<'_>,
        rng: &mut Rng,
    ) -> Result<SearchResult, PlanError>;
}

/// How a backend initializes its decision variables.
#[derive(Debug, Clone, Copy)]
pub enum InitialGuess<'a> {
    /// Resample this guide path by arc length into the initial waypoints.
    Guide(&'a GuidePath),
    /// Warm start from a previous trajectory (e.g. the same branch in the last cycle).
    WarmStart(&'a PolyTraj),
}

/// A request for one optimized trajectory.
#[derive(Debug, Clone, Copy)]
pub struct TrajRequest<'a> {
    /// Start state (fixed head of the trajectory).
    pub start: State,
    /// Global goal (the heuristic terminal cost pulls the free terminal toward it).
    pub goal: Vec3,
    /// Dynamic limits.
    pub limits: Limits,
    /// Initial guess.
    pub initial: InitialGuess<'a>,
    /// Optional hard deadline on a monotonic clock; the backend returns its best iterate with
    /// [`crate::SolveStatus::TimeLimit`] when it passes.
    pub deadline: Option<Instant>,
    /// Planning horizon `T_h` (s) of a receding-horizon planner, or `None` to plan all the way to
    /// the goal. With a horizon, a free-terminal backend (UTF-MINCO) pulls its terminal only to
    /// the goal guidance surface `‖p − p_g‖ = r_des`, `r_des = max(0, ‖p_s − p_g‖ − T_h·v_max)`
    /// (paper Sec. III-B, the surface DEV-PRM's paths end on), so that the trajectory covers about
    /// one horizon instead of the whole remaining distance; near the goal (`r_des = 0`) it is the
    /// paper's `H_s` toward the goal itself. Fixed-terminal backends ignore it.
    pub horizon_s: Option<f64>,
    /// Optional cap on cost evaluations for this request; the smaller of it and the backend's own
    /// budget applies. A manager re-solving a branch from a warm start needs far fewer evaluations
    /// than a cold solve, and refines it again next cycle.
    pub max_evaluations: Option<usize>,
}

impl TrajRequest<'_> {
    /// Checks every field.
    pub fn validate(&self) -> Result<(), PlanError> {
        self.start.validate("request.start")?;
        check_scaled_vec("request.goal", &self.goal, Quantity::Position)?;
        self.limits.validate()?;
        if let Some(h) = self.horizon_s {
            check_positive("request.horizon_s", h)?;
            check_scaled("request.horizon_s", h, Quantity::PositiveDuration)?;
        }
        if let InitialGuess::Guide(path) = self.initial {
            path.validate("request.initial")?;
        }
        if self.max_evaluations == Some(0) {
            return Err(PlanError::invalid(
                "request.max_evaluations",
                0,
                "at least 1 evaluation",
            ));
        }
        Ok(())
    }
}

/// Optimizes one trajectory (paper Sec. III-D).
///
/// # Example
///
/// A (useless but valid) backend that hovers at the start for one second:
///
/// ```
/// use std::time::Duration;
/// use trust_core::{
///     CostBreakdown, PlanError, PolyTraj, Scene, Solution, SolveStats, SolveStatus, TrajRequest,
///     TrajectoryBackend,
/// };
///
/// struct Hover;
///
/// impl TrajectoryBackend for Hover {
///     fn name(&self) -> &str {
///         "hover"
///     }
///
///     fn optimize(&self, req: &TrajRequest<'_>, _scene: &Scene<'_>) -> Result<Solution, PlanError> {
///         req.validate()?;
///         Ok(Solution {
///             traj: PolyTraj::hold(req.start.t, req.start.p, 1.0)?,
///             costs: CostBreakdown { ht: 1.0, total: 1.0, ..CostBreakdown::default() },
///             stats: SolveStats {
///                 iteration_count: 0,
///                 evaluation_count: 0,
///                 elapsed: Duration::ZERO,
///                 status: SolveStatus::Converged,
///             },
///             violations: Vec::new(),
///         })
///     }
/// }
/// # let _: &dyn TrajectoryBackend = &Hover;
/// ```
pub trait TrajectoryBackend: Send + Sync {
    /// Short name for reports (`"utf-minco"`, `"minco"`).
    fn name(&self) -> &str;

    /// Optimizes a trajectory from `req.start`.
    ///
    /// The contract (crate docs, [the backend contract](crate#the-backend-contract)):
    /// - `Err` only for invalid input or misuse, naming the culprit field with its value and the
    ///   accepted range;
    /// - `Ok` whenever the solve ran, also when it did not converge (see
    ///   [`crate::SolveStats::status`]); the trajectory is finite and starts at `req.start`;
    /// - `Ok` does not hide anything: [`Solution::violations`] lists what the returned trajectory
    ///   violates against `scene` and `req.limits` ([`crate::verify_trajectory`]); an
    ///   implementation fills it by calling that function on the trajectory it returns.
    fn optimize(&self, req: &TrajRequest<'_>, scene: &Scene<'_>) -> Result<Solution, PlanError>;
}

/// Decides whether two curves are in the same homotopy class (paper Sec. III-A: UVD for paths, TVD for
/// trajectories).
///
/// # Example
///
/// A checker that calls two curves equivalent when their resampled points stay within 1 m:
///
/// ```
/// use trust_core::{Curve, HomotopyChecker, PlanError, Scene};
///
/// struct Near;
///
/// impl HomotopyChecker for Near {
///     fn name(&self) -> &str {
///         "near"
///     }
///
///     fn equivalent(&self, a: &dyn Curve, b: &dyn Curve, _scene: &Scene<'_>) -> Result<bool, PlanError> {
///         let (mut pa, mut pb) = (Vec::new(), Vec::new());
///         a.resample_by_arc_length(16, &mut pa);
///         b.resample_by_arc_length(16, &mut pb);
///         Ok(pa.iter().zip(&pb).all(|(p, q)| (p - q).norm() < 1.0))
///     }
/// }
/// # let _: &dyn HomotopyChecker = &Near;
/// ```
pub trait HomotopyChecker: Send + Sync {
    /// Short name for reports (`"uvd"`, `"tvd"`).
    fn name(&self) -> &str;

    /// Whether `a` and `b` can be deformed into each other without crossing an obstacle. Returns
    /// [`PlanError::Unsupported`] when the curves lack what the checker needs (e.g. TVD on untimed
    /// paths).
    fn equivalent(
        &self,
        a: &dyn Curve,
        b: &dyn Curve,
        scene: &Scene<'_>,
    ) -> Result<bool, PlanError>;
}
