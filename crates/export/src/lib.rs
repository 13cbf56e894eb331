//! # trust-export — run logs to MCAP, for Foxglove (or its open fork Lichtblick) and `ros2 bag`
//!
//! [`export_mcap`] turns a run log ([`trust_runlog::RunLog`], schema `trust-sim-log/1`) into an
//! [MCAP](https://mcap.dev) file that replays the flight in 3-D. It knows no simulator type: a log
//! is all it reads, so a log written anywhere can be exported.
//!
//! # Channels
//!
//! | topic | schema (encoding) | message encoding | when |
//! |---|---|---|---|
//! | `/vehicle/pose` | `foxglove.PoseInFrame` (`jsonschema`) | `json` | every state record |
//! | `/tf` | `foxglove.FrameTransform` (`jsonschema`) | `json` | every state record (`world` → `vehicle`) |
//! | `/scene/obstacles` | `foxglove.SceneUpdate` (`jsonschema`) | `json` | every state record: one entity per moving obstacle, a sphere, cylinder or cube primitive of its true size |
//! | `/scene/path` | `foxglove.SceneUpdate` (`jsonschema`) | `json` | every [`PATH_PERIOD_S`] and at the end: the flown path so far as a line strip |
//! | `/scene/map` | `foxglove.SceneUpdate` (`jsonschema`) | `json` | once, at the first state: static shapes, the bounds as a wire box, start and goal |
//! | `/scene/branches` | `foxglove.SceneUpdate` (`jsonschema`) | `json` | once per cycle with branches (only when [`Branches`] are given): one line strip per branch, the main one first and highlighted |
//! | `/ros/vehicle/pose` | `geometry_msgs/msg/PoseStamped` (`ros2msg`) | `cdr` | every state record |
//! | `/ros/vehicle/path` | `nav_msgs/msg/Path` (`ros2msg`) | `cdr` | with `/scene/path` |
//!
//! Frame `world` is the log's frame (metres, z up). Log times become MCAP log and publish times in
//! nanoseconds (`round(t · 1e9)`). The log holds no attitude: a pose's orientation is the heading
//! of the horizontal velocity (a yaw about z, held while the vehicle is slower than 5 cm/s), which
//! is what a viewer needs to show where the vehicle goes. Paths are decimated to at most one point
//! per [`PATH_POINT_SPACING_S`] (plus the newest state), so that a path message stays small.
//!
//! The JSON schemas are written out here from the field lists of Foxglove's message reference
//! (only the fields we send, with their JSON types); the ROS 2 definitions are the standard
//! `.msg` texts with their dependencies in the concatenated form `ros2 bag` writes. The CDR
//! serialization ([`cdr`]) is ours: little-endian with the 4-byte encapsulation header
//! `00 01 00 00` (CDR_LE), each primitive aligned to its size relative to the end of the header.
//!
//! A static point cloud file (`static_points_file`) is not exported; its generating shapes are,
//! when the log has them.
//!
//! Chunks are written uncompressed: the `mcap` crate is built without its default `zstd`/`lz4`
//! features (C libraries), and every MCAP reader reads uncompressed chunks.
//!
//! # Changelog
//!
//! - New (issue 20): `trust-sim export RUN.jsonl --mcap FILE`.
#![warn(missing_docs)]

pub mod cdr;
mod scene;

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use mcap::records::MessageHeader;
use trust_runlog::{RunLog, StateRecord};

pub use scene::{foxglove_schema, ros2_schema};

/// Period (s) of the path messages (`/scene/path`, `/ros/vehicle/path`).
pub const PATH_PERIOD_S: f64 = 0.5;
/// Smallest time (s) between two points of a path message.
pub const PATH_POINT_SPACING_S: f64 = 0.1;
/// The world frame's name.
pub const WORLD_FRAME: &str = "world";
/// The vehicle frame's name (child of [`WORLD_FRAME`] on `/tf`).
pub const VEHICLE_FRAME: &str = "vehicle";

/// The branches the manager held in one cycle, as sampled polylines (main first), for
/// `/scene/branches`. Callers map the cycles' sampled branches onto this type; without branches
/// the file has no branch channel. [`export_file`] (and `trust-sim export`) takes them from the
/// log's cycle records ([`branches_of`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Branches {
    /// Cycle time (s).
    pub t: f64,
    /// Whether the first polyline is the main branch (`false` while braking).
    pub has_main: bool,
    /// One polyline per branch, positions `[x, y, z]` (m), the main branch first.
    pub polylines: Vec<Vec<[f64; 3]>>,
}

/// Why an export failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ExportError {
    /// The run log could not be read (file and line in the message).
    #[error(transparent)]
    Log(#[from] trust_runlog::LogError),
    /// The MCAP file could not be created or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The MCAP file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// The `mcap` writer refused a record.
    #[error("{}: writing MCAP: {message}", path.display())]
    Mcap {
        /// The MCAP file.
        path: PathBuf,
        /// The writer's message.
        message: String,
    },
    /// A value cannot be exported (a non-finite number or a negative time in a log built in
    /// code, or branches out of time order).
    #[error("{field}: {value} — expected {expected}")]
    Input {
        /// What is wrong (`states[3].t`, `branches[2].t`).
        field: String,
        /// The offending value.
        value: String,
        /// What was expected.
        expected: String,
    },
}

/// What an export wrote.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct ExportSummary {
    /// Messages per topic.
    pub message_counts: BTreeMap<String, u64>,
}

/// Reads the run log at `log_path` and writes `mcap_path` (module docs), with the branches its
/// cycle records carry ([`branches_of`]; none when the flight was logged without them).
///
/// # Errors
/// [`ExportError::Log`] naming the log file and line; [`ExportError::Io`] /
/// [`ExportError::Mcap`] naming the MCAP file.
pub fn export_file(log_path: &Path, mcap_path: &Path) -> Result<ExportSummary, ExportError> {
    let log = RunLog::read(log_path)?;
    export_mcap(&log, &branches_of(&log), mcap_path)
}

/// The sampled branches of `log`'s cycle records (`branch_samples`, written when branch logging
/// is on), one [`Branches`] per cycle that carries any, main branch first; empty for a log
/// without them.
pub fn branches_of(log: &RunLog) -> Vec<Branches> {
    log.cycles
        .iter()
        .filter_map(|c| {
            let samples = c.branch_samples.as_ref()?;
            Some(Branches {
                t: c.t,
                has_main: c.main.is_some() && !samples.is_empty(),
                polylines: samples
                    .iter()
                    .map(|b| b.samples.iter().map(|s| [s[1], s[2], s[3]]).collect())
                    .collect(),
            })
        })
        .collect()
}

/// Writes `log` (and `branches`, in cycle order; may be empty) to the MCAP file `path` (module
/// docs for the channels).
///
/// # Errors
/// [`ExportError::Input`] for a non-finite number, a negative time or branches out of order;
/// [`ExportError::Io`] / [`ExportError::Mcap`] naming the file (input errors are found before
/// the file is created; a write error may leave a partial file, which no MCAP reader accepts).
pub fn export_mcap(
    log: &RunLog,
    branches: &[Branches],
    path: &Path,
) -> Result<ExportSummary, ExportError> {
    check(log, branches)?;
    let file = File::create(path).map_err(|source| ExportError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let mcap_err = |e: mcap::McapError| ExportError::Mcap {
        path: path.to_path_buf(),
        message: e.to_string(),
    };
    let options = mcap::WriteOptions::new()
        .compression(None)
        .profile("")
        .library(concat!("trust-export ", env!("CARGO_PKG_VERSION")));
    let mut w = options.create(BufWriter::new(file)).map_err(&mcap_err)?;
    let mut out = Out {
        writer: &mut w,
        channels: BTreeMap::new(),
        counts: BTreeMap::new(),
    };
    let topics: &[(&str, &str)] = &[
        ("/vehicle/pose", "foxglove.PoseInFrame"),
        ("/tf", "foxglove.FrameTransform"),
        ("/scene/map", "foxglove.SceneUpdate"),
        ("/scene/obstacles", "foxglove.SceneUpdate"),
        ("/scene/path", "foxglove.SceneUpdate"),
    ];
    let mut schema_ids = BTreeMap::new();
    for (topic, schema) in topics
        .iter()
        .copied()
        .chain((!branches.is_empty()).then_some(("/scene/branches", "foxglove.SceneUpdate")))
    {
        let id = match schema_ids.get(schema) {
            Some(id) => *id,
            None => {
                let data = foxglove_schema(schema).expect("a schema of ours");
                let id = out
                    .writer
                    .add_schema(schema, "jsonschema", data.as_bytes())
                    .map_err(mcap_err)?;
                schema_ids.insert(schema, id);
                id
            }
        };
        let channel = out
            .writer
            .add_channel(id, topic, "json", &BTreeMap::new())
            .map_err(mcap_err)?;
        out.channels.insert(topic, channel);
    }
    for (topic, schema) in [
        ("/ros/vehicle/pose", "geometry_msgs/msg/PoseStamped"),
        ("/ros/vehicle/path", "nav_msgs/msg/Path"),
    ] {
        let data = ros2_schema(schema).expect("a schema of ours");
        let id = out
            .writer
            .add_schema(schema, "ros2msg", data.as_bytes())
            .map_err(mcap_err)?;
        let channel = out
            .writer
            .add_channel(id, topic, "cdr", &BTreeMap::new())
            .map_err(mcap_err)?;
        out.channels.insert(topic, channel);
    }

    let states = &log.states;
    let t0 = states[0].t;
    out.json("/scene/map", t0, &scene::map_update(&log.header, t0))
        .map_err(mcap_err)?;
    let mut yaw = 0.0;
    let mut next_path_t = t0;
    let mut branch_iter = branches.iter().peekable();
    for (k, s) in states.iter().enumerate() {
        yaw = scene::heading(&s.v, yaw);
        // Branches planned up to this state, in time order with the states.
        while let Some(b) = branch_iter.next_if(|b| b.t <= s.t) {
            out.json("/scene/branches", b.t, &scene::branches_update(b))
                .map_err(mcap_err)?;
        }
        out.json("/vehicle/pose", s.t, &scene::pose_in_frame(s, yaw))
            .map_err(mcap_err)?;
        out.json("/tf", s.t, &scene::frame_transform(s, yaw))
            .map_err(mcap_err)?;
        out.json(
            "/scene/obstacles",
            s.t,
            &scene::obstacles_update(&log.header, s),
        )
        .map_err(mcap_err)?;
        out.cdr("/ros/vehicle/pose", s.t, &cdr::pose_stamped(s.t, s.p, yaw))
            .map_err(mcap_err)?;
        let last = k + 1 == states.len();
        if s.t >= next_path_t - 1e-9 || last {
            let path = decimated_path(&states[..=k]);
            out.json("/scene/path", s.t, &scene::path_update(s.t, &path))
                .map_err(mcap_err)?;
            let poses: Vec<(f64, [f64; 3], f64)> =
                path.iter().map(|(q, yaw)| (q.t, q.p, *yaw)).collect();
            out.cdr("/ros/vehicle/path", s.t, &cdr::path(s.t, &poses))
                .map_err(mcap_err)?;
            // The next multiple of the period after this state (relative to the first state).
            next_path_t = t0 + PATH_PERIOD_S * (((s.t - t0) / PATH_PERIOD_S + 1e-9).floor() + 1.0);
        }
    }
    for b in branch_iter {
        out.json("/scene/branches", b.t, &scene::branches_update(b))
            .map_err(mcap_err)?;
    }
    let counts = std::mem::take(&mut out.counts);
    w.finish().map_err(mcap_err)?;
    w.into_inner()
        .into_inner()
        .map_err(|e| ExportError::Io {
            path: path.to_path_buf(),
            source: e.into_error(),
        })?
        .sync_all()
        .map_err(|source| ExportError::Io {
            path: path.to_path_buf(),
            source,
        })?;
    Ok(ExportSummary {
        message_counts: counts
            .into_iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect(),
    })
}

/// The states of a path message: one per [`PATH_POINT_SPACING_S`], and the newest; each with
/// the heading of its velocity.
fn decimated_path(states: &[StateRecord]) -> Vec<(&StateRecord, f64)> {
    let mut out = Vec::new();
    let mut yaw = 0.0;
    let mut next_t = f64::NEG_INFINITY;
    for (k, s) in states.iter().enumerate() {
        yaw = scene::heading(&s.v, yaw);
        if s.t >= next_t - 1e-9 || k + 1 == states.len() {
            out.push((s, yaw));
            next_t = s.t + PATH_POINT_SPACING_S;
        }
    }
    out
}

/// Rejects what no message can carry: non-finite numbers, negative times, branches out of order.
fn check(log: &RunLog, branches: &[Branches]) -> Result<(), ExportError> {
    let bad = |field: String, value: String, expected: &str| ExportError::Input {
        field,
        value,
        expected: expected.to_string(),
    };
    let finite = |xs: &[f64]| xs.iter().all(|x| x.is_finite());
    if log.states.is_empty() {
        return Err(bad("states".into(), "[]".into(), "at least one state"));
    }
    for (i, s) in log.states.iter().enumerate() {
        if !(s.t.is_finite() && s.t >= 0.0 && s.t <= 1e7) {
            return Err(bad(
                format!("states[{i}].t"),
                s.t.to_string(),
                "a time in [0, 1e7] s",
            ));
        }
        if !finite(&s.p) || !finite(&s.v) || s.obstacles.iter().any(|o| !finite(o)) {
            return Err(bad(
                format!("states[{i}]"),
                format!("t = {}", s.t),
                "finite positions and velocities",
            ));
        }
    }
    let mut previous = f64::NEG_INFINITY;
    for (i, b) in branches.iter().enumerate() {
        if !(b.t.is_finite() && b.t >= 0.0 && b.t <= 1e7 && b.t >= previous) {
            return Err(bad(
                format!("branches[{i}].t"),
                b.t.to_string(),
                "a time in [0, 1e7] s, not before the previous cycle's",
            ));
        }
        previous = b.t;
        if b.polylines.iter().flatten().any(|q| !finite(q)) {
            return Err(bad(
                format!("branches[{i}]"),
                format!("t = {}", b.t),
                "finite branch points",
            ));
        }
    }
    Ok(())
}

/// Nanoseconds of a (checked, non-negative) log time.
pub(crate) fn nanos(t: f64) -> u64 {
    (t * 1e9).round() as u64
}

/// The writer with its channel ids, sequence numbers and counts.
struct Out<'a, W: std::io::Write + std::io::Seek> {
    writer: &'a mut mcap::Writer<W>,
    channels: BTreeMap<&'static str, u16>,
    counts: BTreeMap<&'static str, u64>,
}

impl<W: std::io::Write + std::io::Seek> Out<'_, W> {
    fn raw(&mut self, topic: &'static str, t: f64, data: &[u8]) -> Result<(), mcap::McapError> {
        let channel_id = self.channels[topic];
        let count = self.counts.entry(topic).or_insert(0);
        *count += 1;
        let header = MessageHeader {
            channel_id,
            sequence: u32::try_from(*count).unwrap_or(u32::MAX),
            log_time: nanos(t),
            publish_time: nanos(t),
        };
        self.writer.write_to_known_channel(&header, data)
    }

    fn json(
        &mut self,
        topic: &'static str,
        t: f64,
        value: &serde_json::Value,
    ) -> Result<(), mcap::McapError> {
        let data = serde_json::to_vec(value).expect("JSON values serialize");
        self.raw(topic, t, &data)
    }

    fn cdr(&mut self, topic: &'static str, t: f64, data: &[u8]) -> Result<(), mcap::McapError> {
        self.raw(topic, t, data)
    }
}
