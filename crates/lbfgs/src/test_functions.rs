//! Standard test problems in the solver's fused cost-and-gradient form, and a finite-difference
//! gradient for checking hand-written gradients. Used by this crate's tests, examples and
//! benches; public so that other crates can reuse them.

/// The chained (generalized) Rosenbrock function
/// `f(x) = Σ_{i=0}^{n−2} 100·(x_{i+1} − x_i²)² + (1 − x_i)²`, writing its gradient into `g`.
///
/// Global minimum 0 at `x = (1, …, 1)`. For `4 <= n <= 7` there is a second local minimum near
/// `(−1, 1, …, 1)`. With `n = 1` the function is identically 0.
///
/// # Panics
/// If `g.len() != x.len()`.
pub fn rosenbrock(x: &[f64], g: &mut [f64]) -> f64 {
    assert_eq!(g.len(), x.len(), "gradient length must equal x length");
    g.fill(0.0);
    let mut cost = 0.0;
    for i in 0..x.len().saturating_sub(1) {
        let valley = x[i + 1] - x[i] * x[i];
        let offset = 1.0 - x[i];
        cost += 100.0 * valley * valley + offset * offset;
        g[i] += -400.0 * x[i] * valley - 2.0 * offset;
        g[i + 1] += 200.0 * valley;
    }
    cost
}

/// The standard hard start point for [`rosenbrock`]: `(−1.2, 1, −1.2, 1, …)`.
pub fn rosenbrock_start(dimension: usize) -> Vec<f64> {
    (0..dimension)
        .map(|i| if i % 2 == 0 { -1.2 } else { 1.0 })
        .collect()
}

/// Central finite-difference gradient of the cost part of a fused cost-and-gradient function:
/// `grad[i] = (f(x + h·eᵢ) − f(x − h·eᵢ)) / (2h)`.
///
/// [`trust_numdiff::gradient`] (the workspace's one finite-difference home, where the step-size
/// rationale is) applied to the fused form. Allocates two scratch vectors; meant for tests, not for
/// inner loops.
///
/// # Panics
/// If `grad.len() != x.len()`.
pub fn central_difference_gradient<F>(mut f: F, x: &[f64], h: f64, grad: &mut [f64])
where
    F: FnMut(&[f64], &mut [f64]) -> f64,
{
    let mut scratch = vec![0.0; x.len()];
    trust_numdiff::gradient(|probe| f(probe, &mut scratch), x, h, grad);
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn rosenbrock_values() {
        let mut g = [0.0; 2];
        assert_eq!(rosenbrock(&[1.0, 1.0], &mut g), 0.0);
        assert_eq!(g, [0.0, 0.0]);
        approx::assert_relative_eq!(rosenbrock(&[-1.2, 1.0], &mut g), 24.2, epsilon = 1e-12);
        approx::assert_relative_eq!(g[0], -215.6, epsilon = 1e-12);
        approx::assert_relative_eq!(g[1], -88.0, epsilon = 1e-12);
        let mut g1 = [5.0];
        assert_eq!(rosenbrock(&[3.0], &mut g1), 0.0);
        assert_eq!(g1, [0.0]);
        assert_eq!(rosenbrock_start(3), vec![-1.2, 1.0, -1.2]);
    }

    proptest! {
        #[test]
        fn rosenbrock_gradient_matches_central_differences(
            x in prop::collection::vec(-2.0..2.0f64, 1..8),
        ) {
            let mut g = vec![0.0; x.len()];
            rosenbrock(&x, &mut g);
            let mut numeric = vec![0.0; x.len()];
            central_difference_gradient(rosenbrock, &x, 1e-6, &mut numeric);
            for i in 0..x.len() {
                prop_assert!((g[i] - numeric[i]).abs() <= 1e-5 * (1.0 + g[i].abs()),
                    "i = {i}: analytic {} vs numeric {}", g[i], numeric[i]);
            }
        }
    }
}
