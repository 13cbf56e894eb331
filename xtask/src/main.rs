//! # xtask — automation for the TRUST-Planner workspace
//!
//! `cargo xtask <command>` (alias in `.cargo/config.toml`). Heavy work shells out to
//! `cargo run --release` so that it never runs in a debug build.
//!
//! Commands:
//! - `ci`: runs `.ci/run`, exactly what CI runs.
//! - `experiment e1`: paper Fig. Sim-A-1-1(c), DEV-PRM vs V-PRM distinct paths per CPU ms over the
//!   number of dynamic obstacles; writes `out/e1/results.json` and `out/e1/report.md`.
//! - `experiment e2`: paper Table Sim-A-2, UTF-MINCO vs MINCO on the static and dynamic 50×20×10 m
//!   scenes; writes `out/e2/results.json` and `out/e2/report.md`.
//! - `experiment e3`: paper Table Sim-B-1, the branches of one cold cycle on an E1-like scene.
//! - `experiment e4` / `ablate [ARGS]`: paper Fig. baseline-test-3, baselines 1–3 vs
//!   TRUST-Planner in closed loop (`trust-sim ablate`, see its `--help`); `ablate merge DIR...`
//!   combines the shards of a study.
//! - `fuzz [--cases N] [--seed S] [--only API]`: adversarial inputs against every public entry
//!   point of the library crates (`trust-fuzz`, release build); fails on any panic, hang,
//!   non-finite output, wrong answer or call over 1 s.
//! - `proptest [--seeds K] [--cases N]`: every property test under K random seeds
//!   (`PROPTEST_RNG_SEED`), reporting each failing seed with its reproducing command.
//! - `results [--study SUMMARY.json] [--suite RUNS.csv]... [--out FILE]`: `docs/results.md` from
//!   studies already run, stamped with the commit and the machine (`results.rs`).
//! - `replay-check PAGE [--at T]`: opens a replay page (`trust-sim replay`) in headless Chromium
//!   at `#t=0` and `#t=T`, fails on any script or console error, and checks that the vehicle
//!   moved (its canvas position and the screenshots' pixels; `trust_replay::browser`).

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand, ValueEnum};
use serde_json::Value;
use trust_experiments::{e1, e2};

mod fuzz;
mod proptest;
mod release;
mod results;

#[derive(Parser)]
#[command(
    name = "cargo xtask",
    about = "Automation for the TRUST-Planner workspace"
)]
struct Cli {
    #[command(subcommand)]
    command: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Run `.ci/run` (format, clippy, tests, rustdoc, benchmark and example smoke runs).
    Ci,
    /// The main job: E4, baselines 1–3 vs TRUST-Planner in closed loop (release build of
    /// `trust-sim ablate`; every argument is passed on, see `cargo xtask ablate --help`).
    /// `cargo xtask ablate merge --out DIR SHARD_DIR...` combines a sharded study.
    #[command(disable_help_flag = true)]
    Ablate {
        /// Arguments of `trust-sim ablate` (or `merge` followed by those of `ablate-merge`).
        #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
        args: Vec<String>,
    },
    /// Reproduce one of the paper's experiments (release build) and write a report under `out/`.
    Experiment {
        /// Which experiment.
        name: Experiment,
        /// Trials per configuration (E1: random scenes per obstacle count; E2: timing repetitions).
        #[arg(long, default_value_t = 50)]
        trials: usize,
        /// Base seed (E1).
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Output directory.
        #[arg(long, default_value = "out")]
        out: PathBuf,
    },
    /// Throw random, adversarial and boundary inputs at every public API (release build of
    /// `trust-fuzz`); fails on any panic, hang, non-finite output, wrong answer or slow call.
    Fuzz {
        /// Total number of calls.
        #[arg(long, default_value_t = 1_000_000)]
        cases: u64,
        /// Seed of the run.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Only the APIs whose name contains this.
        #[arg(long)]
        only: Option<String>,
    },
    /// Run every property test (`proptest!`) of the workspace under K random seeds
    /// (`PROPTEST_RNG_SEED`) with `PROPTEST_CASES=N`; lists the seeds that fail which tests.
    Proptest {
        /// Number of random seeds.
        #[arg(long, default_value_t = 8)]
        seeds: u32,
        /// `PROPTEST_CASES` of every run (blocks that set their own case count keep it).
        #[arg(long, default_value_t = 256)]
        cases: u32,
        /// Base of the seed sequence (default: from the clock; printed so a run can be repeated).
        #[arg(long)]
        base: Option<u64>,
        /// Run exactly this one seed (e.g. CI's seed derived from the commit).
        #[arg(long, conflicts_with_all = ["seeds", "base"])]
        seed: Option<u64>,
        /// Build and run the tests in the release profile instead of the test profile.
        #[arg(long)]
        release: bool,
    },
    /// Write `docs/results.md` from studies already run (a study's `summary.json`, suites'
    /// `runs.csv`), stamped with the commit and the machine; fails naming a missing input.
    Results {
        /// The study's `summary.json` (`cargo xtask ablate` writes it).
        #[arg(long, default_value = results::DEFAULT_STUDY)]
        study: PathBuf,
        /// A suite's `runs.csv` (repeatable; default: `out/suite/runs.csv` when it exists).
        #[arg(long = "suite")]
        suites: Vec<PathBuf>,
        /// The file to write.
        #[arg(long, default_value = results::DEFAULT_OUT)]
        out: PathBuf,
    },
    /// Open a replay page in headless Chromium (`$TRUST_CHROMIUM` or `chromium` on the PATH):
    /// no script or console errors, and the vehicle moves when the slider does.
    ReplayCheck {
        /// The page (`trust-sim replay RUN.jsonl` writes `RUN.replay.html`).
        page: PathBuf,
        /// The later time the slider is moved to (s; the page clamps it to the flight).
        #[arg(long, default_value_t = 3.0)]
        at: f64,
        /// Where the screenshots go.
        #[arg(long, default_value = "target/replay-check")]
        out: PathBuf,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum Experiment {
    /// DEV-PRM vs V-PRM path-finding efficiency (paper Fig. Sim-A-1-1(c)).
    E1,
    /// UTF-MINCO vs MINCO on static and dynamic scenes (paper Table Sim-A-2).
    E2,
    /// The branches of one cold cycle on an E1-like scene (paper Table Sim-B-1).
    E3,
    /// Baselines 1–3 vs TRUST-Planner in closed loop (paper Fig. baseline-test-3): `ablate`.
    E4,
}

fn main() -> Result<()> {
    let cli = Cli::parse();
    let root = workspace_root()?;
    match cli.command {
        Cmd::Ci => run_status(
            Command::new("bash")
                .arg(root.join(".ci/run"))
                .current_dir(&root),
        ),
        Cmd::Experiment {
            name,
            trials,
            seed,
            out,
        } => {
            if trials == 0 {
                bail!("--trials must be at least 1");
            }
            let out = root.join(out);
            match name {
                Experiment::E1 => experiment_e1(&root, trials, seed, &out.join("e1")),
                Experiment::E2 => experiment_e2(&root, trials, &out.join("e2")),
                Experiment::E3 => trust_sim(
                    &root,
                    &[
                        "e3".into(),
                        "--seed".into(),
                        seed.to_string(),
                        "--out".into(),
                        out.join("e3").display().to_string(),
                    ],
                ),
                Experiment::E4 => trust_sim(
                    &root,
                    &[
                        "ablate".into(),
                        "--trials".into(),
                        trials.to_string(),
                        "--seed".into(),
                        seed.to_string(),
                        "--out".into(),
                        out.join("e4").display().to_string(),
                    ],
                ),
            }
        }
        Cmd::Ablate { args } => {
            let mut full = Vec::with_capacity(args.len() + 1);
            match args.first().map(String::as_str) {
                Some("merge") => {
                    full.push("ablate-merge".to_string());
                    full.extend(args[1..].iter().cloned());
                }
                _ => {
                    full.push("ablate".to_string());
                    full.extend(args);
                }
            }
            trust_sim(&root, &full)
        }
        Cmd::Fuzz { cases, seed, only } => fuzz::run(&root, cases, seed, only.as_deref()),
        Cmd::Proptest {
            seeds,
            cases,
            base,
            seed,
            release,
        } => proptest::run(
            &root,
            &proptest::Options {
                seeds,
                cases,
                base,
                seed,
                release,
            },
        ),
        Cmd::Results { study, suites, out } => {
            results::run(&root, &results::Options { study, suites, out })
        }
        Cmd::ReplayCheck { page, at, out } => replay_check(&page, at, &root.join(out)),
    }
}

fn replay_check(page: &Path, at: f64, out: &Path) -> Result<()> {
    if !(at.is_finite() && at > 0.0) {
        bail!("--at must be a positive number of seconds, got {at}");
    }
    let chromium = trust_replay::browser::find_chromium().context(
        "no chromium on the PATH (Debian: apt-get install chromium chromium-driver; or set \
         TRUST_CHROMIUM)",
    )?;
    let check = trust_replay::browser::check_page(&chromium, page, at, out)?;
    println!(
        "{}: no errors; vehicle at t = {} s {:?} px, at t = {} s {:?} px ({:.0} px apart); \
         {} pixels changed; screenshots {} and {}",
        page.display(),
        check.start.t,
        check.start.vehicle_px,
        check.later.t,
        check.later.vehicle_px,
        check.moved_px,
        check.changed_pixels,
        check.screenshots[0].display(),
        check.screenshots[1].display()
    );
    Ok(())
}

/// Obstacle counts of paper Fig. Sim-A-1-1(c).
const E1_OBSTACLE_COUNTS: [usize; 5] = [2, 5, 10, 15, 20];

fn experiment_e1(root: &Path, trials: usize, seed: u64, out: &Path) -> Result<()> {
    let mut raw = Vec::new();
    let mut rows = Vec::new();
    for (i, k) in E1_OBSTACLE_COUNTS.iter().enumerate() {
        eprintln!(
            "[{}/{}] E1 with {k} dynamic obstacles, {trials} scenes",
            i + 1,
            E1_OBSTACLE_COUNTS.len()
        );
        let stdout = cargo_example_output(
            root,
            "trust-topo-prm",
            e1::EXAMPLE,
            &[
                "--obstacles",
                &k.to_string(),
                "--trials",
                &trials.to_string(),
                "--seed",
                &seed.to_string(),
            ],
        )?;
        rows.push(e1::parse_row(&stdout)?);
        raw.push(example_json(e1::EXAMPLE, &stdout)?);
    }
    write_outputs(out, &Value::Array(raw), &e1::report(&rows))
}

fn experiment_e2(root: &Path, trials: usize, out: &Path) -> Result<()> {
    eprintln!("E2: UTF-MINCO vs MINCO, {trials} repetitions per case");
    let stdout = cargo_example_output(
        root,
        "trust-minco",
        e2::EXAMPLE,
        &["--repeats", &trials.to_string()],
    )?;
    let results = e2::parse(&stdout)?;
    write_outputs(
        out,
        &example_json(e2::EXAMPLE, &stdout)?,
        &e2::report(&results),
    )
}

/// Runs `trust-sim ARGS` in release ([`release`]) in the workspace root, passing the terminal
/// through (progress bars, the report), with the source's git sha for the report.
fn trust_sim(root: &Path, args: &[String]) -> Result<()> {
    let mut cmd = release::command(
        root,
        release::Program::Bin {
            package: "trust-sim",
            name: "trust-sim",
        },
    )?;
    cmd.args(args);
    if let Ok(out) = Command::new("git")
        .current_dir(root)
        .args(["rev-parse", "HEAD"])
        .output()
        && out.status.success()
    {
        cmd.env("TRUST_GIT_SHA", String::from_utf8_lossy(&out.stdout).trim());
    }
    run_status(&mut cmd)
}

fn write_outputs(out: &Path, json: &Value, md: &str) -> Result<()> {
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    std::fs::write(
        out.join("results.json"),
        serde_json::to_string_pretty(json)?,
    )?;
    std::fs::write(out.join("report.md"), md)?;
    println!("{md}");
    eprintln!("wrote {}", out.display());
    Ok(())
}

/// Runs the release example `EXAMPLE` of `PACKAGE` with `ARGS` ([`release`]) and returns its stdout.
fn cargo_example_output(
    root: &Path,
    package: &str,
    example: &str,
    args: &[&str],
) -> Result<String> {
    let output = release::command(
        root,
        release::Program::Example {
            package,
            name: example,
        },
    )?
    .args(args)
    .stderr(std::process::Stdio::inherit())
    .output()
    .with_context(|| format!("failed to start cargo for example {example}"))?;
    if !output.status.success() {
        bail!("example {example} failed with {}", output.status);
    }
    String::from_utf8(output.stdout).context("example output is not UTF-8")
}

/// The example's output as it printed it, archived in `results.json`.
fn example_json(example: &str, stdout: &str) -> Result<Value> {
    serde_json::from_str(stdout.trim())
        .with_context(|| format!("example {example} did not print one JSON object: {stdout}"))
}

fn workspace_root() -> Result<PathBuf> {
    let manifest_dir = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    manifest_dir
        .parent()
        .map(|p| p.to_path_buf())
        .context("xtask must live one level below the workspace root")
}

fn run_status(cmd: &mut Command) -> Result<()> {
    let status = cmd
        .status()
        .with_context(|| format!("failed to start {cmd:?}"))?;
    if !status.success() {
        bail!("{cmd:?} failed with {status}");
    }
    Ok(())
}
