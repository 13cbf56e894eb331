//! The CDR serialization of the two ROS 2 messages we write, `geometry_msgs/msg/PoseStamped` and
//! `nav_msgs/msg/Path`, as `ros2 bag` stores them: the 4-byte encapsulation header `00 01 00 00`
//! (CDR, little-endian), then the fields in declaration order, each primitive aligned to its own
//! size counted from the end of the header; a string is a `uint32` length that counts its
//! terminating NUL, the bytes and the NUL; a sequence is a `uint32` count and its elements.
//!
//! ```text
//! builtin_interfaces/Time  { int32 sec; uint32 nanosec }
//! std_msgs/Header          { Time stamp; string frame_id }
//! geometry_msgs/Pose       { Point position {x, y, z: float64}; Quaternion orientation {x, y, z, w} }
//! geometry_msgs/PoseStamped{ Header header; Pose pose }
//! nav_msgs/Path            { Header header; PoseStamped[] poses }
//! ```

use crate::WORLD_FRAME;

/// A CDR (little-endian) buffer; offsets for alignment count from the end of the encapsulation
/// header.
#[derive(Debug, Clone)]
pub struct CdrWriter {
    buf: Vec<u8>,
}

impl Default for CdrWriter {
    fn default() -> Self {
        CdrWriter::new()
    }
}

impl CdrWriter {
    /// A buffer holding the encapsulation header (CDR_LE, options 0).
    pub fn new() -> Self {
        CdrWriter {
            buf: vec![0x00, 0x01, 0x00, 0x00],
        }
    }

    fn align(&mut self, n: usize) {
        let offset = self.buf.len() - 4;
        let pad = (n - offset % n) % n;
        self.buf.extend(std::iter::repeat_n(0u8, pad));
    }

    /// An `int32`.
    pub fn i32(&mut self, x: i32) {
        self.align(4);
        self.buf.extend_from_slice(&x.to_le_bytes());
    }

    /// A `uint32`.
    pub fn u32(&mut self, x: u32) {
        self.align(4);
        self.buf.extend_from_slice(&x.to_le_bytes());
    }

    /// A `float64`.
    pub fn f64(&mut self, x: f64) {
        self.align(8);
        self.buf.extend_from_slice(&x.to_le_bytes());
    }

    /// A `string`: length including the NUL, bytes, NUL.
    pub fn string(&mut self, s: &str) {
        let len = u32::try_from(s.len() + 1).unwrap_or(u32::MAX);
        self.u32(len);
        self.buf.extend_from_slice(s.as_bytes());
        self.buf.push(0);
    }

    /// A `builtin_interfaces/Time` of `t` seconds (non-negative, below 2³¹ s).
    pub fn time(&mut self, t: f64) {
        let ns = crate::nanos(t);
        self.i32(i32::try_from(ns / 1_000_000_000).unwrap_or(i32::MAX));
        self.u32((ns % 1_000_000_000) as u32);
    }

    /// A `std_msgs/Header` in [`WORLD_FRAME`].
    pub fn header(&mut self, t: f64) {
        self.time(t);
        self.string(WORLD_FRAME);
    }

    /// A `geometry_msgs/Pose` at `p` with yaw `yaw` (rad) about z.
    pub fn pose(&mut self, p: [f64; 3], yaw: f64) {
        for x in p {
            self.f64(x);
        }
        let (s, c) = (0.5 * yaw).sin_cos();
        for x in [0.0, 0.0, s, c] {
            self.f64(x);
        }
    }

    /// The bytes written.
    pub fn into_bytes(self) -> Vec<u8> {
        self.buf
    }
}

/// A `geometry_msgs/msg/PoseStamped` at time `t` (s) in [`WORLD_FRAME`].
pub fn pose_stamped(t: f64, p: [f64; 3], yaw: f64) -> Vec<u8> {
    let mut w = CdrWriter::new();
    w.header(t);
    w.pose(p, yaw);
    w.into_bytes()
}

/// A `nav_msgs/msg/Path` stamped `t` with one `PoseStamped` per `(time, position, yaw)`.
pub fn path(t: f64, poses: &[(f64, [f64; 3], f64)]) -> Vec<u8> {
    let mut w = CdrWriter::new();
    w.header(t);
    w.u32(u32::try_from(poses.len()).unwrap_or(u32::MAX));
    for (tp, p, yaw) in poses {
        w.header(*tp);
        w.pose(*p, *yaw);
    }
    w.into_bytes()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pose_stamped_has_the_ros2_layout() {
        let b = pose_stamped(1.5, [1.0, 2.0, 3.0], 0.0);
        assert_eq!(&b[..4], &[0, 1, 0, 0], "CDR_LE encapsulation");
        assert_eq!(i32::from_le_bytes(b[4..8].try_into().unwrap()), 1);
        assert_eq!(
            u32::from_le_bytes(b[8..12].try_into().unwrap()),
            500_000_000
        );
        // "world" + NUL = 6 bytes after its length.
        assert_eq!(u32::from_le_bytes(b[12..16].try_into().unwrap()), 6);
        assert_eq!(&b[16..22], b"world\0");
        // Offset 18 from the payload start pads to 24 for the first float64 (byte 28 overall).
        assert_eq!(&b[22..28], &[0; 6]);
        let f = |i: usize| f64::from_le_bytes(b[28 + 8 * i..36 + 8 * i].try_into().unwrap());
        assert_eq!([f(0), f(1), f(2)], [1.0, 2.0, 3.0]);
        assert_eq!([f(3), f(4), f(5), f(6)], [0.0, 0.0, 0.0, 1.0]);
        assert_eq!(b.len(), 28 + 56);
    }

    #[test]
    fn a_path_is_a_header_and_a_sequence_of_poses() {
        let poses = [(0.0, [0.0; 3], 0.0), (0.1, [1.0, 0.0, 0.0], 0.0)];
        let b = path(0.1, &poses);
        // Header: 8 (time) + 4 (length) + 6 ("world\0") = 18; the count aligns to 20.
        assert_eq!(u32::from_le_bytes(b[24..28].try_into().unwrap()), 2);
        // Each PoseStamped: header at offset 24 → 42, pad to 48, 56 bytes of pose → 104; the
        // second starts at 104 (aligned to 4) and ends at 104 + 18 → 122 → 128 → 184.
        assert_eq!(b.len(), 4 + 184);
        let x1 = f64::from_le_bytes(b[4 + 128..4 + 136].try_into().unwrap());
        assert_eq!(x1, 1.0);
    }
}
