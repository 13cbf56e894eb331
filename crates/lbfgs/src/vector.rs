//! The few dense-vector kernels the solver needs, on plain slices.
//!
//! The summation order of every reduction is fixed (it depends only on the length), so results
//! are bit-reproducible across runs and machines.

/// `aᵀb`, accumulated in four interleaved partial sums (lane `k` takes entries `k, k+4, …`) and
/// combined as `(s₀ + s₁) + (s₂ + s₃) + tail`: a fixed order that lets the compiler use SIMD
/// and hides floating-point add latency.
pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    debug_assert_eq!(a.len(), b.len());
    let a_chunks = a.chunks_exact(4);
    let b_chunks = b.chunks_exact(4);
    let tail: f64 = a_chunks
        .remainder()
        .iter()
        .zip(b_chunks.remainder())
        .map(|(x, y)| x * y)
        .sum();
    let mut lanes = [0.0; 4];
    for (ca, cb) in a_chunks.zip(b_chunks) {
        for k in 0..4 {
            lanes[k] += ca[k] * cb[k];
        }
    }
    (lanes[0] + lanes[1]) + (lanes[2] + lanes[3]) + tail
}

/// `y ← y + alpha·x`.
pub(crate) fn axpy(alpha: f64, x: &[f64], y: &mut [f64]) {
    debug_assert_eq!(x.len(), y.len());
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi += alpha * xi;
    }
}

/// `out ← base + step·direction`.
pub(crate) fn step_from(base: &[f64], step: f64, direction: &[f64], out: &mut [f64]) {
    debug_assert_eq!(base.len(), out.len());
    debug_assert_eq!(direction.len(), out.len());
    for ((oi, bi), di) in out.iter_mut().zip(base).zip(direction) {
        *oi = bi + step * di;
    }
}

/// `out ← −v`.
pub(crate) fn negate_into(v: &[f64], out: &mut [f64]) {
    debug_assert_eq!(v.len(), out.len());
    for (oi, vi) in out.iter_mut().zip(v) {
        *oi = -vi;
    }
}

/// `‖v‖∞` (0 for an empty slice).
pub(crate) fn inf_norm(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, vi| m.max(vi.abs()))
}

/// `‖v‖₂`.
pub(crate) fn norm2(v: &[f64]) -> f64 {
    dot(v, v).sqrt()
}

/// True if every entry is finite.
pub(crate) fn all_finite(v: &[f64]) -> bool {
    v.iter().all(|vi| vi.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kernels_on_small_vectors() {
        let a = [1.0, -2.0, 3.0];
        let b = [4.0, 5.0, -6.0];
        assert_eq!(dot(&a, &b), 4.0 - 10.0 - 18.0);
        assert_eq!(inf_norm(&a), 3.0);
        assert_eq!(inf_norm(&[]), 0.0);
        assert_eq!(norm2(&[3.0, 4.0]), 5.0);

        let mut y = b;
        axpy(2.0, &a, &mut y);
        assert_eq!(y, [6.0, 1.0, 0.0]);

        let mut out = [0.0; 3];
        step_from(&a, 0.5, &b, &mut out);
        assert_eq!(out, [3.0, 0.5, 0.0]);
        negate_into(&a, &mut out);
        assert_eq!(out, [-1.0, 2.0, -3.0]);

        let long: Vec<f64> = (1..=11).map(f64::from).collect();
        assert_eq!(dot(&long, &long), 506.0);

        assert!(all_finite(&a));
        assert!(!all_finite(&[1.0, f64::NAN]));
    }
}
