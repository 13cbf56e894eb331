//! trust-minco: MINCO trajectories (paper Sec. III-D) for TRUST-Planner.
//!
//! - [`banded`]: banded LU without pivoting and the plain/transposed solves, the O(n) kernel of
//!   MINCO's `C = A⁻¹(T) D` and of the adjoint `A⁻ᵀ ∂I/∂C` (eq. analytical-gradients-I-to-S).
//! - [`minco`]: MINCO with s = 3 (minimum jerk, quintic pieces) — coefficients from head/tail
//!   states, waypoints and durations; the jerk energy (eq. design-of-Ie); propagation of any cost's
//!   gradient to waypoints, durations and the head/tail states (eq. analytical-gradients).
//!
//! Use [`MincoS3`] inside an optimizer's cost evaluation (preallocated, allocation-free), or the
//! free functions ([`jerk_energy`], [`eval_piece`], [`BandedMatrix`]) on their own.
#![warn(missing_docs)]

pub mod backend;
pub mod banded;
pub mod costs;
pub mod error;
pub mod minco;
pub mod scenes;

pub use banded::{BandRhs, BandedMatrix};
pub use error::MincoError;
pub use minco::{
    BoundaryState, MincoGrad, MincoS3, PieceDerivatives, accumulate_jerk_energy_grad,
    basis_derivatives, eval_json, eval_piece, jerk_energy, piece_jerk, piece_jerk_energy,
};
pub use backend::{
    Minco, MincoObjective, MincoParams, PieceParams, SolverParams, UtfMinco, UtfMincoObjective,
    UtfMincoParams,
};
pub use costs::{CostWeights, PenaltyParams};
