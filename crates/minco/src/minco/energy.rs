//! The jerk energy `E = Σ_i ∫₀^{T_i} ‖p_i'''(t)‖² dt` (no ½ factor; paper eq. design-of-Ie) and its
//! partial derivatives with respect to the coefficients and (explicitly) the durations.
//!
//! Closed form per piece with `T = T_i` and coefficients `c3, c4, c5`:
//! `E_i = 36‖c3‖²T + 144 c3·c4 T² + 192‖c4‖²T³ + 240 c3·c5 T³ + 720 c4·c5 T⁴ + 720‖c5‖²T⁵`;
//! `∂E/∂c3 = 72c3T + 144c4T² + 240c5T³`, `∂E/∂c4 = 144c3T² + 384c4T³ + 720c5T⁴`,
//! `∂E/∂c5 = 240c3T³ + 720c4T⁴ + 1440c5T⁵`, `∂E/∂c0..c2 = 0`, and explicitly
//! `∂E/∂T_i = ‖p_i'''(T_i)‖²`.

use nalgebra::Vector3;

use crate::error::MincoError;
use crate::minco::validate::{check_durations, check_len, check_vectors};

/// Powers `[1, T, T², T³, T⁴, T⁵]` of a duration.
#[inline(always)]
pub(crate) fn powers(t: f64) -> [f64; 6] {
    let t2 = t * t;
    let t3 = t2 * t;
    let t4 = t3 * t;
    [1.0, t, t2, t3, t4, t4 * t]
}

/// Energy of one piece from its top coefficients and duration powers.
#[inline(always)]
pub(crate) fn piece_energy_pw(c: &[Vector3<f64>], pw: &[f64; 6]) -> f64 {
    let (c3, c4, c5) = (&c[3], &c[4], &c[5]);
    36.0 * c3.norm_squared() * pw[1]
        + 144.0 * c3.dot(c4) * pw[2]
        + 192.0 * c4.norm_squared() * pw[3]
        + 240.0 * c3.dot(c5) * pw[3]
        + 720.0 * c4.dot(c5) * pw[4]
        + 720.0 * c5.norm_squared() * pw[5]
}

/// Adds `weight · ∂E_i/∂c` (rows 3..6 of the piece) and returns the explicit `∂E_i/∂T_i`.
#[inline(always)]
pub(crate) fn add_piece_energy_grad_pw(
    c: &[Vector3<f64>],
    pw: &[f64; 6],
    weight: f64,
    grad: &mut [Vector3<f64>],
) -> f64 {
    let (c3, c4, c5) = (c[3], c[4], c[5]);
    grad[3] += (c3 * (72.0 * pw[1]) + c4 * (144.0 * pw[2]) + c5 * (240.0 * pw[3])) * weight;
    grad[4] += (c3 * (144.0 * pw[2]) + c4 * (384.0 * pw[3]) + c5 * (720.0 * pw[4])) * weight;
    grad[5] += (c3 * (240.0 * pw[3]) + c4 * (720.0 * pw[4]) + c5 * (1440.0 * pw[5])) * weight;
    let jerk = c3 * 6.0 + c4 * (24.0 * pw[1]) + c5 * (60.0 * pw[2]);
    jerk.norm_squared()
}

/// Jerk energy of one piece of duration `t`.
pub fn piece_jerk_energy(c: &[Vector3<f64>; 6], t: f64) -> f64 {
    piece_energy_pw(c, &powers(t))
}

fn check_energy_inputs(coeffs: &[Vector3<f64>], durations: &[f64]) -> Result<(), MincoError> {
    check_len("coeffs", 6 * durations.len(), coeffs.len())?;
    check_durations(durations)?;
    check_vectors("coeffs", coeffs)
}

/// Jerk energy of a whole trajectory: `coeffs` holds 6 rows per piece (piece `i`, power `k` at row
/// `6i + k`), `durations` one entry per piece.
///
/// # Errors
/// [`MincoError::LengthMismatch`] if `coeffs.len() != 6 · durations.len()`;
/// [`MincoError::InvalidDuration`] / [`MincoError::NonFiniteVector`] on invalid numbers;
/// [`MincoError::NonFiniteResult`] naming the first piece whose energy overflows f64.
pub fn jerk_energy(coeffs: &[Vector3<f64>], durations: &[f64]) -> Result<f64, MincoError> {
    check_energy_inputs(coeffs, durations)?;
    let mut total = 0.0;
    for (i, (c, &t)) in coeffs.chunks_exact(6).zip(durations).enumerate() {
        total += piece_energy_pw(c, &powers(t));
        if !total.is_finite() {
            // Name the piece whose coefficients and duration overflowed the energy.
            return Err(MincoError::NonFiniteResult {
                field: "jerk energy (coeffs and durations of this piece)",
                index: i,
            });
        }
    }
    Ok(total)
}

/// Adds `weight · ∂E/∂c` to `grad_c` (6 rows per piece) and `weight · ∂E/∂T_i` (explicit part,
/// `‖jerk_i(T_i)‖²`) to `grad_t`, and returns the (unweighted) energy `E`.
///
/// Accumulating lets several cost terms share one gradient buffer before a single
/// [`MincoS3::propagate_grad`](crate::minco::MincoS3::propagate_grad).
///
/// # Errors
/// As [`jerk_energy`], plus [`MincoError::LengthMismatch`] for `grad_c` / `grad_t` of the wrong
/// length and [`MincoError::NonFiniteScalar`] for a non-finite `weight`.
pub fn accumulate_jerk_energy_grad(
    coeffs: &[Vector3<f64>],
    durations: &[f64],
    weight: f64,
    grad_c: &mut [Vector3<f64>],
    grad_t: &mut [f64],
) -> Result<f64, MincoError> {
    check_energy_inputs(coeffs, durations)?;
    check_len("grad_c", coeffs.len(), grad_c.len())?;
    check_len("grad_t", durations.len(), grad_t.len())?;
    if !weight.is_finite() {
        return Err(MincoError::NonFiniteScalar {
            field: "weight",
            index: 0,
            value: weight,
        });
    }
    let mut energy = 0.0;
    for (((c, &t), g), gt) in coeffs
        .chunks_exact(6)
        .zip(durations)
        .zip(grad_c.chunks_exact_mut(6))
        .zip(grad_t.iter_mut())
    {
        let pw = powers(t);
        energy += piece_energy_pw(c, &pw);
        *gt += weight * add_piece_energy_grad_pw(c, &pw, weight, g);
    }
    Ok(energy)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::minco::piece::piece_jerk;
    use approx::assert_relative_eq;

    fn piece() -> [Vector3<f64>; 6] {
        [
            Vector3::new(0.1, 0.2, 0.3),
            Vector3::new(-1.0, 0.5, 0.0),
            Vector3::new(0.4, -0.2, 1.0),
            Vector3::new(1.2, 0.3, -0.8),
            Vector3::new(-0.5, 0.9, 0.1),
            Vector3::new(0.25, -0.6, 0.7),
        ]
    }

    #[test]
    fn closed_form_matches_simpson_quadrature() {
        let c = piece();
        let t = 1.3;
        let m = 2000;
        let h = t / m as f64;
        let f = |s: f64| piece_jerk(&c, s).norm_squared();
        let mut sum = f(0.0) + f(t);
        for k in 1..m {
            sum += f(k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 };
        }
        assert_relative_eq!(
            piece_jerk_energy(&c, t),
            sum * h / 3.0,
            max_relative = 1e-12
        );
    }

    #[test]
    fn gradient_matches_finite_differences() {
        let c = piece();
        let t = 0.9;
        let mut g = [Vector3::zeros(); 6];
        let mut gt = [0.0];
        let e = accumulate_jerk_energy_grad(&c, &[t], 1.0, &mut g, &mut gt).unwrap();
        assert_relative_eq!(e, piece_jerk_energy(&c, t), max_relative = 1e-14);
        let h = 1e-6;
        for k in 0..6 {
            for d in 0..3 {
                let fd = trust_numdiff::central_difference(
                    |s| {
                        let mut probe = c;
                        probe[k][d] += s;
                        piece_jerk_energy(&probe, t)
                    },
                    0.0,
                    h,
                );
                assert_relative_eq!(g[k][d], fd, epsilon = 1e-6, max_relative = 1e-6);
            }
        }
        let fd_t = trust_numdiff::central_difference(|s| piece_jerk_energy(&c, s), t, h);
        assert_relative_eq!(gt[0], fd_t, max_relative = 1e-6);
    }

    #[test]
    fn accumulation_is_weighted_and_additive() {
        let c = piece();
        let mut g = [Vector3::new(1.0, 1.0, 1.0); 6];
        let mut gt = [2.0];
        let mut g1 = [Vector3::zeros(); 6];
        let mut gt1 = [0.0];
        accumulate_jerk_energy_grad(&c, &[0.7], 3.0, &mut g, &mut gt).unwrap();
        accumulate_jerk_energy_grad(&c, &[0.7], 1.0, &mut g1, &mut gt1).unwrap();
        for k in 0..6 {
            assert_relative_eq!(
                g[k],
                g1[k] * 3.0 + Vector3::new(1.0, 1.0, 1.0),
                epsilon = 1e-12
            );
        }
        assert_relative_eq!(gt[0], 2.0 + 3.0 * gt1[0], epsilon = 1e-12);
    }

    #[test]
    fn invalid_inputs_are_rejected() {
        let c = piece();
        assert!(matches!(
            jerk_energy(&c, &[0.5, 0.5]),
            Err(MincoError::LengthMismatch {
                field: "coeffs",
                ..
            })
        ));
        assert!(matches!(
            jerk_energy(&c, &[-0.5]),
            Err(MincoError::InvalidDuration { index: 0, .. })
        ));
        let mut bad = c;
        bad[2].y = f64::NAN;
        assert!(matches!(
            jerk_energy(&bad, &[0.5]),
            Err(MincoError::NonFiniteVector {
                field: "coeffs",
                index: 2,
                ..
            })
        ));
        let mut g = [Vector3::zeros(); 6];
        let mut gt = [0.0];
        assert!(accumulate_jerk_energy_grad(&c, &[0.5], f64::INFINITY, &mut g, &mut gt).is_err());
        assert!(accumulate_jerk_energy_grad(&c, &[0.5], 1.0, &mut g[..5], &mut gt).is_err());
    }
}
