//! Trapezoidal integration of a pointwise cost over a piecewise-quintic trajectory, with the
//! gradients of paper eqs. dI-a, dI-b and dI-c (including the time coupling of moving obstacles).

use trust_core::{Aabb, Vec3};

use super::integrand::{Integrand, SampleGrad, SampleState};
use crate::error::MincoError;

mod fused;

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
///
/// # Implementation
///
/// The nodes sit at the same fractions `u_k = k/κ` of every piece, so the integrator keeps the
/// powers `u_k^e` in a table and works with each piece's coefficients scaled to `u`: node values
/// are sums of independent products (no Horner chain, no powers computed per node), and
/// `∂I/∂c` is gathered per piece as the moments `Σ_k ω_k h ∂L/∂(d-th derivative) u_k^e`, which
/// are turned into coefficient gradients once per piece (`β_d` of `s = uT` factorizes into
/// `u^e T^e`).
///
/// The backends' objectives use a crate-private rule for their fused penalties
/// ([`PenaltyIntegrand`](crate::costs::PenaltyIntegrand)) in the same quadrature loop: it
/// evaluates only the nodes where a penalty can be active and gives the same result bit for bit
/// (module `fused`, tested against this generic path).
#[derive(Debug, Clone)]
pub struct TrapezoidIntegrator {
    kappa: usize,
    /// `[1, u, u², u³, u⁴, u⁵]` at every node fraction `u_k = k/κ`.
    u_powers: Vec<[f64; 6]>,
    /// `[p, v, a, j]` at every node, piece by piece ([`TrapezoidIntegrator::integrate`]).
    nodes: Vec<[Vec3; 4]>,
    /// Box of the points each piece's rule evaluates (its broad phase).
    boxes: Vec<Aabb>,
    /// Per piece, `Σ_k ω_k (T_i/κ) ∂L/∂t` (the dI-c coupling it sends to earlier pieces).
    coupling: Vec<f64>,
    /// Scaled coefficients of every piece.
    scaled: Vec<ScaledPiece>,
    /// Column-wise node scratch of the objective's rule ([`TrapezoidIntegrator::integrate_penalties`]).
    columns: fused::NodeColumns,
}

impl TrapezoidIntegrator {
    /// An integrator with `kappa` intervals per piece (`κ + 1` nodes); `kappa = 0` is raised to 1.
    pub fn new(kappa: usize) -> Self {
        let kappa = kappa.max(1);
        let u_powers: Vec<[f64; 6]> = (0..=kappa)
            .map(|k| {
                let u = k as f64 / kappa as f64;
                let mut pw = [1.0; 6];
                for e in 1..6 {
                    pw[e] = pw[e - 1] * u;
                }
                pw
            })
            .collect();
        Self {
            kappa,
            columns: fused::NodeColumns::new(&u_powers),
            u_powers,
            nodes: Vec::new(),
            boxes: Vec::new(),
            coupling: Vec::new(),
            scaled: Vec::new(),
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
        let mut rule = EveryNode {
            integrand,
            nodes: std::mem::take(&mut self.nodes),
            node_count: 0,
        };
        let result = self.run(traj, &mut rule, grad_c, grad_t, f64::INFINITY);
        self.nodes = rule.nodes;
        result.map(|(total, _)| total)
    }

    /// The quadrature both paths share: scales every piece and asks `rule` for the box of the
    /// points it will evaluate there (pass 1), gives the rule the whole trajectory's window and
    /// box, then adds each piece's integral, `∂I/∂c` and explicit `∂I/∂T` (pass 2), and finally the
    /// dI-c coupling of every piece into the earlier durations.
    ///
    /// Stops after the first piece where the running total exceeds `limit` and returns `(total so
    /// far, false)` (the gradients are then incomplete); otherwise `(total, true)`.
    fn run<R: PieceRule>(
        &mut self,
        traj: &PiecewiseView<'_>,
        rule: &mut R,
        grad_c: &mut [Vec3],
        grad_t: &mut [f64],
        limit: f64,
    ) -> Result<(f64, bool), MincoError> {
        let n = traj.durations.len();
        check_len("coeffs", 6 * n, traj.coeffs.len())?;
        check_len("grad_c", 6 * n, grad_c.len())?;
        check_len("grad_t", n, grad_t.len())?;
        if n == 0 {
            return Ok((0.0, true));
        }

        // Pass 1: scaled coefficients and the boxes of the points each piece is evaluated at.
        self.scaled.clear();
        self.boxes.clear();
        let mut all = Aabb {
            min: Vec3::repeat(f64::INFINITY),
            max: Vec3::repeat(f64::NEG_INFINITY),
        };
        for (c, &duration) in traj.coeffs.chunks_exact(6).zip(traj.durations) {
            let scaled = ScaledPiece::new(c, duration);
            let b = rule.piece_box(self.scaled.len(), &scaled, &self.u_powers);
            // Union of the piece boxes (a `points_box` of the corners would take the initial
            // ±∞ corners as points and span everything).
            all = all.union(&b);
            self.boxes.push(b);
            self.scaled.push(scaled);
        }
        let t_end = traj.t_start + traj.durations.iter().sum::<f64>();
        rule.begin_trajectory(traj.t_start, t_end, &all);

        // Pass 2: every piece the rule does not skip.
        self.coupling.clear();
        self.coupling.resize(n, 0.0);
        let mut total = 0.0;
        let mut piece_start = traj.t_start;
        for i in 0..n {
            let duration = traj.durations[i];
            let piece = rule.piece(PieceContext {
                index: i,
                start: piece_start,
                duration,
                coeffs: &traj.coeffs[6 * i..6 * i + 6],
                scaled: &self.scaled[i],
                bounds: &self.boxes[i],
                kappa: self.kappa,
                u_powers: &self.u_powers,
                columns: &mut self.columns,
            });
            if let Some(piece) = piece
                && piece.active
            {
                total += piece.value;
                piece
                    .moments
                    .add_to(&mut grad_c[6 * i..6 * i + 6], duration);
                grad_t[i] += piece.grad_t;
                self.coupling[i] += piece.coupling;
                if total > limit {
                    return Ok((total, false));
                }
            }
            piece_start += duration;
        }
        // eq. dI-c: piece j collects the explicit-time terms of every later piece.
        let mut later = 0.0;
        for i in (0..n).rev() {
            grad_t[i] += later;
            later += self.coupling[i];
        }
        Ok((total, true))
    }
}

/// What [`TrapezoidIntegrator::run`] hands a rule for one piece.
struct PieceContext<'a> {
    /// Piece index `i`.
    index: usize,
    /// Absolute start time of the piece (s).
    start: f64,
    /// Duration `T_i` (s).
    duration: f64,
    /// The piece's six coefficient rows.
    coeffs: &'a [Vec3],
    /// The coefficients scaled to the node fraction.
    scaled: &'a ScaledPiece,
    /// The box [`PieceRule::piece_box`] gave for this piece.
    bounds: &'a Aabb,
    /// Intervals per piece `κ`.
    kappa: usize,
    /// `[1, u, …, u⁵]` at every node fraction.
    u_powers: &'a [[f64; 6]],
    /// Column-wise node scratch (used by the objective's rule).
    columns: &'a mut fused::NodeColumns,
}

/// Which nodes an integration evaluates and how: [`EveryNode`] (the public path, any
/// [`Integrand`], every node of every piece its broad phase keeps) or the objective's penalties
/// at the nodes their filters flag (module `fused`).
trait PieceRule {
    /// Box of the points the rule evaluates on piece `index` (the broad phase's input); called
    /// for every piece in order before any [`PieceRule::piece`].
    fn piece_box(&mut self, index: usize, piece: &ScaledPiece, u_powers: &[[f64; 6]]) -> Aabb;

    /// The whole trajectory's time window and the union of the piece boxes.
    fn begin_trajectory(&mut self, t_begin: f64, t_end: f64, all: &Aabb);

    /// The piece's contribution, or `None` if the rule skips it (its integrand vanishes there).
    fn piece(&mut self, ctx: PieceContext<'_>) -> Option<PieceIntegral>;
}

/// The generic rule: an [`Integrand`] at every node of every piece its broad phase keeps. The node
/// states are computed once, for the boxes, and kept for the integrand.
struct EveryNode<'i, I: ?Sized> {
    integrand: &'i mut I,
    /// `[p, v, a, j]` at every node of the pieces seen so far (the integrator's scratch).
    nodes: Vec<[Vec3; 4]>,
    /// Nodes per piece (`κ + 1`).
    node_count: usize,
}

impl<I: Integrand + ?Sized> PieceRule for EveryNode<'_, I> {
    #[inline(always)]
    fn piece_box(&mut self, index: usize, piece: &ScaledPiece, u_powers: &[[f64; 6]]) -> Aabb {
        self.node_count = u_powers.len();
        if index == 0 {
            self.nodes.clear();
        }
        let first = self.nodes.len();
        self.nodes.extend(u_powers.iter().map(|u| piece.at(u)));
        let mut b = Aabb {
            min: Vec3::repeat(f64::INFINITY),
            max: Vec3::repeat(f64::NEG_INFINITY),
        };
        for node in &self.nodes[first..] {
            b.min = b.min.inf(&node[0]);
            b.max = b.max.sup(&node[0]);
        }
        b
    }

    fn begin_trajectory(&mut self, t_begin: f64, t_end: f64, all: &Aabb) {
        self.integrand.begin_trajectory(t_begin, t_end, all);
    }

    #[inline(always)]
    fn piece(&mut self, ctx: PieceContext<'_>) -> Option<PieceIntegral> {
        let integrand = &mut *self.integrand;
        let piece_end = ctx.start + ctx.duration;
        if !integrand.begin_piece(ctx.index, ctx.start, piece_end, ctx.bounds) {
            return None;
        }
        let m = self.node_count;
        let nodes = &self.nodes[ctx.index * m..(ctx.index + 1) * m];
        let kappa = ctx.kappa;
        let inv_kappa = 1.0 / kappa as f64;
        let h = ctx.duration * inv_kappa;
        let mut out = PieceIntegral::ZERO;
        for (k, (node, u)) in nodes.iter().zip(ctx.u_powers).enumerate() {
            let [p, v, a, j] = *node;
            let omega = if k == 0 || k == kappa { 0.5 } else { 1.0 };
            let weight = omega * h;
            let s = u[1] * ctx.duration;
            let state = SampleState {
                piece: ctx.index,
                index: k,
                t: ctx.start + s,
                weight,
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
            out.active = true;
            out.value += weight * value;
            let has_jerk = g.j != Vec3::zeros();
            out.moments.add(&g, weight, u, has_jerk);
            let mut along = g.p.dot(&v) + g.v.dot(&a) + g.a.dot(&j) + g.t;
            if has_jerk {
                let snap = ctx.coeffs[4] * 24.0 + ctx.coeffs[5] * (120.0 * s);
                along += g.j.dot(&snap);
            }
            out.grad_t += omega * inv_kappa * value + weight * u[1] * along;
            out.coupling += weight * g.t;
        }
        Some(out)
    }
}

/// What one piece contributes: `I_i`, the moments for `∂I/∂c_i`, the explicit `∂I_i/∂T_i` and the
/// dI-c coupling; `active` if any node contributed.
struct PieceIntegral {
    active: bool,
    value: f64,
    moments: Moments,
    grad_t: f64,
    coupling: f64,
}

impl PieceIntegral {
    const ZERO: PieceIntegral = PieceIntegral {
        active: false,
        value: 0.0,
        moments: Moments::ZERO,
        grad_t: 0.0,
        coupling: 0.0,
    };
}

/// A piece's coefficients rescaled to the node fraction `u = s/T`: position, velocity,
/// acceleration and jerk are `Σ_e X_e u^e` with the `X` below.
#[derive(Debug, Clone, Copy)]
struct ScaledPiece {
    p: [Vec3; 6],
    v: [Vec3; 5],
    a: [Vec3; 4],
    j: [Vec3; 3],
}

impl ScaledPiece {
    #[inline(always)]
    fn new(c: &[Vec3], duration: f64) -> Self {
        let t = duration;
        let tp = [1.0, t, t * t, t * t * t, t * t * t * t, t * t * t * t * t];
        let p = [
            c[0],
            c[1] * tp[1],
            c[2] * tp[2],
            c[3] * tp[3],
            c[4] * tp[4],
            c[5] * tp[5],
        ];
        // d/ds of Σ c_m s^m = Σ m c_m s^{m−1}; with s = uT, s^{m−1} = u^{m−1} T^{m−1}.
        let v = [
            c[1],
            c[2] * (2.0 * tp[1]),
            c[3] * (3.0 * tp[2]),
            c[4] * (4.0 * tp[3]),
            c[5] * (5.0 * tp[4]),
        ];
        let a = [
            c[2] * 2.0,
            c[3] * (6.0 * tp[1]),
            c[4] * (12.0 * tp[2]),
            c[5] * (20.0 * tp[3]),
        ];
        let j = [c[3] * 6.0, c[4] * (24.0 * tp[1]), c[5] * (60.0 * tp[2])];
        Self { p, v, a, j }
    }

    /// `[p, v, a, j]` at the node with powers `u = [1, u, …, u⁵]`.
    #[inline(always)]
    fn at(&self, u: &[f64; 6]) -> [Vec3; 4] {
        let p = self.p[0]
            + self.p[1] * u[1]
            + self.p[2] * u[2]
            + self.p[3] * u[3]
            + self.p[4] * u[4]
            + self.p[5] * u[5];
        let v =
            self.v[0] + self.v[1] * u[1] + self.v[2] * u[2] + self.v[3] * u[3] + self.v[4] * u[4];
        let a = self.a[0] + self.a[1] * u[1] + self.a[2] * u[2] + self.a[3] * u[3];
        let j = self.j[0] + self.j[1] * u[1] + self.j[2] * u[2];
        [p, v, a, j]
    }

    /// Position at the node with powers `u`.
    #[inline(always)]
    fn position(&self, u: &[f64; 6]) -> Vec3 {
        self.p[0]
            + self.p[1] * u[1]
            + self.p[2] * u[2]
            + self.p[3] * u[3]
            + self.p[4] * u[4]
            + self.p[5] * u[5]
    }

    /// Velocity at the node with powers `u`.
    #[inline(always)]
    fn velocity(&self, u: &[f64; 6]) -> Vec3 {
        self.v[0] + self.v[1] * u[1] + self.v[2] * u[2] + self.v[3] * u[3] + self.v[4] * u[4]
    }

    /// Acceleration at the node with powers `u`.
    #[inline(always)]
    fn acceleration(&self, u: &[f64; 6]) -> Vec3 {
        self.a[0] + self.a[1] * u[1] + self.a[2] * u[2] + self.a[3] * u[3]
    }

    /// Jerk at the node with powers `u`.
    #[inline(always)]
    fn jerk(&self, u: &[f64; 6]) -> Vec3 {
        self.j[0] + self.j[1] * u[1] + self.j[2] * u[2]
    }

    /// The position's Bernstein (Bézier) control points on `u ∈ [0, 1]`,
    /// `b_k = Σ_{e ≤ k} C(k, e)/C(5, e) X_e`: by the convex-hull property their convex hull
    /// contains the whole piece, hence every node.
    #[inline(always)]
    fn bernstein_positions(&self) -> [Vec3; 6] {
        trust_core::bernstein_points(&self.p)
    }
}

/// The box of a set of points (empty: inverted infinite box; NaN coordinates are skipped).
#[inline(always)]
fn points_box(points: &[Vec3]) -> Aabb {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    for q in points {
        for k in 0..3 {
            lo[k] = if q[k] < lo[k] { q[k] } else { lo[k] };
            hi[k] = if q[k] > hi[k] { q[k] } else { hi[k] };
        }
    }
    Aabb {
        min: Vec3::from(lo),
        max: Vec3::from(hi),
    }
}

/// Per-piece moments `M_{d,e} = Σ_k w_k ∂L/∂(d-th derivative)_k u_k^e` (`d = 0..3`,
/// `e ≤ 5 − d`), from which `∂I/∂c_m = Σ_d m!/(m−d)! T^{m−d} M_{d,m−d}` (eq. dI-a with
/// `β_d,m(s) = m!/(m−d)! s^{m−d}` and `s = uT`).
struct Moments {
    p: [Vec3; 6],
    v: [Vec3; 5],
    a: [Vec3; 4],
    j: [Vec3; 3],
}

impl Moments {
    const ZERO: Moments = Moments {
        p: [Vec3::new(0.0, 0.0, 0.0); 6],
        v: [Vec3::new(0.0, 0.0, 0.0); 5],
        a: [Vec3::new(0.0, 0.0, 0.0); 4],
        j: [Vec3::new(0.0, 0.0, 0.0); 3],
    };

    #[inline(always)]
    fn add(&mut self, g: &SampleGrad, w: f64, u: &[f64; 6], has_jerk: bool) {
        let (gp, gv, ga) = (g.p * w, g.v * w, g.a * w);
        for (m, ue) in self.p.iter_mut().zip(u) {
            *m += gp * *ue;
        }
        for (m, ue) in self.v.iter_mut().zip(u) {
            *m += gv * *ue;
        }
        for (m, ue) in self.a.iter_mut().zip(u) {
            *m += ga * *ue;
        }
        if has_jerk {
            let gj = g.j * w;
            for (m, ue) in self.j.iter_mut().zip(u) {
                *m += gj * *ue;
            }
        }
    }

    /// Adds the moments of one derivative order `d` (0: position, 1: velocity, 2:
    /// acceleration, 3: jerk) for the partial derivative `g` at a node of weight `w` and powers `u`.
    #[inline(always)]
    fn add_order(&mut self, order: usize, g: &Vec3, w: f64, u: &[f64; 6]) {
        let gw = g * w;
        let moments: &mut [Vec3] = match order {
            0 => &mut self.p,
            1 => &mut self.v,
            2 => &mut self.a,
            _ => &mut self.j,
        };
        for (m, ue) in moments.iter_mut().zip(u) {
            *m += gw * *ue;
        }
    }

    /// `grad_c[m] += Σ_d m!/(m−d)! T^{m−d} M_{d,m−d}` for the six coefficients of the piece.
    #[inline(always)]
    fn add_to(&self, grad_c: &mut [Vec3], duration: f64) {
        let t = duration;
        let tp = [1.0, t, t * t, t * t * t, t * t * t * t, t * t * t * t * t];
        let (p, v, a, j) = (&self.p, &self.v, &self.a, &self.j);
        grad_c[0] += p[0];
        grad_c[1] += p[1] * tp[1] + v[0];
        grad_c[2] += p[2] * tp[2] + v[1] * (2.0 * tp[1]) + a[0] * 2.0;
        grad_c[3] += p[3] * tp[3] + v[2] * (3.0 * tp[2]) + a[1] * (6.0 * tp[1]) + j[0] * 6.0;
        grad_c[4] +=
            p[4] * tp[4] + v[3] * (4.0 * tp[3]) + a[2] * (12.0 * tp[2]) + j[1] * (24.0 * tp[1]);
        grad_c[5] +=
            p[5] * tp[5] + v[4] * (5.0 * tp[4]) + a[3] * (20.0 * tp[3]) + j[2] * (60.0 * tp[2]);
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
    use proptest::prelude::*;

    /// A smooth integrand that uses every input, including jerk and absolute time:
    /// `L = ½‖p − a₀‖² + v·a + ‖j‖² sin(t) + 0.3 t p_x`.
    struct Everything;
    impl Integrand for Everything {
        fn sample(&mut self, s: &SampleState, g: &mut SampleGrad) -> f64 {
            let a0 = Vec3::new(0.5, -0.2, 0.1);
            g.p += s.p - a0 + Vec3::x() * (0.3 * s.t);
            g.v += s.a;
            g.a += s.v;
            g.j += s.j * (2.0 * s.t.sin());
            g.t += s.j.norm_squared() * s.t.cos() + 0.3 * s.p.x;
            0.5 * (s.p - a0).norm_squared()
                + s.v.dot(&s.a)
                + s.j.norm_squared() * s.t.sin()
                + 0.3 * s.t * s.p.x
        }
    }

    fn integral(coeffs: &[Vec3], durations: &[f64], t_start: f64) -> (f64, Vec<Vec3>, Vec<f64>) {
        let view = PiecewiseView {
            t_start,
            coeffs,
            durations,
        };
        let mut gc = vec![Vec3::zeros(); coeffs.len()];
        let mut gt = vec![0.0; durations.len()];
        let v = TrapezoidIntegrator::new(5)
            .integrate(&view, &mut Everything, &mut gc, &mut gt)
            .unwrap();
        (v, gc, gt)
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 32, ..ProptestConfig::default() })]

        /// eqs. dI-a/b/c against central differences, with every derivative order and the
        /// explicit time dependence in play (the moments and the snap term of `∂I/∂T`).
        #[test]
        fn coefficient_and_duration_gradients_match_finite_differences(
            raw in proptest::collection::vec(-1.0..1.0f64, 36),
            d0 in 0.3..1.2f64, d1 in 0.3..1.2f64,
        ) {
            let coeffs: Vec<Vec3> = raw.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect();
            let durations = [d0, d1];
            let (_, gc, gt) = integral(&coeffs, &durations, 0.4);
            let h = 1e-6;
            for row in 0..coeffs.len() {
                for axis in 0..3 {
                    let fd = trust_numdiff::central_difference(|s| {
                        let mut probe = coeffs.clone();
                        probe[row][axis] += s;
                        integral(&probe, &durations, 0.4).0
                    }, 0.0, h);
                    prop_assert!((fd - gc[row][axis]).abs() <= 1e-6 * (1.0 + fd.abs()),
                        "c[{row}][{axis}]: fd {fd} vs {}", gc[row][axis]);
                }
            }
            for i in 0..2 {
                let fd = trust_numdiff::central_difference(|s| {
                    let mut probe = durations;
                    probe[i] += s;
                    integral(&coeffs, &probe, 0.4).0
                }, 0.0, h);
                prop_assert!((fd - gt[i]).abs() <= 1e-5 * (1.0 + fd.abs()), "T[{i}]: fd {fd} vs {}", gt[i]);
            }
        }
    }

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

    /// The box `begin_trajectory` receives is the tight box of the samples (it once spanned all
    /// of space, which switched the moving-obstacle term's per-trajectory broad phase off).
    #[test]
    fn the_trajectory_box_is_the_box_of_the_samples() {
        struct Recorder {
            trajectory_box: Option<Aabb>,
            samples: Vec<Vec3>,
        }
        impl Integrand for Recorder {
            fn begin_trajectory(&mut self, _: f64, _: f64, samples_box: &Aabb) {
                self.trajectory_box = Some(*samples_box);
            }
            fn sample(&mut self, s: &SampleState, _: &mut SampleGrad) -> f64 {
                self.samples.push(s.p);
                0.0
            }
        }
        let mut coeffs = vec![Vec3::zeros(); 12];
        coeffs[0] = Vec3::new(1.0, 2.0, 3.0);
        coeffs[1] = Vec3::new(1.0, -1.0, 0.5);
        coeffs[6] = Vec3::new(2.0, 1.0, 3.5);
        coeffs[7] = Vec3::new(0.0, 2.0, 0.0);
        let durations = [1.0, 0.5];
        let view = PiecewiseView {
            t_start: 0.0,
            coeffs: &coeffs,
            durations: &durations,
        };
        let mut rec = Recorder {
            trajectory_box: None,
            samples: Vec::new(),
        };
        let (mut gc, mut gt) = (vec![Vec3::zeros(); 12], vec![0.0; 2]);
        TrapezoidIntegrator::new(8)
            .integrate(&view, &mut rec, &mut gc, &mut gt)
            .unwrap();
        let b = rec.trajectory_box.expect("begin_trajectory was called");
        let tight = Aabb::from_points(&rec.samples).unwrap();
        for k in 0..3 {
            assert!(b.min[k] <= tight.min[k] + 1e-12 && tight.max[k] <= b.max[k] + 1e-12);
            assert!(
                b.min[k] >= tight.min[k] - 1e-9 && b.max[k] <= tight.max[k] + 1e-9,
                "{b:?}"
            );
        }
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
