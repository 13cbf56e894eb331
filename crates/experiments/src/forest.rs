//! MIT-ACL's dynamic-forest benchmark (`trust-sim forest`): the tiers easy / medium / hard (50 /
//! 100 / 200 obstacles, `trust_scenes::dynamic_forest`) flown by our planners in closed loop and
//! scored with the peers' metrics (`scripts/analyze_dynamic_benchmark.py` and
//! `scripts/run_benchmark.py` of mit-acl/sando; `docs/dynamic-forest.md`).
//!
//! Trial `i` of every tier flies the scenario with seed `seed + i` (the world, the sensor noise
//! and the planner's stream derive from it), the planners of one trial one after the other on
//! its world; (tier, trial) pairs run in parallel and the rows are collected in order, so the
//! results do not depend on `--jobs` (apart from the timing columns).
//!
//! **Scoring** ([`score`]), from the logged true states (at least 50 Hz, `run-log-v1`):
//! success = arrived within the goal tolerance (0.5 m) without a collision — our collision test
//! is the drone's 0.1 m sphere touching an obstacle, stricter than the peers' "centre inside a
//! box"; travel time; path length; the smallest clearance (distance from the drone's centre to
//! the nearest obstacle surface less its radius); per-axis violations counted as the peers count
//! them — one per sample and axis with `|component| > limit + 1e-3` — for the velocity, the
//! acceleration and the jerk (finite differences of consecutive logged accelerations; our
//! vehicle has no jerk limit, so jerk is only reported), with the fraction of samples that
//! violate on any axis beside each count (the peers' counts are per commanded-trajectory
//! message, ours per logged state: compare fractions, not counts).
//!
//! Output in the `--out` directory: `forest.json` (the [`ForestConfig`]), `runs.csv` and
//! `runs.json` (one [`ForestRow`] per flight), `summary.json` ([`ForestSummary`] per tier and
//! planner), `report.md`, and every run log under `logs/<tier>/<planner>/trial-NNNN.jsonl`.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::str::FromStr;
use std::sync::Mutex;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use trust_flight::scenario::Scenario;
use trust_planner::PlannerPreset;
use trust_runlog::{StateRecord, Status};
use trust_world::map_sensing::{DepthSpec, StaticSensing};
use trust_world::scenario::{DynamicForestParams, GeneratorSpec, Latency, VehicleModel};
use trust_world::{World, WorldError};

use crate::ExperimentError;
use crate::study::{create_dir, fly_logged, progress_bar, trial_seed, write_json, write_text};

/// Tolerance of the peers' violation counts (`limit + 1e-3`).
pub const VIOLATION_TOLERANCE: f64 = 1e-3;

/// A tier of the benchmark.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Tier {
    /// 50 obstacles.
    Easy,
    /// 100 obstacles.
    Medium,
    /// 200 obstacles.
    Hard,
}

impl Tier {
    /// Every tier, easiest first.
    pub const ALL: [Tier; 3] = [Tier::Easy, Tier::Medium, Tier::Hard];

    /// `easy`, `medium` or `hard`.
    pub fn name(&self) -> &'static str {
        match self {
            Tier::Easy => "easy",
            Tier::Medium => "medium",
            Tier::Hard => "hard",
        }
    }

    /// Obstacles of the tier: 50 / 100 / 200 (`run_benchmark.py --cases`).
    pub fn obstacle_count(&self) -> usize {
        match self {
            Tier::Easy => 50,
            Tier::Medium => 100,
            Tier::Hard => 200,
        }
    }

    /// Parses `easy`, `medium`, `hard` or `all`, or a comma-separated list of tiers (duplicates
    /// removed, easiest first).
    ///
    /// # Errors
    /// [`ExperimentError::Input`] naming `--tier` and the word that is not a tier.
    pub fn parse_list(text: &str) -> Result<Vec<Tier>, ExperimentError> {
        let mut tiers = Vec::new();
        for word in text.split(',').map(str::trim) {
            match word {
                "all" => tiers.extend(Tier::ALL),
                "easy" => tiers.push(Tier::Easy),
                "medium" => tiers.push(Tier::Medium),
                "hard" => tiers.push(Tier::Hard),
                other => {
                    return Err(ExperimentError::input(
                        "--tier",
                        format!("`{other}`"),
                        "easy, medium, hard or all (or a comma-separated list)",
                    ));
                }
            }
        }
        tiers.sort();
        tiers.dedup();
        Ok(tiers)
    }
}

/// What the planner knows of the static obstacles (`--static`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum StaticMode {
    /// `known`: the planner is given the pillars' and bars' true shapes.
    #[default]
    Known,
    /// `unknown`: the pillars and bars are not given; the vehicle's depth camera senses them
    /// into an online map (`[sensing.static] = { depth = {} }`, the camera's defaults, unless the
    /// scenario names its own sensor). The peers' "unknown" setting builds the map from a depth
    /// or LiDAR point cloud as well.
    Unknown,
}

impl FromStr for StaticMode {
    type Err = ExperimentError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim() {
            "known" => Ok(StaticMode::Known),
            "unknown" => Ok(StaticMode::Unknown),
            other => Err(ExperimentError::input(
                "--static",
                format!("`{other}`"),
                "`known` or `unknown`",
            )),
        }
    }
}

/// Everything that determines the benchmark's results (`forest.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ForestConfig {
    /// The scenario file whose generator is `dynamic-forest` (its `obstacle_count` is set per
    /// tier).
    pub scenario: PathBuf,
    /// Tiers, easiest first.
    pub tiers: Vec<Tier>,
    /// Trials per tier and planner.
    pub trials: usize,
    /// Base seed: trial `i` flies seed `seed + i`.
    pub seed: u64,
    /// Planner presets, in report order.
    pub planners: Vec<PlannerPreset>,
    /// What the planner knows of the static obstacles.
    pub static_mode: StaticMode,
    /// Simulated time limit (s), replacing the scenario's 100 s if set.
    pub time_limit_s: Option<f64>,
    /// Latency model, replacing the scenario's if set (`--real-time`).
    pub latency: Option<Latency>,
    /// Vehicle model, replacing the scenario's (perfect tracking) if set.
    pub vehicle: Option<VehicleModel>,
    /// Scored limits (SANDO's `config/sando.yaml`: 5 m/s, 20 m/s², 100 m/s³); velocity and
    /// acceleration are the scenario's.
    pub j_max: f64,
}

/// SANDO's jerk limit (m/s³, `config/sando.yaml`).
pub const SANDO_J_MAX: f64 = 100.0;

impl ForestConfig {
    /// Checks the counts, the time limit and the planner list.
    ///
    /// # Errors
    /// [`ExperimentError::Input`] naming the option.
    pub fn validate(&self) -> Result<(), ExperimentError> {
        if self.tiers.is_empty() {
            return Err(ExperimentError::input(
                "--tier",
                "(none)",
                "easy, medium, hard or all",
            ));
        }
        if self.trials == 0 {
            return Err(ExperimentError::input("--trials", 0, "at least 1"));
        }
        crate::error::check_planner_list("--planner", &self.planners)?;
        crate::error::check_time_limit(self.time_limit_s)?;
        if !(self.j_max.is_finite() && self.j_max > 0.0) {
            return Err(ExperimentError::input(
                "j_max",
                self.j_max,
                "a positive jerk limit (m/s³)",
            ));
        }
        Ok(())
    }

    /// The scenario of `tier`, trial `trial`, flown by `planner`.
    ///
    /// # Errors
    /// [`ExperimentError::Input`] if the base scenario's generator is not `dynamic-forest`.
    pub fn trial_scenario(
        &self,
        base: &Scenario,
        tier: Tier,
        trial: usize,
        planner: PlannerPreset,
    ) -> Result<Scenario, ExperimentError> {
        if !matches!(base.world.generator, Some(GeneratorSpec::DynamicForest(_))) {
            return Err(ExperimentError::input(
                format!("{} world.generator", self.scenario.display()),
                base.world
                    .generator
                    .as_ref()
                    .map_or("(none)", GeneratorSpec::kind_name),
                "kind = \"dynamic-forest\"",
            ));
        }
        let mut s = base.with_seed(trial_seed(self.seed, trial));
        s.world.generator = Some(GeneratorSpec::DynamicForest(DynamicForestParams {
            obstacle_count: tier.obstacle_count(),
        }));
        s.name = format!("{}-{}", base.name, tier.name());
        if let Some(t) = self.time_limit_s {
            s.time_limit_s = t;
        }
        if let Some(l) = self.latency {
            s.sim.latency = l;
        }
        if let Some(m) = self.vehicle {
            s.vehicle.model = m;
        }
        match self.static_mode {
            // The generator's shapes are the planner's map (no point cloud).
            StaticMode::Known => s.static_map.point_cloud = None,
            StaticMode::Unknown => {
                s.static_map.point_cloud = None;
                if s.sensing.static_map == StaticSensing::Known {
                    s.sensing.static_map = StaticSensing::Depth(DepthSpec::default());
                }
            }
        }
        s.planner.name = planner;
        s.planner.frontend = None;
        s.planner.backend = None;
        s.planner.checker = None;
        s.planner.manager = None;
        Ok(s)
    }
}

/// Options of [`run_forest`] that do not change its results.
#[derive(Debug, Clone, Default)]
pub struct ForestOptions {
    /// Worker threads (`None`: one per core).
    pub jobs: Option<usize>,
    /// Show a progress bar on stderr.
    pub progress: bool,
}

/// Per-axis limit violations of one signal (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct AxisViolations {
    /// Samples × axes with `|component| > limit + 1e-3` (the peers' count).
    pub count: usize,
    /// Samples with at least one violating axis.
    pub samples_over: usize,
    /// Samples looked at.
    pub sample_count: usize,
    /// Largest `|component| − limit` over all samples (m/s, m/s², m/s³; ≤ 0 without
    /// violation; 0 without samples).
    pub max_excess: f64,
}

impl AxisViolations {
    /// Fraction of the samples with a violation (0 without samples).
    pub fn fraction(&self) -> f64 {
        if self.sample_count == 0 {
            0.0
        } else {
            self.samples_over as f64 / self.sample_count as f64
        }
    }
}

/// Counts the per-axis violations of `limit` in `samples` (module docs). Non-finite components
/// count as violations.
pub fn axis_violations(samples: &[[f64; 3]], limit: f64) -> AxisViolations {
    let mut v = AxisViolations {
        sample_count: samples.len(),
        max_excess: if samples.is_empty() {
            0.0
        } else {
            f64::NEG_INFINITY
        },
        ..AxisViolations::default()
    };
    for s in samples {
        let mut over = false;
        for &c in s {
            let excess = if c.is_finite() {
                c.abs() - limit
            } else {
                f64::INFINITY
            };
            if excess > VIOLATION_TOLERANCE {
                v.count += 1;
                over = true;
            }
            v.max_excess = v.max_excess.max(excess.min(1e300));
        }
        v.samples_over += usize::from(over);
    }
    v
}

/// Jerk samples by finite differences of consecutive states' accelerations: `(a_{k+1} − a_k) /
/// (t_{k+1} − t_k)`, for each pair more than 1 µs apart (a shorter interval — the last state of
/// a log can follow its predecessor closely — gives no sample).
pub fn finite_difference_jerk(states: &[StateRecord]) -> Vec<[f64; 3]> {
    states
        .windows(2)
        .filter_map(|w| {
            let dt = w[1].t - w[0].t;
            (dt > 1e-6).then(|| std::array::from_fn(|i| (w[1].a[i] - w[0].a[i]) / dt))
        })
        .collect()
}

/// The limits a flight is scored against.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ScoreLimits {
    /// Velocity per axis (m/s).
    pub v_max: f64,
    /// Acceleration per axis (m/s²).
    pub a_max: f64,
    /// Jerk per axis (m/s³).
    pub j_max: f64,
}

/// The peers' per-axis violation metrics of one flight's logged states.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Violations {
    /// Velocity.
    pub velocity: AxisViolations,
    /// Acceleration.
    pub acceleration: AxisViolations,
    /// Jerk (finite differences, [`finite_difference_jerk`]).
    pub jerk: AxisViolations,
}

/// Scores the logged states of one flight against `limits` (module docs).
pub fn score(states: &[StateRecord], limits: &ScoreLimits) -> Violations {
    let v: Vec<[f64; 3]> = states.iter().map(|s| s.v).collect();
    let a: Vec<[f64; 3]> = states.iter().map(|s| s.a).collect();
    Violations {
        velocity: axis_violations(&v, limits.v_max),
        acceleration: axis_violations(&a, limits.a_max),
        jerk: axis_violations(&finite_difference_jerk(states), limits.j_max),
    }
}

/// One flight of the benchmark (a row of `runs.csv` and an element of `runs.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ForestRow {
    /// Tier.
    pub tier: Tier,
    /// Obstacles in the tier.
    pub obstacle_count: usize,
    /// Trial index.
    pub trial: usize,
    /// Trial seed.
    pub seed: u64,
    /// Planner preset name.
    pub planner: String,
    /// `arrived`, `collided`, `timed_out`, `unreachable` or `invalid`.
    pub status: String,
    /// What was hit, or why the run is invalid (empty otherwise).
    pub with: String,
    /// Arrived within the goal tolerance without a collision.
    pub success: bool,
    /// Flight time (s): to the arrival, the collision or the time limit.
    pub travel_time_s: f64,
    /// Path length (m).
    pub path_length_m: f64,
    /// Smallest clearance from any obstacle, static or moving (m; distance to the surface less
    /// the drone's radius).
    pub min_clearance_m: f64,
    /// Smallest clearance from the pillars and bars (m).
    pub min_clearance_static_m: f64,
    /// Smallest clearance from the cubes (m).
    pub min_clearance_dynamic_m: f64,
    /// Largest speed (m/s).
    pub max_speed: f64,
    /// Largest acceleration norm (m/s²).
    pub max_accel: f64,
    /// Velocity violations, samples × axes.
    pub vel_violation_count: usize,
    /// Fraction of the samples with a velocity violation.
    pub vel_violation_fraction: f64,
    /// Largest per-axis velocity excess (m/s).
    pub vel_max_excess: f64,
    /// Acceleration violations, samples × axes.
    pub acc_violation_count: usize,
    /// Fraction of the samples with an acceleration violation.
    pub acc_violation_fraction: f64,
    /// Largest per-axis acceleration excess (m/s²).
    pub acc_max_excess: f64,
    /// Jerk violations, samples × axes.
    pub jerk_violation_count: usize,
    /// Fraction of the jerk samples with a violation.
    pub jerk_violation_fraction: f64,
    /// Largest per-axis jerk excess (m/s³).
    pub jerk_max_excess: f64,
    /// Logged states scored.
    pub sample_count: usize,
    /// Planning cycles.
    pub cycles: usize,
    /// Cycles that ended in a fallback manoeuvre.
    pub fallbacks: usize,
    /// Median cycle time (ms). Timing.
    pub cycle_ms_median: f64,
    /// Longest cycle (ms). Timing.
    pub cycle_ms_max: f64,
    /// Wall time of the flight (s). Timing.
    pub wall_s: f64,
    /// The run log, relative to the output directory.
    pub log: String,
}

/// `runs.csv` text: a header and one line per row (free text with `,` or newlines cleaned).
pub fn runs_csv(rows: &[ForestRow]) -> String {
    let mut out = String::from(
        "tier,obstacle_count,trial,seed,planner,status,with,success,travel_time_s,path_length_m,\
         min_clearance_m,min_clearance_static_m,min_clearance_dynamic_m,max_speed,max_accel,\
         vel_violation_count,vel_violation_fraction,vel_max_excess,acc_violation_count,\
         acc_violation_fraction,acc_max_excess,jerk_violation_count,jerk_violation_fraction,\
         jerk_max_excess,sample_count,cycles,fallbacks,cycle_ms_median,cycle_ms_max,wall_s,log\n",
    );
    let clean = |s: &str| s.replace([',', '\n', '\r', '"'], ";");
    for r in rows {
        let _ = writeln!(
            out,
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            r.tier.name(),
            r.obstacle_count,
            r.trial,
            r.seed,
            clean(&r.planner),
            clean(&r.status),
            clean(&r.with),
            r.success,
            r.travel_time_s,
            r.path_length_m,
            r.min_clearance_m,
            r.min_clearance_static_m,
            r.min_clearance_dynamic_m,
            r.max_speed,
            r.max_accel,
            r.vel_violation_count,
            r.vel_violation_fraction,
            r.vel_max_excess,
            r.acc_violation_count,
            r.acc_violation_fraction,
            r.acc_max_excess,
            r.jerk_violation_count,
            r.jerk_violation_fraction,
            r.jerk_max_excess,
            r.sample_count,
            r.cycles,
            r.fallbacks,
            r.cycle_ms_median,
            r.cycle_ms_max,
            r.wall_s,
            clean(&r.log),
        );
    }
    out
}

/// Runs the benchmark of `config`, writing everything into `out` (module docs). Returns the
/// rows, sorted by tier, trial and planner.
///
/// # Errors
/// [`ExperimentError`] for an invalid configuration or scenario and file-system failures; a
/// planner that fails mid-flight is not an error (its row says `invalid`).
pub fn run_forest(
    config: &ForestConfig,
    out: &Path,
    options: &ForestOptions,
) -> Result<Vec<ForestRow>, ExperimentError> {
    config.validate()?;
    let base = trust_flight::scenario::load(&config.scenario)?;
    // Every problem of the first trial of each tier and planner before any flight.
    for &tier in &config.tiers {
        for &p in &config.planners {
            let s = config.trial_scenario(&base, tier, 0, p)?;
            let problems = trust_flight::scenario::check(&s);
            if !problems.is_empty() {
                return Err(WorldError::Invalid {
                    path: s.origin(),
                    problems,
                }
                .into());
            }
        }
    }
    create_dir(out)?;
    write_json(&out.join("forest.json"), config)?;
    let jobs: Vec<(Tier, usize)> = config
        .tiers
        .iter()
        .flat_map(|&t| (0..config.trials).map(move |i| (t, i)))
        .collect();
    let bar = progress_bar(
        options.progress,
        (jobs.len() * config.planners.len()) as u64,
    );
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(options.jobs.unwrap_or(0))
        .build()
        .map_err(|e| ExperimentError::input("--jobs", options.jobs.unwrap_or(0), e.to_string()))?;
    let first_error: Mutex<Option<ExperimentError>> = Mutex::new(None);
    let rows: Vec<ForestRow> = pool.install(|| {
        jobs.par_iter()
            .flat_map_iter(|&(tier, trial)| {
                match fly_trial(config, &base, tier, trial, out, &bar) {
                    Ok(rows) => rows,
                    Err(e) => {
                        let mut slot = first_error.lock().unwrap_or_else(|p| p.into_inner());
                        slot.get_or_insert(e);
                        Vec::new()
                    }
                }
            })
            .collect()
    });
    bar.finish_and_clear();
    if let Some(e) = first_error.into_inner().unwrap_or_else(|p| p.into_inner()) {
        return Err(e);
    }
    write_text(&out.join("runs.csv"), &runs_csv(&rows))?;
    write_json(&out.join("runs.json"), &rows)?;
    let summary = summarize(config, &rows);
    write_json(&out.join("summary.json"), &summary)?;
    let limits = ScoreLimits {
        v_max: base.vehicle.limits.v_max,
        a_max: base.vehicle.limits.a_max,
        j_max: config.j_max,
    };
    write_text(
        &out.join("report.md"),
        &report_md(config, &limits, &summary),
    )?;
    Ok(rows)
}

fn fly_trial(
    config: &ForestConfig,
    base: &Scenario,
    tier: Tier,
    trial: usize,
    out: &Path,
    bar: &indicatif::ProgressBar,
) -> Result<Vec<ForestRow>, ExperimentError> {
    let mut rows = Vec::with_capacity(config.planners.len());
    let mut world: Option<World> = None;
    for &planner in &config.planners {
        let s = config.trial_scenario(base, tier, trial, planner)?;
        let w = match world.take() {
            Some(w) => w.with_scenario(&s)?,
            None => World::build(&s)?,
        };
        let spec = trust_flight::scenario::resolve_planner(&s);
        let rel = format!(
            "logs/{}/{}/trial-{trial:04}.jsonl",
            tier.name(),
            planner.name()
        );
        let flight = fly_logged(&w, &s, &spec, &out.join(&rel))?;
        let limits = ScoreLimits {
            v_max: s.vehicle.limits.v_max,
            a_max: s.vehicle.limits.a_max,
            j_max: config.j_max,
        };
        let v = score(&flight.record.states, &limits);
        let sum = &flight.summary;
        let o = &sum.outcome;
        rows.push(ForestRow {
            tier,
            obstacle_count: tier.obstacle_count(),
            trial,
            seed: sum.seed,
            planner: planner.name().to_string(),
            status: o.status.as_str().to_string(),
            with: o.with.clone().unwrap_or_default(),
            success: o.status == Status::Arrived,
            travel_time_s: o.flight_time_s,
            path_length_m: o.path_length_m,
            min_clearance_m: o.min_clearance_static_m.min(o.min_clearance_dynamic_m),
            min_clearance_static_m: o.min_clearance_static_m,
            min_clearance_dynamic_m: o.min_clearance_dynamic_m,
            max_speed: o.max_speed,
            max_accel: o.max_accel,
            vel_violation_count: v.velocity.count,
            vel_violation_fraction: v.velocity.fraction(),
            vel_max_excess: v.velocity.max_excess,
            acc_violation_count: v.acceleration.count,
            acc_violation_fraction: v.acceleration.fraction(),
            acc_max_excess: v.acceleration.max_excess,
            jerk_violation_count: v.jerk.count,
            jerk_violation_fraction: v.jerk.fraction(),
            jerk_max_excess: v.jerk.max_excess,
            sample_count: v.velocity.sample_count,
            cycles: sum.cycle_count,
            fallbacks: sum.fallback_count,
            cycle_ms_median: sum.cycle_ms_median,
            cycle_ms_max: sum.cycle_ms_max,
            wall_s: sum.wall_s,
            log: rel,
        });
        bar.inc(1);
        world = Some(w);
    }
    Ok(rows)
}

/// A sample mean and standard deviation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MeanSd {
    /// Sample size.
    pub n: usize,
    /// Mean (`null` when `n = 0`).
    pub mean: Option<f64>,
    /// Sample standard deviation (`null` when `n < 2`).
    pub sd: Option<f64>,
}

/// Mean and sample standard deviation of the finite values of `xs`.
pub fn mean_sd(xs: &[f64]) -> MeanSd {
    let v: Vec<f64> = xs.iter().copied().filter(|x| x.is_finite()).collect();
    let n = v.len();
    let mean = (n > 0).then(|| v.iter().sum::<f64>() / n as f64);
    let sd = mean
        .filter(|_| n >= 2)
        .map(|m| (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt());
    MeanSd { n, mean, sd }
}

/// The benchmark's figures for one tier and planner (`summary.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ForestSummary {
    /// Tier.
    pub tier: Tier,
    /// Planner preset name.
    pub planner: String,
    /// Flights.
    pub trials: usize,
    /// Successful flights.
    pub successes: usize,
    /// Flights that collided.
    pub collisions: usize,
    /// Flights that ran out of time.
    pub timeouts: usize,
    /// Travel time of the successful flights (s).
    pub travel_time_s: MeanSd,
    /// Path length of the successful flights (m).
    pub path_length_m: MeanSd,
    /// Smallest clearance over all flights (m).
    pub min_clearance_m: f64,
    /// Velocity violations (samples × axes), summed over the flights.
    pub vel_violation_count: usize,
    /// Acceleration violations, summed.
    pub acc_violation_count: usize,
    /// Jerk violations, summed.
    pub jerk_violation_count: usize,
    /// Mean over the flights of the fraction of samples with a velocity violation.
    pub vel_violation_fraction: f64,
    /// Same for the acceleration.
    pub acc_violation_fraction: f64,
    /// Same for the jerk.
    pub jerk_violation_fraction: f64,
}

/// Aggregates `rows` per tier and planner, in the configuration's order.
pub fn summarize(config: &ForestConfig, rows: &[ForestRow]) -> Vec<ForestSummary> {
    let mut out = Vec::new();
    for &tier in &config.tiers {
        for p in &config.planners {
            let r: Vec<&ForestRow> = rows
                .iter()
                .filter(|r| r.tier == tier && r.planner == p.name())
                .collect();
            let ok: Vec<&&ForestRow> = r.iter().filter(|r| r.success).collect();
            let n = r.len().max(1) as f64;
            out.push(ForestSummary {
                tier,
                planner: p.name().to_string(),
                trials: r.len(),
                successes: ok.len(),
                collisions: r.iter().filter(|r| r.status == "collided").count(),
                timeouts: r.iter().filter(|r| r.status == "timed_out").count(),
                travel_time_s: mean_sd(&ok.iter().map(|r| r.travel_time_s).collect::<Vec<_>>()),
                path_length_m: mean_sd(&ok.iter().map(|r| r.path_length_m).collect::<Vec<_>>()),
                min_clearance_m: r
                    .iter()
                    .map(|r| r.min_clearance_m)
                    .fold(trust_flight::NO_OBSTACLE_CLEARANCE_M, f64::min),
                vel_violation_count: r.iter().map(|r| r.vel_violation_count).sum(),
                acc_violation_count: r.iter().map(|r| r.acc_violation_count).sum(),
                jerk_violation_count: r.iter().map(|r| r.jerk_violation_count).sum(),
                vel_violation_fraction: r.iter().map(|r| r.vel_violation_fraction).sum::<f64>() / n,
                acc_violation_fraction: r.iter().map(|r| r.acc_violation_fraction).sum::<f64>() / n,
                jerk_violation_fraction: r.iter().map(|r| r.jerk_violation_fraction).sum::<f64>()
                    / n,
            });
        }
    }
    out
}

fn fmt_mean_sd(m: &MeanSd, digits: usize) -> String {
    match (m.mean, m.sd) {
        (Some(x), Some(s)) => format!("{x:.digits$} ± {s:.digits$}"),
        (Some(x), None) => format!("{x:.digits$}"),
        _ => "—".to_string(),
    }
}

/// The markdown report: one table per tier (ours), the peers' block to fill in, and how to read
/// them.
pub fn report_md(config: &ForestConfig, limits: &ScoreLimits, summary: &[ForestSummary]) -> String {
    let mut md = String::from("# Dynamic forest (MIT-ACL benchmark)\n\n");
    let _ = writeln!(
        md,
        "{} trial(s) per tier and planner from seed {}; static obstacles `{}`; scored limits v {} \
         m/s, a {} m/s², j {} m/s³ per axis (+1e-3). Written by `trust-sim forest`; \
         `docs/dynamic-forest.md` explains the setting.\n",
        config.trials,
        config.seed,
        match config.static_mode {
            StaticMode::Known => "known",
            StaticMode::Unknown => "unknown (depth camera, online map)",
        },
        limits.v_max,
        limits.a_max,
        limits.j_max,
    );
    md.push_str(
        "**Not the peers' information:** our planner sees the moving cubes only as noisy centre \
         measurements through an EKF (constant-velocity forecasts); the peers' \"dynamic\" mode \
         gives their planners the obstacles' true trajectories.\n\n",
    );
    for &tier in &config.tiers {
        let _ = writeln!(
            md,
            "## {} ({} obstacles)\n",
            tier.name(),
            tier.obstacle_count()
        );
        md.push_str(
            "| planner | success | collided / timed out | travel time (s) | path (m) | min clearance (m) \
             | vel / acc / jerk violations (samples × axes) | % samples over (v / a / j) |\n\
             |---|---|---|---|---|---|---|---|\n",
        );
        for s in summary.iter().filter(|s| s.tier == tier) {
            let pct = |k: usize, n: usize| {
                if n == 0 {
                    0.0
                } else {
                    100.0 * k as f64 / n as f64
                }
            };
            let _ = writeln!(
                md,
                "| {} | {}/{} ({:.0} %) | {} / {} | {} | {} | {:.2} | {} / {} / {} | {:.1} / {:.1} / {:.1} |",
                s.planner,
                s.successes,
                s.trials,
                pct(s.successes, s.trials),
                s.collisions,
                s.timeouts,
                fmt_mean_sd(&s.travel_time_s, 1),
                fmt_mean_sd(&s.path_length_m, 1),
                s.min_clearance_m,
                s.vel_violation_count,
                s.acc_violation_count,
                s.jerk_violation_count,
                100.0 * s.vel_violation_fraction,
                100.0 * s.acc_violation_fraction,
                100.0 * s.jerk_violation_fraction,
            );
        }
        md.push_str(
            "\nThe peers' published figures, to set beside ours (fill in from the papers' tables; \
             none are copied here):\n\n\
             | peer (mode) | success | travel time (s) | path (m) | vel / acc / jerk violations |\n\
             |---|---|---|---|---|\n\
             | SANDO (dynamic), arXiv 2604.07599 | — | — | — | — |\n\
             | DYNUS (dynamic), arXiv 2504.16734 | — | — | — | — |\n\n",
        );
    }
    md.push_str(
        "## Reading it\n\n\
         - success = arrived within the goal tolerance (0.5 m) with no collision; our collision \
         test is the drone's 0.1 m sphere touching a box (the peers': the drone's centre inside \
         one). Travel time and path length are over the successful flights (mean ± sample sd).\n\
         - Violations are counted as the peers count them, one per sample and axis beyond the \
         limit + 1e-3, but per logged state (50 Hz) where they count per commanded-trajectory \
         message: compare the fractions of samples, not the counts. Jerk is the finite \
         difference of consecutive logged accelerations; our vehicle model has no jerk limit \
         (the planner penalizes jerk above a_max / 0.3 s).\n\
         - The draws follow the benchmark's distributions from our own seeded stream, not \
         Python's `random`: seed k here is not the peers' world of seed k.\n",
    );
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state(t: f64, v: [f64; 3], a: [f64; 3]) -> StateRecord {
        StateRecord {
            t,
            p: [0.0; 3],
            v,
            a,
            obstacles: Vec::new(),
        }
    }

    const LIMITS: ScoreLimits = ScoreLimits {
        v_max: 5.0,
        a_max: 20.0,
        j_max: 100.0,
    };

    #[test]
    fn a_clean_flight_has_no_violation() {
        // Constant jerk 50 m/s³ along x from rest for 0.2 s: a ≤ 10, v ≤ 1.
        let states: Vec<StateRecord> = (0..=10)
            .map(|k| {
                let t = 0.02 * k as f64;
                state(t, [25.0 * t * t, 0.0, 0.0], [50.0 * t, 0.0, 0.0])
            })
            .collect();
        let v = score(&states, &LIMITS);
        assert_eq!(v.velocity.count + v.acceleration.count + v.jerk.count, 0);
        assert_eq!(v.velocity.sample_count, 11);
        assert_eq!(v.jerk.sample_count, 10);
        assert!((v.jerk.max_excess - (50.0 - 100.0)).abs() < 1e-9);
        assert_eq!(v.velocity.fraction(), 0.0);
    }

    #[test]
    fn violations_are_counted_per_sample_and_axis() {
        let states = vec![
            state(0.0, [5.0005, -5.0, 0.0], [0.0, 0.0, 20.0]),
            // Two axes over: two counts, one sample.
            state(0.02, [5.01, -6.0, 0.0], [0.0, 0.0, 20.0]),
            // a jumps by 21 m/s² in 0.02 s: jerk 1050 m/s³ on y; a_z 21 > 20.
            state(0.04, [0.0, 0.0, 0.0], [0.0, 21.0, 21.0]),
            // The log's last state 0.5 µs later gives no jerk sample.
            state(0.040_000_5, [0.0; 3], [0.0, 0.0, 0.0]),
        ];
        let v = score(&states, &LIMITS);
        assert_eq!(v.velocity.count, 2);
        assert_eq!(v.velocity.samples_over, 1);
        assert!((v.velocity.max_excess - 1.0).abs() < 1e-12);
        assert_eq!(v.acceleration.count, 2);
        assert_eq!(v.acceleration.samples_over, 1);
        assert_eq!(v.jerk.sample_count, 2);
        // 0 -> 1: no jerk; 1 -> 2: y 0 -> 21 (1050 m/s³, counted), z 20 -> 21 (50 m/s³).
        assert_eq!(v.jerk.count, 1);
        assert!((v.jerk.max_excess - 950.0).abs() < 1e-6);
        assert!((v.velocity.fraction() - 0.25).abs() < 1e-12);
        // Non-finite input counts as a violation and leaves the excess finite.
        let bad = axis_violations(&[[f64::NAN, 0.0, 0.0]], 5.0);
        assert_eq!(bad.count, 1);
        assert!(bad.max_excess.is_finite());
        assert_eq!(axis_violations(&[], 5.0).max_excess, 0.0);
    }

    #[test]
    fn tiers_and_static_modes_parse() {
        assert_eq!(Tier::parse_list("all").unwrap(), Tier::ALL.to_vec());
        assert_eq!(
            Tier::parse_list("hard,easy,hard").unwrap(),
            vec![Tier::Easy, Tier::Hard]
        );
        let e = Tier::parse_list("extreme").unwrap_err().to_string();
        assert!(e.contains("--tier") && e.contains("extreme"), "{e}");
        assert_eq!("known".parse::<StaticMode>().unwrap(), StaticMode::Known);
        assert_eq!(
            "unknown".parse::<StaticMode>().unwrap(),
            StaticMode::Unknown
        );
        let e = "partial".parse::<StaticMode>().unwrap_err().to_string();
        assert!(e.contains("partial"), "{e}");
    }

    #[test]
    fn mean_sd_of_small_samples() {
        let m = mean_sd(&[1.0, 3.0, f64::NAN]);
        assert_eq!(m.n, 2);
        assert_eq!(m.mean, Some(2.0));
        assert!((m.sd.unwrap() - 2f64.sqrt()).abs() < 1e-12);
        assert_eq!(mean_sd(&[]).mean, None);
        assert_eq!(mean_sd(&[4.0]).sd, None);
    }
}
