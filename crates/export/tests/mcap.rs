//! The MCAP export read back with the `mcap` crate's reader: channels, schemas, encodings,
//! message counts and the decoded content of a few messages.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use trust_export::{Branches, ExportError, export_file, export_mcap};
use trust_runlog::{
    Bounds, BranchSamples, CycleRecord, Header, LimitsInfo, LogWriter, ObstacleInfo, ObstacleKind,
    Outcome, Record, RunLog, SCHEMA, StateRecord, StaticShape, Status, VehicleInfo,
};

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("trust-export-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A 2 s flight at 50 Hz (101 states) past a sphere, a cylinder and a box.
fn log() -> RunLog {
    let obstacle = |id, shape, radius, half_height, half_extents| ObstacleInfo {
        id,
        shape,
        radius,
        half_height,
        half_extents,
    };
    let header = Header {
        schema: SCHEMA.into(),
        scenario: "export".into(),
        seed: 3,
        planner: "trust".into(),
        bounds: Bounds {
            min: [0.0; 3],
            max: [10.0, 8.0, 3.0],
        },
        vehicle: VehicleInfo {
            radius: 0.1,
            model: None,
        },
        limits: LimitsInfo {
            v_max: 1.0,
            a_max: 3.0,
        },
        start: [1.0, 1.0, 1.0],
        goal: [9.0, 7.0, 1.0],
        goal_tolerance: 0.15,
        static_shapes: vec![
            StaticShape::Box {
                min: [4.0, 0.0, 0.0],
                max: [5.0, 2.0, 3.0],
            },
            StaticShape::Cylinder {
                center: [7.0, 6.0],
                radius: 0.3,
                z_min: 0.0,
                z_max: 3.0,
            },
        ],
        static_points_file: None,
        obstacles: vec![
            obstacle(0, ObstacleKind::Sphere, 0.3, None, None),
            obstacle(1, ObstacleKind::Cylinder, 0.25, Some(0.9), None),
            obstacle(
                2,
                ObstacleKind::Box,
                0.5f64.hypot(0.3),
                None,
                Some([0.5, 0.3, 0.4]),
            ),
        ],
        sim: None,
    };
    let states = (0..=100)
        .map(|k| {
            let t = k as f64 * 0.02;
            StateRecord {
                t,
                p: [1.0 + t, 1.0 + 0.5 * t, 1.0],
                v: [1.0, 0.5, 0.0],
                a: [0.0; 3],
                obstacles: vec![[5.0, 5.0 - t, 1.5], [6.0, 2.0, 0.9], [3.0 + t, 6.0, 1.0]],
            }
        })
        .collect();
    RunLog {
        header,
        states,
        cycles: Vec::new(),
        outcome: Outcome {
            status: Status::TimedOut,
            t: 2.0,
            flight_time_s: 2.0,
            path_length_m: 2.0 * 1.25f64.sqrt(),
            min_clearance_static_m: 1.0,
            min_clearance_dynamic_m: 1.0,
            max_speed: 1.25f64.sqrt(),
            max_accel: 0.0,
            with: None,
            reason: None,
            cycle_count: 0,
            forecast_warning_s: None,
        },
    }
}

struct Read {
    /// topic -> (schema name, schema encoding, message encoding)
    channels: BTreeMap<String, (String, String, String)>,
    counts: BTreeMap<String, u64>,
    messages: Vec<(String, u64, Vec<u8>)>,
}

fn read(path: &Path) -> Read {
    let bytes = std::fs::read(path).unwrap();
    let summary = mcap::Summary::read(&bytes)
        .unwrap()
        .expect("a summary section");
    let mut channels = BTreeMap::new();
    for c in summary.channels.values() {
        let s = c.schema.as_ref().expect("every channel has a schema");
        channels.insert(
            c.topic.clone(),
            (
                s.name.clone(),
                s.encoding.clone(),
                c.message_encoding.clone(),
            ),
        );
    }
    let stats = summary.stats.expect("statistics");
    let mut counts = BTreeMap::new();
    for (id, n) in &stats.channel_message_counts {
        counts.insert(summary.channels[id].topic.clone(), *n);
    }
    let messages = mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(|m| {
            let m = m.unwrap();
            (m.channel.topic.clone(), m.log_time, m.data.into_owned())
        })
        .collect();
    Read {
        channels,
        counts,
        messages,
    }
}

fn json(data: &[u8]) -> serde_json::Value {
    serde_json::from_slice(data).unwrap()
}

#[test]
fn the_export_reads_back_with_the_mcap_reader() {
    let d = dir("read");
    let path = d.join("run.mcap");
    let branches: Vec<Branches> = (0..20)
        .map(|k| Branches {
            t: k as f64 * 0.1,
            has_main: k != 5,
            polylines: vec![
                vec![[1.0, 1.0, 1.0], [2.0, 1.5, 1.0], [3.0, 2.0, 1.0]],
                vec![[1.0, 1.0, 1.0], [2.0, 2.5, 1.2]],
            ],
        })
        .collect();
    let summary = export_mcap(&log(), &branches, &path).unwrap();
    let r = read(&path);

    let fox = |schema: &str| (schema.to_string(), "jsonschema".into(), "json".into());
    let ros = |schema: &str| (schema.to_string(), "ros2msg".into(), "cdr".into());
    let expected: BTreeMap<String, (String, String, String)> = [
        ("/vehicle/pose", fox("foxglove.PoseInFrame")),
        ("/tf", fox("foxglove.FrameTransform")),
        ("/scene/map", fox("foxglove.SceneUpdate")),
        ("/scene/obstacles", fox("foxglove.SceneUpdate")),
        ("/scene/path", fox("foxglove.SceneUpdate")),
        ("/scene/branches", fox("foxglove.SceneUpdate")),
        ("/ros/vehicle/pose", ros("geometry_msgs/msg/PoseStamped")),
        ("/ros/vehicle/path", ros("nav_msgs/msg/Path")),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v))
    .collect();
    assert_eq!(r.channels, expected);

    // 101 states; obstacles every 0.1 s; scene paths at t = 0, 0.5, 1, 1.5, 2 s, ROS paths at
    // 0 s and at the end; one map; 20 cycles of branches.
    let counts: BTreeMap<String, u64> = [
        ("/vehicle/pose", 101),
        ("/tf", 101),
        ("/scene/obstacles", 21),
        ("/ros/vehicle/pose", 101),
        ("/scene/path", 5),
        ("/ros/vehicle/path", 2),
        ("/scene/map", 1),
        ("/scene/branches", 20),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v))
    .collect();
    assert_eq!(r.counts, counts);
    assert_eq!(summary.message_counts, counts);
    assert_eq!(r.messages.len() as u64, counts.values().sum::<u64>());
    // Log times never go backwards in the file.
    assert!(r.messages.windows(2).all(|w| w[0].1 <= w[1].1));

    // Decoded content: the pose at t = 1 s (JSON and CDR), the obstacles' true shapes.
    let at = |topic: &str, ns: u64| {
        r.messages
            .iter()
            .find(|m| m.0 == topic && m.1 == ns)
            .unwrap_or_else(|| panic!("{topic} at {ns} ns"))
            .2
            .clone()
    };
    let pose = json(&at("/vehicle/pose", 1_000_000_000));
    assert_eq!(pose["frame_id"], "world");
    assert_eq!(pose["timestamp"]["sec"], 1);
    assert!((pose["pose"]["position"]["x"].as_f64().unwrap() - 2.0).abs() < 1e-12);
    let yaw = 0.5f64.atan2(1.0);
    assert!((pose["pose"]["orientation"]["z"].as_f64().unwrap() - (0.5 * yaw).sin()).abs() < 1e-12);
    let cdr = at("/ros/vehicle/pose", 1_000_000_000);
    assert_eq!(&cdr[..4], &[0, 1, 0, 0]);
    let f = |i: usize| f64::from_le_bytes(cdr[28 + 8 * i..36 + 8 * i].try_into().unwrap());
    assert_eq!([f(0), f(1), f(2)], [2.0, 1.5, 1.0]);
    // One entity per shape kind.
    let obstacles = json(&at("/scene/obstacles", 0));
    let e = &obstacles["entities"];
    assert_eq!(e[0]["id"], "obstacles:spheres");
    assert_eq!(e[0]["spheres"][0]["size"]["x"], 0.6);
    assert_eq!(e[1]["cylinders"][0]["size"]["z"], 1.8);
    assert_eq!(e[2]["cubes"][0]["size"]["x"], 1.0);
    assert_eq!(e[2]["cubes"][0]["size"]["z"], 0.8);
    let map = json(&at("/scene/map", 0));
    assert_eq!(map["entities"][0]["cubes"].as_array().unwrap().len(), 1);
    assert_eq!(map["entities"][0]["cylinders"].as_array().unwrap().len(), 1);
    assert_eq!(
        map["entities"][1]["lines"][0]["points"]
            .as_array()
            .unwrap()
            .len(),
        24
    );
    // The last scene path: the segment since 1.5 s (one point per 0.1 s, joined to the previous
    // segment) and the whole path, coarse (every 0.1 s while it is this short).
    let last_path = json(&at("/scene/path", 2_000_000_000));
    let line = |k: usize| {
        last_path["entities"][k]["lines"][0]["points"]
            .as_array()
            .unwrap()
            .len()
    };
    assert_eq!(last_path["entities"][0]["id"], "path:4");
    assert_eq!(line(0), 6, "1.5, 1.6, …, 2.0 s");
    assert_eq!(last_path["entities"][1]["id"], "flown_path");
    assert_eq!(line(1), 21, "one point per 0.1 s over 2 s");
    let branches = json(&at("/scene/branches", 500_000_000));
    assert_eq!(
        branches["entities"][0]["lines"].as_array().unwrap().len(),
        2
    );
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn without_branches_there_is_no_branch_channel_and_a_log_file_exports() {
    let d = dir("file");
    let log_path = d.join("run.jsonl");
    let l = log();
    let mut w = LogWriter::create(&log_path).unwrap();
    w.write(&Record::Header(l.header.clone())).unwrap();
    for s in &l.states {
        w.write(&Record::State(s.clone())).unwrap();
    }
    w.write(&Record::Outcome(l.outcome.clone())).unwrap();
    w.finish().unwrap();
    let path = d.join("run.mcap");
    export_file(&log_path, &path).unwrap();
    let r = read(&path);
    assert_eq!(r.channels.len(), 7);
    assert!(!r.channels.contains_key("/scene/branches"));

    // With sampled branches in its cycle records (branch logging on), the file export carries
    // them on /scene/branches.
    let mut with = l.clone();
    with.cycles = (0..3)
        .map(|k| {
            let t = 0.5 * k as f64;
            CycleRecord {
                t,
                wall_ms: 0.0,
                main: Some(1),
                branches: 1,
                events: vec![],
                frontend_ms: 0.0,
                backend_ms: 0.0,
                checker_ms: 0.0,
                solve_count: 1,
                effective_t: t,
                branch_j: vec![1.0],
                fallback_collision_free: None,
                fallback_shortfall_m: None,
                fallback_along: None,
                dropped: Default::default(),
                route: None,
                route_ms: None,
                branch_samples: Some(vec![BranchSamples {
                    id: 1,
                    samples: vec![[t, 1.0, 1.0, 1.0], [t + 1.0, 2.0, 1.5, 1.0]],
                }]),
                forecasts: None,
                charged_ms: None,
                overrun_ticks: None,
                worker_ms: None,
                waited_ms: None,
                map_ms: None,
            }
        })
        .collect();
    let b = trust_export::branches_of(&with);
    assert_eq!(b.len(), 3);
    assert_eq!(b[1].polylines, vec![vec![[1.0, 1.0, 1.0], [2.0, 1.5, 1.0]]]);
    assert!(b[0].has_main);
    let with_path = d.join("with.jsonl");
    let mut w = LogWriter::create(&with_path).unwrap();
    w.write(&Record::Header(with.header.clone())).unwrap();
    let mut cycles = with.cycles.iter().peekable();
    for s in &with.states {
        while let Some(c) = cycles.next_if(|c| c.t <= s.t) {
            w.write(&Record::Cycle(c.clone())).unwrap();
        }
        w.write(&Record::State(s.clone())).unwrap();
    }
    w.write(&Record::Outcome(with.outcome.clone())).unwrap();
    w.finish().unwrap();
    export_file(&with_path, &path).unwrap();
    let r = read(&path);
    assert!(r.channels.contains_key("/scene/branches"));

    // A broken log line is named with its file and line.
    let text = std::fs::read_to_string(&log_path).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    lines[3] = "{\"type\":\"state\",\"t\":0.06,\"p\":[1,2]}";
    std::fs::write(&log_path, lines.join("\n")).unwrap();
    let e = export_file(&log_path, &path).unwrap_err();
    assert!(matches!(e, ExportError::Log(_)), "{e}");
    assert!(e.to_string().contains("run.jsonl:4:"), "{e}");

    // A log built in code with a non-finite position, and branches out of order.
    let mut bad = log();
    bad.states[7].p[1] = f64::NAN;
    let e = export_mcap(&bad, &[], &path).unwrap_err().to_string();
    assert!(e.starts_with("states[7]"), "{e}");
    let branch = |t| Branches {
        t,
        has_main: true,
        polylines: vec![],
    };
    let e = export_mcap(&log(), &[branch(1.0), branch(0.5)], &path)
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("branches[1].t: 0.5"), "{e}");
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn the_ros2_definitions_name_their_dependencies() {
    let path = trust_export::ros2_schema("nav_msgs/msg/Path").unwrap();
    assert!(path.starts_with("std_msgs/Header header\ngeometry_msgs/PoseStamped[] poses\n"));
    for dep in [
        "MSG: geometry_msgs/PoseStamped",
        "MSG: std_msgs/Header",
        "MSG: builtin_interfaces/Time",
        "MSG: geometry_msgs/Pose",
        "MSG: geometry_msgs/Point",
        "MSG: geometry_msgs/Quaternion",
    ] {
        assert!(path.contains(dep), "{dep}");
    }
    for name in [
        "foxglove.SceneUpdate",
        "foxglove.PoseInFrame",
        "foxglove.FrameTransform",
    ] {
        let s: serde_json::Value =
            serde_json::from_str(&trust_export::foxglove_schema(name).unwrap()).unwrap();
        assert_eq!(s["title"], name);
        assert_eq!(s["type"], "object");
    }
    assert!(trust_export::foxglove_schema("foxglove.Grid").is_none());
}

/// A flight of `n` states at 50 Hz with `obstacle_count` spheres, written as a run log.
fn long_log(path: &Path, n: usize, obstacle_count: usize) {
    let mut l = log();
    l.header.obstacles = (0..obstacle_count)
        .map(|id| ObstacleInfo {
            id,
            shape: ObstacleKind::Sphere,
            radius: 0.3,
            half_height: None,
            half_extents: None,
        })
        .collect();
    let mut w = LogWriter::create(path).unwrap();
    w.write(&Record::Header(l.header.clone())).unwrap();
    let mut last = None;
    for k in 0..n {
        let t = k as f64 * 0.02;
        let s = StateRecord {
            t,
            p: [
                5.0 + 4.0 * (0.01 * t).cos(),
                4.0 + 3.0 * (0.01 * t).sin(),
                1.0,
            ],
            v: [-0.04 * (0.01 * t).sin(), 0.03 * (0.01 * t).cos(), 0.0],
            a: [0.0; 3],
            obstacles: (0..obstacle_count)
                .map(|i| [i as f64 * 0.1, 3.0 + (t + i as f64).sin(), 1.0])
                .collect(),
        };
        w.write(&Record::State(s.clone())).unwrap();
        last = Some(s);
    }
    let last = last.unwrap();
    w.write(&Record::Outcome(trust_runlog::Outcome {
        t: last.t,
        flight_time_s: last.t,
        ..l.outcome.clone()
    }))
    .unwrap();
    w.finish().unwrap();
}

#[test]
fn an_mcap_grows_linearly_with_the_flight() {
    // The path messages used to repeat the whole path: 7 500 states gave 30 MB, 30 000 gave
    // 417 MB (quadratic: 4 times the bytes per state for 4 times the states). Now the bytes per
    // state stay nearly flat (the paths' coarse copies fill up to their caps, then stay).
    let d = dir("linear");
    let mut per_state = Vec::new();
    for n in [3_000, 12_000] {
        let log_path = d.join(format!("run{n}.jsonl"));
        long_log(&log_path, n, 2);
        let mcap = d.join(format!("run{n}.mcap"));
        export_file(&log_path, &mcap).unwrap();
        per_state.push(std::fs::metadata(&mcap).unwrap().len() as f64 / n as f64);
    }
    assert!(
        per_state[1] < 1.25 * per_state[0],
        "bytes per state {per_state:?}"
    );
    // A one-hour flight at this rate (2 obstacles): far below 1 GB.
    assert!(per_state[1] * 180_000.0 < 0.3e9, "{per_state:?}");
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn an_export_error_removes_the_partial_file() {
    let d = dir("partial");
    let log_path = d.join("run.jsonl");
    long_log(&log_path, 100, 1);
    let text = std::fs::read_to_string(&log_path).unwrap();
    let mut lines: Vec<&str> = text.lines().collect();
    lines[50] = "{\"type\":\"state\",\"t\":-1}";
    std::fs::write(&log_path, lines.join("\n")).unwrap();
    let mcap = d.join("run.mcap");
    let e = export_file(&log_path, &mcap).unwrap_err();
    assert!(e.to_string().contains("run.jsonl:51:"), "{e}");
    assert!(!mcap.exists());
    std::fs::remove_dir_all(&d).ok();
}
