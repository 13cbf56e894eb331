//! The objective `J` of paper eq. unconstrained-optimization as a function of the decision
//! vector, with its analytic gradient (eqs. analytical-gradients and analytical-gradients-I-to-S):
//! [`UtfMincoObjective`] over `(P, p_f, v_f, τ)` and [`MincoObjective`] over `(P, τ_1..τ_n)`.

use trust_core::{CostBreakdown, Limits, PlanError, PolyTraj, Scene, State, Vec3};

use super::params::PieceParams;
use super::time_map::{positive_time, positive_time_inverse};
use crate::costs::{
    BrakingTail, CostWeights, PenaltyIntegrand, PenaltyParams, PiecewiseView, TerminalCost,
    TrapezoidIntegrator, final_approach_gain,
};
use crate::error::MincoError;
use crate::minco::{BoundaryState, MincoGrad, MincoS3};

/// What both objectives share: MINCO, the sampled penalties, the jerk energy and the adjoint
/// propagation, with all buffers preallocated.
#[derive(Debug, Clone)]
pub(crate) struct ObjectiveCore<'a> {
    minco: MincoS3,
    integrator: TrapezoidIntegrator,
    penalties: PenaltyIntegrand<'a>,
    weights: CostWeights,
    head: BoundaryState,
    t_start: f64,
    tail: BoundaryState,
    waypoints: Vec<Vec3>,
    durations: Vec<f64>,
    grad_c: Vec<Vec3>,
    grad_t: Vec<f64>,
    grad: MincoGrad,
    /// The cost terms of the last finite cost evaluation.
    last: CostBreakdown,
    /// Whether the last cost evaluation was finite (its gradient may then be computed).
    gradient_ready: bool,
}

impl<'a> ObjectiveCore<'a> {
    fn new(
        scene: &Scene<'a>,
        start: &State,
        limits: Limits,
        weights: &CostWeights,
        penalty: &PenaltyParams,
        pieces: usize,
    ) -> Result<Self, PlanError> {
        let minco = MincoS3::new(pieces).map_err(component)?;
        Ok(Self {
            minco,
            integrator: TrapezoidIntegrator::new(penalty.samples_per_piece),
            penalties: PenaltyIntegrand::new(scene.forecasts, scene.map, limits, weights, penalty),
            weights: weights.clone(),
            head: [start.p, start.v, start.a],
            t_start: start.t,
            tail: [start.p, Vec3::zeros(), Vec3::zeros()],
            waypoints: vec![Vec3::zeros(); pieces - 1],
            durations: vec![1.0; pieces],
            grad_c: vec![Vec3::zeros(); 6 * pieces],
            grad_t: vec![0.0; pieces],
            grad: MincoGrad::new(pieces),
            last: CostBreakdown::default(),
            gradient_ready: false,
        })
    }

    fn pieces(&self) -> usize {
        self.durations.len()
    }

    /// Solves MINCO for the current `tail`, `waypoints`, `durations` and integrates the
    /// penalties; returns the weighted `λ_o I_o + λ_d I_d + λ_e I_e` and the unweighted
    /// `[I_o, I_d, I_e]`. Leaves `∂I/∂c`, `∂I/∂T` of the penalties in `grad_c`, `grad_t` for
    /// [`Self::evaluate_gradient`].
    ///
    /// `base` is the rest of the cost (time and terminal terms) and `bound` the caller's bound
    /// ([`UtfMincoObjective::cost_with_bound`]): as soon as `base` plus the energy and the
    /// penalties summed so far exceed `bound` (by a margin far above rounding), it stops and
    /// returns [`Partial::Above`] with that partial cost — every term is non-negative, so the
    /// full cost exceeds `bound` too.
    fn evaluate_cost(&mut self, base: f64, bound: f64) -> Result<Partial, MincoError> {
        let limit = bound + CUT_MARGIN * bound.abs().max(1.0);
        if base > limit {
            return Ok(Partial::Above(base));
        }
        self.minco
            .solve(&self.head, &self.tail, &self.waypoints, &self.durations)?;
        let energy = self.minco.energy();
        let before_penalties = base + self.weights.energy * energy;
        if before_penalties > limit {
            return Ok(Partial::Above(before_penalties));
        }
        self.grad_c.fill(Vec3::zeros());
        self.grad_t.fill(0.0);
        self.penalties.reset_integrals();
        let view = PiecewiseView {
            t_start: self.t_start,
            coeffs: self.minco.coeffs(),
            durations: self.minco.durations(),
        };
        let (sampled, complete) = self.integrator.integrate_penalties(
            &view,
            &mut self.penalties,
            &mut self.grad_c,
            &mut self.grad_t,
            limit - before_penalties,
        )?;
        if !complete {
            return Ok(Partial::Above(before_penalties + sampled));
        }
        let integrals = self.penalties.integrals();
        Ok(Partial::Complete(
            sampled + self.weights.energy * energy,
            [integrals.obstacle(), integrals.feasibility(), energy],
        ))
    }

    /// After [`Self::evaluate_cost`]: adds the jerk energy's gradient and propagates everything
    /// through MINCO's adjoint into `self.grad`.
    fn evaluate_gradient(&mut self) -> Result<(), MincoError> {
        self.minco.accumulate_energy_grad(
            self.weights.energy,
            &mut self.grad_c,
            &mut self.grad_t,
        )?;
        self.minco
            .propagate_grad(&self.grad_c, &self.grad_t, &mut self.grad)
    }

    /// Shared start of both objectives' `cost_with_bound`: forgets the last gradient and reads
    /// the inner waypoints from `x`. `false` (nothing read) when `x` is not `dimension` long.
    fn begin_cost(&mut self, x: &[f64], dimension: usize) -> bool {
        self.gradient_ready = false;
        if x.len() != dimension {
            return false;
        }
        for (i, w) in self.waypoints.iter_mut().enumerate() {
            *w = get(x, i);
        }
        true
    }

    /// Shared start of both objectives' `gradient`: checks `g`'s length, computes the core's
    /// gradient (the last cost must be finite; `g` is zeroed if not) and writes the inner
    /// waypoints' part of `g`.
    fn begin_gradient(&mut self, g: &mut [f64], dimension: usize) -> Result<(), PlanError> {
        check_len("g", dimension, g.len())?;
        if let Err(e) = self.gradient_after_cost() {
            g.fill(0.0);
            return Err(e);
        }
        for (i, gw) in self.grad.waypoints.iter().enumerate() {
            put(g, i, gw);
        }
        Ok(())
    }

    /// The last cost must be finite; computes the core's gradient.
    fn gradient_after_cost(&mut self) -> Result<(), PlanError> {
        if !self.gradient_ready {
            return Err(component(MincoError::NotSolved {
                operation: "gradient (no finite cost evaluated)",
            }));
        }
        self.gradient_ready = false;
        self.evaluate_gradient().map_err(component)
    }

    /// Shared end of `cost`: rejects a non-finite cost, records the breakdown, allows the
    /// gradient.
    fn record_cost(&mut self, cost: f64, [ht, hs]: [f64; 2], [io, id, ie]: [f64; 3]) -> f64 {
        if !cost.is_finite() {
            return f64::INFINITY;
        }
        self.last = CostBreakdown {
            ht,
            hs,
            io,
            id,
            ie,
            total: cost,
        };
        self.gradient_ready = true;
        cost
    }

    fn trajectory(&self) -> Result<PolyTraj, PlanError> {
        if !self.minco.is_solved() {
            return Err(component(MincoError::NotSolved {
                operation: "trajectory",
            }));
        }
        PolyTraj::new(
            self.t_start,
            self.minco.durations().to_vec(),
            self.minco.to_pieces(),
        )
    }
}

/// Relative margin (of `max(1, |bound|)`) by which a partial cost must exceed the bound before
/// an evaluation stops early: far above the rounding difference between the partial sums and
/// the cost's own summation order.
const CUT_MARGIN: f64 = 1e-9;

/// What [`ObjectiveCore::evaluate_cost`] found.
enum Partial {
    /// The weighted `λ_o I_o + λ_d I_d + λ_e I_e` and the unweighted `[I_o, I_d, I_e]`.
    Complete(f64, [f64; 3]),
    /// A partial cost (including `base`) above the bound; no gradient available.
    Above(f64),
}

fn component(e: MincoError) -> PlanError {
    PlanError::Component {
        component: "trust-minco".into(),
        source: Box::new(e),
    }
}

/// Writes `v` at `x[3i..3i+3]`.
#[inline]
fn put(x: &mut [f64], i: usize, v: &Vec3) {
    x[3 * i..3 * i + 3].copy_from_slice(v.as_slice());
}

/// Reads `x[3i..3i+3]`.
#[inline]
fn get(x: &[f64], i: usize) -> Vec3 {
    Vec3::new(x[3 * i], x[3 * i + 1], x[3 * i + 2])
}

/// `J` and `∇J` of UTF-MINCO (paper Sec. III-D) over the decision vector
/// `x = [q_1, …, q_{n−1}, p_f, v_f, τ]` (`3(n−1) + 7` entries): inner waypoints, free terminal
/// position and velocity (terminal acceleration fixed at 0), and `τ` with
/// `T_Σ = n·T_min + T(τ)` ([`positive_time`]), uniform `T_i = T_Σ/n`.
///
/// `J = λ_t T_Σ + λ_s H_s(p_f, v_f) + λ_o I_o + λ_d I_d + λ_e I_e` and, per eq.
/// analytical-gradients, `∂J/∂P = ∂I/∂P`, `∂J/∂S = ∂H/∂S + ∂I/∂S` (tail rows of the adjoint, eq.
/// analytical-gradients-I-to-S) and `∂J/∂T_Σ = λ_t + (1/n) Σ_i ∂I/∂T_i`, chained through `dT/dτ`.
///
/// Evaluate with [`eval`](Self::eval) (cost and gradient), or in two halves —
/// [`cost`](Self::cost) / [`cost_with_bound`](Self::cost_with_bound), then
/// [`gradient`](Self::gradient) — as the backend's L-BFGS solve does
/// ([`trust_lbfgs::Lbfgs::minimize_split`]): a line search needs the gradient, and the exact
/// cost, only at some trial points. Both give the same numbers bit for bit.
///
/// ```
/// use trust_core::{Limits, Scene, StaticMap, State, Aabb, Vec3};
/// use trust_minco::backend::{UtfMincoObjective, UtfMincoParams};
///
/// let map = StaticMap::empty(Aabb::new(Vec3::zeros(), Vec3::repeat(10.0))?)?;
/// let scene = Scene::new(&map, &[], 0.0)?;
/// let start = State::at_rest(0.0, Vec3::new(1.0, 1.0, 1.0));
/// let goal = Vec3::new(8.0, 1.0, 1.0);
/// let mut f = UtfMincoObjective::new(&scene, &start, goal, Limits::default(), &UtfMincoParams::default(), 3)?;
/// let mut x = vec![0.0; f.dimension()];
/// let waypoints = [Vec3::new(3.0, 1.0, 1.0), Vec3::new(5.0, 1.0, 1.0)];
/// f.encode(&waypoints, &goal, &Vec3::zeros(), 2.0, &mut x)?;
/// let mut g = vec![0.0; f.dimension()];
/// let j = f.eval(&x, &mut g);
/// assert!(j.is_finite() && g.iter().all(|v| v.is_finite()));
/// // The same in two halves.
/// let mut g2 = vec![0.0; f.dimension()];
/// assert_eq!(f.cost(&x), j);
/// f.gradient(&mut g2)?;
/// assert_eq!(g2, g);
/// // Only "more than 1" is needed: the evaluation may stop early with any value above it.
/// assert!(f.cost_with_bound(&x, 1.0) > 1.0);
/// # Ok::<(), trust_core::PlanError>(())
/// ```
#[derive(Debug, Clone)]
pub struct UtfMincoObjective<'a> {
    core: ObjectiveCore<'a>,
    terminal: TerminalCost,
    min_total: f64,
    /// `∂H_s/∂p_f`, `∂H_s/∂v_f` and `dT/dτ` at the last cost evaluation.
    terminal_grad: (Vec3, Vec3, f64),
    /// The braking tail's samples, deceleration (`a_max`) and per-sample weight
    /// (`v_max / a_max / samples`, the quadrature weight of a stop from full speed).
    tail_setup: (usize, f64, f64, f64),
    /// The braking tail at the last cost evaluation.
    tail: BrakingTail,
}

impl<'a> UtfMincoObjective<'a> {
    /// The objective for `pieces` pieces from `start` toward `goal` in `scene`.
    ///
    /// # Errors
    /// [`PlanError::InvalidInput`] if `pieces == 0` or the parameters are invalid.
    pub fn new(
        scene: &Scene<'a>,
        start: &State,
        goal: Vec3,
        limits: Limits,
        params: &super::UtfMincoParams,
        pieces: usize,
    ) -> Result<Self, PlanError> {
        check_pieces(pieces)?;
        params.validate_objective("params")?;
        Ok(Self {
            core: ObjectiveCore::new(
                scene,
                start,
                limits,
                &params.weights,
                &params.penalty,
                pieces,
            )?,
            terminal: TerminalCost::new(goal, &start.p, &params.penalty).with_approach_gain(
                final_approach_gain(
                    params.weights.time,
                    params.weights.terminal,
                    limits.a_max,
                    params
                        .penalty
                        .jerk_limit(limits.a_max)
                        .unwrap_or(f64::INFINITY),
                    params.penalty.goal_settle_m,
                ),
            ),
            min_total: min_total(&params.pieces, pieces),
            terminal_grad: (Vec3::zeros(), Vec3::zeros(), 0.0),
            tail_setup: {
                let k = params.penalty.braking_tail_samples;
                let decel = params.penalty.braking_tail_decel_fraction * limits.a_max;
                (
                    k,
                    decel,
                    params.penalty.braking_tail_delay_s,
                    limits.v_max / decel / k.max(1) as f64,
                )
            },
            tail: BrakingTail::default(),
        })
    }

    /// Number of pieces `n`.
    pub fn pieces(&self) -> usize {
        SplitCost::pieces(self)
    }

    /// Length of the decision vector, `3(n−1) + 7`.
    pub fn dimension(&self) -> usize {
        3 * (self.pieces() - 1) + 7
    }

    /// The terminal cost `H_s` in use (its `α` follows the schedule of eq. design-of-Hs).
    pub fn terminal(&self) -> &TerminalCost {
        &self.terminal
    }

    /// Pulls the free terminal only to the goal guidance surface of radius `radius` (m) around
    /// the goal instead of the goal itself ([`TerminalCost::eval_objective`]); 0 restores the
    /// paper's `H_s`. [`crate::UtfMinco`] sets it from [`trust_core::TrajRequest::horizon_s`].
    pub fn set_guidance_surface(&mut self, radius: f64) {
        self.terminal = self.terminal.clone().with_guidance_surface(radius);
    }

    /// Overrides the terminal-velocity weight `α` of `H_s` (clamped to `[0, 1]`; non-finite
    /// values are ignored). [`crate::UtfMinco`] sets `α = 1` when the goal lies within the
    /// request's horizon, so that a trajectory that reaches the goal stops there.
    pub fn set_terminal_velocity_weight(&mut self, alpha: f64) {
        if alpha.is_finite() {
            self.terminal.alpha = alpha.clamp(0.0, 1.0);
        }
    }

    /// Writes the decision vector for the given waypoints, terminal state and total duration
    /// (clamped to just above the minimum `n·T_min`).
    ///
    /// # Errors
    /// [`PlanError::InvalidInput`] for wrong lengths.
    pub fn encode(
        &self,
        waypoints: &[Vec3],
        end_position: &Vec3,
        end_velocity: &Vec3,
        total_duration: f64,
        x: &mut [f64],
    ) -> Result<(), PlanError> {
        let n = self.pieces();
        check_len("waypoints", n - 1, waypoints.len())?;
        check_len("x", self.dimension(), x.len())?;
        for (i, w) in waypoints.iter().enumerate() {
            put(x, i, w);
        }
        put(x, n - 1, end_position);
        put(x, n, end_velocity);
        x[3 * n + 3] = positive_time_inverse(total_duration - self.min_total);
        Ok(())
    }

    /// Total duration `T_Σ` encoded in `x`.
    pub fn total_duration(&self, x: &[f64]) -> f64 {
        self.min_total + positive_time(x[x.len() - 1]).0
    }

    /// `J(x)`; writes `∇J` into `g`. Returns `+∞` (with `g` zeroed) where MINCO cannot be solved
    /// or the cost or its gradient is not finite, so that a line search backs off; never NaN.
    /// The same as [`Self::cost`] followed by [`Self::gradient`].
    ///
    /// `x` and `g` must be [`dimension`](Self::dimension) long; otherwise the result is `+∞`.
    pub fn eval(&mut self, x: &[f64], g: &mut [f64]) -> f64 {
        SplitCost::eval(self, x, g)
    }

    /// `J(x)` alone; `+∞` where MINCO cannot be solved, the cost is not finite or `x` has the
    /// wrong length; never NaN. The gradient at `x` can then be had from [`Self::gradient`]
    /// (the line search needs it only at some trial points:
    /// [`trust_lbfgs::Lbfgs::minimize_split`]).
    pub fn cost(&mut self, x: &[f64]) -> f64 {
        self.cost_with_bound(x, f64::INFINITY)
    }

    /// [`Self::cost`] where only a cost up to `bound` is needed exactly: once the (non-negative)
    /// terms summed so far exceed `bound`, the evaluation stops and returns that partial sum,
    /// which is `> bound` (there is then no gradient at `x`). Costs `≤ bound` are exactly those of
    /// [`Self::cost`]. This is what [`trust_lbfgs::SplitObjective::cost`] asks for: a line
    /// search rejects such trial points without needing their exact cost.
    pub fn cost_with_bound(&mut self, x: &[f64], bound: f64) -> f64 {
        let n = self.pieces();
        if !self.core.begin_cost(x, self.dimension()) {
            return f64::INFINITY;
        }
        let (p_f, v_f) = (get(x, n - 1), get(x, n));
        let (t_map, dt_dtau) = positive_time(x[3 * n + 3]);
        let total = self.min_total + t_map;
        self.core.durations.fill(total / n as f64);
        self.core.tail = [p_f, v_f, Vec3::zeros()];
        let (hs_objective, hs_p, hs_v) = self.terminal.eval_objective(&p_f, &v_f);
        let (w_time, w_terminal) = (self.core.weights.time, self.core.weights.terminal);
        let base = w_time * total + w_terminal * hs_objective;
        let (integral, terms) = match self.core.evaluate_cost(base, bound) {
            Ok(Partial::Complete(integral, terms)) => (integral, terms),
            Ok(Partial::Above(partial)) => return partial,
            Err(_) => return f64::INFINITY,
        };
        let (samples, decel, delay, weight) = self.tail_setup;
        self.tail = self.core.penalties.braking_tail(
            &p_f,
            &v_f,
            self.core.t_start + total,
            decel,
            delay,
            samples,
            weight,
        );
        let cost = w_time * total + w_terminal * hs_objective + integral + self.tail.cost;
        let terms = [terms[0] + self.tail.integral, terms[1], terms[2]];
        self.terminal_grad = (hs_p, hs_v, dt_dtau);
        // The breakdown reports the paper's H_s (toward the goal itself) for branch ranking.
        let hs = if self.terminal.surface_radius > 0.0 {
            self.terminal.eval(&p_f, &v_f).0
        } else {
            hs_objective
        };
        self.core.record_cost(cost, [total, hs], terms)
    }

    /// `∇J` at the point of the last [`Self::cost`] call, written into `g`.
    ///
    /// # Errors
    /// [`PlanError::InvalidInput`] if `g` is not [`dimension`](Self::dimension) long;
    /// [`PlanError::Component`] if the last cost was not finite (or none was evaluated) or the
    /// gradient is not finite. `g` is then zeroed.
    pub fn gradient(&mut self, g: &mut [f64]) -> Result<(), PlanError> {
        let n = self.pieces();
        self.core.begin_gradient(g, self.dimension())?;
        let w = &self.core.weights;
        let (hs_p, hs_v, dt_dtau) = self.terminal_grad;
        let grad = &self.core.grad;
        let tail = &self.tail;
        put(g, n - 1, &(grad.tail[0] + hs_p * w.terminal + tail.grad_p));
        put(g, n, &(grad.tail[1] + hs_v * w.terminal + tail.grad_v));
        g[3 * n + 3] = (w.time + grad.uniform_total_duration() + tail.grad_t) * dt_dtau;
        check_gradient(g)
    }

    /// The unweighted cost terms and `J` at the last finite cost evaluation (one that did not
    /// stop early at its bound).
    pub fn breakdown(&self) -> CostBreakdown {
        SplitCost::breakdown(self)
    }

    /// The trajectory of the last evaluation (starts at `start.t`); after a
    /// `cost_with_bound` that stopped before solving MINCO (its time and terminal terms alone
    /// exceeded the bound), that of the evaluation before.
    ///
    /// # Errors
    /// If no evaluation has succeeded yet.
    pub fn trajectory(&self) -> Result<PolyTraj, PlanError> {
        SplitCost::trajectory(self)
    }
}

/// `J` and `∇J` of the original MINCO formulation (fixed terminal state, free per-piece
/// durations; the paper's baseline in Table Sim-A-2) over `x = [q_1, …, q_{n−1}, τ_1, …, τ_n]`
/// (`3(n−1) + n` entries), `T_i = T_min + T(τ_i)`.
///
/// `J = λ_t Σ T_i + λ_s H_s(tail) + λ_o I_o + λ_d I_d + λ_e I_e`; `H_s` is a constant here.
/// `∂J/∂T_i = λ_t + ∂I/∂T_i` (MINCO's duration gradient plus the explicit terms of eqs. dI-b and
/// dI-c), chained through `dT_i/dτ_i`.
#[derive(Debug, Clone)]
pub struct MincoObjective<'a> {
    core: ObjectiveCore<'a>,
    terminal_cost: f64,
    min_duration: f64,
    /// `dT_i/dτ_i` at the last cost evaluation.
    duration_slopes: Vec<f64>,
}

impl<'a> MincoObjective<'a> {
    /// The objective for `pieces` pieces from `start` to the fixed terminal `end` (at rest).
    ///
    /// # Errors
    /// [`PlanError::InvalidInput`] if `pieces == 0` or the parameters are invalid.
    pub fn new(
        scene: &Scene<'a>,
        start: &State,
        end: Vec3,
        goal: Vec3,
        limits: Limits,
        params: &super::MincoParams,
        pieces: usize,
    ) -> Result<Self, PlanError> {
        check_pieces(pieces)?;
        params.validate_objective("params")?;
        let mut core = ObjectiveCore::new(
            scene,
            start,
            limits,
            &params.weights,
            &params.penalty,
            pieces,
        )?;
        core.tail = [end, Vec3::zeros(), Vec3::zeros()];
        let terminal = TerminalCost::new(goal, &start.p, &params.penalty);
        Ok(Self {
            core,
            terminal_cost: terminal.eval(&end, &Vec3::zeros()).0,
            min_duration: params.pieces.min_piece_duration_s,
            duration_slopes: vec![1.0; pieces],
        })
    }

    /// Number of pieces `n`.
    pub fn pieces(&self) -> usize {
        SplitCost::pieces(self)
    }

    /// Length of the decision vector, `3(n−1) + n`.
    pub fn dimension(&self) -> usize {
        4 * self.pieces() - 3
    }

    /// Writes the decision vector for the given waypoints and piece durations (each clamped to
    /// just above `T_min`).
    ///
    /// # Errors
    /// [`PlanError::InvalidInput`] for wrong lengths.
    pub fn encode(
        &self,
        waypoints: &[Vec3],
        durations: &[f64],
        x: &mut [f64],
    ) -> Result<(), PlanError> {
        let n = self.pieces();
        check_len("waypoints", n - 1, waypoints.len())?;
        check_len("durations", n, durations.len())?;
        check_len("x", self.dimension(), x.len())?;
        for (i, w) in waypoints.iter().enumerate() {
            put(x, i, w);
        }
        for (xi, t) in x[3 * (n - 1)..].iter_mut().zip(durations) {
            *xi = positive_time_inverse(t - self.min_duration);
        }
        Ok(())
    }

    /// `J(x)`; writes `∇J` into `g`. Returns `+∞` (with `g` zeroed) where MINCO cannot be solved
    /// or the cost or its gradient is not finite; never NaN. The same as [`Self::cost`] followed
    /// by [`Self::gradient`].
    ///
    /// `x` and `g` must be [`dimension`](Self::dimension) long; otherwise the result is `+∞`.
    pub fn eval(&mut self, x: &[f64], g: &mut [f64]) -> f64 {
        SplitCost::eval(self, x, g)
    }

    /// `J(x)` alone; `+∞` where MINCO cannot be solved, the cost is not finite or `x` has the
    /// wrong length; never NaN. See [`UtfMincoObjective::cost`].
    pub fn cost(&mut self, x: &[f64]) -> f64 {
        self.cost_with_bound(x, f64::INFINITY)
    }

    /// [`Self::cost`], exact only up to `bound`; see [`UtfMincoObjective::cost_with_bound`].
    pub fn cost_with_bound(&mut self, x: &[f64], bound: f64) -> f64 {
        let n = self.pieces();
        if !self.core.begin_cost(x, self.dimension()) {
            return f64::INFINITY;
        }
        let taus = &x[3 * (n - 1)..];
        for ((d, slope), &tau) in self
            .core
            .durations
            .iter_mut()
            .zip(self.duration_slopes.iter_mut())
            .zip(taus)
        {
            let (t, dt_dtau) = positive_time(tau);
            *d = self.min_duration + t;
            *slope = dt_dtau;
        }
        let total: f64 = self.core.durations.iter().sum();
        let (w_time, w_terminal) = (self.core.weights.time, self.core.weights.terminal);
        let hs = self.terminal_cost;
        let base = w_time * total + w_terminal * hs;
        let (integral, terms) = match self.core.evaluate_cost(base, bound) {
            Ok(Partial::Complete(integral, terms)) => (integral, terms),
            Ok(Partial::Above(partial)) => return partial,
            Err(_) => return f64::INFINITY,
        };
        let cost = w_time * total + w_terminal * hs + integral;
        self.core.record_cost(cost, [total, hs], terms)
    }

    /// `∇J` at the point of the last [`Self::cost`] call, written into `g`.
    ///
    /// # Errors
    /// As [`UtfMincoObjective::gradient`].
    pub fn gradient(&mut self, g: &mut [f64]) -> Result<(), PlanError> {
        let n = self.pieces();
        self.core.begin_gradient(g, self.dimension())?;
        let w = &self.core.weights;
        let grad = &self.core.grad;
        for ((gi, slope), dj) in g[3 * (n - 1)..]
            .iter_mut()
            .zip(&self.duration_slopes)
            .zip(&grad.durations)
        {
            *gi = (w.time + dj) * slope;
        }
        check_gradient(g)
    }

    /// The unweighted cost terms and `J` at the last finite cost evaluation (one that did not
    /// stop early at its bound).
    pub fn breakdown(&self) -> CostBreakdown {
        SplitCost::breakdown(self)
    }

    /// The trajectory of the last evaluation (starts at `start.t`); after a
    /// `cost_with_bound` that stopped before solving MINCO (its time and terminal terms alone
    /// exceeded the bound), that of the evaluation before.
    ///
    /// # Errors
    /// If no evaluation has succeeded yet.
    pub fn trajectory(&self) -> Result<PolyTraj, PlanError> {
        SplitCost::trajectory(self)
    }
}

/// The two halves of an objective, for [`eval_fused`] and the split L-BFGS solve; what the two
/// objectives share beyond their two halves is provided here, on their [`ObjectiveCore`].
pub(crate) trait SplitCost {
    /// `J(x)`, exact up to `bound`, `+∞` where it cannot be evaluated.
    fn cost(&mut self, x: &[f64], bound: f64) -> f64;
    /// `∇J` at the last cost's point.
    fn gradient(&mut self, g: &mut [f64]) -> Result<(), PlanError>;
    /// MINCO, the penalties and the state of the last evaluation.
    fn core(&self) -> &ObjectiveCore<'_>;
    /// Fused cost and gradient (sets the state that `trajectory` and `breakdown` read).
    fn eval(&mut self, x: &[f64], g: &mut [f64]) -> f64 {
        eval_fused(self, x, g)
    }
    /// The trajectory at the last evaluated point.
    fn trajectory(&self) -> Result<PolyTraj, PlanError> {
        self.core().trajectory()
    }
    /// The cost breakdown at the last evaluated point.
    fn breakdown(&self) -> CostBreakdown {
        self.core().last
    }
    /// Number of pieces `n`.
    fn pieces(&self) -> usize {
        self.core().pieces()
    }
}

impl SplitCost for UtfMincoObjective<'_> {
    fn cost(&mut self, x: &[f64], bound: f64) -> f64 {
        self.cost_with_bound(x, bound)
    }

    fn gradient(&mut self, g: &mut [f64]) -> Result<(), PlanError> {
        UtfMincoObjective::gradient(self, g)
    }

    fn core(&self) -> &ObjectiveCore<'_> {
        &self.core
    }
}

impl SplitCost for MincoObjective<'_> {
    fn cost(&mut self, x: &[f64], bound: f64) -> f64 {
        self.cost_with_bound(x, bound)
    }

    fn gradient(&mut self, g: &mut [f64]) -> Result<(), PlanError> {
        MincoObjective::gradient(self, g)
    }

    fn core(&self) -> &ObjectiveCore<'_> {
        &self.core
    }
}

/// Cost and gradient in one call: `+∞` with `g` zeroed if either is not available.
fn eval_fused<O: SplitCost + ?Sized>(objective: &mut O, x: &[f64], g: &mut [f64]) -> f64 {
    let cost = objective.cost(x, f64::INFINITY);
    if !cost.is_finite() || objective.gradient(g).is_err() {
        g.fill(0.0);
        return f64::INFINITY;
    }
    cost
}

/// Shared end of `gradient`: a non-finite gradient is an error (and `g` is zeroed).
fn check_gradient(g: &mut [f64]) -> Result<(), PlanError> {
    match g.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(index) => {
            g.fill(0.0);
            Err(component(MincoError::NonFiniteResult {
                field: "gradient",
                index,
            }))
        }
    }
}

fn min_total(params: &PieceParams, pieces: usize) -> f64 {
    params.min_piece_duration_s * pieces as f64
}

fn check_pieces(pieces: usize) -> Result<(), PlanError> {
    if pieces == 0 {
        Err(PlanError::invalid("pieces", pieces, "an integer >= 1"))
    } else {
        Ok(())
    }
}

fn check_len(field: &str, expected: usize, got: usize) -> Result<(), PlanError> {
    if expected == got {
        Ok(())
    } else {
        Err(PlanError::invalid(
            field,
            format!("{got} entries"),
            format!("{expected} entries"),
        ))
    }
}
