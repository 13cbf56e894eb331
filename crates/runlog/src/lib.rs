//! # trust-runlog — run logs of the closed loop (JSON Lines, schema `trust-sim-log/1`)
//!
//! The record of one simulated flight (paper Sec. IV's experiments are judged on these), following
//! `shared/contracts/run-log-v1.md` and documented in full in `docs/run-log.md`. One object per line,
//! each with a `"type"`: a `header` first, `state` records of the true vehicle and obstacles at
//! ≥ 50 Hz, one `cycle` record per planning cycle, and an `outcome` last. The contract's fields are
//! never dropped or renamed; this crate adds fields (marked "added" in their docs) and nothing else.
//!
//! Use it to write a log (the closed loop in `trust-flight` does), to read one without building a
//! world (the replay, the MCAP export, studies), or to re-check a log's outcome independently
//! (`trust-sim audit`). It knows no simulator type: its `StaticShape` is also the scenario's.
//!
//! - The record types ([`Header`], [`StateRecord`], [`CycleRecord`], [`Outcome`], [`Record`]) and
//!   [`LogWriter`], which writes a log line by line (buffered) in the shortest form that reads
//!   back to the same `f64`, refusing non-finite numbers (a non-finite value is a bug, not data).
//! - [`reader`]: [`LogReader`] streams a log record by record and checks its structure; a
//!   one-hour log is read in the memory of one line. [`RunLog::read`] collects it whole (for the
//!   logs of tests and studies; tools that may meet long logs stream).
//! - [`files`]: the policy for reading files named by a log or its user — only regular files,
//!   a size cap per kind of file enforced while reading, the points file's path kept inside the
//!   log's folder, no file contents in messages beyond the offending line — and [`readable`]
//!   numbers in messages.
//! - [`kdtree`]: [`PointTree`], the nearest-point index of a static point cloud (why a k-d tree:
//!   its module docs).
//! - [`audit`]: the independent re-check of a log's outcome from its header and states, with its
//!   value policy and consistency checks.
//!
//! ```no_run
//! use std::path::Path;
//! use trust_runlog::RunLog;
//! use trust_runlog::audit::{AuditOptions, audit_file};
//!
//! let log = RunLog::read(Path::new("out/run/run.jsonl"))?;
//! println!("{:?} after {} s", log.outcome.status, log.outcome.flight_time_s);
//! let audit = audit_file(Path::new("out/run/run.jsonl"), AuditOptions::default())?;
//! assert!(audit.findings.is_empty(), "{:?}", audit.findings);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(missing_docs)]

pub mod audit;
pub mod files;
pub mod kdtree;
pub mod reader;

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

pub use files::readable;
pub use kdtree::PointTree;
pub use reader::LogReader;

/// The schema tag of this version.
pub const SCHEMA: &str = "trust-sim-log/1";

/// Map bounds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Bounds {
    /// Lower corner.
    pub min: [f64; 3],
    /// Upper corner.
    pub max: [f64; 3],
}

/// The vehicle as the log knows it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct VehicleInfo {
    /// Collision radius (m).
    pub radius: f64,
    /// Added: `"se3-quadrotor"` or `"perfect-tracking"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model: Option<String>,
}

/// Dynamic limits.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LimitsInfo {
    /// Maximum speed (m/s).
    pub v_max: f64,
    /// Maximum acceleration (m/s²).
    pub a_max: f64,
}

/// A true static obstacle, externally tagged as in the contract:
/// `{"sphere": {...}}`, `{"cylinder": {...}}`, `{"box": {...}}`. Also the scenario file's
/// `[[static.shapes]]` entry (`trust-world` reads it tagged by `kind` through a serde adapter).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StaticShape {
    /// A ball.
    Sphere {
        /// Centre.
        center: [f64; 3],
        /// Radius.
        radius: f64,
    },
    /// A vertical cylinder: axis through `center` (x, y) from `z_min` to `z_max`.
    Cylinder {
        /// Axis position (x, y).
        center: [f64; 2],
        /// Radius.
        radius: f64,
        /// Bottom.
        z_min: f64,
        /// Top.
        z_max: f64,
    },
    /// An axis-aligned box.
    Box {
        /// Lower corner.
        min: [f64; 3],
        /// Upper corner.
        max: [f64; 3],
    },
}

/// A moving obstacle's identity and true size.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ObstacleInfo {
    /// Index in every `state` record's `obstacles`.
    pub id: usize,
    /// `"sphere"`, `"cylinder"` or (added) `"box"`.
    pub shape: ObstacleKind,
    /// Radius (m). For a box: `√(hx² + hy²)`, the radius of the vertical cylinder its
    /// forecasts use (the truth is `half_extents`).
    pub radius: f64,
    /// Half of the height (cylinders only; centre at mid-height).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub half_height: Option<f64>,
    /// Added: half extents `[hx, hy, hz]` of a box (boxes only; axis-aligned, centred at the
    /// state's obstacle position).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub half_extents: Option<[f64; 3]>,
}

/// Shape of a moving obstacle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ObstacleKind {
    /// A ball.
    Sphere,
    /// A vertical cylinder.
    Cylinder,
    /// Added: an axis-aligned box (`half_extents`).
    Box,
}

/// The first line.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Header {
    /// Always [`SCHEMA`].
    pub schema: String,
    /// Scenario name.
    pub scenario: String,
    /// Trial seed.
    pub seed: u64,
    /// Planner name.
    pub planner: String,
    /// Map bounds.
    pub bounds: Bounds,
    /// The vehicle.
    pub vehicle: VehicleInfo,
    /// Its limits.
    pub limits: LimitsInfo,
    /// Start position.
    pub start: [f64; 3],
    /// Goal position.
    pub goal: [f64; 3],
    /// Arrival tolerance (m).
    pub goal_tolerance: f64,
    /// The true static geometry.
    pub static_shapes: Vec<StaticShape>,
    /// A file of `x y z` lines (relative to the log's folder) when the static truth is a point cloud
    /// without generating shapes; `null` otherwise.
    pub static_points_file: Option<String>,
    /// Every moving obstacle with its true size.
    pub obstacles: Vec<ObstacleInfo>,
    /// Added: the simulation's settings (physics step, rates, latency model, vehicle model).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sim: Option<serde_json::Value>,
}

/// The true state at one instant.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StateRecord {
    /// Time (s).
    pub t: f64,
    /// Position.
    pub p: [f64; 3],
    /// Velocity.
    pub v: [f64; 3],
    /// Acceleration.
    pub a: [f64; 3],
    /// True obstacle centres, in header order.
    pub obstacles: Vec<[f64; 3]>,
}

/// One planning cycle. `Default` is an empty cycle at `t = 0` (every added field absent), for
/// building records with `..CycleRecord::default()`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct CycleRecord {
    /// Time of the cycle (s).
    pub t: f64,
    /// Wall-clock time of the cycle (ms).
    pub wall_ms: f64,
    /// Main branch id (`null` while braking).
    pub main: Option<u64>,
    /// Number of kept branches.
    pub branches: usize,
    /// Event tags.
    pub events: Vec<String>,
    /// Added: frontend time (ms).
    #[serde(default)]
    pub frontend_ms: f64,
    /// Added: summed solve time (ms).
    #[serde(default)]
    pub backend_ms: f64,
    /// Added: summed check time (ms).
    #[serde(default)]
    pub checker_ms: f64,
    /// Added: trajectories optimized this cycle.
    #[serde(default)]
    pub solve_count: usize,
    /// Added: the time the new plan took effect (s).
    #[serde(default)]
    pub effective_t: f64,
    /// Added: `J` of the kept branches, in rank order.
    #[serde(default)]
    pub branch_j: Vec<f64>,
    /// Added: whether the plan is a braking fallback, and whether it was collision-free.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fallback_collision_free: Option<bool>,
    /// Added, only on fallback cycles that are not collision-free: by how much (m) the fallback
    /// fails to keep the required clearance under the forecasts.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fallback_shortfall_m: Option<f64>,
    /// Added, only on fallback cycles: what the fallback flies — `committed`, `branch`,
    /// `candidate` or `straight` (braking along it), `evade` (a rejected trajectory as it is) or
    /// `escape` (a short manoeuvre to rest out of the way).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fallback_along: Option<String>,
    /// Added: what the safety check dropped this cycle, by the first violation's cause.
    #[serde(default, skip_serializing_if = "Dropped::is_empty")]
    pub dropped: Dropped,
    /// Added: the global route the manager planned this cycle (event `rerouted`), start first;
    /// absent in the cycles that planned none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub route: Option<Vec<[f64; 3]>>,
    /// Added: time spent planning that route (ms); absent when none was planned.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub route_ms: Option<f64>,
    /// Added (issue 20), only when branch logging is on: the kept branches' trajectories after the
    /// cycle, main branch first, then the others in ranking order.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub branch_samples: Option<Vec<BranchSamples>>,
    /// Added (issue 20), only when branch logging is on: the forecasts the cycle planned against.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub forecasts: Option<Vec<ForecastRecord>>,
    /// Added (issue 31), only in the real-time latency mode: the time the planner was charged
    /// for the cycle (ms): its wall time times the mode's `cpu_scale`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub charged_ms: Option<f64>,
    /// Added (issue 31), only when positive: replanning ticks skipped because the planner was
    /// still busy with this cycle (real-time latency mode).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub overrun_ticks: Option<u64>,
    /// Added (issue 31), only in cycles that merged the manager's worker job (sub-branch
    /// re-solves and exploration started at the end of the previous cycle, off the critical
    /// path): the job's wall time (ms).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub worker_ms: Option<f64>,
    /// Added (issue 31), with `worker_ms`: the part of `wall_ms` the cycle waited for the job
    /// (ms). The real-time clock charges `wall_ms − waited_ms` plus the job's lateness.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub waited_ms: Option<f64>,
    /// Added (issue 31), only in cycles that took back a route search sent away for a slice
    /// between cycles (on a thread of its own, off the critical path): the slice's wall time
    /// (ms; not part of `wall_ms`, its wait is in `waited_ms`). In real time a slice is not
    /// charged: its answer is taken once its time × `cpu_scale` has passed since it was sent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub route_worker_ms: Option<f64>,
    /// Added (issue 34), only when the static map is sensed (`[sensing.static]`): the time the
    /// online map took since the previous cycle (ms): the scans, their insertion and the export
    /// of the planner's map. Perception, not planning: not part of `wall_ms`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub map_ms: Option<f64>,
    /// Added (issue 34), in the planner's cycles: the point its branches aimed at this cycle
    /// (the global route's local goal, a route corner that hides what lies beyond, or the
    /// goal; m, world frame). Where to look first when a flight stalls.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub aim: Option<[f64; 3]>,
}

impl CycleRecord {
    /// A cycle with only the fields of format version 1 (`t`, `wall_ms`, `main`, `branches`,
    /// `events`): every added field is zero, empty or absent, and `effective_t` is `t`. For
    /// logs written from outside the planner (a ROS node's events) and for readers that skip
    /// the added fields.
    pub fn bare(
        t: f64,
        wall_ms: f64,
        main: Option<u64>,
        branches: usize,
        events: Vec<String>,
    ) -> CycleRecord {
        CycleRecord {
            t,
            wall_ms,
            main,
            branches,
            events,
            effective_t: t,
            ..CycleRecord::default()
        }
    }
}

/// One kept branch's trajectory, sampled (added, issue 20).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BranchSamples {
    /// The manager's branch id.
    pub id: u64,
    /// `[t, x, y, z]` along the trajectory from its start to its end, both included (absolute
    /// time, s; position, m).
    pub samples: Vec<[f64; 4]>,
}

/// The base shape of a forecast (added, issue 20).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ForecastShape {
    /// A ball of radius `r(t)`.
    Sphere,
    /// A vertical cylinder of radius `r(t)` and half-height `half_height + mu·(t − t0)`.
    Cylinder {
        /// Half-height at `t0` (m), margin included.
        half_height: f64,
    },
}

/// A forecast of one moving obstacle as the planner planned against it (added, issue 20): centre
/// `p0 + v0·(t − t0)`, radius `r0 + mu·min(t − t0, growth_s)` for `t ≥ t0` (see
/// [`ForecastRecord::centre_at`] and [`ForecastRecord::radius_at`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ForecastRecord {
    /// The obstacle (index in the header's `obstacles`).
    pub id: usize,
    /// Centre at `t0`.
    pub p0: [f64; 3],
    /// Velocity.
    pub v0: [f64; 3],
    /// Time of the forecast (s).
    pub t0: f64,
    /// Avoidance radius at `t0` (m): the obstacle's radius plus the safety margin.
    pub r0: f64,
    /// Growth rate of the radius (m/s).
    pub mu: f64,
    /// Base shape.
    pub shape: ForecastShape,
    /// How long the radius grows (s) after `t0` (added, issue 19): the planner stops the growth
    /// after `trust_manager::ManagerParams::forecast_growth_s`. Absent: it grows for ever (logs
    /// written before the field, or `forecast_growth_s = inf`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub growth_s: Option<f64>,
    /// The region the obstacle's traffic turns it back in, `[min, max]` corners (added, issue
    /// 19): the planner mirrors the forecast at these walls (`trust_predict::Forecast::walls`).
    /// Absent: at the world's bounds (the obstacle has no region of its own, or logs written
    /// before the field).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub walls: Option<[[f64; 3]; 2]>,
}

impl ForecastRecord {
    /// Predicted centre at time `t` (the centre at `t0` for `t < t0`).
    pub fn centre_at(&self, t: f64) -> [f64; 3] {
        let dt = (t - self.t0).max(0.0);
        [
            self.p0[0] + self.v0[0] * dt,
            self.p0[1] + self.v0[1] * dt,
            self.p0[2] + self.v0[2] * dt,
        ]
    }

    /// How much the radius (and a cylinder's half-height) has grown by time `t` (m):
    /// `mu·clamp(t − t0, 0, growth_s)`.
    pub fn growth_at(&self, t: f64) -> f64 {
        let dt = (t - self.t0).max(0.0);
        self.mu * self.growth_s.map_or(dt, |g| dt.min(g))
    }

    /// Avoidance radius at time `t` (m): `r0 +` [`ForecastRecord::growth_at`].
    pub fn radius_at(&self, t: f64) -> f64 {
        self.r0 + self.growth_at(t)
    }
}

/// Trajectories the safety check dropped in one cycle, by cause of the first violation.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Dropped {
    /// Too close to the static map.
    pub static_map: usize,
    /// Too close to a moving obstacle's forecast.
    pub moving: usize,
    /// Left the map bounds.
    pub bounds: usize,
    /// Only the speed or acceleration limit was exceeded.
    pub limits: usize,
    /// Of the above, those whose trajectory was clear and only what follows its end was not:
    /// the braking of one that ends moving (`trust_manager::SafetyParams::braking_tail`) or the
    /// rest hold of one that ends at rest (`trust_manager::SafetyParams::rest_hold_s`).
    #[serde(default)]
    pub braking_tail: usize,
}

impl Dropped {
    /// Nothing was dropped.
    pub fn is_empty(&self) -> bool {
        *self == Self::default()
    }
}

/// How a flight ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// Within the goal tolerance, no collision before.
    Arrived,
    /// A clearance below zero.
    Collided,
    /// The time limit passed.
    TimedOut,
    /// The run could not be carried out as specified (e.g. the planner rejected the input).
    Invalid,
    /// The planner proved the goal cannot be reached (sealed off, inside an obstacle, outside
    /// the bounds, or behind passages narrower than the vehicle plus its margin) and held that
    /// verdict for the settling time; the outcome's `reason` says why. Beyond the contract's
    /// four statuses (an added value, `docs/run-log.md`).
    Unreachable,
}

impl Status {
    /// The contract's spelling.
    pub fn as_str(self) -> &'static str {
        match self {
            Status::Arrived => "arrived",
            Status::Collided => "collided",
            Status::TimedOut => "timed_out",
            Status::Invalid => "invalid",
            Status::Unreachable => "unreachable",
        }
    }
}

/// What the vehicle touched: a `collided` outcome's `with`. Its `Display` is the contract's
/// spelling, `static` or `obstacle:<id>` (the header's obstacle index).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Contact {
    /// The static geometry.
    Static,
    /// The moving obstacle with this id.
    Obstacle(usize),
}

impl std::fmt::Display for Contact {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Contact::Static => f.write_str("static"),
            Contact::Obstacle(id) => write!(f, "obstacle:{id}"),
        }
    }
}

/// The last line.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Outcome {
    /// How it ended.
    pub status: Status,
    /// Time of the end (s).
    pub t: f64,
    /// `t` minus the first state's time (s).
    pub flight_time_s: f64,
    /// Sum of the distances between consecutive logged positions (m).
    pub path_length_m: f64,
    /// Smallest static clearance over the state records (m; `null`/absent without static geometry).
    pub min_clearance_static_m: f64,
    /// Smallest clearance to a moving obstacle over the state records (m).
    pub min_clearance_dynamic_m: f64,
    /// Largest `|v|` over the state records.
    pub max_speed: f64,
    /// Largest `|a|` over the state records.
    pub max_accel: f64,
    /// For `collided`: `"static"` or `"obstacle:<id>"` ([`Contact`]'s spelling).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub with: Option<String>,
    /// Added: why the run is `invalid`, or other notes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
    /// Added: planning cycles run.
    #[serde(default)]
    pub cycle_count: usize,
    /// Added, only for a collision with a moving obstacle: how long before contact the forecasts
    /// the planner planned against (its growth stop applied, with their mirror images at the
    /// map's walls) already had the
    /// obstacle where it was at contact (s) — every forecast of that obstacle issued since then
    /// had its true centre within the forecast's uncertainty (`r_safe` less the vehicle radius,
    /// plus the growth). 0 when even the last forecast before contact missed it: the obstacle
    /// outran its forecast. Compare with the time the vehicle needs to stop (`v/a_max`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub forecast_warning_s: Option<f64>,
}

/// One line of a run log.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Record {
    /// First line.
    Header(Header),
    /// True state.
    State(StateRecord),
    /// Planning cycle.
    Cycle(CycleRecord),
    /// Last line.
    Outcome(Outcome),
}

/// Errors of reading and writing logs.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum LogError {
    /// File-system error.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// A line is not a valid record.
    #[error("{path}:{line}: {message}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// The records do not follow the contract's structure.
    #[error("{path}: {message}")]
    Structure {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// A file to read is not a regular file (a folder, a device such as `/dev/zero`, a pipe).
    #[error("{}: not a regular file; {what} must be one", path.display())]
    NotAFile {
        /// The file.
        path: PathBuf,
        /// What it was read as ("a run log", "a static points file").
        what: &'static str,
    },
    /// A file to read is larger than its cap ([`files`]).
    #[error("{}: larger than the cap on {what} ({limit})", path.display())]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// What it was read as.
        what: &'static str,
        /// The cap exceeded (`"536870912 bytes"`, `"line 7: 67108864 bytes a line"`).
        limit: String,
    },
    /// The log's static points file is refused or cannot be read (the message names it).
    #[error("static points of the log: {message}")]
    Points {
        /// What is wrong, with the file and line.
        message: String,
    },
    /// A record to write holds a non-finite number.
    #[error("refusing to write a non-finite number in a `{record}` record: {detail}")]
    NonFinite {
        /// The record type.
        record: &'static str,
        /// Which value.
        detail: String,
    },
}

/// Writes a run log line by line.
#[derive(Debug)]
pub struct LogWriter {
    path: PathBuf,
    out: BufWriter<File>,
    line: String,
}

impl LogWriter {
    /// Creates (truncates) the file.
    ///
    /// # Errors
    /// [`LogError::Io`].
    pub fn create(path: &Path) -> Result<Self, LogError> {
        let file = File::create(path).map_err(|source| LogError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Ok(LogWriter {
            path: path.to_path_buf(),
            out: BufWriter::new(file),
            line: String::new(),
        })
    }

    /// The file being written.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Writes one record as one line.
    ///
    /// # Errors
    /// [`LogError::NonFinite`] (nothing is written) or [`LogError::Io`].
    pub fn write(&mut self, record: &Record) -> Result<(), LogError> {
        check_finite(record)?;
        self.line.clear();
        let json = serde_json::to_string(record).map_err(|e| LogError::NonFinite {
            record: record_type(record),
            detail: e.to_string(),
        })?;
        self.line.push_str(&json);
        self.line.push('\n');
        self.out
            .write_all(self.line.as_bytes())
            .map_err(|source| LogError::Io {
                path: self.path.clone(),
                source,
            })
    }

    /// Flushes and closes the file.
    ///
    /// # Errors
    /// [`LogError::Io`].
    pub fn finish(mut self) -> Result<(), LogError> {
        self.out.flush().map_err(|source| LogError::Io {
            path: self.path.clone(),
            source,
        })
    }
}

fn record_type(r: &Record) -> &'static str {
    match r {
        Record::Header(_) => "header",
        Record::State(_) => "state",
        Record::Cycle(_) => "cycle",
        Record::Outcome(_) => "outcome",
    }
}

fn check_finite(record: &Record) -> Result<(), LogError> {
    let bad = |detail: String| {
        Err(LogError::NonFinite {
            record: record_type(record),
            detail,
        })
    };
    let all = |xs: &[f64]| xs.iter().all(|x| x.is_finite());
    match record {
        Record::State(s) => {
            if !s.t.is_finite() || !all(&s.p) || !all(&s.v) || !all(&s.a) {
                return bad(format!("vehicle at t = {}", s.t));
            }
            if let Some(i) = s.obstacles.iter().position(|o| !all(o)) {
                return bad(format!("obstacle {i} at t = {}", s.t));
            }
        }
        Record::Cycle(c) => {
            if !c.t.is_finite() || !c.wall_ms.is_finite() || !c.effective_t.is_finite() {
                return bad(format!("cycle at t = {}", c.t));
            }
            if !all(&c.branch_j) {
                return bad(format!("branch J at t = {}", c.t));
            }
            for b in c.branch_samples.iter().flatten() {
                if let Some(k) = b.samples.iter().position(|s| !all(s)) {
                    return bad(format!("sample {k} of branch {} at t = {}", b.id, c.t));
                }
            }
            for f in c.forecasts.iter().flatten() {
                let h = match f.shape {
                    ForecastShape::Sphere => 0.0,
                    ForecastShape::Cylinder { half_height } => half_height,
                };
                if !(all(&f.p0) && all(&f.v0) && all(&[f.t0, f.r0, f.mu, h])) {
                    return bad(format!("forecast of obstacle {} at t = {}", f.id, c.t));
                }
            }
        }
        Record::Outcome(o) => {
            let xs = [
                o.t,
                o.flight_time_s,
                o.path_length_m,
                o.min_clearance_static_m,
                o.min_clearance_dynamic_m,
                o.max_speed,
                o.max_accel,
            ];
            if !all(&xs) {
                return bad(format!("{xs:?}"));
            }
        }
        Record::Header(h) => {
            if !all(&h.start) || !all(&h.goal) || !h.goal_tolerance.is_finite() {
                return bad("start, goal or tolerance".into());
            }
        }
    }
    Ok(())
}

/// A whole run log, read back.
#[derive(Debug, Clone, PartialEq)]
pub struct RunLog {
    /// The header.
    pub header: Header,
    /// The state records in order.
    pub states: Vec<StateRecord>,
    /// The cycle records in order.
    pub cycles: Vec<CycleRecord>,
    /// The outcome.
    pub outcome: Outcome,
}

impl RunLog {
    /// Reads a whole log ([`LogReader`], which checks the contract's structure: a header first
    /// with the right schema and every box obstacle with positive `half_extents`, an outcome
    /// last, exactly one of each, state times strictly increasing with steps ≤ 0.02 s, every
    /// state listing one position per header obstacle). It holds every record: a one-hour log of
    /// 100 obstacles takes about half a GB; stream long logs with [`LogReader`] instead.
    ///
    /// # Errors
    /// [`LogError`] naming the file and, for a bad line, its number.
    pub fn read(path: &Path) -> Result<RunLog, LogError> {
        let mut reader = LogReader::open(path)?;
        let mut states = Vec::new();
        let mut cycles = Vec::new();
        let mut outcome = None;
        while let Some(record) = reader.next_record()? {
            match record {
                Record::State(s) => states.push(s),
                Record::Cycle(c) => cycles.push(c),
                Record::Outcome(o) => outcome = Some(o),
                Record::Header(_) => {}
            }
        }
        Ok(RunLog {
            header: reader.header().clone(),
            states,
            cycles,
            outcome: outcome.ok_or_else(|| LogError::Structure {
                path: path.to_path_buf(),
                message: "no outcome (the run did not finish)".into(),
            })?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header() -> Header {
        Header {
            schema: SCHEMA.into(),
            scenario: "unit".into(),
            seed: 7,
            planner: "trust".into(),
            bounds: Bounds {
                min: [0.0; 3],
                max: [10.0, 10.0, 5.0],
            },
            vehicle: VehicleInfo {
                radius: 0.3,
                model: None,
            },
            limits: LimitsInfo {
                v_max: 10.0,
                a_max: 15.0,
            },
            start: [1.0, 1.0, 1.0],
            goal: [9.0, 9.0, 1.0],
            goal_tolerance: 0.5,
            static_shapes: vec![
                StaticShape::Sphere {
                    center: [5.0, 5.0, 1.0],
                    radius: 1.0,
                },
                StaticShape::Cylinder {
                    center: [2.0, 8.0],
                    radius: 0.5,
                    z_min: 0.0,
                    z_max: 5.0,
                },
                StaticShape::Box {
                    min: [7.0, 1.0, 0.0],
                    max: [8.0, 2.0, 3.0],
                },
            ],
            static_points_file: None,
            obstacles: vec![ObstacleInfo {
                id: 0,
                shape: ObstacleKind::Cylinder,
                radius: 0.4,
                half_height: Some(1.5),
                half_extents: None,
            }],
            sim: None,
        }
    }

    #[test]
    fn the_header_serializes_as_in_the_contract() {
        let json = serde_json::to_value(Record::Header(header())).unwrap();
        assert_eq!(json["type"], "header");
        assert_eq!(json["schema"], SCHEMA);
        assert_eq!(json["static_shapes"][0]["sphere"]["radius"], 1.0);
        assert_eq!(json["static_shapes"][1]["cylinder"]["z_max"], 5.0);
        assert_eq!(json["static_shapes"][2]["box"]["min"][0], 7.0);
        assert_eq!(json["obstacles"][0]["shape"], "cylinder");
        assert_eq!(json["obstacles"][0]["half_height"], 1.5);
        assert!(json["static_points_file"].is_null());
        let outcome = Record::Outcome(Outcome {
            status: Status::Collided,
            t: 1.0,
            flight_time_s: 1.0,
            path_length_m: 2.0,
            min_clearance_static_m: -0.1,
            min_clearance_dynamic_m: 1.0,
            max_speed: 2.0,
            max_accel: 1.0,
            with: Some("static".into()),
            reason: None,
            cycle_count: 10,
            forecast_warning_s: None,
        });
        let json = serde_json::to_value(outcome).unwrap();
        assert_eq!(json["status"], "collided");
        assert_eq!(json["with"], "static");
        let timed_out = serde_json::to_value(Status::TimedOut).unwrap();
        assert_eq!(timed_out, "timed_out");
    }

    fn cycle(t: f64) -> CycleRecord {
        CycleRecord {
            frontend_ms: 0.5,
            backend_ms: 0.75,
            checker_ms: 0.25,
            solve_count: 2,
            effective_t: t + 0.1,
            branch_j: vec![1.0, 2.0],
            ..CycleRecord::bare(t, 1.5, Some(3), 2, vec!["switched".into()])
        }
    }

    #[test]
    fn a_planned_route_round_trips_and_is_absent_otherwise() {
        let mut c = cycle(0.0);
        assert!(!serde_json::to_string(&c).unwrap().contains("route"));
        c.route = Some(vec![[0.0, 0.0, 1.0], [5.0, 2.0, 1.0], [9.0, 0.0, 1.5]]);
        c.route_ms = Some(0.8);
        let text = serde_json::to_string(&c).unwrap();
        let back: CycleRecord = serde_json::from_str(&text).unwrap();
        assert_eq!(back, c);
    }

    #[test]
    fn branch_samples_and_forecasts_round_trip_and_stay_absent_when_off() {
        let mut c = cycle(1.0);
        let off = serde_json::to_string(&Record::Cycle(c.clone())).unwrap();
        assert!(
            !off.contains("branch_samples") && !off.contains("forecasts"),
            "{off}"
        );
        c.branch_samples = Some(vec![
            BranchSamples {
                id: 3,
                samples: vec![[1.0, 0.1, 0.2, 1.0], [1.2, 0.3, 0.2, 1.0]],
            },
            BranchSamples {
                id: 1,
                samples: vec![[1.0, 0.1, 0.2, 1.0]],
            },
        ]);
        c.forecasts = Some(vec![
            ForecastRecord {
                id: 0,
                p0: [4.0, 4.0, 1.5],
                v0: [0.5, -0.25, 0.0],
                t0: 1.0,
                r0: 0.6,
                mu: 0.3,
                shape: ForecastShape::Cylinder { half_height: 1.7 },
                growth_s: Some(1.0),
                walls: Some([[2.0, 0.0, 0.0], [8.0, 6.0, 3.0]]),
            },
            ForecastRecord {
                id: 2,
                p0: [1.0, 2.0, 3.0],
                v0: [0.0; 3],
                t0: 1.0,
                r0: 0.5,
                mu: 0.0,
                shape: ForecastShape::Sphere,
                growth_s: None,
                walls: None,
            },
        ]);
        let on = serde_json::to_string(&Record::Cycle(c.clone())).unwrap();
        let back: Record = serde_json::from_str(&on).unwrap();
        assert_eq!(back, Record::Cycle(c.clone()));
        let json: serde_json::Value = serde_json::from_str(&on).unwrap();
        assert_eq!(json["branch_samples"][0]["samples"][1][0], 1.2);
        assert_eq!(
            json["forecasts"][0]["shape"]["cylinder"]["half_height"],
            1.7
        );
        assert_eq!(json["forecasts"][1]["shape"], "sphere");
        assert_eq!(json["forecasts"][0]["growth_s"], 1.0);
        assert!(json["forecasts"][1].get("growth_s").is_none());
        // A non-finite sample is refused.
        let dir = std::env::temp_dir().join(format!("trust-runlog-nf-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut w = LogWriter::create(&dir.join("run.jsonl")).unwrap();
        c.branch_samples.as_mut().unwrap()[1].samples[0][2] = f64::INFINITY;
        let e = w.write(&Record::Cycle(c)).unwrap_err().to_string();
        assert!(e.contains("sample 0 of branch 1"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn a_forecast_grows_until_its_growth_stop_and_without_one_for_ever() {
        let old =
            r#"{"id":1,"p0":[0,0,1],"v0":[1,0,0],"t0":2.0,"r0":0.5,"mu":0.25,"shape":"sphere"}"#;
        let mut f: ForecastRecord = serde_json::from_str(old).unwrap();
        assert_eq!(f.growth_s, None);
        assert_eq!(f.radius_at(1.0), 0.5);
        assert_eq!(f.radius_at(6.0), 1.5);
        assert_eq!(f.centre_at(3.5), [1.5, 0.0, 1.0]);
        assert_eq!(f.centre_at(1.0), [0.0, 0.0, 1.0]);
        f.growth_s = Some(1.0);
        assert_eq!(f.radius_at(2.5), 0.625);
        assert_eq!(f.radius_at(6.0), 0.75);
        assert_eq!(f.growth_at(6.0), 0.25);
    }

    #[test]
    fn a_cycle_line_written_before_issue_20_still_reads() {
        let old = r#"{"type":"cycle","t":0.1,"wall_ms":2.0,"main":1,"branches":1,"events":["added"],"frontend_ms":1.0,"backend_ms":0.5,"checker_ms":0.1,"solve_count":1,"effective_t":0.2,"branch_j":[3.5]}"#;
        let Record::Cycle(c) = serde_json::from_str::<Record>(old).unwrap() else {
            panic!("not a cycle");
        };
        assert_eq!(c.branch_samples, None);
        assert_eq!(c.forecasts, None);
        assert_eq!(c.branch_j, vec![3.5]);
    }

    #[test]
    fn a_log_round_trips_and_bad_structure_is_named() {
        let dir = std::env::temp_dir().join(format!("trust-runlog-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("run.jsonl");
        let mut w = LogWriter::create(&path).unwrap();
        w.write(&Record::Header(header())).unwrap();
        let state = |t: f64| StateRecord {
            t,
            p: [1.0 + t, 1.0, 1.0],
            v: [1.0 / 3.0, 0.0, 0.0],
            a: [0.0, 0.1, 0.0],
            obstacles: vec![[4.0, 4.0, 1.5]],
        };
        w.write(&Record::State(state(0.0))).unwrap();
        w.write(&Record::State(state(0.02))).unwrap();
        let mut bad = state(0.03);
        bad.p[0] = f64::NAN;
        assert!(matches!(
            w.write(&Record::State(bad)),
            Err(LogError::NonFinite { .. })
        ));
        let outcome = Outcome {
            status: Status::TimedOut,
            t: 0.02,
            flight_time_s: 0.02,
            path_length_m: 0.02,
            min_clearance_static_m: 1.0,
            min_clearance_dynamic_m: 1.0,
            max_speed: 1.0 / 3.0,
            max_accel: 0.1,
            with: None,
            reason: None,
            cycle_count: 0,
            forecast_warning_s: None,
        };
        w.write(&Record::Outcome(outcome.clone())).unwrap();
        w.finish().unwrap();
        let log = RunLog::read(&path).unwrap();
        assert_eq!(log.header, header());
        assert_eq!(log.states.len(), 2);
        assert_eq!(log.states[0].v[0], 1.0 / 3.0, "shortest round-trip floats");
        assert_eq!(log.outcome, outcome);

        // A state too late after the previous one, and a missing outcome.
        let text = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        let gap = format!(
            "{}\n{}\n{}\n",
            lines[0],
            lines[1],
            lines[2].replace("0.02", "0.5")
        );
        std::fs::write(&path, gap).unwrap();
        let e = RunLog::read(&path).unwrap_err().to_string();
        assert!(e.contains(":3:") && e.contains("0.02 s"), "{e}");
        std::fs::write(&path, format!("{}\n{}\n", lines[0], lines[1])).unwrap();
        let e = RunLog::read(&path).unwrap_err().to_string();
        assert!(e.contains("no outcome"), "{e}");
        std::fs::write(&path, format!("{}\n{}\n", lines[1], lines[0])).unwrap();
        let e = RunLog::read(&path).unwrap_err().to_string();
        assert!(e.contains(":1:"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
