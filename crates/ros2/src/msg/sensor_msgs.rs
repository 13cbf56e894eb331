//! `sensor_msgs`: [`CompressedImage`] (a field of `visualization_msgs/Marker`) and
//! [`PointCloud2`] with its [`PointField`] (the node's `cloud` input; decoded by
//! [`crate::cloud`]).

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

/// `sensor_msgs/msg/PointField`: one field of a [`PointCloud2`]'s points.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct PointField {
    /// `string name` (`x`, `y`, `z`, `intensity`, `rgb`, …).
    pub name: String,
    /// `uint32 offset`: the field's first byte from the start of its point.
    pub offset: u32,
    /// `uint8 datatype`: one of the constants below.
    pub datatype: u8,
    /// `uint32 count`: elements in the field (1 for a scalar).
    pub count: u32,
}
ros_message!(PointField, "sensor_msgs", "PointField");

impl PointField {
    /// `INT8 = 1`.
    pub const INT8: u8 = 1;
    /// `UINT8 = 2`.
    pub const UINT8: u8 = 2;
    /// `INT16 = 3`.
    pub const INT16: u8 = 3;
    /// `UINT16 = 4`.
    pub const UINT16: u8 = 4;
    /// `INT32 = 5`.
    pub const INT32: u8 = 5;
    /// `UINT32 = 6`.
    pub const UINT32: u8 = 6;
    /// `FLOAT32 = 7`.
    pub const FLOAT32: u8 = 7;
    /// `FLOAT64 = 8`.
    pub const FLOAT64: u8 = 8;

    /// The size in bytes of one element of `datatype` (`None` for an unknown datatype).
    pub fn datatype_size(datatype: u8) -> Option<usize> {
        match datatype {
            Self::INT8 | Self::UINT8 => Some(1),
            Self::INT16 | Self::UINT16 => Some(2),
            Self::INT32 | Self::UINT32 | Self::FLOAT32 => Some(4),
            Self::FLOAT64 => Some(8),
            _ => None,
        }
    }
}

/// `sensor_msgs/msg/PointCloud2`: `height` rows of `width` points, each `point_step` bytes laid
/// out by `fields`, rows `row_step` bytes apart in `data`.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct PointCloud2 {
    /// `std_msgs/Header header`: the frame of the points and the time they were taken.
    pub header: Header,
    /// `uint32 height`: rows (1 for an unordered cloud).
    pub height: u32,
    /// `uint32 width`: points per row.
    pub width: u32,
    /// `PointField[] fields`.
    pub fields: Vec<PointField>,
    /// `bool is_bigendian`.
    pub is_bigendian: bool,
    /// `uint32 point_step`: bytes per point.
    pub point_step: u32,
    /// `uint32 row_step`: bytes per row.
    pub row_step: u32,
    /// `uint8[] data`: `row_step * height` bytes.
    pub data: Vec<u8>,
    /// `bool is_dense`: true if no point is invalid.
    pub is_dense: bool,
}
ros_message!(PointCloud2, "sensor_msgs", "PointCloud2");
