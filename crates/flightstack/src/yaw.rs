//! The yaw policy: the planner plans positions only (paper Sec. III-D), so the heading sent to a
//! flight stack is a choice, made here once for every target.

use serde::{Deserialize, Serialize};
use trust_core::Vec3;
use trust_core::scale::{self, Quantity};

use crate::error::FlightStackError;
use crate::frame::wrap_angle;

/// How the exported yaw is chosen. Angles are in our world frame (from +x, counter-clockwise
/// about +z, rad); the target's frame transform and the NED conversion are applied afterwards.
///
/// The default holds yaw 0, which is what our closed loop flies every plan with
/// (`Reference::from_traj(plan, τ, 0.0)` in `crates/flight/src/closed_loop.rs`). On a real
/// vehicle a fixed yaw different from its current heading turns it when the stream starts: set
/// `yaw_rad` to its heading, or use [`YawPolicy::Uncontrolled`] on PX4.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, tag = "kind", rename_all = "snake_case")]
pub enum YawPolicy {
    /// Yaw not controlled: PX4 gets NaN yaw and yawspeed, which it reads as "not controlled"
    /// and keeps its heading. The Crazyflie's `poly4d` has no such value: exporting to it fails
    /// with [`FlightStackError::Unsupported`].
    Uncontrolled,
    /// Hold one yaw (rad) for the whole trajectory; the yaw rate is zero.
    Fixed {
        /// The yaw (rad, any finite value; exports wrap it where the target wants a range).
        yaw_rad: f64,
    },
    /// Face the horizontal velocity while the horizontal speed exceeds `min_speed_m_s`, with the
    /// yaw rate `(v_x a_y − v_y a_x) / (v_x² + v_y²)`; slower, hold the last yaw with rate zero
    /// (at first `initial_yaw_rad`). Our MCAP export draws headings the same way with 5 cm/s
    /// (`trust-export`).
    FaceVelocity {
        /// Horizontal speed (m/s, `> 0`) above which the yaw follows the velocity.
        min_speed_m_s: f64,
        /// The yaw held until the vehicle first moves faster than `min_speed_m_s` (rad).
        initial_yaw_rad: f64,
    },
}

impl Default for YawPolicy {
    /// [`YawPolicy::Fixed`] at 0 rad, what `trust-flight`'s closed loop flies.
    fn default() -> Self {
        YawPolicy::Fixed { yaw_rad: 0.0 }
    }
}

impl YawPolicy {
    /// Checks the fields: angles finite, `min_speed_m_s` a positive speed of the scale policy.
    /// `field` prefixes the names in the error.
    pub fn validate(&self, field: &str) -> Result<(), FlightStackError> {
        let finite_angle = |name: &str, x: f64| {
            if x.is_finite() {
                Ok(())
            } else {
                Err(FlightStackError::invalid(
                    format!("{field}.{name}"),
                    x,
                    "a finite angle (rad)",
                ))
            }
        };
        match *self {
            YawPolicy::Uncontrolled => Ok(()),
            YawPolicy::Fixed { yaw_rad } => finite_angle("yaw_rad", yaw_rad),
            YawPolicy::FaceVelocity {
                min_speed_m_s,
                initial_yaw_rad,
            } => {
                if !min_speed_m_s.is_finite() {
                    return Err(FlightStackError::invalid(
                        format!("{field}.min_speed_m_s"),
                        min_speed_m_s,
                        "a finite speed > 0 (m/s)",
                    ));
                }
                scale::check(
                    &format!("{field}.min_speed_m_s"),
                    min_speed_m_s,
                    Quantity::PositiveSpeed,
                )?;
                finite_angle("initial_yaw_rad", initial_yaw_rad)
            }
        }
    }
}

/// A yaw and its rate in our world frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct YawSample {
    /// Yaw (rad), wrapped to `(−π, π]`.
    pub yaw_rad: f64,
    /// Yaw rate about +z (rad/s).
    pub yaw_rate_rad_s: f64,
}

/// A [`YawPolicy`] with its memory (the last yaw), fed the trajectory's states in time order.
///
/// Keep one tracker for a whole stream, across replans: [`YawPolicy::FaceVelocity`] then holds
/// the heading of the old plan when the new one starts slowly.
#[derive(Debug, Clone, PartialEq)]
pub struct YawTracker {
    policy: YawPolicy,
    last_yaw_rad: f64,
}

impl YawTracker {
    /// A tracker for a validated `policy`.
    ///
    /// # Errors
    /// [`FlightStackError`] naming `yaw.…` if the policy is invalid ([`YawPolicy::validate`]).
    pub fn new(policy: YawPolicy) -> Result<Self, FlightStackError> {
        policy.validate("yaw")?;
        let last_yaw_rad = match policy {
            YawPolicy::Uncontrolled => 0.0,
            YawPolicy::Fixed { yaw_rad } => wrap_angle(yaw_rad),
            YawPolicy::FaceVelocity {
                initial_yaw_rad, ..
            } => wrap_angle(initial_yaw_rad),
        };
        Ok(Self {
            policy,
            last_yaw_rad,
        })
    }

    /// The policy.
    pub fn policy(&self) -> YawPolicy {
        self.policy
    }

    /// The yaw for the next state (velocity `v`, acceleration `a`, world frame), or `None` if
    /// yaw is not controlled. Finite for finite input.
    pub fn next(&mut self, v: &Vec3, a: &Vec3) -> Option<YawSample> {
        match self.policy {
            YawPolicy::Uncontrolled => None,
            YawPolicy::Fixed { .. } => Some(YawSample {
                yaw_rad: self.last_yaw_rad,
                yaw_rate_rad_s: 0.0,
            }),
            YawPolicy::FaceVelocity { min_speed_m_s, .. } => {
                let speed2 = v.x * v.x + v.y * v.y;
                if speed2.sqrt() > min_speed_m_s {
                    self.last_yaw_rad = wrap_angle(v.y.atan2(v.x));
                    Some(YawSample {
                        yaw_rad: self.last_yaw_rad,
                        yaw_rate_rad_s: (v.x * a.y - v.y * a.x) / speed2,
                    })
                } else {
                    Some(YawSample {
                        yaw_rad: self.last_yaw_rad,
                        yaw_rate_rad_s: 0.0,
                    })
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use std::f64::consts::{FRAC_PI_2, PI};

    fn face(min: f64, initial: f64) -> YawPolicy {
        YawPolicy::FaceVelocity {
            min_speed_m_s: min,
            initial_yaw_rad: initial,
        }
    }

    #[test]
    fn fixed_and_uncontrolled() {
        let mut t = YawTracker::new(YawPolicy::default()).unwrap();
        let s = t.next(&Vec3::new(1.0, 1.0, 0.0), &Vec3::zeros()).unwrap();
        assert_eq!((s.yaw_rad, s.yaw_rate_rad_s), (0.0, 0.0));
        let mut t = YawTracker::new(YawPolicy::Fixed { yaw_rad: 3.0 * PI }).unwrap();
        assert_relative_eq!(
            t.next(&Vec3::zeros(), &Vec3::zeros())
                .unwrap()
                .yaw_rad
                .abs(),
            PI,
            epsilon = 1e-12
        );
        let mut t = YawTracker::new(YawPolicy::Uncontrolled).unwrap();
        assert_eq!(t.next(&Vec3::x(), &Vec3::zeros()), None);
    }

    #[test]
    fn faces_the_velocity_and_holds_when_slow() {
        let mut t = YawTracker::new(face(0.1, 0.5)).unwrap();
        // Hovering: the initial yaw.
        let s = t
            .next(&Vec3::new(0.01, 0.05, 1.0), &Vec3::new(1.0, 0.0, 0.0))
            .unwrap();
        assert_eq!((s.yaw_rad, s.yaw_rate_rad_s), (0.5, 0.0));
        // Flying north.
        let s = t.next(&Vec3::new(0.0, 2.0, 0.0), &Vec3::zeros()).unwrap();
        assert_relative_eq!(s.yaw_rad, FRAC_PI_2);
        // Slowing down: hold north.
        let s = t.next(&Vec3::new(0.05, 0.0, 0.0), &Vec3::zeros()).unwrap();
        assert_relative_eq!(s.yaw_rad, FRAC_PI_2);
        assert_eq!(s.yaw_rate_rad_s, 0.0);
    }

    #[test]
    fn yaw_rate_matches_a_finite_difference_on_a_circle() {
        // v(t) = (−sin t, cos t) · 2, a = (−cos t, −sin t) · 2: the yaw t + π/2 turns at 1 rad/s.
        let mut t = YawTracker::new(face(0.1, 0.0)).unwrap();
        for k in 0..20 {
            let s = k as f64 * 0.3;
            let v = Vec3::new(-s.sin(), s.cos(), 0.0) * 2.0;
            let a = Vec3::new(-s.cos(), -s.sin(), 0.0) * 2.0;
            let y = t.next(&v, &a).unwrap();
            assert_relative_eq!(y.yaw_rate_rad_s, 1.0, epsilon = 1e-12);
            assert_relative_eq!(wrap_angle(y.yaw_rad - s - FRAC_PI_2), 0.0, epsilon = 1e-12);
        }
    }

    #[test]
    fn invalid_policies_are_named() {
        for (p, field) in [
            (YawPolicy::Fixed { yaw_rad: f64::NAN }, "yaw.yaw_rad"),
            (face(0.0, 0.0), "yaw.min_speed_m_s"),
            (face(-1.0, 0.0), "yaw.min_speed_m_s"),
            (face(f64::INFINITY, 0.0), "yaw.min_speed_m_s"),
            (face(0.1, f64::NEG_INFINITY), "yaw.initial_yaw_rad"),
        ] {
            let e = YawTracker::new(p).unwrap_err().to_string();
            assert!(e.contains(field), "{e}");
        }
    }

    #[test]
    fn serde_names_the_kind() {
        let p: YawPolicy = serde_json::from_str(
            r#"{"kind": "face_velocity", "min_speed_m_s": 0.05, "initial_yaw_rad": 0}"#,
        )
        .unwrap();
        assert_eq!(p, face(0.05, 0.0));
        let p: YawPolicy = serde_json::from_str(r#"{"kind": "uncontrolled"}"#).unwrap();
        assert_eq!(p, YawPolicy::Uncontrolled);
        assert!(serde_json::from_str::<YawPolicy>(r#"{"kind": "fixed", "yaw": 1}"#).is_err());
        assert!(
            serde_json::from_str::<YawPolicy>(r#"{"kind": "fixed", "yaw_rad": 1, "x": 2}"#)
                .is_err()
        );
    }
}
