//! MINCO with s = 3 (minimum jerk, quintic pieces): the map from head/tail states, inner waypoints
//! and piece durations to polynomial coefficients, `C = A⁻¹(T) D` (paper Sec. III-D, eq.
//! Polynomials), the jerk energy, and the adjoint propagation of any cost's gradient back to the
//! waypoints, the durations and the head/tail states (eqs. analytical-gradients and
//! analytical-gradients-I-to-S).
//!
//! # The linear system
//!
//! `n` pieces, piece `i` is `p_i(t) = Σ_k c_{i,k} tᵏ` on `t ∈ [0, T_i]`; the `6n × 3` unknowns are
//! stored piece by piece (piece `i`, power `k` at row `6i + k`). Rows of `A(T) c = b` (0-based,
//! `T = T_i`, `c` piece `i`, `c'` piece `i + 1`):
//!
//! | rows | condition | right-hand side |
//! |---|---|---|
//! | 0, 1, 2 | `c₀₀`, `c₀₁`, `2c₀₂` | head position, velocity, acceleration |
//! | `6i+3` | jerk continuity `6c3 + 24T c4 + 60T² c5 − 6c'3` | 0 |
//! | `6i+4` | snap continuity `24c4 + 120T c5 − 24c'4` | 0 |
//! | `6i+5` | waypoint `Σ c_k Tᵏ` | `q_{i+1}` |
//! | `6i+6 ..= 6i+8` | position, velocity, acceleration of piece `i` at `T` minus `c'0`, `c'1`, `2c'2` | 0 |
//! | `6n−3 ..= 6n−1` | position, velocity, acceleration of the last piece at its end | tail state |
//!
//! The matrix has lower and upper bandwidth 6. [`MincoS3`] factorizes it with the banded LU
//! without pivoting (the elimination of [`crate::banded::BandedMatrix`]) restricted to the
//! entries that are structurally non-zero: same pivots, same order, about half the arithmetic and
//! no index bookkeeping. [`MincoS3::system`] returns the same system as a general
//! [`BandedMatrix`] for reference (the tests check both paths agree). Very short pieces make the
//! waypoint pivot (`6T⁵` for the first piece) tiny; a zero or non-finite pivot, or a non-finite
//! coefficient, energy or gradient, is reported as an error, never returned.
//!
//! # Gradients
//!
//! For any cost `K(c, T)` with `G = ∂K/∂c` and explicit `g = ∂K/∂T`, one transposed solve
//! `Aᵀ λ = G` gives `∂K/∂q_{i+1} = λ_{6i+5}`, `∂K/∂head = λ_{0..3}`, `∂K/∂tail = λ_{6n−3..6n}` and
//! `∂K/∂T_i = g_i − Σ_r λ_r · ∂(A c)_r/∂T_i` (junction rows pair with snap, crackle, velocity,
//! velocity, acceleration, jerk of piece `i` at `T_i`; the tail rows with velocity, acceleration,
//! jerk of the last piece). With uniform durations `T_i = T_Σ/n`,
//! `∂K/∂T_Σ = (1/n) Σ_i ∂K/∂T_i` ([`MincoGrad::uniform_total_duration`]).
//!
//! # Hot path
//!
//! [`MincoS3`] owns all storage for a fixed piece count: [`MincoS3::solve`],
//! [`MincoS3::accumulate_energy_grad`] and [`MincoS3::propagate_grad`] allocate nothing.

mod energy;
mod factor;
mod json;
mod piece;
mod validate;

use nalgebra::Vector3;

pub use energy::{accumulate_jerk_energy_grad, jerk_energy, piece_jerk_energy};
pub use json::{EvalInput, EvalOutput, eval_json};
pub use piece::{PieceDerivatives, basis_derivatives, eval_piece, piece_jerk};

use crate::banded::BandedMatrix;
use crate::error::MincoError;
use energy::{add_piece_energy_grad_pw, piece_energy_pw, powers};
use factor::MincoFactors;
use validate::{check_durations, check_len, check_scalars, check_vectors, first_non_finite};

/// A boundary (head or tail) state: `[position, velocity, acceleration]`.
pub type BoundaryState = [Vector3<f64>; 3];

/// Lower and upper bandwidth of the MINCO s = 3 matrix.
pub const MINCO_BANDWIDTH: usize = 6;

/// Gradients of a cost `K` with respect to the MINCO parameters, written by
/// [`MincoS3::propagate_grad`]. Allocate once with [`MincoGrad::new`] and reuse.
#[derive(Debug, Clone, PartialEq)]
pub struct MincoGrad {
    /// `∂K/∂q_i` for the inner waypoints `q_1 ..= q_{n−1}` (`n − 1` entries).
    pub waypoints: Vec<Vector3<f64>>,
    /// Total `∂K/∂T_i` per piece (explicit part plus the part through the coefficients).
    pub durations: Vec<f64>,
    /// `∂K/∂(head position, velocity, acceleration)`.
    pub head: BoundaryState,
    /// `∂K/∂(tail position, velocity, acceleration)` (paper eq. analytical-gradients-I-to-S).
    pub tail: BoundaryState,
}

impl MincoGrad {
    /// Zeroed gradient buffers for `pieces` pieces.
    pub fn new(pieces: usize) -> Self {
        Self {
            waypoints: vec![Vector3::zeros(); pieces.saturating_sub(1)],
            durations: vec![0.0; pieces],
            head: [Vector3::zeros(); 3],
            tail: [Vector3::zeros(); 3],
        }
    }

    /// `∂K/∂T_Σ` when all durations are tied, `T_i = T_Σ / n`: `(1/n) Σ_i ∂K/∂T_i` (paper eq.
    /// analytical-gradients). Zero when there are no pieces.
    pub fn uniform_total_duration(&self) -> f64 {
        if self.durations.is_empty() {
            0.0
        } else {
            self.durations.iter().sum::<f64>() / self.durations.len() as f64
        }
    }
}

/// MINCO s = 3 for a fixed number of pieces, with preallocated storage.
///
/// Typical use in an optimizer's cost evaluation:
///
/// ```
/// use nalgebra::Vector3;
/// use trust_minco::minco::{MincoGrad, MincoS3};
///
/// let mut minco = MincoS3::new(2)?;
/// let rest = |p: Vector3<f64>| [p, Vector3::zeros(), Vector3::zeros()];
/// minco.solve(
///     &rest(Vector3::zeros()),
///     &rest(Vector3::new(2.0, 0.0, 0.0)),
///     &[Vector3::new(1.0, 0.5, 0.0)],
///     &[1.0, 1.0],
/// )?;
/// // Cost = jerk energy; other terms would add into the same buffers.
/// let mut grad_c = vec![Vector3::zeros(); 6 * minco.pieces()];
/// let mut grad_t = vec![0.0; minco.pieces()];
/// let energy = minco.accumulate_energy_grad(1.0, &mut grad_c, &mut grad_t)?;
/// let mut grad = MincoGrad::new(minco.pieces());
/// minco.propagate_grad(&grad_c, &grad_t, &mut grad)?;
/// assert!(energy > 0.0 && grad.waypoints[0].norm() > 0.0);
/// # Ok::<(), trust_minco::MincoError>(())
/// ```
#[derive(Debug, Clone)]
pub struct MincoS3 {
    pieces: usize,
    head: BoundaryState,
    tail: BoundaryState,
    waypoints: Vec<Vector3<f64>>,
    durations: Vec<f64>,
    /// `[1, T, …, T⁵]` per piece.
    powers: Vec<[f64; 6]>,
    /// LU factors of `A(T)` after a successful solve.
    factors: MincoFactors,
    /// `6n` coefficient rows.
    coeffs: Vec<Vector3<f64>>,
    /// Adjoint `λ = A⁻ᵀ G` of the last propagation.
    adjoint: Vec<Vector3<f64>>,
    /// Scratch for [`MincoS3::energy_and_grad`].
    scratch_grad_c: Vec<Vector3<f64>>,
    scratch_grad_t: Vec<f64>,
    /// Jerk energy of the current coefficients.
    energy: f64,
    solved: bool,
}

/// Largest piece count of one MINCO problem: the trajectory piece cap of the scale policy
/// (`trust_core::scale::MAX_VERTEX_COUNT`, 100 000), so that the up-front storage (about 1.5 kB
/// per piece) stays bounded.
pub const MAX_PIECES: usize = trust_core::scale::MAX_VERTEX_COUNT;

impl MincoS3 {
    /// Storage for `pieces` pieces (unsolved: zero coefficients, unit durations).
    ///
    /// # Errors
    /// [`MincoError::NoPieces`] if `pieces == 0`, [`MincoError::TooManyPieces`] above
    /// [`MAX_PIECES`].
    pub fn new(pieces: usize) -> Result<Self, MincoError> {
        if pieces == 0 {
            return Err(MincoError::NoPieces { got: pieces });
        }
        if pieces > MAX_PIECES {
            return Err(MincoError::TooManyPieces {
                got: pieces,
                max: MAX_PIECES,
            });
        }
        let rows = 6 * pieces;
        Ok(Self {
            pieces,
            head: [Vector3::zeros(); 3],
            tail: [Vector3::zeros(); 3],
            waypoints: vec![Vector3::zeros(); pieces - 1],
            durations: vec![1.0; pieces],
            powers: vec![[1.0; 6]; pieces],
            factors: MincoFactors::new(pieces),
            coeffs: vec![Vector3::zeros(); rows],
            adjoint: vec![Vector3::zeros(); rows],
            scratch_grad_c: vec![Vector3::zeros(); rows],
            scratch_grad_t: vec![0.0; pieces],
            energy: 0.0,
            solved: false,
        })
    }

    /// Builds `A(T)` and `b`, factorizes and solves for the coefficients.
    ///
    /// `head` and `tail` are `[position, velocity, acceleration]`; `waypoints` are the `n − 1`
    /// inner junction positions `q_1 ..= q_{n−1}`; `durations` the `n` piece durations (s).
    ///
    /// # Errors
    /// Invalid input (checked before anything changes): [`MincoError::LengthMismatch`],
    /// [`MincoError::NonFiniteVector`], [`MincoError::InvalidDuration`]. Numerical breakdown
    /// (durations too short for f64): [`MincoError::SingularPivot`] or
    /// [`MincoError::NonFiniteResult`]; the solver is then unsolved (zero coefficients) until the
    /// next successful solve.
    pub fn solve(
        &mut self,
        head: &BoundaryState,
        tail: &BoundaryState,
        waypoints: &[Vector3<f64>],
        durations: &[f64],
    ) -> Result<(), MincoError> {
        let n = self.pieces;
        check_vectors("head", head)?;
        check_vectors("tail", tail)?;
        check_len("waypoints", n - 1, waypoints.len())?;
        check_vectors("waypoints", waypoints)?;
        check_len("durations", n, durations.len())?;
        check_durations(durations)?;

        self.solved = false;
        self.head = *head;
        self.tail = *tail;
        self.waypoints.copy_from_slice(waypoints);
        self.durations.copy_from_slice(durations);
        for (pw, &t) in self.powers.iter_mut().zip(durations) {
            *pw = powers(t);
        }
        build_rhs(&mut self.coeffs, head, tail, waypoints);
        let outcome = self
            .factors
            .factorize(&self.powers)
            .and_then(|()| {
                self.factors.solve(&self.powers, &mut self.coeffs);
                check_finite_result("coeffs", &self.coeffs)
            })
            .and_then(|()| {
                let energy = energy_of(&self.coeffs, &self.powers);
                if energy.is_finite() {
                    Ok(energy)
                } else {
                    Err(MincoError::NonFiniteResult {
                        field: "energy",
                        index: 0,
                    })
                }
            });
        match outcome {
            Ok(energy) => {
                self.energy = energy;
                self.solved = true;
                Ok(())
            }
            Err(e) => {
                self.coeffs.fill(Vector3::zeros());
                self.energy = 0.0;
                Err(e)
            }
        }
    }

    /// Number of pieces `n`.
    pub fn pieces(&self) -> usize {
        self.pieces
    }

    /// Whether the coefficients come from a successful [`solve`](Self::solve).
    pub fn is_solved(&self) -> bool {
        self.solved
    }

    /// Head state `[position, velocity, acceleration]` of the last solve.
    pub fn head(&self) -> &BoundaryState {
        &self.head
    }

    /// Tail state `[position, velocity, acceleration]` of the last solve.
    pub fn tail(&self) -> &BoundaryState {
        &self.tail
    }

    /// Inner waypoints of the last solve (`n − 1` entries).
    pub fn waypoints(&self) -> &[Vector3<f64>] {
        &self.waypoints
    }

    /// Piece durations of the last solve (s).
    pub fn durations(&self) -> &[f64] {
        &self.durations
    }

    /// Sum of the piece durations (s).
    pub fn total_duration(&self) -> f64 {
        self.durations.iter().sum()
    }

    /// All coefficients: `6n` rows, piece `i`, power `k` at row `6i + k` (ascending powers).
    pub fn coeffs(&self) -> &[Vector3<f64>] {
        &self.coeffs
    }

    /// The six coefficients of piece `index`, or `None` if `index >= n`.
    pub fn piece(&self, index: usize) -> Option<&[Vector3<f64>; 6]> {
        self.coeffs
            .get(6 * index..6 * index + 6)
            .and_then(|s| s.try_into().ok())
    }

    /// The coefficients as one `[c0, …, c5]` array per piece.
    pub fn to_pieces(&self) -> Vec<[Vector3<f64>; 6]> {
        let mut out = Vec::with_capacity(self.pieces);
        self.write_pieces(&mut out);
        out
    }

    /// Replaces the contents of `out` with one `[c0, …, c5]` array per piece (reuses its capacity).
    pub fn write_pieces(&self, out: &mut Vec<[Vector3<f64>; 6]>) {
        out.clear();
        out.extend(self.coeffs.chunks_exact(6).map(|c| {
            let mut piece = [Vector3::zeros(); 6];
            piece.copy_from_slice(c);
            piece
        }));
    }

    /// Position and derivatives up to snap of piece `index` at local time `t`, or `None` if
    /// `index >= n`. `t` is not clamped to `[0, T_index]`.
    pub fn eval(&self, index: usize, t: f64) -> Option<PieceDerivatives> {
        self.piece(index).map(|c| eval_piece(c, t))
    }

    /// Jerk energy `E = Σ_i ∫₀^{T_i} ‖p_i'''‖² dt` of the current coefficients (computed by
    /// [`solve`](Self::solve); 0 when unsolved).
    pub fn energy(&self) -> f64 {
        self.energy
    }

    /// Writes `∂E/∂c` (6 rows per piece, rows `c0..c2` zero) into `grad_c`.
    ///
    /// # Errors
    /// [`MincoError::LengthMismatch`] unless `grad_c.len() == 6n`.
    pub fn energy_grad_coeffs(&self, grad_c: &mut [Vector3<f64>]) -> Result<(), MincoError> {
        check_len("grad_c", self.coeffs.len(), grad_c.len())?;
        grad_c.fill(Vector3::zeros());
        for ((c, pw), g) in self
            .coeffs
            .chunks_exact(6)
            .zip(&self.powers)
            .zip(grad_c.chunks_exact_mut(6))
        {
            add_piece_energy_grad_pw(c, pw, 1.0, g);
        }
        Ok(())
    }

    /// Writes the explicit `∂E/∂T_i = ‖p_i'''(T_i)‖²` into `grad_t` (the part through the
    /// coefficients comes from [`propagate_grad`](Self::propagate_grad)).
    ///
    /// # Errors
    /// [`MincoError::LengthMismatch`] unless `grad_t.len() == n`.
    pub fn energy_grad_durations(&self, grad_t: &mut [f64]) -> Result<(), MincoError> {
        check_len("grad_t", self.pieces, grad_t.len())?;
        for ((c, pw), g) in self.coeffs.chunks_exact(6).zip(&self.powers).zip(grad_t) {
            let jerk = c[3] * 6.0 + c[4] * (24.0 * pw[1]) + c[5] * (60.0 * pw[2]);
            *g = jerk.norm_squared();
        }
        Ok(())
    }

    /// Adds `weight · ∂E/∂c` to `grad_c` and `weight · ∂E/∂T` (explicit) to `grad_t`, and returns
    /// the unweighted energy `E`. Use this to stack the jerk term onto other cost terms before one
    /// [`propagate_grad`](Self::propagate_grad).
    ///
    /// # Errors
    /// [`MincoError::LengthMismatch`] for buffers of the wrong length;
    /// [`MincoError::NonFiniteScalar`] for a non-finite `weight`.
    pub fn accumulate_energy_grad(
        &self,
        weight: f64,
        grad_c: &mut [Vector3<f64>],
        grad_t: &mut [f64],
    ) -> Result<f64, MincoError> {
        check_len("grad_c", self.coeffs.len(), grad_c.len())?;
        check_len("grad_t", self.pieces, grad_t.len())?;
        check_scalars("weight", &[weight])?;
        let mut energy = 0.0;
        for (((c, pw), g), gt) in self
            .coeffs
            .chunks_exact(6)
            .zip(&self.powers)
            .zip(grad_c.chunks_exact_mut(6))
            .zip(grad_t.iter_mut())
        {
            energy += piece_energy_pw(c, pw);
            *gt += weight * add_piece_energy_grad_pw(c, pw, weight, g);
        }
        Ok(energy)
    }

    /// Adjoint propagation: given `grad_c = ∂K/∂c` (`6n` rows) and the explicit
    /// `grad_t = ∂K/∂T` (`n` entries) of any cost `K`, writes the total gradients with respect to
    /// the waypoints, durations, head and tail states into `out` (one transposed banded solve,
    /// O(n), no allocation).
    ///
    /// # Errors
    /// [`MincoError::NotSolved`] before a successful [`solve`](Self::solve);
    /// [`MincoError::LengthMismatch`] for buffers of the wrong length (including `out`, which must
    /// come from `MincoGrad::new(n)`); [`MincoError::NonFiniteVector`] /
    /// [`MincoError::NonFiniteScalar`] for non-finite input gradients;
    /// [`MincoError::NonFiniteResult`] if the adjoint overflows. After an error `out` may be
    /// partially written.
    pub fn propagate_grad(
        &mut self,
        grad_c: &[Vector3<f64>],
        grad_t: &[f64],
        out: &mut MincoGrad,
    ) -> Result<(), MincoError> {
        let n = self.pieces;
        if !self.solved {
            return Err(MincoError::NotSolved {
                operation: "propagate_grad",
            });
        }
        check_len("grad_c", 6 * n, grad_c.len())?;
        check_len("grad_t", n, grad_t.len())?;
        check_len("out.waypoints", n - 1, out.waypoints.len())?;
        check_len("out.durations", n, out.durations.len())?;

        self.adjoint.copy_from_slice(grad_c);
        self.factors
            .solve_transposed(&self.powers, &mut self.adjoint);
        // A non-finite input makes the adjoint non-finite: check once on the output, and only on
        // failure find out whether the input or the solve is to blame.
        if let Err(overflow) = check_finite_result("adjoint", &self.adjoint) {
            check_vectors("grad_c", grad_c)?;
            return Err(overflow);
        }
        let adj = &self.adjoint;

        for i in 0..n - 1 {
            let c = &self.coeffs[6 * i..6 * i + 6];
            let pw = &self.powers[i];
            let d = top_derivatives(c, pw);
            let a = &adj[6 * i + 3..6 * i + 9];
            let through_c = a[0].dot(&d.snap)
                + a[1].dot(&d.crackle)
                + (a[2] + a[3]).dot(&d.velocity)
                + a[4].dot(&d.acceleration)
                + a[5].dot(&d.jerk);
            out.durations[i] = grad_t[i] - through_c;
            out.waypoints[i] = a[2];
        }
        let last = 6 * (n - 1);
        let d = top_derivatives(&self.coeffs[last..last + 6], &self.powers[n - 1]);
        let a = &adj[last + 3..last + 6];
        out.durations[n - 1] =
            grad_t[n - 1] - (a[0].dot(&d.velocity) + a[1].dot(&d.acceleration) + a[2].dot(&d.jerk));
        out.head = [adj[0], adj[1], adj[2]];
        out.tail = [a[0], a[1], a[2]];
        match out.durations.iter().position(|g| !g.is_finite()) {
            None => Ok(()),
            Some(index) => {
                check_scalars("grad_t", grad_t)?;
                Err(MincoError::NonFiniteResult {
                    field: "grad durations",
                    index,
                })
            }
        }
    }

    /// The adjoint `λ = A⁻ᵀ ∂K/∂c` of the last [`propagate_grad`](Self::propagate_grad) (`6n`
    /// rows; the `G` of paper eq. analytical-gradients-I-to-S).
    pub fn adjoint(&self) -> &[Vector3<f64>] {
        &self.adjoint
    }

    /// The linear system `A(T) c = b` of the last solve as a general [`BandedMatrix`] (not
    /// factorized) and its right-hand side. This is the reference path: solving it with
    /// [`BandedMatrix::factorize`] and [`BandedMatrix::solve_vec3`] gives the same coefficients as
    /// [`solve`](Self::solve), whose structure-aware factorization skips the band's zeros. Allocates.
    pub fn system(&self) -> (BandedMatrix, Vec<Vector3<f64>>) {
        let rows = 6 * self.pieces;
        let mut a = BandedMatrix::zeros(rows, MINCO_BANDWIDTH, MINCO_BANDWIDTH);
        build_matrix(&mut a, &self.powers);
        let mut b = vec![Vector3::zeros(); rows];
        build_rhs(&mut b, &self.head, &self.tail, &self.waypoints);
        (a, b)
    }

    /// Jerk energy and its total gradient with respect to waypoints, durations, head and tail
    /// (explicit energy gradients followed by [`propagate_grad`](Self::propagate_grad)), using
    /// internal scratch buffers. Returns `E`.
    ///
    /// # Errors
    /// As [`propagate_grad`](Self::propagate_grad).
    pub fn energy_and_grad(&mut self, out: &mut MincoGrad) -> Result<f64, MincoError> {
        let mut grad_c = std::mem::take(&mut self.scratch_grad_c);
        let mut grad_t = std::mem::take(&mut self.scratch_grad_t);
        grad_c.fill(Vector3::zeros());
        grad_t.fill(0.0);
        let result = self
            .accumulate_energy_grad(1.0, &mut grad_c, &mut grad_t)
            .and_then(|energy| {
                self.propagate_grad(&grad_c, &grad_t, out)?;
                Ok(energy)
            });
        self.scratch_grad_c = grad_c;
        self.scratch_grad_t = grad_t;
        result
    }
}

/// Velocity, acceleration, jerk, snap and crackle of a piece at its end `T` (powers `pw`).
struct EndDerivatives {
    velocity: Vector3<f64>,
    acceleration: Vector3<f64>,
    jerk: Vector3<f64>,
    snap: Vector3<f64>,
    crackle: Vector3<f64>,
}

#[inline(always)]
fn top_derivatives(c: &[Vector3<f64>], pw: &[f64; 6]) -> EndDerivatives {
    EndDerivatives {
        velocity: c[1]
            + c[2] * (2.0 * pw[1])
            + c[3] * (3.0 * pw[2])
            + c[4] * (4.0 * pw[3])
            + c[5] * (5.0 * pw[4]),
        acceleration: c[2] * 2.0
            + c[3] * (6.0 * pw[1])
            + c[4] * (12.0 * pw[2])
            + c[5] * (20.0 * pw[3]),
        jerk: c[3] * 6.0 + c[4] * (24.0 * pw[1]) + c[5] * (60.0 * pw[2]),
        snap: c[4] * 24.0 + c[5] * (120.0 * pw[1]),
        crackle: c[5] * 120.0,
    }
}

fn energy_of(coeffs: &[Vector3<f64>], powers: &[[f64; 6]]) -> f64 {
    coeffs
        .chunks_exact(6)
        .zip(powers)
        .map(|(c, pw)| piece_energy_pw(c, pw))
        .sum()
}

fn check_finite_result(field: &'static str, rows: &[Vector3<f64>]) -> Result<(), MincoError> {
    match first_non_finite(rows) {
        None => Ok(()),
        Some(index) => Err(MincoError::NonFiniteResult { field, index }),
    }
}

/// Fills the right-hand side `b` (`6n` rows) with the row layout documented at module level.
fn build_rhs(
    b: &mut [Vector3<f64>],
    head: &BoundaryState,
    tail: &BoundaryState,
    waypoints: &[Vector3<f64>],
) {
    b.fill(Vector3::zeros());
    b[..3].copy_from_slice(head);
    for (i, q) in waypoints.iter().enumerate() {
        b[6 * i + 5] = *q;
    }
    let last = b.len() - 3;
    b[last..].copy_from_slice(tail);
}

/// Fills `A(T)` (a `6n × 6n` banded matrix with bandwidths 6) with the row layout documented at
/// module level.
pub(crate) fn build_matrix(a: &mut BandedMatrix, powers: &[[f64; 6]]) {
    let n = powers.len();
    a.clear();
    *a.entry_mut(0, 0) = 1.0;
    *a.entry_mut(1, 1) = 1.0;
    *a.entry_mut(2, 2) = 2.0;
    for (i, pw) in powers[..n - 1].iter().enumerate() {
        let r = 6 * i;
        // Jerk and snap continuity.
        *a.entry_mut(r + 3, r + 3) = 6.0;
        *a.entry_mut(r + 3, r + 4) = 24.0 * pw[1];
        *a.entry_mut(r + 3, r + 5) = 60.0 * pw[2];
        *a.entry_mut(r + 3, r + 9) = -6.0;
        *a.entry_mut(r + 4, r + 4) = 24.0;
        *a.entry_mut(r + 4, r + 5) = 120.0 * pw[1];
        *a.entry_mut(r + 4, r + 10) = -24.0;
        // Waypoint and position continuity.
        for (k, &p) in pw.iter().enumerate() {
            *a.entry_mut(r + 5, r + k) = p;
            *a.entry_mut(r + 6, r + k) = p;
        }
        *a.entry_mut(r + 6, r + 6) = -1.0;
        // Velocity and acceleration continuity.
        write_velocity_row(a, r + 7, r, pw);
        *a.entry_mut(r + 7, r + 7) = -1.0;
        write_acceleration_row(a, r + 8, r, pw);
        *a.entry_mut(r + 8, r + 8) = -2.0;
    }
    // Tail position, velocity, acceleration at the end of the last piece.
    let r = 6 * (n - 1);
    let pw = &powers[n - 1];
    for (k, &p) in pw.iter().enumerate() {
        *a.entry_mut(r + 3, r + k) = p;
    }
    write_velocity_row(a, r + 4, r, pw);
    write_acceleration_row(a, r + 5, r, pw);
}

#[inline(always)]
fn write_velocity_row(a: &mut BandedMatrix, row: usize, col: usize, pw: &[f64; 6]) {
    *a.entry_mut(row, col + 1) = 1.0;
    *a.entry_mut(row, col + 2) = 2.0 * pw[1];
    *a.entry_mut(row, col + 3) = 3.0 * pw[2];
    *a.entry_mut(row, col + 4) = 4.0 * pw[3];
    *a.entry_mut(row, col + 5) = 5.0 * pw[4];
}

#[inline(always)]
fn write_acceleration_row(a: &mut BandedMatrix, row: usize, col: usize, pw: &[f64; 6]) {
    *a.entry_mut(row, col + 2) = 2.0;
    *a.entry_mut(row, col + 3) = 6.0 * pw[1];
    *a.entry_mut(row, col + 4) = 12.0 * pw[2];
    *a.entry_mut(row, col + 5) = 20.0 * pw[3];
}
