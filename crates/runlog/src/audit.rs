//! An independent check of a run log: recomputes collisions, clearances, limits, path length and
//! arrival from the `header` and `state` records alone and compares them with the `outcome`
//! record, as the contract's external checker does (clearances within 0.02 m, maxima within 1 %).
//!
//! It deliberately shares no geometry code with the simulator: the distance functions below are
//! written out again from their closed forms, so a bug in `trust-geometry` cannot hide itself.
//! `trust-sim audit LOG` runs it from the command line ([`audit_file`], streaming: an hour's log
//! is audited in the memory of one line plus the static points).
//!
//! # What it checks, in order
//!
//! 1. **Values within the audit's policy** before any arithmetic, so no norm can overflow and no
//!    tolerance can become infinite: every coordinate (positions, obstacle centres, bounds,
//!    shapes, points) at most [`MAX_COORDINATE_M`] in magnitude, every velocity component at
//!    most [`MAX_SPEED_M_S`], every acceleration component at most [`MAX_ACCEL_M_S2`], times
//!    within [`MAX_TIME_S`], sizes finite and non-negative. (Times strictly increasing with steps
//!    ≤ 0.02 s are the reader's check, [`crate::LogReader`].) A state outside the policy is a
//!    finding and is left out of the figures (its norms are never taken).
//! 2. **Consistency of consecutive states** (a teleport, a forged velocity): the position step
//!    must match the trapezoid of the logged velocities, `|Δp − ½(v₀ + v₁)·dt| ≤`
//!    [`POSITION_STEP_TOLERANCE_M`], and the velocity step the trapezoid of the logged
//!    accelerations, `|Δv − ½(a₀ + a₁)·dt| ≤` [`VELOCITY_STEP_TOLERANCE_M_S`]. The simulator's
//!    logs stay within 2·10⁻⁵ m and 1.2·10⁻³ m/s (quickstart, E4, pedestrians, either vehicle
//!    model), so the tolerances leave a wide margin; a state moved by more than 1 cm, or given a
//!    velocity off by more than 5 cm/s, is flagged (at the step into it and the step out of it).
//! 3. **The outcome against the recomputed figures**, with absolute tolerances: clearances within
//!    [`CLEARANCE_TOLERANCE_M`], maxima within [`MAXIMA_TOLERANCE`] of the (policy-bounded, so
//!    finite) recomputed value, path length within 10⁻³ of it (at least 1 mm), times within 1 µs.
//!    Without geometry of a kind the recomputed clearance is `+∞` and the log must hold at least
//!    [`NO_GEOMETRY_CLEARANCE_M`].
//! 4. Optionally ([`AuditOptions::cycles`], `trust-sim audit --cycles`), **the cycle records
//!    against the contract**: every cycle has `t`, `wall_ms`, `main` (a number or `null`),
//!    `branches` and `events` (a missing field other than `main` is already the reader's parse
//!    error); `wall_ms` is finite and ≥ 0; `t` lies within the flight (first to last state).
//!
//! Findings are listed at most [`MAX_LISTED_FINDINGS`] per field, then counted ("… and 17 more");
//! numbers in them are [`readable`].
//!
//! Static point clouds are indexed by a k-d tree ([`PointTree`]), so a state costs `O(log m)`
//! for `m` points whatever the distance to the nearest one.

use std::collections::BTreeMap;
use std::path::Path;

use serde::Deserialize;

use crate::files::{read_points, readable, resolve_points_file};
use crate::{
    CycleRecord, Header, LogError, LogReader, ObstacleKind, Outcome, PointTree, Record, RunLog,
    StateRecord, StaticShape, Status,
};

/// Clearance tolerance of the contract (m).
pub const CLEARANCE_TOLERANCE_M: f64 = 0.02;
/// Relative tolerance of the contract on maxima.
pub const MAXIMA_TOLERANCE: f64 = 0.01;
pub use crate::files::MAX_COORDINATE_M;
/// Largest magnitude of a velocity component the audit accepts (m/s).
pub const MAX_SPEED_M_S: f64 = 1e4;
/// Largest magnitude of an acceleration component the audit accepts (m/s²).
pub const MAX_ACCEL_M_S2: f64 = 1e5;
/// Largest magnitude of a time the audit accepts (s): about 115 days.
pub const MAX_TIME_S: f64 = 1e7;
/// Largest gap between a position step and the trapezoid of the logged velocities (m).
pub const POSITION_STEP_TOLERANCE_M: f64 = 0.01;
/// Largest gap between a velocity step and the trapezoid of the logged accelerations (m/s).
pub const VELOCITY_STEP_TOLERANCE_M_S: f64 = 0.05;
/// Without geometry of a kind, the logged clearance must be at least this (m; the simulator
/// writes `1e9`).
pub const NO_GEOMETRY_CLEARANCE_M: f64 = 1e6;
/// Findings listed per field; the rest are counted.
pub const MAX_LISTED_FINDINGS: usize = 20;

/// What the states say.
#[derive(Debug, Clone, PartialEq)]
pub struct Recomputed {
    /// The status the states imply.
    pub status: Status,
    /// For a collision: `"static"` or `"obstacle:<id>"`, at the first state with a negative
    /// clearance.
    pub with: Option<String>,
    /// Time of the first collision, if any.
    pub collision_t: Option<f64>,
    /// Smallest static clearance (m, `+∞` without static geometry).
    pub min_clearance_static_m: f64,
    /// Smallest dynamic clearance (m, `+∞` without moving obstacles).
    pub min_clearance_dynamic_m: f64,
    /// Largest `|v|`.
    pub max_speed: f64,
    /// Largest `|a|`.
    pub max_accel: f64,
    /// Sum of distances between consecutive positions.
    pub path_length_m: f64,
    /// Last state time minus first.
    pub flight_time_s: f64,
}

/// A disagreement between the log and what the audit recomputes or requires.
#[derive(Debug, Clone, PartialEq)]
pub struct Finding {
    /// The outcome field (`max_speed`), or the check (`state.v`, `state.teleport`, `header`,
    /// `cycle.wall_ms`).
    pub field: &'static str,
    /// What the log says.
    pub logged: String,
    /// What the states say, or what the policy requires.
    pub recomputed: String,
}

impl std::fmt::Display for Finding {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.field.contains('.') || self.field == "header" {
            write!(f, "{}: {} — {}", self.field, self.logged, self.recomputed)
        } else {
            write!(
                f,
                "{}: logged {}, states say {}",
                self.field, self.logged, self.recomputed
            )
        }
    }
}

/// The audit of one log.
#[derive(Debug, Clone, PartialEq)]
pub struct Audit {
    /// The recomputed figures.
    pub recomputed: Recomputed,
    /// Disagreements (empty: the log is consistent).
    pub findings: Vec<Finding>,
    /// The outcome's status as logged.
    pub logged_status: Status,
    /// State records audited.
    pub state_count: usize,
    /// Cycle records read.
    pub cycle_count: usize,
}

impl Audit {
    /// Whether the outcome agrees with the states.
    pub fn passed(&self) -> bool {
        self.findings.is_empty()
    }
}

/// What to check beyond the outcome.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct AuditOptions {
    /// Also check the cycle records against the contract (module docs, step 4).
    pub cycles: bool,
}

fn norm(v: &[f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

fn dist(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    norm(&[a[0] - b[0], a[1] - b[1], a[2] - b[2]])
}

/// Signed distance to a vertical cylinder (axis `(cx, cy)`, radius `r`, from `z0` to `z1`).
fn vertical_cylinder(p: &[f64; 3], cx: f64, cy: f64, r: f64, z0: f64, z1: f64) -> f64 {
    let radial = ((p[0] - cx).powi(2) + (p[1] - cy).powi(2)).sqrt() - r;
    let axial = (z0 - p[2]).max(p[2] - z1);
    if radial > 0.0 && axial > 0.0 {
        (radial * radial + axial * axial).sqrt()
    } else {
        radial.max(axial)
    }
}

/// Signed distance to an axis-aligned box.
fn aligned_box(p: &[f64; 3], min: &[f64; 3], max: &[f64; 3]) -> f64 {
    let mut outside = 0.0;
    let mut inside = f64::NEG_INFINITY;
    for k in 0..3 {
        let c = 0.5 * (min[k] + max[k]);
        let h = 0.5 * (max[k] - min[k]);
        let q = (p[k] - c).abs() - h;
        outside += q.max(0.0).powi(2);
        inside = inside.max(q);
    }
    if inside > 0.0 { outside.sqrt() } else { inside }
}

fn static_distance(p: &[f64; 3], shape: &StaticShape) -> f64 {
    match *shape {
        StaticShape::Sphere { center, radius } => dist(p, &center) - radius,
        StaticShape::Cylinder {
            center,
            radius,
            z_min,
            z_max,
        } => vertical_cylinder(p, center[0], center[1], radius, z_min, z_max),
        StaticShape::Box { min, max } => aligned_box(p, &min, &max),
    }
}

/// The true geometry of a log, for clearances: its header's shapes and obstacles and its static
/// points (indexed).
#[derive(Debug, Clone)]
pub struct TrueGeometry {
    header: Header,
    points: Option<PointTree>,
}

impl TrueGeometry {
    /// The geometry of a log with `header`, read from a file in `log_dir` (which resolves its
    /// `static_points_file` under [`crate::files`]' policy).
    ///
    /// # Errors
    /// A message naming the points file (and the line) if it is refused or cannot be read.
    pub fn new(header: &Header, log_dir: &Path) -> Result<Self, String> {
        Ok(Self::with_points(header, read_log_points(header, log_dir)?))
    }

    /// The geometry of a log with `header` and the static `points` its points file holds
    /// (read with [`read_log_points`]).
    pub fn with_points(header: &Header, points: Option<Vec<[f64; 3]>>) -> Self {
        TrueGeometry {
            header: header.clone(),
            points: points.map(PointTree::new),
        }
    }
}

/// The static points of a log with `header` in `log_dir`: its `static_points_file` resolved
/// under [`crate::files`]' policy and read ([`read_points`]); `None` when it names none.
///
/// # Errors
/// A message naming the points file (and the line) if it is refused or cannot be read.
pub fn read_log_points(header: &Header, log_dir: &Path) -> Result<Option<Vec<[f64; 3]>>, String> {
    match &header.static_points_file {
        Some(f) => Ok(Some(read_points(&resolve_points_file(log_dir, f)?)?)),
        None => Ok(None),
    }
}

impl TrueGeometry {
    /// The static and dynamic clearances at state `s` (m, vehicle radius subtracted; `+∞`
    /// without geometry of that kind), and the nearest moving obstacle's id.
    pub fn clearances(&self, s: &StateRecord) -> (f64, f64, usize) {
        clearance_at(&self.header, self.points.as_ref(), s)
    }
}

/// Reads the `x y z` points of a log's `static_points_file` ([`crate::files::read_points`]).
///
/// # Errors
/// A message naming the file and line.
pub fn read_static_points(path: &Path) -> Result<Vec<[f64; 3]>, String> {
    read_points(path)
}

/// The static and dynamic clearances of the vehicle in state `s` (minus its radius), and the
/// nearest moving obstacle's id.
fn clearance_at(h: &Header, points: Option<&PointTree>, s: &StateRecord) -> (f64, f64, usize) {
    let radius = h.vehicle.radius;
    let mut static_c = h
        .static_shapes
        .iter()
        .map(|shape| static_distance(&s.p, shape) - radius)
        .fold(f64::INFINITY, f64::min);
    if let Some(t) = points {
        static_c = static_c.min(t.nearest_distance(&s.p) - radius);
    }
    let (mut dynamic_c, mut nearest) = (f64::INFINITY, 0);
    for (info, c) in h.obstacles.iter().zip(&s.obstacles) {
        let d = match info.shape {
            ObstacleKind::Sphere => dist(&s.p, c) - info.radius,
            ObstacleKind::Cylinder => {
                let hh = info.half_height.unwrap_or(0.0);
                vertical_cylinder(&s.p, c[0], c[1], info.radius, c[2] - hh, c[2] + hh)
            }
            ObstacleKind::Box => {
                let e = info.half_extents.unwrap_or([0.0; 3]);
                let min = [c[0] - e[0], c[1] - e[1], c[2] - e[2]];
                let max = [c[0] + e[0], c[1] + e[1], c[2] + e[2]];
                aligned_box(&s.p, &min, &max)
            }
        } - radius;
        if d < dynamic_c {
            dynamic_c = d;
            nearest = info.id;
        }
    }
    (static_c, dynamic_c, nearest)
}

/// The clearances at every state of `log`, `[static, dynamic]` (m, vehicle radius subtracted;
/// `+∞` without geometry of that kind), with the audit's own distance formulas; `log_dir`
/// resolves `static_points_file`.
///
/// # Errors
/// A message if the points file is refused or cannot be read.
pub fn state_clearances(log: &RunLog, log_dir: &Path) -> Result<Vec<[f64; 2]>, String> {
    let g = TrueGeometry::new(&log.header, log_dir)?;
    Ok(log
        .states
        .iter()
        .map(|s| {
            let (st, dy, _) = g.clearances(s);
            [st, dy]
        })
        .collect())
}

fn vec3(v: &[f64; 3]) -> String {
    format!(
        "[{}, {}, {}]",
        readable(v[0]),
        readable(v[1]),
        readable(v[2])
    )
}

fn within(xs: &[f64], bound: f64) -> bool {
    xs.iter().all(|x| x.is_finite() && x.abs() <= bound)
}

/// Why the header is outside the audit's policy, if it is.
fn header_problem(h: &Header) -> Option<String> {
    let c = MAX_COORDINATE_M;
    let size = |x: f64| x.is_finite() && (0.0..=c).contains(&x);
    if !within(&h.bounds.min, c) || !within(&h.bounds.max, c) {
        return Some(format!(
            "bounds {} to {}",
            vec3(&h.bounds.min),
            vec3(&h.bounds.max)
        ));
    }
    if !within(&h.start, c) || !within(&h.goal, c) {
        return Some(format!(
            "start {} or goal {}",
            vec3(&h.start),
            vec3(&h.goal)
        ));
    }
    if !size(h.goal_tolerance) || !size(h.vehicle.radius) {
        return Some(format!(
            "goal_tolerance {} or vehicle radius {}",
            readable(h.goal_tolerance),
            readable(h.vehicle.radius)
        ));
    }
    for (i, shape) in h.static_shapes.iter().enumerate() {
        let ok = match *shape {
            StaticShape::Sphere { center, radius } => within(&center, c) && size(radius),
            StaticShape::Cylinder {
                center,
                radius,
                z_min,
                z_max,
            } => within(&center, c) && size(radius) && within(&[z_min, z_max], c),
            StaticShape::Box { min, max } => within(&min, c) && within(&max, c),
        };
        if !ok {
            return Some(format!("static shape {i}"));
        }
    }
    for o in &h.obstacles {
        let ok = size(o.radius)
            && o.half_height.is_none_or(size)
            && o.half_extents.is_none_or(|e| e.iter().all(|&x| size(x)));
        if !ok {
            return Some(format!("the size of obstacle {}", o.id));
        }
    }
    None
}

/// Why state `s` is outside the audit's policy, if it is: the check's name and what is wrong.
fn state_problem(s: &StateRecord) -> Option<(&'static str, String)> {
    if !(s.t.is_finite() && s.t.abs() <= MAX_TIME_S) {
        return Some(("state.t", format!("t = {}", readable(s.t))));
    }
    if !within(&s.p, MAX_COORDINATE_M) {
        return Some(("state.p", format!("p = {}", vec3(&s.p))));
    }
    if !within(&s.v, MAX_SPEED_M_S) {
        return Some(("state.v", format!("v = {}", vec3(&s.v))));
    }
    if !within(&s.a, MAX_ACCEL_M_S2) {
        return Some(("state.a", format!("a = {}", vec3(&s.a))));
    }
    if let Some(i) = s
        .obstacles
        .iter()
        .position(|o| !within(o, MAX_COORDINATE_M))
    {
        return Some((
            "state.obstacles",
            format!("obstacle {i} at {}", vec3(&s.obstacles[i])),
        ));
    }
    None
}

fn policy_of(field: &str) -> String {
    match field {
        "state.t" => format!("a time within ±{} s", readable(MAX_TIME_S)),
        "state.v" => format!(
            "velocity components within ±{} m/s (the audit's policy)",
            readable(MAX_SPEED_M_S)
        ),
        "state.a" => format!(
            "acceleration components within ±{} m/s² (the audit's policy)",
            readable(MAX_ACCEL_M_S2)
        ),
        _ => format!(
            "coordinates within ±{} m (the audit's policy)",
            readable(MAX_COORDINATE_M)
        ),
    }
}

/// The keys of a cycle line whose absence the record type cannot tell (`main` reads as `None`
/// when absent).
#[derive(Deserialize)]
struct CycleKeys {
    #[serde(default, deserialize_with = "present")]
    main: Option<()>,
}

fn present<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Option<()>, D::Error> {
    serde::de::IgnoredAny::deserialize(d)?;
    Ok(Some(()))
}

/// The last in-policy state, for the consistency checks.
#[derive(Debug, Clone, Copy)]
struct Previous {
    index: usize,
    t: f64,
    p: [f64; 3],
    v: [f64; 3],
    a: [f64; 3],
}

/// The audit, fed one record at a time (so that a log can be streamed).
struct Auditor<'a> {
    header: &'a Header,
    geometry: TrueGeometry,
    options: AuditOptions,
    r: Recomputed,
    findings: Vec<Finding>,
    counts: BTreeMap<&'static str, usize>,
    previous: Option<Previous>,
    first_t: Option<f64>,
    last: Option<(f64, [f64; 3])>,
    state_count: usize,
    cycle_count: usize,
    /// Cycles later than the last state read so far: (index, t); checked at the end.
    late_cycles: Vec<(usize, f64)>,
    late_cycle_count: usize,
}

impl<'a> Auditor<'a> {
    fn new(header: &'a Header, log_dir: &Path, options: AuditOptions) -> Result<Self, String> {
        let mut a = Auditor {
            header,
            geometry: TrueGeometry {
                header: header.clone(),
                points: None,
            },
            options,
            r: Recomputed {
                status: Status::TimedOut,
                with: None,
                collision_t: None,
                min_clearance_static_m: f64::INFINITY,
                min_clearance_dynamic_m: f64::INFINITY,
                max_speed: 0.0,
                max_accel: 0.0,
                path_length_m: 0.0,
                flight_time_s: 0.0,
            },
            findings: Vec::new(),
            counts: BTreeMap::new(),
            previous: None,
            first_t: None,
            last: None,
            state_count: 0,
            cycle_count: 0,
            late_cycles: Vec::new(),
            late_cycle_count: 0,
        };
        if let Some(problem) = header_problem(header) {
            a.flag(
                "header",
                problem,
                format!(
                    "finite sizes ≥ 0 and coordinates within ±{} m (the audit's policy)",
                    readable(MAX_COORDINATE_M)
                ),
            );
        } else {
            a.geometry = TrueGeometry::new(header, log_dir)?;
        }
        Ok(a)
    }

    fn flag(&mut self, field: &'static str, logged: String, recomputed: String) {
        let n = self.counts.entry(field).or_insert(0);
        *n += 1;
        if *n <= MAX_LISTED_FINDINGS {
            self.findings.push(Finding {
                field,
                logged,
                recomputed,
            });
        }
    }

    fn state(&mut self, s: &StateRecord) {
        let index = self.state_count;
        self.state_count += 1;
        let at = |s: &StateRecord| format!("state {index} (t = {} s)", readable(s.t));
        if self.first_t.is_none() {
            self.first_t = Some(s.t);
        }
        if let Some((field, problem)) = state_problem(s) {
            self.flag(field, format!("{}: {problem}", at(s)), policy_of(field));
            // Left out of the figures; the next state is not compared with it.
            self.previous = None;
            self.last = Some((s.t, [f64::NAN; 3]));
            return;
        }
        if let Some(prev) = self.previous {
            let dt = s.t - prev.t;
            let step = |x: &[f64; 3], x0: &[f64; 3], d: &[f64; 3], d0: &[f64; 3]| {
                norm(&[
                    x[0] - x0[0] - 0.5 * (d[0] + d0[0]) * dt,
                    x[1] - x0[1] - 0.5 * (d[1] + d0[1]) * dt,
                    x[2] - x0[2] - 0.5 * (d[2] + d0[2]) * dt,
                ])
            };
            let at = format!("{} after state {}", at(s), prev.index);
            let gap_p = step(&s.p, &prev.p, &s.v, &prev.v);
            if gap_p > POSITION_STEP_TOLERANCE_M {
                self.flag(
                    "state.teleport",
                    format!(
                        "{at}: moved {} m from {}, {} m off the logged velocities over {} s",
                        readable(dist(&s.p, &prev.p)),
                        vec3(&prev.p),
                        readable(gap_p),
                        readable(dt)
                    ),
                    format!(
                        "|Δp − ½(v₀ + v₁)·dt| ≤ {} m",
                        readable(POSITION_STEP_TOLERANCE_M)
                    ),
                );
            }
            let gap_v = step(&s.v, &prev.v, &s.a, &prev.a);
            if gap_v > VELOCITY_STEP_TOLERANCE_M_S {
                self.flag(
                    "state.velocity_step",
                    format!(
                        "{at}: v = {} after {}, {} m/s off the logged accelerations",
                        vec3(&s.v),
                        vec3(&prev.v),
                        readable(gap_v)
                    ),
                    format!(
                        "|Δv − ½(a₀ + a₁)·dt| ≤ {} m/s",
                        readable(VELOCITY_STEP_TOLERANCE_M_S)
                    ),
                );
            }
        }
        let r = &mut self.r;
        let (static_c, dynamic_c, nearest) = self.geometry.clearances(s);
        r.min_clearance_static_m = r.min_clearance_static_m.min(static_c);
        r.min_clearance_dynamic_m = r.min_clearance_dynamic_m.min(dynamic_c);
        r.max_speed = r.max_speed.max(norm(&s.v));
        r.max_accel = r.max_accel.max(norm(&s.a));
        if let Some((_, p)) = self.last
            && p.iter().all(|x| x.is_finite())
        {
            r.path_length_m += dist(&p, &s.p);
        }
        if r.collision_t.is_none() && (static_c < 0.0 || dynamic_c < 0.0) {
            r.collision_t = Some(s.t);
            let contact = if static_c <= dynamic_c {
                crate::Contact::Static
            } else {
                crate::Contact::Obstacle(nearest)
            };
            r.with = Some(contact.to_string());
        }
        self.previous = Some(Previous {
            index,
            t: s.t,
            p: s.p,
            v: s.v,
            a: s.a,
        });
        self.last = Some((s.t, s.p));
    }

    /// A cycle record; `line` is its text when read from a file (to see which keys it has).
    fn cycle(&mut self, c: &CycleRecord, line: Option<&str>) {
        let index = self.cycle_count;
        self.cycle_count += 1;
        if !self.options.cycles {
            return;
        }
        let at = format!("cycle {index} (t = {} s)", readable(c.t));
        if let Some(text) = line
            && serde_json::from_str::<CycleKeys>(text).is_ok_and(|k| k.main.is_none())
        {
            self.flag(
                "cycle.main",
                format!("{at}: no `main`"),
                "`main`: the main branch id, or null while braking".into(),
            );
        }
        if !(c.wall_ms.is_finite() && c.wall_ms >= 0.0) {
            self.flag(
                "cycle.wall_ms",
                format!("{at}: wall_ms = {}", readable(c.wall_ms)),
                "a finite wall time ≥ 0 ms".into(),
            );
        }
        let first = self.first_t.unwrap_or(f64::INFINITY);
        if !(c.t.is_finite() && c.t >= first - 1e-9) {
            self.flag(
                "cycle.t",
                format!("{at}: before the first state (t = {})", readable(first)),
                "a time within the flight".into(),
            );
        } else if c.t > self.last.map_or(f64::NEG_INFINITY, |l| l.0) + 1e-9 {
            // Judged at the end, against the last state.
            self.late_cycle_count += 1;
            if self.late_cycles.len() < MAX_LISTED_FINDINGS {
                self.late_cycles.push((index, c.t));
            }
        }
    }

    fn finish(mut self, o: &Outcome) -> Audit {
        let (first_t, (last_t, last_p)) = match (self.first_t, self.last) {
            (Some(f), Some(l)) => (f, l),
            _ => (0.0, (0.0, [f64::NAN; 3])),
        };
        if self.options.cycles {
            let late: Vec<(usize, f64)> = std::mem::take(&mut self.late_cycles)
                .into_iter()
                .filter(|&(_, t)| t > last_t + 1e-9)
                .collect();
            let listed = late.len();
            for (index, t) in late {
                self.flag(
                    "cycle.t",
                    format!(
                        "cycle {index} (t = {} s): after the last state (t = {})",
                        readable(t),
                        readable(last_t)
                    ),
                    "a time within the flight".into(),
                );
            }
            // The outcome counts the cycles it ran (0: a log from before the field); a
            // duplicated or dropped cycle line shows here.
            if o.cycle_count > 0 && o.cycle_count != self.cycle_count {
                self.flag(
                    "outcome.cycle_count",
                    format!("{} in the outcome", o.cycle_count),
                    format!("{} cycle records in the log", self.cycle_count),
                );
            }
            if listed == MAX_LISTED_FINDINGS && self.late_cycle_count > listed {
                // Some of the uncounted ones may be late too; say so rather than guess.
                self.flag(
                    "cycle.t",
                    format!(
                        "{} more cycles read before the states that reach them",
                        self.late_cycle_count - listed
                    ),
                    "not checked one by one".into(),
                );
            }
        }
        let mut r = self.r.clone();
        r.flight_time_s = last_t - first_t;
        r.status = if r.collision_t.is_some() {
            Status::Collided
        } else if last_p.iter().all(|x| x.is_finite())
            && dist(&last_p, &self.header.goal) <= self.header.goal_tolerance
        {
            Status::Arrived
        } else {
            Status::TimedOut
        };
        self.compare(o, &r, last_t);
        let mut findings = std::mem::take(&mut self.findings);
        for (field, n) in &self.counts {
            if *n > MAX_LISTED_FINDINGS {
                findings.push(Finding {
                    field,
                    logged: format!("… and {} more", n - MAX_LISTED_FINDINGS),
                    recomputed: "as above".into(),
                });
            }
        }
        Audit {
            recomputed: r,
            findings,
            logged_status: o.status,
            state_count: self.state_count,
            cycle_count: self.cycle_count,
        }
    }

    fn compare(&mut self, o: &Outcome, r: &Recomputed, last_t: f64) {
        let mut check = |field: &'static str, ok: bool, logged: f64, recomputed: String| {
            if !ok {
                self.flag(field, readable(logged), recomputed);
            }
        };
        // Every recomputed figure is finite (or +∞ for a clearance without geometry): the
        // policy bounds every value that enters it, so every tolerance below is finite.
        let close =
            |a: f64, b: f64, tol: f64| a.is_finite() && b.is_finite() && (a - b).abs() <= tol;
        check(
            "t",
            close(o.t, last_t, 1e-6),
            o.t,
            format!("{} (last state)", readable(last_t)),
        );
        check(
            "flight_time_s",
            close(o.flight_time_s, r.flight_time_s, 1e-6),
            o.flight_time_s,
            readable(r.flight_time_s),
        );
        check(
            "path_length_m",
            close(
                o.path_length_m,
                r.path_length_m,
                1e-3 * r.path_length_m.max(1.0),
            ),
            o.path_length_m,
            readable(r.path_length_m),
        );
        for (field, logged, recomputed) in [
            (
                "min_clearance_static_m",
                o.min_clearance_static_m,
                r.min_clearance_static_m,
            ),
            (
                "min_clearance_dynamic_m",
                o.min_clearance_dynamic_m,
                r.min_clearance_dynamic_m,
            ),
        ] {
            let ok = if recomputed == f64::INFINITY {
                logged.is_finite() && logged >= NO_GEOMETRY_CLEARANCE_M
            } else {
                close(logged, recomputed, CLEARANCE_TOLERANCE_M)
            };
            check(field, ok, logged, readable(recomputed));
        }
        for (field, logged, recomputed) in [
            ("max_speed", o.max_speed, r.max_speed),
            ("max_accel", o.max_accel, r.max_accel),
        ] {
            check(
                field,
                close(
                    logged,
                    recomputed,
                    MAXIMA_TOLERANCE * recomputed.abs() + 1e-9,
                ),
                logged,
                readable(recomputed),
            );
        }
        if o.status == Status::Unreachable {
            // The planner's verdict is not recomputable from the states; what is: the flight
            // ended neither in a collision nor at the goal.
            if r.status != Status::TimedOut {
                self.flag(
                    "status",
                    o.status.as_str().into(),
                    format!(
                        "{} (unreachable needs no collision and no arrival)",
                        r.status.as_str()
                    ),
                );
            }
        } else if o.status != Status::Invalid {
            if o.status != r.status {
                self.flag("status", o.status.as_str().into(), r.status.as_str().into());
            }
            if r.status == Status::Collided && o.with != r.with {
                self.flag("with", format!("{:?}", o.with), format!("{:?}", r.with));
            }
        }
    }
}

/// Recomputes the outcome of `log`; `log_dir` resolves `static_points_file`.
///
/// # Errors
/// A message if the points file is refused or cannot be read.
pub fn recompute(log: &RunLog, log_dir: &Path) -> Result<Recomputed, String> {
    Ok(audit(log, log_dir)?.recomputed)
}

/// Audits `log` (read from a file in `log_dir`): checks the values against the policy, the
/// consecutive states against each other, and the outcome record against the recomputed figures
/// (module docs), listing every disagreement. An `invalid` outcome is accepted as is (the run did
/// not fly as specified) but its figures are still compared; an `unreachable` one needs a flight
/// that ended neither in a collision nor at the goal.
///
/// # Errors
/// A message if the points file is refused or cannot be read.
pub fn audit(log: &RunLog, log_dir: &Path) -> Result<Audit, String> {
    audit_with(log, log_dir, AuditOptions::default())
}

/// [`audit`] with options ([`AuditOptions::cycles`]: a log in memory has no line text, so a
/// missing `main` cannot be told from `null` here; [`audit_file`] can).
///
/// # Errors
/// As [`audit`].
pub fn audit_with(log: &RunLog, log_dir: &Path, options: AuditOptions) -> Result<Audit, String> {
    let mut a = Auditor::new(&log.header, log_dir, options)?;
    // States and cycles in the log's order: a cycle after the state at its time.
    let mut cycles = log.cycles.iter().peekable();
    for s in &log.states {
        while let Some(c) = cycles.next_if(|c| c.t < s.t) {
            a.cycle(c, None);
        }
        a.state(s);
    }
    for c in cycles {
        a.cycle(c, None);
    }
    Ok(a.finish(&log.outcome))
}

/// Audits the run log at `path`, streaming it ([`LogReader`]): memory is one line plus the
/// static points, whatever the length of the flight.
///
/// # Errors
/// [`LogError`] for a log that cannot be read or breaks the contract's structure, and
/// [`LogError::Points`] for a points file that is refused or cannot be read.
pub fn audit_file(path: &Path, options: AuditOptions) -> Result<Audit, LogError> {
    let mut reader = LogReader::open(path)?.light_cycles();
    let header = reader.header().clone();
    let log_dir = path.parent().unwrap_or(Path::new("."));
    let mut a =
        Auditor::new(&header, log_dir, options).map_err(|message| LogError::Points { message })?;
    let mut outcome = None;
    while let Some(record) = reader.next_record()? {
        match record {
            Record::State(s) => a.state(&s),
            Record::Cycle(c) => a.cycle(&c, Some(reader.line())),
            Record::Outcome(o) => outcome = Some(o),
            Record::Header(_) => {}
        }
    }
    let outcome = outcome.ok_or_else(|| LogError::Structure {
        path: path.to_path_buf(),
        message: "no outcome (the run did not finish)".into(),
    })?;
    Ok(a.finish(&outcome))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Record;

    #[test]
    fn closed_forms() {
        // Cylinder: outside radially, above, at the rim, inside.
        let c = |p: [f64; 3]| vertical_cylinder(&p, 0.0, 0.0, 1.0, 0.0, 2.0);
        assert!((c([3.0, 0.0, 1.0]) - 2.0).abs() < 1e-12);
        assert!((c([0.0, 0.0, 5.0]) - 3.0).abs() < 1e-12);
        assert!((c([4.0, 0.0, 6.0]) - 5.0).abs() < 1e-12);
        assert!((c([0.5, 0.0, 1.0]) + 0.5).abs() < 1e-12);
        // Box: outside a corner, inside.
        let b = |p: [f64; 3]| aligned_box(&p, &[0.0; 3], &[2.0, 2.0, 2.0]);
        assert!((b([5.0, 6.0, 1.0]) - 5.0).abs() < 1e-12);
        assert!((b([1.0, 1.0, 1.5]) + 0.5).abs() < 1e-12);
    }

    /// A log with one moving box: the audit measures the box itself, not a sphere or cylinder
    /// around it (a point diagonally off a corner is clear of the box but inside its
    /// circumscribing cylinder), and names the collision when the vehicle enters it.
    #[test]
    fn audit_measures_a_moving_box() {
        let line = r#"{"type":"header","schema":"trust-sim-log/1","scenario":"box","seed":0,
            "planner":"trust","bounds":{"min":[0,0,0],"max":[10,10,3]},"vehicle":{"radius":0.3},
            "limits":{"v_max":2,"a_max":3},"start":[6.3,6.3,1],"goal":[9,9,1],
            "goal_tolerance":0.2,"static_shapes":[],"static_points_file":null,
            "obstacles":[{"id":0,"shape":"box","radius":1.4142135623730951,
            "half_extents":[1,1,1]}]}"#
            .replace('\n', "");
        let Record::Header(header) = serde_json::from_str::<Record>(&line).unwrap() else {
            panic!("a header");
        };
        let state = |t: f64, p: [f64; 3], box_x: f64| StateRecord {
            t,
            p,
            v: [0.0; 3],
            a: [0.0; 3],
            obstacles: vec![[box_x, 5.0, 1.0]],
        };
        let clear = state(0.0, [6.3, 6.3, 1.0], 5.0);
        let outcome = |status, with: Option<&str>, t, min_dyn| crate::Outcome {
            status,
            t,
            flight_time_s: t,
            path_length_m: 0.0,
            min_clearance_static_m: 1e9,
            min_clearance_dynamic_m: min_dyn,
            max_speed: 0.0,
            max_accel: 0.0,
            with: with.map(str::to_string),
            reason: None,
            cycle_count: 0,
            forecast_warning_s: None,
        };
        let corner = 0.3f64.hypot(0.3) - 0.3;
        let log = RunLog {
            header: header.clone(),
            states: vec![clear.clone()],
            cycles: Vec::new(),
            outcome: outcome(Status::TimedOut, None, 0.0, corner),
        };
        let a = audit(&log, Path::new(".")).unwrap();
        assert!(a.passed(), "{:?}", a.findings);
        assert!((a.recomputed.min_clearance_dynamic_m - corner).abs() < 1e-12);
        // The box moves 0.1 m towards +x: the vehicle is now 0.2 m from its face, 0.1 m inside
        // its radius.
        let log = RunLog {
            header,
            // The vehicle moves 1.3 m in 0.02 s, and its logged velocity says so (the audit
            // checks that positions follow the velocities).
            states: vec![
                StateRecord {
                    v: [0.0, -65.0, 0.0],
                    ..clear
                },
                StateRecord {
                    v: [0.0, -65.0, 0.0],
                    ..state(0.02, [6.3, 5.0, 1.0], 5.1)
                },
            ],
            cycles: Vec::new(),
            outcome: crate::Outcome {
                path_length_m: 1.3,
                max_speed: 65.0,
                ..outcome(Status::Collided, Some("obstacle:0"), 0.02, -0.1)
            },
        };
        let a = audit(&log, Path::new(".")).unwrap();
        assert!(a.passed(), "{:?}", a.findings);
        assert_eq!(a.recomputed.with.as_deref(), Some("obstacle:0"));
        assert!((a.recomputed.min_clearance_dynamic_m + 0.1).abs() < 1e-12);
    }
}
