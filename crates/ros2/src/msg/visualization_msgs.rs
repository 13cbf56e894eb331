//! `visualization_msgs`: [`Marker`] (with its `UVCoordinate` and `MeshFile` fields) and
//! [`MarkerArray`], as in ROS 2 Humble and Jazzy (textures and embedded meshes included: the
//! fields are on the wire even when empty).

use serde::{Deserialize, Serialize};

use crate::msg::builtin_interfaces::Duration;
use crate::msg::geometry_msgs::{Point, Pose, Vector3};
use crate::msg::sensor_msgs::CompressedImage;
use crate::msg::std_msgs::{ColorRGBA, Header};

/// `visualization_msgs/msg/UVCoordinate`.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct UVCoordinate {
    /// `float32 u`.
    pub u: f32,
    /// `float32 v`.
    pub v: f32,
}
ros_message!(UVCoordinate, "visualization_msgs", "UVCoordinate");

/// `visualization_msgs/msg/MeshFile`.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct MeshFile {
    /// `string filename`.
    pub filename: String,
    /// `uint8[] data`.
    pub data: Vec<u8>,
}
ros_message!(MeshFile, "visualization_msgs", "MeshFile");

/// `visualization_msgs/msg/Marker`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct Marker {
    /// `std_msgs/Header header`.
    pub header: Header,
    /// `string ns`.
    pub ns: String,
    /// `int32 id`.
    pub id: i32,
    /// `int32 type` (`Marker::SPHERE`, …).
    #[serde(rename = "type")]
    pub kind: i32,
    /// `int32 action` (`Marker::ADD`, …).
    pub action: i32,
    /// `geometry_msgs/Pose pose`.
    pub pose: Pose,
    /// `geometry_msgs/Vector3 scale`.
    pub scale: Vector3,
    /// `std_msgs/ColorRGBA color`.
    pub color: ColorRGBA,
    /// `builtin_interfaces/Duration lifetime` (0: for ever).
    pub lifetime: Duration,
    /// `bool frame_locked`.
    pub frame_locked: bool,
    /// `geometry_msgs/Point[] points`.
    pub points: Vec<Point>,
    /// `std_msgs/ColorRGBA[] colors`.
    pub colors: Vec<ColorRGBA>,
    /// `string texture_resource`.
    pub texture_resource: String,
    /// `sensor_msgs/CompressedImage texture`.
    pub texture: CompressedImage,
    /// `UVCoordinate[] uv_coordinates`.
    pub uv_coordinates: Vec<UVCoordinate>,
    /// `string text`.
    pub text: String,
    /// `string mesh_resource`.
    pub mesh_resource: String,
    /// `MeshFile mesh_file`.
    pub mesh_file: MeshFile,
    /// `bool mesh_use_embedded_materials`.
    pub mesh_use_embedded_materials: bool,
}
ros_message!(Marker, "visualization_msgs", "Marker");

impl Marker {
    /// `type`: a sphere.
    pub const SPHERE: i32 = 2;
    /// `type`: a cylinder along the pose's z axis.
    pub const CYLINDER: i32 = 3;
    /// `type`: a line through `points`.
    pub const LINE_STRIP: i32 = 4;
    /// `action`: add or modify.
    pub const ADD: i32 = 0;
    /// `action`: delete every marker (of `ns`, when set).
    pub const DELETEALL: i32 = 3;
}

/// `visualization_msgs/msg/MarkerArray`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct MarkerArray {
    /// `Marker[] markers`.
    pub markers: Vec<Marker>,
}
ros_message!(MarkerArray, "visualization_msgs", "MarkerArray");
