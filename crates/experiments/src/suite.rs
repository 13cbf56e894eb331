//! The scenario suite (`trust-sim suite`, issue 19): every scenario file of a folder (one file per
//! class — wide wall, U-trap, long trip, Crazyflie rooms, …) flown with `K` seeds for the chosen
//! planners, each flight writing its run log; one table per class (arrived / collided / timed
//! out, flight time against `distance / v_max`, clearances, acceleration against `a_max`) and a
//! chart of the outcomes.
//!
//! Unlike a study ([`crate::study`]), which flies one scenario in the paper's setting, the suite
//! flies each file as written — the global route included (`[planner.route]`, on by default) —
//! with only the planner preset, the seed and the time limit replaced. Files are flown in
//! parallel, each flight from its own seed: the same command gives the same rows.
//!
//! Outputs in the output folder: `runs.csv` (one row per flight: [`SuiteRow`]),
//! `summary.json` ([`ClassSummary`] per class and planner), `report.md` and the chart
//! `outcomes.svg`/`.png`, and `logs/<class>/<planner>-seed<S>.jsonl`.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use trust_flight::scenario::Scenario;
use trust_planner::PlannerPreset;
use trust_plot::{Bar, BarChart, Color, Figure};
use trust_world::World;
use trust_world::scenario::Latency;

use crate::ExperimentError;
use crate::study::{create_dir, fly_logged, write_json, write_text};

/// What a suite flies.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SuiteConfig {
    /// The scenario files, one class each (the class is the file's stem).
    pub files: Vec<PathBuf>,
    /// Seeds per file and planner: `seed, seed + 1, …, seed + seeds − 1`.
    pub seeds: usize,
    /// The first seed.
    pub seed: u64,
    /// Planner presets; empty: each file's own `[planner]` section as written.
    pub planners: Vec<PlannerPreset>,
    /// Simulated time limit (s), replacing the files' if set.
    pub time_limit_s: Option<f64>,
    /// The loop's latency model, replacing the files' `sim.latency` if set (the real-time
    /// mode: `trust-sim suite --real-time`).
    #[serde(default)]
    pub latency: Option<Latency>,
}

/// How to run a suite (nothing here changes its results).
#[derive(Debug, Clone, Default)]
pub struct SuiteOptions {
    /// Worker threads (`None`: one per core).
    pub jobs: Option<usize>,
    /// Show a progress bar.
    pub progress: bool,
    /// Skip the chart.
    pub no_plots: bool,
}

/// One flight of the suite (a row of `runs.csv`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SuiteRow {
    /// The class: the scenario file's stem.
    pub class: String,
    /// The planner label.
    pub planner: String,
    /// The flight's seed.
    pub seed: u64,
    /// `arrived`, `collided`, `timed_out` or `invalid`.
    pub status: String,
    /// What was hit, or why the run is invalid (empty otherwise).
    pub with: String,
    /// Flight time (s).
    pub flight_time_s: f64,
    /// Straight-line distance from the start to the goal (m).
    pub distance_m: f64,
    /// `distance_m / v_max` (s): the flight time no planner can beat.
    pub ideal_time_s: f64,
    /// Path length flown (m).
    pub path_length_m: f64,
    /// Smallest true clearance from the static geometry (m; 1e9 without any).
    pub min_clearance_static_m: f64,
    /// Smallest true clearance from a moving obstacle (m; 1e9 without any).
    pub min_clearance_dynamic_m: f64,
    /// Largest acceleration (m/s²).
    pub max_accel: f64,
    /// The vehicle's `a_max` (m/s²).
    pub a_max: f64,
    /// Cycles that ended in a braking fallback.
    pub fallbacks: usize,
    /// The run log, relative to the output folder.
    pub log: String,
    /// For a collision with a moving obstacle: how long the planner's forecasts had the obstacle
    /// where it hit (s; `trust_runlog::Outcome::forecast_warning_s`); empty otherwise.
    pub forecast_warning_s: Option<f64>,
    /// The vehicle's `v_max` (m/s).
    pub v_max: f64,
    /// The longest planning cycle's wall time (ms).
    pub cycle_ms_max: f64,
    /// Cycles longer than the manager's cycle budget.
    pub over_budget: usize,
    /// Replanning ticks skipped because the planner was busy (real-time mode; 0 otherwise).
    pub skipped_ticks: u64,
    /// Simulated time over the flight's wall time (how many times faster than real time it
    /// flew, planning and simulation included; depends on the machine and its load).
    #[serde(default)]
    pub real_time_factor: f64,
}

impl SuiteRow {
    const COLUMNS: &'static str = "class,planner,seed,status,with,flight_time_s,distance_m,\
                                   ideal_time_s,path_length_m,min_clearance_static_m,\
                                   min_clearance_dynamic_m,max_accel,a_max,fallbacks,log,\
                                   forecast_warning_s,v_max,cycle_ms_max,over_budget,\
                                   skipped_ticks,real_time_factor";

    fn to_line(&self) -> String {
        let clean = |s: &str| s.replace([',', '\n', '\r', '"'], ";");
        format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            clean(&self.class),
            clean(&self.planner),
            self.seed,
            self.status,
            clean(&self.with),
            self.flight_time_s,
            self.distance_m,
            self.ideal_time_s,
            self.path_length_m,
            self.min_clearance_static_m,
            self.min_clearance_dynamic_m,
            self.max_accel,
            self.a_max,
            self.fallbacks,
            clean(&self.log),
            self.forecast_warning_s
                .map_or(String::new(), |w| w.to_string()),
            self.v_max,
            self.cycle_ms_max,
            self.over_budget,
            self.skipped_ticks,
            self.real_time_factor,
        )
    }
}

/// The flights of one class and planner, summarized (`summary.json`, one table row).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ClassSummary {
    /// The class.
    pub class: String,
    /// The planner label.
    pub planner: String,
    /// Flights.
    pub flights: usize,
    /// Arrivals.
    pub arrived: usize,
    /// Collisions.
    pub collided: usize,
    /// Flights that ran out of time.
    pub timed_out: usize,
    /// Invalid runs (the planner rejected its input).
    pub invalid: usize,
    /// Flights ended by the planner's verdict that the goal cannot be reached.
    #[serde(default)]
    pub unreachable: usize,
    /// The longest planning cycle over every flight (ms).
    #[serde(default)]
    pub worst_cycle_ms: f64,
    /// Cycles longer than the cycle budget, over every flight.
    #[serde(default)]
    pub over_budget: usize,
    /// Replanning ticks skipped, over every flight (real-time mode).
    #[serde(default)]
    pub skipped_ticks: u64,
    /// Mean flight time of the arrivals (s).
    pub mean_arrival_time_s: Option<f64>,
    /// Mean `distance / v_max` of the arrivals (s).
    pub mean_ideal_time_s: Option<f64>,
    /// Largest ratio of flight time to `distance / v_max` over the arrivals.
    pub worst_time_ratio: Option<f64>,
    /// Smallest static clearance over every flight (m; `None` without static geometry).
    pub min_clearance_static_m: Option<f64>,
    /// Smallest moving-obstacle clearance over every flight (m; `None` without moving obstacles).
    pub min_clearance_dynamic_m: Option<f64>,
    /// Largest `max_accel / a_max` over every flight.
    pub worst_accel_ratio: f64,
}

/// Clearances at or above this are "no obstacle of that kind" (the run log writes 1e9).
const NO_OBSTACLE: f64 = 1e8;

impl SuiteConfig {
    /// Checks the file list, the seed count and the time limit.
    ///
    /// # Errors
    /// [`ExperimentError::Input`] naming the option.
    pub fn validate(&self) -> Result<(), ExperimentError> {
        if self.files.is_empty() {
            return Err(ExperimentError::input(
                "SCENARIOS",
                "(none)",
                "one or more scenario files or folders holding *.toml files",
            ));
        }
        if self.seeds == 0 {
            return Err(ExperimentError::input("--seeds", 0, "at least 1"));
        }
        if let Some(t) = self.time_limit_s
            && !(t.is_finite() && t > 0.0)
        {
            return Err(ExperimentError::input(
                "--time-limit",
                t,
                "a positive number of seconds",
            ));
        }
        let mut stems: Vec<String> = self.files.iter().map(|f| class_of(f)).collect();
        stems.sort();
        if let Some(w) = stems.windows(2).find(|w| w[0] == w[1]) {
            return Err(ExperimentError::input(
                "SCENARIOS",
                &w[0],
                "files with distinct names (the name is the class)",
            ));
        }
        Ok(())
    }
}

/// The scenario files named by `paths`: files as given, folders expanded to their `*.toml`
/// files (sorted by name, not recursive).
///
/// # Errors
/// [`ExperimentError::Input`] for a path that does not exist or a folder that cannot be read.
pub fn expand_paths(paths: &[PathBuf]) -> Result<Vec<PathBuf>, ExperimentError> {
    let mut out = Vec::new();
    for p in paths {
        if p.is_dir() {
            let entries = std::fs::read_dir(p).map_err(|e| {
                ExperimentError::input(p.display().to_string(), e, "a readable folder")
            })?;
            let mut files: Vec<PathBuf> = entries
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|f| f.extension().is_some_and(|x| x == "toml"))
                .collect();
            files.sort();
            out.extend(files);
        } else if p.is_file() {
            out.push(p.clone());
        } else {
            return Err(ExperimentError::input(
                p.display().to_string(),
                "(missing)",
                "an existing scenario file or folder",
            ));
        }
    }
    Ok(out)
}

/// The class of a scenario file: its stem.
fn class_of(path: &Path) -> String {
    path.file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string())
}

/// Flies the suite, writing everything into `out` (module docs); returns the rows, sorted by
/// class, planner and seed.
///
/// # Errors
/// [`ExperimentError`] for an invalid configuration or scenario (checked for every file before
/// any flight) and file-system failures. A planner that fails mid-flight is not an error: its
/// row says `invalid`.
pub fn run_suite(
    config: &SuiteConfig,
    out: &Path,
    options: &SuiteOptions,
) -> Result<Vec<SuiteRow>, ExperimentError> {
    config.validate()?;
    let mut jobs = Vec::new();
    for file in &config.files {
        let base = trust_flight::scenario::load(file)?;
        let presets: Vec<Option<PlannerPreset>> = if config.planners.is_empty() {
            vec![None]
        } else {
            config.planners.iter().copied().map(Some).collect()
        };
        for preset in presets {
            for k in 0..config.seeds {
                let s = flight_scenario(&base, config, preset, k);
                let problems = s.validate();
                if !problems.is_empty() {
                    return Err(trust_world::WorldError::Invalid {
                        path: s.origin(),
                        problems,
                    }
                    .into());
                }
                jobs.push((class_of(file), s));
            }
        }
    }
    create_dir(out)?;
    write_json(&out.join("suite.json"), config)?;
    let bar = crate::study::progress_bar(options.progress, jobs.len() as u64);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(options.jobs.unwrap_or(0))
        .build()
        .map_err(|e| ExperimentError::input("--jobs", options.jobs.unwrap_or(0), e.to_string()))?;
    let first_error: Mutex<Option<ExperimentError>> = Mutex::new(None);
    let mut rows: Vec<SuiteRow> = pool.install(|| {
        jobs.par_iter()
            .filter_map(|(class, s)| {
                let row = fly_one(class, s, out);
                bar.inc(1);
                match row {
                    Ok(r) => Some(r),
                    Err(e) => {
                        let mut slot = first_error.lock().unwrap_or_else(|p| p.into_inner());
                        slot.get_or_insert(e);
                        None
                    }
                }
            })
            .collect()
    });
    bar.finish_and_clear();
    if let Some(e) = first_error.into_inner().unwrap_or_else(|p| p.into_inner()) {
        return Err(e);
    }
    rows.sort_by(|a, b| (&a.class, &a.planner, a.seed).cmp(&(&b.class, &b.planner, b.seed)));
    let mut csv = String::from(SuiteRow::COLUMNS);
    csv.push('\n');
    for r in &rows {
        csv.push_str(&r.to_line());
        csv.push('\n');
    }
    write_text(&out.join("runs.csv"), &csv)?;
    let summary = summarize(&rows);
    write_json(&out.join("summary.json"), &summary)?;
    write_text(&out.join("report.md"), &report(config, &summary, &rows))?;
    if !options.no_plots {
        outcome_chart(&summary)
            .write(out, "outcomes")
            .map_err(|e| ExperimentError::input("outcomes chart", e, "a chart that draws"))?;
    }
    Ok(rows)
}

/// The scenario of flight `k` of `base` for `preset` (`None`: the file's planner as written).
fn flight_scenario(
    base: &Scenario,
    config: &SuiteConfig,
    preset: Option<PlannerPreset>,
    k: usize,
) -> Scenario {
    let mut s = base.with_seed(config.seed.wrapping_add(k as u64));
    if let Some(t) = config.time_limit_s {
        s.time_limit_s = t;
    }
    if let Some(latency) = config.latency {
        s.sim.latency = latency;
    }
    if let Some(p) = preset
        && p != s.planner.name
    {
        // Another preset: its parts as the paper defines them, the file's route setting kept.
        s.planner.name = p;
        s.planner.frontend = None;
        s.planner.backend = None;
        s.planner.checker = None;
        s.planner.manager = None;
    }
    s
}

fn fly_one(class: &str, s: &Scenario, out: &Path) -> Result<SuiteRow, ExperimentError> {
    let world = World::build(s)?;
    let planner = trust_flight::scenario::resolve_planner(s);
    let rel = format!(
        "logs/{class}/{}-seed{}.jsonl",
        s.planner.name.name(),
        s.seed
    );
    let flight = fly_logged(&world, s, &planner, &out.join(&rel))?;
    let sm = &flight.summary;
    let o = &sm.outcome;
    let distance = (world.goal() - world.start()).norm();
    let limits = s.vehicle.limits;
    Ok(SuiteRow {
        class: class.to_string(),
        planner: planner.label.clone(),
        seed: s.seed,
        status: o.status.as_str().to_string(),
        with: o
            .with
            .clone()
            .or_else(|| o.reason.clone())
            .unwrap_or_default(),
        flight_time_s: o.flight_time_s,
        distance_m: distance,
        ideal_time_s: distance / limits.v_max,
        path_length_m: o.path_length_m,
        min_clearance_static_m: o.min_clearance_static_m,
        min_clearance_dynamic_m: o.min_clearance_dynamic_m,
        max_accel: o.max_accel,
        a_max: limits.a_max,
        fallbacks: sm.fallback_count,
        log: rel,
        forecast_warning_s: o.forecast_warning_s,
        v_max: limits.v_max,
        cycle_ms_max: sm.cycle_ms_max,
        over_budget: sm.over_budget_count,
        skipped_ticks: sm.skipped_tick_count,
        real_time_factor: sm.real_time_factor,
    })
}

/// One [`ClassSummary`] per class and planner, in the rows' order.
pub fn summarize(rows: &[SuiteRow]) -> Vec<ClassSummary> {
    let mut groups: BTreeMap<(String, String), Vec<&SuiteRow>> = BTreeMap::new();
    for r in rows {
        groups
            .entry((r.class.clone(), r.planner.clone()))
            .or_default()
            .push(r);
    }
    groups
        .into_iter()
        .map(|((class, planner), rs)| {
            let count = |s: &str| rs.iter().filter(|r| r.status == s).count();
            let arrivals: Vec<&&SuiteRow> = rs.iter().filter(|r| r.status == "arrived").collect();
            let mean = |f: &dyn Fn(&SuiteRow) -> f64| {
                (!arrivals.is_empty())
                    .then(|| arrivals.iter().map(|r| f(r)).sum::<f64>() / arrivals.len() as f64)
            };
            let min_below = |f: &dyn Fn(&SuiteRow) -> f64| {
                rs.iter()
                    .map(|r| f(r))
                    .filter(|c| *c < NO_OBSTACLE)
                    .min_by(f64::total_cmp)
            };
            ClassSummary {
                flights: rs.len(),
                arrived: arrivals.len(),
                collided: count("collided"),
                timed_out: count("timed_out"),
                invalid: count("invalid"),
                unreachable: count("unreachable"),
                worst_cycle_ms: rs.iter().map(|r| r.cycle_ms_max).fold(0.0, f64::max),
                over_budget: rs.iter().map(|r| r.over_budget).sum(),
                skipped_ticks: rs.iter().map(|r| r.skipped_ticks).sum(),
                mean_arrival_time_s: mean(&|r| r.flight_time_s),
                mean_ideal_time_s: mean(&|r| r.ideal_time_s),
                worst_time_ratio: arrivals
                    .iter()
                    .map(|r| r.flight_time_s / r.ideal_time_s.max(1e-9))
                    .max_by(f64::total_cmp),
                min_clearance_static_m: min_below(&|r| r.min_clearance_static_m),
                min_clearance_dynamic_m: min_below(&|r| r.min_clearance_dynamic_m),
                worst_accel_ratio: rs.iter().map(|r| r.max_accel / r.a_max).fold(0.0, f64::max),
                class,
                planner,
            }
        })
        .collect()
}

/// `report.md`: the totals, then one table per class.
fn report(config: &SuiteConfig, summary: &[ClassSummary], rows: &[SuiteRow]) -> String {
    let opt = |x: Option<f64>, d: usize| x.map_or("–".to_string(), |v| format!("{v:.d$}"));
    let mut s = String::from("# Scenario suite\n\n");
    s.push_str(&format!(
        "{} file(s) × {} seed(s) (from {}) × {} planner(s){}. Each file is one class, flown as \
         written (global route included) with only the planner preset, seed and time limit \
         replaced. Clearances are true clearances from the vehicle's surface (negative: a \
         collision); `T / (d / v_max)` compares the flight time with the straight-line \
         distance over the speed limit.\n\n",
        config.files.len(),
        config.seeds,
        config.seed,
        config.planners.len().max(1),
        config
            .time_limit_s
            .map_or(String::new(), |t| format!(", time limit {t} s")),
    ));
    if let Some(Latency::Measured { cpu_scale }) = config.latency {
        s.push_str(&format!(
            "Flown in real time (CPU scale {}): each cycle's measured wall time is charged and a \
             busy planner skips replanning ticks.\n\n",
            cpu_scale.unwrap_or(1.0)
        ));
    }
    let total = |f: fn(&ClassSummary) -> usize| summary.iter().map(f).sum::<usize>();
    s.push_str(&format!(
        "**Total: {} flights — {} arrived, {} collided, {} timed out, {} invalid.**\n\n",
        total(|c| c.flights),
        total(|c| c.arrived),
        total(|c| c.collided),
        total(|c| c.timed_out),
        total(|c| c.invalid),
    ));
    if total(|c| c.unreachable) > 0 {
        s.push_str(&format!(
            "**{} flight(s) ended with the goal proved unreachable.**\n\n",
            total(|c| c.unreachable)
        ));
    }
    s.push_str(&format!(
        "**Worst planning cycle {:.1} ms; {} cycle(s) over the budget; {} replanning tick(s) \
         skipped.**\n\n",
        summary.iter().map(|c| c.worst_cycle_ms).fold(0.0, f64::max),
        total(|c| c.over_budget),
        summary.iter().map(|c| c.skipped_ticks).sum::<u64>(),
    ));
    if let Some(slowest) = rows
        .iter()
        .filter(|r| r.real_time_factor > 0.0)
        .min_by(|a, b| a.real_time_factor.total_cmp(&b.real_time_factor))
    {
        s.push_str(&format!(
            "Slowest flight {:.1}× real time ({}, seed {}; simulated over wall time on this \
             machine, flights in parallel share its cores).\n\n",
            slowest.real_time_factor, slowest.class, slowest.seed,
        ));
    }
    let mut class = "";
    for c in summary {
        if c.class != class {
            class = &c.class;
            s.push_str(&format!(
                "## {class}\n\n| planner | flights | arrived | collided | timed out | invalid \
                 | mean T (s) | mean d / v_max (s) | worst T / (d / v_max) | min clearance \
                 static (m) | min clearance moving (m) | worst max accel / a_max |\n\
                 |---|---|---|---|---|---|---|---|---|---|---|---|\n"
            ));
        }
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.2} |\n",
            c.planner,
            c.flights,
            c.arrived,
            c.collided,
            c.timed_out,
            c.invalid,
            opt(c.mean_arrival_time_s, 1),
            opt(c.mean_ideal_time_s, 1),
            opt(c.worst_time_ratio, 2),
            opt(c.min_clearance_static_m, 3),
            opt(c.min_clearance_dynamic_m, 3),
            c.worst_accel_ratio,
        ));
        if summary
            .iter()
            .skip_while(|x| !std::ptr::eq(*x, c))
            .nth(1)
            .is_none_or(|n| n.class != c.class)
        {
            s.push('\n');
        }
    }
    let collisions: Vec<&SuiteRow> = rows.iter().filter(|r| r.status == "collided").collect();
    if !collisions.is_empty() {
        s.push_str(
            "## Collisions

For a moving obstacle, how long before contact every forecast the \
             planner got (with its wall images) had the obstacle where it hit — 0 s: it outran \
             its forecast — beside the time to stop from `v_max` (`v_max / a_max`).\n\n\
             | class | planner | seed | t (s) | with | in its forecasts for (s) | stop from v_max (s) |\n\
             |---|---|---|---|---|---|---|\n",
        );
        for r in collisions {
            s.push_str(&format!(
                "| {} | {} | {} | {:.2} | {} | {} | {:.2} |\n",
                r.class,
                r.planner,
                r.seed,
                r.flight_time_s,
                r.with,
                opt(r.forecast_warning_s, 2),
                r.v_max / r.a_max,
            ));
        }
        s.push('\n');
    }
    s
}

/// The arrival rate of every class and planner, one bar each.
fn outcome_chart(summary: &[ClassSummary]) -> BarChart {
    let mut chart = BarChart::new("Scenario suite: arrivals per class")
        .y_label("arrived [%]")
        .y_range(0.0, 100.0)
        .value_format(0, " %")
        .interval_label("")
        .reference_label("");
    let planners: Vec<&str> = {
        let mut p: Vec<&str> = summary.iter().map(|c| c.planner.as_str()).collect();
        p.sort();
        p.dedup();
        p
    };
    for c in summary {
        let rate = 100.0 * c.arrived as f64 / c.flights.max(1) as f64;
        let name = if planners.len() > 1 {
            format!("{} ({})", c.class, c.planner)
        } else {
            c.class.clone()
        };
        let color = if c.collided > 0 {
            Color::rgb(200, 40, 40)
        } else if c.arrived == c.flights {
            Color::rgb(40, 150, 60)
        } else {
            Color::rgb(220, 150, 30)
        };
        chart = chart.bar(Bar::new(name, rate).color(color));
    }
    chart
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(class: &str, status: &str, t: f64, sc: f64) -> SuiteRow {
        SuiteRow {
            class: class.into(),
            planner: "trust".into(),
            seed: 0,
            status: status.into(),
            with: if status == "collided" {
                "obstacle:0".into()
            } else {
                String::new()
            },
            flight_time_s: t,
            distance_m: 10.0,
            ideal_time_s: 5.0,
            path_length_m: 11.0,
            min_clearance_static_m: sc,
            min_clearance_dynamic_m: 1e9,
            max_accel: 3.0,
            a_max: 3.0,
            fallbacks: 0,
            log: String::new(),
            forecast_warning_s: (status == "collided").then_some(1.25),
            v_max: 1.0,
            cycle_ms_max: 4.0,
            over_budget: 0,
            skipped_ticks: 0,
            real_time_factor: 5.0,
        }
    }

    #[test]
    fn summary_counts_outcomes_and_ignores_absent_obstacle_kinds() {
        let rows = [
            row("a", "arrived", 6.0, 0.2),
            row("a", "arrived", 8.0, 0.1),
            row("a", "collided", 3.0, -0.01),
            row("b", "timed_out", 40.0, 1.0),
        ];
        let s = summarize(&rows);
        assert_eq!(s.len(), 2);
        assert_eq!((s[0].arrived, s[0].collided, s[0].timed_out), (2, 1, 0));
        assert_eq!(s[0].mean_arrival_time_s, Some(7.0));
        assert_eq!(s[0].worst_time_ratio, Some(1.6));
        assert_eq!(s[0].min_clearance_static_m, Some(-0.01));
        assert_eq!(s[0].min_clearance_dynamic_m, None);
        assert_eq!(s[1].mean_arrival_time_s, None);
        let md = report(
            &SuiteConfig {
                files: vec![PathBuf::from("a.toml"), PathBuf::from("b.toml")],
                seeds: 2,
                seed: 0,
                planners: vec![],
                time_limit_s: None,
                latency: None,
            },
            &s,
            &rows,
        );
        assert!(md.contains("## a\n") && md.contains("## b\n"), "{md}");
        assert!(
            md.contains("| a | trust | 0 | 3.00 | obstacle:0 | 1.25 | 0.33 |"),
            "{md}"
        );
        assert!(
            md.contains("4 flights — 2 arrived, 1 collided, 1 timed out"),
            "{md}"
        );
    }

    #[test]
    fn bad_configurations_name_the_option() {
        let mut c = SuiteConfig {
            files: vec![],
            seeds: 1,
            seed: 0,
            planners: vec![],
            time_limit_s: None,
            latency: None,
        };
        assert!(c.validate().unwrap_err().to_string().contains("SCENARIOS"));
        c.files = vec![PathBuf::from("x/a.toml"), PathBuf::from("y/a.toml")];
        assert!(c.validate().unwrap_err().to_string().contains("distinct"));
        c.files.pop();
        c.seeds = 0;
        assert!(c.validate().unwrap_err().to_string().contains("--seeds"));
        c.seeds = 1;
        c.time_limit_s = Some(-1.0);
        assert!(
            c.validate()
                .unwrap_err()
                .to_string()
                .contains("--time-limit")
        );
        let e = expand_paths(&[PathBuf::from("/nonexistent/suite")]).unwrap_err();
        assert!(e.to_string().contains("/nonexistent/suite"), "{e}");
    }
}
