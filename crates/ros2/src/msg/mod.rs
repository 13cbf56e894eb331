//! The ROS 2 messages the node speaks, as serde structs whose fields are the `.msg` fields in
//! declaration order with the same types: ros2-client serializes them to CDR (XCDR1) with
//! serde, so the struct **is** the wire layout. A `float64[36]` is a fixed array (no length on
//! the wire, [`Covariance`]); `T[]` is a `Vec<T>` (a `uint32` count, then the elements); a
//! `string` is a `String` (a `uint32` length counting a trailing NUL, the bytes, the NUL).
//!
//! Each type knows its ROS name ([`RosMessage::PACKAGE`], [`RosMessage::NAME`]); on the wire
//! `pkg/msg/Name` is the DDS type `pkg::msg::dds_::Name_`. Definitions: ROS 2 Humble/Jazzy
//! `common_interfaces` (identical for these types) and our `trust_msgs`
//! (`crates/ros2/msg/trust_msgs/msg/*.msg`).

use serde::de::{self, SeqAccess, Visitor};
use serde::ser::SerializeTuple;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// A ROS 2 message type: its package and name (`PACKAGE/msg/NAME`).
pub trait RosMessage: Serialize + serde::de::DeserializeOwned + ros2_client::Message {
    /// The ROS package (`nav_msgs`).
    const PACKAGE: &'static str;
    /// The type name inside the package (`Odometry`).
    const NAME: &'static str;
}

/// Implements [`RosMessage`] and `ros2_client::Message` for a message struct.
macro_rules! ros_message {
    ($ty:ty, $pkg:literal, $name:literal) => {
        impl ros2_client::Message for $ty {}
        impl $crate::msg::RosMessage for $ty {
            const PACKAGE: &'static str = $pkg;
            const NAME: &'static str = $name;
        }
    };
}
pub(crate) use ros_message;

pub mod builtin_interfaces;
pub mod geometry_msgs;
pub mod nav_msgs;
pub mod rosgraph_msgs;
pub mod sensor_msgs;
pub mod std_msgs;
pub mod tf2_msgs;
pub mod trajectory_msgs;
pub mod trust_msgs;
pub mod visualization_msgs;

/// A row-major 6×6 covariance, `float64[36]` on the wire: 36 doubles, no length prefix
/// (serde has no impl for arrays longer than 32, so this serializes as a 36-tuple).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Covariance(pub [f64; 36]);

impl Default for Covariance {
    fn default() -> Self {
        Covariance([0.0; 36])
    }
}

impl Serialize for Covariance {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut t = serializer.serialize_tuple(36)?;
        for x in &self.0 {
            t.serialize_element(x)?;
        }
        t.end()
    }
}

impl<'de> Deserialize<'de> for Covariance {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Covariance;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("36 float64 values")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Covariance, A::Error> {
                let mut out = [0.0; 36];
                for (i, slot) in out.iter_mut().enumerate() {
                    *slot = seq
                        .next_element()?
                        .ok_or_else(|| de::Error::invalid_length(i, &self))?;
                }
                Ok(Covariance(out))
            }
        }
        deserializer.deserialize_tuple(36, V)
    }
}
