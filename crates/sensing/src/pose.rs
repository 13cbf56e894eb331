//! The vehicle's (or sensor's) pose in the world frame.

use nalgebra::UnitQuaternion;
use serde::{Deserialize, Serialize};
use trust_geometry::Vec3;
use trust_geometry::scale::MAX_COORD_M;

use crate::error::{SensingError, check_finite};

/// Position and attitude of the sensor in the world frame (z up).
///
/// The sensor frame is the body frame of the vehicle (FLU: x forward, y left, z up, as
/// `trust-vehicle`'s attitude): a camera looks along +x with image rows going down (−z) and
/// columns going right (−y); a LiDAR spins about +z. `attitude` rotates sensor-frame vectors into
/// the world frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    /// Sensor origin in the world frame, metres.
    pub position: Vec3,
    /// Rotation from the sensor frame to the world frame.
    pub attitude: UnitQuaternion<f64>,
}

impl Pose {
    /// A pose at `position` with the given attitude.
    pub fn new(position: Vec3, attitude: UnitQuaternion<f64>) -> Self {
        Self { position, attitude }
    }

    /// A pose at `position` looking along +x (identity attitude).
    pub fn at(position: Vec3) -> Self {
        Self::new(position, UnitQuaternion::identity())
    }

    /// A pose at `position` turned by `yaw` radians about +z (level flight).
    pub fn level(position: Vec3, yaw: f64) -> Self {
        Self::new(
            position,
            UnitQuaternion::from_axis_angle(&Vec3::z_axis(), yaw),
        )
    }

    /// Checks that the position is finite and within the scale policy (`|x| ≤ 1e6` m) and that
    /// the attitude is a finite unit quaternion (norm within `1e-6` of 1).
    pub fn validate(&self) -> Result<(), SensingError> {
        for (i, axis) in ['x', 'y', 'z'].into_iter().enumerate() {
            let field = format!("pose.position.{axis}");
            let v = check_finite(&field, self.position[i])?;
            if v.abs() > MAX_COORD_M {
                return Err(SensingError::OutOfRange {
                    field,
                    value: v,
                    expected: "|x| <= 1e6 m (the scale policy)",
                });
            }
        }
        let q = self.attitude.quaternion();
        for (i, c) in ['i', 'j', 'k', 'w'].into_iter().enumerate() {
            check_finite(&format!("pose.attitude.{c}"), q.coords[i])?;
        }
        let n = q.norm();
        if (n - 1.0).abs() > 1e-6 {
            return Err(SensingError::OutOfRange {
                field: "pose.attitude.norm".into(),
                value: n,
                expected: "a unit quaternion (norm 1 within 1e-6)",
            });
        }
        Ok(())
    }
}
