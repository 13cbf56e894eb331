//! CDR (XCDR1, little-endian) payloads of our messages, exactly as ros2-client writes them:
//! the 4-byte encapsulation header `00 01 00 00` (`CDR_LE`), then RustDDS's serde CDR
//! serializer (`cdr-encoding`), which aligns each primitive to its size counted from the end of
//! the header. For tests, the benchmark and tools that write bags; the DDS layer does not call
//! it (the writer does the same itself).

use byteorder::LittleEndian;
use ros2_client::dds::rustdds::cdr_encoding;
use serde::Serialize;
use serde::de::DeserializeOwned;

use crate::error::Ros2Error;

/// The encapsulation header of a little-endian CDR payload (`CDR_LE`, options 0).
pub const CDR_LE_HEADER: [u8; 4] = [0x00, 0x01, 0x00, 0x00];

/// `msg` as a CDR payload: [`CDR_LE_HEADER`] then the body.
///
/// # Errors
/// [`Ros2Error::Cdr`] if serde fails (a sequence without a known length).
pub fn encode<T: Serialize>(msg: &T) -> Result<Vec<u8>, Ros2Error> {
    let mut out = CDR_LE_HEADER.to_vec();
    cdr_encoding::to_writer::<T, LittleEndian, _>(&mut out, msg)
        .map_err(|e| Ros2Error::Cdr(e.to_string()))?;
    Ok(out)
}

/// A message back from a payload written by [`encode`] (little-endian only).
///
/// # Errors
/// [`Ros2Error::Cdr`] for another encapsulation, truncated or malformed data.
pub fn decode<T: DeserializeOwned>(payload: &[u8]) -> Result<T, Ros2Error> {
    let Some(body) = payload.strip_prefix(&CDR_LE_HEADER[..]) else {
        return Err(Ros2Error::Cdr(format!(
            "encapsulation header {:02x?}: expected {CDR_LE_HEADER:02x?} (CDR_LE)",
            &payload[..payload.len().min(4)]
        )));
    };
    cdr_encoding::from_bytes::<T, LittleEndian>(body)
        .map(|(msg, _)| msg)
        .map_err(|e| Ros2Error::Cdr(e.to_string()))
}

#[cfg(test)]
mod tests {
    //! Payloads checked against bytes written out by hand from the XCDR1 rules: after the
    //! 4-byte header, each primitive is aligned to its size counted from the body's start; a
    //! string is `u32` length (with the NUL), bytes, NUL; a sequence a `u32` count; a
    //! `float64[36]` 36 doubles with no count.

    use super::*;
    use crate::msg::builtin_interfaces::{Duration, Time};
    use crate::msg::geometry_msgs::{Point, Quaternion, Transform, Twist, Vector3};
    use crate::msg::nav_msgs::Odometry;
    use crate::msg::std_msgs::Header;
    use crate::msg::trajectory_msgs::{MultiDOFJointTrajectory, MultiDOFJointTrajectoryPoint};
    use crate::msg::visualization_msgs::{Marker, MarkerArray};

    /// A hand-written payload.
    struct Bytes(Vec<u8>);

    impl Bytes {
        fn new() -> Self {
            Bytes(CDR_LE_HEADER.to_vec())
        }
        /// Zero padding up to a multiple of `n` from the body's start; returns the pad size.
        fn pad(&mut self, n: usize) -> usize {
            let mut k = 0;
            while !(self.0.len() - 4).is_multiple_of(n) {
                self.0.push(0);
                k += 1;
            }
            k
        }
        fn u32(&mut self, v: u32) {
            self.0.extend_from_slice(&v.to_le_bytes());
        }
        fn i32(&mut self, v: i32) {
            self.0.extend_from_slice(&v.to_le_bytes());
        }
        fn f64s(&mut self, vs: &[f64]) {
            for v in vs {
                self.0.extend_from_slice(&v.to_le_bytes());
            }
        }
        fn string(&mut self, s: &str) {
            self.u32(s.len() as u32 + 1);
            self.0.extend_from_slice(s.as_bytes());
            self.0.push(0);
        }
        fn body_len(&self) -> usize {
            self.0.len() - 4
        }
    }

    #[test]
    fn odometry_matches_hand_computed_bytes() {
        let mut pose_cov = [0.0; 36];
        pose_cov[0] = 0.25;
        pose_cov[35] = 0.5;
        let mut twist_cov = [0.0; 36];
        twist_cov[7] = -1.0;
        let msg = Odometry {
            header: Header {
                stamp: Time { sec: 1, nanosec: 2 },
                frame_id: "map".into(),
            },
            child_frame_id: "base_link".into(),
            pose: crate::msg::geometry_msgs::PoseWithCovariance {
                pose: crate::msg::geometry_msgs::Pose {
                    position: Point {
                        x: 1.5,
                        y: -2.0,
                        z: 3.25,
                    },
                    orientation: Quaternion {
                        x: 0.0,
                        y: 0.0,
                        z: 0.6,
                        w: 0.8,
                    },
                },
                covariance: crate::msg::Covariance(pose_cov),
            },
            twist: crate::msg::geometry_msgs::TwistWithCovariance {
                twist: Twist {
                    linear: Vector3 {
                        x: 0.1,
                        y: 0.2,
                        z: 0.3,
                    },
                    angular: Vector3 {
                        x: 0.0,
                        y: 0.0,
                        z: -0.5,
                    },
                },
                covariance: crate::msg::Covariance(twist_cov),
            },
        };
        let mut b = Bytes::new();
        b.i32(1); // stamp.sec          body 0..4
        b.u32(2); // stamp.nanosec      4..8
        b.string("map"); // frame_id    8..16 (len 4 + "map\0")
        b.string("base_link"); // child 16..30 (len 10 + 10 bytes)
        assert_eq!(b.body_len(), 30);
        assert_eq!(b.pad(8), 2, "position.x is a float64: 30 -> 32");
        b.f64s(&[1.5, -2.0, 3.25]); // 32..56
        b.f64s(&[0.0, 0.0, 0.6, 0.8]); // 56..88
        b.f64s(&pose_cov); // 88..376, no count
        b.f64s(&[0.1, 0.2, 0.3, 0.0, 0.0, -0.5]); // 376..424
        b.f64s(&twist_cov); // 424..712
        assert_eq!(b.body_len(), 712);
        let payload = encode(&msg).expect("encodes");
        assert_eq!(payload.len(), 716);
        assert_eq!(payload, b.0);
        assert_eq!(decode::<Odometry>(&payload).expect("decodes"), msg);
    }

    #[test]
    fn tiny_multi_dof_trajectory_matches_hand_computed_bytes() {
        let msg = MultiDOFJointTrajectory {
            header: Header {
                stamp: Time { sec: 5, nanosec: 0 },
                frame_id: "map".into(),
            },
            joint_names: vec!["a".into()],
            points: vec![MultiDOFJointTrajectoryPoint {
                transforms: vec![Transform {
                    translation: Vector3 {
                        x: 1.0,
                        y: 2.0,
                        z: 3.0,
                    },
                    rotation: Quaternion::IDENTITY,
                }],
                velocities: vec![Twist {
                    linear: Vector3 {
                        x: 4.0,
                        y: 0.0,
                        z: 0.0,
                    },
                    angular: Vector3::default(),
                }],
                accelerations: vec![Twist::default()],
                time_from_start: Duration {
                    sec: 0,
                    nanosec: 500_000_000,
                },
            }],
        };
        let mut b = Bytes::new();
        b.i32(5); // 0..4
        b.u32(0); // 4..8
        b.string("map"); // 8..16
        b.u32(1); // joint_names count 16..20
        b.string("a"); // 20..26 (len 2 + "a\0")
        assert_eq!(b.pad(4), 2, "points count is a uint32: 26 -> 28");
        b.u32(1); // points count 28..32
        b.u32(1); // transforms count 32..36
        assert_eq!(b.pad(8), 4, "translation.x: 36 -> 40");
        b.f64s(&[1.0, 2.0, 3.0, 0.0, 0.0, 0.0, 1.0]); // 40..96
        b.u32(1); // velocities count 96..100
        assert_eq!(b.pad(8), 4, "100 -> 104");
        b.f64s(&[4.0, 0.0, 0.0, 0.0, 0.0, 0.0]); // 104..152
        b.u32(1); // accelerations count 152..156
        assert_eq!(b.pad(8), 4, "156 -> 160");
        b.f64s(&[0.0; 6]); // 160..208
        b.i32(0); // time_from_start.sec 208..212
        b.u32(500_000_000); // 212..216
        assert_eq!(b.body_len(), 216);
        let payload = encode(&msg).expect("encodes");
        assert_eq!(payload, b.0);
        assert_eq!(
            decode::<MultiDOFJointTrajectory>(&payload).expect("decodes"),
            msg
        );
    }

    #[test]
    fn empty_marker_has_every_humble_jazzy_field_on_the_wire() {
        let msg = MarkerArray {
            markers: vec![Marker::default()],
        };
        let mut b = Bytes::new();
        b.u32(1); // markers count 0..4
        b.i32(0); // stamp.sec 4..8
        b.u32(0); // 8..12
        b.string(""); // frame_id 12..17
        b.pad(4); // 17 -> 20
        b.string(""); // ns 20..25
        b.pad(4); // -> 28
        b.i32(0); // id 28..32
        b.i32(0); // type 32..36
        b.i32(0); // action 36..40
        b.f64s(&[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]); // pose 40..96
        b.f64s(&[0.0; 3]); // scale 96..120
        b.0.extend_from_slice(&[0; 16]); // color: 4 float32, 120..136
        b.i32(0); // lifetime.sec
        b.u32(0); // lifetime.nanosec 136..144
        b.0.push(0); // frame_locked 144
        b.pad(4); // -> 148
        b.u32(0); // points 148..152
        b.u32(0); // colors 152..156
        b.string(""); // texture_resource 156..161
        b.pad(4);
        b.i32(0); // texture.header.stamp
        b.u32(0);
        b.string(""); // texture.header.frame_id
        b.pad(4);
        b.string(""); // texture.format
        b.pad(4);
        b.u32(0); // texture.data
        b.u32(0); // uv_coordinates
        b.string(""); // text
        b.pad(4);
        b.string(""); // mesh_resource
        b.pad(4);
        b.string(""); // mesh_file.filename
        b.pad(4);
        b.u32(0); // mesh_file.data
        b.0.push(0); // mesh_use_embedded_materials
        assert_eq!(encode(&msg).expect("encodes"), b.0);
    }

    #[test]
    fn tf_message_and_clock_match_hand_computed_bytes() {
        use crate::msg::rosgraph_msgs::Clock;
        use crate::msg::tf2_msgs::{TFMessage, TransformStamped};
        let msg = TFMessage {
            transforms: vec![TransformStamped {
                header: Header {
                    stamp: Time { sec: 7, nanosec: 9 },
                    frame_id: "map".into(),
                },
                child_frame_id: "base_link".into(),
                transform: Transform {
                    translation: Vector3 {
                        x: 1.0,
                        y: 2.0,
                        z: 3.0,
                    },
                    rotation: Quaternion::from_yaw(0.5),
                },
            }],
        };
        let q = Quaternion::from_yaw(0.5);
        let mut b = Bytes::new();
        b.u32(1); // transforms count    0..4
        b.i32(7); // stamp.sec           4..8
        b.u32(9); // stamp.nanosec       8..12
        b.string("map"); // frame_id     12..20
        b.string("base_link"); // child  20..34
        assert_eq!(b.pad(8), 6, "translation.x is a float64: 34 -> 40");
        b.f64s(&[1.0, 2.0, 3.0, q.x, q.y, q.z, q.w]); // 40..96
        let payload = encode(&msg).expect("encodes");
        assert_eq!(payload, b.0);
        assert_eq!(decode::<TFMessage>(&payload).expect("decodes"), msg);

        let clock = Clock {
            clock: Time {
                sec: 1000,
                nanosec: 20_000_000,
            },
        };
        let mut b = Bytes::new();
        b.i32(1000);
        b.u32(20_000_000);
        assert_eq!(encode(&clock).expect("encodes"), b.0);
    }

    #[test]
    fn another_encapsulation_is_a_typed_error() {
        let err = decode::<Time>(&[0x00, 0x00, 0x00, 0x00, 1, 0, 0, 0, 0, 0, 0, 0])
            .expect_err("big-endian header");
        assert!(err.to_string().contains("CDR_LE"), "{err}");
    }
}
