//! Physical parameters of the simulated quadrotor and their defaults.

use serde::{Deserialize, Serialize};
use trust_core::Vec3;

use super::error::{
    VehicleError, check_finite, check_non_negative, check_positive, check_positive_vec,
    out_of_range,
};

/// Standard gravity (m/s²), the value the paper's simulator and ours use.
pub const STANDARD_GRAVITY: f64 = 9.81;

/// Mass of the reference platform (kg): Foehn, Romero & Scaramuzza, "Time-optimal planning for
/// quadrotor waypoint flight", Science Robotics 2021, quadrotor model (`quads/quad.yaml` of their
/// published planner).
const FOEHN_MASS_KG: f64 = 0.85;
/// Centre-to-motor distance of the reference platform (m), X configuration (same source).
const FOEHN_ARM_LENGTH_M: f64 = 0.15;
/// Diagonal inertia of the reference platform (kg·m²) (same source).
const FOEHN_INERTIA_KG_M2: [f64; 3] = [0.001, 0.001, 0.0017];
/// Thrust-to-weight ratio of the reference platform (same source).
const FOEHN_THRUST_TO_WEIGHT: f64 = 3.3;
/// Rotor drag torque per unit rotor thrust (m) of the reference platform (same source).
const FOEHN_TORQUE_COEFF_M: f64 = 0.05;
/// Body-rate limit about the body x and y axes (rad/s) of the reference platform (same source).
const FOEHN_MAX_BODY_RATE_XY: f64 = 15.0;

/// Physical parameters of the rigid-body quadrotor [`Quadrotor`](super::Quadrotor).
///
/// The body frame is x forward, y left, z up along the collective thrust; the world frame is z up.
/// Actuation is modelled at the level of collective thrust and body torques (what a flight
/// controller's mixer receives), each saturated to a box; rotor dynamics and the coupling of the
/// per-rotor limits (full torque is only available at half collective thrust) are not modelled.
///
/// # Defaults
///
/// The default is the 0.85 kg racing quadrotor of Foehn, Romero & Scaramuzza, "Time-optimal
/// planning for quadrotor waypoint flight", Science Robotics 6(56), 2021 (the model file
/// `quads/quad.yaml` published with their planner): mass 0.85 kg, arm length 0.15 m (X
/// configuration), inertia diag(1.0, 1.0, 1.7) g·m², thrust-to-weight ratio 3.3, per-rotor thrust
/// 0 … 6.88 N, rotor torque coefficient 0.05 m, body rates up to 15 rad/s about x and y.
///
/// The paper's planner limits are v_max = 10 m/s and a_max = 15 m/s² (Sec. IV). The worst case
/// needs a specific thrust of |a + g| ≤ 15 + 9.81 = 24.8 m/s²; this vehicle produces
/// 3.3 · 9.81 = 32.4 m/s², a 30 % margin for feedback. (The paper's real platform, a Crazyflie 2.1,
/// could not fly those limits, hence a racing-class model.)
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct QuadrotorParams {
    /// Mass (kg). Default 0.85 kg (Foehn et al. 2021).
    pub mass_kg: f64,
    /// Principal moments of inertia about the body x, y, z axes (kg·m²); the body axes are taken
    /// as principal axes. Default (0.001, 0.001, 0.0017) (Foehn et al. 2021).
    pub inertia_kg_m2: Vec3,
    /// Largest collective thrust (N). Default 3.3 · 0.85 kg · 9.81 m/s² = 27.5 N (thrust-to-weight
    /// ratio 3.3, Foehn et al. 2021), i.e. 6.88 N per rotor.
    pub max_thrust_n: f64,
    /// Smallest collective thrust (N). Default 0 N (per-rotor minimum 0 N, Foehn et al. 2021).
    pub min_thrust_n: f64,
    /// Largest body torque magnitude per axis (N·m). Default derived from the per-rotor limits of
    /// Foehn et al. 2021: about x and y, two rotors at full thrust against two at zero on the
    /// diagonal arm (0.15 m, X configuration): √2 · 0.15 m · 6.88 N = 1.46 N·m; about z, the rotor
    /// drag torque 0.05 m · 2 · 6.88 N = 0.69 N·m.
    pub max_torque_n_m: Vec3,
    /// Largest body rate magnitude per axis (rad/s), the limit of the onboard rate loop. Applied as
    /// a projection after each integration step. Default 15 rad/s about x and y (Foehn et al. 2021).
    /// About z the source caps the *planned* yaw rate at 0.3 rad/s to keep the heading still; our
    /// controller holds the heading itself, so we use the same 15 rad/s (our choice).
    pub max_body_rate_rad_s: Vec3,
    /// Gravitational acceleration (m/s²), along −z. Default 9.81 m/s².
    pub gravity_m_s2: f64,
    /// Linear aerodynamic drag coefficient (kg/s): drag force = −coefficient · velocity (world
    /// frame). Default 0: the planner's limits and the controller's model assume no drag; set it
    /// to study the effect of unmodelled drag.
    pub drag_coefficient_kg_s: f64,
}

impl Default for QuadrotorParams {
    fn default() -> Self {
        let max_thrust_n = FOEHN_THRUST_TO_WEIGHT * FOEHN_MASS_KG * STANDARD_GRAVITY;
        let rotor_max_n = max_thrust_n / 4.0;
        let roll_pitch_torque = std::f64::consts::SQRT_2 * FOEHN_ARM_LENGTH_M * rotor_max_n;
        let yaw_torque = FOEHN_TORQUE_COEFF_M * 2.0 * rotor_max_n;
        QuadrotorParams {
            mass_kg: FOEHN_MASS_KG,
            inertia_kg_m2: Vec3::from(FOEHN_INERTIA_KG_M2),
            max_thrust_n,
            min_thrust_n: 0.0,
            max_torque_n_m: Vec3::new(roll_pitch_torque, roll_pitch_torque, yaw_torque),
            max_body_rate_rad_s: Vec3::repeat(FOEHN_MAX_BODY_RATE_XY),
            gravity_m_s2: STANDARD_GRAVITY,
            drag_coefficient_kg_s: 0.0,
        }
    }
}

impl QuadrotorParams {
    /// Checks every field: finite; mass, inertia, torque and rate limits and gravity > 0; the
    /// inertia satisfies the triangle inequality of a rigid body (each moment ≤ the sum of the
    /// other two); 0 ≤ `min_thrust_n` < `max_thrust_n`; the vehicle can hover
    /// (`max_thrust_n` > `mass_kg` · `gravity_m_s2`); drag ≥ 0.
    pub fn validate(&self) -> Result<(), VehicleError> {
        check_positive("mass_kg", self.mass_kg)?;
        check_positive_vec("inertia_kg_m2", &self.inertia_kg_m2)?;
        let j = &self.inertia_kg_m2;
        for (i, axis) in ["x", "y", "z"].iter().enumerate() {
            let others = j[(i + 1) % 3] + j[(i + 2) % 3];
            if j[i] > others {
                return Err(out_of_range(
                    &format!("inertia_kg_m2.{axis}"),
                    j[i],
                    format!("at most the sum of the other two moments ({others}) for a rigid body"),
                ));
            }
        }
        check_non_negative("min_thrust_n", self.min_thrust_n)?;
        check_finite("max_thrust_n", self.max_thrust_n)?;
        check_positive("gravity_m_s2", self.gravity_m_s2)?;
        let weight = self.mass_kg * self.gravity_m_s2;
        if self.max_thrust_n <= weight {
            return Err(out_of_range(
                "max_thrust_n",
                self.max_thrust_n,
                format!("more than the weight mass_kg · gravity_m_s2 = {weight} N (must hover)"),
            ));
        }
        if self.min_thrust_n >= self.max_thrust_n {
            return Err(out_of_range(
                "min_thrust_n",
                self.min_thrust_n,
                format!("less than max_thrust_n = {}", self.max_thrust_n),
            ));
        }
        check_positive_vec("max_torque_n_m", &self.max_torque_n_m)?;
        check_positive_vec("max_body_rate_rad_s", &self.max_body_rate_rad_s)?;
        check_non_negative("drag_coefficient_kg_s", self.drag_coefficient_kg_s)?;
        Ok(())
    }

    /// Thrust that balances gravity (N).
    pub fn hover_thrust_n(&self) -> f64 {
        self.mass_kg * self.gravity_m_s2
    }

    /// Thrust-to-weight ratio `max_thrust_n / (mass_kg · gravity_m_s2)` (3.3 for the default).
    pub fn thrust_to_weight(&self) -> f64 {
        self.max_thrust_n / self.hover_thrust_n()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn default_is_valid_and_matches_the_source() {
        let p = QuadrotorParams::default();
        p.validate().unwrap();
        assert_relative_eq!(p.thrust_to_weight(), 3.3, epsilon = 1e-12);
        assert_relative_eq!(p.max_thrust_n / 4.0, 6.879, epsilon = 1e-3);
        assert_relative_eq!(p.max_torque_n_m.x, 1.459, epsilon = 1e-3);
        assert_relative_eq!(p.max_torque_n_m.z, 0.688, epsilon = 1e-3);
        // The planner's worst case |a + g| = a_max + g must be reachable with margin.
        let a_max = 15.0;
        assert!(p.max_thrust_n / p.mass_kg > 1.25 * (a_max + p.gravity_m_s2));
    }

    #[test]
    fn validation_names_the_field() {
        let bad = |f: fn(&mut QuadrotorParams), field: &str| {
            let mut p = QuadrotorParams::default();
            f(&mut p);
            let err = p.validate().unwrap_err();
            assert!(err.to_string().contains(field), "{err} should name {field}");
        };
        bad(|p| p.mass_kg = 0.0, "mass_kg");
        bad(|p| p.mass_kg = f64::NAN, "mass_kg");
        bad(|p| p.inertia_kg_m2.y = -1.0, "inertia_kg_m2.y");
        bad(|p| p.inertia_kg_m2.z = 1.0, "inertia_kg_m2.z");
        bad(|p| p.min_thrust_n = 30.0, "min_thrust_n");
        bad(|p| p.min_thrust_n = -1.0, "min_thrust_n");
        bad(|p| p.max_thrust_n = 5.0, "max_thrust_n");
        bad(|p| p.max_thrust_n = f64::INFINITY, "max_thrust_n");
        bad(|p| p.max_torque_n_m.z = 0.0, "max_torque_n_m.z");
        bad(
            |p| p.max_body_rate_rad_s.x = f64::NAN,
            "max_body_rate_rad_s.x",
        );
        bad(|p| p.gravity_m_s2 = 0.0, "gravity_m_s2");
        bad(|p| p.drag_coefficient_kg_s = -0.1, "drag_coefficient_kg_s");
    }
}
