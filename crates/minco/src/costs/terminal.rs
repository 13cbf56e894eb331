//! The flight-duration cost `H_t` and the heuristic terminal guidance cost `H_s` (paper
//! eqs. design-of-J and design-of-Hs).

use trust_core::Vec3;

use super::PenaltyParams;

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
        }
    }

    /// `(H_s, ∂H_s/∂p_f, ∂H_s/∂ṗ_f)`.
    pub fn eval(&self, p_f: &Vec3, v_f: &Vec3) -> (f64, Vec3, Vec3) {
        let (hp, gp) =
            smoothed_weighted_norm(&(p_f - self.goal), &self.position_gains, self.epsilon);
        let (hv, gv) = smoothed_weighted_norm(v_f, &self.velocity_gains, self.epsilon);
        (hp + self.alpha * hv, gp, gv * self.alpha)
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
    fn time_cost_is_the_duration() {
        assert_eq!(time_cost(3.5), (3.5, 1.0));
    }
}
