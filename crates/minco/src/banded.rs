//! Square banded matrices with an in-place LU factorization **without pivoting**, and solves with
//! the factors for `A x = b` and `Aᵀ x = b`.
//!
//! This is the linear-algebra kernel of MINCO (paper Sec. III-D: `C = A⁻¹(T) D`): the MINCO system
//! is banded with lower and upper bandwidth 6, so factorization and both solves are O(n). The
//! transposed solve reuses the same factors and gives the adjoint `G = A⁻ᵀ ∂I/∂C` of eq.
//! analytical-gradients-I-to-S. [`crate::minco::MincoS3`] runs the same elimination specialised
//! to the MINCO sparsity pattern; this general version is its reference
//! ([`crate::minco::MincoS3::system`]) and serves any other banded system.
//!
//! Without pivoting the factorization is only safe for matrices whose leading principal minors are
//! well away from zero (diagonally dominant matrices, the MINCO matrix for reasonable durations). A
//! zero or non-finite pivot is reported as [`MincoError::SingularPivot`] instead of silently
//! producing inf/NaN.
//!
//! Storage: row-major band storage, each row holds the `lower + upper + 1` entries of columns
//! `i - lower ..= i + upper`, so the elimination updates and both solves walk contiguous memory.
//! Right-hand sides are slices of rows ([`BandRhs`]): `f64` for one column, `[f64; K]` or
//! [`nalgebra::Vector3<f64>`] for several columns solved together.

use nalgebra::Vector3;

use crate::error::MincoError;

/// One row of a right-hand side: a value that can be scaled and combined, so that several columns
/// can be solved at once while the matrix factors are read only once.
///
/// Implemented for `f64` (one column), `[f64; K]` (K columns) and `Vector3<f64>` (3 columns, the
/// MINCO x/y/z layout).
pub trait BandRhs: Copy {
    /// `self -= factor * other`.
    fn sub_scaled(&mut self, factor: f64, other: &Self);
    /// `self *= factor`.
    fn scale(&mut self, factor: f64);
    /// Whether every component is finite.
    fn all_finite(&self) -> bool;
}

impl BandRhs for f64 {
    #[inline(always)]
    fn sub_scaled(&mut self, factor: f64, other: &Self) {
        *self -= factor * other;
    }
    #[inline(always)]
    fn scale(&mut self, factor: f64) {
        *self *= factor;
    }
    #[inline(always)]
    fn all_finite(&self) -> bool {
        self.is_finite()
    }
}

impl<const K: usize> BandRhs for [f64; K] {
    #[inline(always)]
    fn sub_scaled(&mut self, factor: f64, other: &Self) {
        for (s, o) in self.iter_mut().zip(other) {
            *s -= factor * o;
        }
    }
    #[inline(always)]
    fn scale(&mut self, factor: f64) {
        for s in self.iter_mut() {
            *s *= factor;
        }
    }
    #[inline(always)]
    fn all_finite(&self) -> bool {
        self.iter().all(|s| s.is_finite())
    }
}

impl BandRhs for Vector3<f64> {
    #[inline(always)]
    fn sub_scaled(&mut self, factor: f64, other: &Self) {
        self.x -= factor * other.x;
        self.y -= factor * other.y;
        self.z -= factor * other.z;
    }
    #[inline(always)]
    fn scale(&mut self, factor: f64) {
        self.x *= factor;
        self.y *= factor;
        self.z *= factor;
    }
    #[inline(always)]
    fn all_finite(&self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.z.is_finite()
    }
}

/// A square `size × size` matrix with `lower` sub-diagonals and `upper` super-diagonals, which can
/// be LU-factorized in place (no pivoting) and then used to solve `A x = b` and `Aᵀ x = b`.
///
/// Life cycle: fill with [`set`](Self::set) (or build in place), [`factorize`](Self::factorize),
/// then any number of [`solve`](Self::solve) / [`solve_transposed`](Self::solve_transposed) calls.
/// Writing an entry or calling [`clear`](Self::clear) invalidates the factors.
#[derive(Debug, Clone, PartialEq)]
pub struct BandedMatrix {
    size: usize,
    lower: usize,
    upper: usize,
    /// Row-major band storage: entry (i, j) at `i * width + (j + lower - i)`.
    data: Vec<f64>,
    /// `1 / U(i, i)` after a successful factorization.
    inv_diag: Vec<f64>,
    factorized: bool,
}

impl BandedMatrix {
    /// A zero matrix of the given size and bandwidths. Bandwidths larger than `size - 1` are
    /// allowed (the extra diagonals are simply never used).
    pub fn zeros(size: usize, lower: usize, upper: usize) -> Self {
        let width = lower + upper + 1;
        Self {
            size,
            lower,
            upper,
            data: vec![0.0; size * width],
            inv_diag: vec![0.0; size],
            factorized: false,
        }
    }

    /// Number of rows (= columns).
    pub fn size(&self) -> usize {
        self.size
    }

    /// Number of sub-diagonals.
    pub fn lower(&self) -> usize {
        self.lower
    }

    /// Number of super-diagonals.
    pub fn upper(&self) -> usize {
        self.upper
    }

    /// Whether the matrix currently holds valid LU factors.
    #[cfg(test)]
    pub(crate) fn is_factorized(&self) -> bool {
        self.factorized
    }

    #[inline(always)]
    fn width(&self) -> usize {
        self.lower + self.upper + 1
    }

    /// Whether `(row, col)` lies inside the matrix and inside the band.
    pub fn in_band(&self, row: usize, col: usize) -> bool {
        row < self.size && col < self.size && col + self.lower >= row && col <= row + self.upper
    }

    /// Sets every entry to zero and drops the factors.
    pub fn clear(&mut self) {
        self.data.fill(0.0);
        self.factorized = false;
    }

    /// Writes entry `(row, col)`. Drops the factors.
    ///
    /// # Errors
    /// [`MincoError::OutOfBand`] if the entry is outside the matrix or the band.
    pub fn set(&mut self, row: usize, col: usize, value: f64) -> Result<(), MincoError> {
        if !self.in_band(row, col) {
            return Err(self.out_of_band(row, col));
        }
        *self.entry_mut(row, col) = value;
        self.factorized = false;
        Ok(())
    }

    /// Reads entry `(row, col)`: `Some(0.0)` outside the band, `None` outside the matrix. After
    /// [`factorize`](Self::factorize) the storage holds the factors (`L` strictly below the diagonal
    /// with an implicit unit diagonal, `U` on and above it), and this returns those.
    pub fn get(&self, row: usize, col: usize) -> Option<f64> {
        if row >= self.size || col >= self.size {
            None
        } else if self.in_band(row, col) {
            Some(self.data[row * self.width() + col + self.lower - row])
        } else {
            Some(0.0)
        }
    }

    fn out_of_band(&self, row: usize, col: usize) -> MincoError {
        MincoError::OutOfBand {
            row,
            col,
            size: self.size,
            lower: self.lower,
            upper: self.upper,
        }
    }

    /// Mutable access to an in-band entry without dropping the factors; the caller guarantees
    /// `(row, col)` is in the band (checked in debug builds).
    #[inline(always)]
    pub(crate) fn entry_mut(&mut self, row: usize, col: usize) -> &mut f64 {
        debug_assert!(self.in_band(row, col), "({row}, {col}) outside the band");
        let width = self.width();
        &mut self.data[row * width + col + self.lower - row]
    }

    /// Factorizes `A = L U` in place without pivoting (Doolittle: `L` unit lower triangular with
    /// bandwidth `lower`, `U` upper triangular with bandwidth `upper`). Zero multipliers skip their
    /// row update.
    ///
    /// # Errors
    /// [`MincoError::SingularPivot`] if a pivot is zero or not finite; the storage is then left
    /// partially eliminated and must be rebuilt before the next factorization.
    pub fn factorize(&mut self) -> Result<(), MincoError> {
        self.factorized = false;
        let (n, lower, upper, width) = (self.size, self.lower, self.upper, self.width());
        for k in 0..n {
            let inv = checked_inverse_pivot(k, self.data[k * width + lower])?;
            self.inv_diag[k] = inv;
            let i1 = (k + lower).min(n - 1);
            let len = (k + upper).min(n - 1) - k;
            // Row k lies before every row i > k in storage.
            let (top, bottom) = self.data.split_at_mut((k + 1) * width);
            let pivot_row = &top[k * width + lower + 1..k * width + lower + 1 + len];
            for i in k + 1..=i1 {
                let lik_idx = (i - k - 1) * width + k + lower - i;
                let a_ik = bottom[lik_idx];
                if a_ik != 0.0 {
                    let l = a_ik * inv;
                    bottom[lik_idx] = l;
                    let target = &mut bottom[lik_idx + 1..lik_idx + 1 + len];
                    for (t, u) in target.iter_mut().zip(pivot_row) {
                        *t -= l * u;
                    }
                }
            }
        }
        self.factorized = true;
        Ok(())
    }

    fn check_solve(&self, len: usize) -> Result<(), MincoError> {
        if !self.factorized {
            return Err(MincoError::NotFactorized);
        }
        if len != self.size {
            return Err(MincoError::LengthMismatch {
                field: "rhs",
                expected: self.size,
                got: len,
            });
        }
        Ok(())
    }

    /// Solves `A x = b` for one column in place (`b` becomes `x`).
    ///
    /// # Errors
    /// [`MincoError::NotFactorized`] before a successful [`factorize`](Self::factorize);
    /// [`MincoError::LengthMismatch`] if `b.len() != size`.
    pub fn solve(&self, b: &mut [f64]) -> Result<(), MincoError> {
        self.solve_rows(b)
    }

    /// Solves `Aᵀ x = b` for one column in place, reusing the factors of `A`.
    ///
    /// # Errors
    /// As [`solve`](Self::solve).
    pub fn solve_transposed(&self, b: &mut [f64]) -> Result<(), MincoError> {
        self.solve_transposed_rows(b)
    }

    /// Solves `A X = B` for three columns stored as rows of `Vector3` (the MINCO x/y/z layout).
    ///
    /// # Errors
    /// As [`solve`](Self::solve).
    pub fn solve_vec3(&self, b: &mut [Vector3<f64>]) -> Result<(), MincoError> {
        self.solve_rows(b)
    }

    /// Solves `Aᵀ X = B` for three columns stored as rows of `Vector3`, reusing the factors of `A`.
    ///
    /// # Errors
    /// As [`solve`](Self::solve).
    pub fn solve_transposed_vec3(&self, b: &mut [Vector3<f64>]) -> Result<(), MincoError> {
        self.solve_transposed_rows(b)
    }

    /// Solves `A X = B` in place for any row type (`f64`, `[f64; K]`, `Vector3<f64>`): all columns
    /// share one pass over the factors.
    ///
    /// # Errors
    /// As [`solve`](Self::solve).
    pub fn solve_rows<R: BandRhs>(&self, b: &mut [R]) -> Result<(), MincoError> {
        self.check_solve(b.len())?;
        let (n, lower, upper, width) = (self.size, self.lower, self.upper, self.width());
        // Forward: L y = b (unit diagonal), row-oriented over the L part of row i.
        for i in 1..n {
            let j0 = i.saturating_sub(lower);
            let row = &self.data[i * width + j0 + lower - i..i * width + lower];
            let (done, rest) = b.split_at_mut(i);
            let bi = &mut rest[0];
            for (l, bj) in row.iter().zip(&done[j0..]) {
                bi.sub_scaled(*l, bj);
            }
        }
        // Backward: U x = y, row-oriented over the U part of row i.
        for i in (0..n).rev() {
            let start = i * width + lower + 1;
            let row = &self.data[start..start + ((i + upper).min(n - 1) - i)];
            let (head, tail) = b.split_at_mut(i + 1);
            let bi = &mut head[i];
            for (u, bj) in row.iter().zip(tail.iter()) {
                bi.sub_scaled(*u, bj);
            }
            bi.scale(self.inv_diag[i]);
        }
        Ok(())
    }

    /// Solves `Aᵀ X = B` in place for any row type, reusing the factors of `A`
    /// (`Aᵀ = Uᵀ Lᵀ`: a forward pass with `Uᵀ`, then a backward pass with `Lᵀ`).
    ///
    /// # Errors
    /// As [`solve`](Self::solve).
    pub fn solve_transposed_rows<R: BandRhs>(&self, b: &mut [R]) -> Result<(), MincoError> {
        self.check_solve(b.len())?;
        let (n, lower, upper, width) = (self.size, self.lower, self.upper, self.width());
        // Forward: Uᵀ z = b, column-oriented: once z_j is final, subtract U(j, i) z_j from the
        // later rows i; U(j, j+1..) is contiguous in row j.
        for j in 0..n {
            let start = j * width + lower + 1;
            let row = &self.data[start..start + ((j + upper).min(n - 1) - j)];
            let (head, tail) = b.split_at_mut(j + 1);
            let bj = &mut head[j];
            bj.scale(self.inv_diag[j]);
            let zj = *bj;
            for (u, bi) in row.iter().zip(tail.iter_mut()) {
                bi.sub_scaled(*u, &zj);
            }
        }
        // Backward: Lᵀ x = z, column-oriented: x_j is final, subtract L(j, i) x_j from rows
        // i < j; L(j, ..j) is contiguous in row j.
        for j in (1..n).rev() {
            let i0 = j.saturating_sub(lower);
            let row = &self.data[j * width + i0 + lower - j..j * width + lower];
            let (head, tail) = b.split_at_mut(j);
            let xj = tail[0];
            for (l, bi) in row.iter().zip(head[i0..].iter_mut()) {
                bi.sub_scaled(*l, &xj);
            }
        }
        Ok(())
    }
}

#[inline(always)]
fn checked_inverse_pivot(row: usize, pivot: f64) -> Result<f64, MincoError> {
    let inv = 1.0 / pivot;
    if pivot == 0.0 || !pivot.is_finite() || !inv.is_finite() {
        return Err(MincoError::SingularPivot { row, value: pivot });
    }
    Ok(inv)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn tridiagonal(n: usize) -> BandedMatrix {
        let mut m = BandedMatrix::zeros(n, 1, 1);
        for i in 0..n {
            m.set(i, i, 4.0).unwrap();
            if i > 0 {
                m.set(i, i - 1, -1.0).unwrap();
            }
            if i + 1 < n {
                m.set(i, i + 1, 2.0).unwrap();
            }
        }
        m
    }

    fn dense_mul(m: &BandedMatrix, x: &[f64], transposed: bool) -> Vec<f64> {
        let n = m.size();
        (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| {
                        let a = if transposed { m.get(j, i) } else { m.get(i, j) };
                        a.unwrap_or(0.0) * x[j]
                    })
                    .sum()
            })
            .collect()
    }

    #[test]
    fn tridiagonal_solve_and_transposed_solve_reproduce_rhs() {
        let a = tridiagonal(7);
        let mut lu = a.clone();
        lu.factorize().unwrap();
        let b: Vec<f64> = (0..7).map(|i| (i as f64).sin() + 1.0).collect();
        let mut x = b.clone();
        lu.solve(&mut x).unwrap();
        for (got, want) in dense_mul(&a, &x, false).iter().zip(&b) {
            assert_relative_eq!(*got, *want, epsilon = 1e-12);
        }
        let mut y = b.clone();
        lu.solve_transposed(&mut y).unwrap();
        for (got, want) in dense_mul(&a, &y, true).iter().zip(&b) {
            assert_relative_eq!(*got, *want, epsilon = 1e-12);
        }
    }

    #[test]
    fn multi_column_rows_match_single_columns() {
        let a = tridiagonal(5);
        let mut lu = a;
        lu.factorize().unwrap();
        let mut rows: Vec<Vector3<f64>> = (0..5)
            .map(|i| Vector3::new(i as f64, 1.0, -(i as f64) * 0.5))
            .collect();
        let mut arrays: Vec<[f64; 3]> = rows.iter().map(|r| [r.x, r.y, r.z]).collect();
        let mut col_y: Vec<f64> = rows.iter().map(|r| r.y).collect();
        lu.solve_transposed_vec3(&mut rows).unwrap();
        lu.solve_transposed_rows(&mut arrays).unwrap();
        lu.solve_transposed(&mut col_y).unwrap();
        for i in 0..5 {
            assert_relative_eq!(rows[i].y, col_y[i], epsilon = 1e-14);
            assert_relative_eq!(rows[i].x, arrays[i][0], epsilon = 1e-14);
            assert_relative_eq!(rows[i].z, arrays[i][2], epsilon = 1e-14);
        }
    }

    #[test]
    fn zero_pivot_is_an_error_not_nan() {
        let mut a = BandedMatrix::zeros(3, 1, 1);
        a.set(0, 0, 1.0).unwrap();
        a.set(0, 1, 1.0).unwrap();
        a.set(1, 0, 1.0).unwrap();
        a.set(1, 1, 1.0).unwrap(); // second pivot becomes exactly zero
        a.set(2, 2, 1.0).unwrap();
        assert_eq!(
            a.factorize(),
            Err(MincoError::SingularPivot { row: 1, value: 0.0 })
        );
        assert!(!a.is_factorized());
        let mut b = vec![1.0; 3];
        assert_eq!(a.solve(&mut b), Err(MincoError::NotFactorized));
    }

    #[test]
    fn non_finite_pivot_is_an_error() {
        let mut a = BandedMatrix::zeros(2, 0, 0);
        a.set(0, 0, f64::NAN).unwrap();
        assert!(matches!(
            a.factorize(),
            Err(MincoError::SingularPivot { row: 0, .. })
        ));
        let mut tiny = BandedMatrix::zeros(1, 0, 0);
        tiny.set(0, 0, 1e-320).unwrap(); // 1/pivot overflows
        assert!(tiny.factorize().is_err());
    }

    #[test]
    fn out_of_band_and_length_errors() {
        let mut a = BandedMatrix::zeros(4, 1, 2);
        assert!(a.set(3, 1, 1.0).is_err());
        assert!(a.set(0, 3, 1.0).is_err());
        assert!(a.set(4, 4, 1.0).is_err());
        assert!(a.set(0, 2, 1.0).is_ok());
        assert_eq!(a.get(3, 0), Some(0.0));
        assert_eq!(a.get(4, 0), None);
        for i in 0..4 {
            a.set(i, i, 1.0).unwrap();
        }
        a.factorize().unwrap();
        let mut short = vec![0.0; 3];
        assert_eq!(
            a.solve(&mut short),
            Err(MincoError::LengthMismatch {
                field: "rhs",
                expected: 4,
                got: 3
            })
        );
        a.set(0, 0, 2.0).unwrap();
        assert!(!a.is_factorized());
    }

    #[test]
    fn empty_and_oversized_bandwidth_matrices_work() {
        let mut empty = BandedMatrix::zeros(0, 2, 2);
        empty.factorize().unwrap();
        empty.solve(&mut []).unwrap();
        let mut small = BandedMatrix::zeros(2, 6, 6);
        small.set(0, 0, 2.0).unwrap();
        small.set(0, 1, 1.0).unwrap();
        small.set(1, 0, 1.0).unwrap();
        small.set(1, 1, 3.0).unwrap();
        small.factorize().unwrap();
        let mut b = [3.0, 4.0];
        small.solve(&mut b).unwrap();
        assert_relative_eq!(b[0], 1.0, epsilon = 1e-14);
        assert_relative_eq!(b[1], 1.0, epsilon = 1e-14);
    }

    mod against_faer {
        use super::*;
        use faer::Mat;
        use faer::prelude::Solve;
        use proptest::prelude::*;
        use rand::{Rng, SeedableRng};
        use rand_chacha::ChaCha8Rng;

        /// A random banded matrix, strictly diagonally dominant by rows and by columns (so LU
        /// without pivoting exists and is stable), as banded storage and as a dense faer matrix.
        fn random_system(n: usize, p: usize, q: usize, seed: u64) -> (BandedMatrix, Mat<f64>) {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let mut dense = Mat::<f64>::zeros(n, n);
            for i in 0..n {
                for j in i.saturating_sub(p)..(i + q + 1).min(n) {
                    if i != j {
                        dense[(i, j)] = rng.random_range(-1.0..1.0);
                    }
                }
            }
            for i in 0..n {
                let row: f64 = (0..n).map(|j| dense[(i, j)].abs()).sum();
                let col: f64 = (0..n).map(|j| dense[(j, i)].abs()).sum();
                let sign = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
                dense[(i, i)] = sign * (row.max(col) + rng.random_range(0.1..1.0));
            }
            let mut banded = BandedMatrix::zeros(n, p, q);
            for i in 0..n {
                for j in i.saturating_sub(p)..(i + q + 1).min(n) {
                    banded.set(i, j, dense[(i, j)]).unwrap();
                }
            }
            (banded, dense)
        }

        fn random_rhs(n: usize, seed: u64) -> Vec<Vector3<f64>> {
            let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x9e37_79b9_7f4a_7c15);
            (0..n)
                .map(|_| {
                    Vector3::new(
                        rng.random_range(-10.0..10.0),
                        rng.random_range(-10.0..10.0),
                        rng.random_range(-10.0..10.0),
                    )
                })
                .collect()
        }

        fn to_faer(rhs: &[Vector3<f64>]) -> Mat<f64> {
            Mat::from_fn(rhs.len(), 3, |i, j| rhs[i][j])
        }

        fn assert_close(ours: &[Vector3<f64>], theirs: &Mat<f64>) -> Result<(), TestCaseError> {
            let scale = ours.iter().map(|v| v.amax()).fold(1.0, f64::max);
            for (i, v) in ours.iter().enumerate() {
                for j in 0..3 {
                    let err = (v[j] - theirs[(i, j)]).abs();
                    prop_assert!(
                        err <= 1e-11 * scale,
                        "row {i} col {j}: ours {} faer {} (error {err:e})",
                        v[j],
                        theirs[(i, j)]
                    );
                }
            }
            Ok(())
        }

        proptest! {
            #[test]
            fn solve_matches_dense_lu(
                n in 1usize..=60, p in 1usize..=7, q in 1usize..=7, seed in any::<u64>()
            ) {
                let (mut banded, dense) = random_system(n, p, q, seed);
                banded.factorize().unwrap();
                let rhs = random_rhs(n, seed);
                let lu = dense.partial_piv_lu();

                let mut ours = rhs.clone();
                banded.solve_vec3(&mut ours).unwrap();
                assert_close(&ours, &lu.solve(to_faer(&rhs)))?;

                let mut ours_t = rhs.clone();
                banded.solve_transposed_vec3(&mut ours_t).unwrap();
                assert_close(&ours_t, &lu.solve_transpose(to_faer(&rhs)))?;

                // The single-column entry points agree with the multi-column ones.
                let mut column: Vec<f64> = rhs.iter().map(|v| v.y).collect();
                banded.solve_transposed(&mut column).unwrap();
                for (c, v) in column.iter().zip(&ours_t) {
                    prop_assert!((c - v.y).abs() <= 1e-12 * (1.0 + v.y.abs()));
                }
                let mut column: Vec<f64> = rhs.iter().map(|v| v.z).collect();
                banded.solve(&mut column).unwrap();
                for (c, v) in column.iter().zip(&ours) {
                    prop_assert!((c - v.z).abs() <= 1e-12 * (1.0 + v.z.abs()));
                }
            }
        }
    }
}
