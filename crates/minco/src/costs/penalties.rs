//! All sampled penalties of the objective in one integrand: moving obstacles, static map, speed
//! and acceleration, with their weights and their separate (unweighted) integrals.

use trust_core::{Aabb, Forecast, Limits, StaticMap, Vec3};

use super::dynamic::DynamicObstacleTerm;
use super::feasibility::FeasibilityTerm;
use super::integrand::{Integrand, SampleGrad, SampleState};
use super::static_map::StaticObstacleTerm;
use super::{CostWeights, PenaltyParams};

/// Unweighted integrals of the sampled penalties at the last integration.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PenaltyIntegrals {
    /// Moving obstacles (DDF), part of `I_o`.
    pub dynamic: f64,
    /// Static map, part of `I_o`.
    pub static_map: f64,
    /// Speed, part of `I_d`.
    pub speed: f64,
    /// Acceleration, part of `I_d`.
    pub acceleration: f64,
    /// Jerk beyond the optional jerk limit (`PenaltyParams::jerk_ramp_s`), part of `I_d`.
    pub jerk: f64,
}

impl PenaltyIntegrals {
    /// `I_o` = moving obstacles + static map.
    pub fn obstacle(&self) -> f64 {
        self.dynamic + self.static_map
    }

    /// `I_d` = speed + acceleration (+ jerk, with a jerk limit).
    pub fn feasibility(&self) -> f64 {
        self.speed + self.acceleration + self.jerk
    }
}

/// The integrand `λ_o (L_o + L_s) + λ_d L_d` of paper eq. design-of-J, evaluated in one pass over
/// the samples (each node's derivatives are computed once for all terms). Records the unweighted
/// integral of each part ([`PenaltyIntegrand::integrals`]); call
/// [`PenaltyIntegrand::reset_integrals`] before each integration.
#[derive(Debug, Clone)]
pub struct PenaltyIntegrand<'a> {
    dynamic: DynamicObstacleTerm<'a>,
    static_map: StaticObstacleTerm<'a>,
    feasibility: FeasibilityTerm,
    obstacle_weight: f64,
    feasibility_weight: f64,
    dynamic_active: bool,
    static_active: bool,
    integrals: PenaltyIntegrals,
}

impl<'a> PenaltyIntegrand<'a> {
    /// The penalties against `forecasts` and `map` for `limits`, with weights `λ_o`, `λ_d` from
    /// `weights` and shapes from `params`.
    pub fn new(
        forecasts: &'a [Forecast],
        map: &'a StaticMap,
        limits: Limits,
        weights: &CostWeights,
        params: &PenaltyParams,
    ) -> Self {
        Self {
            dynamic: DynamicObstacleTerm::new(
                forecasts,
                params.dynamic_clearance_m,
                params.smoothing,
            ),
            static_map: StaticObstacleTerm::new(map, params.static_clearance_m, params.smoothing),
            feasibility: FeasibilityTerm::new(limits, params.smoothing)
                .with_jerk_limit(params.jerk_limit(limits.a_max)),
            obstacle_weight: weights.obstacle,
            feasibility_weight: weights.feasibility,
            dynamic_active: false,
            static_active: false,
            integrals: PenaltyIntegrals::default(),
        }
    }

    /// Zeroes the recorded integrals.
    pub fn reset_integrals(&mut self) {
        self.integrals = PenaltyIntegrals::default();
    }

    /// Unweighted integrals accumulated since the last reset.
    pub fn integrals(&self) -> PenaltyIntegrals {
        self.integrals
    }

    /// `(v_max², a_max²)` of the feasibility term.
    #[inline]
    pub(crate) fn squared_limits(&self) -> (f64, f64) {
        let l = self.feasibility.limits();
        (l.v_max * l.v_max, l.a_max * l.a_max)
    }

    /// `j_max²` of the feasibility term, if it has a jerk limit.
    #[inline]
    pub(crate) fn squared_jerk_limit(&self) -> Option<f64> {
        self.feasibility.jerk_limit().map(|j| j * j)
    }

    /// Sets `flags[k]` for every node `k` (position `(x[k], y[k], z[k])`, time `t[k]`) that
    /// may be within the clearance of an obstacle kept by the current piece's broad phase
    /// (conservative: obstacles grown by a margin far above rounding; non-finite input is
    /// flagged).
    pub(crate) fn flag_obstacle_nodes(
        &self,
        x: &[f64],
        y: &[f64],
        z: &[f64],
        t: &[f64],
        flags: &mut [bool],
    ) {
        if self.dynamic_active {
            self.dynamic.flag_nodes(x, y, z, t, flags);
        }
        if self.static_active {
            self.static_map.flag_nodes(x, y, z, flags);
        }
    }

    /// Broad phase of the moving-obstacle term for the whole trajectory (time window and box of
    /// all samples).
    #[inline]
    pub(crate) fn begin_trajectory_obstacles(
        &mut self,
        t_begin: f64,
        t_end: f64,
        samples_box: &Aabb,
    ) {
        self.dynamic
            .begin_trajectory_impl(t_begin, t_end, samples_box);
    }

    /// Broad phase of the obstacle terms for one piece; `true` if any obstacle may be violated
    /// at its samples (the feasibility term is evaluated at every sample regardless).
    #[inline]
    pub(crate) fn begin_piece_obstacles(
        &mut self,
        t_begin: f64,
        t_end: f64,
        samples_box: &Aabb,
    ) -> bool {
        self.dynamic_active = self.dynamic.begin_piece_impl(t_begin, t_end, samples_box);
        self.static_active = self.static_map.begin_piece_impl(samples_box);
        self.dynamic_active || self.static_active
    }

    /// `λ_o (L_o + L_s)` at position `p` and time `t` of a node of quadrature weight `w`; adds
    /// `λ_o ∂/∂p` into `grad_p` and `λ_o ∂/∂t` into `grad_t`, records the unweighted integrals.
    #[inline(always)]
    pub(crate) fn obstacles_at(
        &mut self,
        p: &Vec3,
        t: f64,
        w: f64,
        grad_p: &mut Vec3,
        grad_t: &mut f64,
    ) -> f64 {
        let wo = self.obstacle_weight;
        let mut total = 0.0;
        if self.dynamic_active {
            let l = self.dynamic.at(p, t, wo, grad_p, grad_t);
            self.integrals.dynamic += w * l;
            total += wo * l;
        }
        if self.static_active {
            let l = self.static_map.at(p, wo, grad_p);
            self.integrals.static_map += w * l;
            total += wo * l;
        }
        total
    }

    /// `λ_d L_d` at velocity `v` and acceleration `a` of a node of quadrature weight `w`; adds
    /// `λ_d ∂/∂v` into `grad_v` and `λ_d ∂/∂a` into `grad_a`, records the unweighted integrals.
    #[inline(always)]
    pub(crate) fn feasibility_at(
        &mut self,
        v: &Vec3,
        a: &Vec3,
        w: f64,
        grad_v: &mut Vec3,
        grad_a: &mut Vec3,
    ) -> f64 {
        let wd = self.feasibility_weight;
        let (lv, la) = self.feasibility.at(v, a, wd, grad_v, grad_a);
        self.integrals.speed += w * lv;
        self.integrals.acceleration += w * la;
        wd * (lv + la)
    }

    /// `λ_d L_j` at jerk `j` of a node of quadrature weight `w` (0 without a jerk limit); adds
    /// `λ_d ∂/∂j` into `grad_j`, records the unweighted integral.
    #[inline(always)]
    pub(crate) fn jerk_at(&mut self, j: &Vec3, w: f64, grad_j: &mut Vec3) -> f64 {
        let wd = self.feasibility_weight;
        let lj = self.feasibility.jerk_at(j, wd, grad_j);
        self.integrals.jerk += w * lj;
        wd * lj
    }
}

/// Terminal speed (m/s) below which [`PenaltyIntegrand::braking_tail`] is ramped in
/// quadratically from zero.
pub const TAIL_RAMP_MPS: f64 = 1.0;

/// What [`PenaltyIntegrand::braking_tail`] returns: the weighted cost, its unweighted integral
/// (part of `I_o`) and the cost's partial derivatives.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BrakingTail {
    /// `λ_o Σ_k w L(q_k, t_k)`.
    pub cost: f64,
    /// `Σ_k w L(q_k, t_k)`, added to `I_o`.
    pub integral: f64,
    /// `∂cost/∂p_f`.
    pub grad_p: Vec3,
    /// `∂cost/∂v_f`.
    pub grad_v: Vec3,
    /// `∂cost/∂t_end`.
    pub grad_t: f64,
}

impl PenaltyIntegrand<'_> {
    /// The obstacle penalty (moving obstacles and static map) along the straight braking
    /// manoeuvre after a trajectory that ends at `p_f` with velocity `v_f` at time `t_end`:
    /// keeping `v_f` for `delay` seconds and then decelerating at `decel` along `v_f`, the
    /// vehicle is at `q(σ) = p_f + v_f·(delay + (|v_f|/decel)·(σ − σ²/2))` at time
    /// `t(σ) = t_end + delay + σ·|v_f|/decel`, `σ ∈ [0, 1]`, and stops at `σ = 1`. Samples
    /// `σ_k = k/samples`, `k = 1…samples`, and `σ = 0` when `delay > 0` (the trajectory's own
    /// last node is `p_f`), each with quadrature weight `weight`, the sum scaled by
    /// `min(1, (|v_f| / TAIL_RAMP_MPS)²)`. Zero for a terminal at rest, `samples == 0` or a
    /// non-positive `decel`. Leaves the obstacle broad phase set for the tail (the next
    /// integration sets its own).
    ///
    /// The ramp keeps the cost continuous (and differentiable) at `v_f = 0`: as `v_f → 0` every
    /// sample tends to `p_f`, so without it the tail would jump from `0` (at rest) to
    /// `samples · weight · L(p_f)` (at any speed) wherever the terminal lies in an obstacle's
    /// margin — a cold start from a guide path ends at rest, and L-BFGS's first line search then
    /// found no decrease in 64 trials (E3 seeds 5, 7, 9). Below 1 m/s the braking distance is
    /// under 0.15 m, which the trajectory's own samples around `p_f` already cover.
    #[allow(clippy::too_many_arguments)]
    pub fn braking_tail(
        &mut self,
        p_f: &Vec3,
        v_f: &Vec3,
        t_end: f64,
        decel: f64,
        delay: f64,
        samples: usize,
        weight: f64,
    ) -> BrakingTail {
        let speed = v_f.norm();
        let mut out = BrakingTail::default();
        let usable = decel > 0.0 && speed > 1e-9 && speed.is_finite() && delay >= 0.0;
        if samples == 0 || !usable {
            return out;
        }
        let stop_time = speed / decel;
        let stop = p_f + v_f * (delay + 0.5 * stop_time);
        let Some(bbox) = Aabb::from_points(&[*p_f, stop]) else {
            return out;
        };
        let t_stop = t_end + delay + stop_time;
        self.begin_trajectory_obstacles(t_end, t_stop, &bbox);
        if !self.begin_piece_obstacles(t_end, t_stop, &bbox) {
            return out;
        }
        let unit = v_f / speed;
        let (ramp, ramp_slope) = if speed < TAIL_RAMP_MPS {
            let u = speed / TAIL_RAMP_MPS;
            (u * u, 2.0 * u / TAIL_RAMP_MPS)
        } else {
            (1.0, 0.0)
        };
        let first = if delay > 0.0 { 0 } else { 1 };
        for k in first..=samples {
            let sigma = k as f64 / samples as f64;
            let c = (sigma - 0.5 * sigma * sigma) / decel;
            let q = p_f + v_f * (delay + speed * c);
            let t = t_end + delay + sigma * stop_time;
            let (mut gp, mut gt) = (Vec3::zeros(), 0.0);
            let before = self.integrals.obstacle();
            let value = self.obstacles_at(&q, t, weight, &mut gp, &mut gt);
            out.integral += self.integrals.obstacle() - before;
            out.cost += weight * value;
            let (gp, gt) = (gp * weight, gt * weight);
            // q = p_f + (delay + c·|v|)·v, t = t_end + delay + σ·|v|/decel.
            out.grad_p += gp;
            out.grad_v += gp * (delay + speed * c) + unit * (c * v_f.dot(&gp) + gt * sigma / decel);
            out.grad_t += gt;
        }
        if ramp < 1.0 {
            // d(ramp · cost)/dv_f = ramp · dcost/dv_f + cost · ramp'(|v|) · v_f/|v|.
            out.grad_v = out.grad_v * ramp + unit * (out.cost * ramp_slope);
            out.grad_p *= ramp;
            out.grad_t *= ramp;
            out.cost *= ramp;
            out.integral *= ramp;
        }
        out
    }
}

impl Integrand for PenaltyIntegrand<'_> {
    fn begin_trajectory(&mut self, t_begin: f64, t_end: f64, samples_box: &Aabb) {
        self.begin_trajectory_obstacles(t_begin, t_end, samples_box);
    }

    fn begin_piece(&mut self, _piece: usize, t_begin: f64, t_end: f64, samples_box: &Aabb) -> bool {
        self.begin_piece_obstacles(t_begin, t_end, samples_box);
        true
    }

    #[inline]
    fn sample(&mut self, s: &SampleState, grad: &mut SampleGrad) -> f64 {
        let obstacles = self.obstacles_at(&s.p, s.t, s.weight, &mut grad.p, &mut grad.t);
        obstacles
            + self.feasibility_at(&s.v, &s.a, s.weight, &mut grad.v, &mut grad.a)
            + self.jerk_at(&s.j, s.weight, &mut grad.j)
    }
}
