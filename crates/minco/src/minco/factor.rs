//! Structure-aware LU of the MINCO s = 3 matrix `A(T)`.
//!
//! This is exactly the banded LU without pivoting of [`crate::banded::BandedMatrix`] (same
//! elimination order, same pivots), restricted to the entries that are structurally non-zero: of
//! the 6 × 13 band entries per piece, the factors have 20 non-zeros in `L` and 11 off-diagonal
//! non-zeros in `U`. The code is straight-line per piece (no index arithmetic, no branches), which
//! is what makes it several times faster than the general band loops.
//!
//! # Structure (piece `i`, `r = 6i`, columns `r..r+6` are the coefficients `c0..c5`)
//!
//! Columns `r, r+1, r+2` are pivoted by three rows `R0, R1, R2` that come from the previous
//! junction (its position, velocity and acceleration continuity rows) or, for piece 0, the head
//! rows. Their pivots are `d = (-1, -1, -2)` (head: `(1, 1, 2)`); `R0` has no other `U` entry, `R1`
//! and `R2` have `U` entries `e1, f1` and `e2, f2` in columns `r+3, r+4` ([`Incoming`]).
//!
//! For an inner piece, row `r+3` (jerk, pivot 6) and row `r+4` (snap, pivot 24) are untouched by
//! the elimination. The waypoint row `w = r+5` gets multipliers `lw[0..5]` for columns `r..r+4`,
//! pivot `W`, and `U` entries `w9, w10` in columns `r+9, r+10`. The position-continuity row `r+6`
//! receives exactly the same updates as `w` (identical entries), so its multipliers are `lw` plus
//! `1` in column `r+5`, and its `U` part reduces to its pivot `−1`. The velocity row `r+7` has
//! multipliers `lv` in columns `r+1..r+5` and the acceleration row `r+8` has `la` in `r+2..r+5`;
//! their `U` entries in columns `r+9, r+10` are the next piece's `e1, f1, e2, f2`.
//!
//! For the last piece the three tail rows `r+3..r+5` form a dense 3 × 3 trailing block after
//! their multipliers `lp` (columns `r..r+2`), `lv` (`r+1..r+3`) and `la` (`r+2..r+4`).

use nalgebra::Vector3;

use crate::error::MincoError;

/// The three rows that pivot columns `r, r+1, r+2` of a piece: inverse pivots and their `U`
/// entries in columns `r+3` (`e`) and `r+4` (`f`).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Incoming {
    inv_d: [f64; 3],
    e1: f64,
    f1: f64,
    e2: f64,
    f2: f64,
}

/// Head rows `c00 = p, c01 = v, 2 c02 = a`.
const HEAD: Incoming = Incoming {
    inv_d: [1.0, 1.0, 0.5],
    e1: 0.0,
    f1: 0.0,
    e2: 0.0,
    f2: 0.0,
};

/// Factors of the rows of an inner junction (rows `r+3 ..= r+8` of piece `i`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct JunctionFactors {
    /// `L` of the waypoint row (and of the position row) in columns `r..r+4`.
    lw: [f64; 5],
    /// `L` of the velocity row in columns `r+1..r+5`.
    lv: [f64; 5],
    /// `L` of the acceleration row in columns `r+2..r+5`.
    la: [f64; 4],
    /// `1 / W`, the waypoint row's pivot.
    inv_w: f64,
    /// `U` of the waypoint row in columns `r+9, r+10`.
    w9: f64,
    w10: f64,
    /// `U` of the velocity and acceleration rows in columns `r+9, r+10`.
    e1: f64,
    f1: f64,
    e2: f64,
    f2: f64,
}

impl JunctionFactors {
    fn outgoing(&self) -> Incoming {
        Incoming {
            inv_d: [-1.0, -1.0, -0.5],
            e1: self.e1,
            f1: self.f1,
            e2: self.e2,
            f2: self.f2,
        }
    }
}

/// Factors of the three tail rows (`6n−3 ..= 6n−1`).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct TailFactors {
    /// `L` of the tail-position row in columns `r..r+2`.
    lp: [f64; 3],
    /// `L` of the tail-velocity row in columns `r+1..r+3`.
    lv: [f64; 3],
    /// `L` of the tail-acceleration row in columns `r+2..r+4`.
    la: [f64; 3],
    inv_p3: f64,
    p4: f64,
    p5: f64,
    inv_v4: f64,
    v5: f64,
    inv_a5: f64,
}

#[inline(always)]
fn inverse_pivot(row: usize, pivot: f64) -> Result<f64, MincoError> {
    let inv = 1.0 / pivot;
    if pivot != 0.0 && pivot.is_finite() && inv.is_finite() {
        Ok(inv)
    } else {
        Err(MincoError::SingularPivot { row, value: pivot })
    }
}

/// LU factors of `A(T)` for `n` pieces, stored per piece.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct MincoFactors {
    junctions: Vec<JunctionFactors>,
    tail: TailFactors,
}

impl MincoFactors {
    /// Storage for `pieces ≥ 1` pieces.
    pub(crate) fn new(pieces: usize) -> Self {
        Self {
            junctions: vec![JunctionFactors::default(); pieces.saturating_sub(1)],
            tail: TailFactors::default(),
        }
    }

    #[inline(always)]
    fn incoming(&self, piece: usize) -> Incoming {
        if piece == 0 {
            HEAD
        } else {
            self.junctions[piece - 1].outgoing()
        }
    }

    /// Factorizes `A(T)` given the duration powers `[1, T, …, T⁵]` of every piece.
    pub(crate) fn factorize(&mut self, powers: &[[f64; 6]]) -> Result<(), MincoError> {
        let n = powers.len();
        let mut inc = HEAD;
        for (i, (jf, pw)) in self.junctions.iter_mut().zip(powers).enumerate() {
            *jf = factor_junction(&inc, pw, 6 * i + 5)?;
            inc = jf.outgoing();
        }
        self.tail = factor_tail(&inc, &powers[n - 1], 6 * n - 3)?;
        Ok(())
    }

    /// Solves `A x = b` in place (`b`: `6n` rows).
    pub(crate) fn solve(&self, powers: &[[f64; 6]], b: &mut [Vector3<f64>]) {
        let n = powers.len();
        // Forward: L y = b. Head rows and jerk/snap rows have no L entries.
        for (i, jf) in self.junctions.iter().enumerate() {
            let r = 6 * i;
            let y = &mut b[r..r + 9];
            let bw = y[5];
            let s = y[0] * jf.lw[0]
                + y[1] * jf.lw[1]
                + y[2] * jf.lw[2]
                + y[3] * jf.lw[3]
                + y[4] * jf.lw[4];
            y[5] = bw - s;
            // Row r+6 has the same multipliers as w plus 1 at w: y6 = b6 − s − y5 = b6 − bw.
            y[6] -= bw;
            y[7] -= y[1] * jf.lv[0]
                + y[2] * jf.lv[1]
                + y[3] * jf.lv[2]
                + y[4] * jf.lv[3]
                + y[5] * jf.lv[4];
            y[8] -= y[2] * jf.la[0] + y[3] * jf.la[1] + y[4] * jf.la[2] + y[5] * jf.la[3];
        }
        let r = 6 * (n - 1);
        let tf = &self.tail;
        {
            let y = &mut b[r..r + 6];
            y[3] -= y[0] * tf.lp[0] + y[1] * tf.lp[1] + y[2] * tf.lp[2];
            y[4] -= y[1] * tf.lv[0] + y[2] * tf.lv[1] + y[3] * tf.lv[2];
            y[5] -= y[2] * tf.la[0] + y[3] * tf.la[1] + y[4] * tf.la[2];
        }
        // Backward: U x = y.
        {
            let inc = self.incoming(n - 1);
            let x = &mut b[r..r + 6];
            x[5] *= tf.inv_a5;
            x[4] = (x[4] - x[5] * tf.v5) * tf.inv_v4;
            x[3] = (x[3] - x[4] * tf.p4 - x[5] * tf.p5) * tf.inv_p3;
            backward_incoming(&inc, x);
        }
        for i in (0..n - 1).rev() {
            let r = 6 * i;
            let jf = &self.junctions[i];
            let pw = &powers[i];
            let inc = self.incoming(i);
            let x = &mut b[r..r + 11];
            x[5] = (x[5] - x[9] * jf.w9 - x[10] * jf.w10) * jf.inv_w;
            x[4] = (x[4] - x[5] * (120.0 * pw[1]) + x[10] * 24.0) * (1.0 / 24.0);
            x[3] =
                (x[3] - x[4] * (24.0 * pw[1]) - x[5] * (60.0 * pw[2]) + x[9] * 6.0) * (1.0 / 6.0);
            backward_incoming(&inc, x);
        }
    }

    /// Solves `Aᵀ x = g` in place (`g`: `6n` rows), reusing the factors.
    pub(crate) fn solve_transposed(&self, powers: &[[f64; 6]], g: &mut [Vector3<f64>]) {
        let n = powers.len();
        // Forward: Uᵀ z = g.
        for (i, pw) in powers.iter().enumerate() {
            let r = 6 * i;
            let inc = self.incoming(i);
            g[r] *= inc.inv_d[0];
            g[r + 1] *= inc.inv_d[1];
            g[r + 2] *= inc.inv_d[2];
            // U entries of the rows above in columns r+3 and r+4.
            let mut c3 = g[r + 1] * inc.e1 + g[r + 2] * inc.e2;
            let mut c4 = g[r + 1] * inc.f1 + g[r + 2] * inc.f2;
            if i > 0 {
                let prev = &self.junctions[i - 1];
                // Previous jerk row (−6), snap row (−24) and waypoint row (w9, w10).
                c3 += g[r - 1] * prev.w9 - g[r - 3] * 6.0;
                c4 += g[r - 1] * prev.w10 - g[r - 2] * 24.0;
            }
            if i + 1 < n {
                let jf = &self.junctions[i];
                g[r + 3] = (g[r + 3] - c3) * (1.0 / 6.0);
                g[r + 4] = (g[r + 4] - c4 - g[r + 3] * (24.0 * pw[1])) * (1.0 / 24.0);
                g[r + 5] =
                    (g[r + 5] - g[r + 3] * (60.0 * pw[2]) - g[r + 4] * (120.0 * pw[1])) * jf.inv_w;
            } else {
                let tf = &self.tail;
                g[r + 3] = (g[r + 3] - c3) * tf.inv_p3;
                g[r + 4] = (g[r + 4] - c4 - g[r + 3] * tf.p4) * tf.inv_v4;
                g[r + 5] = (g[r + 5] - g[r + 3] * tf.p5 - g[r + 4] * tf.v5) * tf.inv_a5;
            }
        }
        // Backward: Lᵀ x = z.
        let r = 6 * (n - 1);
        {
            let tf = &self.tail;
            let x = &mut g[r..r + 6];
            x[4] -= x[5] * tf.la[2];
            x[3] -= x[4] * tf.lv[2] + x[5] * tf.la[1];
            x[2] -= x[3] * tf.lp[2] + x[4] * tf.lv[1] + x[5] * tf.la[0];
            x[1] -= x[3] * tf.lp[1] + x[4] * tf.lv[0];
            x[0] -= x[3] * tf.lp[0];
        }
        for i in (0..n - 1).rev() {
            let r = 6 * i;
            let jf = &self.junctions[i];
            let x = &mut g[r..r + 9];
            x[5] -= x[6] + x[7] * jf.lv[4] + x[8] * jf.la[3];
            let q = x[5] + x[6];
            x[4] -= q * jf.lw[4] + x[7] * jf.lv[3] + x[8] * jf.la[2];
            x[3] -= q * jf.lw[3] + x[7] * jf.lv[2] + x[8] * jf.la[1];
            x[2] -= q * jf.lw[2] + x[7] * jf.lv[1] + x[8] * jf.la[0];
            x[1] -= q * jf.lw[1] + x[7] * jf.lv[0];
            x[0] -= q * jf.lw[0];
        }
    }
}

/// Back substitution of the three incoming rows (`x[3]`, `x[4]` already final).
#[inline(always)]
fn backward_incoming(inc: &Incoming, x: &mut [Vector3<f64>]) {
    x[2] = (x[2] - x[3] * inc.e2 - x[4] * inc.f2) * inc.inv_d[2];
    x[1] = (x[1] - x[3] * inc.e1 - x[4] * inc.f1) * inc.inv_d[1];
    x[0] *= inc.inv_d[0];
}

/// Eliminates columns `r..r+5` of an inner piece (see the module docs); `w_row` is the global
/// index of the waypoint row, for error reports.
#[inline(always)]
fn factor_junction(
    inc: &Incoming,
    pw: &[f64; 6],
    w_row: usize,
) -> Result<JunctionFactors, MincoError> {
    let [_, t1, t2, t3, t4, t5] = *pw;
    let [id0, id1, id2] = inc.inv_d;
    // Columns r, r+1, r+2 (incoming pivots).
    let lw0 = id0;
    let lw1 = t1 * id1;
    let lv1 = id1;
    let lw2 = t2 * id2;
    let lv2 = 2.0 * t1 * id2;
    let la2 = 2.0 * id2;
    let w3 = t3 - lw1 * inc.e1 - lw2 * inc.e2;
    let mut w4 = t4 - lw1 * inc.f1 - lw2 * inc.f2;
    let v3 = 3.0 * t2 - lv1 * inc.e1 - lv2 * inc.e2;
    let mut v4 = 4.0 * t3 - lv1 * inc.f1 - lv2 * inc.f2;
    let a3 = 6.0 * t1 - la2 * inc.e2;
    let mut a4 = 12.0 * t2 - la2 * inc.f2;
    // Column r+3: jerk row, pivot 6, U = (24T, 60T², −6 at r+9).
    let (lw3, lv3, la3) = (w3 / 6.0, v3 / 6.0, a3 / 6.0);
    let (u34, u35) = (24.0 * t1, 60.0 * t2);
    w4 -= lw3 * u34;
    v4 -= lv3 * u34;
    a4 -= la3 * u34;
    let mut w5 = t5 - lw3 * u35;
    let mut v5 = 5.0 * t4 - lv3 * u35;
    let mut a5 = 20.0 * t3 - la3 * u35;
    // Column r+4: snap row, pivot 24, U = (120T, −24 at r+10).
    let (lw4, lv4, la4) = (w4 / 24.0, v4 / 24.0, a4 / 24.0);
    let u45 = 120.0 * t1;
    w5 -= lw4 * u45;
    v5 -= lv4 * u45;
    a5 -= la4 * u45;
    // Column r+5: waypoint row, pivot W, U = (w9, w10) = (6 lw3, 24 lw4) at r+9, r+10.
    let inv_w = inverse_pivot(w_row, w5)?;
    let (w9, w10) = (w3, w4);
    let lv5 = v5 * inv_w;
    let la5 = a5 * inv_w;
    Ok(JunctionFactors {
        lw: [lw0, lw1, lw2, lw3, lw4],
        lv: [lv1, lv2, lv3, lv4, lv5],
        la: [la2, la3, la4, la5],
        inv_w,
        w9,
        w10,
        e1: v3 - lv5 * w9,
        f1: v4 - lv5 * w10,
        e2: a3 - la5 * w9,
        f2: a4 - la5 * w10,
    })
}

/// Eliminates the last piece's columns with the three tail rows; `p_row` is the global index of
/// the tail-position row.
#[inline(always)]
fn factor_tail(inc: &Incoming, pw: &[f64; 6], p_row: usize) -> Result<TailFactors, MincoError> {
    let [_, t1, t2, t3, t4, t5] = *pw;
    let [id0, id1, id2] = inc.inv_d;
    let lp0 = id0;
    let lp1 = t1 * id1;
    let lv1 = id1;
    let lp2 = t2 * id2;
    let lv2 = 2.0 * t1 * id2;
    let la2 = 2.0 * id2;
    let p3 = t3 - lp1 * inc.e1 - lp2 * inc.e2;
    let p4 = t4 - lp1 * inc.f1 - lp2 * inc.f2;
    let p5 = t5;
    let v3 = 3.0 * t2 - lv1 * inc.e1 - lv2 * inc.e2;
    let mut v4 = 4.0 * t3 - lv1 * inc.f1 - lv2 * inc.f2;
    let mut v5 = 5.0 * t4;
    let a3 = 6.0 * t1 - la2 * inc.e2;
    let mut a4 = 12.0 * t2 - la2 * inc.f2;
    let mut a5 = 20.0 * t3;
    let inv_p3 = inverse_pivot(p_row, p3)?;
    let lv3 = v3 * inv_p3;
    let la3 = a3 * inv_p3;
    v4 -= lv3 * p4;
    v5 -= lv3 * p5;
    a4 -= la3 * p4;
    a5 -= la3 * p5;
    let inv_v4 = inverse_pivot(p_row + 1, v4)?;
    let la4 = a4 * inv_v4;
    a5 -= la4 * v5;
    let inv_a5 = inverse_pivot(p_row + 2, a5)?;
    Ok(TailFactors {
        lp: [lp0, lp1, lp2],
        lv: [lv1, lv2, lv3],
        la: [la2, la3, la4],
        inv_p3,
        p4,
        p5,
        inv_v4,
        v5,
        inv_a5,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::banded::BandedMatrix;
    use crate::minco::energy::powers;
    use crate::minco::{MINCO_BANDWIDTH, build_matrix};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn random_rows(rng: &mut ChaCha8Rng, rows: usize) -> Vec<Vector3<f64>> {
        (0..rows)
            .map(|_| {
                Vector3::new(
                    rng.random_range(-5.0..5.0),
                    rng.random_range(-5.0..5.0),
                    rng.random_range(-5.0..5.0),
                )
            })
            .collect()
    }

    /// The structured factorization solves the same system as the general banded LU, for dense
    /// right-hand sides (not only MINCO's sparse one) and for the transposed system.
    #[test]
    fn structured_lu_matches_general_banded_lu() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for n in 1..=7 {
            for _ in 0..20 {
                let pw: Vec<[f64; 6]> = (0..n)
                    .map(|_| powers(rng.random_range(0.05..3.0)))
                    .collect();
                let mut general = BandedMatrix::zeros(6 * n, MINCO_BANDWIDTH, MINCO_BANDWIDTH);
                build_matrix(&mut general, &pw);
                general.factorize().unwrap();
                let mut structured = MincoFactors::new(n);
                structured.factorize(&pw).unwrap();

                let rhs = random_rows(&mut rng, 6 * n);
                for transposed in [false, true] {
                    let mut want = rhs.clone();
                    let mut got = rhs.clone();
                    if transposed {
                        general.solve_transposed_vec3(&mut want).unwrap();
                        structured.solve_transposed(&pw, &mut got);
                    } else {
                        general.solve_vec3(&mut want).unwrap();
                        structured.solve(&pw, &mut got);
                    }
                    let scale = want.iter().map(|v| v.amax()).fold(1.0, f64::max);
                    for (row, (g, w)) in got.iter().zip(&want).enumerate() {
                        assert!(
                            (g - w).amax() <= 1e-10 * scale,
                            "n = {n}, transposed = {transposed}, row {row}: {g:?} vs {w:?}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn zero_waypoint_pivot_is_reported_with_its_row() {
        // After the head rows the first waypoint pivot is 6 T⁵; with T = 1e-70 every term of it
        // underflows to zero.
        let pw = vec![powers(1e-70), powers(1.0)];
        let mut f = MincoFactors::new(2);
        assert_eq!(
            f.factorize(&pw),
            Err(MincoError::SingularPivot { row: 5, value: 0.0 })
        );
    }
}
