//! The trajectory backends of paper Sec. III-D: [`UtfMinco`] (uniform-time, terminal-free MINCO,
//! the paper's method) and [`Minco`] (the original fixed-terminal MINCO, the baseline of Table
//! Sim-A-2), both implementing [`trust_core::TrajectoryBackend`] with L-BFGS (`trust-lbfgs`) over
//! the analytic objectives [`UtfMincoObjective`] and [`MincoObjective`].
//!
//! | decision variable | UTF-MINCO | MINCO |
//! |---|---|---|
//! | inner waypoints `P` | free | free |
//! | terminal `p_f`, `v_f` | free (`a_f = 0`) | fixed: end of guide, at rest |
//! | durations | `T_i = T_Σ/n`, one `τ` | one `τ_i` per piece |
//!
//! Durations go through the positive map [`positive_time`] plus a floor `T_min`
//! ([`PieceParams::min_piece_duration_s`]). A solve never returns NaN: non-finite trial costs make
//! the line search back off, the solver returns its best finite point, and the trajectory is
//! validated ([`trust_core::PolyTraj::new`]).
//!
//! ```
//! use trust_core::{GuidePath, InitialGuess, Limits, State, TrajRequest, TrajectoryBackend, Vec3};
//! use trust_minco::backend::UtfMinco;
//! use trust_minco::scenes::e2_static;
//!
//! let case = e2_static();
//! let guide = case.guide();
//! let req = TrajRequest {
//!     start: case.start,
//!     goal: case.goal,
//!     limits: case.limits,
//!     initial: InitialGuess::Guide(&guide),
//!     deadline: None,
//!     horizon_s: None,
//!     max_evaluations: None,
//! };
//! let solution = UtfMinco::default().optimize(&req, &case.scene())?;
//! assert!(solution.traj.duration() > 0.0);
//! # Ok::<(), trust_core::PlanError>(())
//! ```

mod init;
mod minco_backend;
mod objective;
mod params;
mod solve;
mod time_map;
mod utf_minco;

pub use init::{InitialTrajectory, SpeedProfile, initial_trajectory, rest_to_rest_time};
pub use minco_backend::Minco;
pub use objective::{MincoObjective, UtfMincoObjective};
pub use params::{
    MAX_MIN_PIECE_DURATION_S, MincoParams, PieceParams, SolverParams, UtfMincoParams,
};
pub use solve::{solve_status, validate_request};
pub use time_map::{positive_time, positive_time_inverse};
pub use utf_minco::UtfMinco;
