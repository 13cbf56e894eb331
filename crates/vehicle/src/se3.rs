//! Geometric tracking control on SE(3) (Lee, Leok & McClamroch 2010) with the differential-flatness
//! feed-forward of the desired body rate from jerk (Mellinger & Kumar 2011).
//!
//! With the world frame z up, position error `e_x = p − p_d`, velocity error `e_v = v − v_d`:
//!
//! ```text
//! A    = −k_x e_x − k_v e_v + a_d + g e₃          desired specific force (m/s²)*
//! f    = m A · R e₃                                 collective thrust (Lee et al., z up)
//! b₃,d = A / |A|,  b₁,c = (cos ψ_d, sin ψ_d, 0)
//! b₂,d = b₃,d × b₁,c / |b₃,d × b₁,c|,  b₁,d = b₂,d × b₃,d,  R_d = [b₁,d b₂,d b₃,d]
//! e_R  = ½ (R_dᵀ R − Rᵀ R_d)^∨,  e_ω = ω − Rᵀ R_d ω_d
//! M    = J (−k_R e_R − k_ω e_ω) + ω × J ω − J (ω × Rᵀ R_d ω_d)      (Lee et al., ω̇_d = 0)
//! ```
//!
//! \* For large errors the position feedback is bounded (our addition, not in either paper):
//! it is computed as `−k_v (e_v + sat(k_x/k_v · e_x))` and its norm is capped, see
//! [`Se3Gains::max_approach_speed_m_s`] and [`Se3Gains::max_feedback_m_s2`]. Within the caps (errors
//! below 1.75 m and 1.3 m/s with the defaults, which the figure-eights never reach) this is exactly
//! Lee's `−k_x e_x − k_v e_v`. Without the caps a 30 m jump of the reference asks for a nearly
//! horizontal thrust of 480 m/s², and with rate or thrust limits active the vehicle can tumble.
//!
//! The desired body rate `ω_d` is the angular velocity of `R_d` when `A` changes at the reference
//! jerk (the differential-flatness argument of Mellinger & Kumar 2011): `ḃ₃,d = (j_d − (b₃,d·j_d) b₃,d) / |A|`, then
//! `p_d = −b₂,d·ḃ₃,d`, `q_d = b₁,d·ḃ₃,d` and, for a held yaw (ψ̇_d = 0), the exact yaw rate of this
//! construction `r_d = p_d (b₁,c·b₃,d) / |b₃,d × b₁,c|` (Mellinger & Kumar's `r = ψ̇ z_W·z_B`
//! omits this term, which is not zero when the vehicle rolls at constant heading; a unit test checks
//! the whole `ω_d` against finite differences of `R_d`). The time derivative of the feedback terms
//! (Lee et al. differentiate the full `R_d`) and the angular-acceleration feed-forward `ω̇_d`
//! (which would need snap, absent from [`Reference`]) are neglected.
//!
//! The gains are normalized by the model's mass and inertia (`k_x` in 1/s², `k_v` in 1/s, `k_R` in
//! 1/s², `k_ω` in 1/s), so that they describe closed-loop dynamics and carry over between vehicles.

use nalgebra::{Matrix3, Rotation3, UnitQuaternion};
use serde::{Deserialize, Serialize};
use trust_core::Vec3;

use super::error::{VehicleError, check_positive};
use super::params::QuadrotorParams;
use super::rigid_body::Command;
use super::{Reference, VehicleState};

/// Below this specific force (m/s²) the jerk feed-forward is scaled as if the thrust were this
/// large: near free fall the thrust direction is undefined and `ḃ₃ = j⊥/|A|` would blow up.
const MIN_FEEDFORWARD_SPECIFIC_FORCE: f64 = 1.0;
/// Below this specific force (m/s²) the thrust direction is taken from the fallback attitude.
const MIN_SPECIFIC_FORCE: f64 = 1e-9;
/// Below this `|b₃ × b₁,c|` the heading is taken from the fallback attitude.
const MIN_HEADING_SINE: f64 = 1e-6;

/// Gains of the [`Se3Controller`], normalized by mass (position loop) and inertia (attitude loop).
///
/// # Defaults
///
/// Position loop: `k_x = 16 s⁻²`, `k_v = 5.6 s⁻¹` — the gains of the numerical example of Lee,
/// Leok & McClamroch 2010 (`k_x = 16 m`, `k_v = 5.6 m` for their m = 4.34 kg vehicle) divided by
/// the mass: natural frequency 4 rad/s, damping 0.7. Attitude loop: `k_R = 400 s⁻²`, `k_ω = 36 s⁻¹` — natural frequency 20 rad/s, damping 0.9,
/// our tuning. Lee et al.'s attitude gains (`k_R = 8.81`, `k_Ω = 2.54` for `J_xx` = 0.082 kg·m²)
/// normalized by their inertia (≈ 107 s⁻², 31 s⁻¹) are
/// conservative for a 0.85 kg racing quadrotor with 1.5 N·m of torque authority: measured on the
/// aggressive [`FigureEight`](super::FigureEight) they give 65 mm RMS position error, these 5 mm
/// (the attitude lag left by the missing angular-acceleration feed-forward dominates). The inner
/// loop's 20 rad/s stays far below the 500 Hz physics/control rate.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Se3Gains {
    /// Position gain (1/s²): specific force per metre of position error.
    pub k_x: f64,
    /// Velocity gain (1/s): specific force per m/s of velocity error.
    pub k_v: f64,
    /// Attitude gain (1/s²): angular acceleration per unit attitude error `e_R` (≈ radians for
    /// small errors).
    pub k_r: f64,
    /// Body-rate gain (1/s): angular acceleration per rad/s of body-rate error.
    pub k_omega: f64,
    /// Largest speed (m/s) at which the position loop closes a position error: the feedback is
    /// written `−k_v (e_v + c)` with the velocity correction `c = (k_x / k_v) e_x` scaled down to
    /// at most this norm. Default 5 m/s (half the planner's v_max): acts only for position
    /// errors above `5 · k_v / k_x` = 1.75 m.
    pub max_approach_speed_m_s: f64,
    /// Largest norm of the position-loop feedback (m/s²), scaled down to it keeping the direction.
    /// Default 7.5 m/s²: the specific thrust the default vehicle has left at the planner's worst
    /// case, 3.3 g − (15 m/s² + g) = 7.6 m/s². Acts only when `|e_v + c|` exceeds
    /// `7.5 / k_v` = 1.3 m/s.
    pub max_feedback_m_s2: f64,
    /// Largest norm (m/s²) of the commanded acceleration `a_d + feedback` (the thrust's specific
    /// force minus gravity), scaled down to it keeping the direction: the vehicle's acceleration
    /// limit, as a flight stack enforces it (our addition). A jerky reference otherwise makes the
    /// feedback push the vehicle beyond its limit while the attitude catches up (up to 1.2
    /// `a_max` in the rooms with people). The thrust along the actual body axis is capped too,
    /// so that an attitude lagging the command does not carry the vehicle past it (within
    /// `asin(cap/g)` of tilt). Tilted further, no thrust keeps the acceleration within the cap,
    /// so the cap leaves room for the attitude's overshoot: a body swinging its thrust towards
    /// the command at `ȧ` (m/s³) overshoots by about `ȧ·lead`, with `lead` the peak of the
    /// attitude loop's response to a released rate (`exp(−ζ/√(1−ζ²)·atan(√(1−ζ²)/ζ))/ω_n`,
    /// 20 ms with the default gains), and the command is held within `cap − ȧ·lead` (at least
    /// half the cap). Without that room a swing to the cap within 0.2 s peaked at 1.12–1.15 times
    /// the cap below 2 m/s²; with it every swing stays within 1.02 (measured in
    /// `crates/flight/tests/accel_headroom.rs`). Default `None` (no cap); the closed loop
    /// (`trust-flight`) sets it to the scenario's `a_max` when a scenario leaves it out.
    #[serde(default)]
    pub max_accel_m_s2: Option<f64>,
}

impl Default for Se3Gains {
    fn default() -> Self {
        Se3Gains {
            k_x: 16.0,
            k_v: 5.6,
            k_r: 400.0,
            k_omega: 36.0,
            max_approach_speed_m_s: 5.0,
            max_feedback_m_s2: 7.5,
            max_accel_m_s2: None,
        }
    }
}

impl Se3Gains {
    /// Checks that every gain is finite and strictly positive.
    pub fn validate(&self) -> Result<(), VehicleError> {
        check_positive("k_x", self.k_x)?;
        check_positive("k_v", self.k_v)?;
        check_positive("k_r", self.k_r)?;
        check_positive("k_omega", self.k_omega)?;
        check_positive("max_approach_speed_m_s", self.max_approach_speed_m_s)?;
        check_positive("max_feedback_m_s2", self.max_feedback_m_s2)?;
        if let Some(cap) = self.max_accel_m_s2 {
            check_positive("max_accel_m_s2", cap)?;
        }
        Ok(())
    }
}

/// The geometric SE(3) tracking controller (see the module docs for the equations).
///
/// It reads only the reference and the vehicle state; its own model of the vehicle (mass, inertia,
/// gravity) is copied at construction, so a mismatched model can be studied by building it from
/// different parameters than the body's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Se3Controller {
    gains: Se3Gains,
    /// How far (s of its swing rate) the attitude overshoots a command that stops turning.
    lead_s: f64,
    mass_kg: f64,
    inertia_kg_m2: Vec3,
    gravity_m_s2: f64,
}

impl Se3Controller {
    /// A controller with validated gains and the mass, inertia and gravity of `model`.
    pub fn new(gains: Se3Gains, model: &QuadrotorParams) -> Result<Self, VehicleError> {
        gains.validate()?;
        model.validate()?;
        let lead_s = overshoot_per_rate(gains.k_r, gains.k_omega);
        Ok(Se3Controller {
            gains,
            lead_s,
            mass_kg: model.mass_kg,
            inertia_kg_m2: model.inertia_kg_m2,
            gravity_m_s2: model.gravity_m_s2,
        })
    }

    /// The gains.
    pub fn gains(&self) -> &Se3Gains {
        &self.gains
    }

    /// The command (collective thrust, body torques) that tracks `r` from `state`, before
    /// saturation. Finite for finite inputs; the caller handles non-finite references.
    pub fn command(&self, state: &VehicleState, r: &Reference) -> Command {
        let k = &self.gains;
        let rot = *state.attitude.to_rotation_matrix().matrix();
        let e_x = state.p - r.p;
        let e_v = state.v - r.v;
        let correction = clamp_norm(e_x * (k.k_x / k.k_v), k.max_approach_speed_m_s);
        let feedback = clamp_norm(-(e_v + correction) * k.k_v, k.max_feedback_m_s2);
        let wanted = feedback + r.a;
        // The commanded acceleration and its rate (the reference's jerk, the feed-forward of the
        // body rate). Clamped to the cap, the command only turns: the jerk's radial part would
        // rotate the desired attitude past the capped tilt, so it is projected out.
        let (accel, accel_rate) = match k.max_accel_m_s2 {
            Some(cap) => {
                let n = wanted.norm();
                let u = direction(&wanted).unwrap_or_else(Vec3::zeros);
                // The body still turning towards the command carries the attitude past it by
                // about `lead_s` times the rate at which it swings the thrust: leave that room.
                let b3_rate = rot * state.body_rate.cross(&Vec3::z());
                let swing = u.dot(&b3_rate) * (r.a + Vec3::z() * self.gravity_m_s2).norm();
                let room = (cap - swing.max(0.0) * self.lead_s).max(0.5 * cap);
                if n > room {
                    (u * room, (r.j - u * u.dot(&r.j)) * (room / n))
                } else {
                    (wanted, r.j)
                }
            }
            None => (wanted, r.j),
        };
        let force = accel + Vec3::z() * self.gravity_m_s2;
        let desired = desired_frame(&force, &accel_rate, r.yaw, &rot);

        let mut thrust = self.mass_kg * force.dot(&rot.column(2));
        if let Some(cap) = k.max_accel_m_s2 {
            thrust = self.mass_kg
                * specific_thrust_within(
                    thrust / self.mass_kg,
                    rot[(2, 2)],
                    self.gravity_m_s2,
                    cap,
                );
        }
        // R_dᵀ R; its transpose is Rᵀ R_d.
        let rd_t_r = desired.rotation.transpose() * rot;
        let e_r = 0.5 * vee(&(rd_t_r - rd_t_r.transpose()));
        let w_d = rd_t_r.transpose() * desired.body_rate;
        let w = state.body_rate;
        let e_w = w - w_d;
        let j = &self.inertia_kg_m2;
        let torque = j.component_mul(&(-e_r * k.k_r - e_w * k.k_omega))
            + w.cross(&j.component_mul(&w))
            - j.component_mul(&w.cross(&w_d));
        Command { thrust, torque }
    }
}

/// A desired attitude and its body rate (in the desired body frame).
pub(crate) struct DesiredFrame {
    pub rotation: Matrix3<f64>,
    pub body_rate: Vec3,
    /// The thrust direction or the heading came from the fallback attitude.
    pub degenerate: bool,
}

/// The desired frame of a specific force `force` changing at `force_rate`, with heading `yaw`;
/// `fallback` supplies the thrust axis (near free fall) or the heading (thrust axis horizontal
/// along the heading).
pub(crate) fn desired_frame(
    force: &Vec3,
    force_rate: &Vec3,
    yaw: f64,
    fallback: &Matrix3<f64>,
) -> DesiredFrame {
    let norm = force.norm();
    let mut degenerate = false;
    let b3 = match direction(force) {
        Some(b3) if norm > MIN_SPECIFIC_FORCE => b3,
        _ => {
            degenerate = true;
            fallback.column(2).into_owned()
        }
    };
    let b1c = Vec3::new(yaw.cos(), yaw.sin(), 0.0);
    let candidates = [
        b1c,
        fallback.column(0).into_owned(),
        fallback.column(1).into_owned(),
    ];
    let mut b2 = Vec3::y();
    let mut heading_sine = 0.0;
    for (i, c) in candidates.iter().enumerate() {
        let y = b3.cross(c);
        let n = y.norm();
        if n > MIN_HEADING_SINE {
            b2 = y / n;
            if i == 0 {
                heading_sine = n;
            } else {
                degenerate = true;
            }
            break;
        }
    }
    let b1 = b2.cross(&b3);
    let b3_rate = (force_rate - b3 * b3.dot(force_rate)) / norm.max(MIN_FEEDFORWARD_SPECIFIC_FORCE);
    let p = -b2.dot(&b3_rate);
    let q = b1.dot(&b3_rate);
    let r = if heading_sine > 0.0 {
        p * b1c.dot(&b3) / heading_sine
    } else {
        0.0
    };
    DesiredFrame {
        rotation: Matrix3::from_columns(&[b1, b2, b3]),
        body_rate: Vec3::new(p, q, r),
        degenerate,
    }
}

/// Attitude and body rate of a quadrotor that follows a flat output exactly (differential
/// flatness, Mellinger & Kumar 2011, Sec. III): thrust along `a + g e₃`, heading `yaw`, body rate
/// from the jerk `j` at constant yaw.
///
/// `None` when the attitude is undefined: near free fall (`|a + g e₃| ≈ 0`) or with the thrust
/// axis horizontal along the heading. Building block of [`PerfectTracking`](super::PerfectTracking)
/// and [`VehicleState::on_reference`].
pub fn flat_attitude(
    a: &Vec3,
    j: &Vec3,
    yaw: f64,
    gravity_m_s2: f64,
) -> Option<(UnitQuaternion<f64>, Vec3)> {
    let force = a + Vec3::z() * gravity_m_s2;
    if !(force.iter().all(|x| x.is_finite()) && j.iter().all(|x| x.is_finite()) && yaw.is_finite())
    {
        return None;
    }
    let frame = desired_frame(&force, j, yaw, &Matrix3::identity());
    if frame.degenerate {
        return None;
    }
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(frame.rotation));
    Some((q, frame.body_rate))
}

/// The peak (s) of the attitude error `e` of `ë + k_ω ė + k_R e = 0` released at `e = 0` with
/// rate 1: with `ω_n = √k_R`, `ζ = k_ω/(2ω_n)`, `exp(−ζ/√(1−ζ²)·atan(√(1−ζ²)/ζ))/ω_n`
/// underdamped, `e⁻¹/ω_n` critically damped, `(e^{−aω_n t*} − e^{−bω_n t*})/(2sω_n)` overdamped
/// (`s = √(ζ²−1)`, `a, b = ζ ∓ s`, at `t* = ln(b/a)/((b − a)ω_n)`).
fn overshoot_per_rate(k_r: f64, k_omega: f64) -> f64 {
    let wn = k_r.sqrt();
    let zeta = k_omega / (2.0 * wn);
    if (zeta - 1.0).abs() < 1e-9 {
        (-1.0f64).exp() / wn
    } else if zeta < 1.0 {
        let s = (1.0 - zeta * zeta).sqrt();
        (-(zeta / s) * (s / zeta).atan()).exp() / wn
    } else {
        let s = (zeta * zeta - 1.0).sqrt();
        let (a, b) = (zeta - s, zeta + s);
        let t = (b / a).ln() / ((b - a) * wn);
        ((-a * wn * t).exp() - (-b * wn * t).exp()) / (2.0 * s * wn)
    }
}

/// The specific thrust `τ` (m/s²) nearest `wanted` for which the body's acceleration
/// `τ·b₃ − g·e₃` has a norm of at most `cap`, with `cos_tilt = b₃·e₃`: `|τb₃ − ge₃|² = τ² −
/// 2gτ·cos_tilt + g²`, so `τ` must lie within `g·cos_tilt ± √(cap² − g²·sin²tilt)`; tilted beyond
/// `asin(cap/g)` no thrust does, and the one with the least acceleration, `g·cos_tilt`, is taken.
///
/// The commanded acceleration is capped before the attitude is chosen, but while the attitude
/// lags a quick swing of the command (braking, dodging) the thrust along the actual body axis
/// accelerates the vehicle beyond it: 3° more tilt at 3 m/s² is 3.5 m/s² (1.065 `a_max` in the
/// suite's penetration flight). Capping the thrust closes that gap while the tilt is within
/// `asin(cap/g)`; the room the command leaves for the attitude's overshoot keeps it there.
fn specific_thrust_within(wanted: f64, cos_tilt: f64, g: f64, cap: f64) -> f64 {
    let sin2 = (1.0 - cos_tilt * cos_tilt).max(0.0);
    let disc = cap * cap - g * g * sin2;
    let mid = g * cos_tilt;
    if disc < 0.0 {
        return mid.max(0.0);
    }
    let half = disc.sqrt();
    wanted.clamp((mid - half).max(0.0), (mid + half).max(0.0))
}

/// `v` scaled down to norm `max` if it is longer; a finite `v` whose norm overflows keeps its
/// direction, a non-finite `v` stays non-finite.
fn clamp_norm(v: Vec3, max: f64) -> Vec3 {
    let n = v.norm();
    if n <= max {
        v
    } else if let Some(u) = direction(&v) {
        u * max
    } else {
        v
    }
}

/// The unit vector along `v`, also when `|v|` overflows; `None` for a zero or non-finite `v`.
fn direction(v: &Vec3) -> Option<Vec3> {
    let scale = v.amax();
    if !(scale.is_finite() && scale > 0.0) {
        return None;
    }
    let u = v / scale;
    Some(u / u.norm())
}

/// The vector of a skew-symmetric matrix (the "vee" map, inverse of the hat map).
fn vee(s: &Matrix3<f64>) -> Vec3 {
    Vec3::new(s[(2, 1)], s[(0, 2)], s[(1, 0)])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::FigureEight;
    use approx::assert_relative_eq;

    #[test]
    fn feedforward_body_rate_is_the_derivative_of_the_flat_attitude() {
        // Along the aggressive figure-eight, the body rate returned with the flat attitude must
        // equal the central finite difference of that attitude: ω̂ = Rᵀ Ṙ.
        let fig = FigureEight::aggressive();
        let h = 1e-5;
        for i in 0..200 {
            let t = 0.0357 * f64::from(i);
            let at = |t: f64| {
                let r = fig.reference(t);
                flat_attitude(&r.a, &r.j, r.yaw, 9.81).unwrap()
            };
            let (q, w) = at(t);
            let (qm, _) = at(t - h);
            let (qp, _) = at(t + h);
            let w_fd = (qm.inverse() * qp).scaled_axis() / (2.0 * h);
            assert_relative_eq!(w, w_fd, epsilon = 1e-6);
            // Thrust axis along a + g; heading yaw = 0: b₂ = b₃ × x_W / |…| is orthogonal to x_W.
            let r = fig.reference(t);
            let b3 = q * Vec3::z();
            assert_relative_eq!(b3, (r.a + Vec3::z() * 9.81).normalize(), epsilon = 1e-12);
            assert_relative_eq!((q * Vec3::y()).x, 0.0, epsilon = 1e-12);
        }
    }

    #[test]
    fn on_the_reference_the_command_is_pure_feedforward() {
        // State exactly on the flat reference: thrust = m |a + g|, torque = the gyroscopic term only.
        let params = QuadrotorParams::default();
        let ctrl = Se3Controller::new(Se3Gains::default(), &params).unwrap();
        let fig = FigureEight::aggressive();
        for i in 0..50 {
            let t = 0.13 * f64::from(i);
            let r = fig.reference(t);
            let state = VehicleState::on_reference(t, &r, params.gravity_m_s2).unwrap();
            let cmd = ctrl.command(&state, &r);
            let expected = params.mass_kg * (r.a + Vec3::z() * params.gravity_m_s2).norm();
            assert_relative_eq!(cmd.thrust, expected, max_relative = 1e-12);
            let w = state.body_rate;
            let j = params.inertia_kg_m2;
            assert_relative_eq!(cmd.torque, w.cross(&j.component_mul(&w)), epsilon = 1e-12);
        }
    }

    #[test]
    fn degenerate_forces_fall_back_without_nan() {
        let id = Matrix3::identity();
        // Free fall.
        let f = desired_frame(&Vec3::zeros(), &Vec3::new(1.0, 2.0, 3.0), 0.3, &id);
        assert!(f.degenerate);
        assert!(
            f.rotation
                .iter()
                .chain(f.body_rate.iter())
                .all(|x| x.is_finite())
        );
        // Thrust axis horizontal, along the heading.
        let f = desired_frame(
            &Vec3::new(10.0, 0.0, 0.0),
            &Vec3::new(0.0, 5.0, 0.0),
            0.0,
            &id,
        );
        assert!(f.degenerate);
        assert_relative_eq!(f.rotation.transpose() * f.rotation, id, epsilon = 1e-12);
        assert!(flat_attitude(&Vec3::new(0.0, 0.0, -9.81), &Vec3::zeros(), 0.0, 9.81).is_none());
        assert!(flat_attitude(&Vec3::new(f64::NAN, 0.0, 0.0), &Vec3::zeros(), 0.0, 9.81).is_none());
    }

    #[test]
    fn clamping_keeps_the_direction_even_when_the_norm_overflows() {
        let v = Vec3::new(3.0, -4.0, 0.0);
        assert_eq!(clamp_norm(v, 10.0), v);
        assert_relative_eq!(
            clamp_norm(v, 1.0),
            Vec3::new(0.6, -0.8, 0.0),
            epsilon = 1e-15
        );
        let huge = Vec3::new(3e307, -4e307, 0.0);
        assert!(huge.norm().is_infinite());
        assert_relative_eq!(
            clamp_norm(huge, 1.0),
            Vec3::new(0.6, -0.8, 0.0),
            epsilon = 1e-15
        );
        assert!(clamp_norm(Vec3::new(f64::NAN, 0.0, 0.0), 1.0).x.is_nan());
        assert_eq!(direction(&Vec3::zeros()), None);
    }

    #[test]
    fn gain_validation_names_the_field() {
        let g = Se3Gains {
            k_omega: -1.0,
            ..Default::default()
        };
        assert!(g.validate().unwrap_err().to_string().contains("k_omega"));
        let g = Se3Gains {
            k_x: f64::NAN,
            ..Default::default()
        };
        assert!(g.validate().unwrap_err().to_string().contains("k_x"));
        let g = Se3Gains {
            max_feedback_m_s2: 0.0,
            ..Default::default()
        };
        assert!(
            g.validate()
                .unwrap_err()
                .to_string()
                .contains("max_feedback_m_s2")
        );
    }
    #[test]
    fn the_lead_is_the_attitude_loops_overshoot_per_released_rate() {
        // ë + k_ω ė + k_R e = 0 from e = 0, ė = 1: the peak of e, by explicit integration.
        for (k_r, k_omega) in [
            (400.0, 36.0),
            (400.0, 20.0),
            (100.0, 20.0),
            (400.0, 60.0),
            (400.0, 40.0),
        ] {
            let gains = Se3Gains {
                k_r,
                k_omega,
                ..Se3Gains::default()
            };
            let c = Se3Controller::new(gains, &QuadrotorParams::default()).unwrap();
            let (mut e, mut de, mut peak) = (0.0f64, 1.0f64, 0.0f64);
            let dt = 1e-6;
            for _ in 0..1_000_000 {
                de += (-k_omega * de - k_r * e) * dt;
                e += de * dt;
                peak = peak.max(e);
            }
            assert_relative_eq!(c.lead_s, peak, max_relative = 1e-3);
        }
    }

    #[test]
    fn the_thrust_cap_keeps_the_bodys_acceleration_within_the_cap() {
        let g = 9.81;
        let cap = 3.0;
        let accel = |tau: f64, tilt: f64| {
            let b3 = Vec3::new(tilt.sin(), 0.0, tilt.cos());
            (b3 * tau - Vec3::z() * g).norm()
        };
        for tilt_deg in [0.0_f64, 5.0, 10.0, 15.0, 17.0] {
            let tilt = tilt_deg.to_radians();
            for wanted in [0.0, 5.0, 9.0, 9.81, 11.0, 13.0, 20.0] {
                let tau = specific_thrust_within(wanted, tilt.cos(), g, cap);
                assert!(
                    accel(tau, tilt) <= cap + 1e-9,
                    "tilt {tilt_deg}°, {wanted}: {tau}"
                );
                if accel(wanted, tilt) <= cap {
                    assert!((tau - wanted).abs() < 1e-12, "an allowed thrust is kept");
                }
            }
        }
        // Tilted beyond asin(cap/g) = 17.8°: the least acceleration, g·sin(tilt).
        let tilt = 20.0_f64.to_radians();
        let tau = specific_thrust_within(12.0, tilt.cos(), g, cap);
        assert!((tau - g * tilt.cos()).abs() < 1e-12);
        assert!((accel(tau, tilt) - g * tilt.sin()).abs() < 1e-9);
    }
}
