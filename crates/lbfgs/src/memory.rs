//! The limited memory: a ring buffer of correction pairs and the two-loop recursion.

use crate::vector::{axpy, dot};

/// The `capacity` most recent correction pairs `s = x_{k+1} − x_k`, `y = g_{k+1} − g_k` of an
/// `n`-dimensional problem, stored column-wise in preallocated flat buffers.
#[derive(Debug, Clone)]
pub(crate) struct CorrectionMemory {
    dimension: usize,
    capacity: usize,
    /// Pair `j` occupies `s[j·n .. (j+1)·n]`.
    s: Vec<f64>,
    /// Pair `j` occupies `y[j·n .. (j+1)·n]`.
    y: Vec<f64>,
    /// `yⱼᵀsⱼ` (positive for every stored pair).
    ys: Vec<f64>,
    /// `yⱼᵀyⱼ`.
    yy: Vec<f64>,
    /// Scratch for the two-loop recursion.
    alpha: Vec<f64>,
    /// Number of stored pairs (at most `capacity`).
    len: usize,
    /// Slot the next pair is written to (the oldest pair once the buffer is full).
    next: usize,
}

impl CorrectionMemory {
    /// An empty memory for `capacity >= 1` pairs of dimension `dimension`.
    pub(crate) fn new(dimension: usize, capacity: usize) -> Self {
        Self {
            dimension,
            capacity,
            s: vec![0.0; dimension * capacity],
            y: vec![0.0; dimension * capacity],
            ys: vec![0.0; capacity],
            yy: vec![0.0; capacity],
            alpha: vec![0.0; capacity],
            len: 0,
            next: 0,
        }
    }

    /// Forgets every pair.
    pub(crate) fn clear(&mut self) {
        self.len = 0;
        self.next = 0;
    }

    /// True if no pair is stored.
    pub(crate) fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Offers the pair `s = x − x_prev`, `y = g − g_prev` and stores it (dropping the oldest pair
    /// if full) only if it passes the cautious test of Li and Fukushima (2001) as LBFGS-Lite
    /// applies it: `yᵀs > cautious_factor·‖s‖₂²·‖g_prev‖₂`. Returns whether it was stored.
    pub(crate) fn push_if_cautious(
        &mut self,
        x: &[f64],
        x_prev: &[f64],
        g: &[f64],
        g_prev: &[f64],
        cautious_factor: f64,
    ) -> bool {
        let (mut ys, mut ss, mut yy) = (0.0, 0.0, 0.0);
        for i in 0..self.dimension {
            let si = x[i] - x_prev[i];
            let yi = g[i] - g_prev[i];
            ys += yi * si;
            ss += si * si;
            yy += yi * yi;
        }
        let threshold = cautious_factor * ss * dot(g_prev, g_prev).sqrt();
        let usable = ys > threshold && ys > 0.0 && ys.is_finite() && yy.is_finite();
        if !usable {
            return false;
        }
        let slot = self.next;
        let range = self.column(slot);
        for (k, i) in range.enumerate() {
            self.s[i] = x[k] - x_prev[k];
            self.y[i] = g[k] - g_prev[k];
        }
        self.ys[slot] = ys;
        self.yy[slot] = yy;
        self.next = (slot + 1) % self.capacity;
        self.len = (self.len + 1).min(self.capacity);
        true
    }

    /// `d ← H·d`, with `H` the L-BFGS inverse-Hessian approximation built from the stored pairs
    /// and the initial scaling `H₀ = (yᵀs / yᵀy)·I` of the newest pair (Nocedal 1980, the
    /// two-loop recursion). Leaves `d` unchanged if the memory is empty.
    pub(crate) fn apply_inverse_hessian(&mut self, d: &mut [f64]) {
        if self.is_empty() {
            return;
        }
        let n = self.dimension;
        let newest = self.slot_back(1);
        let oldest = self.slot_back(self.len);
        // Newest to oldest (slots step down through the ring, without a modulo per pair).
        let mut j = newest;
        for _ in 0..self.len {
            let (s, y) = (&self.s[j * n..(j + 1) * n], &self.y[j * n..(j + 1) * n]);
            let alpha = dot(s, d) / self.ys[j];
            self.alpha[j] = alpha;
            axpy(-alpha, y, d);
            j = if j == 0 { self.capacity - 1 } else { j - 1 };
        }
        let gamma = self.ys[newest] / self.yy[newest];
        for di in d.iter_mut() {
            *di *= gamma;
        }
        // Oldest to newest.
        let mut j = oldest;
        for _ in 0..self.len {
            let (s, y) = (&self.s[j * n..(j + 1) * n], &self.y[j * n..(j + 1) * n]);
            let beta = dot(y, d) / self.ys[j];
            axpy(self.alpha[j] - beta, s, d);
            j = if j + 1 == self.capacity { 0 } else { j + 1 };
        }
    }

    /// Slot of the pair stored `back` pushes ago (1 = newest).
    fn slot_back(&self, back: usize) -> usize {
        (self.next + self.capacity - back) % self.capacity
    }

    /// Index range of column `slot` in the flat buffers.
    fn column(&self, slot: usize) -> std::ops::Range<usize> {
        slot * self.dimension..(slot + 1) * self.dimension
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// After the ring has wrapped, the recursion uses the newest `capacity` pairs in order: it
    /// matches a plain two-loop recursion over a list of those pairs.
    #[test]
    fn a_wrapped_ring_matches_the_two_loop_over_the_newest_pairs() {
        let (n, capacity, pushes) = (4, 3, 7);
        let mut memory = CorrectionMemory::new(n, capacity);
        let mut pairs: Vec<(Vec<f64>, Vec<f64>)> = Vec::new();
        let zero = vec![0.0; n];
        for k in 0..pushes {
            // Positive curvature: y = diag(1 + i + k)·s with s varying by pair.
            let s: Vec<f64> = (0..n).map(|i| ((k * 7 + i * 3) % 5) as f64 - 1.5).collect();
            let y: Vec<f64> = (0..n).map(|i| (1.0 + (i + k) as f64) * s[i]).collect();
            assert!(memory.push_if_cautious(&s, &zero, &y, &zero, 0.0));
            pairs.push((s, y));
        }
        let newest = &pairs[pushes - capacity..];
        let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
        let d0: Vec<f64> = (0..n).map(|i| 0.7 - 0.4 * i as f64).collect();
        let mut expected = d0.clone();
        let mut alphas = vec![0.0; capacity];
        for (j, (s, y)) in newest.iter().enumerate().rev() {
            alphas[j] = dot(s, &expected) / dot(y, s);
            for i in 0..n {
                expected[i] -= alphas[j] * y[i];
            }
        }
        let (s, y) = newest.last().unwrap();
        let gamma = dot(y, s) / dot(y, y);
        expected.iter_mut().for_each(|e| *e *= gamma);
        for (j, (s, y)) in newest.iter().enumerate() {
            let beta = dot(y, &expected) / dot(y, s);
            for i in 0..n {
                expected[i] += (alphas[j] - beta) * s[i];
            }
        }
        let mut d = d0;
        memory.apply_inverse_hessian(&mut d);
        for i in 0..n {
            approx::assert_relative_eq!(d[i], expected[i], max_relative = 1e-12);
        }
    }

    /// With one pair from a quadratic with Hessian `diag(a)`, the result must satisfy the secant
    /// equation `H·y = s`.
    #[test]
    fn secant_equation_holds_for_newest_pair() {
        let mut memory = CorrectionMemory::new(3, 4);
        let x_prev = [0.0, 0.0, 0.0];
        let x = [1.0, -2.0, 0.5];
        let hess = [2.0, 5.0, 1.0];
        let g_prev = [0.3, -0.1, 0.2];
        let g: Vec<f64> = (0..3)
            .map(|i| g_prev[i] + hess[i] * (x[i] - x_prev[i]))
            .collect();
        assert!(memory.push_if_cautious(&x, &x_prev, &g, &g_prev, 1e-6));

        let mut d: Vec<f64> = (0..3).map(|i| g[i] - g_prev[i]).collect();
        memory.apply_inverse_hessian(&mut d);
        for i in 0..3 {
            approx::assert_relative_eq!(d[i], x[i] - x_prev[i], epsilon = 1e-12);
        }
    }

    #[test]
    fn cautious_test_rejects_negative_curvature_and_keeps_capacity() {
        let mut memory = CorrectionMemory::new(1, 2);
        // y·s < 0: rejected.
        assert!(!memory.push_if_cautious(&[1.0], &[0.0], &[-1.0], &[0.0], 1e-6));
        assert!(memory.is_empty());
        for k in 0..5 {
            let x = [k as f64 + 1.0];
            assert!(memory.push_if_cautious(&x, &[k as f64], &[1.0], &[0.0], 1e-6));
        }
        assert_eq!(memory.len, 2);
        memory.clear();
        assert!(memory.is_empty());
    }

    #[test]
    fn empty_memory_is_identity() {
        let mut memory = CorrectionMemory::new(2, 3);
        let mut d = [1.5, -2.0];
        memory.apply_inverse_hessian(&mut d);
        assert_eq!(d, [1.5, -2.0]);
    }
}
