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
//! `t = 0` (as in an occupancy map) and otherwise runs with Fast-Planner's parameters; DEV-PRM runs with
//! its defaults ([`DevPrmParams`]; `--devprm-params '{"obstacle_aware_samples": false}'` overrides
//! fields for ablations) and sees the predictive directional cones over the horizon (`--horizon-s`,
//! default 2 s: the goal, 18 m away, is then within `T_h·v_max = 20 m`, so the goal guidance surface
//! degenerates to the goal point and both planners end their paths at the goal).
//!
//! # What counts as a path (the `metric` field of the output)
//!
//! A homotopy class is only defined for paths in free space: a "path" that cuts through where a moving
//! obstacle may be is not a way around it, and two such paths can be "distinct" only because the
//! obstacle is between them. So the headline metric counts **distinct valid paths**:
//!
//! 1. *valid*: every segment of a returned path keeps clear (clearance 0) of the static map and of the
//!    predictive directional cone of every moving obstacle over the horizon — the same obstacle set the
//!    common checker uses, which ignores a cone that contains the path's start or goal (no path can
//!    avoid such a cone in space; the trajectory has to avoid it in time);
//! 2. *distinct*: the size of the greedy representative set of the valid paths under the ONE common
//!    checker `"uvd+pdc"` (UVD at 0.1 m with the static map and the PDCs as obstacles, so it sees the
//!    moving obstacles), the same for both planners.
//!
//! `distinct_paths_mean`, `paths_per_ms` and `ratio` are that headline metric. The same counted over
//! all returned paths (valid or not) is reported as `raw_distinct_paths_mean`, `raw_paths_per_ms` and
//! `raw_ratio`; it rewards V-PRM for paths through the obstacles' future positions.
//!
//! A second, neutral spatio-temporal check favours neither planner's visibility model: each returned
//! path is flown at constant speed `v_max` from the query time, and it is *st-valid* if every point at
//! its time keeps clear of the forecast obstacles as they are then and of the static map (checked
//! conservatively by stepping in time by clearance / (speed + fastest obstacle motion)). The st-valid
//! paths are then compared as trajectories by temporal visibility deformation ([`Tvd`], 0.05 s): its
//! classes are `st_distinct_paths_mean`, `st_paths_per_ms` and `st_ratio`.
//!
//! Other fields: `cpu_ms_mean` — the planner's own monotonic-clock measurement of the whole search
//! call (`SearchStats::elapsed`; single-threaded, so wall time equals CPU time up to preemption);
//! every `*_per_ms` is Σ count / Σ cpu_ms over the trials (a ratio of sums, not a mean of ratios);
//! `*ratio` = DEV-PRM's value / V-PRM's (paper: 0.338 / 0.186 = 1.82 at K = 10).

use clap::Parser;
use rand::{RngCore, SeedableRng};
use serde_json::json;

use trust_core::{Curve, GuidePath, HomotopyChecker, PathFrontend, PlanError, Rng, Scene, Vec3};
use trust_topo_prm::uvd::{Polyline, polyline_length};
use trust_topo_prm::{DevPrm, DevPrmParams, Tvd, Uvd, Vprm, VprmParams, scenes};

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
    /// DEV-PRM parameters as JSON (`DevPrmParams` fields; missing fields keep their defaults);
    /// `--budget-ms` and `--devprm-max-samples` override `budget_ms` and `max_samples`.
    #[arg(long, default_value = "{}")]
    devprm_params: String,
}

/// Totals of one planner over all trials.
#[derive(Debug, Default)]
struct Totals {
    returned: usize,
    raw_distinct: usize,
    valid: usize,
    distinct: usize,
    st_valid: usize,
    st_distinct: usize,
    cpu_ms: f64,
    samples: usize,
}

impl Totals {
    fn per_ms(&self, count: usize) -> f64 {
        if self.cpu_ms > 0.0 {
            count as f64 / self.cpu_ms
        } else {
            0.0
        }
    }

    fn summary(&self, trials: usize) -> serde_json::Value {
        let n = trials.max(1) as f64;
        let mean = |x: usize| x as f64 / n;
        json!({
            "distinct_paths_mean": mean(self.distinct),
            "cpu_ms_mean": self.cpu_ms / n,
            "paths_per_ms": self.per_ms(self.distinct),
            "valid_paths_mean": mean(self.valid),
            "returned_paths_mean": mean(self.returned),
            "raw_distinct_paths_mean": mean(self.raw_distinct),
            "raw_paths_per_ms": self.per_ms(self.raw_distinct),
            "st_valid_paths_mean": mean(self.st_valid),
            "st_distinct_paths_mean": mean(self.st_distinct),
            "st_paths_per_ms": self.per_ms(self.st_distinct),
            "samples_mean": mean(self.samples),
        })
    }
}

/// Size of the greedy representative set of `curves` under `checker`.
fn distinct_count<C: Curve>(
    curves: &[C],
    checker: &dyn HomotopyChecker,
    scene: &Scene<'_>,
) -> Result<usize, PlanError> {
    let mut kept: Vec<&C> = Vec::new();
    for c in curves {
        let mut new = true;
        for k in &kept {
            if checker.equivalent(*k, c, scene)? {
                new = false;
                break;
            }
        }
        if new {
            kept.push(c);
        }
    }
    Ok(kept.len())
}

/// A path flown at constant `speed` from time `t0`: the timed curve of the spatio-temporal check.
#[derive(Debug, Clone)]
struct ConstantSpeedPath<'a> {
    points: &'a [Vec3],
    length: f64,
    t0: f64,
    speed: f64,
}

impl<'a> ConstantSpeedPath<'a> {
    fn new(path: &'a GuidePath, t0: f64, speed: f64) -> Self {
        ConstantSpeedPath {
            points: &path.points,
            length: polyline_length(&path.points),
            t0,
            speed,
        }
    }

    fn duration(&self) -> f64 {
        self.length / self.speed
    }

    /// The point at arc length `s` (clamped to the path).
    fn point_at_length(&self, s: f64) -> Vec3 {
        let mut walked = 0.0;
        for w in self.points.windows(2) {
            let seg = (w[1] - w[0]).norm();
            if walked + seg >= s && seg > 0.0 {
                return w[0] + (w[1] - w[0]) * ((s - walked) / seg).clamp(0.0, 1.0);
            }
            walked += seg;
        }
        self.points[self.points.len() - 1]
    }
}

impl Curve for ConstantSpeedPath<'_> {
    fn length(&self) -> f64 {
        self.length
    }

    fn resample_by_arc_length(&self, count: usize, out: &mut Vec<Vec3>) {
        Polyline(self.points).resample_by_arc_length(count, out);
    }

    fn time_span(&self) -> Option<(f64, f64)> {
        Some((self.t0, self.t0 + self.duration()))
    }

    fn position_at_time(&self, t: f64) -> Option<Vec3> {
        Some(self.point_at_length(self.speed * (t - self.t0)))
    }
}

/// Smallest time step of the spatio-temporal check (s): a graze shallower than the relative motion
/// over this step may be missed.
const ST_MIN_STEP_S: f64 = 1e-3;

/// Whether the path flown at its speed keeps clear of everything in `scene` at every instant. Steps in
/// time by `clearance / (path speed + fastest obstacle motion)`: the clearance cannot drop to zero
/// within such a step.
fn st_valid(path: &ConstantSpeedPath<'_>, scene: &Scene<'_>) -> bool {
    // Signed distances change at most by the centre speed plus twice the growth rate (radius and, for
    // cylinders, height), with a √2 margin for the cylinder's combined radial/vertical distance.
    let obstacle_rate = scene
        .forecasts
        .iter()
        .map(|f| std::f64::consts::SQRT_2 * (f.v0.norm() + 2.0 * f.mu))
        .fold(0.0, f64::max);
    let rate = path.speed + obstacle_rate;
    let (t_start, t_end) = (path.t0, path.t0 + path.duration());
    let mut t = t_start;
    loop {
        let p = path.point_at_length(path.speed * (t - t_start));
        let d = scene.clearance(&p, t);
        if d.is_nan() || d < 0.0 {
            return false;
        }
        if t >= t_end {
            return true;
        }
        t = (t + (d / rate).max(ST_MIN_STEP_S)).min(t_end);
    }
}

fn run(args: &Args) -> Result<serde_json::Value, PlanError> {
    let scene_params = scenes::SceneParams {
        horizon_s: args.horizon_s,
        ..scenes::SceneParams::default()
    };
    let devprm_params: DevPrmParams = serde_json::from_str(&args.devprm_params).map_err(|e| {
        PlanError::invalid(
            "--devprm-params",
            &args.devprm_params,
            format!("a JSON object of DevPrmParams fields ({e})"),
        )
    })?;
    // Both planners sample the same box, so that the comparison measures the PDC enhancements
    // and not the region.
    let vprm = Vprm::new(VprmParams {
        budget_ms: args.budget_ms,
        max_samples: args.vprm_max_samples,
        inflate: devprm_params.inflate,
        ..VprmParams::default()
    })?;
    let devprm = DevPrm::new(DevPrmParams {
        budget_ms: args.budget_ms,
        max_samples: args.devprm_max_samples,
        ..devprm_params
    })?;
    let checker = Uvd::with_pdc(args.horizon_s)?;
    let st_checker = Tvd::default();
    let planners: [&dyn PathFrontend; 2] = [&vprm, &devprm];
    let mut totals = [Totals::default(), Totals::default()];
    let mut master = Rng::seed_from_u64(args.seed);
    for _ in 0..args.trials {
        let mut scene_rng = Rng::seed_from_u64(master.next_u64());
        let world = scenes::random_dynamic_scene(args.obstacles, &scene_params, &mut scene_rng)?;
        let t0 = world.query.start.t;
        let scene = Scene::new(&world.map, &world.forecasts, t0)?;
        let speed = world.query.limits.v_max;
        let planner_seed = master.next_u64();
        for (planner, total) in planners.iter().zip(&mut totals) {
            let mut rng = Rng::seed_from_u64(planner_seed);
            let result = planner.search(&world.query, &scene, &mut rng)?;
            let mut valid: Vec<GuidePath> = Vec::with_capacity(result.paths.len());
            for p in &result.paths {
                let obstacles = checker.obstacles(p, p, &scene)?;
                if p.points
                    .windows(2)
                    .all(|w| obstacles.segment_clear(&w[0], &w[1], 0.0))
                {
                    valid.push(p.clone());
                }
            }
            let timed: Vec<ConstantSpeedPath<'_>> = result
                .paths
                .iter()
                .map(|p| ConstantSpeedPath::new(p, t0, speed))
                .filter(|p| st_valid(p, &scene))
                .collect();
            total.returned += result.paths.len();
            total.raw_distinct += distinct_count(&result.paths, &checker, &scene)?;
            total.valid += valid.len();
            total.distinct += distinct_count(&valid, &checker, &scene)?;
            total.st_valid += timed.len();
            total.st_distinct += distinct_count(&timed, &st_checker, &scene)?;
            total.cpu_ms += result.stats.elapsed.as_secs_f64() * 1e3;
            total.samples += result.stats.sample_count;
        }
    }
    let [v, d] = &totals;
    let ratio = |dev: f64, v: f64| if v > 0.0 { dev / v } else { f64::NAN };
    Ok(json!({
        "obstacles": args.obstacles,
        "trials": args.trials,
        "seed": args.seed,
        "budget_ms": args.budget_ms,
        "horizon_s": args.horizon_s,
        "vprm_max_samples": args.vprm_max_samples,
        "devprm_max_samples": args.devprm_max_samples,
        "devprm_params": devprm.params(),
        "checker": checker.name(),
        "st_checker": st_checker.name(),
        "metric": "headline (distinct_paths_mean, paths_per_ms, ratio): returned paths clear of the \
                   static map and of every moving obstacle's PDC over the horizon (cones containing \
                   the path's start or goal ignored, as the checker does), counted as the greedy \
                   representative set under the common uvd+pdc checker; raw_*: the same over all \
                   returned paths; st_*: paths flown at v_max from t0 that keep clear of the forecast \
                   obstacles at every instant, counted under TVD (0.05 s); per_ms = sum of counts / \
                   sum of the planners' own cpu_ms over trials",
        "vprm": v.summary(args.trials),
        "devprm": d.summary(args.trials),
        "ratio": ratio(d.per_ms(d.distinct), v.per_ms(v.distinct)),
        "raw_ratio": ratio(d.per_ms(d.raw_distinct), v.per_ms(v.raw_distinct)),
        "st_ratio": ratio(d.per_ms(d.st_distinct), v.per_ms(v.st_distinct)),
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
