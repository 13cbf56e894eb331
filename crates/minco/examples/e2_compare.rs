//! Experiment E2 (paper Table Sim-A-2): UTF-MINCO vs MINCO on the static and dynamic E2 scenes.
//!
//! Runs each backend `R` times per case (first argument, default 20) and prints one JSON object:
//! per case and method the median CPU time of one `optimize` call (`cpu_ms`, wall clock of a
//! single-threaded call), the trajectory duration, whether it stays clear of every obstacle at
//! dense times (every 5 ms, `Scene::clearance ≥ 0`, forecasts included), the minimum clearance,
//! the solve status and evaluation count, and the largest speed and acceleration.
//!
//! ```text
//! cargo run --release -p trust-minco --example e2_compare -- 50
//! ```
//!
//! Paper (C++ on an i9-13980HX): UTF-MINCO 8.98 ms / 7.08 s static, 9.71 ms / 6.47 s dynamic;
//! MINCO 7.77 / 7.09 and 8.52 / 6.72 (MINCO collides in the dynamic case).

use serde_json::{Map, Value, json};
use trust_core::{InitialGuess, PlanError, Solution, TrajRequest, TrajectoryBackend};
use trust_minco::backend::{Minco, UtfMinco};
use trust_minco::scenes::{E2Case, e2_dynamic, e2_static};

/// Dense collision check: smallest clearance every `dt` seconds along the trajectory.
fn min_clearance(case: &E2Case, solution: &Solution, dt: f64) -> Result<f64, PlanError> {
    let scene = case.scene();
    let mut worst = f64::INFINITY;
    solution
        .traj
        .for_each_sample(dt, |t, s| worst = worst.min(scene.clearance(&s.p, t)))?;
    Ok(worst)
}

fn run(case: &E2Case, backend: &dyn TrajectoryBackend, repeats: usize) -> Result<Value, PlanError> {
    let guide = case.guide();
    let req = TrajRequest {
        start: case.start,
        goal: case.goal,
        limits: case.limits,
        initial: InitialGuess::Guide(&guide),
        deadline: None,
    };
    let scene = case.scene();
    let mut times = Vec::with_capacity(repeats);
    let mut last = None;
    for _ in 0..repeats.max(1) {
        let solution = backend.optimize(&req, &scene)?;
        times.push(solution.stats.elapsed.as_secs_f64() * 1e3);
        last = Some(solution);
    }
    let solution = last.expect("at least one run");
    times.sort_by(f64::total_cmp);
    let clearance = min_clearance(case, &solution, 0.005)?;
    let (v, a) = solution.traj.max_speed_and_acceleration(64);
    let end = solution.traj.position(solution.traj.t_end());
    Ok(json!({
        "cpu_ms": times[times.len() / 2],
        "cpu_ms_min": times[0],
        "duration_s": solution.traj.duration(),
        "collision_free": clearance >= 0.0,
        "min_clearance_m": clearance,
        "status": format!("{:?}", solution.stats.status),
        "iterations": solution.stats.iteration_count,
        "evaluations": solution.stats.evaluation_count,
        "pieces": solution.traj.piece_count(),
        "max_speed": v,
        "max_acceleration": a,
        "end_to_goal_m": (end - case.goal).norm(),
        "costs": solution.costs,
    }))
}

fn main() -> Result<(), PlanError> {
    let repeats = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(20);
    let backends: [(&str, Box<dyn TrajectoryBackend>); 2] = [
        ("utf-minco", Box::new(UtfMinco::default())),
        ("minco", Box::new(Minco::default())),
    ];
    let mut out = Map::new();
    for case in [e2_static(), e2_dynamic()] {
        let mut per_method = Map::new();
        for (name, backend) in &backends {
            per_method.insert((*name).into(), run(&case, backend.as_ref(), repeats)?);
        }
        out.insert(case.name.into(), Value::Object(per_method));
    }
    out.insert("repeats".into(), json!(repeats));
    println!(
        "{}",
        serde_json::to_string_pretty(&Value::Object(out)).expect("JSON")
    );
    Ok(())
}
