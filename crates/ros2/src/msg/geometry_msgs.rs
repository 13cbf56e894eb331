//! `geometry_msgs`: points, vectors, poses, twists, transforms and their stamped and covariance
//! forms.

use serde::{Deserialize, Serialize};
use trust_core::Vec3;

use crate::msg::Covariance;
use crate::msg::std_msgs::Header;

/// `geometry_msgs/msg/Point`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Point {
    /// `float64 x`.
    pub x: f64,
    /// `float64 y`.
    pub y: f64,
    /// `float64 z`.
    pub z: f64,
}
ros_message!(Point, "geometry_msgs", "Point");

/// `geometry_msgs/msg/Vector3`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Vector3 {
    /// `float64 x`.
    pub x: f64,
    /// `float64 y`.
    pub y: f64,
    /// `float64 z`.
    pub z: f64,
}
ros_message!(Vector3, "geometry_msgs", "Vector3");

impl From<Vec3> for Point {
    fn from(v: Vec3) -> Self {
        Point {
            x: v.x,
            y: v.y,
            z: v.z,
        }
    }
}

impl From<Point> for Vec3 {
    fn from(p: Point) -> Self {
        Vec3::new(p.x, p.y, p.z)
    }
}

impl From<Vec3> for Vector3 {
    fn from(v: Vec3) -> Self {
        Vector3 {
            x: v.x,
            y: v.y,
            z: v.z,
        }
    }
}

impl From<Vector3> for Vec3 {
    fn from(p: Vector3) -> Self {
        Vec3::new(p.x, p.y, p.z)
    }
}

/// `geometry_msgs/msg/Quaternion` (`x, y, z, w`; ROS's default is the identity `w = 1`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Quaternion {
    /// `float64 x`.
    pub x: f64,
    /// `float64 y`.
    pub y: f64,
    /// `float64 z`.
    pub z: f64,
    /// `float64 w`.
    pub w: f64,
}
ros_message!(Quaternion, "geometry_msgs", "Quaternion");

impl Default for Quaternion {
    /// The identity, as ROS 2's message default (`w = 1`).
    fn default() -> Self {
        Quaternion::IDENTITY
    }
}

impl Quaternion {
    /// The identity rotation.
    pub const IDENTITY: Quaternion = Quaternion {
        x: 0.0,
        y: 0.0,
        z: 0.0,
        w: 1.0,
    };

    /// A rotation by `yaw` (rad) about `z`.
    pub fn from_yaw(yaw: f64) -> Self {
        let h = 0.5 * yaw;
        Quaternion {
            x: 0.0,
            y: 0.0,
            z: h.sin(),
            w: h.cos(),
        }
    }

    /// The norm `√(x² + y² + z² + w²)`.
    pub fn norm(&self) -> f64 {
        (self.x * self.x + self.y * self.y + self.z * self.z + self.w * self.w).sqrt()
    }
}

/// `geometry_msgs/msg/Pose`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Pose {
    /// `Point position`.
    pub position: Point,
    /// `Quaternion orientation`.
    pub orientation: Quaternion,
}
ros_message!(Pose, "geometry_msgs", "Pose");

/// `geometry_msgs/msg/PoseStamped`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct PoseStamped {
    /// `std_msgs/Header header`.
    pub header: Header,
    /// `Pose pose`.
    pub pose: Pose,
}
ros_message!(PoseStamped, "geometry_msgs", "PoseStamped");

/// `geometry_msgs/msg/Twist`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Twist {
    /// `Vector3 linear`.
    pub linear: Vector3,
    /// `Vector3 angular`.
    pub angular: Vector3,
}
ros_message!(Twist, "geometry_msgs", "Twist");

/// `geometry_msgs/msg/Transform`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Transform {
    /// `Vector3 translation`.
    pub translation: Vector3,
    /// `Quaternion rotation`.
    pub rotation: Quaternion,
}
ros_message!(Transform, "geometry_msgs", "Transform");

/// `geometry_msgs/msg/PoseWithCovariance`: row-major covariance of `(x, y, z, rot x, rot y, rot
/// z)`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct PoseWithCovariance {
    /// `Pose pose`.
    pub pose: Pose,
    /// `float64[36] covariance`.
    pub covariance: Covariance,
}
ros_message!(PoseWithCovariance, "geometry_msgs", "PoseWithCovariance");

/// `geometry_msgs/msg/TwistWithCovariance`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct TwistWithCovariance {
    /// `Twist twist`.
    pub twist: Twist,
    /// `float64[36] covariance`.
    pub covariance: Covariance,
}
ros_message!(TwistWithCovariance, "geometry_msgs", "TwistWithCovariance");
