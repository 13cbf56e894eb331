//! Central finite differences: the one home of the numerical derivative that every analytic
//! gradient in the workspace is tested against (house style rule 10, issue 33).
//!
//! Use it in tests (unit tests, property tests, `tests/` binaries) to check a hand-written
//! derivative or gradient; it is not meant for inner loops (it evaluates the function twice per
//! variable and [`gradient`] allocates a probe). It implements no equation of the paper: it checks
//! the gradients of §III (MINCO, the penalty terms, the forecasts' signed distances). The crate
//! depends on nothing, so every crate of the workspace, down to `geometry`, may use it as a
//! dev-dependency without breaking the layering of ARCHITECTURE.md.
//!
//! # Step size
//! The central difference `(f(x + h) − f(x − h)) / (2h)` has a truncation error `h²·f‴/6` and a
//! rounding error of about `ε·|f|/h` (`ε` = 2.2e-16). The two balance near `h ≈ ε^(1/3)·scale`,
//! i.e. `h` of 1e-6 to 1e-5 for quantities of order one, giving an error near 1e-10 relative to
//! the function's scale. The functions take `h` from the caller because the scale is the caller's
//! knowledge: a piecewise function (a voxel grid, a smoothed kink) needs `h` small enough that
//! both probes stay on one piece, a large-valued cost needs a larger `h`. Tolerances of the tests
//! using it are chosen for their `h`; do not change one without the other.

#![warn(missing_docs)]

use std::ops::{Div, Sub};

/// Central finite difference of a function of one variable:
/// `(f(x + h) − f(x − h)) / (2h)`.
///
/// The value may be a scalar or anything that subtracts and divides by an `f64` (an
/// `nalgebra::Vector3<f64>`, for the velocity of a path). For the partial derivative of a function
/// of a point along one axis, pass `|s| f(p + s·eᵢ)` at `x = 0` (the probes are then exactly
/// `p ± h·eᵢ`). See the crate docs for choosing `h`.
pub fn central_difference<T, F>(mut f: F, x: f64, h: f64) -> T
where
    F: FnMut(f64) -> T,
    T: Sub<Output = T> + Div<f64, Output = T>,
{
    let ahead = f(x + h);
    let behind = f(x - h);
    (ahead - behind) / (2.0 * h)
}

/// Central finite-difference gradient of a function of several variables:
/// `grad[i] = (f(x + h·eᵢ) − f(x − h·eᵢ)) / (2h)`.
///
/// Each probe moves one coordinate of a copy of `x` and restores it afterwards, so the other
/// coordinates are bit-for-bit those of `x`. Allocates one probe vector.
///
/// # Panics
/// If `grad.len() != x.len()`.
pub fn gradient<F>(mut f: F, x: &[f64], h: f64, grad: &mut [f64])
where
    F: FnMut(&[f64]) -> f64,
{
    assert_eq!(grad.len(), x.len(), "gradient length must equal x length");
    let mut probe = x.to_vec();
    for i in 0..x.len() {
        probe[i] = x[i] + h;
        let ahead = f(&probe);
        probe[i] = x[i] - h;
        let behind = f(&probe);
        probe[i] = x[i];
        grad[i] = (ahead - behind) / (2.0 * h);
    }
}

/// [`gradient`] of a function of a fixed-size array (a point's coordinates), returned by value.
pub fn gradient_array<const N: usize, F>(mut f: F, x: [f64; N], h: f64) -> [f64; N]
where
    F: FnMut([f64; N]) -> f64,
{
    std::array::from_fn(|i| {
        central_difference(
            |s| {
                let mut probe = x;
                probe[i] += s;
                f(probe)
            },
            0.0,
            h,
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn exact_on_quadratics() {
        // The central difference has no truncation error on a quadratic.
        let d: f64 = central_difference(|x| 3.0 * x * x - 2.0 * x + 1.0, 0.5, 1e-3);
        assert!((d - 1.0).abs() < 1e-9, "{d}");
    }

    #[test]
    fn a_wrong_derivative_is_caught() {
        // The check must be able to fail: sin' = cos, not −cos.
        let d: f64 = central_difference(f64::sin, 1.0, 1e-6);
        assert!((d - 1.0f64.cos()).abs() < 1e-8);
        assert!((d + 1.0f64.cos()).abs() > 0.5);
    }

    #[test]
    fn vector_values() {
        struct V(f64, f64);
        impl Sub for V {
            type Output = V;
            fn sub(self, o: V) -> V {
                V(self.0 - o.0, self.1 - o.1)
            }
        }
        impl Div<f64> for V {
            type Output = V;
            fn div(self, k: f64) -> V {
                V(self.0 / k, self.1 / k)
            }
        }
        let v = central_difference(|t| V(t.cos(), t.sin()), 0.3, 1e-6);
        assert!((v.0 + 0.3f64.sin()).abs() < 1e-9 && (v.1 - 0.3f64.cos()).abs() < 1e-9);
    }

    proptest! {
        #[test]
        fn gradient_of_a_bowl(x in proptest::collection::vec(-10.0..10.0f64, 1..6)) {
            // f = Σ (i+1)·xᵢ², ∂f/∂xᵢ = 2(i+1)·xᵢ.
            let f = |y: &[f64]| y.iter().enumerate().map(|(i, v)| (i as f64 + 1.0) * v * v).sum();
            let mut g = vec![0.0; x.len()];
            gradient(f, &x, 1e-5, &mut g);
            for (i, (gi, xi)) in g.iter().zip(&x).enumerate() {
                let exact = 2.0 * (i as f64 + 1.0) * xi;
                prop_assert!((gi - exact).abs() <= 1e-6 * (1.0 + exact.abs()), "{i}: {gi} vs {exact}");
            }
            let a = gradient_array(|p: [f64; 2]| p[0] * p[0] * p[1], [x[0], 2.0], 1e-5);
            prop_assert!((a[0] - 4.0 * x[0]).abs() <= 1e-6 * (1.0 + x[0].abs()));
            prop_assert!((a[1] - x[0] * x[0]).abs() <= 1e-6 * (1.0 + x[0] * x[0]));
        }
    }
}
