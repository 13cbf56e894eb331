//! `std_msgs`: [`Header`] and [`ColorRGBA`].

use serde::{Deserialize, Serialize};

use crate::msg::builtin_interfaces::Time;

/// `std_msgs/msg/Header`.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct Header {
    /// `builtin_interfaces/Time stamp`.
    pub stamp: Time,
    /// `string frame_id`.
    pub frame_id: String,
}
ros_message!(Header, "std_msgs", "Header");

// Beside `Header`, not in `builtin_interfaces`: `std_msgs` uses `builtin_interfaces`, never the
// other way round (no module cycle, tests/tests/tidy.rs).
impl Time {
    /// A header stamped with this time in `frame`.
    pub fn into_header(self, frame: &str) -> Header {
        Header {
            stamp: self,
            frame_id: frame.to_owned(),
        }
    }
}

/// `std_msgs/msg/ColorRGBA`, each channel in `[0, 1]`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct ColorRGBA {
    /// `float32 r`.
    pub r: f32,
    /// `float32 g`.
    pub g: f32,
    /// `float32 b`.
    pub b: f32,
    /// `float32 a`.
    pub a: f32,
}
ros_message!(ColorRGBA, "std_msgs", "ColorRGBA");
