//! Evaluation of one quintic piece `p(t) = Σ_k c_k t^k` (ascending powers, local time `t`).

use nalgebra::Vector3;

/// Position and its first four time derivatives of a piece at one local time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PieceDerivatives {
    /// `p(t)`.
    pub position: Vector3<f64>,
    /// `p'(t)`.
    pub velocity: Vector3<f64>,
    /// `p''(t)`.
    pub acceleration: Vector3<f64>,
    /// `p'''(t)`.
    pub jerk: Vector3<f64>,
    /// `p''''(t)`.
    pub snap: Vector3<f64>,
}

/// Derivatives 0..=4 of the monomial basis `b(t) = [1, t, t², t³, t⁴, t⁵]` (paper eq.
/// Polynomials): row `d` is `dᵈb/dtᵈ`, so the d-th derivative of a piece is `Σ_k row[d][k] c_k`.
/// These are the `β_d` of the trapezoidal penalty integration.
pub fn basis_derivatives(t: f64) -> [[f64; 6]; 5] {
    let t2 = t * t;
    let t3 = t2 * t;
    let t4 = t3 * t;
    let t5 = t4 * t;
    [
        [1.0, t, t2, t3, t4, t5],
        [0.0, 1.0, 2.0 * t, 3.0 * t2, 4.0 * t3, 5.0 * t4],
        [0.0, 0.0, 2.0, 6.0 * t, 12.0 * t2, 20.0 * t3],
        [0.0, 0.0, 0.0, 6.0, 24.0 * t, 60.0 * t2],
        [0.0, 0.0, 0.0, 0.0, 24.0, 120.0 * t],
    ]
}

/// Evaluates a quintic piece (coefficients `c[0..6]`, ascending powers) and its derivatives up to
/// snap at local time `t` (Horner form).
pub fn eval_piece(c: &[Vector3<f64>; 6], t: f64) -> PieceDerivatives {
    let position = ((((c[5] * t + c[4]) * t + c[3]) * t + c[2]) * t + c[1]) * t + c[0];
    let velocity = (((c[5] * (5.0 * t) + c[4] * 4.0) * t + c[3] * 3.0) * t + c[2] * 2.0) * t + c[1];
    let acceleration = ((c[5] * (20.0 * t) + c[4] * 12.0) * t + c[3] * 6.0) * t + c[2] * 2.0;
    let jerk = (c[5] * (60.0 * t) + c[4] * 24.0) * t + c[3] * 6.0;
    let snap = c[5] * (120.0 * t) + c[4] * 24.0;
    PieceDerivatives {
        position,
        velocity,
        acceleration,
        jerk,
        snap,
    }
}

/// Jerk `p'''(t)` of a piece at local time `t`.
#[inline]
pub fn piece_jerk(c: &[Vector3<f64>; 6], t: f64) -> Vector3<f64> {
    (c[5] * (60.0 * t) + c[4] * 24.0) * t + c[3] * 6.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn sample_piece() -> [Vector3<f64>; 6] {
        [
            Vector3::new(1.0, -2.0, 0.5),
            Vector3::new(0.3, 0.1, -1.0),
            Vector3::new(-0.7, 2.0, 0.2),
            Vector3::new(1.5, -0.4, 0.9),
            Vector3::new(-0.2, 0.8, -0.6),
            Vector3::new(0.05, -0.3, 0.4),
        ]
    }

    #[test]
    fn horner_matches_basis_rows() {
        let c = sample_piece();
        let t = 0.83;
        let d = eval_piece(&c, t);
        let b = basis_derivatives(t);
        let combine =
            |row: &[f64; 6]| -> Vector3<f64> { row.iter().zip(&c).map(|(w, ck)| ck * *w).sum() };
        assert_relative_eq!(d.position, combine(&b[0]), epsilon = 1e-12);
        assert_relative_eq!(d.velocity, combine(&b[1]), epsilon = 1e-12);
        assert_relative_eq!(d.acceleration, combine(&b[2]), epsilon = 1e-12);
        assert_relative_eq!(d.jerk, combine(&b[3]), epsilon = 1e-12);
        assert_relative_eq!(d.snap, combine(&b[4]), epsilon = 1e-12);
        assert_relative_eq!(piece_jerk(&c, t), d.jerk, epsilon = 1e-12);
    }

    #[test]
    fn derivatives_match_finite_differences() {
        let c = sample_piece();
        let (t, h) = (0.6, 1e-6);
        let mid = eval_piece(&c, t);
        let fd = |d: fn(&PieceDerivatives) -> Vector3<f64>| {
            trust_numdiff::central_difference(|s| d(&eval_piece(&c, s)), t, h)
        };
        assert_relative_eq!(mid.velocity, fd(|e| e.position), epsilon = 1e-7);
        assert_relative_eq!(mid.acceleration, fd(|e| e.velocity), epsilon = 1e-7);
        assert_relative_eq!(mid.jerk, fd(|e| e.acceleration), epsilon = 1e-7);
        assert_relative_eq!(mid.snap, fd(|e| e.jerk), epsilon = 1e-7);
    }
}
