//! Comparative studies: the paper's E4 (Fig. baseline-test-3) and its ablations.
//!
//! A study flies one scenario for `trials` trials and every chosen planner. Trial `i` uses the
//! scenario with seed [`trial_seed`]`(seed, i)` — the same world, obstacle maneuvers, sensor noise
//! and planner stream for every planner — so planners are compared on identical trials. Trials
//! run in parallel (one world in memory per worker); the planners of one trial fly one after the
//! other on its world.
//!
//! Output in the study directory:
//! - `study.json`: the [`StudyConfig`] (what to reproduce it with), including the shard;
//! - `runs.csv`: one [`RunRow`] per flight, sorted by trial and planner — identical for the same
//!   configuration whatever the number of workers, except the timing columns
//!   ([`RunRow::timing_columns`]);
//! - `summary.json`, `report.md` and plots ([`report`]);
//! - `logs/<planner>/trial-NNNN.jsonl`: every run log (contract `run-log-v1`).
//!
//! **Scale-out**: `shard = K/M` runs only the trials `i` with `i mod M = K − 1`, so M machines
//! (a Slurm job array, `docs/ablate.md`) split a study; [`merge`] combines their directories into
//! one whose `runs.csv`, `summary.json` and `report.md` equal a single-machine run's apart from
//! timing.

pub mod report;
pub mod stats;
mod variant;

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::ExperimentError;
use trust_flight::scenario::Scenario;
use trust_flight::{RunOptions, fly};
use trust_planner::PlannerPreset;
use trust_world::World;
use trust_world::WorldError;

pub use variant::Variant;

/// Which part of a study this process runs: trials `i` with `i mod count = index − 1`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// 1-based shard number `K`.
    pub index: usize,
    /// Number of shards `M`.
    pub count: usize,
}

impl Shard {
    /// The whole study.
    pub const ALL: Shard = Shard { index: 1, count: 1 };

    /// Parses `K/M` with `1 ≤ K ≤ M`.
    ///
    /// # Errors
    /// [`ExperimentError::Input`] naming `--shard` and the expected form.
    pub fn parse(text: &str) -> Result<Shard, ExperimentError> {
        let bad = || ExperimentError::input("--shard", text, "K/M with 1 <= K <= M, e.g. 2/8");
        let (k, m) = text.split_once('/').ok_or_else(bad)?;
        let index: usize = k.trim().parse().map_err(|_| bad())?;
        let count: usize = m.trim().parse().map_err(|_| bad())?;
        if index == 0 || count == 0 || index > count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }

    /// Whether trial `i` belongs to this shard.
    pub fn owns(&self, trial: usize) -> bool {
        trial % self.count == self.index - 1
    }
}

/// Everything that determines a study's results (`study.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StudyConfig {
    /// The scenario file.
    pub scenario: PathBuf,
    /// Its `name`.
    pub scenario_name: String,
    /// Trials per planner.
    pub trials: usize,
    /// Base seed ([`trial_seed`]).
    pub seed: u64,
    /// Planners, in report order.
    pub planners: Vec<PlannerPreset>,
    /// The ablation applied to every planner it concerns.
    pub variant: Variant,
    /// Simulated time limit (s), replacing the scenario's if set.
    pub time_limit_s: Option<f64>,
    /// This process's part of the trials.
    pub shard: Shard,
}

impl StudyConfig {
    /// Checks the counts, the time limit and the planner list.
    ///
    /// # Errors
    /// [`ExperimentError::Input`] naming the option.
    pub fn validate(&self) -> Result<(), ExperimentError> {
        if self.trials == 0 {
            return Err(ExperimentError::input(
                "--trials",
                self.trials,
                "at least 1",
            ));
        }
        crate::error::check_planner_list("--planners", &self.planners)?;
        crate::error::check_time_limit(self.time_limit_s)?;
        Ok(())
    }

    /// The trials this shard runs.
    pub fn my_trials(&self) -> Vec<usize> {
        (0..self.trials).filter(|&i| self.shard.owns(i)).collect()
    }

    /// The scenario of trial `i` for `planner`, with the variant applied.
    ///
    /// # Errors
    /// [`ExperimentError`] from the variant (a part it needs is missing).
    pub fn trial_scenario(
        &self,
        base: &Scenario,
        trial: usize,
        planner: PlannerPreset,
    ) -> Result<Scenario, ExperimentError> {
        let mut s = base.with_seed(trial_seed(self.seed, trial));
        if let Some(t) = self.time_limit_s {
            s.time_limit_s = t;
        }
        s.planner.name = planner;
        s.planner.frontend = None;
        s.planner.backend = None;
        s.planner.checker = None;
        s.planner.manager = None;
        // The paper's setting: no global route (every query aims at the final goal), unless the
        // variant is `route`.
        s.planner.route.enabled = false;
        self.variant.apply(&mut s)?;
        Ok(s)
    }
}

/// The seed of trial `i` of a study with base seed `seed`: `seed + i` (wrapping), so that trial
/// `i` of `--seed S` is `trust-sim run SCENARIO --seed S+i`.
pub fn trial_seed(seed: u64, trial: usize) -> u64 {
    seed.wrapping_add(trial as u64)
}

/// One flight of a study (a row of `runs.csv`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunRow {
    /// Trial index.
    pub trial: usize,
    /// Planner preset name.
    pub planner: String,
    /// Trial seed.
    pub seed: u64,
    /// `arrived`, `collided`, `timed_out` or `invalid`.
    pub status: String,
    /// What was hit, or why the run is invalid (empty otherwise).
    pub with: String,
    /// Flight time (s).
    pub flight_time_s: f64,
    /// Path length (m).
    pub path_length_m: f64,
    /// Smallest true clearance from the static geometry (m).
    pub min_clearance_static_m: f64,
    /// Smallest true clearance from a moving obstacle (m).
    pub min_clearance_dynamic_m: f64,
    /// Planning cycles.
    pub cycles: usize,
    /// Cycles that ended in a braking fallback.
    pub fallbacks: usize,
    /// Largest speed (m/s).
    pub max_speed: f64,
    /// Largest acceleration (m/s²).
    pub max_accel: f64,
    /// Median cycle wall time (ms). Timing.
    pub cycle_ms_median: f64,
    /// 99th percentile of the cycle wall time (ms). Timing.
    pub cycle_ms_p99: f64,
    /// Mean solve time per optimized trajectory (ms). Timing.
    pub solve_ms_per_trajectory: f64,
    /// Mean CPU time per optimized trajectory, frontend and checks included (ms). Timing.
    pub cpu_ms_per_trajectory: f64,
    /// Wall time of the flight, simulation included (s). Timing.
    pub wall_s: f64,
    /// The longest cycle's wall time (ms). Timing.
    pub cycle_ms_max: f64,
    /// Cycles longer than the manager's cycle budget. Timing.
    pub over_budget: usize,
    /// Replanning ticks skipped because the planner was busy (real-time variants). Timing.
    pub skipped_ticks: u64,
    /// The run log, relative to the study directory.
    pub log: String,
}

impl RunRow {
    /// The CSV header.
    pub const COLUMNS: [&'static str; 23] = [
        "trial",
        "planner",
        "seed",
        "status",
        "with",
        "flight_time_s",
        "path_length_m",
        "min_clearance_static_m",
        "min_clearance_dynamic_m",
        "cycles",
        "fallbacks",
        "max_speed",
        "max_accel",
        "cycle_ms_median",
        "cycle_ms_p99",
        "solve_ms_per_trajectory",
        "cpu_ms_per_trajectory",
        "wall_s",
        "cycle_ms_max",
        "over_budget",
        "skipped_ticks",
        "log",
        "",
    ];

    /// The columns that hold measured times (they differ between runs of the same study):
    /// `cycle_ms_median` … `wall_s` of [`RunRow::COLUMNS`].
    pub fn timing_columns() -> &'static [&'static str] {
        &Self::COLUMNS[13..21]
    }

    fn header_line() -> String {
        Self::COLUMNS[..22].join(",")
    }

    fn to_line(&self) -> String {
        let clean = |s: &str| s.replace([',', '\n', '\r', '"'], ";");
        format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            self.trial,
            clean(&self.planner),
            self.seed,
            clean(&self.status),
            clean(&self.with),
            self.flight_time_s,
            self.path_length_m,
            self.min_clearance_static_m,
            self.min_clearance_dynamic_m,
            self.cycles,
            self.fallbacks,
            self.max_speed,
            self.max_accel,
            self.cycle_ms_median,
            self.cycle_ms_p99,
            self.solve_ms_per_trajectory,
            self.cpu_ms_per_trajectory,
            self.wall_s,
            self.cycle_ms_max,
            self.over_budget,
            self.skipped_ticks,
            clean(&self.log),
        )
    }

    fn from_line(line: &str, place: &str) -> Result<RunRow, ExperimentError> {
        let f: Vec<&str> = line.split(',').collect();
        if f.len() != 22 {
            return Err(ExperimentError::input(
                place,
                line,
                "22 comma-separated fields (runs.csv of trust-sim ablate)",
            ));
        }
        fn num<T: std::str::FromStr>(
            s: &str,
            column: &str,
            place: &str,
        ) -> Result<T, ExperimentError> {
            s.parse().map_err(|_| {
                ExperimentError::input(format!("{place}, column {column}"), s, "a number")
            })
        }
        Ok(RunRow {
            trial: num(f[0], "trial", place)?,
            planner: f[1].to_string(),
            seed: num(f[2], "seed", place)?,
            status: f[3].to_string(),
            with: f[4].to_string(),
            flight_time_s: num(f[5], "flight_time_s", place)?,
            path_length_m: num(f[6], "path_length_m", place)?,
            min_clearance_static_m: num(f[7], "min_clearance_static_m", place)?,
            min_clearance_dynamic_m: num(f[8], "min_clearance_dynamic_m", place)?,
            cycles: num(f[9], "cycles", place)?,
            fallbacks: num(f[10], "fallbacks", place)?,
            max_speed: num(f[11], "max_speed", place)?,
            max_accel: num(f[12], "max_accel", place)?,
            cycle_ms_median: num(f[13], "cycle_ms_median", place)?,
            cycle_ms_p99: num(f[14], "cycle_ms_p99", place)?,
            solve_ms_per_trajectory: num(f[15], "solve_ms_per_trajectory", place)?,
            cpu_ms_per_trajectory: num(f[16], "cpu_ms_per_trajectory", place)?,
            wall_s: num(f[17], "wall_s", place)?,
            cycle_ms_max: num(f[18], "cycle_ms_max", place)?,
            over_budget: num(f[19], "over_budget", place)?,
            skipped_ticks: num(f[20], "skipped_ticks", place)?,
            log: f[21].to_string(),
        })
    }

    /// The row with every timing column set to 0 (for comparing studies).
    pub fn without_timing(&self) -> RunRow {
        RunRow {
            cycle_ms_median: 0.0,
            cycle_ms_p99: 0.0,
            solve_ms_per_trajectory: 0.0,
            cpu_ms_per_trajectory: 0.0,
            wall_s: 0.0,
            cycle_ms_max: 0.0,
            over_budget: 0,
            skipped_ticks: 0,
            ..self.clone()
        }
    }
}

/// Writes `rows` as `runs.csv` text.
pub fn runs_csv(rows: &[RunRow]) -> String {
    let mut out = RunRow::header_line();
    out.push('\n');
    for r in rows {
        let _ = writeln!(out, "{}", r.to_line());
    }
    out
}

/// Reads `runs.csv`.
///
/// # Errors
/// [`ExperimentError::Write`]-style I/O errors naming the file, or [`ExperimentError::Input`] naming the line.
pub fn read_runs_csv(path: &Path) -> Result<Vec<RunRow>, ExperimentError> {
    let text = std::fs::read_to_string(path).map_err(|source| ExperimentError::Write {
        path: path.to_path_buf(),
        source,
    })?;
    let mut lines = text.lines();
    match lines.next() {
        Some(h) if h == RunRow::header_line() => {}
        other => {
            return Err(ExperimentError::input(
                format!("{} line 1", path.display()),
                other.unwrap_or("(empty file)"),
                "the runs.csv header of this trust-sim version",
            ));
        }
    }
    lines
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty())
        .map(|(k, l)| RunRow::from_line(l, &format!("{} line {}", path.display(), k + 2)))
        .collect()
}

/// Options of [`run_study`] that do not change its results.
#[derive(Debug, Clone, Default)]
pub struct RunStudyOptions {
    /// Worker threads (`None`: rayon's default, one per core).
    pub jobs: Option<usize>,
    /// Skip the plots.
    pub no_plots: bool,
    /// Show a progress bar on stderr.
    pub progress: bool,
}

/// Runs the shard of `config` described by it, writing everything into `out` (module docs).
/// Returns the rows of this shard.
///
/// # Errors
/// [`ExperimentError`] for an invalid configuration, scenario or world, and file-system failures. A
/// planner that fails mid-flight is not an error: its row says `invalid`.
pub fn run_study(
    config: &StudyConfig,
    out: &Path,
    options: &RunStudyOptions,
) -> Result<Vec<RunRow>, ExperimentError> {
    config.validate()?;
    let base = trust_flight::scenario::load(&config.scenario)?;
    // Fail early on a variant or planner that does not apply, before any world is built.
    for &p in &config.planners {
        let s = config.trial_scenario(&base, 0, p)?;
        let problems = s.validate();
        if !problems.is_empty() {
            return Err(WorldError::Invalid {
                path: s.origin(),
                problems,
            }
            .into());
        }
    }
    create_dir(out)?;
    write_json(&out.join("study.json"), config)?;
    let trials = config.my_trials();
    let flights = trials.len() * config.planners.len();
    let bar = progress_bar(options.progress, flights as u64);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(options.jobs.unwrap_or(0))
        .build()
        .map_err(|e| ExperimentError::input("--jobs", options.jobs.unwrap_or(0), e.to_string()))?;
    let first_error: Mutex<Option<ExperimentError>> = Mutex::new(None);
    let mut rows: Vec<RunRow> = pool.install(|| {
        trials
            .par_iter()
            .flat_map_iter(|&trial| match run_trial(config, &base, trial, out, &bar) {
                Ok(rows) => rows,
                Err(e) => {
                    let mut slot = first_error.lock().unwrap_or_else(|p| p.into_inner());
                    slot.get_or_insert(e);
                    Vec::new()
                }
            })
            .collect()
    });
    bar.finish_and_clear();
    if let Some(e) = first_error.into_inner().unwrap_or_else(|p| p.into_inner()) {
        return Err(e);
    }
    sort_rows(&mut rows, &config.planners);
    write_text(&out.join("runs.csv"), &runs_csv(&rows))?;
    report::write_all(config, &rows, out, !options.no_plots)?;
    Ok(rows)
}

fn run_trial(
    config: &StudyConfig,
    base: &Scenario,
    trial: usize,
    out: &Path,
    bar: &indicatif::ProgressBar,
) -> Result<Vec<RunRow>, ExperimentError> {
    let mut rows = Vec::with_capacity(config.planners.len());
    let mut world: Option<World> = None;
    for &planner in &config.planners {
        let s = config.trial_scenario(base, trial, planner)?;
        // The planners of a trial share its world (built once: the E4 ESDF takes seconds).
        let w = match world.take() {
            Some(w) => w.with_scenario(&s)?,
            None => World::build(&s)?,
        };
        let planner_spec = trust_flight::scenario::resolve_planner(&s);
        let rel = format!("logs/{}/trial-{trial:04}.jsonl", planner.name());
        let flight = fly_logged(&w, &s, &planner_spec, &out.join(&rel))?;
        let s = &flight.summary;
        let o = &s.outcome;
        rows.push(RunRow {
            trial,
            planner: planner.name().to_string(),
            seed: s.seed,
            status: o.status.as_str().to_string(),
            with: o.with.clone().unwrap_or_default(),
            flight_time_s: o.flight_time_s,
            path_length_m: o.path_length_m,
            min_clearance_static_m: o.min_clearance_static_m,
            min_clearance_dynamic_m: o.min_clearance_dynamic_m,
            cycles: s.cycle_count,
            fallbacks: s.fallback_count,
            max_speed: o.max_speed,
            max_accel: o.max_accel,
            cycle_ms_median: s.cycle_ms_median,
            cycle_ms_p99: s.cycle_ms_p99,
            solve_ms_per_trajectory: s.solve_ms_per_trajectory,
            cpu_ms_per_trajectory: s.cpu_ms_per_trajectory,
            wall_s: s.wall_s,
            cycle_ms_max: s.cycle_ms_max,
            over_budget: s.over_budget_count,
            skipped_ticks: s.skipped_tick_count,
            log: rel,
        });
        bar.inc(1);
        world = Some(w);
    }
    Ok(rows)
}

fn sort_rows(rows: &mut [RunRow], planners: &[PlannerPreset]) {
    let rank = |name: &str| {
        planners
            .iter()
            .position(|p| p.name() == name)
            .unwrap_or(usize::MAX)
    };
    rows.sort_by_key(|r| (r.trial, rank(&r.planner)));
}

/// One flight of a study or the suite, logged to `log_path` (its folder created). Studies keep
/// their logs small: branches only when the scenario asks (`[log] branches = true`).
pub(crate) fn fly_logged(
    world: &World,
    scenario: &Scenario,
    planner: &trust_planner::ResolvedPlanner,
    log_path: &Path,
) -> Result<trust_flight::Flight, ExperimentError> {
    if let Some(dir) = log_path.parent() {
        create_dir(dir)?;
    }
    let options = RunOptions {
        log_path: Some(log_path.to_path_buf()),
        zero_timing: false,
        progress_every_s: None,
        log_branches: scenario.log.branches_or(false),
    };
    Ok(fly(world, planner, &options, |_| {})?)
}

pub(crate) fn progress_bar(show: bool, total: u64) -> indicatif::ProgressBar {
    if !show {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(total);
    bar.set_style(
        indicatif::ProgressStyle::with_template(
            "{elapsed_precise} [{bar:40}] {pos}/{len} flights (eta {eta})",
        )
        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
        .progress_chars("=> "),
    );
    bar
}

/// Combines the directories of a sharded study into `out`: checks that they are shards of one
/// configuration and together hold every trial of every planner exactly once, copies the run
/// logs, and writes `runs.csv`, `summary.json`, `report.md` and plots as a single run would.
///
/// # Errors
/// [`ExperimentError::Input`] naming the directory and what disagrees or is missing; I/O errors naming
/// the file.
pub fn merge(dirs: &[PathBuf], out: &Path, plots: bool) -> Result<Vec<RunRow>, ExperimentError> {
    if dirs.is_empty() {
        return Err(ExperimentError::input(
            "DIR",
            "(none)",
            "one or more shard directories",
        ));
    }
    let mut config: Option<StudyConfig> = None;
    let mut rows: Vec<RunRow> = Vec::new();
    let mut sources: Vec<(RunRow, PathBuf)> = Vec::new();
    for dir in dirs {
        let c: StudyConfig = read_json(&dir.join("study.json"))?;
        let unsharded = StudyConfig {
            shard: Shard::ALL,
            ..c.clone()
        };
        match &config {
            None => config = Some(unsharded),
            Some(first) if *first == unsharded => {}
            Some(_) => {
                return Err(ExperimentError::input(
                    format!("{}/study.json", dir.display()),
                    "a different study",
                    "shards of one study (same scenario, trials, seed, planners, variant, time limit)",
                ));
            }
        }
        for r in read_runs_csv(&dir.join("runs.csv"))? {
            sources.push((r.clone(), dir.join(&r.log)));
            rows.push(r);
        }
    }
    let config = config.expect("at least one directory");
    let mut seen = std::collections::BTreeSet::new();
    for r in &rows {
        if !seen.insert((r.trial, r.planner.clone())) {
            return Err(ExperimentError::input(
                "shards",
                format!("trial {} of {}", r.trial, r.planner),
                "each trial of each planner in exactly one shard",
            ));
        }
    }
    let mut missing = Vec::new();
    for trial in 0..config.trials {
        for p in &config.planners {
            if !seen.contains(&(trial, p.name().to_string())) {
                missing.push(format!("{}#{trial}", p.name()));
            }
        }
    }
    if !missing.is_empty() {
        let shown: Vec<_> = missing.iter().take(10).cloned().collect();
        return Err(ExperimentError::input(
            "shards",
            format!("{} missing flight(s): {}", missing.len(), shown.join(" ")),
            "every trial of every planner (run the missing shards first)",
        ));
    }
    create_dir(out)?;
    for (row, from) in &sources {
        let to = out.join(&row.log);
        if let Some(dir) = to.parent() {
            create_dir(dir)?;
        }
        if std::fs::canonicalize(from).ok() != std::fs::canonicalize(&to).ok() {
            std::fs::copy(from, &to).map_err(|source| ExperimentError::Write {
                path: to.clone(),
                source,
            })?;
        }
    }
    sort_rows(&mut rows, &config.planners);
    write_json(&out.join("study.json"), &config)?;
    write_text(&out.join("runs.csv"), &runs_csv(&rows))?;
    report::write_all(&config, &rows, out, plots)?;
    Ok(rows)
}

pub(crate) fn create_dir(dir: &Path) -> Result<(), ExperimentError> {
    std::fs::create_dir_all(dir).map_err(|source| ExperimentError::Write {
        path: dir.to_path_buf(),
        source,
    })
}

pub(crate) fn write_text(path: &Path, text: &str) -> Result<(), ExperimentError> {
    std::fs::write(path, text).map_err(|source| ExperimentError::Write {
        path: path.to_path_buf(),
        source,
    })
}

pub(crate) fn write_json<T: Serialize>(path: &Path, value: &T) -> Result<(), ExperimentError> {
    let text = serde_json::to_string_pretty(value)
        .map_err(|e| ExperimentError::input(path.display().to_string(), e, "serializable data"))?;
    write_text(path, &(text + "\n"))
}

fn read_json<T: for<'de> Deserialize<'de>>(path: &Path) -> Result<T, ExperimentError> {
    let text = std::fs::read_to_string(path).map_err(|source| ExperimentError::Write {
        path: path.to_path_buf(),
        source,
    })?;
    serde_json::from_str(&text).map_err(|e| {
        ExperimentError::input(
            path.display().to_string(),
            e,
            "a study.json written by trust-sim ablate",
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn timing_columns_are_the_measured_times() {
        assert_eq!(
            RunRow::timing_columns(),
            [
                "cycle_ms_median",
                "cycle_ms_p99",
                "solve_ms_per_trajectory",
                "cpu_ms_per_trajectory",
                "wall_s",
                "cycle_ms_max",
                "over_budget",
                "skipped_ticks"
            ]
        );
    }

    #[test]
    fn shards_partition_the_trials() {
        assert_eq!(Shard::parse("2/3").unwrap(), Shard { index: 2, count: 3 });
        for bad in ["0/3", "4/3", "1", "a/b", "1/0", ""] {
            let e = Shard::parse(bad).unwrap_err().to_string();
            assert!(e.contains("--shard"), "{e}");
        }
        let shards: Vec<Shard> = (1..=3).map(|k| Shard { index: k, count: 3 }).collect();
        for trial in 0..20 {
            assert_eq!(shards.iter().filter(|s| s.owns(trial)).count(), 1);
        }
    }

    #[test]
    fn csv_round_trips() {
        let row = RunRow {
            trial: 3,
            planner: "trust".into(),
            seed: 42,
            status: "collided".into(),
            with: "obstacle 7, cylinder".into(),
            flight_time_s: 12.5,
            path_length_m: 101.25,
            min_clearance_static_m: -0.01,
            min_clearance_dynamic_m: 1e9,
            cycles: 125,
            fallbacks: 2,
            max_speed: 9.99,
            max_accel: 14.2,
            cycle_ms_median: 1.5,
            cycle_ms_p99: 4.25,
            solve_ms_per_trajectory: 0.75,
            cpu_ms_per_trajectory: 1.0,
            wall_s: 3.0,
            cycle_ms_max: 48.5,
            over_budget: 1,
            skipped_ticks: 2,
            log: "logs/trust/trial-0003.jsonl".into(),
        };
        let dir = std::env::temp_dir().join(format!("trust-sim-csv-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("runs.csv");
        std::fs::write(&path, runs_csv(std::slice::from_ref(&row))).unwrap();
        let back = read_runs_csv(&path).unwrap();
        // Commas in free text become semicolons; everything else is exact.
        assert_eq!(back[0].with, "obstacle 7; cylinder");
        assert_eq!(
            RunRow {
                with: row.with.replace(',', ";"),
                ..row
            },
            back[0]
        );
        std::fs::write(&path, "nonsense\n").unwrap();
        assert!(
            read_runs_csv(&path)
                .unwrap_err()
                .to_string()
                .contains("line 1")
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}
