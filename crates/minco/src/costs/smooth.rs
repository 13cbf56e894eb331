//! The smooth `max(x, 0)` used by every penalty (paper eq. design-of-Io: `f_max`).

/// C² smoothed L1 ("smoothed max"), `f_max(x) ≈ max(x, 0)` with smoothing width `mu > 0`, and its
/// slope. With `r = x / mu`:
///
/// | range | value | slope |
/// |---|---|---|
/// | `x ≤ 0` | `0` | `0` |
/// | `0 < x < mu` | `mu (r³ − r⁴/2)` | `r² (3 − 2r)` |
/// | `x ≥ mu` | `x − mu/2` | `1` |
///
/// This is GCOPTER's `smoothedL1` (its penalty integration); value, slope and curvature are
/// continuous at `0` and `mu`.
///
/// ```
/// use trust_minco::costs::smoothed_l1;
/// assert_eq!(smoothed_l1(-1.0, 0.01), (0.0, 0.0));
/// assert_eq!(smoothed_l1(2.0, 0.01), (2.0 - 0.005, 1.0));
/// ```
#[inline]
pub fn smoothed_l1(x: f64, mu: f64) -> (f64, f64) {
    SmoothedL1::new(mu).eval(x)
}

/// [`smoothed_l1`] with its width fixed and `1/μ` precomputed, for inner loops (a division costs
/// as much as the rest of the function).
///
/// ```
/// use trust_minco::costs::{SmoothedL1, smoothed_l1};
/// let f = SmoothedL1::new(0.01);
/// assert_eq!(f.eval(0.004), smoothed_l1(0.004, 0.01));
/// assert_eq!(f.mu(), 0.01);
/// ```
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SmoothedL1 {
    mu: f64,
    inv_mu: f64,
}

impl SmoothedL1 {
    /// The smoothed max of width `mu` (> 0 for a smooth function; the caller validates).
    #[inline]
    pub fn new(mu: f64) -> Self {
        Self {
            mu,
            inv_mu: 1.0 / mu,
        }
    }

    /// The width `μ`.
    #[inline]
    pub fn mu(&self) -> f64 {
        self.mu
    }

    /// `(f_max(x), f_max'(x))`, see [`smoothed_l1`].
    #[inline]
    pub fn eval(&self, x: f64) -> (f64, f64) {
        if x <= 0.0 {
            (0.0, 0.0)
        } else if x < self.mu {
            let r = x * self.inv_mu;
            let r2 = r * r;
            (self.mu * r2 * (r - 0.5 * r2), r2 * (3.0 - 2.0 * r))
        } else {
            (x - 0.5 * self.mu, 1.0)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    #[test]
    fn continuous_at_the_knots() {
        let mu = 0.01;
        let (v, s) = smoothed_l1(mu, mu);
        let (v2, s2) = smoothed_l1(mu * (1.0 - 1e-12), mu);
        assert_relative_eq!(v, v2, epsilon = 1e-12);
        assert_relative_eq!(s, s2, epsilon = 1e-9);
        let (v0, s0) = smoothed_l1(1e-14, mu);
        assert!(v0 < 1e-20 && s0 < 1e-20);
    }

    proptest! {
        #[test]
        fn slope_matches_finite_differences(x in -0.05..0.2f64, mu in 1e-3..0.1f64) {
            let h = 1e-7;
            let fd = trust_numdiff::central_difference(|y| smoothed_l1(y, mu).0, x, h);
            let (_, slope) = smoothed_l1(x, mu);
            prop_assert!((fd - slope).abs() < 1e-5, "x {x} mu {mu}: fd {fd} vs {slope}");
        }
    }
}
