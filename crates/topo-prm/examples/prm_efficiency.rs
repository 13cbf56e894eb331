//! Experiment E1 (paper Sec. IV-A, Fig. Sim-A-1-1(c)): distinct topological paths found per CPU
//! millisecond, DEV-PRM versus V-PRM, in random 20 × 20 × 10 m scenes with `K` moving obstacles.
//!
//! ```text
//! cargo run --release -p trust-topo-prm --example prm_efficiency -- --obstacles 10 --trials 50 --seed 1
//! ```
//!
//! For each trial a scene is drawn with [`scenes::random_dynamic_scene`] (spheres and full-height
//! cylinders, 0.5–3 m/s, `r_o` 0.5–1.5 m, `mu` 0.1–0.3 m/s, start and goal on opposite faces, free at
//! `t = 0`), and both planners run once with the same time budget (20 ms by default, as in the paper)
//! and the same random-sample cap (2000, Fast-Planner's; `--vprm-max-samples`,
//! `--devprm-max-samples` change them). V-PRM sees the moving obstacles frozen where they are at
//! `t = 0` (as in an occupancy map); DEV-PRM sees their predictive directional cones over the horizon
//! (`--horizon-s`, default 2 s: the goal, 18 m away, is then within `T_h·v_max = 20 m`, so the goal
//! guidance surface degenerates to the goal point and both planners end their paths at the goal).
//!
//! Output: one JSON object on stdout.
//! * `checker` — the ONE checker that judges "distinct" for both planners: `"uvd+pdc"`, UVD at 0.1 m
//!   with the static map and the PDCs of all forecasts over the horizon as obstacles, so it sees the
//!   moving obstacles. `distinct_paths` of a run is the size of the greedy representative set of its
//!   returned paths under that checker.
//! * `cpu_ms` — the planner's own monotonic-clock measurement of the whole search call
//!   (`SearchStats::elapsed`; single-threaded, so wall time equals CPU time up to preemption).
//! * `paths_per_ms` = Σ distinct / Σ cpu_ms over all trials (a ratio of sums, not a mean of ratios).
//! * `valid_*` — the same counted over the returned paths that also keep clear (clearance 0) of the
//!   static map and every PDC, i.e. paths that avoid where the moving obstacles may be.
//! * `ratio` = devprm.paths_per_ms / vprm.paths_per_ms (paper: 0.338 / 0.186 = 1.82 at K = 10).

use clap::Parser;
use rand::{RngCore, SeedableRng};
use serde_json::json;

use trust_core::{GuidePath, HomotopyChecker, PathFrontend, PlanError, Rng, Scene};
use trust_topo_prm::visibility::Obstacles;
use trust_topo_prm::{DevPrm, DevPrmParams, Uvd, Vprm, VprmParams, scenes};

/// Command-line arguments.
#[derive(Debug, Parser)]
#[command(about = "E1: distinct paths per CPU ms, DEV-PRM vs V-PRM")]
struct Args {
    /// Number of moving obstacles K.
    #[arg(long, default_value_t = 10)]
    obstacles: usize,
    /// Number of random scenes.
    #[arg(long, default_value_t = 50)]
    trials: usize,
    /// Master seed (scenes and planners derive their seeds from it).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Roadmap time budget of both planners (ms). Paper: 20.
    #[arg(long, default_value_t = 20.0)]
    budget_ms: f64,
    /// Planning horizon T_h (s) of the query, the PDCs and the common checker.
    #[arg(long, default_value_t = 2.0)]
    horizon_s: f64,
    /// Random-sample cap of V-PRM (Fast-Planner's default: 2000).
    #[arg(long, default_value_t = 2000)]
    vprm_max_samples: usize,
    /// Random-sample cap `N_max` of DEV-PRM (default: the same 2000; the paper gives no value).
    #[arg(long, default_value_t = 2000)]
    devprm_max_samples: usize,
}

/// Totals of one planner over all trials.
#[derive(Debug, Default)]
struct Totals {
    returned: usize,
    distinct: usize,
    valid_distinct: usize,
    cpu_ms: f64,
    samples: usize,
}

impl Totals {
    fn summary(&self, trials: usize) -> serde_json::Value {
        let n = trials.max(1) as f64;
        let per_ms = |x: usize| {
            if self.cpu_ms > 0.0 {
                x as f64 / self.cpu_ms
            } else {
                0.0
            }
        };
        json!({
            "distinct_paths_mean": self.distinct as f64 / n,
            "cpu_ms_mean": self.cpu_ms / n,
            "paths_per_ms": per_ms(self.distinct),
            "returned_paths_mean": self.returned as f64 / n,
            "valid_distinct_paths_mean": self.valid_distinct as f64 / n,
            "valid_paths_per_ms": per_ms(self.valid_distinct),
            "samples_mean": self.samples as f64 / n,
        })
    }
}

/// Size of the greedy representative set of `paths` under `checker`.
fn distinct_count(
    paths: &[&GuidePath],
    checker: &dyn HomotopyChecker,
    scene: &Scene<'_>,
) -> Result<usize, PlanError> {
    let mut kept: Vec<&GuidePath> = Vec::new();
    for p in paths {
        let mut new = true;
        for k in &kept {
            if checker.equivalent(*k, *p, scene)? {
                new = false;
                break;
            }
        }
        if new {
            kept.push(p);
        }
    }
    Ok(kept.len())
}

fn run(args: &Args) -> Result<serde_json::Value, PlanError> {
    let scene_params = scenes::SceneParams {
        horizon_s: args.horizon_s,
        ..scenes::SceneParams::default()
    };
    let vprm = Vprm::new(VprmParams {
        budget_ms: args.budget_ms,
        max_samples: args.vprm_max_samples,
        ..VprmParams::default()
    })?;
    let devprm = DevPrm::new(DevPrmParams {
        budget_ms: args.budget_ms,
        max_samples: args.devprm_max_samples,
        ..DevPrmParams::default()
    })?;
    let checker = Uvd::with_pdc(args.horizon_s)?;
    let planners: [&dyn PathFrontend; 2] = [&vprm, &devprm];
    let mut totals = [Totals::default(), Totals::default()];
    let mut master = Rng::seed_from_u64(args.seed);
    for _ in 0..args.trials {
        let mut scene_rng = Rng::seed_from_u64(master.next_u64());
        let world = scenes::random_dynamic_scene(args.obstacles, &scene_params, &mut scene_rng)?;
        let scene = Scene::new(&world.map, &world.forecasts, world.query.start.t)?;
        let pdcs = Obstacles::with_forecast_cones(
            &world.map,
            &world.forecasts,
            world.query.start.t,
            args.horizon_s,
        );
        let planner_seed = master.next_u64();
        for (planner, total) in planners.iter().zip(&mut totals) {
            let mut rng = Rng::seed_from_u64(planner_seed);
            let result = planner.search(&world.query, &scene, &mut rng)?;
            let all: Vec<&GuidePath> = result.paths.iter().collect();
            let valid: Vec<&GuidePath> = result
                .paths
                .iter()
                .filter(|p| {
                    p.points
                        .windows(2)
                        .all(|w| pdcs.segment_clear(&w[0], &w[1], 0.0))
                })
                .collect();
            total.returned += all.len();
            total.distinct += distinct_count(&all, &checker, &scene)?;
            total.valid_distinct += distinct_count(&valid, &checker, &scene)?;
            total.cpu_ms += result.stats.elapsed.as_secs_f64() * 1e3;
            total.samples += result.stats.sample_count;
        }
    }
    let [v, d] = &totals;
    let v_sum = v.summary(args.trials);
    let d_sum = d.summary(args.trials);
    let ratio = |key: &str| {
        let a = d_sum[key].as_f64().unwrap_or(0.0);
        let b = v_sum[key].as_f64().unwrap_or(0.0);
        if b > 0.0 { a / b } else { f64::NAN }
    };
    Ok(json!({
        "obstacles": args.obstacles,
        "trials": args.trials,
        "seed": args.seed,
        "budget_ms": args.budget_ms,
        "horizon_s": args.horizon_s,
        "vprm_max_samples": args.vprm_max_samples,
        "devprm_max_samples": args.devprm_max_samples,
        "checker": checker.name(),
        "paths_per_ms_definition": "sum of distinct paths / sum of cpu_ms over trials",
        "vprm": v_sum,
        "devprm": d_sum,
        "ratio": ratio("paths_per_ms"),
        "valid_ratio": ratio("valid_paths_per_ms"),
    }))
}

fn main() {
    let args = Args::parse();
    match run(&args) {
        Ok(report) => println!("{report}"),
        Err(e) => {
            eprintln!("prm_efficiency: {e}");
            std::process::exit(2);
        }
    }
}
