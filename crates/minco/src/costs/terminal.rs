//! The flight-duration cost `H_t` and the heuristic terminal guidance cost `H_s` (paper
//! eqs. design-of-J and design-of-Hs).

use trust_core::Vec3;

use super::{PenaltyParams, SmoothedL1};

/// `H_t = T_Σ` and `∂H_t/∂T_Σ = 1` (paper Sec. III-D, "Flight duration cost").
#[inline]
pub fn time_cost(total_duration: f64) -> (f64, f64) {
    (total_duration, 1.0)
}

/// The smoothed weighted norm `√(xᵀKx + ε²) − ε` (`K = diag(k)`) and its gradient `Kx / √(xᵀKx + ε²)`.
///
/// It replaces the paper's `‖x‖_K = √(xᵀKx)`, whose gradient `Kx/‖x‖_K` is undefined at `x = 0`
/// and jumps around it, which makes L-BFGS stall once the terminal reaches the goal. The
/// deviation from `‖x‖_K` is at most `ε`; it is 0 at `x = 0` and the cost is `C^∞`.
#[inline]
pub fn smoothed_weighted_norm(x: &Vec3, k: &Vec3, epsilon: f64) -> (f64, Vec3) {
    let kx = k.component_mul(x);
    let root = (x.dot(&kx) + epsilon * epsilon).sqrt();
    (root - epsilon, kx / root)
}

/// The terminal-velocity weight `α` of paper eq. design-of-Hs: 0 when the vehicle (at distance
/// `distance_to_goal` from the goal) is at least `goal_radius` away, else
/// `1 − distance_to_goal / goal_radius`.
#[inline]
pub fn terminal_velocity_weight(distance_to_goal: f64, goal_radius: f64) -> f64 {
    if distance_to_goal >= goal_radius || goal_radius <= 0.0 {
        0.0
    } else {
        1.0 - distance_to_goal / goal_radius
    }
}

/// The heuristic terminal guidance cost of paper eq. design-of-Hs, with the smoothed norm
/// ([`smoothed_weighted_norm`]):
/// `H_s = ‖p_f − p_g‖_{K_p,ε} + α ‖ṗ_f‖_{K_v,ε}`.
#[derive(Debug, Clone, PartialEq)]
pub struct TerminalCost {
    /// Global goal `p_g`.
    pub goal: Vec3,
    /// Diagonal of `K_f^p`.
    pub position_gains: Vec3,
    /// Diagonal of `K_f^ṗ`.
    pub velocity_gains: Vec3,
    /// Terminal-velocity weight `α` ([`terminal_velocity_weight`]).
    pub alpha: f64,
    /// Smoothing `ε` of the norms.
    pub epsilon: f64,
    /// Radius `r_des` (m) of the goal guidance surface the objective pulls the terminal to
    /// ([`TerminalCost::eval_objective`]); 0: the goal itself (the paper's `H_s`).
    pub surface_radius: f64,
    /// Width (m) of the smoothed max at the surface.
    pub surface_smoothing: f64,
    /// Final-approach gain `k ≥ 1` on the position part of the objective (not of the reported
    /// `H_s`), blended in with `α`: the objective uses `(1 + α (k − 1))·‖p_f − p_g‖`
    /// ([`final_approach_gain`]). 1: the paper's cost.
    pub approach_gain: f64,
}

/// The final-approach gain `k` for time weight `λ_t`, terminal weight `λ_s`, acceleration limit
/// `a_max`, jerk limit `j_max` (`∞`: none) and settling distance `d_s` (beyond the paper;
/// issue 19).
///
/// Near the goal the free terminal trades the pull of `H_s` (slope `λ_s` per metre) against the
/// time `T(d)` a rest-to-rest move of the last `d` metres takes: a minimum-jerk quintic whose peak
/// acceleration `5.77·d/T²` and peak jerk `60·d/T³` stay within the limits,
/// `T(d) = max(√(5.77·d/a_max), ∛(60·d/j_max))`. `T(d)/d` grows without bound as `d → 0`, so
/// a vehicle at rest `d` short of the goal stays there whenever `λ_t·T(d) > λ_s·d` — with the
/// paper's cost 0.48 m at a Crazyflie's `a_max = 3` (`λ_t = λ_s`), and with the presets' jerk
/// limit 1.2 m at E4's limits: more than the goal tolerance (measured: room flights hovered
/// 0.17–0.25 m short). Scaling the pull by `k = (λ_t/λ_s)·T(d_s)/d_s` makes going to the goal
/// cheaper than staying for every `d ≥ d_s`, and (`T` being concave) moves the balance of an
/// approaching terminal within `d_s` too. `k` is at least 1 (no change when the paper's cost
/// already settles within `d_s`). Non-finite or non-positive inputs give 1.
pub fn final_approach_gain(
    time_weight: f64,
    terminal_weight: f64,
    a_max: f64,
    j_max: f64,
    settle_m: f64,
) -> f64 {
    let k = (time_weight / terminal_weight) * rest_to_rest_quintic_time(settle_m, a_max, j_max)
        / settle_m;
    if k.is_finite() && k > 0.0 {
        k.max(1.0)
    } else {
        1.0
    }
}

/// The duration of the minimum-jerk quintic that moves `distance` metres from rest to rest
/// within the acceleration limit `a_max` and the jerk limit `j_max` (`∞`: none): its peak
/// acceleration is `5.77·d/T²` and its peak jerk `60·d/T³`.
pub fn rest_to_rest_quintic_time(distance: f64, a_max: f64, j_max: f64) -> f64 {
    let by_accel = (5.77 * distance / a_max).sqrt();
    let by_jerk = if j_max.is_finite() {
        (60.0 * distance / j_max).cbrt()
    } else {
        0.0
    };
    by_accel.max(by_jerk)
}

impl TerminalCost {
    /// The terminal cost for a vehicle at `start_position` heading to `goal`, with `α` from the
    /// schedule of eq. design-of-Hs (`d_ε = params.goal_radius_m`).
    pub fn new(goal: Vec3, start_position: &Vec3, params: &PenaltyParams) -> Self {
        Self {
            goal,
            position_gains: params.terminal_position_gains,
            velocity_gains: params.terminal_velocity_gains,
            alpha: terminal_velocity_weight((start_position - goal).norm(), params.goal_radius_m),
            epsilon: params.terminal_norm_epsilon,
            surface_radius: 0.0,
            surface_smoothing: params.guidance_smoothing_m,
            approach_gain: 1.0,
        }
    }

    /// The same cost with the final-approach gain `k` ([`final_approach_gain`]; values below 1
    /// or non-finite mean 1).
    pub fn with_approach_gain(mut self, gain: f64) -> Self {
        self.approach_gain = if gain.is_finite() { gain.max(1.0) } else { 1.0 };
        self
    }

    /// The same cost with the terminal pulled only to the goal guidance surface of radius
    /// `radius` (m; non-finite or negative values mean 0): see [`Self::eval_objective`].
    pub fn with_guidance_surface(mut self, radius: f64) -> Self {
        self.surface_radius = if radius.is_finite() {
            radius.max(0.0)
        } else {
            0.0
        };
        self
    }

    /// `(H_s, ∂H_s/∂p_f, ∂H_s/∂ṗ_f)`.
    pub fn eval(&self, p_f: &Vec3, v_f: &Vec3) -> (f64, Vec3, Vec3) {
        let (hp, gp) =
            smoothed_weighted_norm(&(p_f - self.goal), &self.position_gains, self.epsilon);
        let (hv, gv) = smoothed_weighted_norm(v_f, &self.velocity_gains, self.epsilon);
        (hp + self.alpha * hv, gp, gv * self.alpha)
    }

    /// The terminal term the backend minimizes and its gradients `(H̃_s, ∂/∂p_f, ∂/∂ṗ_f)`.
    ///
    /// Without a guidance surface (`surface_radius == 0`) it is [`Self::eval`] with the position
    /// part scaled by the final-approach factor `1 + α (k − 1)` ([`final_approach_gain`]; `k = 1`
    /// is exactly the paper's `H_s`). With one, the
    /// position part measures how far the terminal is *outside the ball* of radius `r_des`
    /// around the goal: `f_max(‖p_f − p_g‖_{K,ε} − r_des) + α‖ṗ_f‖_{K,ε}` with the C² smoothed
    /// max of width `surface_smoothing` ([`SmoothedL1`]). A receding-horizon planner thereby ends
    /// its trajectory on the goal guidance surface of paper Sec. III-B (where DEV-PRM's guide
    /// paths end) instead of stretching it over the whole remaining distance: inside the ball only
    /// the flight time `H_t` acts, which pulls the terminal back onto the surface. The reported
    /// `H_s` stays the paper's ([`Self::eval`]), so branch ranking is unchanged.
    pub fn eval_objective(&self, p_f: &Vec3, v_f: &Vec3) -> (f64, Vec3, Vec3) {
        if self.surface_radius <= 0.0 {
            let gain = 1.0 + self.alpha * (self.approach_gain - 1.0);
            let (hp, gp) =
                smoothed_weighted_norm(&(p_f - self.goal), &self.position_gains, self.epsilon);
            let (hv, gv) = smoothed_weighted_norm(v_f, &self.velocity_gains, self.epsilon);
            return (gain * hp + self.alpha * hv, gp * gain, gv * self.alpha);
        }
        let (hp, gp) =
            smoothed_weighted_norm(&(p_f - self.goal), &self.position_gains, self.epsilon);
        let (outside, slope) =
            SmoothedL1::new(self.surface_smoothing).eval(hp - self.surface_radius);
        let (hv, gv) = smoothed_weighted_norm(v_f, &self.velocity_gains, self.epsilon);
        (outside + self.alpha * hv, gp * slope, gv * self.alpha)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn alpha_schedule() {
        assert_eq!(terminal_velocity_weight(20.0, 10.0), 0.0);
        assert_eq!(terminal_velocity_weight(10.0, 10.0), 0.0);
        assert_relative_eq!(terminal_velocity_weight(2.5, 10.0), 0.75);
        assert_eq!(terminal_velocity_weight(0.0, 10.0), 1.0);
    }

    #[test]
    fn smoothed_norm_is_close_to_the_norm_and_flat_at_zero() {
        let k = Vec3::new(1.0, 2.0, 3.0);
        let (v, g) = smoothed_weighted_norm(&Vec3::zeros(), &k, 0.01);
        assert_eq!(v, 0.0);
        assert_eq!(g, Vec3::zeros());
        let x = Vec3::new(3.0, -1.0, 0.5);
        let exact = x.dot(&k.component_mul(&x)).sqrt();
        let (v, _) = smoothed_weighted_norm(&x, &k, 0.01);
        assert!((v - exact).abs() <= 0.01);
    }

    #[test]
    fn guidance_surface_relaxes_only_the_position_part() {
        let params = PenaltyParams::default();
        let goal = Vec3::new(50.0, 0.0, 0.0);
        let plain = TerminalCost::new(goal, &Vec3::zeros(), &params);
        let relaxed = plain.clone().with_guidance_surface(20.0);
        let v = Vec3::new(1.0, 0.0, 0.0);
        // r_des = 0 is the paper's H_s, bit for bit.
        let p = Vec3::new(10.0, 3.0, 0.0);
        assert_eq!(
            plain
                .clone()
                .with_guidance_surface(0.0)
                .eval_objective(&p, &v),
            plain.eval(&p, &v)
        );
        assert_eq!(
            plain.clone().with_guidance_surface(f64::NAN).surface_radius,
            0.0
        );
        // Inside the ball: no position cost and no position gradient.
        let (h, gp, _) = relaxed.eval_objective(&Vec3::new(40.0, 0.0, 0.0), &v);
        assert_eq!((h, gp), (0.0, Vec3::zeros()));
        // Far outside: the distance to the surface minus half the smoothing width.
        let (h, gp, _) = relaxed.eval_objective(&Vec3::zeros(), &v);
        // (The smoothed norm is `ε` short of the distance.)
        assert_relative_eq!(h, 30.0 - params.guidance_smoothing_m / 2.0, epsilon = 2e-2);
        assert_relative_eq!(gp, Vec3::new(-1.0, 0.0, 0.0), epsilon = 1e-6);
    }

    #[test]
    fn guidance_surface_gradient_matches_finite_differences() {
        // α > 0: the velocity part is active too.
        let params = PenaltyParams {
            goal_radius_m: 100.0,
            ..PenaltyParams::default()
        };
        let goal = Vec3::new(12.0, -3.0, 2.0);
        let cost =
            TerminalCost::new(goal, &Vec3::new(1.0, 0.0, 0.0), &params).with_guidance_surface(10.0);
        // Points on both sides of the surface and inside the smoothing band.
        for p in [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.7, -2.9, 1.0),
            Vec3::new(2.3, -3.0, 2.0),
            Vec3::new(12.0, 6.8, 2.1),
        ] {
            let v = Vec3::new(0.3, -2.0, 1.0);
            let (_, gp, gv) = cost.eval_objective(&p, &v);
            let h = 1e-6;
            for k in 0..3 {
                let e = |s: f64| Vec3::ith(k, s);
                let fd_p = trust_numdiff::central_difference(
                    |s| cost.eval_objective(&(p + e(s)), &v).0,
                    0.0,
                    h,
                );
                let fd_v = trust_numdiff::central_difference(
                    |s| cost.eval_objective(&p, &(v + e(s))).0,
                    0.0,
                    h,
                );
                assert_relative_eq!(gp[k], fd_p, epsilon = 1e-6);
                assert_relative_eq!(gv[k], fd_v, epsilon = 1e-6);
            }
        }
    }

    #[test]
    fn time_cost_is_the_duration() {
        assert_eq!(time_cost(3.5), (3.5, 1.0));
    }
}
