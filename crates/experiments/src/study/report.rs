//! A study's `summary.json`, `report.md` and plots, computed from its rows alone (so a merged
//! sharded study reports exactly what a single run does).

use std::fmt::Write as _;
use std::path::Path;

use serde::{Deserialize, Serialize};

use super::stats::{Mean, Rate, mean_ci, median, wilson};
use super::{RunRow, StudyConfig, write_json, write_text};
use crate::ExperimentError;
use crate::flight_plots::write_comparison_view;
use trust_plot::{Bar, BarChart, Distribution, Figure};
use trust_runlog::RunLog;

/// The paper's E4 numbers (Sec. IV-D, Fig. baseline-test-3) for a planner, where the text states
/// them (the baselines' bars are only drawn in the figure).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PaperNumbers {
    /// Success rate of safe arrival.
    pub success_rate: Option<f64>,
    /// Mean flight duration (s).
    pub flight_time_s: Option<f64>,
    /// CPU time per trajectory (ms).
    pub cpu_ms_per_trajectory: Option<f64>,
}

/// What the paper's text says about `planner` in `scenario` (only E4 has paper numbers).
pub fn paper_numbers(scenario: &str, planner: &str) -> PaperNumbers {
    match (scenario, planner) {
        ("e4", "trust") => PaperNumbers {
            success_rate: Some(0.96),
            flight_time_s: Some(29.4),
            cpu_ms_per_trajectory: Some(10.0),
        },
        _ => PaperNumbers {
            success_rate: None,
            flight_time_s: None,
            cpu_ms_per_trajectory: None,
        },
    }
}

/// One planner's results.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlannerSummary {
    /// Preset name.
    pub planner: String,
    /// Trials flown.
    pub trials: usize,
    /// Safe arrivals, with the 95 % Wilson interval.
    pub success: Rate,
    /// Collisions (static or moving).
    pub collisions: usize,
    /// Collisions with the static geometry.
    pub static_collisions: usize,
    /// Time-outs.
    pub timeouts: usize,
    /// Invalid runs (the planner rejected its input).
    pub invalid: usize,
    /// Flight time of the arrivals (s), mean and 95 % t-interval.
    pub flight_time_s: Mean,
    /// Path length of the arrivals (m).
    pub path_length_m: Mean,
    /// Braking fallbacks per flight.
    pub fallbacks_per_flight: Mean,
    /// CPU time per optimized trajectory (ms; frontend and checks included), mean over
    /// flights. Timing.
    pub cpu_ms_per_trajectory: Mean,
    /// Solve time per optimized trajectory (ms), mean over flights. Timing.
    pub solve_ms_per_trajectory: Mean,
    /// Median over flights of the per-flight median cycle time (ms). Timing.
    pub cycle_ms_median: Option<f64>,
    /// Median over flights of the per-flight 99th-percentile cycle time (ms). Timing.
    pub cycle_ms_p99: Option<f64>,
    /// The longest cycle over every flight (ms). Timing.
    #[serde(default)]
    pub cycle_ms_max: Option<f64>,
    /// Cycles longer than the cycle budget, over every flight. Timing.
    #[serde(default)]
    pub over_budget: usize,
    /// Replanning ticks skipped because the planner was busy, over every flight (real-time
    /// variants). Timing.
    #[serde(default)]
    pub skipped_ticks: u64,
    /// The paper's numbers, where stated.
    pub paper: PaperNumbers,
}

/// `summary.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StudySummary {
    /// Format tag.
    pub schema: String,
    /// The study (shard `1/1` for a complete or merged study).
    pub config: StudyConfig,
    /// `git rev-parse HEAD` of the source tree, if known (`TRUST_GIT_SHA` or git itself).
    pub git_sha: Option<String>,
    /// Ideal flight time: straight-line distance / v_max (s), from the first run log.
    pub ideal_flight_time_s: Option<f64>,
    /// Per planner, in the study's order.
    pub planners: Vec<PlannerSummary>,
}

/// Summarizes the rows of one planner in a study of `scenario`.
pub fn summarize(scenario: &str, planner: &str, rows: &[&RunRow]) -> PlannerSummary {
    let count = |status: &str| rows.iter().filter(|r| r.status == status).count();
    let arrived: Vec<&&RunRow> = rows.iter().filter(|r| r.status == "arrived").collect();
    let collided = count("collided");
    PlannerSummary {
        planner: planner.to_string(),
        trials: rows.len(),
        success: wilson(arrived.len(), rows.len()),
        collisions: collided,
        static_collisions: rows
            .iter()
            .filter(|r| r.status == "collided" && r.with == "static")
            .count(),
        timeouts: count("timed_out"),
        invalid: count("invalid"),
        flight_time_s: mean_ci(&arrived.iter().map(|r| r.flight_time_s).collect::<Vec<_>>()),
        path_length_m: mean_ci(&arrived.iter().map(|r| r.path_length_m).collect::<Vec<_>>()),
        fallbacks_per_flight: mean_ci(&rows.iter().map(|r| r.fallbacks as f64).collect::<Vec<_>>()),
        cpu_ms_per_trajectory: mean_ci(
            &rows
                .iter()
                .map(|r| r.cpu_ms_per_trajectory)
                .collect::<Vec<_>>(),
        ),
        solve_ms_per_trajectory: mean_ci(
            &rows
                .iter()
                .map(|r| r.solve_ms_per_trajectory)
                .collect::<Vec<_>>(),
        ),
        cycle_ms_median: median(&rows.iter().map(|r| r.cycle_ms_median).collect::<Vec<_>>()),
        cycle_ms_p99: median(&rows.iter().map(|r| r.cycle_ms_p99).collect::<Vec<_>>()),
        cycle_ms_max: rows.iter().map(|r| r.cycle_ms_max).max_by(f64::total_cmp),
        over_budget: rows.iter().map(|r| r.over_budget).sum(),
        skipped_ticks: rows.iter().map(|r| r.skipped_ticks).sum(),
        paper: paper_numbers(scenario, planner),
    }
}

/// The summary of a whole study.
pub fn summary(config: &StudyConfig, rows: &[RunRow], out: &Path) -> StudySummary {
    let planners = config
        .planners
        .iter()
        .map(|p| {
            let mine: Vec<&RunRow> = rows.iter().filter(|r| r.planner == p.name()).collect();
            summarize(&config.scenario_name, p.name(), &mine)
        })
        .collect();
    let ideal = rows
        .first()
        .and_then(|r| RunLog::read(&out.join(&r.log)).ok())
        .map(|log| {
            let (s, g) = (log.header.start, log.header.goal);
            let d = ((g[0] - s[0]).powi(2) + (g[1] - s[1]).powi(2) + (g[2] - s[2]).powi(2)).sqrt();
            d / log.header.limits.v_max
        });
    StudySummary {
        schema: "trust-sim-study-v1".to_string(),
        config: config.clone(),
        git_sha: git_sha(),
        ideal_flight_time_s: ideal,
        planners,
    }
}

fn git_sha() -> Option<String> {
    if let Ok(s) = std::env::var("TRUST_GIT_SHA")
        && !s.trim().is_empty()
    {
        return Some(s.trim().to_string());
    }
    let out = std::process::Command::new("git")
        .args(["rev-parse", "HEAD"])
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
        .filter(|s| !s.is_empty())
}

fn pct(x: f64) -> String {
    format!("{:.0} %", 100.0 * x)
}

/// A mean with its 95 % half-width (`"3.2 ± 0.4"`), the mean alone, or `–` without samples.
pub fn mean_text(m: &Mean, decimals: usize) -> String {
    match (m.mean, m.ci95_half_width) {
        (Some(x), Some(h)) => format!("{x:.decimals$} ± {h:.decimals$}"),
        (Some(x), None) => format!("{x:.decimals$}"),
        _ => "–".to_string(),
    }
}

/// A value to `decimals` places, or `–` when there is none.
pub fn opt(x: Option<f64>, decimals: usize) -> String {
    x.map_or("–".to_string(), |x| format!("{x:.decimals$}"))
}

/// `report.md`: the paper-style table with intervals and the paper's numbers, the targets, and
/// how to read it.
pub fn report_md(s: &StudySummary) -> String {
    let c = &s.config;
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Comparative study: {} ({} trial{} per planner, seed {}, variant `{}`)\n",
        c.scenario_name,
        c.trials,
        if c.trials == 1 { "" } else { "s" },
        c.seed,
        c.variant
    );
    let _ = writeln!(
        md,
        "Paper Sec. IV-D, Fig. baseline-test-3: baseline 1 (straight line + UTF-MINCO, single \
         branch), baseline 2 (sparse A* + UTF-MINCO, single branch), baseline 3 (DEV-PRM, \
         multi-branch without history) and TRUST-Planner. Trial i flies the same world, \
         obstacle maneuvers and sensor noise for every planner. Intervals are 95 %: Wilson for \
         rates, Student t for means (over arrivals for the flight time).\n"
    );
    let _ = writeln!(
        md,
        "| planner | success (95 % CI) | collisions (static) | time-outs | invalid | flight time s | \
         fallbacks / flight | CPU ms / trajectory | cycle ms median / p99 | worst cycle ms \
         | over budget / skipped ticks | paper |"
    );
    let _ = writeln!(md, "|---|---|---|---|---|---|---|---|---|---|---|---|");
    for p in &s.planners {
        let paper = match (
            p.paper.success_rate,
            p.paper.flight_time_s,
            p.paper.cpu_ms_per_trajectory,
        ) {
            (Some(r), Some(t), Some(c)) => format!("{}, {t} s, ~{c} ms", pct(r)),
            _ if c.scenario_name == "e4" => "below ours (figure only)".to_string(),
            _ => "–".to_string(),
        };
        let _ = writeln!(
            md,
            "| {} | {} [{}, {}] ({}/{}) | {} ({}) | {} | {} | {} | {} | {} | {} / {} | {} | {} / {} | {} |",
            p.planner,
            pct(p.success.rate),
            pct(p.success.ci95_low),
            pct(p.success.ci95_high),
            p.success.k,
            p.success.n,
            p.collisions,
            p.static_collisions,
            p.timeouts,
            p.invalid,
            mean_text(&p.flight_time_s, 1),
            mean_text(&p.fallbacks_per_flight, 1),
            mean_text(&p.cpu_ms_per_trajectory, 2),
            opt(p.cycle_ms_median, 2),
            opt(p.cycle_ms_p99, 2),
            opt(p.cycle_ms_max, 1),
            p.over_budget,
            p.skipped_ticks,
            paper
        );
    }
    let _ = writeln!(md, "\n## Targets\n");
    let ours = s.planners.iter().find(|p| p.planner == "trust");
    let baselines: Vec<&PlannerSummary> =
        s.planners.iter().filter(|p| p.planner != "trust").collect();
    let mark = |ok: bool| if ok { "met" } else { "**not met**" };
    if let Some(o) = ours {
        if !baselines.is_empty() {
            let ahead = baselines.iter().all(|b| o.success.rate > b.success.rate);
            let _ = writeln!(
                md,
                "- ours ahead of every baseline on success: {} ({} vs {})",
                mark(ahead),
                pct(o.success.rate),
                baselines
                    .iter()
                    .map(|b| format!("{} {}", b.planner, pct(b.success.rate)))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
        }
        let _ = writeln!(
            md,
            "- success ≥ 96 % (paper): {} ({}, 95 % CI [{}, {}], n = {})",
            mark(o.success.rate >= 0.96),
            pct(o.success.rate),
            pct(o.success.ci95_low),
            pct(o.success.ci95_high),
            o.success.n
        );
        if let (Some(ideal), Some(t)) = (s.ideal_flight_time_s, o.flight_time_s.mean) {
            let _ = writeln!(
                md,
                "- mean flight time within 10 % of distance / v_max = {ideal:.1} s: {} ({t:.1} s, \
                 paper 29.4 s)",
                mark(t <= 1.1 * ideal)
            );
        }
        if let (Some(m), Some(p99)) = (o.cycle_ms_median, o.cycle_ms_p99) {
            let _ = writeln!(
                md,
                "- cycle ≤ 2 ms median, ≤ 5 ms p99: {} ({m:.2} ms, {p99:.2} ms; timing depends on \
                 the machine)",
                mark(m <= 2.0 && p99 <= 5.0)
            );
        }
    }
    let _ = writeln!(
        md,
        "\n## Reading it\n\n\
         - **success** is a safe arrival within the time limit; a **collision** is the true \
         vehicle sphere touching a true obstacle or the true static geometry (recomputed from \
         the run logs by `trust-sim audit`).\n\
         - **CPU ms / trajectory** is the planning time of a flight (frontend, solves and checks) \
         divided by the trajectories it optimized, the paper's \"CPU time per trajectory\".\n\
         - Per-flight rows are in `runs.csv`, every run log under `logs/`, and the plots \
         beside this file (`success_rate`, `flight_time`, `cpu_time`, `trajectories`).\n\
         - Reproduce: `cargo xtask ablate --trials {} --seed {} --planners {} --variant {}`{}.\n",
        c.trials,
        c.seed,
        c.planners
            .iter()
            .map(|p| p.name())
            .collect::<Vec<_>>()
            .join(","),
        c.variant,
        c.time_limit_s
            .map(|t| format!(" --time-limit {t}"))
            .unwrap_or_default()
    );
    if let Some(sha) = &s.git_sha {
        let _ = writeln!(md, "Source: `{sha}`.");
    }
    md
}

/// Writes `summary.json`, `report.md` and (if `plots`) the figures into `out`.
///
/// # Errors
/// File-system and plotting failures, naming the file.
pub fn write_all(
    config: &StudyConfig,
    rows: &[RunRow],
    out: &Path,
    plots: bool,
) -> Result<StudySummary, ExperimentError> {
    let s = summary(config, rows, out);
    write_json(&out.join("summary.json"), &s)?;
    write_text(&out.join("report.md"), &report_md(&s))?;
    if plots {
        write_plots(&s, rows, out)?;
    }
    Ok(s)
}

fn write_plots(s: &StudySummary, rows: &[RunRow], out: &Path) -> Result<(), ExperimentError> {
    let plot = |e: trust_plot::PlotError| ExperimentError::input("plots", e, "writable figures");
    let mut success = BarChart::new("Success rate of safe arrival (95 % Wilson interval)")
        .y_label("success rate [%]")
        .y_range(0.0, 100.0)
        .value_format(0, " %")
        .interval_label("95 % Wilson interval")
        .reference_label("paper");
    let mut cpu = BarChart::new("CPU time per trajectory (mean ± 95 % CI)")
        .y_label("CPU time [ms]")
        .value_format(2, " ms")
        .interval_label("95 % CI")
        .reference_label("paper");
    let mut times = Distribution::new("Flight duration of the arrivals").y_label("flight time [s]");
    for p in &s.planners {
        let mut bar = Bar::new(&p.planner, 100.0 * p.success.rate)
            .interval(100.0 * p.success.ci95_low, 100.0 * p.success.ci95_high);
        if let Some(r) = p.paper.success_rate {
            bar = bar.reference(100.0 * r);
        }
        success = success.bar(bar);
        let m = &p.cpu_ms_per_trajectory;
        let mut bar = Bar::new(&p.planner, m.mean.unwrap_or(f64::NAN));
        if let (Some(x), Some(h)) = (m.mean, m.ci95_half_width) {
            bar = bar.interval(x - h, x + h);
        }
        if let Some(r) = p.paper.cpu_ms_per_trajectory {
            bar = bar.reference(r);
        }
        cpu = cpu.bar(bar);
        let arrivals: Vec<f64> = rows
            .iter()
            .filter(|r| r.planner == p.planner && r.status == "arrived")
            .map(|r| r.flight_time_s)
            .collect();
        times = times.category(&p.planner, arrivals);
    }
    success.write(out, "success_rate").map_err(plot)?;
    cpu.write(out, "cpu_time").map_err(plot)?;
    // A distribution with no arrival at all has nothing to draw: say so in the report instead.
    if rows.iter().any(|r| r.status == "arrived") {
        times.write(out, "flight_time").map_err(plot)?;
    }
    // The representative trial: the first trial (the lowest seed) with every planner's path.
    if let Some(first) = rows.first() {
        let logs: Vec<(String, RunLog)> = rows
            .iter()
            .filter(|r| r.trial == first.trial)
            .filter_map(|r| {
                RunLog::read(&out.join(&r.log))
                    .ok()
                    .map(|l| (format!("{} ({})", r.planner, r.status), l))
            })
            .collect();
        if let Some((_, head)) = logs.first() {
            let flights: Vec<(String, &[trust_runlog::StateRecord])> = logs
                .iter()
                .map(|(label, l)| (label.clone(), l.states.as_slice()))
                .collect();
            write_comparison_view(
                out,
                "trajectories",
                &format!(
                    "{}, trial {} (seed {}): flown paths",
                    s.config.scenario_name, first.trial, first.seed
                ),
                &head.header,
                &flights,
            )
            .map_err(plot)?;
        }
    }
    Ok(())
}
