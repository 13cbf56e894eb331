//! The interface between the integrator and the cost terms: the node an integrand sees
//! ([`SampleState`]), the partial derivatives it adds ([`SampleGrad`]) and the trait
//! ([`Integrand`]). Below both: the terms implement it, the integrator runs it.

use trust_core::{Aabb, Vec3};

/// Distance (m) by which the obstacle filters grow every obstacle beyond its clearance: far
/// above the rounding of positions (≈ 1e-14 m at 100 m), far below any geometry.
pub(crate) const FILTER_MARGIN_M: f64 = 1e-6;

/// One integration node: where the trajectory is and what the node weighs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampleState {
    /// Piece index `i`.
    pub piece: usize,
    /// Node index `k ∈ 0..=κ` within the piece.
    pub index: usize,
    /// Absolute time `t0 + Σ_{m<i} T_m + k T_i/κ` (s).
    pub t: f64,
    /// Quadrature weight `ω_k T_i / κ` of this node (s).
    pub weight: f64,
    /// Position.
    pub p: Vec3,
    /// Velocity.
    pub v: Vec3,
    /// Acceleration.
    pub a: Vec3,
    /// Jerk.
    pub j: Vec3,
}

/// Partial derivatives of an integrand `L(p, v, a, j, t)` at one node. Integrands **add** into
/// these fields (several terms may share one `SampleGrad`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampleGrad {
    /// `∂L/∂p`.
    pub p: Vec3,
    /// `∂L/∂v`.
    pub v: Vec3,
    /// `∂L/∂a`.
    pub a: Vec3,
    /// `∂L/∂j`.
    pub j: Vec3,
    /// Explicit `∂L/∂t` at fixed `p, v, a, j` (term (b) of paper eq. gradients-of-Io: how moving
    /// obstacles change the cost with absolute time). It couples every earlier duration
    /// (eq. dI-c).
    pub t: f64,
}

impl SampleGrad {
    /// All partial derivatives zero.
    pub const ZERO: SampleGrad = SampleGrad {
        p: Vec3::new(0.0, 0.0, 0.0),
        v: Vec3::new(0.0, 0.0, 0.0),
        a: Vec3::new(0.0, 0.0, 0.0),
        j: Vec3::new(0.0, 0.0, 0.0),
        t: 0.0,
    };

    pub(super) fn is_zero(&self) -> bool {
        self.t == 0.0
            && self.p == Vec3::zeros()
            && self.v == Vec3::zeros()
            && self.a == Vec3::zeros()
            && self.j == Vec3::zeros()
    }
}

impl Default for SampleGrad {
    fn default() -> Self {
        Self::ZERO
    }
}

/// A pointwise cost `L(p, v, a, j, t)` integrated by [`TrapezoidIntegrator`](super::TrapezoidIntegrator).
///
/// The integrator calls [`Integrand::begin_trajectory`] once, then per piece
/// [`Integrand::begin_piece`] and, if that returns `true`, [`Integrand::sample`] at each of the
/// piece's `κ + 1` nodes. The two `begin` hooks receive the axis-aligned box of the sample
/// positions (the only points where `L` is evaluated) and the time window, so that a term can do
/// its broad phase there. Returning `false` from `begin_piece` promises that `L`
/// and its derivatives are zero at every node of that piece.
pub trait Integrand {
    /// Called once per integration with the trajectory's time window and the box of all samples.
    fn begin_trajectory(&mut self, t_begin: f64, t_end: f64, samples_box: &Aabb) {
        let _ = (t_begin, t_end, samples_box);
    }

    /// Called before the nodes of piece `piece` (time window `[t_begin, t_end]`, samples in
    /// `samples_box`). Return `false` if the integrand vanishes on all of them.
    fn begin_piece(&mut self, piece: usize, t_begin: f64, t_end: f64, samples_box: &Aabb) -> bool {
        let _ = (piece, t_begin, t_end, samples_box);
        true
    }

    /// `L` at one node; adds its partial derivatives into `grad`.
    fn sample(&mut self, state: &SampleState, grad: &mut SampleGrad) -> f64;
}
