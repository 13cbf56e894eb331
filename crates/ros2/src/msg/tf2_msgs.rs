//! `tf2_msgs`: [`TFMessage`], and the `geometry_msgs/msg/TransformStamped` it is made of
//! ([`TransformStamped`], kept here beside its one user).

use serde::{Deserialize, Serialize};

use crate::msg::geometry_msgs::Transform;
use crate::msg::std_msgs::Header;

/// `geometry_msgs/msg/TransformStamped`: the pose of `child_frame_id` in `header.frame_id`
/// (a point in the child frame maps to the parent frame by `transform`).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct TransformStamped {
    /// `std_msgs/Header header`: the stamp and the parent frame.
    pub header: Header,
    /// `string child_frame_id`.
    pub child_frame_id: String,
    /// `geometry_msgs/Transform transform`.
    pub transform: Transform,
}
ros_message!(TransformStamped, "geometry_msgs", "TransformStamped");

/// `tf2_msgs/msg/TFMessage`, the type of `/tf` and `/tf_static`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct TFMessage {
    /// `geometry_msgs/TransformStamped[] transforms`.
    pub transforms: Vec<TransformStamped>,
}
ros_message!(TFMessage, "tf2_msgs", "TFMessage");
