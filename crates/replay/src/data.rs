//! The flight's data as the page embeds it: one JSON object, numbers rounded.

use std::path::Path;

use serde_json::{Map, Value, json};
use trust_runlog::audit::{TrueGeometry, read_log_points};
use trust_runlog::{
    BranchSamples, CycleRecord, ForecastRecord, ForecastShape, Header, LogError, LogReader,
    Outcome, Record, RunLog, StateRecord,
};

use crate::{ReplayError, ReplayParams};

/// Checks the parameters shared by the page and the GIF.
pub(crate) fn check_params(params: &ReplayParams) -> Result<(), ReplayError> {
    let invalid = |field, value: String, expected| {
        Err(ReplayError::InvalidParam {
            field,
            value,
            expected,
        })
    };
    if !(params.state_step_s.is_finite() && params.state_step_s >= 0.0) {
        return invalid(
            "state_step_s",
            params.state_step_s.to_string(),
            "a finite number ≥ 0",
        );
    }
    for (field, value) in [
        ("branch_tolerance_m", params.branch_tolerance_m),
        ("forecast_near_m", params.forecast_near_m),
    ] {
        if !(value.is_finite() && value >= 0.0) {
            return invalid(field, value.to_string(), "a finite number ≥ 0");
        }
    }
    if !(0..=9).contains(&params.decimals) {
        return invalid("decimals", params.decimals.to_string(), "0 to 9");
    }
    for (field, value) in [
        ("max_states", params.max_states),
        ("max_cycles", params.max_cycles),
    ] {
        if value < 2 {
            return invalid(field, value.to_string(), "≥ 2");
        }
    }
    Ok(())
}

/// Rounds every number in `v` to `decimals` decimals; non-finite numbers cannot occur in a
/// `Value` (serde_json turns them into `null`).
fn round(v: &mut Value, scale: f64) {
    match v {
        Value::Number(n) => {
            if n.is_f64()
                && let Some(x) = n.as_f64()
            {
                let r = (x * scale).round() / scale;
                // -0 prints as "-0.0": keep it plain.
                let r = if r == 0.0 { 0.0 } else { r };
                if let Some(m) = serde_json::Number::from_f64(r) {
                    *n = m;
                }
            }
        }
        Value::Array(xs) => xs.iter_mut().for_each(|x| round(x, scale)),
        Value::Object(m) => m.values_mut().for_each(|x| round(x, scale)),
        _ => {}
    }
}

/// The Ramer–Douglas–Peucker simplification of a polyline: the fewest vertices (first and last
/// kept) such that no dropped vertex is farther than `tolerance` from the simplified line.
pub(crate) fn simplify(points: &[[f64; 3]], tolerance: f64) -> Vec<[f64; 3]> {
    if points.len() < 3 {
        return points.to_vec();
    }
    let mut keep = vec![false; points.len()];
    keep[0] = true;
    keep[points.len() - 1] = true;
    let mut stack = vec![(0, points.len() - 1)];
    while let Some((a, b)) = stack.pop() {
        let (mut worst, mut at) = (0.0, 0);
        for (i, p) in points.iter().enumerate().take(b).skip(a + 1) {
            let d = segment_distance(p, &points[a], &points[b]);
            if d > worst {
                (worst, at) = (d, i);
            }
        }
        if worst > tolerance {
            keep[at] = true;
            stack.push((a, at));
            stack.push((at, b));
        }
    }
    points
        .iter()
        .zip(keep)
        .filter_map(|(p, k)| k.then_some(*p))
        .collect()
}

fn segment_distance(p: &[f64; 3], a: &[f64; 3], b: &[f64; 3]) -> f64 {
    let ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let ap = [p[0] - a[0], p[1] - a[1], p[2] - a[2]];
    let len2 = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2];
    let u = if len2 > 0.0 {
        ((ap[0] * ab[0] + ap[1] * ab[1] + ap[2] * ab[2]) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let d = [ap[0] - u * ab[0], ap[1] - u * ab[1], ap[2] - u * ab[2]];
    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
}

/// Whether forecast `f` matters to the picture of its cycle: its centre at the cycle's time is
/// within `near` (plus its radius then) of the vehicle, or its predicted centre comes within
/// `near` plus its grown radius of a kept branch's sample at that sample's time.
fn forecast_is_near(
    f: &ForecastRecord,
    vehicle: &[f64; 3],
    branches: Option<&[BranchSamples]>,
    near: f64,
) -> bool {
    let at = |t: f64| (f.centre_at(t), f.radius_at(t));
    let dist = |a: &[f64; 3], b: &[f64; 3]| {
        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
    };
    let (c, r) = at(f.t0);
    if dist(&c, vehicle) <= near + r {
        return true;
    }
    branches.into_iter().flatten().any(|b| {
        b.samples.iter().any(|s| {
            let (c, r) = at(s[0]);
            dist(&c, &[s[1], s[2], s[3]]) <= near + r
        })
    })
}

/// A forecast as the page reads it:
/// `[id, x, y, z, vx, vy, vz, t0, r0, mu, half_height, growth_s, walls]` (`half_height` 0 for a
/// sphere, `growth_s` `null` when the radius grows for ever, `walls` `[min, max]` of the region
/// the planner mirrors the forecast in, `null` at the world's bounds).
fn compact_forecast(f: &ForecastRecord) -> Value {
    let hh = match f.shape {
        ForecastShape::Sphere => 0.0,
        ForecastShape::Cylinder { half_height } => half_height,
    };
    json!([
        f.id,
        f.p0[0],
        f.p0[1],
        f.p0[2],
        f.v0[0],
        f.v0[1],
        f.v0[2],
        f.t0,
        f.r0,
        f.mu,
        hh,
        f.growth_s.map_or(Value::Null, num),
        f.walls.map_or(Value::Null, |[lo, hi]| json!([
            [num(lo[0]), num(lo[1]), num(lo[2])],
            [num(hi[0]), num(hi[1]), num(hi[2])]
        ]))
    ])
}

/// A finite number, or `null`.
fn num(x: f64) -> Value {
    serde_json::Number::from_f64(x).map_or(Value::Null, Value::Number)
}

/// One record of a log, as the page and the GIF read it.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Item<'a> {
    /// A state record.
    State(&'a StateRecord),
    /// A cycle record.
    Cycle(&'a CycleRecord),
}

/// Feeds the states and cycles of a log in memory to `f` in the order of a log file: each cycle
/// after the states up to its time.
pub(crate) fn visit_log(
    log: &RunLog,
    f: &mut dyn FnMut(Item<'_>) -> Result<(), ReplayError>,
) -> Result<(), ReplayError> {
    let mut cycles = log.cycles.iter().peekable();
    for s in &log.states {
        while let Some(c) = cycles.next_if(|c| c.t < s.t) {
            f(Item::Cycle(c))?;
        }
        f(Item::State(s))?;
    }
    for c in cycles {
        f(Item::Cycle(c))?;
    }
    Ok(())
}

/// Streams the log at `path` to `f` in file order; returns its header and outcome.
pub(crate) fn visit_file(
    path: &Path,
    f: &mut dyn FnMut(&Header, Item<'_>) -> Result<(), ReplayError>,
) -> Result<(Header, Outcome), ReplayError> {
    let mut reader = LogReader::open(path)?;
    let header = reader.header().clone();
    let mut outcome = None;
    while let Some(record) = reader.next_record()? {
        match record {
            Record::State(s) => f(&header, Item::State(&s))?,
            Record::Cycle(c) => f(&header, Item::Cycle(&c))?,
            Record::Outcome(o) => outcome = Some(o),
            Record::Header(_) => {}
        }
    }
    let outcome = outcome.ok_or_else(|| LogError::Structure {
        path: path.to_path_buf(),
        message: "no outcome (the run did not finish)".into(),
    })?;
    Ok((header, outcome))
}

/// The static points of a log thinned for the page and the GIF (every k-th in file order, at
/// most `max_points`), and the geometry of its clearances (every point).
pub(crate) fn geometry(
    header: &Header,
    log_dir: &Path,
    max_points: usize,
) -> Result<(Vec<[f64; 3]>, TrueGeometry), ReplayError> {
    let points =
        read_log_points(header, log_dir).map_err(|message| ReplayError::Points { message })?;
    let thinned = points.as_ref().map_or_else(Vec::new, |pts| {
        let every = pts.len().div_ceil(max_points.max(1)).max(1);
        pts.iter().step_by(every).copied().collect()
    });
    Ok((thinned, TrueGeometry::with_points(header, points)))
}

/// A state kept in the page.
#[derive(Debug, Clone)]
struct KeptState {
    t: f64,
    p: [f64; 3],
    speed: f64,
    /// The smallest `[static, dynamic]` clearance since the previous kept state, this one's
    /// included.
    clear: [f64; 2],
    obstacles: Vec<[f64; 3]>,
}

/// A cycle kept in the page: its compact form, and what later cycles may inherit.
#[derive(Debug, Clone)]
struct KeptCycle {
    value: Map<String, Value>,
    events: Vec<String>,
    route: Option<Value>,
}

fn min2(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0].min(b[0]), a[1].min(b[1])]
}

/// The page's data, built record by record in bounded memory (see [`ReplayParams`]): states
/// kept at `state_step_s` (doubled whenever more than `max_states` would be kept), cycles kept
/// every one (every second, fourth, … whenever more than `max_cycles` would be).
pub(crate) struct PageBuilder<'p> {
    params: &'p ReplayParams,
    geometry: TrueGeometry,
    page_tolerance: f64,
    state_step: f64,
    next_state_t: f64,
    states: Vec<KeptState>,
    pending_clear: [f64; 2],
    latest: Option<StateRecord>,
    cycle_stride: usize,
    cycle_count: usize,
    cycles: Vec<KeptCycle>,
    pending_events: Vec<String>,
    pending_route: Option<Value>,
}

impl<'p> PageBuilder<'p> {
    pub(crate) fn new(params: &'p ReplayParams, geometry: TrueGeometry) -> Self {
        PageBuilder {
            params,
            geometry,
            page_tolerance: 0.5 * 10f64.powi(-params.decimals),
            state_step: params.state_step_s,
            next_state_t: f64::NEG_INFINITY,
            states: Vec::new(),
            pending_clear: [f64::INFINITY; 2],
            latest: None,
            cycle_stride: 1,
            cycle_count: 0,
            cycles: Vec::new(),
            pending_events: Vec::new(),
            pending_route: None,
        }
    }

    /// The time span of the states seen (first, latest).
    pub(crate) fn span(&self) -> Option<(f64, f64)> {
        Some((self.states.first()?.t, self.latest.as_ref()?.t))
    }

    pub(crate) fn item(&mut self, item: Item<'_>) {
        match item {
            Item::State(s) => self.state(s),
            Item::Cycle(c) => self.cycle(c),
        }
    }

    fn state(&mut self, s: &StateRecord) {
        let (st, dy, _) = self.geometry.clearances(s);
        self.pending_clear = min2(self.pending_clear, [st, dy]);
        if s.t + 1e-9 >= self.next_state_t {
            self.push_state(s);
            self.next_state_t = s.t + self.state_step;
            if self.states.len() > self.params.max_states.max(2) {
                self.halve_states();
            }
        }
        self.latest = Some(s.clone());
    }

    fn push_state(&mut self, s: &StateRecord) {
        self.states.push(KeptState {
            t: s.t,
            p: s.p,
            speed: (s.v[0] * s.v[0] + s.v[1] * s.v[1] + s.v[2] * s.v[2]).sqrt(),
            clear: self.pending_clear,
            obstacles: s.obstacles.clone(),
        });
        self.pending_clear = [f64::INFINITY; 2];
    }

    /// Keeps every other state (the first included), each with the smallest clearance of the
    /// window it now covers; doubles the step.
    fn halve_states(&mut self) {
        let old = std::mem::take(&mut self.states);
        let mut carried = [f64::INFINITY; 2];
        for (k, mut s) in old.into_iter().enumerate() {
            if k % 2 == 1 {
                carried = s.clear;
            } else {
                s.clear = min2(s.clear, carried);
                carried = [f64::INFINITY; 2];
                self.states.push(s);
            }
        }
        self.pending_clear = min2(self.pending_clear, carried);
        self.state_step = (2.0 * self.state_step).max(0.02);
        self.next_state_t = self.states.last().map_or(f64::NEG_INFINITY, |s| s.t) + self.state_step;
    }

    fn cycle(&mut self, c: &CycleRecord) {
        let index = self.cycle_count;
        self.cycle_count += 1;
        let route = c.route.as_ref().map(|r| json!(r));
        if !index.is_multiple_of(self.cycle_stride) {
            // Not kept: its events and route go to the next kept cycle.
            self.pending_events.extend(c.events.iter().cloned());
            if route.is_some() {
                self.pending_route = route;
            }
            return;
        }
        let mut events = std::mem::take(&mut self.pending_events);
        events.extend(c.events.iter().cloned());
        let route = route.or_else(|| self.pending_route.take());
        self.pending_route = None;
        let vehicle = self.latest.as_ref().map_or([f64::NAN; 3], |s| s.p);
        let mut m = Map::new();
        m.insert("t".into(), num(c.t));
        m.insert("main".into(), json!(c.main));
        if let Some(b) = &c.branch_samples {
            let tolerance = self.params.branch_tolerance_m.max(self.page_tolerance);
            m.insert(
                "branches".into(),
                Value::Array(
                    b.iter()
                        .map(|b| {
                            let xyz: Vec<[f64; 3]> =
                                b.samples.iter().map(|s| [s[1], s[2], s[3]]).collect();
                            json!(simplify(&xyz, tolerance))
                        })
                        .collect(),
                ),
            );
            m.insert(
                "ids".into(),
                Value::Array(b.iter().map(|b| json!(b.id)).collect()),
            );
        }
        if let Some(f) = &c.forecasts {
            let near = f.iter().filter(|f| {
                forecast_is_near(
                    f,
                    &vehicle,
                    c.branch_samples.as_deref(),
                    self.params.forecast_near_m,
                )
            });
            m.insert(
                "forecasts".into(),
                Value::Array(near.map(compact_forecast).collect()),
            );
        }
        self.cycles.push(KeptCycle {
            value: m,
            events,
            route,
        });
        if self.cycles.len() > self.params.max_cycles.max(2) {
            self.halve_cycles();
        }
    }

    /// Keeps every other cycle (the first included); a dropped cycle's events and route go to
    /// the next kept one.
    fn halve_cycles(&mut self) {
        let old = std::mem::take(&mut self.cycles);
        let mut carried_events: Vec<String> = Vec::new();
        let mut carried_route = None;
        for (k, mut c) in old.into_iter().enumerate() {
            if k % 2 == 1 {
                carried_events = c.events;
                carried_route = c.route;
            } else {
                if !carried_events.is_empty() {
                    carried_events.append(&mut c.events);
                    c.events = std::mem::take(&mut carried_events);
                }
                if c.route.is_none() {
                    c.route = carried_route.take();
                }
                carried_route = None;
                self.cycles.push(c);
            }
        }
        carried_events.append(&mut self.pending_events);
        self.pending_events = carried_events;
        if self.pending_route.is_none() {
            self.pending_route = carried_route;
        }
        self.cycle_stride *= 2;
    }

    /// The page's data: `header` and `outcome` as logged (so optional fields added later pass
    /// through), the thinned static `points`, the kept `states` (time, position, speed,
    /// `[static, dynamic]` clearance — the smallest since the previous kept state —, obstacle
    /// centres) and per kept cycle its time, main branch, events (with those of the cycles
    /// dropped before it), branches (main first, simplified to `[x, y, z]` polylines), the
    /// forecasts near the vehicle or a branch (compact arrays, see [`compact_forecast`]) and the
    /// route when logged.
    pub(crate) fn finish(
        mut self,
        header: &Header,
        outcome: &Outcome,
        points: &[[f64; 3]],
    ) -> Value {
        if let Some(s) = self.latest.take()
            && self.states.last().is_none_or(|k| k.t < s.t)
        {
            self.push_state(&s);
        }
        let n = self.states.len();
        let (mut t, mut p, mut speed, mut clear, mut obstacles) = (
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
        );
        for s in &self.states {
            t.push(num(s.t));
            p.push(json!(s.p));
            speed.push(num(s.speed));
            clear.push(json!([num(s.clear[0]), num(s.clear[1])]));
            obstacles.push(json!(s.obstacles));
        }
        let cycles: Vec<Value> = self
            .cycles
            .into_iter()
            .map(|c| {
                let mut m = c.value;
                m.insert("events".into(), json!(c.events));
                if let Some(r) = c.route {
                    m.insert("route".into(), r);
                }
                Value::Object(m)
            })
            .collect();
        let mut data = json!({
            "header": serde_json::to_value(header).unwrap_or(Value::Null),
            "outcome": serde_json::to_value(outcome).unwrap_or(Value::Null),
            "points": points,
            "states": {"t": t, "p": p, "speed": speed, "clear": clear, "obstacles": obstacles},
            "cycles": cycles,
        });
        round(&mut data, 10f64.powi(self.params.decimals));
        data
    }
}

/// The page's data of a log in memory ([`PageBuilder::finish`]).
pub(crate) fn page_data(
    log: &RunLog,
    log_dir: &Path,
    params: &ReplayParams,
) -> Result<Value, ReplayError> {
    check_params(params)?;
    let (points, geometry) = geometry(&log.header, log_dir, params.max_points)?;
    let mut page = PageBuilder::new(params, geometry);
    visit_log(log, &mut |item| {
        page.item(item);
        Ok(())
    })?;
    Ok(page.finish(&log.header, &log.outcome, &points))
}

/// `data` as JSON that can sit inside a `<script>` element: every `<` is written `\u003c`, so
/// no `</script>` or `<!--` can end or disturb the element, and the text is still JSON.
pub(crate) fn script_safe_json(data: &Value) -> String {
    data.to_string().replace('<', "\\u003c")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn simplification_keeps_corners_and_drops_collinear_points() {
        let line: Vec<[f64; 3]> = (0..=10).map(|i| [i as f64, 0.0, 1.0]).collect();
        assert_eq!(
            simplify(&line, 0.01),
            vec![[0.0, 0.0, 1.0], [10.0, 0.0, 1.0]]
        );
        let mut corner = line.clone();
        corner.extend((1..=5).map(|i| [10.0, i as f64, 1.0]));
        let s = simplify(&corner, 0.01);
        assert_eq!(s, vec![[0.0, 0.0, 1.0], [10.0, 0.0, 1.0], [10.0, 5.0, 1.0]]);
        // Within tolerance of the original everywhere.
        let wavy: Vec<[f64; 3]> = (0..=100)
            .map(|i| [i as f64 * 0.1, (i as f64 * 0.1).sin(), 0.0])
            .collect();
        let s = simplify(&wavy, 0.02);
        assert!(s.len() < wavy.len() / 2, "{}", s.len());
        for p in &wavy {
            let d = s
                .windows(2)
                .map(|w| segment_distance(p, &w[0], &w[1]))
                .fold(f64::INFINITY, f64::min);
            assert!(d <= 0.02 + 1e-12, "{d}");
        }
    }

    #[test]
    fn rounding_keeps_integers_and_rounds_floats() {
        let mut v = json!({"a": 1.23456, "b": [2, -0.0001], "c": "x<y"});
        round(&mut v, 1000.0);
        assert_eq!(v, json!({"a": 1.235, "b": [2, 0.0], "c": "x<y"}));
        let text = script_safe_json(&v);
        assert!(!text.contains('<'));
        let back: Value = serde_json::from_str(&text).unwrap();
        assert_eq!(back["c"], "x<y");
    }
}
