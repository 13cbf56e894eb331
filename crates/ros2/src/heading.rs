//! The yaw the node publishes. The planner plans positions only (paper Sec. III-D), so the
//! heading in `trajectory`, `path`, `setpoint` and PX4's `TrajectorySetpoint` is a policy
//! ([`YawMode`], the parameter `yaw`), applied by `trust_flightstack`'s [`YawTracker`]:
//!
//! - `face_velocity` (the default, threshold 0.3 m/s): face the plan's horizontal velocity
//!   while its horizontal speed exceeds the threshold, with the analytic yaw rate
//!   `(v_x a_y − v_y a_x) / (v_x² + v_y²)`; slower (hovering, taking off, braking to the goal)
//!   hold the last yaw with rate 0. Before the first fast motion the held yaw is the vehicle's
//!   own heading (its odometry's at the node's first plan), so the vehicle does not turn when
//!   the stream starts.
//! - `fixed { yaw_rad }`: that yaw, rate 0.
//! - `uncontrolled`: PX4 gets NaN yaw and yawspeed ("not controlled": it keeps its heading);
//!   the ROS messages, which have no "not controlled", carry the vehicle's latest heading
//!   (odometry) with rate 0.
//!
//! Never NaN in a ROS message, whatever the velocity (zero included). Yaws are in the world
//! frame (ENU: from +x east, counter-clockwise about +z); PX4's is `π/2 − yaw`, wrapped to
//! `(−π, π]` (`trust_flightstack::frame::yaw_enu_to_ned`), its rate `−rate`.
//!
//! One [`Heading`] holds the stream's memory (the last yaw): it is advanced at the present
//! only (a cycle's first sample, each setpoint); a message sampling the plan ahead uses a copy
//! ([`Heading::ahead`]), so the held yaw is never one of the plan's future.

use nalgebra::UnitQuaternion;
use serde::{Deserialize, Serialize};
use trust_core::Vec3;
use trust_flightstack::yaw::{YawPolicy, YawSample, YawTracker};

use crate::error::Ros2Error;

/// The node's yaw policy (module docs), parameter `yaw` (a TOML table tagged by `kind`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, tag = "kind", rename_all = "snake_case")]
pub enum YawMode {
    /// Face the plan's horizontal velocity above `min_speed_m_s`, else hold the last yaw (at
    /// first the vehicle's heading).
    FaceVelocity {
        /// Horizontal speed (m/s, `> 0`) above which the yaw follows the velocity.
        min_speed_m_s: f64,
    },
    /// Hold one yaw (rad, world frame).
    Fixed {
        /// The yaw (rad, finite).
        yaw_rad: f64,
    },
    /// PX4: NaN yaw and yawspeed; ROS messages: the vehicle's latest heading.
    Uncontrolled,
}

impl Default for YawMode {
    /// `face_velocity` at 0.3 m/s.
    fn default() -> Self {
        YawMode::FaceVelocity {
            min_speed_m_s: DEFAULT_MIN_SPEED_M_S,
        }
    }
}

/// The default threshold of `face_velocity` (m/s): well below the cruise speeds of our
/// scenarios (1 to 10 m/s), well above a plan's speed in the instants it starts or stops.
pub const DEFAULT_MIN_SPEED_M_S: f64 = 0.3;

impl YawMode {
    /// The flight stack's policy for a vehicle now heading `vehicle_yaw_rad`.
    pub fn policy(&self, vehicle_yaw_rad: f64) -> YawPolicy {
        match *self {
            YawMode::FaceVelocity { min_speed_m_s } => YawPolicy::FaceVelocity {
                min_speed_m_s,
                initial_yaw_rad: vehicle_yaw_rad,
            },
            YawMode::Fixed { yaw_rad } => YawPolicy::Fixed { yaw_rad },
            YawMode::Uncontrolled => YawPolicy::Uncontrolled,
        }
    }

    /// Checks the fields (`yaw.min_speed_m_s` finite and positive, `yaw.yaw_rad` finite).
    ///
    /// # Errors
    /// [`Ros2Error::FlightStack`] naming the field.
    pub fn validate(&self) -> Result<(), Ros2Error> {
        Ok(self.policy(0.0).validate("yaw")?)
    }
}

/// The heading (yaw about +z, rad, in `(−π, π]`) of an orientation: the `z` angle of its
/// roll-pitch-yaw (ZYX) angles, the direction its body x axis points to in the horizontal plane.
pub fn yaw_of(q: &UnitQuaternion<f64>) -> f64 {
    q.euler_angles().2
}

/// The node's yaw stream (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct Heading {
    mode: YawMode,
    /// Created at the first sample, from the vehicle's heading then.
    tracker: Option<YawTracker>,
    /// The vehicle's latest heading (odometry), 0 before any.
    vehicle_yaw_rad: f64,
}

impl Heading {
    /// A stream with policy `mode`.
    ///
    /// # Errors
    /// [`Ros2Error::FlightStack`] naming the invalid field of `mode`.
    pub fn new(mode: YawMode) -> Result<Self, Ros2Error> {
        mode.validate()?;
        Ok(Heading {
            mode,
            tracker: None,
            vehicle_yaw_rad: 0.0,
        })
    }

    /// Records the vehicle's heading (rad, from its odometry).
    pub fn observe_vehicle(&mut self, yaw_rad: f64) {
        if yaw_rad.is_finite() {
            self.vehicle_yaw_rad = yaw_rad;
        }
    }

    /// The flight stack's tracker (PX4's setpoints are sampled with it), created at its first
    /// use from the vehicle's heading then.
    ///
    /// # Errors
    /// [`Ros2Error::FlightStack`] for an invalid policy (checked in [`Heading::new`] already).
    pub fn tracker(&mut self) -> Result<&mut YawTracker, Ros2Error> {
        let tracker = match self.tracker.take() {
            Some(t) => t,
            None => YawTracker::new(self.mode.policy(self.vehicle_yaw_rad))?,
        };
        Ok(self.tracker.insert(tracker))
    }

    /// The yaw of a ROS message at a state of velocity `v` and acceleration `a` (world frame),
    /// taken in time order: never NaN (module docs).
    ///
    /// # Errors
    /// As [`Heading::tracker`].
    pub fn next(&mut self, v: &Vec3, a: &Vec3) -> Result<YawSample, Ros2Error> {
        let held = self.vehicle_yaw_rad;
        Ok(self.tracker()?.next(v, a).unwrap_or(YawSample {
            yaw_rad: held,
            yaw_rate_rad_s: 0.0,
        }))
    }

    /// A copy for sampling a plan ahead of the present: it starts from this stream's held yaw
    /// and leaves this stream as it is.
    ///
    /// # Errors
    /// As [`Heading::tracker`].
    pub fn ahead(&mut self) -> Result<Heading, Ros2Error> {
        self.tracker()?;
        Ok(self.clone())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use std::f64::consts::{FRAC_PI_2, PI};

    fn face() -> Heading {
        Heading::new(YawMode::default()).expect("valid")
    }

    #[test]
    fn holds_the_vehicles_heading_until_it_moves_then_faces_the_velocity() {
        let mut h = face();
        h.observe_vehicle(FRAC_PI_2);
        // At rest and slow: the vehicle's heading (north), never NaN.
        for v in [Vec3::zeros(), Vec3::new(0.1, 0.1, 2.0)] {
            let y = h.next(&v, &Vec3::new(3.0, 0.0, 0.0)).expect("yaw");
            assert_eq!((y.yaw_rad, y.yaw_rate_rad_s), (FRAC_PI_2, 0.0));
        }
        // Fast towards the west.
        let y = h
            .next(&Vec3::new(-2.0, 0.0, 0.0), &Vec3::zeros())
            .expect("yaw");
        assert_relative_eq!(y.yaw_rad, PI);
        // Stopped: west is held, whatever the odometry says since.
        h.observe_vehicle(0.3);
        let y = h.next(&Vec3::zeros(), &Vec3::zeros()).expect("yaw");
        assert_relative_eq!(y.yaw_rad, PI);
    }

    #[test]
    fn a_copy_ahead_leaves_the_stream_alone() {
        let mut h = face();
        h.observe_vehicle(0.5);
        let mut ahead = h.ahead().expect("copy");
        ahead
            .next(&Vec3::new(0.0, -3.0, 0.0), &Vec3::zeros())
            .expect("yaw");
        let y = h.next(&Vec3::zeros(), &Vec3::zeros()).expect("yaw");
        assert_eq!(y.yaw_rad, 0.5);
    }

    #[test]
    fn uncontrolled_carries_the_vehicles_latest_heading_in_ros_messages() {
        let mut h = Heading::new(YawMode::Uncontrolled).expect("valid");
        h.observe_vehicle(-1.0);
        assert_eq!(h.next(&Vec3::x(), &Vec3::y()).expect("yaw").yaw_rad, -1.0);
        h.observe_vehicle(2.0);
        assert_eq!(h.next(&Vec3::x(), &Vec3::y()).expect("yaw").yaw_rad, 2.0);
        assert_eq!(
            h.tracker().expect("tracker").next(&Vec3::x(), &Vec3::y()),
            None
        );
    }

    #[test]
    fn invalid_modes_are_named() {
        for (m, field) in [
            (
                YawMode::FaceVelocity { min_speed_m_s: 0.0 },
                "yaw.min_speed_m_s",
            ),
            (
                YawMode::FaceVelocity {
                    min_speed_m_s: f64::NAN,
                },
                "yaw.min_speed_m_s",
            ),
            (
                YawMode::Fixed {
                    yaw_rad: f64::INFINITY,
                },
                "yaw.yaw_rad",
            ),
        ] {
            let e = Heading::new(m).expect_err("invalid").to_string();
            assert!(e.contains(field), "{e}");
        }
    }

    #[test]
    fn yaw_of_a_tilted_vehicle_is_its_heading() {
        let q = UnitQuaternion::from_euler_angles(0.2, -0.1, 2.5);
        assert_relative_eq!(yaw_of(&q), 2.5, epsilon = 1e-12);
        assert_relative_eq!(yaw_of(&UnitQuaternion::identity()), 0.0);
    }
}
