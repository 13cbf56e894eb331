//! The dynamic feasibility penalty `I_d` (paper eqs. design-of-Id and gradients-of-Id).

use trust_core::{Limits, Vec3};

use super::integrate::{Integrand, SampleGrad, SampleState};
use super::smooth::smoothed_l1;

/// `φ = ‖x‖²/x_max² − 1` and `∂φ/∂x = 2x/x_max²` (paper eq. design-of-Id, for `x` = velocity or
/// acceleration).
#[inline]
pub fn norm_violation(x: &Vec3, x_max: f64) -> (f64, Vec3) {
    let inv = 1.0 / (x_max * x_max);
    (x.norm_squared() * inv - 1.0, x * (2.0 * inv))
}

/// `L_d = f_max(φ_v) + f_max(φ_a)` with `φ_v = vᵀv/v_max² − 1`, `φ_a = aᵀa/a_max² − 1`
/// (paper eq. design-of-Id; gradients eq. gradients-of-Id — the time derivatives `2aᵀv/v_max²`
/// and `2jᵀa/a_max²` follow from `∂L/∂v · a` and `∂L/∂a · j` in the integrator).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FeasibilityTerm {
    /// Speed and acceleration limits.
    pub limits: Limits,
    /// Smoothing `μ`.
    pub smoothing: f64,
}

impl FeasibilityTerm {
    /// The penalty for `limits` with smoothing `μ`.
    pub fn new(limits: Limits, smoothing: f64) -> Self {
        Self { limits, smoothing }
    }

    /// Unweighted `(f_max(φ_v), f_max(φ_a))` at one node; adds `weight · ∂L_d` into `grad`.
    #[inline]
    pub(crate) fn sample_parts(
        &self,
        s: &SampleState,
        grad: &mut SampleGrad,
        weight: f64,
    ) -> (f64, f64) {
        let (phi_v, dv) = norm_violation(&s.v, self.limits.v_max);
        let (phi_a, da) = norm_violation(&s.a, self.limits.a_max);
        let mut out = (0.0, 0.0);
        if phi_v > 0.0 {
            let (value, slope) = smoothed_l1(phi_v, self.smoothing);
            grad.v += dv * (weight * slope);
            out.0 = value;
        }
        if phi_a > 0.0 {
            let (value, slope) = smoothed_l1(phi_a, self.smoothing);
            grad.a += da * (weight * slope);
            out.1 = value;
        }
        out
    }
}

impl Integrand for FeasibilityTerm {
    fn sample(&mut self, s: &SampleState, grad: &mut SampleGrad) -> f64 {
        let (v, a) = self.sample_parts(s, grad, 1.0);
        v + a
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn violation_is_zero_on_the_limit() {
        let (phi, g) = norm_violation(&Vec3::new(3.0, 4.0, 0.0), 5.0);
        assert_relative_eq!(phi, 0.0, epsilon = 1e-15);
        assert_relative_eq!(g, Vec3::new(0.24, 0.32, 0.0), epsilon = 1e-15);
    }
}
