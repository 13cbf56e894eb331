//! Parameter-edge cases and contract oracles for the trust-minco backends (issue 18).
//!
//! - [`params_edges`]: every numeric field of `UtfMincoParams` / `MincoParams` (found by walking
//!   the serde form, so new fields are covered without editing this file) set to an extreme or
//!   edge value, one at a time or in pairs. Oracles: a rejected set names one of the perturbed
//!   fields (`params.<path>`) and prints no number with more than 20 digits in a row; an
//!   accepted set solves with `Ok` (an error after acceptance is the defect "an accepted value
//!   breaks the solve with an error about something else"), finite costs and a trajectory.
//! - [`violations_oracle`]: random requests (warm starts outside the map included) against the
//!   fixtures' maps and forecasts. Oracle: an `Ok` solution whose trajectory penetrates a static
//!   obstacle or a forecast, leaves the bounds or exceeds `v_max`/`a_max` at an independent dense
//!   check (every 5 ms, by more than what can hide between the verifier's instants: half a
//!   spacing of the trajectory's top speed, acceleration or jerk) must list that kind in
//!   `Solution::violations`, and every listed violation must be real (its amount found again
//!   at its time).
//!
//! [`apis`] lists both for the harness's registry (`main.rs`).

use trust_core::{
    GuidePath, InitialGuess, Limits, PolyTraj, Scene, State, TrajRequest, TrajectoryBackend, Vec3,
    Violation,
};

use crate::apis::{Api, Fixtures, Outcome};
use crate::inputs::Gen;

/// The minco oracles as harness entries (name, weight, call).
pub fn apis() -> Vec<Api> {
    vec![
        Api {
            name: "params::minco_edges",
            weight: 3,
            run: params_edges,
        },
        Api {
            name: "minco::violations",
            weight: 5,
            run: violations_oracle,
        },
    ]
}

/// Extreme and edge values tried for a float field.
const FLOAT_EDGES: [f64; 16] = [
    0.0,
    -0.0,
    -1.0,
    1e-300,
    1e-12,
    1e-9,
    1e-6,
    1e-3,
    1.0,
    10.0,
    1e3,
    1e6,
    1e7,
    1e12,
    1e300,
    f64::MAX,
];

/// Edge values tried for an integer field.
const INT_EDGES: [u64; 9] = [0, 1, 2, 3, 1024, 1025, 100_000, 100_001, u64::MAX];

/// Dotted paths of every number in `v` (document order).
fn number_paths(v: &serde_json::Value, prefix: &str, out: &mut Vec<String>) {
    match v {
        serde_json::Value::Number(_) => out.push(prefix.to_string()),
        serde_json::Value::Array(a) => {
            for (i, x) in a.iter().enumerate() {
                number_paths(x, &format!("{prefix}[{i}]"), out);
            }
        }
        serde_json::Value::Object(o) => {
            for (k, x) in o {
                let p = if prefix.is_empty() {
                    k.clone()
                } else {
                    format!("{prefix}.{k}")
                };
                number_paths(x, &p, out);
            }
        }
        _ => {}
    }
}

fn slot<'a>(v: &'a mut serde_json::Value, path: &str) -> Option<&'a mut serde_json::Value> {
    let mut cur = v;
    for part in path.split('.') {
        let (key, index) = match part.split_once('[') {
            Some((k, rest)) => (k, rest.trim_end_matches(']').parse::<usize>().ok()),
            None => (part, None),
        };
        cur = cur.get_mut(key)?;
        if let Some(i) = index {
            cur = cur.get_mut(i)?;
        }
    }
    Some(cur)
}

/// The field name a validator reports for a serde path (`a.b[1]` → `a.b.y`).
fn reported_name(path: &str) -> String {
    path.replace("[0]", ".x")
        .replace("[1]", ".y")
        .replace("[2]", ".z")
}

/// Sets one or two numeric fields of `params` to edge values; returns the edited struct and the
/// paths edited (`None` if serde refuses the value, e.g. a negative integer).
fn perturb<T: serde::Serialize + serde::de::DeserializeOwned>(
    g: &mut Gen,
    params: &T,
) -> Option<(T, Vec<String>)> {
    let mut v = serde_json::to_value(params).ok()?;
    let mut paths = Vec::new();
    number_paths(&v, "", &mut paths);
    if paths.is_empty() {
        return None;
    }
    let mut edited = Vec::new();
    for _ in 0..1 + usize::from(g.chance(0.3)) {
        let path = paths[g.index(paths.len())].clone();
        let s = slot(&mut v, &path)?;
        *s = if s.is_u64() || s.is_i64() {
            serde_json::Value::from(INT_EDGES[g.index(INT_EDGES.len())])
        } else {
            let x = FLOAT_EDGES[g.index(FLOAT_EDGES.len())];
            serde_json::Value::from(if g.chance(0.2) { -x } else { x })
        };
        edited.push(path);
    }
    let parsed = serde_json::from_value(v).ok()?;
    Some((parsed, edited))
}

/// An ordinary number in `[lo, hi]` (never one of `Gen::num`'s adversarial values: the
/// requests here must be valid so that an error can only come from the parameters).
fn ordinary(g: &mut Gen, lo: f64, hi: f64) -> f64 {
    lo + (hi - lo) * g.index(1001) as f64 / 1000.0
}

/// Longest run of ASCII digits in `s`.
fn longest_digit_run(s: &str) -> usize {
    s.split(|c: char| !c.is_ascii_digit())
        .map(str::len)
        .max()
        .unwrap_or(0)
}

fn request<'a>(g: &mut Gen, guide: &'a GuidePath) -> TrajRequest<'a> {
    let start = guide.points[0];
    let goal = *guide.points.last().unwrap_or(&start);
    TrajRequest {
        start: State::at_rest(0.0, start),
        goal,
        limits: Limits {
            v_max: ordinary(g, 1.0, 10.0),
            a_max: ordinary(g, 2.0, 15.0),
        },
        initial: InitialGuess::Guide(guide),
        deadline: Some(std::time::Instant::now() + std::time::Duration::from_millis(300)),
        horizon_s: if g.chance(0.5) { Some(3.0) } else { None },
        max_evaluations: Some(60),
    }
}

/// A start and goal in free space of `scene` (or `None` after a few tries).
fn free_pair(g: &mut Gen, scene: &Scene<'_>) -> Option<GuidePath> {
    let b = *scene.map.bounds();
    let pick = |g: &mut Gen| {
        for _ in 0..20 {
            let mut p = Vec3::zeros();
            for i in 0..3 {
                p[i] = b.min[i] + (b.max[i] - b.min[i]) * ordinary(g, 0.05, 0.95);
            }
            if scene.static_clearance(&p) > 0.3 {
                return Some(p);
            }
        }
        None
    };
    let (s, e) = (pick(g)?, pick(g)?);
    GuidePath::new(vec![s, e]).ok()
}

/// Every numeric parameter at an edge, one at a time or in pairs (see the module docs).
pub fn params_edges(g: &mut Gen, fx: &Fixtures) -> Outcome {
    let map = if g.chance(0.5) {
        &fx.shapes_map
    } else {
        &fx.cloud_map
    };
    let Ok(scene) = Scene::new(map, &fx.forecasts, 0.0) else {
        return Outcome::Err;
    };
    let Some(guide) = free_pair(g, &scene) else {
        return Outcome::Err;
    };
    let req = request(g, &guide);
    let (built, edited): (Result<Box<dyn TrajectoryBackend>, _>, Vec<String>) = if g.chance(0.5) {
        let Some((p, e)) = perturb(g, &trust_minco::UtfMincoParams::default()) else {
            return Outcome::Err;
        };
        (
            trust_minco::UtfMinco::new(p).map(|b| Box::new(b) as Box<dyn TrajectoryBackend>),
            e,
        )
    } else {
        let Some((p, e)) = perturb(g, &trust_minco::MincoParams::default()) else {
            return Outcome::Err;
        };
        (
            trust_minco::Minco::new(p).map(|b| Box::new(b) as Box<dyn TrajectoryBackend>),
            e,
        )
    };
    let backend = match built {
        Ok(b) => b,
        Err(e) => {
            let msg = e.to_string();
            if longest_digit_run(&msg) > 20 {
                return Outcome::Wrong(format!("unreadable number: {msg}"));
            }
            // `solver.lbfgs.*` errors are wrapped under `params.solver.lbfgs`.
            let named = edited.iter().any(|p| {
                let name = reported_name(p);
                msg.contains(&format!("params.{name}"))
                    || (name.starts_with("solver.lbfgs") && msg.contains("params.solver.lbfgs"))
            });
            if !named {
                return Outcome::Wrong(format!("edited {edited:?}, error names: {msg}"));
            }
            return Outcome::Err;
        }
    };
    match backend.optimize(&req, &scene) {
        Ok(sol) => {
            let c = &sol.costs;
            if ![c.ht, c.hs, c.io, c.id, c.ie, c.total]
                .iter()
                .all(|v| v.is_finite())
            {
                return Outcome::NonFinite(format!("{edited:?}: costs {c:?}"));
            }
            check_violations(&sol, &scene, &req.limits)
        }
        // The request is valid and the parameters were accepted: any error is the defect.
        Err(e) => Outcome::Wrong(format!("accepted {edited:?}, then: {e}")),
    }
}

/// Random requests, warm starts outside the map included (see the module docs).
pub fn violations_oracle(g: &mut Gen, fx: &Fixtures) -> Outcome {
    let map = if g.chance(0.5) {
        &fx.shapes_map
    } else {
        &fx.cloud_map
    };
    let Ok(scene) = Scene::new(map, &fx.forecasts, 0.0) else {
        return Outcome::Err;
    };
    let Some(guide) = free_pair(g, &scene) else {
        return Outcome::Err;
    };
    let warm;
    let mut req = request(g, &guide);
    if g.chance(0.4) {
        // A warm start that runs out of the map at speed.
        let mut piece = [Vec3::zeros(); 6];
        piece[0] = guide.points[0];
        piece[1] = Vec3::new(
            ordinary(g, -12.0, 12.0),
            ordinary(g, -12.0, 12.0),
            ordinary(g, -3.0, 3.0),
        );
        warm = PolyTraj::new(0.0, vec![ordinary(g, 0.5, 6.0)], vec![piece]);
        match &warm {
            Ok(t) => req.initial = InitialGuess::WarmStart(t),
            Err(_) => return Outcome::Err,
        }
    }
    if g.chance(0.3) {
        req.max_evaluations = Some(1 + g.index(10));
    }
    let sol = if g.chance(0.5) {
        trust_minco::UtfMinco::default().optimize(&req, &scene)
    } else {
        trust_minco::Minco::default().optimize(&req, &scene)
    };
    match sol {
        Ok(sol) => check_violations(&sol, &scene, &req.limits),
        Err(e) => {
            let msg = e.to_string();
            if longest_digit_run(&msg) > 20 {
                Outcome::Wrong(format!("unreadable number: {msg}"))
            } else {
                Outcome::Err
            }
        }
    }
}

/// The oracle on an `Ok` solution: what an independent dense check finds is listed, and what is
/// listed is real.
fn check_violations(sol: &trust_core::Solution, scene: &Scene<'_>, limits: &Limits) -> Outcome {
    const TOL: f64 = 1e-6;
    let traj = &sol.traj;
    let has = |pred: &dyn Fn(&Violation) -> bool| sol.violations.iter().any(pred);
    let b = scene.map.bounds();
    // What `verify_trajectory` may miss between its instants (spacing ≤ VERIFY_STEP_S, or
    // longer on trajectories above 82 s): half a spacing of motion, of acceleration (for the
    // speed) and of jerk (for the acceleration).
    let h = trust_core::VERIFY_STEP_S.max(traj.duration() / trust_core::VERIFY_MAX_SAMPLES as f64);
    let (mut v_top, mut a_top, mut j_top) = (0.0_f64, 0.0_f64, 0.0_f64);
    let step = (traj.duration() / 20_000.0).max(0.005);
    let _ = traj.for_each_sample(step, |t, s| {
        v_top = v_top.max(s.v.norm());
        a_top = a_top.max(s.a.norm());
        j_top = j_top.max(traj.jerk(t).norm());
    });
    let (slack_p, slack_v, slack_a) = (
        v_top * h / 2.0 + TOL,
        a_top * h / 2.0 + TOL,
        j_top * h / 2.0 + TOL,
    );
    let mut found = [false; 5]; // static, dynamic, bounds, speed, accel
    let result = traj.for_each_sample(step, |t, s| {
        if scene.static_clearance(&s.p) < -slack_p {
            found[0] = true;
        }
        if scene.dynamic_clearance(&s.p, t) < -slack_p {
            found[1] = true;
        }
        if (0..3).any(|i| s.p[i] < b.min[i] - slack_p || s.p[i] > b.max[i] + slack_p) {
            found[2] = true;
        }
        if s.v.norm() > limits.v_max + slack_v {
            found[3] = true;
        }
        if s.a.norm() > limits.a_max + slack_a {
            found[4] = true;
        }
    });
    if result.is_err() {
        return Outcome::Ok;
    }
    let listed = [
        has(&|v| matches!(v, Violation::StaticPenetration { .. })),
        has(&|v| matches!(v, Violation::DynamicPenetration { .. })),
        has(&|v| matches!(v, Violation::LeavesBounds { .. })),
        has(&|v| matches!(v, Violation::OverSpeed { .. })),
        has(&|v| matches!(v, Violation::OverAccel { .. })),
    ];
    let names = [
        "static penetration",
        "dynamic penetration",
        "leaving the bounds",
        "over-speed",
        "over-acceleration",
    ];
    for k in 0..5 {
        if found[k] && !listed[k] {
            return Outcome::Wrong(format!(
                "Ok with unreported {} ({:?}; listed {:?})",
                names[k], sol.stats.status, sol.violations
            ));
        }
    }
    for v in &sol.violations {
        let real = match *v {
            Violation::StaticPenetration { depth_m, point, .. } => {
                let p = Vec3::new(point[0], point[1], point[2]);
                depth_m > 0.0 && (scene.static_clearance(&p) + depth_m).abs() < 1e-6
            }
            Violation::DynamicPenetration {
                forecast,
                depth_m,
                t,
                point,
            } => {
                let p = Vec3::new(point[0], point[1], point[2]);
                scene
                    .forecasts
                    .get(forecast)
                    .is_some_and(|f| (f.signed_distance(&p, t) + depth_m).abs() < 1e-6)
            }
            Violation::LeavesBounds { by_m, .. } => by_m > 0.0,
            Violation::OverSpeed { v, v_max, t } => {
                v > v_max && (traj.velocity(t).norm() - v).abs() <= 1e-6 * v.max(1.0)
            }
            Violation::OverAccel { a, a_max, t } => {
                a > a_max && (traj.acceleration(t).norm() - a).abs() <= 1e-6 * a.max(1.0)
            }
            _ => true,
        };
        if !real {
            return Outcome::Wrong(format!("listed violation not found again: {v:?}"));
        }
        if longest_digit_run(&v.to_string()) > 20 {
            return Outcome::Wrong(format!("unreadable violation text: {v}"));
        }
    }
    Outcome::Ok
}
