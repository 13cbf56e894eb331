//! `cargo xtask results`: turns the outputs of studies already run — a comparative study's
//! `summary.json` (`cargo xtask ablate`) and the `runs.csv` of scenario suites (`trust-sim
//! suite`) — into `docs/results.md`, stamped with the commit (`git rev-parse HEAD`) and the
//! machine (CPU model from `/proc/cpuinfo`, `nproc`, memory). Nothing is flown here; a missing
//! input is an error naming the file and the command that writes it.
//!
//! The summaries are read with the types that write them (`trust_experiments::study::report`,
//! `trust_experiments::suite`), so a change of those formats is a compile error here, not a
//! silently wrong table.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, Result, bail};
use trust_experiments::study::report::{
    PaperNumbers, PlannerSummary, StudySummary, mean_text as mean, opt,
};
use trust_experiments::suite::{ClassSummary, SuiteRow, summarize};

/// Where `cargo xtask ablate` writes its summary.
pub const DEFAULT_STUDY: &str = "target/ablate/summary.json";
/// Where `trust-sim suite` writes its rows by default; read when present and no `--suite` is given.
pub const DEFAULT_SUITE: &str = "out/suite/runs.csv";
/// The generated file.
pub const DEFAULT_OUT: &str = "docs/results.md";

/// The inputs and the output, relative to the workspace root unless absolute.
pub struct Options {
    /// A study's `summary.json` (required).
    pub study: PathBuf,
    /// Suites' `runs.csv`, each required; empty: [`DEFAULT_SUITE`] when it exists.
    pub suites: Vec<PathBuf>,
    /// The Markdown file to write.
    pub out: PathBuf,
}

/// Reads the inputs, writes the results file and says where.
pub fn run(root: &Path, options: &Options) -> Result<()> {
    let study_path = root.join(&options.study);
    let study = read_study(&study_path)?;
    let mut suites = Vec::new();
    let mut notes = Vec::new();
    if options.suites.is_empty() {
        let default = root.join(DEFAULT_SUITE);
        if default.is_file() {
            suites.push((DEFAULT_SUITE.to_string(), read_suite(&default)?));
        } else {
            let note = format!(
                "No suite rows at `{DEFAULT_SUITE}` (`cargo run --release -p trust-sim -- suite \
                 --seeds 5` writes them; `--suite PATH` names others)."
            );
            eprintln!("note: {note}");
            notes.push(note);
        }
    } else {
        for path in &options.suites {
            suites.push((path.display().to_string(), read_suite(&root.join(path))?));
        }
    }
    let stamp = Stamp::measure(root);
    let md = render(
        &stamp,
        &options.study.display().to_string(),
        &study,
        &suites,
        &notes,
    );
    let out = root.join(&options.out);
    if let Some(dir) = out.parent() {
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    }
    std::fs::write(&out, md).with_context(|| format!("cannot write {}", out.display()))?;
    eprintln!(
        "wrote {} (commit {}, {})",
        out.display(),
        stamp.commit,
        stamp.machine
    );
    Ok(())
}

/// Reads a study's `summary.json`.
fn read_study(path: &Path) -> Result<StudySummary> {
    if !path.is_file() {
        bail!(
            "study summary {} not found: run `cargo xtask ablate` first (it writes {DEFAULT_STUDY}), \
             or name another with --study PATH",
            path.display()
        );
    }
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let summary: StudySummary = serde_json::from_str(&text)
        .with_context(|| format!("{} is not a study summary.json", path.display()))?;
    if summary.schema != "trust-sim-study-v1" {
        bail!(
            "{}: schema {:?}, expected \"trust-sim-study-v1\"",
            path.display(),
            summary.schema
        );
    }
    Ok(summary)
}

/// Reads a suite's `runs.csv` (the columns `trust-sim suite` writes, found by name).
fn read_suite(path: &Path) -> Result<Vec<SuiteRow>> {
    if !path.is_file() {
        bail!(
            "suite rows {} not found: run `cargo run --release -p trust-sim -- suite [FILES] \
             --out DIR` first (it writes DIR/runs.csv)",
            path.display()
        );
    }
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
    let rows = parse_suite_csv(&text).with_context(|| format!("in {}", path.display()))?;
    if rows.is_empty() {
        bail!("{}: no flights (only a header)", path.display());
    }
    Ok(rows)
}

/// Parses the text of a suite's `runs.csv`. Columns added to the format later (`forecast_warning_s`,
/// `v_max`, `cycle_ms_max`, `over_budget`, `skipped_ticks`) may be absent.
fn parse_suite_csv(text: &str) -> Result<Vec<SuiteRow>> {
    let mut lines = text.lines();
    let header: Vec<&str> = lines
        .next()
        .context("empty file: expected a header line")?
        .split(',')
        .collect();
    let index = |name: &str| header.iter().position(|h| h.trim() == name);
    let mut rows = Vec::new();
    for (i, line) in lines.enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        let line_no = i + 2;
        let cells: Vec<&str> = line.split(',').collect();
        if cells.len() != header.len() {
            bail!(
                "line {line_no}: {} fields, the header has {}",
                cells.len(),
                header.len()
            );
        }
        let text = |name: &str| -> Result<&str> {
            let at = index(name).with_context(|| format!("no column `{name}` in the header"))?;
            Ok(cells[at].trim())
        };
        let optional = |name: &str| index(name).map(|at| cells[at].trim());
        let number = |name: &str, value: &str| -> Result<f64> {
            value.parse::<f64>().with_context(|| {
                format!("line {line_no}, column `{name}`: {value:?} is not a number")
            })
        };
        let required = |name: &str| -> Result<f64> { number(name, text(name)?) };
        let count = |name: &str| -> Result<u64> {
            match optional(name) {
                None | Some("") => Ok(0),
                Some(v) => v.parse::<u64>().with_context(|| {
                    format!("line {line_no}, column `{name}`: {v:?} is not a count")
                }),
            }
        };
        rows.push(SuiteRow {
            class: text("class")?.to_string(),
            planner: text("planner")?.to_string(),
            seed: text("seed")?
                .parse()
                .with_context(|| format!("line {line_no}, column `seed`: not a seed"))?,
            status: text("status")?.to_string(),
            with: text("with")?.to_string(),
            flight_time_s: required("flight_time_s")?,
            distance_m: required("distance_m")?,
            ideal_time_s: required("ideal_time_s")?,
            path_length_m: required("path_length_m")?,
            min_clearance_static_m: required("min_clearance_static_m")?,
            min_clearance_dynamic_m: required("min_clearance_dynamic_m")?,
            max_accel: required("max_accel")?,
            a_max: required("a_max")?,
            fallbacks: usize::try_from(count("fallbacks")?)?,
            log: text("log")?.to_string(),
            forecast_warning_s: match optional("forecast_warning_s") {
                None | Some("") => None,
                Some(v) => Some(number("forecast_warning_s", v)?),
            },
            v_max: match optional("v_max") {
                None | Some("") => f64::NAN,
                Some(v) => number("v_max", v)?,
            },
            cycle_ms_max: match optional("cycle_ms_max") {
                None | Some("") => 0.0,
                Some(v) => number("cycle_ms_max", v)?,
            },
            over_budget: usize::try_from(count("over_budget")?)?,
            skipped_ticks: count("skipped_ticks")?,
            real_time_factor: match optional("real_time_factor") {
                None | Some("") => 0.0,
                Some(v) => number("real_time_factor", v)?,
            },
        });
    }
    Ok(rows)
}

/// The commit and the machine the file is stamped with.
struct Stamp {
    commit: String,
    machine: String,
}

impl Stamp {
    fn measure(root: &Path) -> Stamp {
        let git = |args: &[&str]| {
            Command::new("git")
                .current_dir(root)
                .args(args)
                .output()
                .ok()
                .filter(|o| o.status.success())
                .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        };
        let commit = match git(&["rev-parse", "HEAD"]) {
            Some(sha) => {
                let dirty = git(&["status", "--porcelain", "--untracked-files=no"])
                    .is_some_and(|s| !s.is_empty());
                if dirty {
                    format!("`{sha}` (the working tree had uncommitted changes)")
                } else {
                    format!("`{sha}`")
                }
            }
            None => "unknown (not a git checkout)".to_string(),
        };
        let cpuinfo = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
        let cpu = cpu_model(&cpuinfo).unwrap_or_else(|| "unknown CPU".to_string());
        let cores = Command::new("nproc")
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
            .or_else(|| {
                std::thread::available_parallelism()
                    .ok()
                    .map(|n| n.to_string())
            })
            .unwrap_or_else(|| "?".to_string());
        let memory = std::fs::read_to_string("/proc/meminfo")
            .ok()
            .and_then(|m| mem_total_gib(&m))
            .map(|g| format!(", {g:.1} GiB memory"))
            .unwrap_or_default();
        Stamp {
            commit,
            machine: format!("{cpu}, {cores} cores (nproc){memory}"),
        }
    }
}

/// The first `model name` of `/proc/cpuinfo` (x86), else its `Hardware` or `Processor` line.
fn cpu_model(cpuinfo: &str) -> Option<String> {
    ["model name", "Hardware", "Processor"]
        .iter()
        .find_map(|key| {
            cpuinfo.lines().find_map(|l| {
                let (k, v) = l.split_once(':')?;
                (k.trim() == *key && !v.trim().is_empty()).then(|| v.trim().to_string())
            })
        })
}

/// `MemTotal` of `/proc/meminfo`, in GiB.
fn mem_total_gib(meminfo: &str) -> Option<f64> {
    let line = meminfo.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / (1024.0 * 1024.0))
}

fn render(
    stamp: &Stamp,
    study_path: &str,
    study: &StudySummary,
    suites: &[(String, Vec<SuiteRow>)],
    notes: &[String],
) -> String {
    let mut md = String::from("# Results\n\n");
    md.push_str(
        "Generated by `cargo xtask results` from the outputs of studies already run; edit the \
         generator (`xtask/src/results.rs`), not this file. The README's table is an extract.\n\n",
    );
    let _ = writeln!(md, "- Commit: {}", stamp.commit);
    let _ = writeln!(md, "- Machine: {}", stamp.machine);
    md.push_str(
        "- Timing columns (CPU ms, cycle ms) depend on the machine and its load; the flights \
         themselves are reproducible (same seed, same outcome).\n",
    );
    render_study(&mut md, study_path, study);
    for (path, rows) in suites {
        render_suite(&mut md, path, rows);
    }
    for note in notes {
        let _ = write!(md, "\n{note}\n");
    }
    md
}

fn paper(p: &PaperNumbers) -> String {
    let parts: Vec<String> = [
        p.success_rate.map(|r| format!("{:.0} %", 100.0 * r)),
        p.flight_time_s.map(|t| format!("{t:.1} s")),
        p.cpu_ms_per_trajectory.map(|c| format!("~{c:.0} ms")),
    ]
    .into_iter()
    .flatten()
    .collect();
    if parts.is_empty() {
        "–".to_string()
    } else {
        parts.join(", ")
    }
}

fn render_study(md: &mut String, path: &str, s: &StudySummary) {
    let c = &s.config;
    let _ = writeln!(
        md,
        "\n## Comparative study `{}` (`{path}`)\n",
        c.scenario_name
    );
    let planners: Vec<&str> = s.planners.iter().map(|p| p.planner.as_str()).collect();
    let _ = writeln!(
        md,
        "{} trials per planner from seed {}, variant `{}`, scenario `{}`{}; flown from commit `{}` \
         (recorded in the summary). Ideal flight time (distance / v_max): {} s.",
        c.trials,
        c.seed,
        c.variant,
        c.scenario.display(),
        if c.shard.count > 1 {
            format!(" — shard {}/{} only", c.shard.index, c.shard.count)
        } else {
            String::new()
        },
        s.git_sha.as_deref().unwrap_or("not recorded"),
        opt(s.ideal_flight_time_s, 1),
    );
    let _ = writeln!(
        md,
        "Reproduce: `cargo xtask ablate --trials {} --seed {} --planners {} --variant {}{}`.\n",
        c.trials,
        c.seed,
        planners.join(","),
        c.variant,
        c.time_limit_s
            .map(|t| format!(" --time-limit {t}"))
            .unwrap_or_default()
    );
    md.push_str(
        "| planner | arrived (95 % CI) | collisions (static) | time-outs | flight time (s) | \
         fallbacks / flight | CPU ms / trajectory | cycle ms median / p99 / max | paper |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    for p in &s.planners {
        let _ = writeln!(md, "{}", study_row(p));
    }
}

fn study_row(p: &PlannerSummary) -> String {
    format!(
        "| {} | {}/{} [{:.0} %, {:.0} %] | {} ({}) | {} | {} | {} | {} | {} / {} / {} | {} |",
        p.planner,
        p.success.k,
        p.success.n,
        100.0 * p.success.ci95_low,
        100.0 * p.success.ci95_high,
        p.collisions,
        p.static_collisions,
        p.timeouts,
        mean(&p.flight_time_s, 1),
        mean(&p.fallbacks_per_flight, 1),
        mean(&p.cpu_ms_per_trajectory, 1),
        opt(p.cycle_ms_median, 1),
        opt(p.cycle_ms_p99, 0),
        opt(p.cycle_ms_max, 0),
        paper(&p.paper),
    )
}

fn render_suite(md: &mut String, path: &str, rows: &[SuiteRow]) {
    let count = |status: &str| rows.iter().filter(|r| r.status == status).count();
    let arrivals: Vec<&SuiteRow> = rows.iter().filter(|r| r.status == "arrived").collect();
    let classes = summarize(rows);
    let (seed_min, seed_max) = rows.iter().fold((u64::MAX, 0), |(lo, hi), r| {
        (lo.min(r.seed), hi.max(r.seed))
    });
    let mut planners: Vec<&str> = rows.iter().map(|r| r.planner.as_str()).collect();
    planners.sort_unstable();
    planners.dedup();
    let ratio_mean = (!arrivals.is_empty()).then(|| {
        arrivals
            .iter()
            .map(|r| r.flight_time_s / r.ideal_time_s.max(1e-9))
            .sum::<f64>()
            / arrivals.len() as f64
    });
    let worst_accel = rows
        .iter()
        .map(|r| r.max_accel / r.a_max)
        .fold(0.0, f64::max);
    let min_moving = classes
        .iter()
        .filter_map(|c| c.min_clearance_dynamic_m)
        .min_by(f64::total_cmp);
    let _ = writeln!(md, "\n## Scenario suite (`{path}`)\n");
    let _ = writeln!(
        md,
        "{} flights: {} classes × seeds {seed_min}–{seed_max}, planner {}. **{} arrived, {} \
         collided, {} timed out, {} unreachable, {} invalid.** Mean T / (d / v_max) over the \
         arrivals {}; worst max accel / a_max {worst_accel:.3}; smallest clearance to a moving \
         obstacle {} m. The suite's folders and seeds are in its `report.md`.\n",
        rows.len(),
        classes.len() / planners.len().max(1),
        planners.join(", "),
        arrivals.len(),
        count("collided"),
        count("timed_out"),
        count("unreachable"),
        count("invalid"),
        opt(ratio_mean, 3),
        opt(min_moving, 3),
    );
    md.push_str(
        "| class | planner | arrived / flights | collided | timed out | mean T (s) | worst T / \
         (d / v_max) | min clearance static / moving (m) | worst accel / a_max | worst cycle (ms) |\n\
         |---|---|---|---|---|---|---|---|---|---|\n",
    );
    for c in &classes {
        let _ = writeln!(md, "{}", suite_row(c));
    }
}

fn suite_row(c: &ClassSummary) -> String {
    format!(
        "| {} | {} | {}/{} | {} | {} | {} | {} | {} / {} | {:.2} | {:.0} |",
        c.class,
        c.planner,
        c.arrived,
        c.flights,
        c.collided,
        c.timed_out,
        opt(c.mean_arrival_time_s, 1),
        opt(c.worst_time_ratio, 2),
        opt(c.min_clearance_static_m, 3),
        opt(c.min_clearance_dynamic_m, 3),
        c.worst_accel_ratio,
        c.worst_cycle_ms,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEADER: &str = "class,planner,seed,status,with,flight_time_s,distance_m,ideal_time_s,\
                          path_length_m,min_clearance_static_m,min_clearance_dynamic_m,max_accel,\
                          a_max,fallbacks,log,forecast_warning_s,v_max,cycle_ms_max,over_budget,\
                          skipped_ticks";

    fn row(class: &str, seed: u64, status: &str, t: f64) -> String {
        format!(
            "{class},trust,{seed},{status},,{t},10,5,10.5,0.2,1000000000,1.5,3,0,logs/x.jsonl,,2,\
             4.5,0,0"
        )
    }

    #[test]
    fn a_suite_csv_is_read_by_column_name_and_summarized() {
        let text = format!(
            "{HEADER}\n{}\n{}\n{}\n",
            row("wall", 0, "arrived", 6.0),
            row("wall", 1, "arrived", 7.0),
            row("trap", 0, "timed_out", 30.0)
        );
        let rows = parse_suite_csv(&text).unwrap();
        assert_eq!(rows.len(), 3);
        assert_eq!(rows[1].seed, 1);
        assert_eq!(rows[0].forecast_warning_s, None);
        let mut md = String::new();
        render_suite(&mut md, "out/suite/runs.csv", &rows);
        assert!(md.contains("**2 arrived, 0 collided, 1 timed out"), "{md}");
        assert!(md.contains("| wall | trust | 2/2 |"), "{md}");
        assert!(md.contains("seeds 0–1"), "{md}");
    }

    #[test]
    fn an_older_csv_without_the_later_columns_is_read() {
        let old_header = "class,planner,seed,status,with,flight_time_s,distance_m,ideal_time_s,\
                          path_length_m,min_clearance_static_m,min_clearance_dynamic_m,max_accel,\
                          a_max,fallbacks,log";
        let text = format!("{old_header}\nwall,trust,3,arrived,,6,10,5,10.5,0.2,1e9,1.5,3,2,l\n");
        let rows = parse_suite_csv(&text).unwrap();
        assert_eq!(rows[0].fallbacks, 2);
        assert_eq!(rows[0].over_budget, 0);
    }

    #[test]
    fn bad_rows_name_the_line_and_the_column() {
        let text = format!(
            "{HEADER}\n{}\n",
            row("wall", 0, "arrived", 6.0).replace(",6,", ",six,")
        );
        let e = format!("{:#}", parse_suite_csv(&text).unwrap_err());
        assert!(e.contains("line 2") && e.contains("flight_time_s"), "{e}");
        let short = format!("{HEADER}\nwall,trust\n");
        let e = format!("{:#}", parse_suite_csv(&short).unwrap_err());
        assert!(e.contains("line 2: 2 fields"), "{e}");
        let e = format!("{:#}", parse_suite_csv("class,seed\nwall,0\n").unwrap_err());
        assert!(e.contains("no column `planner`"), "{e}");
    }

    #[test]
    fn missing_inputs_are_named() {
        let dir = std::env::temp_dir().join(format!("xtask-results-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let options = Options {
            study: PathBuf::from("nowhere/summary.json"),
            suites: Vec::new(),
            out: PathBuf::from("results.md"),
        };
        let e = format!("{:#}", run(&dir, &options).unwrap_err());
        assert!(
            e.contains("nowhere/summary.json") && e.contains("cargo xtask ablate"),
            "{e}"
        );
        let e = format!("{:#}", read_suite(&dir.join("suite/runs.csv")).unwrap_err());
        assert!(
            e.contains("suite/runs.csv") && e.contains("trust-sim"),
            "{e}"
        );
        assert!(!dir.join("results.md").exists());
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn the_machine_is_read_from_proc() {
        let cpuinfo = "processor\t: 0\nvendor_id\t: AuthenticAMD\nmodel name\t: AMD EPYC\n";
        assert_eq!(cpu_model(cpuinfo).as_deref(), Some("AMD EPYC"));
        assert_eq!(
            cpu_model("Hardware\t: BCM2835\n").as_deref(),
            Some("BCM2835")
        );
        assert_eq!(cpu_model("flags : x\n"), None);
        let gib = mem_total_gib("MemTotal:        8388608 kB\nMemFree: 1 kB\n").unwrap();
        assert!((gib - 8.0).abs() < 1e-12);
    }
}
