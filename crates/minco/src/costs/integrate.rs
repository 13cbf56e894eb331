//! Trapezoidal integration of a pointwise cost over a piecewise-quintic trajectory, with the
//! gradients of paper eqs. dI-a, dI-b and dI-c (including the time coupling of moving obstacles).

use trust_core::{Aabb, Vec3};

use crate::error::MincoError;

/// A piecewise-quintic trajectory as the integrator reads it: absolute start time, `6n`
/// coefficient rows (piece `i`, power `k` at row `6i + k`, ascending powers of local time) and `n`
/// durations. This is the layout of [`crate::MincoS3::coeffs`].
#[derive(Debug, Clone, Copy)]
pub struct PiecewiseView<'a> {
    /// Absolute time of the start of the first piece (s).
    pub t_start: f64,
    /// `6n` coefficient rows.
    pub coeffs: &'a [Vec3],
    /// `n` piece durations (s).
    pub durations: &'a [f64],
}

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

    fn is_zero(&self) -> bool {
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

/// A pointwise cost `L(p, v, a, j, t)` integrated by [`TrapezoidIntegrator`].
///
/// The integrator calls [`Integrand::begin_trajectory`] once, then per piece
/// [`Integrand::begin_piece`] and, if that returns `true`, [`Integrand::sample`] at each of the
/// piece's `κ + 1` nodes. The two `begin` hooks receive the axis-aligned box of the sample
/// positions (the only points where `L` is evaluated) and the time window, so that a term can do
/// its broad phase there (design.md §6). Returning `false` from `begin_piece` promises that `L`
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

/// Trapezoidal integration of paper eq. trapezoidal-integration,
/// `I = Σ_i Σ_{k=0}^{κ} ω_k (T_i/κ) L(p_i(k T_i/κ), …, t_k)` (`ω = ½` at both ends, 1 inside),
/// with the gradients
///
/// - eq. dI-a: `∂I/∂c_i = Σ_k ω_k (T_i/κ) Σ_d β_d(s_k) ∂L/∂(d-th derivative)`;
/// - eq. dI-b: `∂I_i/∂T_i = I_i/T_i + Σ_k ω_k (T_i/κ)(k/κ) dL/ds` where `dL/ds` is the total
///   derivative along the piece (ego motion `∂L/∂p·v + ∂L/∂v·a + ∂L/∂a·j + ∂L/∂j·snap` plus the
///   explicit `∂L/∂t`);
/// - eq. dI-c: `∂I_i/∂T_j = Σ_k ω_k (T_i/κ) ∂L/∂t` for every earlier piece `j < i` (absolute time
///   of the nodes of piece `i` moves with every earlier duration).
///
/// Holds its scratch buffers; [`TrapezoidIntegrator::integrate`] allocates only when a trajectory
/// has more pieces than any before.
#[derive(Debug, Clone)]
pub struct TrapezoidIntegrator {
    kappa: usize,
    /// `[p, v, a, j]` at every node, piece by piece.
    nodes: Vec<[Vec3; 4]>,
    /// Box of each piece's node positions.
    boxes: Vec<Aabb>,
    /// Per piece, `Σ_k ω_k (T_i/κ) ∂L/∂t` (the dI-c coupling it sends to earlier pieces).
    coupling: Vec<f64>,
}

impl TrapezoidIntegrator {
    /// An integrator with `kappa` intervals per piece (`κ + 1` nodes); `kappa = 0` is raised to 1.
    pub fn new(kappa: usize) -> Self {
        Self {
            kappa: kappa.max(1),
            nodes: Vec::new(),
            boxes: Vec::new(),
            coupling: Vec::new(),
        }
    }

    /// Intervals per piece `κ`.
    pub fn kappa(&self) -> usize {
        self.kappa
    }

    /// Integrates `integrand` over `traj`, **adds** `∂I/∂c` into `grad_c` (`6n` rows) and the
    /// explicit `∂I/∂T` (eqs. dI-b and dI-c; the part through the coefficients comes from MINCO's
    /// adjoint) into `grad_t` (`n` entries), and returns `I`.
    ///
    /// # Errors
    /// [`MincoError::LengthMismatch`] if the coefficient or gradient buffers do not match the
    /// number of durations.
    pub fn integrate<I: Integrand + ?Sized>(
        &mut self,
        traj: &PiecewiseView<'_>,
        integrand: &mut I,
        grad_c: &mut [Vec3],
        grad_t: &mut [f64],
    ) -> Result<f64, MincoError> {
        let n = traj.durations.len();
        check_len("coeffs", 6 * n, traj.coeffs.len())?;
        check_len("grad_c", 6 * n, grad_c.len())?;
        check_len("grad_t", n, grad_t.len())?;
        if n == 0 {
            return Ok(0.0);
        }
        let kappa = self.kappa;
        let kf = kappa as f64;

        // Pass 1: node derivatives and per-piece boxes.
        self.nodes.clear();
        self.boxes.clear();
        let mut all = Aabb {
            min: Vec3::repeat(f64::INFINITY),
            max: Vec3::repeat(f64::NEG_INFINITY),
        };
        for (c, &duration) in traj.coeffs.chunks_exact(6).zip(traj.durations) {
            let h = duration / kf;
            let mut b = Aabb {
                min: Vec3::repeat(f64::INFINITY),
                max: Vec3::repeat(f64::NEG_INFINITY),
            };
            for k in 0..=kappa {
                let node = node_derivatives(c, k as f64 * h);
                b.min = b.min.inf(&node[0]);
                b.max = b.max.sup(&node[0]);
                self.nodes.push(node);
            }
            all = all.union(&b);
            self.boxes.push(b);
        }
        let t_end = traj.t_start + traj.durations.iter().sum::<f64>();
        integrand.begin_trajectory(traj.t_start, t_end, &all);

        // Pass 2: the integrand at every node of every piece its broad phase keeps.
        self.coupling.clear();
        self.coupling.resize(n, 0.0);
        let mut total = 0.0;
        let mut piece_start = traj.t_start;
        for i in 0..n {
            let duration = traj.durations[i];
            let piece_end = piece_start + duration;
            let h = duration / kf;
            if integrand.begin_piece(i, piece_start, piece_end, &self.boxes[i]) {
                let c = &traj.coeffs[6 * i..6 * i + 6];
                let (gc, gt) = (&mut grad_c[6 * i..6 * i + 6], &mut grad_t[i]);
                for k in 0..=kappa {
                    let [p, v, a, j] = self.nodes[i * (kappa + 1) + k];
                    let omega = if k == 0 || k == kappa { 0.5 } else { 1.0 };
                    let s = k as f64 * h;
                    let state = SampleState {
                        piece: i,
                        index: k,
                        t: piece_start + s,
                        weight: omega * h,
                        p,
                        v,
                        a,
                        j,
                    };
                    let mut g = SampleGrad::ZERO;
                    let value = integrand.sample(&state, &mut g);
                    if value == 0.0 && g.is_zero() {
                        continue;
                    }
                    let w = state.weight;
                    total += w * value;
                    add_coefficient_grad(gc, s, &g, w);
                    let snap = if g.j == Vec3::zeros() {
                        Vec3::zeros()
                    } else {
                        c[4] * 24.0 + c[5] * (120.0 * s)
                    };
                    let along = g.p.dot(&v) + g.v.dot(&a) + g.a.dot(&j) + g.j.dot(&snap) + g.t;
                    *gt += omega / kf * value + w * (k as f64 / kf) * along;
                    self.coupling[i] += w * g.t;
                }
            }
            piece_start = piece_end;
        }
        // eq. dI-c: piece j collects the explicit-time terms of every later piece.
        let mut later = 0.0;
        for i in (0..n).rev() {
            grad_t[i] += later;
            later += self.coupling[i];
        }
        Ok(total)
    }
}

/// `[p, v, a, j]` of a piece at local time `s` (Horner form).
#[inline(always)]
fn node_derivatives(c: &[Vec3], s: f64) -> [Vec3; 4] {
    let p = ((((c[5] * s + c[4]) * s + c[3]) * s + c[2]) * s + c[1]) * s + c[0];
    let v = (((c[5] * (5.0 * s) + c[4] * 4.0) * s + c[3] * 3.0) * s + c[2] * 2.0) * s + c[1];
    let a = ((c[5] * (20.0 * s) + c[4] * 12.0) * s + c[3] * 6.0) * s + c[2] * 2.0;
    let j = (c[5] * (60.0 * s) + c[4] * 24.0) * s + c[3] * 6.0;
    [p, v, a, j]
}

/// `grad_c[m] += w Σ_d β_d[m](s) ∂L/∂(d-th derivative)` for the six coefficients of one piece,
/// with `β_d[m] = m!/(m−d)! s^{m−d}` written out (the zero entries of the basis skipped).
#[inline(always)]
fn add_coefficient_grad(grad_c: &mut [Vec3], s: f64, g: &SampleGrad, w: f64) {
    let (p, v, a) = (g.p * w, g.v * w, g.a * w);
    let (s2, s3) = (s * s, s * s * s);
    let s4 = s2 * s2;
    grad_c[0] += p;
    grad_c[1] += p * s + v;
    grad_c[2] += p * s2 + v * (2.0 * s) + a * 2.0;
    grad_c[3] += p * s3 + v * (3.0 * s2) + a * (6.0 * s);
    grad_c[4] += p * s4 + v * (4.0 * s3) + a * (12.0 * s2);
    grad_c[5] += p * (s4 * s) + v * (5.0 * s4) + a * (20.0 * s3);
    if g.j != Vec3::zeros() {
        let j = g.j * w;
        grad_c[3] += j * 6.0;
        grad_c[4] += j * (24.0 * s);
        grad_c[5] += j * (60.0 * s2);
    }
}

fn check_len(field: &'static str, expected: usize, got: usize) -> Result<(), MincoError> {
    if expected == got {
        Ok(())
    } else {
        Err(MincoError::LengthMismatch {
            field,
            expected,
            got,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// `L = ‖p‖²` (no time dependence).
    struct SquaredNorm;
    impl Integrand for SquaredNorm {
        fn sample(&mut self, s: &SampleState, g: &mut SampleGrad) -> f64 {
            g.p += 2.0 * s.p;
            s.p.norm_squared()
        }
    }

    #[test]
    fn integrates_a_constant_exactly() {
        struct One;
        impl Integrand for One {
            fn sample(&mut self, _: &SampleState, _: &mut SampleGrad) -> f64 {
                1.0
            }
        }
        let coeffs = vec![Vec3::zeros(); 12];
        let durations = [0.7, 1.1];
        let view = PiecewiseView {
            t_start: 3.0,
            coeffs: &coeffs,
            durations: &durations,
        };
        let mut gc = vec![Vec3::zeros(); 12];
        let mut gt = vec![0.0; 2];
        let v = TrapezoidIntegrator::new(4)
            .integrate(&view, &mut One, &mut gc, &mut gt)
            .unwrap();
        assert_relative_eq!(v, 1.8, epsilon = 1e-12);
        // ∂I/∂T_i = 1 for a constant integrand.
        assert_relative_eq!(gt[0], 1.0, epsilon = 1e-12);
        assert_relative_eq!(gt[1], 1.0, epsilon = 1e-12);
    }

    #[test]
    fn converges_to_the_integral_of_a_line() {
        // p(t) = (t, 0, 0) on [0, 2]: ∫ t² = 8/3.
        let mut coeffs = vec![Vec3::zeros(); 6];
        coeffs[1] = Vec3::x();
        let durations = [2.0];
        let view = PiecewiseView {
            t_start: 0.0,
            coeffs: &coeffs,
            durations: &durations,
        };
        let mut gc = vec![Vec3::zeros(); 6];
        let mut gt = vec![0.0];
        let v = TrapezoidIntegrator::new(1000)
            .integrate(&view, &mut SquaredNorm, &mut gc, &mut gt)
            .unwrap();
        assert_relative_eq!(v, 8.0 / 3.0, epsilon = 1e-5);
        // d/dT ∫₀ᵀ t² dt = T² = 4.
        assert_relative_eq!(gt[0], 4.0, epsilon = 1e-4);
    }

    #[test]
    fn rejects_mismatched_buffers() {
        let coeffs = vec![Vec3::zeros(); 6];
        let view = PiecewiseView {
            t_start: 0.0,
            coeffs: &coeffs,
            durations: &[1.0, 1.0],
        };
        let mut gc = vec![Vec3::zeros(); 12];
        let mut gt = vec![0.0; 2];
        let e = TrapezoidIntegrator::new(4)
            .integrate(&view, &mut SquaredNorm, &mut gc, &mut gt)
            .unwrap_err();
        assert!(matches!(
            e,
            MincoError::LengthMismatch {
                field: "coeffs",
                ..
            }
        ));
    }
}
