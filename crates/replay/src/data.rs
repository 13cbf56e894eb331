//! The flight's data as the page embeds it: one JSON object, numbers rounded.

use std::path::Path;

use serde_json::{Map, Value, json};
use trust_runlog::audit::{read_static_points, state_clearances};
use trust_runlog::{BranchSamples, ForecastRecord, ForecastShape, RunLog};

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

/// Indices of the states kept in the page: the first, then each at least `step` after the
/// previous kept one, and the last.
pub(crate) fn kept_states(log: &RunLog, step: f64) -> Vec<usize> {
    let mut kept = Vec::new();
    let mut next = f64::NEG_INFINITY;
    for (i, s) in log.states.iter().enumerate() {
        if s.t + 1e-9 >= next {
            kept.push(i);
            next = s.t + step;
        }
    }
    let last = log.states.len() - 1;
    if kept.last() != Some(&last) {
        kept.push(last);
    }
    kept
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

/// The page's data: `header` and `outcome` as logged (so optional fields added later, such as a
/// global `route`, pass through), the thinned static `points`, the kept `states` (time, position,
/// speed, `[static, dynamic]` clearance, obstacle centres) and per cycle its time, main branch,
/// events, branches (main first, simplified to `[x, y, z]` polylines), the forecasts near the
/// vehicle or a branch (compact arrays, see [`compact_forecast`]) and the route when logged.
pub(crate) fn page_data(
    log: &RunLog,
    log_dir: &Path,
    params: &ReplayParams,
) -> Result<Value, ReplayError> {
    check_params(params)?;
    let clearances =
        state_clearances(log, log_dir).map_err(|message| ReplayError::Points { message })?;
    let points = match &log.header.static_points_file {
        Some(f) => {
            let pts = read_static_points(&log_dir.join(f))
                .map_err(|message| ReplayError::Points { message })?;
            let every = pts.len().div_ceil(params.max_points.max(1)).max(1);
            pts.into_iter().step_by(every).collect()
        }
        None => Vec::new(),
    };
    let kept = kept_states(log, params.state_step_s);
    let page_tolerance = 0.5 * 10f64.powi(-params.decimals);
    let mut t = Vec::with_capacity(kept.len());
    let mut p = Vec::with_capacity(kept.len());
    let mut speed = Vec::with_capacity(kept.len());
    let mut clear = Vec::with_capacity(kept.len());
    let mut obstacles = Vec::with_capacity(kept.len());
    for &i in &kept {
        let s = &log.states[i];
        t.push(num(s.t));
        p.push(json!(s.p));
        speed.push(num(
            (s.v[0] * s.v[0] + s.v[1] * s.v[1] + s.v[2] * s.v[2]).sqrt()
        ));
        clear.push(json!([num(clearances[i][0]), num(clearances[i][1])]));
        obstacles.push(json!(s.obstacles));
    }
    let header = serde_json::to_value(&log.header).unwrap_or(Value::Null);
    let outcome = serde_json::to_value(&log.outcome).unwrap_or(Value::Null);
    let cycles: Vec<Value> = log
        .cycles
        .iter()
        .map(|c| {
            let mut m = Map::new();
            m.insert("t".into(), num(c.t));
            m.insert("main".into(), json!(c.main));
            m.insert("events".into(), json!(c.events));
            if let Some(b) = &c.branch_samples {
                m.insert(
                    "branches".into(),
                    Value::Array(
                        b.iter()
                            .map(|b| {
                                let xyz: Vec<[f64; 3]> =
                                    b.samples.iter().map(|s| [s[1], s[2], s[3]]).collect();
                                json!(simplify(
                                    &xyz,
                                    params.branch_tolerance_m.max(page_tolerance)
                                ))
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
                let vehicle = log.states[log.states.partition_point(|s| s.t <= c.t).max(1) - 1].p;
                let near = f.iter().filter(|f| {
                    forecast_is_near(
                        f,
                        &vehicle,
                        c.branch_samples.as_deref(),
                        params.forecast_near_m,
                    )
                });
                m.insert(
                    "forecasts".into(),
                    Value::Array(near.map(compact_forecast).collect()),
                );
            }
            // Fields other crates may add to the cycle record (a re-planned global route).
            if let Ok(Value::Object(all)) = serde_json::to_value(c)
                && let Some(route) = all.get("route")
                && !route.is_null()
            {
                m.insert("route".into(), route.clone());
            }
            Value::Object(m)
        })
        .collect();
    let mut data = json!({
        "header": header,
        "outcome": outcome,
        "points": points,
        "states": {"t": t, "p": p, "speed": speed, "clear": clear, "obstacles": obstacles},
        "cycles": cycles,
    });
    round(&mut data, 10f64.powi(params.decimals));
    Ok(data)
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
