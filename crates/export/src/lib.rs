//! # trust-export — run logs to MCAP, for Foxglove (or its open fork Lichtblick) and `ros2 bag`
//!
//! [`export_mcap`] turns a run log ([`trust_runlog::RunLog`], schema `trust-sim-log/1`) into an
//! [MCAP](https://mcap.dev) file that replays the flight in 3-D. It knows no simulator type: a log
//! is all it reads, so a log written anywhere can be exported. Use it (`trust-sim export RUN.jsonl
//! --mcap FILE`) to inspect a flight of the paper's experiments (Sec. IV) in a 3-D viewer or to feed
//! ROS 2 tools; the planner itself does not need it.
//!
//! # Channels
//!
//! | topic | schema (encoding) | message encoding | when |
//! |---|---|---|---|
//! | `/vehicle/pose` | `foxglove.PoseInFrame` (`jsonschema`) | `json` | every state record |
//! | `/tf` | `foxglove.FrameTransform` (`jsonschema`) | `json` | every state record (`world` → `vehicle`) |
//! | `/scene/obstacles` | `foxglove.SceneUpdate` (`jsonschema`) | `json` | every [`obstacle_period_s`] (0.1 s up to 50 obstacles, 0.2 s up to 100, …) and at the last state: one entity per shape kind (`obstacles:spheres`, `obstacles:cylinders`, `obstacles:boxes`) holding one primitive of true size per moving obstacle, in id order, centres rounded to the millimetre |
//! | `/scene/path` | `foxglove.SceneUpdate` (`jsonschema`) | `json` | every [`PATH_PERIOD_S`] and at the end: the path flown since the previous message as a new entity `path:<n>` (one point per [`PATH_POINT_SPACING_S`], joined to the previous segment), and the entity `flown_path`, the whole path so far coarsened to at most [`MAX_COARSE_PATH_POINTS`] points |
//! | `/scene/map` | `foxglove.SceneUpdate` (`jsonschema`) | `json` | once, at the first state: static shapes, the bounds as a wire box, start and goal |
//! | `/scene/branches` | `foxglove.SceneUpdate` (`jsonschema`) | `json` | once per cycle with branches (only when there are [`Branches`]; the channel is added with the first): one line strip per branch, the main one first and highlighted |
//! | `/ros/vehicle/pose` | `geometry_msgs/msg/PoseStamped` (`ros2msg`) | `cdr` | every state record |
//! | `/ros/vehicle/path` | `nav_msgs/msg/Path` (`ros2msg`) | `cdr` | every [`ROS_PATH_PERIOD_S`] and at the end: the whole path so far, at most [`MAX_ROS_PATH_POSES`] poses, the newest state last |
//!
//! # Size: what each panel shows
//!
//! No message repeats the whole path at full resolution, so the file grows linearly with the flight
//! (a synthetic one-hour flight: 663 MB; `docs/decisions/0006-mcap-incremental-path.md`). While
//! playing forward Foxglove's 3D panel draws every `/scene/path` segment; after a seek it has the
//! coarse `flown_path` (at most [`MAX_COARSE_PATH_POINTS`] points) and the segments from there on. A
//! `nav_msgs/Path` display shows the newest `/ros/vehicle/path` (at most [`MAX_ROS_PATH_POSES`]
//! poses). Obstacles move at 10 Hz up to 50 obstacles, 5 Hz up to 100 ([`obstacle_period_s`]).
//!
//! [`export_file`] streams the log ([`trust_runlog::LogReader`]): memory is one line plus the
//! two bounded paths, whatever the flight's length.
//!
//! Frame `world` is the log's frame (metres, z up). Log times become MCAP log and publish times in
//! nanoseconds (`round(t · 1e9)`). The log holds no attitude: a pose's orientation is the heading
//! of the horizontal velocity (a yaw about z, held while the vehicle is slower than 5 cm/s), which
//! is what a viewer needs to show where the vehicle goes.
//!
//! The JSON schemas are written out here from the field lists of Foxglove's message reference
//! (only the fields we send, with their JSON types); the ROS 2 definitions are the standard
//! `.msg` texts with their dependencies in the concatenated form `ros2 bag` writes. The CDR
//! serialization ([`cdr`]) is ours: little-endian with the 4-byte encapsulation header
//! `00 01 00 00` (CDR_LE), each primitive aligned to its size relative to the end of the header.
//!
//! A static point cloud file (`static_points_file`) is not exported; its generating shapes are,
//! when the log has them. Chunks are written uncompressed (the `mcap` crate without its C codecs).
//!
//! ```no_run
//! use std::path::Path;
//!
//! let summary = trust_export::export_file(Path::new("out/run/run.jsonl"), Path::new("run.mcap"))?;
//! println!("{summary:?}");
//! # Ok::<(), trust_export::ExportError>(())
//! ```
#![warn(missing_docs)]

pub mod cdr;
mod scene;

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use mcap::records::MessageHeader;
use trust_runlog::{CycleRecord, Header, LogReader, Record, RunLog, StateRecord, readable};

pub use scene::{foxglove_schema, ros2_schema};

/// Period (s) of the `/scene/path` messages.
pub const PATH_PERIOD_S: f64 = 0.5;
/// Smallest time (s) between two points of a path segment, and of the paths while they are short.
pub const PATH_POINT_SPACING_S: f64 = 0.1;
/// Most points of `/scene/path`'s coarse whole path (`flown_path`).
pub const MAX_COARSE_PATH_POINTS: usize = 250;
/// Period (s) of the `/ros/vehicle/path` messages.
pub const ROS_PATH_PERIOD_S: f64 = 5.0;
/// Most poses of a `/ros/vehicle/path` message.
pub const MAX_ROS_PATH_POSES: usize = 1000;
/// Period (s) of the `/scene/obstacles` messages with up to [`OBSTACLES_AT_FULL_RATE`] moving
/// obstacles; [`obstacle_period_s`] for more.
pub const OBSTACLE_PERIOD_S: f64 = 0.1;
/// Most moving obstacles sent every [`OBSTACLE_PERIOD_S`].
pub const OBSTACLES_AT_FULL_RATE: usize = 50;

/// Period (s) of the `/scene/obstacles` messages for `obstacle_count` moving obstacles:
/// [`OBSTACLE_PERIOD_S`] times one more for every [`OBSTACLES_AT_FULL_RATE`] started (0.1 s up to
/// 50 obstacles, 0.2 s up to 100, …), so that they stay under about 100 kB per second of flight
/// (an obstacle takes about 200 bytes).
pub fn obstacle_period_s(obstacle_count: usize) -> f64 {
    OBSTACLE_PERIOD_S * obstacle_count.div_ceil(OBSTACLES_AT_FULL_RATE).max(1) as f64
}
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

/// Reads the run log at `log_path`, streaming it, and writes `mcap_path` (module docs), with the
/// branches its cycle records carry ([`branches_of_cycle`]; none when the flight was logged
/// without them).
///
/// # Errors
/// [`ExportError::Log`] naming the log file and line; [`ExportError::Input`] for a value no
/// message can carry; [`ExportError::Io`] / [`ExportError::Mcap`] naming the MCAP file. The
/// partial MCAP file is removed on any error.
pub fn export_file(log_path: &Path, mcap_path: &Path) -> Result<ExportSummary, ExportError> {
    let mut reader = LogReader::open(log_path)?;
    let header = reader.header().clone();
    let result = (|| {
        let mut x = Exporter::create(&header, mcap_path)?;
        let (mut state_index, mut branch_index) = (0, 0);
        while let Some(record) = reader.next_record()? {
            match record {
                Record::State(s) => {
                    check_state(state_index, &s)?;
                    state_index += 1;
                    x.state(&s)?;
                }
                Record::Cycle(c) => {
                    if let Some(b) = branches_of_cycle(&c) {
                        check_branches(branch_index, &b, x.last_branch_t)?;
                        branch_index += 1;
                        x.branches(&b)?;
                    }
                }
                Record::Outcome(_) | Record::Header(_) => {}
            }
        }
        x.finish()
    })();
    if result.is_err() {
        std::fs::remove_file(mcap_path).ok();
    }
    result
}

/// The sampled branches of one cycle record (`branch_samples`, written when branch logging is
/// on), main branch first; `None` without them.
pub fn branches_of_cycle(c: &CycleRecord) -> Option<Branches> {
    let samples = c.branch_samples.as_ref()?;
    Some(Branches {
        t: c.t,
        has_main: c.main.is_some() && !samples.is_empty(),
        polylines: samples
            .iter()
            .map(|b| b.samples.iter().map(|s| [s[1], s[2], s[3]]).collect())
            .collect(),
    })
}

/// The sampled branches of `log`'s cycle records ([`branches_of_cycle`]), one [`Branches`] per
/// cycle that carries any; empty for a log without them.
pub fn branches_of(log: &RunLog) -> Vec<Branches> {
    log.cycles.iter().filter_map(branches_of_cycle).collect()
}

/// Writes `log` (and `branches`, in cycle order; may be empty) to the MCAP file `path` (module
/// docs for the channels).
///
/// # Errors
/// [`ExportError::Input`] for a non-finite number, a negative time or branches out of order
/// (found before the file is created); [`ExportError::Io`] / [`ExportError::Mcap`] naming the
/// file (a write error may leave a partial file, which no MCAP reader accepts).
pub fn export_mcap(
    log: &RunLog,
    branches: &[Branches],
    path: &Path,
) -> Result<ExportSummary, ExportError> {
    check(log, branches)?;
    let mut x = Exporter::create(&log.header, path)?;
    let mut branch_iter = branches.iter().peekable();
    for s in &log.states {
        // Branches planned up to this state, in time order with the states.
        while let Some(b) = branch_iter.next_if(|b| b.t <= s.t) {
            x.branches(b)?;
        }
        x.state(s)?;
    }
    for b in branch_iter {
        x.branches(b)?;
    }
    x.finish()
}

/// A path kept at most `max` points long: one point per `spacing` (from
/// [`PATH_POINT_SPACING_S`]), the spacing doubling (every other point dropped) whenever it would
/// exceed `max`.
#[derive(Debug, Clone)]
struct CoarsePath {
    max: usize,
    spacing: f64,
    next_t: f64,
    points: Vec<(f64, [f64; 3], f64)>,
}

impl CoarsePath {
    fn new(max: usize) -> Self {
        CoarsePath {
            max,
            spacing: PATH_POINT_SPACING_S,
            next_t: f64::NEG_INFINITY,
            points: Vec::new(),
        }
    }

    fn push(&mut self, t: f64, p: [f64; 3], yaw: f64) {
        if t < self.next_t - 1e-9 {
            return;
        }
        self.points.push((t, p, yaw));
        self.next_t = t + self.spacing;
        if self.points.len() > self.max {
            let mut k = 0;
            self.points.retain(|_| {
                k += 1;
                k % 2 == 1
            });
            self.spacing *= 2.0;
            self.next_t = self.points.last().map_or(t, |q| q.0) + self.spacing;
        }
    }

    /// The points, with `newest` appended unless it is the last one.
    fn with_newest(&self, newest: (f64, [f64; 3], f64)) -> Vec<(f64, [f64; 3], f64)> {
        let mut v = self.points.clone();
        if v.last().is_none_or(|q| q.0 < newest.0) {
            v.push(newest);
        }
        v
    }
}

/// The export of one log, fed state by state (module docs for what it writes when).
struct Exporter<'h> {
    path: PathBuf,
    header: &'h Header,
    writer: mcap::Writer<BufWriter<File>>,
    channels: BTreeMap<&'static str, u16>,
    branch_schema: Option<u16>,
    counts: BTreeMap<&'static str, u64>,
    t0: Option<f64>,
    yaw: f64,
    next_path_t: f64,
    next_ros_path_t: f64,
    next_obstacles_t: f64,
    /// The current segment of `/scene/path`, starting with the end of the previous one.
    segment: Vec<[f64; 3]>,
    segment_next_t: f64,
    segment_count: u64,
    coarse: CoarsePath,
    ros_path: CoarsePath,
    /// The newest state not yet in every message it belongs to (the last state is flushed by
    /// `finish`).
    pending: Option<StateRecord>,
    /// When `/scene/obstacles`, `/scene/path` and `/ros/vehicle/path` were last sent.
    sent_t: [f64; 3],
    last_branch_t: f64,
}

impl<'h> Exporter<'h> {
    fn create(header: &'h Header, path: &Path) -> Result<Self, ExportError> {
        let file = File::create(path).map_err(|source| ExportError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let mcap_err = mcap_error(path);
        let options = mcap::WriteOptions::new()
            .compression(None)
            .profile("")
            .library(concat!("trust-export ", env!("CARGO_PKG_VERSION")));
        let mut writer = options.create(BufWriter::new(file)).map_err(&mcap_err)?;
        let mut channels = BTreeMap::new();
        let topics: &[(&str, &str)] = &[
            ("/vehicle/pose", "foxglove.PoseInFrame"),
            ("/tf", "foxglove.FrameTransform"),
            ("/scene/map", "foxglove.SceneUpdate"),
            ("/scene/obstacles", "foxglove.SceneUpdate"),
            ("/scene/path", "foxglove.SceneUpdate"),
        ];
        let mut schema_ids = BTreeMap::new();
        for &(topic, schema) in topics {
            let id = match schema_ids.get(schema) {
                Some(id) => *id,
                None => {
                    let data = foxglove_schema(schema).expect("a schema of ours");
                    let id = writer
                        .add_schema(schema, "jsonschema", data.as_bytes())
                        .map_err(&mcap_err)?;
                    schema_ids.insert(schema, id);
                    id
                }
            };
            let channel = writer
                .add_channel(id, topic, "json", &BTreeMap::new())
                .map_err(&mcap_err)?;
            channels.insert(topic, channel);
        }
        for (topic, schema) in [
            ("/ros/vehicle/pose", "geometry_msgs/msg/PoseStamped"),
            ("/ros/vehicle/path", "nav_msgs/msg/Path"),
        ] {
            let data = ros2_schema(schema).expect("a schema of ours");
            let id = writer
                .add_schema(schema, "ros2msg", data.as_bytes())
                .map_err(&mcap_err)?;
            let channel = writer
                .add_channel(id, topic, "cdr", &BTreeMap::new())
                .map_err(&mcap_err)?;
            channels.insert(topic, channel);
        }
        Ok(Exporter {
            path: path.to_path_buf(),
            header,
            writer,
            channels,
            branch_schema: schema_ids.get("foxglove.SceneUpdate").copied(),
            counts: BTreeMap::new(),
            t0: None,
            yaw: 0.0,
            next_path_t: f64::NEG_INFINITY,
            next_ros_path_t: f64::NEG_INFINITY,
            next_obstacles_t: f64::NEG_INFINITY,
            segment: Vec::new(),
            segment_next_t: f64::NEG_INFINITY,
            segment_count: 0,
            coarse: CoarsePath::new(MAX_COARSE_PATH_POINTS),
            ros_path: CoarsePath::new(MAX_ROS_PATH_POSES),
            pending: None,
            sent_t: [f64::NAN; 3],
            last_branch_t: f64::NEG_INFINITY,
        })
    }

    fn raw(&mut self, topic: &'static str, t: f64, data: &[u8]) -> Result<(), ExportError> {
        let channel_id = self.channels[topic];
        let count = self.counts.entry(topic).or_insert(0);
        *count += 1;
        let header = MessageHeader {
            channel_id,
            sequence: u32::try_from(*count).unwrap_or(u32::MAX),
            log_time: nanos(t),
            publish_time: nanos(t),
        };
        self.writer
            .write_to_known_channel(&header, data)
            .map_err(mcap_error(&self.path))
    }

    fn json(
        &mut self,
        topic: &'static str,
        t: f64,
        value: &serde_json::Value,
    ) -> Result<(), ExportError> {
        let data = serde_json::to_vec(value).expect("JSON values serialize");
        self.raw(topic, t, &data)
    }

    fn branches(&mut self, b: &Branches) -> Result<(), ExportError> {
        if !self.channels.contains_key("/scene/branches") {
            let schema = self.branch_schema.expect("the scene schema is added first");
            let channel = self
                .writer
                .add_channel(schema, "/scene/branches", "json", &BTreeMap::new())
                .map_err(mcap_error(&self.path))?;
            self.channels.insert("/scene/branches", channel);
        }
        self.last_branch_t = b.t;
        self.json("/scene/branches", b.t, &scene::branches_update(b))
    }

    fn state(&mut self, s: &StateRecord) -> Result<(), ExportError> {
        if self.t0.is_none() {
            self.t0 = Some(s.t);
            self.json("/scene/map", s.t, &scene::map_update(self.header, s.t))?;
        }
        self.yaw = scene::heading(&s.v, self.yaw);
        let yaw = self.yaw;
        self.json("/vehicle/pose", s.t, &scene::pose_in_frame(s, yaw))?;
        self.json("/tf", s.t, &scene::frame_transform(s, yaw))?;
        self.raw("/ros/vehicle/pose", s.t, &cdr::pose_stamped(s.t, s.p, yaw))?;
        self.coarse.push(s.t, s.p, yaw);
        self.ros_path.push(s.t, s.p, yaw);
        if s.t >= self.segment_next_t - 1e-9 {
            self.segment.push(s.p);
            self.segment_next_t = s.t + PATH_POINT_SPACING_S;
        }
        self.periodic(s, false)?;
        self.pending = Some(s.clone());
        Ok(())
    }

    /// The periodic messages due at state `s`; `last`: every one not yet sent at `s`.
    fn periodic(&mut self, s: &StateRecord, last: bool) -> Result<(), ExportError> {
        let t0 = self.t0.unwrap_or(s.t);
        // The next multiple of `period` after `t` (relative to the first state).
        let next = |t: f64, period: f64| t0 + period * (((t - t0) / period + 1e-9).floor() + 1.0);
        let due = |next_t: f64, sent_t: f64| {
            if last {
                sent_t != s.t
            } else {
                s.t >= next_t - 1e-9
            }
        };
        if due(self.next_obstacles_t, self.sent_t[0]) {
            self.json(
                "/scene/obstacles",
                s.t,
                &scene::obstacles_update(self.header, s),
            )?;
            self.next_obstacles_t = next(s.t, obstacle_period_s(self.header.obstacles.len()));
            self.sent_t[0] = s.t;
        }
        let newest = (s.t, s.p, self.yaw);
        if due(self.next_path_t, self.sent_t[1]) {
            let mut segment = std::mem::take(&mut self.segment);
            if segment.last() != Some(&s.p) {
                segment.push(s.p);
            }
            let coarse: Vec<[f64; 3]> = self
                .coarse
                .with_newest(newest)
                .iter()
                .map(|q| q.1)
                .collect();
            let n = self.segment_count;
            self.segment_count += 1;
            self.json(
                "/scene/path",
                s.t,
                &scene::path_update(s.t, n, &segment, &coarse),
            )?;
            // The next segment starts where this one ends.
            self.segment = vec![s.p];
            self.segment_next_t = s.t + PATH_POINT_SPACING_S;
            self.next_path_t = next(s.t, PATH_PERIOD_S);
            self.sent_t[1] = s.t;
        }
        if due(self.next_ros_path_t, self.sent_t[2]) {
            let poses = self.ros_path.with_newest(newest);
            self.raw("/ros/vehicle/path", s.t, &cdr::path(s.t, &poses))?;
            self.next_ros_path_t = next(s.t, ROS_PATH_PERIOD_S);
            self.sent_t[2] = s.t;
        }
        Ok(())
    }

    fn finish(mut self) -> Result<ExportSummary, ExportError> {
        let Some(last) = self.pending.take() else {
            return Err(ExportError::Input {
                field: "states".into(),
                value: "[]".into(),
                expected: "at least one state".into(),
            });
        };
        // Every periodic topic ends with the last state.
        self.periodic(&last, true)?;
        let path = self.path.clone();
        let counts = std::mem::take(&mut self.counts);
        self.writer.finish().map_err(mcap_error(&path))?;
        self.writer
            .into_inner()
            .into_inner()
            .map_err(|e| ExportError::Io {
                path: path.clone(),
                source: e.into_error(),
            })?
            .sync_all()
            .map_err(|source| ExportError::Io { path, source })?;
        Ok(ExportSummary {
            message_counts: counts
                .into_iter()
                .map(|(k, v)| (k.to_string(), v))
                .collect(),
        })
    }
}

fn bad(field: String, value: String, expected: &str) -> ExportError {
    ExportError::Input {
        field,
        value,
        expected: expected.to_string(),
    }
}

fn finite(xs: &[f64]) -> bool {
    xs.iter().all(|x| x.is_finite())
}

/// Rejects a state no message can carry: a non-finite number, a time outside [0, 1e7] s.
fn check_state(i: usize, s: &StateRecord) -> Result<(), ExportError> {
    if !(s.t.is_finite() && s.t >= 0.0 && s.t <= 1e7) {
        return Err(bad(
            format!("states[{i}].t"),
            readable(s.t),
            "a time in [0, 1e7] s",
        ));
    }
    if !finite(&s.p) || !finite(&s.v) || s.obstacles.iter().any(|o| !finite(o)) {
        return Err(bad(
            format!("states[{i}]"),
            format!("t = {}", readable(s.t)),
            "finite positions and velocities",
        ));
    }
    Ok(())
}

/// Rejects branches no message can carry, or out of order (`previous`: the time of the branches
/// before).
fn check_branches(i: usize, b: &Branches, previous: f64) -> Result<(), ExportError> {
    if !(b.t.is_finite() && b.t >= 0.0 && b.t <= 1e7 && b.t >= previous) {
        return Err(bad(
            format!("branches[{i}].t"),
            readable(b.t),
            "a time in [0, 1e7] s, not before the previous cycle's",
        ));
    }
    if b.polylines.iter().flatten().any(|q| !finite(q)) {
        return Err(bad(
            format!("branches[{i}]"),
            format!("t = {}", readable(b.t)),
            "finite branch points",
        ));
    }
    Ok(())
}

/// Rejects what no message can carry: non-finite numbers, negative times, branches out of order.
fn check(log: &RunLog, branches: &[Branches]) -> Result<(), ExportError> {
    if log.states.is_empty() {
        return Err(bad("states".into(), "[]".into(), "at least one state"));
    }
    for (i, s) in log.states.iter().enumerate() {
        check_state(i, s)?;
    }
    let mut previous = f64::NEG_INFINITY;
    for (i, b) in branches.iter().enumerate() {
        check_branches(i, b, previous)?;
        previous = b.t;
    }
    Ok(())
}

fn mcap_error(path: &Path) -> impl Fn(mcap::McapError) -> ExportError + '_ {
    move |e| ExportError::Mcap {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

/// Nanoseconds of a (checked, non-negative) log time.
pub(crate) fn nanos(t: f64) -> u64 {
    (t * 1e9).round() as u64
}
