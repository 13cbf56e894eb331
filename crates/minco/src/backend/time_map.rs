//! The smooth positive map from an unconstrained variable `τ` to a duration (GCOPTER's rational
//! map for the total duration).

/// `T(τ) = ½τ² + τ + 1` for `τ > 0` and `1 / (½τ² − τ + 1)` for `τ ≤ 0`, with `dT/dτ`.
///
/// `T` is C², strictly increasing and strictly positive: it approaches 0 only as `τ → −∞` (like
/// `2/τ²`), so a long trial step of the line search cannot drive a duration to 0 or below (with
/// `T = exp(τ)` it can underflow to 0, which made MINCO produce NaN in the reference's tests).
///
/// ```
/// use trust_minco::backend::{positive_time, positive_time_inverse};
/// assert_eq!(positive_time(0.0), (1.0, 1.0));
/// let tau = positive_time_inverse(0.25);
/// assert!((positive_time(tau).0 - 0.25).abs() < 1e-12);
/// ```
#[inline]
pub fn positive_time(tau: f64) -> (f64, f64) {
    if tau > 0.0 {
        ((0.5 * tau + 1.0) * tau + 1.0, tau + 1.0)
    } else {
        let den = (0.5 * tau - 1.0) * tau + 1.0;
        // The clamp only matters for |τ| > 1e154, where 1/den underflows.
        (
            (1.0 / den).max(f64::MIN_POSITIVE),
            (1.0 - tau) / (den * den),
        )
    }
}

/// The `τ` with `positive_time(τ).0 == duration` for `duration > 0`. Non-positive or NaN
/// durations map to a very negative `τ` (a tiny duration); `+∞` maps to `f64::MAX.sqrt()`.
#[inline]
pub fn positive_time_inverse(duration: f64) -> f64 {
    if duration.is_nan() || duration <= 0.0 {
        return -1e150;
    }
    if duration > 1.0 {
        if duration.is_infinite() {
            return f64::MAX.sqrt();
        }
        (2.0 * duration - 1.0).sqrt() - 1.0
    } else {
        1.0 - (2.0 / duration - 1.0).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn inverse_round_trips(t in 1e-4..1e3f64) {
            let tau = positive_time_inverse(t);
            prop_assert!((positive_time(tau).0 - t).abs() <= 1e-9 * t);
        }

        #[test]
        fn derivative_matches_finite_differences(tau in -50.0..50.0f64) {
            let h = 1e-6;
            let fd = trust_numdiff::central_difference(|x| positive_time(x).0, tau, h);
            let (t, d) = positive_time(tau);
            prop_assert!(t > 0.0 && d > 0.0);
            prop_assert!((fd - d).abs() <= 1e-6 * (1.0 + d), "{fd} vs {d}");
        }
    }

    #[test]
    fn stays_positive_for_extreme_steps() {
        for tau in [-1e100, -1e200, f64::MIN] {
            let (t, d) = positive_time(tau);
            assert!(t > 0.0 && t.is_finite() && d.is_finite(), "{tau}");
        }
        assert_relative_eq!(positive_time(0.0).0, 1.0);
        assert!(positive_time_inverse(0.0) < -1e100);
        assert!(positive_time_inverse(f64::NAN) < -1e100);
    }
}
