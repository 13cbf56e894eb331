//! `trust-sim`: fly a scenario, validate scenario files, audit run logs, run studies — the
//! simulator and the experiments of the paper's Sec. IV from the command line.
//!
//! ```text
//! trust-sim run SCENARIO.toml [--planner NAME] [--seed S] [--out DIR] [--vehicle quadrotor|perfect]
//!                             [--real-time [CPU_SCALE]]
//! trust-sim validate SCENARIO.toml...
//! trust-sim audit RUN.jsonl... [--cycles]
//! trust-sim replay RUN.jsonl [--out DIR] [--gif-width PX] [--gif-frames N]
//! trust-sim export RUN.jsonl --mcap FILE
//! trust-sim ablate [--scenario FILE] [--trials N] [--seed S] [--planners a,b] [--variant V]
//!                  [--out DIR] [--jobs J] [--shard K/M] [--time-limit T] [--no-plots]
//! trust-sim ablate-merge --out DIR SHARD_DIR...
//! trust-sim suite [SCENARIO.toml|DIR...] [--seeds K] [--seed S] [--planners a,b] [--out DIR]
//!                 [--jobs J] [--time-limit T] [--no-plots] [--real-time [CPU_SCALE]]
//! trust-sim e3 [--scenario FILE] [--seed S] [--out DIR]
//! trust-sim forest [--tier easy|medium|hard|all] [--trials N] [--seed S] [--planner a,b]
//!                  [--jobs J] [--out DIR] [--static known] [--time-limit T]
//!                  [--vehicle perfect|quadrotor] [--real-time [CPU_SCALE]]
//! ```
//!
//! The binary only parses the command line; the work is in `trust-world` (scenarios, worlds),
//! `trust-flight` (the closed loop), `trust-runlog` (logs, audit), `trust-experiments`
//! (studies, E3, figures), `trust-replay` (the replay page and GIF) and `trust-export` (MCAP).

use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand, ValueEnum};
use trust_experiments::flight_plots::write_flight_plots;
use trust_experiments::study::{RunStudyOptions, Shard, StudyConfig, merge, run_study};
use trust_experiments::suite::{SuiteConfig, SuiteOptions, expand_paths, run_suite};
use trust_flight::scenario::Scenario;
use trust_flight::{RunOptions, fly, header};
use trust_planner::PlannerPreset;
use trust_world::scenario::{Latency, MAX_CPU_SCALE, VehicleModel};
use trust_world::{World, WorldError};

#[derive(Parser)]
#[command(
    name = "trust-sim",
    version,
    about = "Closed-loop simulator of TRUST-Planner and its baselines"
)]
struct Cli {
    #[command(subcommand)]
    command: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Fly one scenario and write the run log, summary.json and plots.
    Run {
        /// The scenario file (see scenarios/ and `cargo doc -p trust-world`, module `scenario`).
        scenario: PathBuf,
        /// Planner preset, replacing the scenario's `[planner]` section: trust, baseline1,
        /// baseline2 or baseline3.
        #[arg(long)]
        planner: Option<String>,
        /// Trial seed (the world, the obstacles' maneuvers, the sensor noise and the planner's
        /// random stream all derive from it).
        #[arg(long)]
        seed: Option<u64>,
        /// Output directory.
        #[arg(long, default_value = "out/run")]
        out: PathBuf,
        /// Vehicle model, replacing the scenario's.
        #[arg(long)]
        vehicle: Option<Model>,
        /// Simulated time limit (s), replacing the scenario's.
        #[arg(long)]
        time_limit: Option<f64>,
        /// Write 0 instead of measured times in the log's cycle records (byte-identical logs for
        /// the same seed).
        #[arg(long)]
        zero_timing: bool,
        /// Skip the plots.
        #[arg(long)]
        no_plots: bool,
        /// Log the kept branches and the forecasts in every cycle record (the default for `run`
        /// unless the scenario's `[log] branches` says otherwise).
        #[arg(long, conflicts_with = "no_log_branches")]
        log_branches: bool,
        /// Do not log branches and forecasts.
        #[arg(long)]
        no_log_branches: bool,
        /// Also write the replay (run.replay.html and run.replay.gif) next to the log.
        #[arg(long)]
        replay: bool,
        /// Fly in real time, replacing the scenario's `sim.latency`: each cycle's measured wall
        /// time (times CPU_SCALE, default 1: a computer CPU_SCALE times slower) is charged, and
        /// a busy planner skips replanning ticks (logged as the cycle's `overrun_ticks`).
        #[arg(long, value_name = "CPU_SCALE", num_args = 0..=1, default_missing_value = "1")]
        real_time: Option<f64>,
    },
    /// Write the replay of a run log: one self-contained HTML page that plays the flight, and an
    /// animated GIF of its top view (RUN.replay.html, RUN.replay.gif).
    Replay {
        /// The run log (JSON Lines).
        log: PathBuf,
        /// Output directory (default: the log's folder).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Width of the GIF (px).
        #[arg(long, default_value_t = 480)]
        gif_width: u32,
        /// At most this many GIF frames (at least 0.5 s of flight apart).
        #[arg(long, default_value_t = 48)]
        gif_frames: usize,
    },
    /// Check scenario files and report every problem found (exit status 1 if any).
    Validate {
        /// Scenario files.
        #[arg(required = true)]
        scenarios: Vec<PathBuf>,
    },
    /// Be the ROS 2 world of a separate `trust-node` (docs/ros2.md): publish the vehicle's
    /// odometry, the goal and the true obstacles over DDS, fly the trajectory the node
    /// publishes in real time, and write the run log (out/run.jsonl) as `run` does.
    DdsWorld {
        /// The scenario file (the node should be started with the same one).
        scenario: PathBuf,
        /// Trial seed, as for `run`.
        #[arg(long)]
        seed: Option<u64>,
        /// ROS domain id (the node's --domain-id).
        #[arg(long, default_value_t = 0)]
        domain_id: u16,
        /// Output directory.
        #[arg(long, default_value = "out/dds-world")]
        out: PathBuf,
        /// Simulated ROS time: `/clock` and every stamp are this (s) plus the simulated time
        /// since the start (`trust-node --use-sim-time` needed); default: the system time.
        #[arg(long)]
        clock_start: Option<f64>,
    },
    /// Run a comparative study (the paper's E4 by default): every planner on the same trials;
    /// writes runs.csv, summary.json, report.md, plots and every run log.
    Ablate {
        /// The scenario of every trial.
        #[arg(long, default_value = "scenarios/e4.toml")]
        scenario: PathBuf,
        /// Trials per planner (100 is the paper's size).
        #[arg(long, default_value_t = 4)]
        trials: usize,
        /// Base seed: trial i flies the scenario with seed S + i.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Planners, comma-separated, in report order.
        #[arg(
            long,
            default_value = "trust,baseline1,baseline2,baseline3",
            value_delimiter = ','
        )]
        planners: Vec<String>,
        /// One-component ablation applied to every planner it concerns: none, vprm, minco, uvd,
        /// no-pdc, no-ggs, no-history, no-hysteresis, no-worker (every solve in the cycle),
        /// perfect, quadrotor, mu=X, fault=X, explore=K, route (a global route on the static map;
        /// without it every planner aims at the final goal, the paper's setting), real-time or
        /// real-time=X (each cycle's measured wall time, times X, is charged: use `--jobs 1` on a
        /// quiet machine), unknown (the static map is not given: a depth camera senses it).
        #[arg(long, default_value = "none")]
        variant: String,
        /// Output directory.
        #[arg(long, default_value = "target/ablate")]
        out: PathBuf,
        /// Worker threads (default: one per core).
        #[arg(long)]
        jobs: Option<usize>,
        /// Run only shard K of M (trials i with i mod M = K - 1); combine with ablate-merge.
        #[arg(long, default_value = "1/1")]
        shard: String,
        /// Simulated time limit per flight (s), replacing the scenario's.
        #[arg(long)]
        time_limit: Option<f64>,
        /// Skip the plots.
        #[arg(long)]
        no_plots: bool,
    },
    /// Fly the scenario suite: every file (one class each; folders expand to their *.toml) with
    /// K seeds, as written (global route included); writes runs.csv, summary.json, report.md
    /// (one table per class), outcomes.svg/png and every run log. Exit status 1 if any flight
    /// collided or was invalid.
    Suite {
        /// Scenario files or folders.
        #[arg(default_value = "scenarios/suite")]
        scenarios: Vec<PathBuf>,
        /// Seeds per file and planner: S, S + 1, ..., S + K - 1.
        #[arg(long, default_value_t = 5)]
        seeds: usize,
        /// The first seed.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Planner presets, comma-separated (default: each file's own `[planner]` section).
        #[arg(long, value_delimiter = ',')]
        planners: Vec<String>,
        /// Output directory.
        #[arg(long, default_value = "out/suite")]
        out: PathBuf,
        /// Worker threads (default: one per core).
        #[arg(long)]
        jobs: Option<usize>,
        /// Simulated time limit per flight (s), replacing the files'.
        #[arg(long)]
        time_limit: Option<f64>,
        /// Skip the chart.
        #[arg(long)]
        no_plots: bool,
        /// Fly in real time (see `run --real-time`), replacing the files' `sim.latency`.
        /// Measured times depend on the machine's load: use `--jobs 1` on a quiet machine.
        #[arg(long, value_name = "CPU_SCALE", num_args = 0..=1, default_missing_value = "1")]
        real_time: Option<f64>,
    },
    /// Experiment E3 (paper Table Sim-B-1): the branches of one cold cycle, beside the paper's
    /// table; writes summary.json, report.md and a top view with the forecasts.
    E3 {
        /// The scenario.
        #[arg(long, default_value = "scenarios/e3.toml")]
        scenario: PathBuf,
        /// Trial seed, replacing the scenario's.
        #[arg(long)]
        seed: Option<u64>,
        /// Output directory.
        #[arg(long, default_value = "out/e3")]
        out: PathBuf,
    },
    /// MIT-ACL's dynamic-forest benchmark (docs/dynamic-forest.md): the tiers easy / medium /
    /// hard (50 / 100 / 200 obstacles, 65 % cubes on trefoil knots) flown in closed loop and
    /// scored with the peers' metrics; writes runs.csv, runs.json, summary.json, report.md and
    /// every run log.
    Forest {
        /// Tiers: easy, medium, hard or all (or a comma-separated list).
        #[arg(long, default_value = "all")]
        tier: String,
        /// Trials per tier and planner (the peers fly 10).
        #[arg(long, default_value_t = 10)]
        trials: usize,
        /// Base seed: trial i flies seed S + i.
        #[arg(long, default_value_t = 0)]
        seed: u64,
        /// Planner presets, comma-separated, in report order.
        #[arg(
            long,
            alias = "planners",
            default_value = "trust",
            value_delimiter = ','
        )]
        planner: Vec<String>,
        /// Worker threads (default: one per core).
        #[arg(long)]
        jobs: Option<usize>,
        /// Output directory.
        #[arg(long, default_value = "out/forest")]
        out: PathBuf,
        /// The scenario (its generator must be `dynamic-forest`; the tier sets its count).
        #[arg(long, default_value = "scenarios/dynamic_forest.toml")]
        scenario: PathBuf,
        /// What the planner knows of the static obstacles: known (their true shapes) or unknown
        /// (sensed by the vehicle's depth camera into an online map).
        #[arg(long = "static", default_value = "known")]
        static_mode: String,
        /// Simulated time limit per flight (s), replacing the scenario's 100 s.
        #[arg(long)]
        time_limit: Option<f64>,
        /// Vehicle model, replacing the scenario's (perfect tracking, as the peers' simulator).
        #[arg(long)]
        vehicle: Option<Model>,
        /// Fly in real time (see `run --real-time`), replacing the scenario's `sim.latency`.
        /// Measured times depend on the machine's load: use `--jobs 1` on a quiet machine.
        #[arg(long, value_name = "CPU_SCALE", num_args = 0..=1, default_missing_value = "1")]
        real_time: Option<f64>,
    },
    /// Combine the directories of a sharded study into one report, as a single run would write.
    AblateMerge {
        /// Output directory.
        #[arg(long)]
        out: PathBuf,
        /// The shards' output directories.
        #[arg(required = true)]
        dirs: Vec<PathBuf>,
        /// Skip the plots.
        #[arg(long)]
        no_plots: bool,
    },
    /// Re-check run logs: recompute the outcome from the header and state records with
    /// independent geometry and compare (exit status 1 on any disagreement).
    Audit {
        /// Run logs (JSON Lines).
        #[arg(required = true)]
        logs: Vec<PathBuf>,
        /// Also check the cycle records against the contract (t, wall_ms ≥ 0, main, branches,
        /// events; t within the flight).
        #[arg(long)]
        cycles: bool,
    },
    /// Export a run log for other tools: `--mcap FILE` writes an MCAP file that Foxglove (or
    /// Lichtblick) replays in 3-D and `ros2 bag` reads (pose and path as ROS 2 messages).
    Export {
        /// The run log (JSON Lines).
        log: PathBuf,
        /// The MCAP file to write.
        #[arg(long, value_name = "FILE")]
        mcap: PathBuf,
    },
}

#[derive(Clone, Copy, ValueEnum)]
enum Model {
    /// Rigid-body quadrotor with a geometric SE(3) controller.
    Quadrotor,
    /// The vehicle is exactly on the plan.
    Perfect,
}

/// `println!` that ends the program quietly when standard output is closed (`trust-sim … |
/// head`) instead of panicking; any other write error ends it with a message and code 1.
macro_rules! out {
    ($($arg:tt)*) => {
        emit(format_args!($($arg)*))
    };
}

fn emit(args: std::fmt::Arguments<'_>) {
    use std::io::Write as _;
    let mut stdout = std::io::stdout().lock();
    if let Err(e) = stdout
        .write_fmt(args)
        .and_then(|()| stdout.write_all(b"\n"))
    {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(0);
        }
        eprintln!("error: writing to standard output: {e}");
        std::process::exit(1);
    }
}

fn main() -> ExitCode {
    match run_cli() {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}

/// The real-time latency at `--real-time CPU_SCALE`.
fn real_time_latency(scale: f64) -> Result<Latency> {
    if !(scale > 0.0 && scale <= MAX_CPU_SCALE) {
        bail!("--real-time takes a CPU scale in (0, {MAX_CPU_SCALE}], got {scale}");
    }
    Ok(Latency::real_time(scale))
}

fn run_cli() -> Result<ExitCode> {
    match Cli::parse().command {
        Cmd::Run {
            scenario,
            planner,
            seed,
            out,
            vehicle,
            time_limit,
            zero_timing,
            no_plots,
            log_branches,
            no_log_branches,
            replay,
            real_time,
        } => {
            // Checked once, with the overrides applied, where the world is built (`run`).
            let mut s = Scenario::parse_file(&scenario)?;
            if let Some(name) = planner {
                s.planner.name = parse_preset(&name)?;
                s.planner.frontend = None;
                s.planner.backend = None;
                s.planner.checker = None;
                s.planner.manager = None;
            }
            if let Some(seed) = seed {
                s = s.with_seed(seed);
            }
            if let Some(m) = vehicle {
                s.vehicle.model = match m {
                    Model::Quadrotor => VehicleModel::Quadrotor,
                    Model::Perfect => VehicleModel::Perfect,
                };
            }
            if let Some(limit) = time_limit {
                if !(limit.is_finite() && limit > 0.0) {
                    bail!("--time-limit must be a positive number of seconds, got {limit}");
                }
                s.time_limit_s = limit;
            }
            if let Some(scale) = real_time {
                s.sim.latency = real_time_latency(scale)?;
            }
            let branches = if log_branches {
                true
            } else if no_log_branches {
                false
            } else {
                s.log.branches_or(true)
            };
            let options = RunFlags {
                zero_timing,
                plots: !no_plots,
                log_branches: branches,
                replay,
            };
            run(&s, &out, &options)
        }
        Cmd::Replay {
            log,
            out,
            gif_width,
            gif_frames,
        } => {
            let dir = out.unwrap_or_else(|| {
                log.parent()
                    .filter(|p| !p.as_os_str().is_empty())
                    .map_or_else(|| PathBuf::from("."), Path::to_path_buf)
            });
            let mut params = trust_replay::ReplayParams::default();
            params.gif.width_px = gif_width;
            params.gif.max_frames = gif_frames;
            write_replay_files(&log, &dir, &params)?;
            Ok(ExitCode::SUCCESS)
        }
        Cmd::Ablate {
            scenario,
            trials,
            seed,
            planners,
            variant,
            out,
            jobs,
            shard,
            time_limit,
            no_plots,
        } => {
            let planners = parse_presets(&planners)?;
            let scenario_name = trust_flight::scenario::load(&scenario)?.name;
            let config = StudyConfig {
                scenario,
                scenario_name,
                trials,
                seed,
                planners,
                variant: variant.parse()?,
                time_limit_s: time_limit,
                shard: Shard::parse(&shard)?,
            };
            let flights = config.my_trials().len() * config.planners.len();
            eprintln!(
                "{} trial(s) × {} planner(s) = {flights} flight(s) of `{}`, variant `{}`, shard {}/{}",
                config.my_trials().len(),
                config.planners.len(),
                config.scenario_name,
                config.variant,
                config.shard.index,
                config.shard.count
            );
            let options = RunStudyOptions {
                jobs,
                no_plots,
                progress: std::io::stderr().is_terminal(),
            };
            let rows = run_study(&config, &out, &options)?;
            print_study(&out, rows.len())
        }
        Cmd::Suite {
            scenarios,
            seeds,
            seed,
            planners,
            out,
            jobs,
            time_limit,
            no_plots,
            real_time,
        } => {
            let planners = parse_presets(&planners)?;
            let config = SuiteConfig {
                files: expand_paths(&scenarios)?,
                seeds,
                seed,
                planners,
                time_limit_s: time_limit,
                latency: real_time.map(real_time_latency).transpose()?,
            };
            eprintln!(
                "{} file(s) × {} seed(s) × {} planner setting(s)",
                config.files.len(),
                config.seeds,
                config.planners.len().max(1)
            );
            let options = SuiteOptions {
                jobs,
                no_plots,
                progress: std::io::stderr().is_terminal(),
            };
            let rows = run_suite(&config, &out, &options)?;
            let report = std::fs::read_to_string(out.join("report.md"))
                .with_context(|| format!("reading {}", out.join("report.md").display()))?;
            out!("{report}");
            out!("wrote {} ({} flights)", out.display(), rows.len());
            let bad = rows
                .iter()
                .filter(|r| r.status == "collided" || r.status == "invalid")
                .count();
            Ok(if bad == 0 {
                ExitCode::SUCCESS
            } else {
                ExitCode::FAILURE
            })
        }
        Cmd::E3 {
            scenario,
            seed,
            out,
        } => {
            // Checked once, where `run_e3` builds the world.
            let mut s = Scenario::parse_file(&scenario)?;
            if let Some(seed) = seed {
                s = s.with_seed(seed);
            }
            let summary = trust_experiments::e3::run_e3(&s, &out)?;
            out!("{}", trust_experiments::e3::report_md(&summary));
            out!("wrote {}", out.display());
            Ok(ExitCode::SUCCESS)
        }
        Cmd::Forest {
            tier,
            trials,
            seed,
            planner,
            jobs,
            out,
            scenario,
            static_mode,
            time_limit,
            vehicle,
            real_time,
        } => {
            use trust_experiments::forest::{
                ForestConfig, ForestOptions, SANDO_J_MAX, StaticMode, Tier, run_forest,
            };
            let static_mode: StaticMode = static_mode.parse()?;
            let config = ForestConfig {
                scenario,
                tiers: Tier::parse_list(&tier)?,
                trials,
                seed,
                planners: parse_presets(&planner)?,
                static_mode,
                time_limit_s: time_limit,
                latency: real_time.map(real_time_latency).transpose()?,
                vehicle: vehicle.map(|m| match m {
                    Model::Quadrotor => VehicleModel::Quadrotor,
                    Model::Perfect => VehicleModel::Perfect,
                }),
                j_max: SANDO_J_MAX,
            };
            config.validate()?;
            eprintln!(
                "{} tier(s) × {} trial(s) × {} planner(s) = {} flight(s) of the dynamic forest",
                config.tiers.len(),
                config.trials,
                config.planners.len(),
                config.tiers.len() * config.trials * config.planners.len()
            );
            let options = ForestOptions {
                jobs,
                progress: std::io::stderr().is_terminal(),
            };
            let rows = run_forest(&config, &out, &options)?;
            let report = std::fs::read_to_string(out.join("report.md"))
                .with_context(|| format!("reading {}", out.join("report.md").display()))?;
            let head = report.split("## Reading it").next().unwrap_or(&report);
            out!("{}", head.trim_end());
            out!("\n{} flight(s); wrote {}", rows.len(), out.display());
            Ok(ExitCode::SUCCESS)
        }
        Cmd::AblateMerge {
            out,
            dirs,
            no_plots,
        } => {
            let rows = merge(&dirs, &out, !no_plots)?;
            print_study(&out, rows.len())
        }
        Cmd::Validate { scenarios } => {
            let mut bad = 0;
            for path in &scenarios {
                match trust_flight::scenario::load_checked(path) {
                    Ok(_) => out!("{}: ok", path.display()),
                    Err(e) => {
                        bad += 1;
                        out!("{e}");
                    }
                }
            }
            Ok(if bad == 0 {
                ExitCode::SUCCESS
            } else {
                ExitCode::FAILURE
            })
        }
        Cmd::DdsWorld {
            scenario,
            seed,
            domain_id,
            out,
            clock_start,
        } => {
            let mut s = Scenario::parse_file(&scenario)?;
            if let Some(seed) = seed {
                s = s.with_seed(seed);
            }
            let problems = trust_flight::scenario::check(&s);
            if !problems.is_empty() {
                return Err(WorldError::Invalid {
                    path: s.origin(),
                    problems,
                }
                .into());
            }
            let world = World::build(&s)?;
            std::fs::create_dir_all(&out).with_context(|| format!("creating {}", out.display()))?;
            let log_path = out.join("run.jsonl");
            eprintln!(
                "dds-world: `{}` (seed {}) on ROS domain {domain_id}, waiting for trust-node...",
                s.name, s.seed
            );
            let o = trust_ros2::dds_world::fly(
                &world,
                domain_id,
                &log_path,
                &trust_ros2::dds_world::DdsWorldOptions {
                    clock_start_s: clock_start,
                    ..Default::default()
                },
            )?;
            out!(
                "trust-node over DDS: {}{} at t = {:.2} s; path {:.1} m; min clearance static {}, \
                 moving {}; max speed {:.2} m/s; {} cycles; wrote {}",
                o.status.as_str(),
                o.with
                    .as_ref()
                    .map(|w| format!(" with {w}"))
                    .unwrap_or_default(),
                o.t,
                o.path_length_m,
                clearance_text(o.min_clearance_static_m),
                clearance_text(o.min_clearance_dynamic_m),
                o.max_speed,
                o.cycle_count,
                log_path.display()
            );
            Ok(ExitCode::SUCCESS)
        }
        Cmd::Audit { logs, cycles } => {
            let mut bad = 0;
            for path in &logs {
                // Streamed: an hour's log is audited in the memory of one line.
                let a = trust_runlog::audit::audit_file(
                    path,
                    trust_runlog::audit::AuditOptions { cycles },
                )?;
                if a.passed() {
                    out!(
                        "{}: ok ({}, {} states{})",
                        path.display(),
                        a.logged_status.as_str(),
                        a.state_count,
                        if cycles {
                            format!(", {} cycles", a.cycle_count)
                        } else {
                            String::new()
                        }
                    );
                } else {
                    bad += 1;
                    out!("{}: {} disagreement(s)", path.display(), a.findings.len());
                    for f in &a.findings {
                        out!("  {f}");
                    }
                }
            }
            Ok(if bad == 0 {
                ExitCode::SUCCESS
            } else {
                ExitCode::FAILURE
            })
        }
        Cmd::Export { log, mcap } => {
            let summary = trust_export::export_file(&log, &mcap)?;
            let total: u64 = summary.message_counts.values().sum();
            out!(
                "wrote {} ({total} messages on {} topics)",
                mcap.display(),
                summary.message_counts.len()
            );
            Ok(ExitCode::SUCCESS)
        }
    }
}

fn print_study(out: &Path, flights: usize) -> Result<ExitCode> {
    let report = std::fs::read_to_string(out.join("report.md"))
        .with_context(|| format!("reading {}", out.join("report.md").display()))?;
    // The table and the targets: everything up to "## Reading it".
    let head = report.split("## Reading it").next().unwrap_or(&report);
    out!("{}", head.trim_end());
    out!("\n{flights} flight(s); wrote {}", out.display());
    Ok(ExitCode::SUCCESS)
}

/// `--planners a,b,…` as presets, in order.
fn parse_presets(names: &[String]) -> Result<Vec<PlannerPreset>> {
    names.iter().map(|p| parse_preset(p.trim())).collect()
}

fn parse_preset(name: &str) -> Result<PlannerPreset> {
    serde_json::from_value(serde_json::Value::String(name.to_string())).with_context(|| {
        format!("unknown planner `{name}`: expected trust, baseline1, baseline2 or baseline3")
    })
}

/// The switches of `trust-sim run` beyond the scenario.
struct RunFlags {
    zero_timing: bool,
    plots: bool,
    log_branches: bool,
    replay: bool,
}

fn write_replay_files(log: &Path, dir: &Path, params: &trust_replay::ReplayParams) -> Result<()> {
    let files = trust_replay::write_replay(log, dir, params)?;
    out!(
        "replay: {} ({:.0} kB), {} ({} frames, {}×{} px)",
        files.html.display(),
        files.html_bytes as f64 / 1e3,
        files.gif.path.display(),
        files.gif.frame_count,
        files.gif.width_px,
        files.gif.height_px
    );
    Ok(())
}

fn run(s: &Scenario, out: &Path, flags: &RunFlags) -> Result<ExitCode> {
    std::fs::create_dir_all(out).with_context(|| format!("creating {}", out.display()))?;
    let tty = std::io::stderr().is_terminal();
    eprintln!("building the world of `{}` (seed {})...", s.name, s.seed);
    // Every problem at once, as `validate` reports them: the world's sections and the
    // planner's, which only this crate knows together.
    let problems = trust_flight::scenario::check(s);
    if !problems.is_empty() {
        return Err(WorldError::Invalid {
            path: s.origin(),
            problems,
        }
        .into());
    }
    let world = World::build(s)?;
    let planner = trust_flight::scenario::resolve_planner(s);
    let log_path = out.join("run.jsonl");
    let options = RunOptions {
        log_path: Some(log_path.clone()),
        zero_timing: flags.zero_timing,
        progress_every_s: Some(1.0),
        log_branches: flags.log_branches,
    };
    let limit = s.time_limit_s;
    let flight = fly(&world, &planner, &options, |t| {
        if tty {
            eprint!("\r  simulated {t:5.1} s of at most {limit:.0} s");
        }
    })?;
    if tty {
        eprintln!();
    }
    let summary = &flight.summary;
    let json = serde_json::to_string_pretty(summary)?;
    std::fs::write(out.join("summary.json"), json + "\n")
        .with_context(|| format!("writing {}", out.join("summary.json").display()))?;
    if flags.plots {
        let h = header(&world, &planner.label, None);
        write_flight_plots(out, &h, &flight.record, world.static_points())?;
    }
    let o = &summary.outcome;
    out!(
        "{}: {}{} at t = {:.2} s; path {:.1} m; min clearance static {}, moving {}; \
         max speed {:.2} m/s, max accel {:.2} m/s²",
        planner.label,
        o.status.as_str(),
        o.with
            .as_ref()
            .map(|w| match o.forecast_warning_s {
                Some(s) => format!(" with {w} (in its forecasts for {s:.2} s before)"),
                None => format!(" with {w}"),
            })
            .unwrap_or_default(),
        o.t,
        o.path_length_m,
        clearance_text(o.min_clearance_static_m),
        clearance_text(o.min_clearance_dynamic_m),
        o.max_speed,
        o.max_accel
    );
    if let (trust_runlog::Status::Unreachable | trust_runlog::Status::Invalid, Some(why)) =
        (o.status, &o.reason)
    {
        out!("why: {why}");
    }
    out!(
        "{} cycles: median {:.2} ms, p99 {:.2} ms, max {:.2} ms ({} over the {} ms budget{}); \
         {:.3} ms solve per trajectory; {} fallbacks; {:.1}× real time",
        summary.cycle_count,
        summary.cycle_ms_median,
        summary.cycle_ms_p99,
        summary.cycle_ms_max,
        summary.over_budget_count,
        planner.manager.cycle_budget_ms,
        if world.scenario().sim.latency.is_real_time() {
            format!(
                "; real time: {} replanning tick(s) skipped",
                summary.skipped_tick_count
            )
        } else {
            String::new()
        },
        summary.solve_ms_per_trajectory,
        summary.fallback_count,
        summary.real_time_factor
    );
    out!("wrote {}", out.display());
    if flags.replay {
        write_replay_files(&log_path, out, &trust_replay::ReplayParams::default())?;
    }
    Ok(ExitCode::SUCCESS)
}

/// A minimum clearance for the console: "none met" when there was nothing of that kind to meet
/// (the outcome's `trust_flight::NO_OBSTACLE_CLEARANCE_M` sentinel), else metres.
fn clearance_text(m: f64) -> String {
    if m >= trust_flight::NO_OBSTACLE_CLEARANCE_M {
        "– (none met)".to_string()
    } else {
        format!("{m:.2} m")
    }
}
