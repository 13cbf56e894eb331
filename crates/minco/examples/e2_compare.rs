//! Experiment E2 (paper Table Sim-A-2): UTF-MINCO vs MINCO on the static and dynamic E2 scenes.
//!
//! Runs each backend `N` times per case (`--repeats N`, default 20) and prints one JSON object on
//! stdout (progress goes to stderr): per case and method the median CPU time of one `optimize`
//! call (`cpu_ms`, wall clock of a single-threaded call), the trajectory duration, whether it
//! stays clear of every obstacle at dense times (every 5 ms, `Scene::clearance ≥ 0`, forecasts
//! included), the minimum clearance, the solve status and evaluation count, and the largest speed
//! and acceleration. `warm_resolve` is the manager's common case: the same request 0.1 s later,
//! from the state the first solution reaches then, warm-started from that solution (median over
//! the repeats, collision check of the re-solved trajectory).
//!
//! ```text
//! cargo run --release -p trust-minco --example e2_compare -- --repeats 50
//! ```
//!
//! `--random N` instead runs each backend on `N` random scenes of each kind
//! ([`trust_minco::scenes::random_e2_static`], [`trust_minco::scenes::random_e2_dynamic`], seeds
//! `0..N`) and prints, per kind and method: the mean `J` and duration, how many trajectories are
//! collision-free (same dense check), exceed a limit by more than 1 %, and end within 0.5 m of the
//! goal, the mean evaluation count, and the median over scenes of the per-scene median CPU time
//! (`--repeats` runs per scene, default 5 in this mode):
//!
//! ```text
//! cargo run --release -p trust-minco --example e2_compare -- --random 60
//! ```
//!
//! Paper (C++ on an i9-13980HX): UTF-MINCO 8.98 ms / 7.08 s static, 9.71 ms / 6.47 s dynamic;
//! MINCO 7.77 / 7.09 and 8.52 / 6.72 (MINCO collides in the dynamic case).

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde_json::{Map, Value, json};
use trust_core::{
    InitialGuess, PlanError, PolyTraj, Scene, Solution, TrajRequest, TrajectoryBackend,
};
use trust_minco::backend::{Minco, UtfMinco};
use trust_minco::scenes::{E2Case, e2_dynamic, e2_static, random_e2_dynamic, random_e2_static};

/// A random scene generator of `trust_minco::scenes`.
type DrawScene = fn(&mut ChaCha8Rng) -> E2Case;

/// Replanning period of the warm re-solve (s).
const REPLAN_PERIOD_S: f64 = 0.1;

/// Dense collision check: smallest clearance every `dt` seconds along the trajectory.
fn min_clearance(case: &E2Case, traj: &PolyTraj, dt: f64) -> Result<f64, PlanError> {
    let scene = case.scene();
    let mut worst = f64::INFINITY;
    traj.for_each_sample(dt, |t, s| worst = worst.min(scene.clearance(&s.p, t)))?;
    Ok(worst)
}

fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    values.get(values.len() / 2).copied().unwrap_or(f64::NAN)
}

/// Re-solves `REPLAN_PERIOD_S` later from where `previous` is then, warm-started from it.
fn warm_resolve(
    case: &E2Case,
    backend: &dyn TrajectoryBackend,
    previous: &PolyTraj,
    repeats: usize,
) -> Result<Value, PlanError> {
    let t = previous.t_start() + REPLAN_PERIOD_S;
    let req = TrajRequest {
        start: previous.state(t),
        goal: case.goal,
        limits: case.limits,
        initial: InitialGuess::WarmStart(previous),
        deadline: None,
        horizon_s: None,
        max_evaluations: None,
    };
    let scene = Scene {
        t0: t,
        ..case.scene()
    };
    let mut times = Vec::with_capacity(repeats);
    let mut last = None;
    for _ in 0..repeats.max(1) {
        let solution = backend.optimize(&req, &scene)?;
        times.push(solution.stats.elapsed.as_secs_f64() * 1e3);
        last = Some(solution);
    }
    let solution = last.expect("at least one run");
    let clearance = min_clearance(case, &solution.traj, 0.005)?;
    Ok(json!({
        "cpu_ms": median(times),
        "duration_s": solution.traj.duration(),
        "collision_free": clearance >= 0.0,
        "min_clearance_m": clearance,
        "status": format!("{:?}", solution.stats.status),
        "evaluations": solution.stats.evaluation_count,
    }))
}

fn run(case: &E2Case, backend: &dyn TrajectoryBackend, repeats: usize) -> Result<Value, PlanError> {
    let guide = case.guide();
    let req = TrajRequest {
        start: case.start,
        goal: case.goal,
        limits: case.limits,
        initial: InitialGuess::Guide(&guide),
        deadline: None,
        horizon_s: None,
        max_evaluations: None,
    };
    let scene = case.scene();
    let mut times = Vec::with_capacity(repeats);
    let mut last = None;
    for _ in 0..repeats.max(1) {
        let solution = backend.optimize(&req, &scene)?;
        times.push(solution.stats.elapsed.as_secs_f64() * 1e3);
        last = Some(solution);
    }
    let solution: Solution = last.expect("at least one run");
    let cpu_ms_min = times.iter().copied().fold(f64::INFINITY, f64::min);
    let clearance = min_clearance(case, &solution.traj, 0.005)?;
    let warm = warm_resolve(case, backend, &solution.traj, repeats)?;
    let (v, a) = solution.traj.max_speed_and_acceleration(64);
    let end = solution.traj.position(solution.traj.t_end());
    Ok(json!({
        "cpu_ms": median(times),
        "cpu_ms_min": cpu_ms_min,
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
        "warm_resolve": warm,
    }))
}

/// Command line: `--repeats N` (or a bare `N`, the older form) and `--random N`.
struct Args {
    repeats: Option<usize>,
    random: Option<usize>,
}

fn parse_args() -> Result<Args, String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let number = |value: &str, flag: &str| match value.parse::<usize>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err(format!("{flag} expects an integer >= 1, got {value:?}")),
    };
    let mut out = Args {
        repeats: None,
        random: None,
    };
    if let [n] = args.as_slice()
        && !n.starts_with('-')
    {
        out.repeats = Some(number(n, "repeats")?);
        return Ok(out);
    }
    let mut rest = args.iter();
    while let Some(flag) = rest.next() {
        let value = rest.next().ok_or_else(|| format!("{flag} needs a value"))?;
        match flag.as_str() {
            "--repeats" => out.repeats = Some(number(value, flag)?),
            "--random" => out.random = Some(number(value, flag)?),
            _ => {
                return Err(format!(
                    "usage: e2_compare [--repeats N] [--random N], got {args:?}"
                ));
            }
        }
    }
    Ok(out)
}

/// One backend over `scenes` random scenes of one kind: the statistics listed in the module
/// documentation.
fn random_stats(
    draw: DrawScene,
    backend: &dyn TrajectoryBackend,
    scenes: usize,
    repeats: usize,
) -> Result<Value, PlanError> {
    let mut cpu_ms = Vec::with_capacity(scenes);
    let (mut total_j, mut total_duration, mut total_evaluations) = (0.0, 0.0, 0usize);
    let (mut collision_free, mut over_limits, mut at_goal) = (0usize, 0usize, 0usize);
    for seed in 0..scenes as u64 {
        let case = draw(&mut ChaCha8Rng::seed_from_u64(seed));
        let guide = case.guide();
        let req = TrajRequest {
            start: case.start,
            goal: case.goal,
            limits: case.limits,
            initial: InitialGuess::Guide(&guide),
            deadline: None,
            horizon_s: None,
            max_evaluations: None,
        };
        let scene = case.scene();
        let mut times = Vec::with_capacity(repeats);
        let mut last = None;
        for _ in 0..repeats {
            let solution = backend.optimize(&req, &scene)?;
            times.push(solution.stats.elapsed.as_secs_f64() * 1e3);
            last = Some(solution);
        }
        let solution = last.expect("at least one run");
        cpu_ms.push(median(times));
        total_j += solution.costs.total;
        total_duration += solution.traj.duration();
        total_evaluations += solution.stats.evaluation_count;
        collision_free += usize::from(min_clearance(&case, &solution.traj, 0.005)? >= 0.0);
        let (v, a) = solution.traj.max_speed_and_acceleration(64);
        over_limits += usize::from(v > 1.01 * case.limits.v_max || a > 1.01 * case.limits.a_max);
        let end = solution.traj.position(solution.traj.t_end());
        at_goal += usize::from((end - case.goal).norm() <= 0.5);
    }
    let n = scenes as f64;
    Ok(json!({
        "scenes": scenes,
        "mean_j": total_j / n,
        "mean_duration_s": total_duration / n,
        "collision_free": collision_free,
        "over_limits": over_limits,
        "at_goal": at_goal,
        "mean_evaluations": total_evaluations as f64 / n,
        "median_cpu_ms": median(cpu_ms),
    }))
}

fn main() -> Result<(), PlanError> {
    let args = match parse_args() {
        Ok(args) => args,
        Err(message) => {
            eprintln!("{message}");
            std::process::exit(2);
        }
    };
    let backends: [(&str, Box<dyn TrajectoryBackend>); 2] = [
        ("utf-minco", Box::new(UtfMinco::default())),
        ("minco", Box::new(Minco::default())),
    ];
    let mut out = Map::new();
    if let Some(scenes) = args.random {
        let repeats = args.repeats.unwrap_or(5);
        let kinds: [(&str, DrawScene); 2] = [
            ("random_static", random_e2_static),
            ("random_dynamic", random_e2_dynamic),
        ];
        for (kind, draw) in kinds {
            let mut per_method = Map::new();
            for (name, backend) in &backends {
                eprintln!("e2_compare: {kind}, {name}, {scenes} scenes x {repeats} repeats");
                let stats = random_stats(draw, backend.as_ref(), scenes, repeats)?;
                per_method.insert((*name).into(), stats);
            }
            out.insert(kind.into(), Value::Object(per_method));
        }
        out.insert("repeats".into(), json!(repeats));
    } else {
        let repeats = args.repeats.unwrap_or(20);
        for case in [e2_static(), e2_dynamic()] {
            let mut per_method = Map::new();
            for (name, backend) in &backends {
                eprintln!("e2_compare: {} case, {name}, {repeats} repeats", case.name);
                per_method.insert((*name).into(), run(&case, backend.as_ref(), repeats)?);
            }
            out.insert(case.name.into(), Value::Object(per_method));
        }
        out.insert("repeats".into(), json!(repeats));
    }
    println!(
        "{}",
        serde_json::to_string_pretty(&Value::Object(out)).expect("JSON")
    );
    Ok(())
}
