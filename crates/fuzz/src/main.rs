//! `trust-fuzz`: throws random, adversarial and boundary inputs at every public entry point of the
//! TRUST-Planner library crates and reports, per API, calls, typed errors, panics, non-finite
//! outputs, wrong answers (oracle violations) and slow calls. Exits non-zero if anything but
//! ordinary results and typed errors occurred. Run it through `cargo xtask fuzz`.
//!
//! Every call runs under `catch_unwind` on a worker thread; a watchdog on the main thread stops
//! the run (exit code 3) when one call exceeds `--hang-ms`, printing the API and the case seed.
//! Each case is reproducible alone: `trust-fuzz --only <api> --replay <case seed>`.

mod apis;
mod files;
mod inputs;
mod minco_oracles;
mod params;

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use anyhow::{Context as _, Result};
use clap::Parser;

use apis::{Api, Fixtures, Outcome};
use inputs::Gen;

#[derive(Parser, Debug)]
#[command(about = "Adversarial-input fuzzing of every public TRUST-Planner API")]
struct Args {
    /// Total number of calls, shared among the APIs by weight.
    #[arg(long, default_value_t = 1_000_000)]
    cases: u64,
    /// Seed of the whole run.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// A call slower than this is reported as slow (ms).
    #[arg(long, default_value_t = 1000)]
    slow_ms: u64,
    /// A call slower than this stops the run as a hang (ms).
    #[arg(long, default_value_t = 20_000)]
    hang_ms: u64,
    /// Only run APIs whose name contains this.
    #[arg(long)]
    only: Option<String>,
    /// Replay one case seed (with --only) and print its outcome.
    #[arg(long)]
    replay: Option<u64>,
    /// How many failing case seeds to print per API (per kind of failure for file groups).
    #[arg(long, default_value_t = 3)]
    show: usize,
    /// Address-space limit of a file-group worker (MiB; 0: none): an allocation beyond it
    /// aborts the worker, which the run counts and survives.
    #[arg(long, default_value_t = 2048)]
    mem_mb: u64,
    /// A scenario that validates with a planner map of more ESDF voxels than this is counted
    /// as heavy and not set up (file groups).
    #[arg(long, default_value_t = 1_000_000.0)]
    max_voxels: f64,
    /// Parallel workers per file group.
    #[arg(long, default_value_t = 1)]
    jobs: usize,
    /// Keep the file groups' folder here (the corpus logs, each worker's last case; with
    /// --replay, the case's files) instead of a temporary one removed at the end.
    #[arg(long)]
    keep: Option<std::path::PathBuf>,
    /// Internal: run as a file-group worker of this group.
    #[arg(long, hide = true)]
    worker: Option<String>,
    /// Internal: the worker's first case.
    #[arg(long, hide = true, default_value_t = 0)]
    from: u64,
    /// Internal: one past the worker's last case.
    #[arg(long, hide = true, default_value_t = 0)]
    to: u64,
    /// Internal: the worker's folder.
    #[arg(long, hide = true)]
    work: Option<std::path::PathBuf>,
    /// Internal: the corpus logs' folder.
    #[arg(long, hide = true)]
    base: Option<std::path::PathBuf>,
}

#[derive(Default, Clone)]
struct Stats {
    calls: u64,
    errors: u64,
    panics: u64,
    non_finite: u64,
    wrong: u64,
    slow: u64,
    max_ms: f64,
    examples: Vec<String>,
}

/// What the watchdog sees: the running call's API index, case seed and start (µs since run start).
struct Current {
    api: AtomicUsize,
    case: AtomicU64,
    started_us: AtomicU64,
    busy: AtomicBool,
}

fn case_seed(run_seed: u64, api: usize, k: u64) -> u64 {
    // SplitMix64 of the triple: independent, reproducible case seeds.
    let mut z = run_seed
        .wrapping_mul(0x9E37_79B9_7F4A_7C15)
        .wrapping_add((api as u64) << 40)
        .wrapping_add(k);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

fn run_one(api: &Api, fx: &Fixtures, seed: u64) -> (std::thread::Result<Outcome>, f64) {
    let mut g = Gen::new(seed);
    let t0 = Instant::now();
    let out = catch_unwind(AssertUnwindSafe(|| (api.run)(&mut g, fx)));
    (out, t0.elapsed().as_secs_f64() * 1e3)
}

fn panic_message(p: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = p.downcast_ref::<&str>() {
        (*s).to_owned()
    } else if let Some(s) = p.downcast_ref::<String>() {
        s.clone()
    } else {
        "non-string panic payload".to_owned()
    }
}

/// Every API the harness calls: the library entry points, the parameter structs at their edges
/// (a module per crate) and the minco contract oracles. Composed here, at the crate root, so
/// that the modules stay free of cycles.
fn registry() -> Vec<Api> {
    let mut v = apis::all();
    v.extend(params::apis());
    v.extend(minco_oracles::apis());
    v
}

fn main() -> Result<()> {
    let args = Args::parse();
    // Panics are counted, not printed one by one.
    std::panic::set_hook(Box::new(|_| {}));
    if let Some(group) = &args.worker {
        return files::worker::worker_main(&files::worker::Plan {
            group: group.clone(),
            from: args.from,
            to: args.to,
            seed: args.seed,
            work: args.work.clone().context("--worker needs --work")?,
            base: args.base.clone().context("--worker needs --base")?,
            max_voxels: args.max_voxels,
        });
    }
    let selected = |name: &str| args.only.as_ref().is_none_or(|o| name.contains(o.as_str()));
    let apis: Vec<Api> = registry()
        .into_iter()
        .filter(|a| selected(a.name))
        .collect();
    // File groups of weight 0 (the harness's self-test) run only when named exactly.
    let file_groups: Vec<(usize, files::FileGroup)> = files::groups()
        .into_iter()
        .enumerate()
        .filter(|(_, g)| {
            if g.weight == 0 {
                args.only.as_deref() == Some(g.name)
            } else {
                selected(g.name)
            }
        })
        .collect();
    anyhow::ensure!(
        !apis.is_empty() || !file_groups.is_empty(),
        "no API or file group matches --only"
    );

    if let Some(seed) = args.replay {
        if !apis.is_empty() {
            let fx = Fixtures::new()?;
            for api in &apis {
                let (out, ms) = run_one(api, &fx, seed);
                match out {
                    Ok(o) => println!("{}: {o:?} in {ms:.3} ms", api.name),
                    Err(p) => println!("{}: PANIC {} in {ms:.3} ms", api.name, panic_message(&*p)),
                }
            }
        }
        for (_, g) in &file_groups {
            replay_file_case(&args, g, seed)?;
        }
        return Ok(());
    }

    // A group of weight 0 runs only when named alone: it then takes every case.
    let weight = |w: u32| u64::from(w.max(1));
    let total_weight: u64 = apis.iter().map(|a| weight(a.weight)).sum::<u64>()
        + file_groups
            .iter()
            .map(|(_, g)| weight(g.weight))
            .sum::<u64>();
    let share = |w: u32| (args.cases * weight(w) / total_weight.max(1)).max(1);
    let mut bad = 0;
    if !apis.is_empty() {
        let calls_per_api: Vec<u64> = apis.iter().map(|a| share(a.weight)).collect();
        bad += run_apis(&args, apis, &calls_per_api)?;
    }
    if !file_groups.is_empty() {
        let cases: Vec<u64> = file_groups.iter().map(|(_, g)| share(g.weight)).collect();
        bad += run_file_groups(&args, &file_groups, &cases)?;
    }
    if bad > 0 {
        println!(
            "FAIL: {bad} calls or cases panicked, aborted, hung, returned non-finite, wrong or \
             unreadable output, disagreed, or were slow"
        );
        std::process::exit(1);
    }
    println!(
        "OK: 0 panics, 0 aborts, 0 hangs, 0 non-finite outputs, 0 wrong answers, 0 unreadable \
         messages, 0 disagreements, 0 slow calls"
    );
    Ok(())
}

/// Runs one case of a file group in this process (`--replay`) and prints its verdict; its files
/// stay in `--keep` (or a temporary folder, printed).
fn replay_file_case(args: &Args, g: &files::FileGroup, seed: u64) -> Result<()> {
    let root = args.keep.clone().unwrap_or_else(|| {
        std::env::temp_dir().join(format!("trust-fuzz-replay-{}", std::process::id()))
    });
    let base = root.join("base");
    if g.needs_logs && !base.join("quickstart").is_dir() {
        files::prepare(&base)?;
    }
    let ctx = files::Ctx::load(&base, args.max_voxels)?;
    let dir = files::corpus::CaseDir::create(&root.join("work"), &ctx.corpus)?;
    let (r, ms) = files::worker::run_case(g, &ctx, &dir, seed);
    match r {
        Ok(v) => {
            println!(
                "{}: {} in {ms:.1} ms{}",
                g.name,
                if v.accepted { "accepted" } else { "refused" },
                if v.heavy { " (heavy: not set up)" } else { "" }
            );
            println!("  what it did: {}", v.note);
            for (flag, detail) in &v.flags {
                println!("  {}: {detail}", flag.name());
            }
        }
        Err(p) => println!("{}: PANIC {} in {ms:.1} ms", g.name, panic_message(&*p)),
    }
    println!("  files: {}", dir.case.display());
    Ok(())
}

/// Runs the file groups (`cases[i]` cases of `groups[i]`) in workers and prints their table;
/// returns the number of bad cases.
fn run_file_groups(
    args: &Args,
    groups: &[(usize, files::FileGroup)],
    cases: &[u64],
) -> Result<u64> {
    let t0 = Instant::now();
    let root = args
        .keep
        .clone()
        .unwrap_or_else(|| std::env::temp_dir().join(format!("trust-fuzz-{}", std::process::id())));
    let base = root.join("base");
    if groups.iter().any(|(_, g)| g.needs_logs) {
        files::prepare(&base)?;
        eprintln!(
            "file groups: corpus logs flown in {:.1} s",
            t0.elapsed().as_secs_f64()
        );
    }
    let opts = files::worker::Options {
        seed: args.seed,
        hang_ms: args.hang_ms,
        mem_mb: args.mem_mb,
        max_voxels: args.max_voxels,
        base,
        work: root.join("work"),
        show: args.show,
        jobs: args.jobs,
    };
    let exe = std::env::current_exe().context("locating trust-fuzz for its workers")?;
    let mut stats = Vec::new();
    for ((index, g), &n) in groups.iter().zip(cases) {
        let t = Instant::now();
        let s = files::worker::run_group(&exe, *index, n, &opts)?;
        eprintln!(
            "{}: {} cases in {:.1} s",
            g.name,
            s.cases,
            t.elapsed().as_secs_f64()
        );
        stats.push((g.name, s));
    }
    let bad = print_file_table(&stats, args, t0);
    if args.keep.is_none() {
        std::fs::remove_dir_all(&root).ok();
    }
    Ok(bad)
}

/// Prints the file groups' table and failing examples; returns the number of bad cases.
fn print_file_table(stats: &[(&str, files::worker::GroupStats)], args: &Args, t0: Instant) -> u64 {
    println!(
        "{:<16} {:>8} {:>9} {:>6} {:>7} {:>7} {:>6} {:>6} {:>11} {:>9} {:>9}",
        "file group",
        "cases",
        "accepted",
        "heavy",
        "panics",
        "aborts",
        "hangs",
        "wrong",
        "unreadable",
        "disagree",
        "max ms"
    );
    let mut total = files::worker::GroupStats::default();
    let row = |name: &str, s: &files::worker::GroupStats| {
        println!(
            "{:<16} {:>8} {:>9} {:>6} {:>7} {:>7} {:>6} {:>6} {:>11} {:>9} {:>9.1}",
            name,
            s.cases,
            s.accepted,
            s.heavy,
            s.panics,
            s.aborts,
            s.hangs,
            s.wrong,
            s.unreadable,
            s.disagree,
            s.slowest.0
        );
    };
    for (name, s) in stats {
        row(name, s);
        total.merge(s, 0);
    }
    row("TOTAL", &total);
    println!(
        "seed {}, {:.1} s wall; workers: {} MiB address space{}, hang after {} ms; heavy: \
         validated with a map above {} ESDF voxels, not set up",
        args.seed,
        t0.elapsed().as_secs_f64(),
        args.mem_mb,
        if args.mem_mb == 0 { " (no limit)" } else { "" },
        args.hang_ms,
        args.max_voxels
    );
    for (name, s) in stats {
        if s.slowest.0 > 0.0 {
            println!(
                "  {name}: slowest case {} ({:.0} ms)",
                s.slowest.1, s.slowest.0
            );
        }
        for (_, e) in &s.examples {
            println!("  {name}: {e}");
        }
        if s.bad() > 0 {
            println!("    replay: trust-fuzz --only '{name}' --replay <case> --keep DIR");
        }
    }
    total.bad()
}

/// Runs the API groups (`calls_per_api[i]` calls of `apis[i]`) with the watchdog and prints their
/// table; returns the number of bad calls.
fn run_apis(args: &Args, apis: Vec<Api>, calls_per_api: &[u64]) -> Result<u64> {
    let fx = Fixtures::new()?;
    let calls_per_api = calls_per_api.to_vec();
    let names: Vec<&'static str> = apis.iter().map(|a| a.name).collect();
    let current = Arc::new(Current {
        api: AtomicUsize::new(0),
        case: AtomicU64::new(0),
        started_us: AtomicU64::new(0),
        busy: AtomicBool::new(false),
    });
    let stats = Arc::new(Mutex::new(vec![Stats::default(); apis.len()]));
    let run_start = Instant::now();
    let done = Arc::new(AtomicBool::new(false));

    let worker = {
        let current = Arc::clone(&current);
        let stats = Arc::clone(&stats);
        let done = Arc::clone(&done);
        let (seed, slow_ms, show) = (args.seed, args.slow_ms as f64, args.show);
        std::thread::Builder::new()
            .name("fuzz-worker".into())
            .stack_size(64 << 20)
            .spawn(move || {
                for (i, api) in apis.iter().enumerate() {
                    let mut s = Stats::default();
                    for k in 0..calls_per_api[i] {
                        let cs = case_seed(seed, i, k);
                        current.api.store(i, Ordering::SeqCst);
                        current.case.store(cs, Ordering::SeqCst);
                        current
                            .started_us
                            .store(run_start.elapsed().as_micros() as u64, Ordering::SeqCst);
                        current.busy.store(true, Ordering::SeqCst);
                        let (out, ms) = run_one(api, &fx, cs);
                        current.busy.store(false, Ordering::SeqCst);
                        s.calls += 1;
                        s.max_ms = s.max_ms.max(ms);
                        let note = |s: &mut Stats, what: String| {
                            if s.examples.len() < show {
                                s.examples.push(format!("case {cs}: {what}"));
                            }
                        };
                        if ms > slow_ms {
                            s.slow += 1;
                            note(&mut s, format!("slow ({ms:.0} ms)"));
                        }
                        match out {
                            Ok(Outcome::Ok) => {}
                            Ok(Outcome::Err) => s.errors += 1,
                            Ok(Outcome::NonFinite(m)) => {
                                s.non_finite += 1;
                                note(&mut s, format!("non-finite: {m}"));
                            }
                            Ok(Outcome::Wrong(m)) => {
                                s.wrong += 1;
                                note(&mut s, format!("wrong: {m}"));
                            }
                            Err(p) => {
                                s.panics += 1;
                                note(&mut s, format!("panic: {}", panic_message(&*p)));
                            }
                        }
                    }
                    stats.lock().map(|mut v| v[i] = s).ok();
                }
                done.store(true, Ordering::SeqCst);
            })?
    };

    // Watchdog.
    let hang_us = args.hang_ms * 1000;
    while !done.load(Ordering::SeqCst) {
        std::thread::sleep(Duration::from_millis(100));
        if current.busy.load(Ordering::SeqCst) {
            let started = current.started_us.load(Ordering::SeqCst);
            let now = run_start.elapsed().as_micros() as u64;
            if now.saturating_sub(started) > hang_us && current.busy.load(Ordering::SeqCst) {
                let api = names[current.api.load(Ordering::SeqCst)];
                let case = current.case.load(Ordering::SeqCst);
                println!(
                    "HANG: {api} case {case} has run for more than {} ms \
                     (replay: trust-fuzz --only '{api}' --replay {case})",
                    args.hang_ms
                );
                if let Ok(stats) = stats.lock() {
                    print_table(&names, &stats, args.seed, run_start);
                }
                std::process::exit(3);
            }
        }
    }
    worker
        .join()
        .map_err(|_| anyhow::anyhow!("worker thread died"))?;

    let stats = stats.lock().map_err(|_| anyhow::anyhow!("poisoned"))?;
    Ok(print_table(&names, &stats, args.seed, run_start))
}

/// Prints the per-API table and the failing examples; returns the number of bad calls.
fn print_table(names: &[&str], stats: &[Stats], seed: u64, run_start: Instant) -> u64 {
    println!(
        "{:<38} {:>9} {:>9} {:>7} {:>10} {:>6} {:>6} {:>9}",
        "api", "calls", "errors", "panics", "non-finite", "wrong", "slow", "max ms"
    );
    let mut bad = 0u64;
    let mut total = Stats::default();
    for (name, s) in names.iter().zip(stats.iter()) {
        println!(
            "{:<38} {:>9} {:>9} {:>7} {:>10} {:>6} {:>6} {:>9.1}",
            name, s.calls, s.errors, s.panics, s.non_finite, s.wrong, s.slow, s.max_ms
        );
        total.calls += s.calls;
        total.errors += s.errors;
        total.panics += s.panics;
        total.non_finite += s.non_finite;
        total.wrong += s.wrong;
        total.slow += s.slow;
        total.max_ms = total.max_ms.max(s.max_ms);
        bad += s.panics + s.non_finite + s.wrong + s.slow;
    }
    println!(
        "{:<38} {:>9} {:>9} {:>7} {:>10} {:>6} {:>6} {:>9.1}",
        "TOTAL",
        total.calls,
        total.errors,
        total.panics,
        total.non_finite,
        total.wrong,
        total.slow,
        total.max_ms
    );
    println!(
        "seed {}, {:.1} s wall",
        seed,
        run_start.elapsed().as_secs_f64()
    );
    for (name, s) in names.iter().zip(stats.iter()) {
        for e in &s.examples {
            println!("  {name}: {e}");
        }
    }
    bad
}
