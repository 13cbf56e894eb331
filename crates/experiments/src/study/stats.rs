//! The statistics of a study: Wilson intervals for rates, Student-t intervals for means,
//! medians.

use serde::{Deserialize, Serialize};
use trust_plot::quantile_sorted;

/// `z` of a two-sided 95 % normal interval.
const Z95: f64 = 1.959_963_984_540_054;

/// A proportion with its 95 % Wilson score interval.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Rate {
    /// Successes.
    pub k: usize,
    /// Trials.
    pub n: usize,
    /// `k / n` (0 for `n = 0`).
    pub rate: f64,
    /// Lower end of the 95 % Wilson interval.
    pub ci95_low: f64,
    /// Upper end of the 95 % Wilson interval.
    pub ci95_high: f64,
}

/// `k` successes in `n` trials with the 95 % Wilson score interval (Wilson 1927), which, unlike
/// the normal approximation, stays inside `[0, 1]` and is honest at `k = 0` or `k = n` and for
/// small `n`. `n = 0` gives the uninformative `[0, 1]`.
pub fn wilson(k: usize, n: usize) -> Rate {
    if n == 0 {
        return Rate {
            k,
            n,
            rate: 0.0,
            ci95_low: 0.0,
            ci95_high: 1.0,
        };
    }
    let nf = n as f64;
    let p = k as f64 / nf;
    let z2 = Z95 * Z95;
    let denom = 1.0 + z2 / nf;
    let center = (p + z2 / (2.0 * nf)) / denom;
    let half = Z95 * (p * (1.0 - p) / nf + z2 / (4.0 * nf * nf)).sqrt() / denom;
    Rate {
        k,
        n,
        rate: p,
        // Exact at the ends (the formula gives 0 and 1 there up to rounding).
        ci95_low: if k == 0 {
            0.0
        } else {
            (center - half).max(0.0)
        },
        ci95_high: if k >= n {
            1.0
        } else {
            (center + half).min(1.0)
        },
    }
}

/// A sample mean with the half-width of its 95 % Student-t interval.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Mean {
    /// Sample size.
    pub n: usize,
    /// Mean (`null` in JSON when `n = 0`).
    pub mean: Option<f64>,
    /// Half-width of the 95 % interval (`null` when `n < 2`).
    pub ci95_half_width: Option<f64>,
}

/// Two-sided 97.5 % quantiles of Student's t for 1–30 degrees of freedom.
const T975: [f64; 30] = [
    12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179, 2.160,
    2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064, 2.060, 2.056,
    2.052, 2.048, 2.045, 2.042,
];

/// Mean and 95 % t-interval of `xs` (non-finite values are ignored).
pub fn mean_ci(xs: &[f64]) -> Mean {
    let v: Vec<f64> = xs.iter().copied().filter(|x| x.is_finite()).collect();
    let n = v.len();
    if n == 0 {
        return Mean {
            n,
            mean: None,
            ci95_half_width: None,
        };
    }
    let mean = v.iter().sum::<f64>() / n as f64;
    let half = (n >= 2).then(|| {
        let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
        let t = T975.get(n - 2).copied().unwrap_or(Z95);
        t * (var / n as f64).sqrt()
    });
    Mean {
        n,
        mean: Some(mean),
        ci95_half_width: half,
    }
}

/// Median of the finite values of `xs` (`None` if there are none), the 0.5-quantile of
/// [`trust_plot::quantile_sorted`].
pub fn median(xs: &[f64]) -> Option<f64> {
    let mut v: Vec<f64> = xs.iter().copied().filter(|x| x.is_finite()).collect();
    v.sort_by(f64::total_cmp);
    quantile_sorted(&v, 0.5)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn wilson_matches_published_values() {
        // 96 of 100 (the paper's success rate): [0.9016, 0.9843] (Wilson score, z = 1.96).
        let r = wilson(96, 100);
        assert_relative_eq!(r.ci95_low, 0.9016, epsilon = 1e-4);
        assert_relative_eq!(r.ci95_high, 0.9843, epsilon = 1e-4);
        // All or nothing stay informative and inside [0, 1].
        let all = wilson(10, 10);
        assert_eq!(all.ci95_high, 1.0);
        assert_relative_eq!(all.ci95_low, 0.7225, epsilon = 1e-4);
        let none = wilson(0, 10);
        assert_eq!(none.ci95_low, 0.0);
        assert_relative_eq!(none.ci95_high, 0.2775, epsilon = 1e-4);
        assert_eq!(wilson(0, 0).ci95_high, 1.0);
    }

    #[test]
    fn t_interval_and_median() {
        let m = mean_ci(&[1.0, 2.0, 3.0, 4.0]);
        assert_eq!(m.mean, Some(2.5));
        // s = 1.291, t(3) = 3.182: 3.182 · 1.291 / 2 = 2.054.
        assert_relative_eq!(m.ci95_half_width.unwrap(), 2.054, epsilon = 1e-3);
        assert_eq!(mean_ci(&[5.0]).ci95_half_width, None);
        assert_eq!(mean_ci(&[f64::NAN]).mean, None);
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), Some(2.5));
        assert_eq!(median(&[]), None);
    }
}
