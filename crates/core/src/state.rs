//! Vehicle state and dynamic limits.

use serde::{Deserialize, Serialize};

use crate::error::{check_positive, check_scaled, check_scaled_vec};
use crate::{PlanError, Vec3};
use trust_geometry::scale::Quantity;

/// Kinematic state of the vehicle at absolute time `t` (seconds): position, velocity, acceleration.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct State {
    /// Absolute time (s).
    pub t: f64,
    /// Position (m).
    pub p: Vec3,
    /// Velocity (m/s).
    pub v: Vec3,
    /// Acceleration (m/s²).
    pub a: Vec3,
}

impl State {
    /// A state at rest at `p` at time `t`.
    pub fn at_rest(t: f64, p: Vec3) -> Self {
        State {
            t,
            p,
            v: Vec3::zeros(),
            a: Vec3::zeros(),
        }
    }

    /// Checks that all numbers are finite and inside the scale policy ([`crate::scale`]); `field` prefixes the field names in the error
    /// (e.g. `start` gives `start.v`).
    pub fn validate(&self, field: &str) -> Result<(), PlanError> {
        check_scaled(&format!("{field}.t"), self.t, Quantity::Time)?;
        check_scaled_vec(&format!("{field}.p"), &self.p, Quantity::Position)?;
        check_scaled_vec(&format!("{field}.v"), &self.v, Quantity::Velocity)?;
        check_scaled_vec(&format!("{field}.a"), &self.a, Quantity::Acceleration)?;
        Ok(())
    }
}

/// Dynamic limits of the vehicle (paper eq. design-of-Id).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Limits {
    /// Maximum speed (m/s).
    pub v_max: f64,
    /// Maximum acceleration norm (m/s²).
    pub a_max: f64,
}

impl Limits {
    /// Validated limits: both must be finite and strictly positive.
    pub fn new(v_max: f64, a_max: f64) -> Result<Self, PlanError> {
        let limits = Limits { v_max, a_max };
        limits.validate()?;
        Ok(limits)
    }

    /// Checks both limits (useful after deserialization).
    pub fn validate(&self) -> Result<(), PlanError> {
        check_positive("limits.v_max", self.v_max)?;
        check_positive("limits.a_max", self.a_max)?;
        check_scaled("limits.v_max", self.v_max, Quantity::PositiveSpeed)?;
        check_scaled("limits.a_max", self.a_max, Quantity::PositiveAcceleration)?;
        Ok(())
    }
}

impl Default for Limits {
    /// The limits of the paper's simulations (Sec. IV): `v_max = 10 m/s`, `a_max = 15 m/s²`.
    fn default() -> Self {
        Limits {
            v_max: 10.0,
            a_max: 15.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_reject_bad_values() {
        assert!(Limits::new(10.0, 15.0).is_ok());
        let e = Limits::new(0.0, 15.0).unwrap_err().to_string();
        assert!(e.contains("limits.v_max"), "{e}");
        let e = Limits::new(10.0, f64::NAN).unwrap_err().to_string();
        assert!(e.contains("limits.a_max"), "{e}");
    }

    #[test]
    fn state_validation_names_the_field() {
        let mut s = State::at_rest(0.0, Vec3::new(1.0, 2.0, 3.0));
        assert!(s.validate("start").is_ok());
        s.v.y = f64::INFINITY;
        let e = s.validate("start").unwrap_err().to_string();
        assert!(e.contains("start.v"), "{e}");
    }

    #[test]
    fn limits_deserialize_strictly() {
        let ok: Limits = serde_json::from_str(r#"{"v_max": 3.0, "a_max": 4.0}"#).unwrap();
        assert_eq!(ok.v_max, 3.0);
        assert!(serde_json::from_str::<Limits>(r#"{"v_max": 3.0, "a_max": 4.0, "j": 1}"#).is_err());
    }
}
