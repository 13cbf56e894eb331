//! `sensor_msgs/PointCloud2` ↔ points, as free functions: [`decode_points`] reads the `x`, `y`,
//! `z` fields of any layout (`FLOAT32` or `FLOAT64` each, at their `offset`s, any `point_step`
//! and `row_step`, `height` > 1 organized clouds, either byte order), skipping points with a
//! NaN or infinite coordinate (an organized depth cloud marks "no return" with NaN);
//! [`encode_points`] writes points in a [`CloudLayout`] (for tests, benches and
//! `trust-sim dds-world`).
//!
//! A malformed cloud (data shorter than `row_step * height`, a row shorter than `width *
//! point_step`, a field `x`, `y` or `z` missing, of another datatype, or past the end of its
//! point) is a [`Ros2Error::Invalid`] naming the field, never a panic. Layout rules: the
//! message's own comments in `sensor_msgs/msg/PointCloud2.msg` and `PointField.msg` (ROS 2
//! `common_interfaces`, Humble/Jazzy).

use trust_core::Vec3;

use crate::error::Ros2Error;
use crate::msg::sensor_msgs::{PointCloud2, PointField};
use crate::msg::std_msgs::Header;

/// The finite points of a cloud, in its frame, row by row.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CloudPoints {
    /// Points whose three coordinates are finite, in the cloud's order.
    pub points: Vec<Vec3>,
    /// Points skipped for a NaN or infinite coordinate.
    pub skipped_count: usize,
}

/// Where one coordinate lies in a point.
#[derive(Debug, Clone, Copy)]
struct Axis {
    offset: usize,
    float64: bool,
}

/// The `x`, `y` or `z` field of `msg`, checked: present, `FLOAT32` or `FLOAT64`, at least one
/// element, within `point_step`.
fn axis(msg: &PointCloud2, name: &str) -> Result<Axis, Ros2Error> {
    let Some((i, f)) = msg.fields.iter().enumerate().find(|(_, f)| f.name == name) else {
        let names: Vec<&str> = msg.fields.iter().map(|f| f.name.as_str()).collect();
        return Err(Ros2Error::invalid(
            "cloud.fields",
            format!("{names:?}"),
            format!("a field named {name:?} (x, y and z are needed)"),
        ));
    };
    let field = |what: &str| format!("cloud.fields[{i}] ({name}).{what}");
    let float64 = match f.datatype {
        PointField::FLOAT32 => false,
        PointField::FLOAT64 => true,
        other => {
            return Err(Ros2Error::invalid(
                field("datatype"),
                other,
                "FLOAT32 (7) or FLOAT64 (8)",
            ));
        }
    };
    if f.count == 0 {
        return Err(Ros2Error::invalid(
            field("count"),
            0,
            "at least one element",
        ));
    }
    let size = if float64 { 8 } else { 4 };
    let offset = f.offset as usize;
    if offset + size > msg.point_step as usize {
        return Err(Ros2Error::invalid(
            field("offset"),
            f.offset,
            format!(
                "a field of {size} bytes within point_step = {} bytes",
                msg.point_step
            ),
        ));
    }
    Ok(Axis { offset, float64 })
}

/// Reads one coordinate at `bytes[at..]` (in bounds: checked by the caller).
fn read(bytes: &[u8], at: usize, axis: Axis, big_endian: bool) -> f64 {
    let at = at + axis.offset;
    if axis.float64 {
        let mut b = [0u8; 8];
        b.copy_from_slice(&bytes[at..at + 8]);
        if big_endian {
            f64::from_be_bytes(b)
        } else {
            f64::from_le_bytes(b)
        }
    } else {
        let mut b = [0u8; 4];
        b.copy_from_slice(&bytes[at..at + 4]);
        f64::from(if big_endian {
            f32::from_be_bytes(b)
        } else {
            f32::from_le_bytes(b)
        })
    }
}

/// The points of `msg` with finite coordinates (module docs), in its frame.
///
/// # Errors
/// [`Ros2Error::Invalid`] naming the field: `x`, `y` or `z` missing, of a datatype other than
/// `FLOAT32`/`FLOAT64`, of count 0 or past `point_step`; `row_step < width * point_step`; `data`
/// shorter than `row_step * height` (sizes that overflow count as too short).
pub fn decode_points(msg: &PointCloud2) -> Result<CloudPoints, Ros2Error> {
    let (width, height) = (msg.width as usize, msg.height as usize);
    if width == 0 || height == 0 {
        return Ok(CloudPoints::default());
    }
    let axes = [axis(msg, "x")?, axis(msg, "y")?, axis(msg, "z")?];
    let (point_step, row_step) = (msg.point_step as usize, msg.row_step as usize);
    let row_bytes = width.checked_mul(point_step);
    if row_bytes.is_none_or(|b| row_step < b) {
        return Err(Ros2Error::invalid(
            "cloud.row_step",
            msg.row_step,
            format!("at least width * point_step = {width} * {point_step}"),
        ));
    }
    let needed = row_step.checked_mul(height);
    if needed.is_none_or(|n| msg.data.len() < n) {
        return Err(Ros2Error::invalid(
            "cloud.data",
            format!("{} bytes", msg.data.len()),
            format!("row_step * height = {row_step} * {height} bytes"),
        ));
    }
    let mut out = CloudPoints {
        points: Vec::with_capacity(width * height),
        skipped_count: 0,
    };
    for row in 0..height {
        for col in 0..width {
            let at = row * row_step + col * point_step;
            let [x, y, z] = axes.map(|a| read(&msg.data, at, a, msg.is_bigendian));
            if x.is_finite() && y.is_finite() && z.is_finite() {
                out.points.push(Vec3::new(x, y, z));
            } else {
                out.skipped_count += 1;
            }
        }
    }
    Ok(out)
}

/// How [`encode_points`] lays points out.
#[derive(Debug, Clone, PartialEq)]
pub struct CloudLayout {
    /// `FLOAT32` or `FLOAT64`, for x, y, z.
    pub datatypes: [u8; 3],
    /// Byte offsets of x, y, z in a point.
    pub offsets: [u32; 3],
    /// Bytes per point.
    pub point_step: u32,
    /// Bytes after each row's points (`row_step = width * point_step + row_padding`).
    pub row_padding: u32,
    /// Rows: the points are `height` rows of `len / height`.
    pub height: u32,
    /// Big-endian coordinates.
    pub is_bigendian: bool,
    /// Further fields declared (their bytes are left zero), e.g. an `intensity`.
    pub extra_fields: Vec<PointField>,
}

impl Default for CloudLayout {
    /// PCL's `PointXYZ`: three `FLOAT32` at 0, 4, 8, 16 bytes a point (aligned), one row,
    /// little-endian.
    fn default() -> Self {
        CloudLayout {
            datatypes: [PointField::FLOAT32; 3],
            offsets: [0, 4, 8],
            point_step: 16,
            row_padding: 0,
            height: 1,
            is_bigendian: false,
            extra_fields: Vec::new(),
        }
    }
}

/// `points` (NaN allowed: an organized cloud's invalid points) as a `PointCloud2` in
/// `layout`, stamped and framed by `header`; `is_dense` is true when every point is finite.
///
/// # Errors
/// [`Ros2Error::Invalid`] for a layout whose axes are not `FLOAT32`/`FLOAT64`, overlap or
/// leave the point, a `height` of 0 or not dividing the number of points, or sizes over
/// `u32`.
pub fn encode_points(
    header: Header,
    points: &[Vec3],
    layout: &CloudLayout,
) -> Result<PointCloud2, Ros2Error> {
    let sizes = layout
        .datatypes
        .iter()
        .enumerate()
        .map(|(i, &d)| match d {
            PointField::FLOAT32 => Ok(4usize),
            PointField::FLOAT64 => Ok(8),
            other => Err(Ros2Error::invalid(
                format!("layout.datatypes[{i}]"),
                other,
                "FLOAT32 (7) or FLOAT64 (8)",
            )),
        })
        .collect::<Result<Vec<_>, _>>()?;
    let spans: Vec<(usize, usize)> = (0..3)
        .map(|i| {
            (
                layout.offsets[i] as usize,
                layout.offsets[i] as usize + sizes[i],
            )
        })
        .collect();
    for (i, &(a, b)) in spans.iter().enumerate() {
        if b > layout.point_step as usize {
            return Err(Ros2Error::invalid(
                format!("layout.offsets[{i}]"),
                a,
                format!("within point_step = {}", layout.point_step),
            ));
        }
        for &(c, d) in &spans[..i] {
            if a < d && c < b {
                return Err(Ros2Error::invalid(
                    format!("layout.offsets[{i}]"),
                    a,
                    "an axis not overlapping another",
                ));
            }
        }
    }
    let height = layout.height as usize;
    if height == 0 || !points.len().is_multiple_of(height) {
        return Err(Ros2Error::invalid(
            "layout.height",
            layout.height,
            format!("a row count > 0 dividing {} points", points.len()),
        ));
    }
    let width = points.len() / height;
    let too_big = |what: &str| Ros2Error::invalid(what, "too large", "a size within u32");
    let row_step = u32::try_from(width)
        .ok()
        .and_then(|w| w.checked_mul(layout.point_step))
        .and_then(|r| r.checked_add(layout.row_padding))
        .ok_or_else(|| too_big("row_step"))?;
    let total = (row_step as usize)
        .checked_mul(height)
        .ok_or_else(|| too_big("data"))?;
    let mut data = vec![0u8; total];
    for (k, p) in points.iter().enumerate() {
        let at = (k / width) * row_step as usize + (k % width) * layout.point_step as usize;
        for (i, v) in [p.x, p.y, p.z].into_iter().enumerate() {
            let o = at + spans[i].0;
            match (sizes[i], layout.is_bigendian) {
                (8, false) => data[o..o + 8].copy_from_slice(&v.to_le_bytes()),
                (8, true) => data[o..o + 8].copy_from_slice(&v.to_be_bytes()),
                (_, false) => data[o..o + 4].copy_from_slice(&(v as f32).to_le_bytes()),
                (_, true) => data[o..o + 4].copy_from_slice(&(v as f32).to_be_bytes()),
            }
        }
    }
    let mut fields: Vec<PointField> = ["x", "y", "z"]
        .iter()
        .enumerate()
        .map(|(i, name)| PointField {
            name: (*name).into(),
            offset: layout.offsets[i],
            datatype: layout.datatypes[i],
            count: 1,
        })
        .collect();
    fields.extend(layout.extra_fields.iter().cloned());
    Ok(PointCloud2 {
        header,
        height: layout.height,
        width: u32::try_from(width).map_err(|_| too_big("width"))?,
        fields,
        is_bigendian: layout.is_bigendian,
        point_step: layout.point_step,
        row_step,
        data,
        is_dense: points.iter().all(|p| p.iter().all(|c| c.is_finite())),
    })
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;

    fn header() -> Header {
        Header {
            frame_id: "map".into(),
            ..Header::default()
        }
    }

    /// A coordinate as the layout stores it.
    fn stored(v: f64, datatype: u8) -> f64 {
        if datatype == PointField::FLOAT32 {
            f64::from(v as f32)
        } else {
            v
        }
    }

    /// A random layout: each axis FLOAT32 or FLOAT64, the axes in a random order with gaps,
    /// an `intensity` field somewhere, padding after the point and the row, 1–3 rows, either
    /// byte order.
    fn layout() -> impl Strategy<Value = CloudLayout> {
        (
            prop::array::uniform3(prop::bool::ANY),
            Just([0usize, 1, 2]).prop_shuffle(),
            prop::array::uniform3(0u32..6),
            0u32..9,
            0u32..13,
            1u32..4,
            prop::bool::ANY,
        )
            .prop_map(|(f64s, order, gaps, tail, row_padding, height, big)| {
                let datatypes = f64s.map(|b| {
                    if b {
                        PointField::FLOAT64
                    } else {
                        PointField::FLOAT32
                    }
                });
                let mut offsets = [0u32; 3];
                let mut at = 4; // an intensity first
                for (k, &axis) in order.iter().enumerate() {
                    at += gaps[k];
                    offsets[axis] = at;
                    at += if f64s[axis] { 8 } else { 4 };
                }
                CloudLayout {
                    datatypes,
                    offsets,
                    point_step: at + tail,
                    row_padding,
                    height,
                    is_bigendian: big,
                    extra_fields: vec![PointField {
                        name: "intensity".into(),
                        offset: 0,
                        datatype: PointField::FLOAT32,
                        count: 1,
                    }],
                }
            })
    }

    /// A coordinate: finite (bounded) or, now and then, NaN or ±∞.
    fn coordinate() -> impl Strategy<Value = f64> {
        prop_oneof![
            8 => -500.0..500.0f64,
            1 => Just(f64::NAN),
            1 => prop_oneof![Just(f64::INFINITY), Just(f64::NEG_INFINITY)],
        ]
    }

    proptest! {
        #[test]
        fn random_clouds_decode_to_the_points_encoded(
            layout in layout(),
            raw in prop::collection::vec(prop::array::uniform3(coordinate()), 0..40),
        ) {
            // Whole rows only.
            let n = raw.len() - raw.len() % layout.height as usize;
            let points: Vec<Vec3> = raw[..n].iter().map(|c| Vec3::new(c[0], c[1], c[2])).collect();
            let msg = encode_points(header(), &points, &layout).expect("a valid layout");
            let decoded = decode_points(&msg).expect("decodes");
            let expected: Vec<Vec3> = points
                .iter()
                .filter(|p| p.iter().all(|c| c.is_finite()))
                .map(|p| Vec3::new(
                    stored(p.x, layout.datatypes[0]),
                    stored(p.y, layout.datatypes[1]),
                    stored(p.z, layout.datatypes[2]),
                ))
                .collect();
            prop_assert_eq!(decoded.skipped_count, points.len() - expected.len());
            prop_assert_eq!(decoded.points, expected);
            // Through CDR as well: the message survives the wire.
            let wire = crate::cdr::encode(&msg).expect("encodes");
            prop_assert_eq!(crate::cdr::decode::<PointCloud2>(&wire).expect("decodes"), msg);
        }
    }

    /// Any header values over a short data buffer: mostly malformed.
    fn arbitrary_cloud() -> impl Strategy<Value = PointCloud2> {
        let field = (
            prop_oneof![Just("x"), Just("y"), Just("z"), Just("rgb")],
            prop_oneof![0u32..40, Just(u32::MAX - 3)],
            0u8..10,
            0u32..3,
        )
            .prop_map(|(name, offset, datatype, count)| PointField {
                name: name.into(),
                offset,
                datatype,
                count,
            });
        (
            prop_oneof![0u32..5, Just(u32::MAX)],
            prop_oneof![0u32..5, Just(u32::MAX)],
            prop::collection::vec(field, 0..6),
            prop::bool::ANY,
            prop_oneof![0u32..40, Just(u32::MAX)],
            prop_oneof![0u32..200, Just(u32::MAX)],
            prop::collection::vec(prop::num::u8::ANY, 0..300),
        )
            .prop_map(
                |(height, width, fields, is_bigendian, point_step, row_step, data)| PointCloud2 {
                    header: header(),
                    height,
                    width,
                    fields,
                    is_bigendian,
                    point_step,
                    row_step,
                    data,
                    is_dense: false,
                },
            )
    }

    proptest! {
        #[test]
        fn any_cloud_decodes_or_is_a_typed_error_never_a_panic(msg in arbitrary_cloud()) {
            match decode_points(&msg) {
                Ok(d) => {
                    prop_assert!(d.points.iter().all(|p| p.iter().all(|c| c.is_finite())));
                    prop_assert_eq!(
                        d.points.len() + d.skipped_count,
                        msg.width as usize * msg.height as usize
                    );
                }
                Err(e) => prop_assert!(matches!(e, Ros2Error::Invalid { .. }), "{e}"),
            }
        }
    }

    fn field_of(e: &Ros2Error) -> String {
        match e {
            Ros2Error::Invalid { field, .. } => field.clone(),
            other => panic!("not an Invalid: {other}"),
        }
    }

    fn cloud() -> PointCloud2 {
        let points = [Vec3::new(1.0, 2.0, 3.0), Vec3::new(-1.0, 0.5, 4.0)];
        encode_points(header(), &points, &CloudLayout::default()).expect("valid")
    }

    #[test]
    fn hand_laid_big_endian_float64_organized_cloud_decodes() {
        // 2 rows × 1 point, x y z FLOAT64 big-endian at 8, 16, 0, point_step 24, row_step 28.
        let mut data = Vec::new();
        for (x, y, z) in [(1.5, -2.0, 3.25), (f64::NAN, 0.0, 0.0)] {
            data.extend_from_slice(&f64::to_be_bytes(z));
            data.extend_from_slice(&f64::to_be_bytes(x));
            data.extend_from_slice(&f64::to_be_bytes(y));
            data.extend_from_slice(&[0xAA; 4]);
        }
        let f = |name: &str, offset| PointField {
            name: name.into(),
            offset,
            datatype: PointField::FLOAT64,
            count: 1,
        };
        let msg = PointCloud2 {
            header: header(),
            height: 2,
            width: 1,
            fields: vec![f("z", 0), f("x", 8), f("y", 16)],
            is_bigendian: true,
            point_step: 24,
            row_step: 28,
            data,
            is_dense: false,
        };
        let d = decode_points(&msg).expect("valid");
        assert_eq!(d.points, vec![Vec3::new(1.5, -2.0, 3.25)]);
        assert_eq!(d.skipped_count, 1);
    }

    #[test]
    fn malformed_clouds_are_typed_errors_naming_the_field() {
        let mut m = cloud();
        m.data.truncate(m.data.len() - 1);
        let e = decode_points(&m).expect_err("short");
        assert_eq!(field_of(&e), "cloud.data");
        assert!(e.to_string().contains("31 bytes"), "{e}");

        let mut m = cloud();
        m.fields.retain(|f| f.name != "y");
        let e = decode_points(&m).expect_err("no y");
        assert_eq!(field_of(&e), "cloud.fields");
        assert!(e.to_string().contains("\"y\""), "{e}");

        let mut m = cloud();
        m.fields[2].datatype = PointField::UINT16;
        let e = decode_points(&m).expect_err("uint16 z");
        assert_eq!(field_of(&e), "cloud.fields[2] (z).datatype");

        let mut m = cloud();
        m.fields[0].offset = 14;
        assert_eq!(
            field_of(&decode_points(&m).expect_err("past the point")),
            "cloud.fields[0] (x).offset"
        );

        let mut m = cloud();
        m.row_step = 16;
        assert_eq!(
            field_of(&decode_points(&m).expect_err("row too short")),
            "cloud.row_step"
        );

        // Sizes that overflow are too short, not a panic.
        let mut m = cloud();
        m.width = u32::MAX;
        m.height = u32::MAX;
        m.point_step = u32::MAX;
        m.row_step = u32::MAX;
        m.fields[0].offset = 0;
        assert!(decode_points(&m).is_err());

        let mut m = cloud();
        m.fields[1].count = 0;
        assert_eq!(
            field_of(&decode_points(&m).expect_err("count 0")),
            "cloud.fields[1] (y).count"
        );
    }

    #[test]
    fn an_empty_cloud_has_no_points_whatever_its_fields() {
        let m = PointCloud2::default();
        assert_eq!(decode_points(&m).expect("empty"), CloudPoints::default());
    }

    #[test]
    fn bad_layouts_are_refused_by_the_encoder() {
        let p = [Vec3::zeros(); 4];
        let overlapping = CloudLayout {
            offsets: [0, 2, 8],
            ..CloudLayout::default()
        };
        assert!(encode_points(header(), &p, &overlapping).is_err());
        let rows = CloudLayout {
            height: 3,
            ..CloudLayout::default()
        };
        assert!(encode_points(header(), &p, &rows).is_err());
        let ints = CloudLayout {
            datatypes: [PointField::INT32; 3],
            ..CloudLayout::default()
        };
        assert!(encode_points(header(), &p, &ints).is_err());
    }
}
