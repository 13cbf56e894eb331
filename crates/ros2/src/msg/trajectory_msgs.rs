//! `trajectory_msgs`: [`MultiDOFJointTrajectory`] and its points.

use serde::{Deserialize, Serialize};

use crate::msg::builtin_interfaces::Duration;
use crate::msg::geometry_msgs::{Transform, Twist};
use crate::msg::std_msgs::Header;

/// `trajectory_msgs/msg/MultiDOFJointTrajectoryPoint`: one entry per joint in each list (the
/// node has one joint, the vehicle).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct MultiDOFJointTrajectoryPoint {
    /// `geometry_msgs/Transform[] transforms`.
    pub transforms: Vec<Transform>,
    /// `geometry_msgs/Twist[] velocities`.
    pub velocities: Vec<Twist>,
    /// `geometry_msgs/Twist[] accelerations`.
    pub accelerations: Vec<Twist>,
    /// `builtin_interfaces/Duration time_from_start`.
    pub time_from_start: Duration,
}
ros_message!(
    MultiDOFJointTrajectoryPoint,
    "trajectory_msgs",
    "MultiDOFJointTrajectoryPoint"
);

/// `trajectory_msgs/msg/MultiDOFJointTrajectory`: points timed from `header.stamp`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct MultiDOFJointTrajectory {
    /// `std_msgs/Header header`.
    pub header: Header,
    /// `string[] joint_names`.
    pub joint_names: Vec<String>,
    /// `MultiDOFJointTrajectoryPoint[] points`.
    pub points: Vec<MultiDOFJointTrajectoryPoint>,
}
ros_message!(
    MultiDOFJointTrajectory,
    "trajectory_msgs",
    "MultiDOFJointTrajectory"
);
