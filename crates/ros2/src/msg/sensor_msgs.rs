//! `sensor_msgs`: only [`CompressedImage`], a field of `visualization_msgs/Marker`.

use serde::{Deserialize, Serialize};

use crate::msg::std_msgs::Header;

/// `sensor_msgs/msg/CompressedImage` (the marker's `texture`; we always send it empty).
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct CompressedImage {
    /// `std_msgs/Header header`.
    pub header: Header,
    /// `string format`.
    pub format: String,
    /// `uint8[] data`.
    pub data: Vec<u8>,
}
ros_message!(CompressedImage, "sensor_msgs", "CompressedImage");
