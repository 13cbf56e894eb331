//! Frames: our world frame, ENU and NED, yaw conventions, and a rigid world-to-target transform.
//!
//! Our world frame is right-handed with z up (`trust-vehicle`: "world frame, z up"); this crate
//! takes it as ENU (x east, y north, z up) and yaw as the angle from +x, counter-clockwise about
//! +z. If your world's x axis is not east, put the rotation into a [`FrameTransform`].
//!
//! PX4 works in NED (x north, y east, z down), yaw from north, clockwise seen from above. The
//! vector map is the same in both directions (it is its own inverse):
//! `(n, e, d) = (y_enu, x_enu, −z_enu)`, for positions, velocities, accelerations and jerks alike.
//! A heading `(cos ψ, sin ψ)` in (east, north) is `(sin ψ, cos ψ)` in (north, east), hence
//! `ψ_ned = π/2 − ψ_enu` and, since NED's z axis points down, `ψ̇_ned = −ψ̇_enu`.

use serde::{Deserialize, Serialize};
use std::f64::consts::{FRAC_PI_2, PI, TAU};
use trust_core::Vec3;
use trust_core::scale::{self, Quantity};

use crate::error::FlightStackError;

/// ENU vector → NED vector: `(y, x, −z)`. Applies to positions, velocities, accelerations and
/// jerks. Non-finite components stay non-finite.
pub fn enu_to_ned(v: &Vec3) -> Vec3 {
    Vec3::new(v.y, v.x, -v.z)
}

/// NED vector → ENU vector: `(y, x, −z)`, the inverse of [`enu_to_ned`] (the same map).
pub fn ned_to_enu(v: &Vec3) -> Vec3 {
    Vec3::new(v.y, v.x, -v.z)
}

/// `angle` wrapped to `(−π, π]` (rad). NaN and ±∞ give NaN.
pub fn wrap_angle(angle: f64) -> f64 {
    let r = angle.rem_euclid(TAU);
    if r > PI { r - TAU } else { r }
}

/// ENU yaw (from east, counter-clockwise) → NED yaw (from north, clockwise):
/// `π/2 − ψ_enu`, wrapped to `(−π, π]`.
pub fn yaw_enu_to_ned(yaw_enu: f64) -> f64 {
    wrap_angle(FRAC_PI_2 - yaw_enu)
}

/// NED yaw → ENU yaw: `π/2 − ψ_ned`, wrapped to `(−π, π]` (the same map as [`yaw_enu_to_ned`]).
pub fn yaw_ned_to_enu(yaw_ned: f64) -> f64 {
    wrap_angle(FRAC_PI_2 - yaw_ned)
}

/// ENU yaw rate (about up) → NED yaw rate (about down): `−ψ̇_enu`; the inverse is the same map.
pub fn yaw_rate_enu_to_ned(yaw_rate_enu: f64) -> f64 {
    -yaw_rate_enu
}

/// A rigid transform from our world frame to a target's z-up frame: a rotation by `yaw_rad`
/// about z, then a shift by `offset_m`: `p_target = R_z(yaw_rad) · p_world + offset_m`.
/// Velocities and accelerations rotate only; yaws gain `yaw_rad`.
///
/// The default is the identity: our world frame *is* the target's frame (PX4's ENU twin of its
/// local NED origin, the Crazyflie's world frame). Both are z-up and right-handed like ours, so
/// a rotation about z and a shift are all a mismatch can be.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrameTransform {
    /// Rotation about z (rad), counter-clockwise: the target's yaw of our world's +x axis.
    pub yaw_rad: f64,
    /// Our world origin in the target frame (m).
    pub offset_m: Vec3,
}

impl FrameTransform {
    /// The identity (the [`Default`]).
    pub fn identity() -> Self {
        Self::default()
    }

    /// Checks the fields: `yaw_rad` finite, `offset_m` a position of the scale policy
    /// ([`trust_core::scale`]). `field` prefixes the names in the error.
    pub fn validate(&self, field: &str) -> Result<(), FlightStackError> {
        if !self.yaw_rad.is_finite() {
            return Err(FlightStackError::invalid(
                format!("{field}.yaw_rad"),
                self.yaw_rad,
                "a finite angle (rad)",
            ));
        }
        scale::check_vec(
            &format!("{field}.offset_m"),
            &self.offset_m,
            Quantity::Position,
        )?;
        Ok(())
    }

    /// A world point in the target frame.
    pub fn point(&self, p: &Vec3) -> Vec3 {
        self.vector(p) + self.offset_m
    }

    /// A world vector (velocity, acceleration, jerk, a polynomial coefficient of order ≥ 1) in the
    /// target frame.
    pub fn vector(&self, v: &Vec3) -> Vec3 {
        let (s, c) = self.yaw_rad.sin_cos();
        Vec3::new(c * v.x - s * v.y, s * v.x + c * v.y, v.z)
    }

    /// A world yaw (rad) in the target frame: `yaw + yaw_rad` (not wrapped).
    pub fn yaw(&self, yaw: f64) -> f64 {
        yaw + self.yaw_rad
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    fn heading(yaw: f64) -> (f64, f64) {
        (yaw.cos(), yaw.sin())
    }

    #[test]
    fn compass_points() {
        // East, north, west, south in ENU; NED yaw is 90°, 0°, -90°, 180°.
        let cases = [
            (0.0, FRAC_PI_2),
            (FRAC_PI_2, 0.0),
            (PI, -FRAC_PI_2),
            (-FRAC_PI_2, PI),
        ];
        for (enu, ned) in cases {
            assert_relative_eq!(yaw_enu_to_ned(enu), ned, epsilon = 1e-15);
            assert_relative_eq!(yaw_ned_to_enu(ned), wrap_angle(enu), epsilon = 1e-15);
        }
        // One metre north and up, moving east.
        let p = enu_to_ned(&Vec3::new(0.0, 1.0, 1.0));
        assert_eq!(p, Vec3::new(1.0, 0.0, -1.0));
        assert_eq!(
            enu_to_ned(&Vec3::new(2.0, 0.0, 0.0)),
            Vec3::new(0.0, 2.0, 0.0)
        );
        assert_eq!(yaw_rate_enu_to_ned(0.5), -0.5);
    }

    #[test]
    fn wrap_is_half_open() {
        assert_eq!(wrap_angle(PI), PI);
        assert_eq!(wrap_angle(-PI), PI);
        assert_eq!(wrap_angle(0.0), 0.0);
        // 3π lands next to ±π, on either side depending on rounding.
        assert_relative_eq!(wrap_angle(3.0 * PI).abs(), PI, epsilon = 1e-12);
        assert_relative_eq!(wrap_angle(-0.5), -0.5);
        assert_relative_eq!(wrap_angle(TAU + 0.25), 0.25, epsilon = 1e-15);
        assert!(wrap_angle(f64::NAN).is_nan());
        assert!(wrap_angle(f64::INFINITY).is_nan());
    }

    #[test]
    fn transform_rotates_then_shifts() {
        let tf = FrameTransform {
            yaw_rad: FRAC_PI_2,
            offset_m: Vec3::new(1.0, 2.0, 3.0),
        };
        assert_relative_eq!(
            tf.point(&Vec3::new(1.0, 0.0, 0.5)),
            Vec3::new(1.0, 3.0, 3.5),
            epsilon = 1e-15
        );
        assert_relative_eq!(
            tf.vector(&Vec3::new(1.0, 0.0, 0.5)),
            Vec3::new(0.0, 1.0, 0.5),
            epsilon = 1e-15
        );
        assert_relative_eq!(tf.yaw(0.25), 0.25 + FRAC_PI_2);
        assert_eq!(FrameTransform::identity().point(&Vec3::x()), Vec3::x());
        tf.validate("frame").unwrap();
        let bad = FrameTransform {
            yaw_rad: f64::NAN,
            ..tf
        };
        assert!(
            bad.validate("frame")
                .unwrap_err()
                .to_string()
                .contains("frame.yaw_rad")
        );
        let far = FrameTransform {
            offset_m: Vec3::new(0.0, 1e9, 0.0),
            ..tf
        };
        assert!(
            far.validate("frame")
                .unwrap_err()
                .to_string()
                .contains("frame.offset_m")
        );
    }

    #[test]
    fn transform_serde_is_strict() {
        let tf: FrameTransform =
            serde_json::from_str(r#"{"yaw_rad": 0.5, "offset_m": [1, 2, 3]}"#).unwrap();
        assert_eq!(tf.offset_m, Vec3::new(1.0, 2.0, 3.0));
        assert!(
            serde_json::from_str::<FrameTransform>(
                r#"{"yaw_rad": 0, "offset_m": [0,0,0], "x": 1}"#
            )
            .is_err()
        );
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]

        /// The vector map is an involution and keeps lengths.
        #[test]
        fn vector_round_trip(x in -1e6..1e6f64, y in -1e6..1e6f64, z in -1e6..1e6f64) {
            let v = Vec3::new(x, y, z);
            prop_assert_eq!(ned_to_enu(&enu_to_ned(&v)), v);
            prop_assert_eq!(enu_to_ned(&v).norm(), v.norm());
        }

        /// Yaw round trips up to wrapping, the result lies in (−π, π], and the NED heading vector is
        /// the ENU heading vector mapped by `enu_to_ned`.
        #[test]
        fn yaw_round_trip_and_heading(yaw in -20.0..20.0f64) {
            let ned = yaw_enu_to_ned(yaw);
            prop_assert!(ned > -PI && ned <= PI);
            let back = yaw_ned_to_enu(ned);
            prop_assert!(back > -PI && back <= PI);
            prop_assert!(wrap_angle(back - yaw).abs() < 1e-12, "{yaw} -> {ned} -> {back}");
            let (e, n) = heading(yaw);
            let mapped = enu_to_ned(&Vec3::new(e, n, 0.0));
            let (cn, sn) = heading(ned);
            prop_assert!((mapped.x - cn).abs() < 1e-12 && (mapped.y - sn).abs() < 1e-12);
        }

        /// A yaw rate maps so that integrating it keeps the two yaws consistent:
        /// ψ_ned(ψ_enu + δ) = ψ_ned(ψ_enu) + δ·(rate map of 1).
        #[test]
        fn yaw_rate_matches_yaw_map(yaw in -3.0..3.0f64, rate in -10.0..10.0f64) {
            let dt = 1e-6;
            let moved = wrap_angle(yaw_enu_to_ned(yaw + rate * dt) - yaw_enu_to_ned(yaw));
            prop_assert!((moved - yaw_rate_enu_to_ned(rate) * dt).abs() < 1e-12);
        }

        /// The transform is rigid: distances are kept, and point differences transform as vectors.
        #[test]
        fn transform_is_rigid(
            yaw in -4.0..4.0f64,
            off in prop::array::uniform3(-100.0..100.0f64),
            a in prop::array::uniform3(-100.0..100.0f64),
            b in prop::array::uniform3(-100.0..100.0f64),
        ) {
            let tf = FrameTransform { yaw_rad: yaw, offset_m: Vec3::from(off) };
            let (a, b) = (Vec3::from(a), Vec3::from(b));
            let d = tf.point(&a) - tf.point(&b);
            prop_assert!((d - tf.vector(&(a - b))).norm() < 1e-9);
            prop_assert!((d.norm() - (a - b).norm()).abs() < 1e-9);
        }
    }
}
