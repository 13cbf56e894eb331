//! # trust-core — the planning vocabulary of TRUST-Planner
//!
//! Every other crate of the planner speaks these types: the vehicle [`State`] and [`Limits`], the
//! [`Scene`] a planner sees (static map plus forecasts of moving obstacles), the untimed [`GuidePath`]
//! a frontend finds, the piecewise-quintic [`PolyTraj`] a backend optimizes (paper eq. Polynomials), the
//! [`Solution`] with its cost breakdown (eq. design-of-J) and solve status, and the one error type
//! [`PlanError`].
//!
//! The three plugin traits let each stage be swapped (paper Fig. framework):
//!
//! | trait | implementations | paper |
//! |---|---|---|
//! | [`PathFrontend`] | V-PRM, DEV-PRM, straight line, sparse A* (`trust-topo-prm`) | Sec. III-B |
//! | [`TrajectoryBackend`] | MINCO, UTF-MINCO (`trust-minco`) | Sec. III-D |
//! | [`HomotopyChecker`] | UVD, TVD (`trust-topo-prm`) | Sec. III-A |
//!
//! A few pieces of mathematics that several stages share live here once, as free functions:
//! [`bernstein_points`] (convex-hull bounds of a polynomial piece; the manager's safety check and
//! UTF-MINCO's penalty integration), [`guidance_radius`] (`r_des` of the goal guidance surface;
//! DEV-PRM and UTF-MINCO) and [`straight_end`] (the straight guide; the straight-line frontend
//! and the manager).
//!
//! Use this crate when you write a new frontend, backend or checker, or when you drive the planner
//! yourself. It depends only on `trust-geometry` and `trust-predict`; implementations depend on it,
//! never the reverse.
//!
//! # Scale policy
//!
//! Every public entry point of the planner accepts only the magnitudes of [`scale`] (defined in
//! `trust-geometry`, re-exported here): positions `|x| ≤ 1e6` m, lengths and sizes `≤ 1e6` m,
//! speeds `≤ 1e4` m/s, accelerations `≤ 1e5` m/s², times and durations `≤ 1e7` s, strictly
//! positive limits, durations and steps `≥ 1e-9`, generated samples `≤ 1e6` per call. Inside these
//! ranges every computation stays finite; outside them the call returns [`PlanError::Scale`] (or
//! [`PlanError::Count`]) naming the field, the value in scientific notation and the accepted
//! range. Points outside the map bounds give [`PlanError::OutOfBounds`].
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
mod path;
mod scene;
mod solution;
mod state;
mod traits;
mod traj;

pub use bernstein::bernstein_points;
pub use curve::Curve;
pub use error::{
    PlanError, check_finite, check_finite_vec, check_non_negative, check_positive, check_scaled,
    check_scaled_vec,
};
pub use guidance::{guidance_radius, straight_end};
pub use path::GuidePath;
pub use scene::Scene;
pub use solution::{CostBreakdown, RankingWeights, Solution, SolveStats, SolveStatus};
pub use state::{Limits, State};
pub use traits::{
    HomotopyChecker, InitialGuess, PathFrontend, PathQuery, SearchResult, SearchStats, TrajRequest,
    TrajectoryBackend,
};
pub use traj::{Derivative, MAX_DERIVATIVE_BOUND, Piece, PolyTraj, eval_piece};

pub use trust_geometry::{Aabb, StaticMap, Vec3, scale};
pub use trust_predict::{Forecast, ObstacleShape};

/// The random number generator every randomized component takes: seeded, portable, fast
/// (style rule 13). Create one with `rand::SeedableRng::seed_from_u64`.
pub type Rng = rand_chacha::ChaCha8Rng;
