//! Foxglove messages (JSON) and the schemas of every channel.

use serde_json::{Value, json};
use trust_runlog::{Header, ObstacleKind, StateRecord, StaticShape};

use crate::{Branches, VEHICLE_FRAME, WORLD_FRAME, nanos};

/// Horizontal speed (m/s) below which the heading is held.
const HEADING_MIN_SPEED: f64 = 0.05;

/// Heading (yaw about z, rad) of the horizontal velocity `v`, or `previous` when slower than
/// 5 cm/s.
pub(crate) fn heading(v: &[f64; 3], previous: f64) -> f64 {
    if v[0].hypot(v[1]) >= HEADING_MIN_SPEED {
        v[1].atan2(v[0])
    } else {
        previous
    }
}

fn time(t: f64) -> Value {
    let ns = nanos(t);
    json!({"sec": ns / 1_000_000_000, "nsec": ns % 1_000_000_000})
}

fn vec3(p: [f64; 3]) -> Value {
    json!({"x": p[0], "y": p[1], "z": p[2]})
}

fn yaw_quat(yaw: f64) -> Value {
    let (s, c) = (0.5 * yaw).sin_cos();
    json!({"x": 0.0, "y": 0.0, "z": s, "w": c})
}

fn pose(p: [f64; 3], yaw: f64) -> Value {
    json!({"position": vec3(p), "orientation": yaw_quat(yaw)})
}

fn color(r: f64, g: f64, b: f64, a: f64) -> Value {
    json!({"r": r, "g": g, "b": b, "a": a})
}

/// A scene entity with every list present (empty unless given).
fn entity(t: f64, id: &str, lists: &[(&str, Vec<Value>)]) -> Value {
    let mut e = json!({
        "timestamp": time(t),
        "frame_id": WORLD_FRAME,
        "id": id,
        "lifetime": {"sec": 0, "nsec": 0},
        "frame_locked": false,
        "metadata": [],
        "arrows": [], "cubes": [], "spheres": [], "cylinders": [],
        "lines": [], "triangles": [], "texts": [], "models": [],
    });
    for (name, items) in lists {
        e[*name] = Value::Array(items.clone());
    }
    e
}

fn update(entities: Vec<Value>) -> Value {
    json!({"deletions": [], "entities": entities})
}

fn cube(center: [f64; 3], size: [f64; 3], c: Value) -> Value {
    json!({"pose": pose(center, 0.0), "size": vec3(size), "color": c})
}

fn sphere(center: [f64; 3], radius: f64, c: Value) -> Value {
    let d = 2.0 * radius;
    json!({"pose": pose(center, 0.0), "size": vec3([d, d, d]), "color": c})
}

fn cylinder(center: [f64; 3], radius: f64, height: f64, c: Value) -> Value {
    let d = 2.0 * radius;
    json!({"pose": pose(center, 0.0), "size": vec3([d, d, height]),
           "bottom_scale": 1.0, "top_scale": 1.0, "color": c})
}

/// A line primitive: `kind` 0 = strip, 2 = list; points rounded to the millimetre.
fn line(kind: u8, points: &[[f64; 3]], thickness: f64, c: Value) -> Value {
    json!({
        "type": kind,
        "pose": pose([0.0; 3], 0.0),
        "thickness": thickness,
        "scale_invariant": true,
        "points": points.iter().map(|p| vec3([mm(p[0]), mm(p[1]), mm(p[2])])).collect::<Vec<_>>(),
        "color": c,
        "colors": [],
        "indices": [],
    })
}

/// `/vehicle/pose`.
pub(crate) fn pose_in_frame(s: &StateRecord, yaw: f64) -> Value {
    json!({"timestamp": time(s.t), "frame_id": WORLD_FRAME, "pose": pose(s.p, yaw)})
}

/// `/tf`.
pub(crate) fn frame_transform(s: &StateRecord, yaw: f64) -> Value {
    json!({
        "timestamp": time(s.t),
        "parent_frame_id": WORLD_FRAME,
        "child_frame_id": VEHICLE_FRAME,
        "translation": vec3(s.p),
        "rotation": yaw_quat(yaw),
    })
}

/// A coordinate rounded to the millimetre (obstacles, paths and branches are the bulk of the
/// file; a millimetre is far below what a viewer draws).
fn mm(x: f64) -> f64 {
    (x * 1e3).round() / 1e3
}

/// `/scene/obstacles`: every moving obstacle at its true centre with its true shape (both to the
/// millimetre); one entity per shape kind, its primitives in id order.
pub(crate) fn obstacles_update(h: &Header, s: &StateRecord) -> Value {
    let red = || color(0.9, 0.25, 0.2, 0.8);
    let (mut spheres, mut cylinders, mut cubes) = (Vec::new(), Vec::new(), Vec::new());
    for (o, c) in h.obstacles.iter().zip(&s.obstacles) {
        let c = [mm(c[0]), mm(c[1]), mm(c[2])];
        match o.shape {
            ObstacleKind::Sphere => spheres.push(sphere(c, mm(o.radius), red())),
            ObstacleKind::Cylinder => {
                let height = 2.0 * o.half_height.unwrap_or(0.0);
                cylinders.push(cylinder(c, mm(o.radius), mm(height), red()));
            }
            ObstacleKind::Box => {
                let e = o.half_extents.unwrap_or([0.0; 3]);
                cubes.push(cube(
                    c,
                    [mm(2.0 * e[0]), mm(2.0 * e[1]), mm(2.0 * e[2])],
                    red(),
                ));
            }
        }
    }
    let entities = [
        ("obstacles:spheres", "spheres", spheres),
        ("obstacles:cylinders", "cylinders", cylinders),
        ("obstacles:boxes", "cubes", cubes),
    ]
    .into_iter()
    .filter(|(_, _, items)| !items.is_empty())
    .map(|(id, list, items)| entity(s.t, id, &[(list, items)]))
    .collect();
    update(entities)
}

/// `/scene/map`: static shapes, bounds, start and goal.
pub(crate) fn map_update(h: &Header, t: f64) -> Value {
    let grey = || color(0.55, 0.57, 0.6, 0.9);
    let (mut cubes, mut spheres, mut cylinders) = (Vec::new(), Vec::new(), Vec::new());
    for s in &h.static_shapes {
        match *s {
            StaticShape::Sphere { center, radius } => spheres.push(sphere(center, radius, grey())),
            StaticShape::Cylinder {
                center,
                radius,
                z_min,
                z_max,
            } => cylinders.push(cylinder(
                [center[0], center[1], 0.5 * (z_min + z_max)],
                radius,
                z_max - z_min,
                grey(),
            )),
            StaticShape::Box { min, max } => cubes.push(cube(
                [
                    0.5 * (min[0] + max[0]),
                    0.5 * (min[1] + max[1]),
                    0.5 * (min[2] + max[2]),
                ],
                [max[0] - min[0], max[1] - min[1], max[2] - min[2]],
                grey(),
            )),
        }
    }
    let (lo, hi) = (h.bounds.min, h.bounds.max);
    let corner = |i: usize| {
        [
            if i & 1 == 0 { lo[0] } else { hi[0] },
            if i & 2 == 0 { lo[1] } else { hi[1] },
            if i & 4 == 0 { lo[2] } else { hi[2] },
        ]
    };
    // The 12 edges of the bounds: corners that differ in one bit.
    let mut edges = Vec::new();
    for i in 0..8usize {
        for bit in [1, 2, 4] {
            if i & bit == 0 {
                edges.push(corner(i));
                edges.push(corner(i | bit));
            }
        }
    }
    let marker = |p, c| sphere(p, h.goal_tolerance.max(0.05), c);
    update(vec![
        entity(
            t,
            "static",
            &[
                ("cubes", cubes),
                ("spheres", spheres),
                ("cylinders", cylinders),
            ],
        ),
        entity(
            t,
            "bounds",
            &[(
                "lines",
                vec![line(2, &edges, 2.0, color(0.3, 0.3, 0.3, 1.0))],
            )],
        ),
        entity(
            t,
            "start_goal",
            &[(
                "spheres",
                vec![
                    marker(h.start, color(0.2, 0.5, 0.95, 0.6)),
                    marker(h.goal, color(0.15, 0.75, 0.3, 0.6)),
                ],
            )],
        ),
    ])
}

/// `/scene/path`: segment `n` of the flown path (a new entity, kept by the viewer) and the whole
/// path so far, coarse (entity `flown_path`, replaced).
pub(crate) fn path_update(t: f64, n: u64, segment: &[[f64; 3]], coarse: &[[f64; 3]]) -> Value {
    let blue = || color(0.1, 0.35, 0.9, 1.0);
    update(vec![
        entity(
            t,
            &format!("path:{n}"),
            &[("lines", vec![line(0, segment, 3.0, blue())])],
        ),
        entity(
            t,
            "flown_path",
            &[(
                "lines",
                vec![line(0, coarse, 2.0, color(0.1, 0.35, 0.9, 0.5))],
            )],
        ),
    ])
}

/// `/scene/branches`: the cycle's branches, main first in a strong colour, the others faint.
pub(crate) fn branches_update(b: &Branches) -> Value {
    let lines = b
        .polylines
        .iter()
        .enumerate()
        .map(|(k, points)| {
            if k == 0 && b.has_main {
                line(0, points, 4.0, color(0.95, 0.55, 0.05, 1.0))
            } else {
                line(0, points, 1.5, color(0.5, 0.5, 0.5, 0.6))
            }
        })
        .collect();
    // One entity replaced every cycle (same id): the view shows the current cycle's branches.
    update(vec![entity(b.t, "branches", &[("lines", lines)])])
}

// --- schemas -------------------------------------------------------------------------------

fn object(properties: Value) -> Value {
    json!({"type": "object", "properties": properties})
}

fn number() -> Value {
    json!({"type": "number"})
}

fn schema_time() -> Value {
    object(json!({"sec": {"type": "integer", "minimum": 0},
                  "nsec": {"type": "integer", "minimum": 0, "maximum": 999_999_999}}))
}

fn schema_vec3() -> Value {
    object(json!({"x": number(), "y": number(), "z": number()}))
}

fn schema_quat() -> Value {
    object(json!({"x": number(), "y": number(), "z": number(), "w": number()}))
}

fn schema_pose() -> Value {
    object(json!({"position": schema_vec3(), "orientation": schema_quat()}))
}

fn schema_color() -> Value {
    object(json!({"r": number(), "g": number(), "b": number(), "a": number()}))
}

fn array(items: Value) -> Value {
    json!({"type": "array", "items": items})
}

fn schema_entity() -> Value {
    let shaped = |extra: Value| {
        let mut o = json!({"pose": schema_pose(), "size": schema_vec3(), "color": schema_color()});
        if let (Some(m), Some(x)) = (o.as_object_mut(), extra.as_object()) {
            m.extend(x.clone());
        }
        object(o)
    };
    let line = object(json!({
        "type": {"type": "integer", "enum": [0, 1, 2]},
        "pose": schema_pose(),
        "thickness": number(),
        "scale_invariant": {"type": "boolean"},
        "points": array(schema_vec3()),
        "color": schema_color(),
        "colors": array(schema_color()),
        "indices": array(json!({"type": "integer", "minimum": 0})),
    }));
    let any = || array(json!({"type": "object"}));
    object(json!({
        "timestamp": schema_time(),
        "frame_id": {"type": "string"},
        "id": {"type": "string"},
        "lifetime": schema_time(),
        "frame_locked": {"type": "boolean"},
        "metadata": array(object(json!({"key": {"type": "string"}, "value": {"type": "string"}}))),
        "arrows": any(),
        "cubes": array(shaped(json!({}))),
        "spheres": array(shaped(json!({}))),
        "cylinders": array(shaped(json!({"bottom_scale": number(), "top_scale": number()}))),
        "lines": array(line),
        "triangles": any(),
        "texts": any(),
        "models": any(),
    }))
}

fn titled(title: &str, mut schema: Value) -> String {
    schema["title"] = Value::from(title);
    schema["$schema"] = Value::from("https://json-schema.org/draft/2020-12/schema");
    serde_json::to_string(&schema).expect("JSON values serialize")
}

/// The JSON schema (`jsonschema` encoding) of a Foxglove message we write
/// (`foxglove.SceneUpdate`, `foxglove.PoseInFrame`, `foxglove.FrameTransform`); `None` for
/// another name. Written from the field lists of Foxglove's message reference, with the fields
/// we send.
pub fn foxglove_schema(name: &str) -> Option<String> {
    let schema = match name {
        "foxglove.SceneUpdate" => object(json!({
            "deletions": array(object(json!({
                "timestamp": schema_time(),
                "type": {"type": "integer", "enum": [0, 1]},
                "id": {"type": "string"},
            }))),
            "entities": array(schema_entity()),
        })),
        "foxglove.PoseInFrame" => object(json!({
            "timestamp": schema_time(),
            "frame_id": {"type": "string"},
            "pose": schema_pose(),
        })),
        "foxglove.FrameTransform" => object(json!({
            "timestamp": schema_time(),
            "parent_frame_id": {"type": "string"},
            "child_frame_id": {"type": "string"},
            "translation": schema_vec3(),
            "rotation": schema_quat(),
        })),
        _ => return None,
    };
    Some(titled(name, schema))
}

const SEPARATOR: &str =
    "================================================================================\n";

const TIME: &str = "int32 sec\nuint32 nanosec\n";
const HEADER: &str = "builtin_interfaces/Time stamp\nstring frame_id\n";
const POSE: &str = "Point position\nQuaternion orientation\n";
const POINT: &str = "float64 x\nfloat64 y\nfloat64 z\n";
const QUATERNION: &str = "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n";

fn with_dependencies(main: &str, deps: &[(&str, &str)]) -> String {
    let mut s = main.to_string();
    for (name, text) in deps {
        s.push_str(SEPARATOR);
        s.push_str(&format!("MSG: {name}\n"));
        s.push_str(text);
    }
    s
}

/// The `ros2msg` definition of a ROS 2 message we write (`geometry_msgs/msg/PoseStamped`,
/// `nav_msgs/msg/Path`), with its dependencies concatenated as `ros2 bag` stores them; `None`
/// for another name.
pub fn ros2_schema(name: &str) -> Option<String> {
    let pose_stamped_deps = [
        ("std_msgs/Header", HEADER),
        ("builtin_interfaces/Time", TIME),
        ("geometry_msgs/Pose", POSE),
        ("geometry_msgs/Point", POINT),
        ("geometry_msgs/Quaternion", QUATERNION),
    ];
    match name {
        "geometry_msgs/msg/PoseStamped" => Some(with_dependencies(
            "std_msgs/Header header\ngeometry_msgs/Pose pose\n",
            &pose_stamped_deps,
        )),
        "nav_msgs/msg/Path" => {
            let mut deps = vec![(
                "geometry_msgs/PoseStamped",
                "std_msgs/Header header\nPose pose\n",
            )];
            deps.extend(pose_stamped_deps);
            Some(with_dependencies(
                "std_msgs/Header header\ngeometry_msgs/PoseStamped[] poses\n",
                &deps,
            ))
        }
        _ => None,
    }
}
