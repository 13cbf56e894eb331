//! The dynamic feasibility penalty `I_d` (paper eqs. design-of-Id and gradients-of-Id).

use trust_core::{Limits, Vec3};

use super::integrand::{Integrand, SampleGrad, SampleState};
use super::smooth::SmoothedL1;

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
///
/// Beyond the paper, an optional jerk limit adds `f_max(φ_j)` with `φ_j = jᵀj/j_max² − 1`
/// ([`FeasibilityTerm::with_jerk_limit`]; its time derivative `2 jᵀs/j_max²` follows from
/// `∂L/∂j · snap`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FeasibilityTerm {
    limits: Limits,
    smoothing: SmoothedL1,
    /// `1/v_max²` and `1/a_max²`, precomputed (no division per sample).
    inv_v2: f64,
    inv_a2: f64,
    /// The jerk limit (m/s³), if any, and `1/j_max²` (0 without a limit).
    jerk_max: Option<f64>,
    inv_j2: f64,
}

impl FeasibilityTerm {
    /// The penalty for `limits` with smoothing `μ`.
    pub fn new(limits: Limits, smoothing: f64) -> Self {
        Self {
            limits,
            smoothing: SmoothedL1::new(smoothing),
            inv_v2: 1.0 / (limits.v_max * limits.v_max),
            inv_a2: 1.0 / (limits.a_max * limits.a_max),
            jerk_max: None,
            inv_j2: 0.0,
        }
    }

    /// The same penalty with a jerk limit `j_max` (m/s³; `None`, zero or non-finite: none).
    pub fn with_jerk_limit(mut self, jerk_max: Option<f64>) -> Self {
        match jerk_max.filter(|j| j.is_finite() && *j > 0.0) {
            Some(j) => {
                self.jerk_max = Some(j);
                self.inv_j2 = 1.0 / (j * j);
            }
            None => {
                self.jerk_max = None;
                self.inv_j2 = 0.0;
            }
        }
        self
    }

    /// The jerk limit (m/s³), if any.
    pub fn jerk_limit(&self) -> Option<f64> {
        self.jerk_max
    }

    /// Unweighted `f_max(φ_j)` at jerk `j` (0 without a jerk limit); adds `weight · ∂/∂j` into
    /// `grad_j`.
    #[inline(always)]
    pub(crate) fn jerk_at(&self, j: &Vec3, weight: f64, grad_j: &mut Vec3) -> f64 {
        if self.jerk_max.is_none() {
            return 0.0;
        }
        let phi = j.norm_squared() * self.inv_j2 - 1.0;
        if phi > 0.0 {
            let (value, slope) = self.smoothing.eval(phi);
            *grad_j += j * (2.0 * self.inv_j2 * weight * slope);
            value
        } else {
            0.0
        }
    }

    /// Speed and acceleration limits.
    pub fn limits(&self) -> &Limits {
        &self.limits
    }

    /// Smoothing `μ`.
    pub fn smoothing(&self) -> f64 {
        self.smoothing.mu()
    }

    /// Unweighted `(f_max(φ_v), f_max(φ_a))` at velocity `v` and acceleration `a`; adds
    /// `weight · ∂L_d/∂v` into `grad_v` and `weight · ∂L_d/∂a` into `grad_a`.
    #[inline(always)]
    pub(crate) fn at(
        &self,
        v: &Vec3,
        a: &Vec3,
        weight: f64,
        grad_v: &mut Vec3,
        grad_a: &mut Vec3,
    ) -> (f64, f64) {
        let phi_v = v.norm_squared() * self.inv_v2 - 1.0;
        let phi_a = a.norm_squared() * self.inv_a2 - 1.0;
        let mut out = (0.0, 0.0);
        if phi_v > 0.0 {
            let (value, slope) = self.smoothing.eval(phi_v);
            *grad_v += v * (2.0 * self.inv_v2 * weight * slope);
            out.0 = value;
        }
        if phi_a > 0.0 {
            let (value, slope) = self.smoothing.eval(phi_a);
            *grad_a += a * (2.0 * self.inv_a2 * weight * slope);
            out.1 = value;
        }
        out
    }
}

impl Integrand for FeasibilityTerm {
    #[inline]
    fn sample(&mut self, s: &SampleState, grad: &mut SampleGrad) -> f64 {
        let (v, a) = self.at(&s.v, &s.a, 1.0, &mut grad.v, &mut grad.a);
        v + a + self.jerk_at(&s.j, 1.0, &mut grad.j)
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
