//! # trust-core — the planning vocabulary of TRUST-Planner
//!
//! Every other crate of the planner speaks these types: the vehicle [`State`] and [`Limits`], the
//! [`Scene`] a planner sees (static map plus forecasts of moving obstacles), the untimed [`GuidePath`]
//! a frontend finds, the piecewise-quintic [`PolyTraj`] a backend optimizes (paper eq. Polynomials), the
//! [`Solution`] with its cost breakdown (eq. design-of-J) and solve status, and the one error type
//! [`PlanError`].
//!
//! The three plugin traits let each stage be swapped (paper Sec. III-A, Fig. framework):
//!
//! | trait | implementations | paper |
//! |---|---|---|
//! | [`PathFrontend`] | V-PRM, DEV-PRM, straight line, sparse A* (`trust-topo-prm`) | Sec. III-B |
//! | [`TrajectoryBackend`] | MINCO, UTF-MINCO (`trust-minco`) | Sec. III-D |
//! | [`HomotopyChecker`] | UVD, TVD (`trust-topo-prm`) | Sec. III-A |
//!
//! A few pieces of mathematics that several stages share live here once, as free functions:
//! [`bernstein_points`] (convex-hull bounds of a polynomial piece), [`guidance_radius`] (`r_des` of
//! the goal guidance surface) and [`straight_end`] (the straight guide).
//!
//! Use this crate when you write a new frontend, backend or checker, or when you drive the planner
//! yourself. It depends only on `trust-geometry` and `trust-predict`; implementations depend on it,
//! never the reverse.
//!
//! # Scale policy
//!
//! Every public entry point accepts only the magnitudes of [`scale`] (positions `|x| ≤ 1e6` m,
//! speeds `≤ 1e4` m/s, times `≤ 1e7` s, …); outside them a call returns [`PlanError::Scale`] (or
//! [`PlanError::Count`]) naming the field, the value and the accepted range. Points outside the map
//! bounds give [`PlanError::OutOfBounds`].
//!
//! # The backend contract
//!
//! [`TrajectoryBackend::optimize`] returns `Err(PlanError)` for invalid input or misuse only (a
//! request, scene or parameter outside its documented range, a start inside a static obstacle, a start
//! or goal outside the bounds), naming the input that is wrong. It returns `Ok(Solution)` whenever the
//! solve ran: a finite trajectory from the request's start, its costs and statistics; not converging
//! is a [`SolveStatus`]. **`Ok` does not mean safe.** Every solution carries
//! [`Solution::violations`], the result of [`verify_trajectory`] against the request's scene and
//! limits (penetration of the static map or of each forecast, leaving the bounds, over-speed,
//! over-acceleration, each with its worst instant), checked at instants at most [`VERIFY_STEP_S`]
//! apart; a caller that needs a proof (the manager's safety check) checks with its own step.
//!
//! ```
//! use trust_core::{PolyTraj, Vec3};
//!
//! let traj = PolyTraj::hold(0.0, Vec3::new(1.0, 2.0, 3.0), 2.0)?;
//! assert_eq!(traj.position(1.0), Vec3::new(1.0, 2.0, 3.0));
//! # Ok::<(), trust_core::PlanError>(())
//! ```
#![warn(missing_docs)]

mod bernstein;
mod curve;
mod error;
mod guidance;
mod overrides;
mod path;
mod problem;
mod scene;
mod solution;
mod state;
mod traits;
mod traj;
mod verify;

pub use bernstein::bernstein_points;
pub use curve::Curve;
pub use error::{
    PlanError, PlanErrorKind, check_finite, check_finite_vec, check_non_negative, check_positive,
    check_range, check_scaled, check_scaled_vec,
};
pub use guidance::{guidance_radius, straight_end};
pub use overrides::Overridable;
pub use path::GuidePath;
pub use problem::Problem;
pub use scene::Scene;
pub use solution::{CostBreakdown, RankingWeights, Solution, SolveStats, SolveStatus};
pub use state::{Limits, State};
pub use traits::{
    HomotopyChecker, InitialGuess, MAX_EXPLORATION, PathFrontend, PathQuery, SearchResult,
    SearchStats, TrajRequest, TrajectoryBackend,
};
pub use traj::{Derivative, MAX_DERIVATIVE_BOUND, Piece, PolyTraj, eval_piece};
/// `#[derive(Overridable)]` for params structs (`trust-overrides`; [`Overridable`]).
pub use trust_overrides::Overridable;
pub use verify::{VERIFY_MAX_SAMPLES, VERIFY_STEP_S, Violation, verify_trajectory};

pub use trust_geometry::{Aabb, MapWork, StaticMap, Vec3, scale};
pub use trust_predict::{Forecast, ObstacleShape};

/// The random number generator every randomized component takes: seeded, portable, fast
/// (style rule 13). Create one with `rand::SeedableRng::seed_from_u64`.
pub type Rng = rand_chacha::ChaCha8Rng;
