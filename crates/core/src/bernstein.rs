//! Bernstein (Bézier) control points of a polynomial on `[0, 1]`: by the convex-hull property the
//! curve lies in their convex hull, which gives cheap proven bounds on a trajectory piece — its
//! bounding box from the position's points, its largest speed or acceleration from the
//! velocity's or acceleration's. The manager's safety check and UTF-MINCO's fused penalty
//! integration both use [`bernstein_points`].

use crate::Vec3;

/// `C(n, k)` as `f64`, by the product `Π_{j<k} (n − j)/(j + 1)` (exact for the small degrees used).
const fn binomial(n: usize, k: usize) -> f64 {
    let mut r = 1.0;
    let mut j = 0;
    while j < k {
        r = r * (n - j) as f64 / (j + 1) as f64;
        j += 1;
    }
    r
}

/// The coefficients `C(i, k)/C(n, k)` (row `i`, column `k ≤ i`) for degree `n = N − 1`.
struct Coefficients<const N: usize>;

impl<const N: usize> Coefficients<N> {
    const TABLE: [[f64; N]; N] = {
        let mut c = [[0.0; N]; N];
        let mut i = 0;
        while i < N {
            let mut k = 0;
            while k <= i {
                c[i][k] = binomial(i, k) / binomial(N - 1, k);
                k += 1;
            }
            i += 1;
        }
        c
    };
}

/// The Bernstein control points `P_0 … P_n` on `u ∈ [0, 1]` of the polynomial
/// `Σ_k b_k u^k` of degree `n = N − 1` given by its monomial coefficients `b`:
/// `P_i = b_0 + Σ_{1 ≤ k ≤ i} C(i, k)/C(n, k) · b_k` (summed in that order). The curve lies in
/// their convex hull; `P_0` and `P_n` are its end points.
///
/// For a trajectory piece `p(t) = Σ_k c_k t^k` of duration `T`, pass `b_k = c_k T^k` for the
/// position, `b_k = (k + 1) c_{k+1} T^k` for the velocity.
///
/// ```
/// use trust_core::{Vec3, bernstein_points};
/// // u ↦ (u², 0, 0): control points 0, 0, 1.
/// let p = bernstein_points(&[Vec3::zeros(), Vec3::zeros(), Vec3::x()]);
/// assert_eq!(p, [Vec3::zeros(), Vec3::zeros(), Vec3::x()]);
/// ```
#[inline(always)]
pub fn bernstein_points<const N: usize>(b: &[Vec3; N]) -> [Vec3; N] {
    let c = &Coefficients::<N>::TABLE;
    let mut out = [Vec3::zeros(); N];
    for i in 0..N {
        let mut p = b[0];
        for k in 1..=i {
            p += b[k] * c[i][k];
        }
        out[i] = p;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coefficients_match_the_closed_forms() {
        // The values UTF-MINCO's fused integration used as literals (bit for bit).
        let c5 = &Coefficients::<6>::TABLE;
        assert_eq!([c5[1][1], c5[2][1], c5[2][2]], [0.2, 0.4, 0.1]);
        assert_eq!([c5[3][1], c5[3][2], c5[3][3]], [0.6, 0.3, 0.1]);
        assert_eq!(
            [c5[4][1], c5[4][2], c5[4][3], c5[4][4]],
            [0.8, 0.6, 0.4, 0.2]
        );
        assert_eq!(c5[5], [1.0; 6]);
        let c4 = &Coefficients::<5>::TABLE;
        assert_eq!([c4[1][1], c4[2][1], c4[2][2]], [0.25, 0.5, 1.0 / 6.0]);
        assert_eq!([c4[3][1], c4[3][2], c4[3][3]], [0.75, 0.5, 0.25]);
        let c3 = &Coefficients::<4>::TABLE;
        assert_eq!(
            [c3[1][1], c3[2][1], c3[2][2]],
            [1.0 / 3.0, 2.0 / 3.0, 1.0 / 3.0]
        );
    }

    #[test]
    fn the_hull_contains_the_curve() {
        let b = [
            Vec3::new(0.3, -1.0, 2.0),
            Vec3::new(-2.0, 0.5, 1.0),
            Vec3::new(4.0, 3.0, -1.5),
            Vec3::new(-1.0, -2.5, 0.7),
            Vec3::new(0.2, 1.1, -0.4),
            Vec3::new(0.9, -0.6, 0.1),
        ];
        let points = bernstein_points(&b);
        let (mut lo, mut hi) = (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY));
        for p in &points {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        for s in 0..=200 {
            let u = s as f64 / 200.0;
            let x: Vec3 = b.iter().rev().fold(Vec3::zeros(), |acc, bk| acc * u + bk);
            assert!((0..3).all(|i| x[i] >= lo[i] - 1e-12 && x[i] <= hi[i] + 1e-12));
        }
        let end: Vec3 = b.iter().sum();
        assert!((points[0] - b[0]).norm() == 0.0 && (points[5] - end).norm() < 1e-12);
    }
}
