//! `nav_msgs`: [`Odometry`] and [`Path`].

use serde::{Deserialize, Serialize};

use crate::msg::geometry_msgs::{PoseStamped, PoseWithCovariance, TwistWithCovariance};
use crate::msg::std_msgs::Header;

/// `nav_msgs/msg/Odometry`: the pose in `header.frame_id`, the twist in `child_frame_id` (ROS
/// convention, REP 105: the body frame).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Odometry {
    /// `std_msgs/Header header`.
    pub header: Header,
    /// `string child_frame_id`.
    pub child_frame_id: String,
    /// `geometry_msgs/PoseWithCovariance pose`.
    pub pose: PoseWithCovariance,
    /// `geometry_msgs/TwistWithCovariance twist`.
    pub twist: TwistWithCovariance,
}
ros_message!(Odometry, "nav_msgs", "Odometry");

/// `nav_msgs/msg/Path`: poses only, no timing.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Path {
    /// `std_msgs/Header header`.
    pub header: Header,
    /// `geometry_msgs/PoseStamped[] poses`.
    pub poses: Vec<PoseStamped>,
}
ros_message!(Path, "nav_msgs", "Path");
