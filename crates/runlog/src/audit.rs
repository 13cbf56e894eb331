//! An independent check of a run log: recomputes collisions, clearances, limits, path length and
//! arrival from the `header` and `state` records alone and compares them with the `outcome`
//! record, as the contract's external checker does (clearances within 0.02 m, maxima within 1 %).
//!
//! It deliberately shares no geometry code with the simulator: the distance functions below are
//! written out again from their closed forms, so a bug in `trust-geometry` cannot hide itself.
//! `trust-sim audit LOG` runs it from the command line.

use std::path::Path;

use crate::{Header, ObstacleKind, RunLog, StateRecord, StaticShape, Status};

/// Clearance tolerance of the contract (m).
pub const CLEARANCE_TOLERANCE_M: f64 = 0.02;
/// Relative tolerance of the contract on maxima.
pub const MAXIMA_TOLERANCE: f64 = 0.01;

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

/// A disagreement between the outcome record and the states.
#[derive(Debug, Clone, PartialEq)]
pub struct Finding {
    /// The outcome field.
    pub field: &'static str,
    /// What the outcome says.
    pub logged: String,
    /// What the states say.
    pub recomputed: String,
}

/// The audit of one log.
#[derive(Debug, Clone, PartialEq)]
pub struct Audit {
    /// The recomputed figures.
    pub recomputed: Recomputed,
    /// Disagreements (empty: the log is consistent).
    pub findings: Vec<Finding>,
}

impl Audit {
    /// Whether the outcome agrees with the states.
    pub fn passed(&self) -> bool {
        self.findings.is_empty()
    }
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

/// Points of a static cloud in a uniform grid of cell `cell`, for nearest-point queries.
struct PointGrid {
    cell: f64,
    cells: std::collections::BTreeMap<(i64, i64, i64), Vec<[f64; 3]>>,
}

impl PointGrid {
    fn new(points: Vec<[f64; 3]>, cell: f64) -> Self {
        let mut cells: std::collections::BTreeMap<(i64, i64, i64), Vec<[f64; 3]>> =
            std::collections::BTreeMap::new();
        for p in points {
            cells.entry(Self::key(&p, cell)).or_default().push(p);
        }
        PointGrid { cell, cells }
    }

    fn key(p: &[f64; 3], cell: f64) -> (i64, i64, i64) {
        let k = |x: f64| (x / cell).floor() as i64;
        (k(p[0]), k(p[1]), k(p[2]))
    }

    /// Distance to the nearest point, searching shells of cells outward until no closer point can
    /// exist; `+∞` if none lies within `max_reach`.
    fn nearest(&self, p: &[f64; 3], max_reach: f64) -> f64 {
        let (x, y, z) = Self::key(p, self.cell);
        let mut best = f64::INFINITY;
        let shells = (max_reach / self.cell).ceil() as i64 + 1;
        for n in 0..=shells {
            // Every point in shell n is at least (n − 1)·cell away.
            if best <= (n - 1) as f64 * self.cell {
                break;
            }
            for i in -n..=n {
                for j in -n..=n {
                    for k in -n..=n {
                        if i.abs().max(j.abs()).max(k.abs()) != n {
                            continue;
                        }
                        if let Some(pts) = self.cells.get(&(x + i, y + j, z + k)) {
                            for q in pts {
                                best = best.min(dist(p, q));
                            }
                        }
                    }
                }
            }
        }
        if best <= max_reach {
            best
        } else {
            f64::INFINITY
        }
    }
}

/// Reads a points file (`x y z` per line; blank lines and `#` comments ignored).
fn read_points(path: &Path) -> Result<Vec<[f64; 3]>, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut points = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let xs: Vec<f64> = line
            .split_whitespace()
            .map(str::parse)
            .collect::<Result<_, _>>()
            .map_err(|e| format!("{}:{}: {e}", path.display(), i + 1))?;
        if xs.len() != 3 {
            return Err(format!("{}:{}: expected `x y z`", path.display(), i + 1));
        }
        points.push([xs[0], xs[1], xs[2]]);
    }
    Ok(points)
}

/// The static and dynamic clearances of the vehicle in state `s` (minus its radius), and the
/// nearest moving obstacle's id.
fn clearance_at(h: &Header, grid: Option<&PointGrid>, s: &StateRecord) -> (f64, f64, usize) {
    let radius = h.vehicle.radius;
    let mut static_c = h
        .static_shapes
        .iter()
        .map(|shape| static_distance(&s.p, shape) - radius)
        .fold(f64::INFINITY, f64::min);
    if let Some(g) = grid {
        static_c = static_c.min(g.nearest(&s.p, 100.0) - radius);
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
/// resolves `static_points_file`. The flight replay draws them as traces.
///
/// # Errors
/// A message if the points file cannot be read.
pub fn state_clearances(log: &RunLog, log_dir: &Path) -> Result<Vec<[f64; 2]>, String> {
    let grid = match &log.header.static_points_file {
        Some(f) => Some(PointGrid::new(read_points(&log_dir.join(f))?, 1.0)),
        None => None,
    };
    Ok(log
        .states
        .iter()
        .map(|s| {
            let (st, dy, _) = clearance_at(&log.header, grid.as_ref(), s);
            [st, dy]
        })
        .collect())
}

/// Reads the `x y z` points of a log's `static_points_file` (blank lines and `#` comments
/// ignored).
///
/// # Errors
/// A message naming the file and line.
pub fn read_static_points(path: &Path) -> Result<Vec<[f64; 3]>, String> {
    read_points(path)
}

/// Recomputes the outcome of `log`; `log_dir` resolves `static_points_file`.
///
/// # Errors
/// A message if the points file cannot be read.
pub fn recompute(log: &RunLog, log_dir: &Path) -> Result<Recomputed, String> {
    let h: &Header = &log.header;
    let grid = match &h.static_points_file {
        Some(f) => Some(PointGrid::new(read_points(&log_dir.join(f))?, 1.0)),
        None => None,
    };
    let mut r = Recomputed {
        status: Status::TimedOut,
        with: None,
        collision_t: None,
        min_clearance_static_m: f64::INFINITY,
        min_clearance_dynamic_m: f64::INFINITY,
        max_speed: 0.0,
        max_accel: 0.0,
        path_length_m: 0.0,
        flight_time_s: 0.0,
    };
    let mut previous: Option<&StateRecord> = None;
    for s in &log.states {
        let (static_c, dynamic_c, nearest) = clearance_at(h, grid.as_ref(), s);
        r.min_clearance_static_m = r.min_clearance_static_m.min(static_c);
        r.min_clearance_dynamic_m = r.min_clearance_dynamic_m.min(dynamic_c);
        r.max_speed = r.max_speed.max(norm(&s.v));
        r.max_accel = r.max_accel.max(norm(&s.a));
        if let Some(prev) = previous {
            r.path_length_m += dist(&prev.p, &s.p);
        }
        if r.collision_t.is_none() && (static_c < 0.0 || dynamic_c < 0.0) {
            r.collision_t = Some(s.t);
            r.with = Some(if static_c <= dynamic_c {
                "static".to_string()
            } else {
                format!("obstacle:{nearest}")
            });
        }
        previous = Some(s);
    }
    let (first, last) = (&log.states[0], &log.states[log.states.len() - 1]);
    r.flight_time_s = last.t - first.t;
    r.status = if r.collision_t.is_some() {
        Status::Collided
    } else if dist(&last.p, &h.goal) <= h.goal_tolerance {
        Status::Arrived
    } else {
        Status::TimedOut
    };
    Ok(r)
}

fn close(a: f64, b: f64, abs: f64) -> bool {
    (a == b) || (a - b).abs() <= abs
}

/// Audits `log` (read from a file in `log_dir`): recomputes the outcome and lists every
/// disagreement with the outcome record. An `invalid` outcome is accepted as is (the run did not
/// fly as specified) but its figures are still compared.
///
/// # Errors
/// A message if the points file cannot be read.
pub fn audit(log: &RunLog, log_dir: &Path) -> Result<Audit, String> {
    let r = recompute(log, log_dir)?;
    let o = &log.outcome;
    let mut findings = Vec::new();
    let mut check = |field: &'static str, ok: bool, logged: String, recomputed: String| {
        if !ok {
            findings.push(Finding {
                field,
                logged,
                recomputed,
            });
        }
    };
    if o.status == Status::Unreachable {
        // The planner's verdict is not recomputable from the states; what is: the flight ended
        // neither in a collision nor at the goal.
        check(
            "status",
            r.status == Status::TimedOut,
            o.status.as_str().into(),
            format!(
                "{} (unreachable needs no collision and no arrival)",
                r.status.as_str()
            ),
        );
    } else if o.status != Status::Invalid {
        check(
            "status",
            o.status == r.status,
            o.status.as_str().into(),
            r.status.as_str().into(),
        );
        if r.status == Status::Collided {
            check(
                "with",
                o.with == r.with,
                format!("{:?}", o.with),
                format!("{:?}", r.with),
            );
        }
    }
    let last_t = log.states[log.states.len() - 1].t;
    check(
        "t",
        close(o.t, last_t, 1e-6),
        o.t.to_string(),
        format!("{last_t} (last state)"),
    );
    check(
        "flight_time_s",
        close(o.flight_time_s, r.flight_time_s, 1e-6),
        o.flight_time_s.to_string(),
        r.flight_time_s.to_string(),
    );
    check(
        "path_length_m",
        close(
            o.path_length_m,
            r.path_length_m,
            1e-3 * r.path_length_m.max(1.0),
        ),
        o.path_length_m.to_string(),
        r.path_length_m.to_string(),
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
        // Without geometry the recomputed minimum is +∞; the log holds a large finite stand-in.
        let ok = if recomputed.is_infinite() {
            logged >= 1e6
        } else {
            close(logged, recomputed, CLEARANCE_TOLERANCE_M)
        };
        check(field, ok, logged.to_string(), recomputed.to_string());
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
                MAXIMA_TOLERANCE * recomputed.abs().max(1e-9),
            ),
            logged.to_string(),
            recomputed.to_string(),
        );
    }
    Ok(Audit {
        recomputed: r,
        findings,
    })
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
            states: vec![clear, state(0.02, [6.3, 5.0, 1.0], 5.1)],
            cycles: Vec::new(),
            outcome: crate::Outcome {
                path_length_m: 1.3,
                ..outcome(Status::Collided, Some("obstacle:0"), 0.02, -0.1)
            },
        };
        let a = audit(&log, Path::new(".")).unwrap();
        assert!(a.passed(), "{:?}", a.findings);
        assert_eq!(a.recomputed.with.as_deref(), Some("obstacle:0"));
        assert!((a.recomputed.min_clearance_dynamic_m + 0.1).abs() < 1e-12);
    }

    #[test]
    fn point_grid_finds_the_nearest_point() {
        let g = PointGrid::new(
            vec![[0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [10.0, 0.0, 0.0]],
            1.0,
        );
        assert!((g.nearest(&[2.5, 0.0, 0.0], 5.0) - 0.5).abs() < 1e-12);
        assert!((g.nearest(&[6.4, 0.3, 0.0], 50.0) - 0.3f64.hypot(3.4)).abs() < 1e-12);
        assert_eq!(g.nearest(&[6.5, 0.0, 40.0], 2.0), f64::INFINITY);
    }
}
