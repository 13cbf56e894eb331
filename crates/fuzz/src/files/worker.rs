//! Worker processes and their supervisor (see [`super`]'s module docs for the protocol).

use std::collections::VecDeque;
use std::io::{BufRead as _, BufReader, Write as _};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::mpsc::{Receiver, RecvTimeoutError, channel};
use std::time::{Duration, Instant};

use anyhow::{Context as _, Result, bail};
use rand::SeedableRng as _;

use super::corpus::CaseDir;
use super::mutate::Rng;
use super::{Ctx, FileGroup, groups};

/// Case seeds of file groups are derived from `FILE_GROUP_BASE + group index` (apart from the
/// API groups' indices).
const FILE_GROUP_BASE: usize = 1000;

/// What a worker runs.
#[derive(Debug, Clone)]
pub struct Plan {
    /// The group's name.
    pub group: String,
    /// First case index.
    pub from: u64,
    /// One past the last.
    pub to: u64,
    /// The run's seed.
    pub seed: u64,
    /// The worker's folder (emptied).
    pub work: PathBuf,
    /// Where the corpus logs are.
    pub base: PathBuf,
    /// The heavy threshold (ESDF voxels).
    pub max_voxels: f64,
}

/// The case seed of case `k` of file group `index`.
pub fn file_case_seed(run_seed: u64, index: usize, k: u64) -> u64 {
    crate::case_seed(run_seed, FILE_GROUP_BASE + index, k)
}

fn find(name: &str) -> Result<(usize, FileGroup)> {
    groups()
        .into_iter()
        .enumerate()
        .find(|(_, g)| g.name == name)
        .with_context(|| format!("no file group {name}"))
}

/// A line for the protocol: no tabs or line ends, at most 400 characters.
fn clean(s: &str) -> String {
    let s: String = s
        .chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .take(400)
        .collect();
    s
}

fn say(line: &str) -> Result<()> {
    let mut out = std::io::stdout();
    writeln!(out, "{line}")?;
    out.flush()?;
    Ok(())
}

/// Runs one case in-process; the verdict, or the panic's message.
pub fn run_case(
    group: &FileGroup,
    ctx: &Ctx,
    dir: &CaseDir,
    seed: u64,
) -> (std::thread::Result<super::Verdict>, f64) {
    let t0 = Instant::now();
    let mut rng = Rng::seed_from_u64(seed);
    let r = catch_unwind(AssertUnwindSafe(|| (group.run)(ctx, &mut rng, dir)));
    (r, t0.elapsed().as_secs_f64() * 1e3)
}

/// The worker: runs the plan's cases, writing the protocol's lines.
///
/// # Errors
/// The corpus or the case folder cannot be set up, or standard output is closed.
pub fn worker_main(plan: &Plan) -> Result<()> {
    let (index, group) = find(&plan.group)?;
    let ctx = Ctx::load(&plan.base, plan.max_voxels)?;
    let dir = CaseDir::create(&plan.work, &ctx.corpus)?;
    for k in plan.from..plan.to {
        say(&format!("@@S\t{k}"))?;
        let (r, ms) = run_case(&group, &ctx, &dir, file_case_seed(plan.seed, index, k));
        let (accepted, heavy) = match r {
            Ok(v) => {
                for (flag, detail) in &v.flags {
                    say(&format!("@@F\t{k}\t{}\t{}", flag.name(), clean(detail)))?;
                }
                (v.accepted, v.heavy)
            }
            Err(p) => {
                say(&format!(
                    "@@F\t{k}\tpanic\t{}",
                    clean(&crate::panic_message(&*p))
                ))?;
                (false, false)
            }
        };
        say(&format!(
            "@@R\t{k}\t{}\t{}\t{ms:.3}",
            u8::from(accepted),
            u8::from(heavy)
        ))?;
    }
    Ok(())
}

/// One group's counts.
#[derive(Debug, Clone, Default)]
pub struct GroupStats {
    /// Cases run (aborted and hung ones included).
    pub cases: u64,
    /// Accepted (validated; logs the audit passes).
    pub accepted: u64,
    /// Validated but not set up (map beyond `--max-voxels`).
    pub heavy: u64,
    /// Panics.
    pub panics: u64,
    /// Aborts (the worker died: an allocation beyond the memory limit, a stack overflow, …).
    pub aborts: u64,
    /// Hangs (killed after `--hang-ms`).
    pub hangs: u64,
    /// Oracle violations.
    pub wrong: u64,
    /// Unreadable messages.
    pub unreadable: u64,
    /// Disagreements between entry points.
    pub disagree: u64,
    /// Slowest case (ms) and its seed.
    pub slowest: (f64, u64),
    /// Examples of failures, per kind.
    pub examples: Vec<(&'static str, String)>,
}

impl GroupStats {
    /// Cases with a failure of any kind.
    pub fn bad(&self) -> u64 {
        self.panics + self.aborts + self.hangs + self.wrong + self.unreadable + self.disagree
    }

    fn note(&mut self, kind: &'static str, seed: u64, detail: &str, show: usize) {
        if self.examples.iter().filter(|(k, _)| *k == kind).count() < show {
            self.examples
                .push((kind, format!("case {seed}: {kind}: {detail}")));
        }
    }

    /// Adds `other`'s counts.
    pub fn merge(&mut self, other: &GroupStats, show: usize) {
        self.cases += other.cases;
        self.accepted += other.accepted;
        self.heavy += other.heavy;
        self.panics += other.panics;
        self.aborts += other.aborts;
        self.hangs += other.hangs;
        self.wrong += other.wrong;
        self.unreadable += other.unreadable;
        self.disagree += other.disagree;
        if other.slowest.0 > self.slowest.0 {
            self.slowest = other.slowest;
        }
        for (kind, e) in &other.examples {
            if self.examples.iter().filter(|(k, _)| k == kind).count() < show {
                self.examples.push((kind, e.clone()));
            }
        }
    }
}

/// How the supervisor runs the workers.
#[derive(Debug, Clone)]
pub struct Options {
    /// The run's seed.
    pub seed: u64,
    /// A case without an answer after this long is a hang (ms).
    pub hang_ms: u64,
    /// Address-space limit of a worker (MiB); 0: none.
    pub mem_mb: u64,
    /// Heavy threshold (ESDF voxels).
    pub max_voxels: f64,
    /// Corpus logs.
    pub base: PathBuf,
    /// Workers' folders go under it.
    pub work: PathBuf,
    /// Examples printed per kind and group.
    pub show: usize,
    /// Parallel workers per group.
    pub jobs: usize,
}

enum Msg {
    Line(String),
    Eof,
}

/// A running worker: its process, its lines, and the reader of its last words (the last lines
/// of its standard error, complete once the process is gone).
struct Running {
    child: Child,
    lines: Receiver<Msg>,
    stderr: Option<std::thread::JoinHandle<VecDeque<String>>>,
}

fn spawn(exe: &Path, plan: &Plan, mem_mb: u64) -> Result<Running> {
    let args: Vec<String> = vec![
        "--worker".into(),
        plan.group.clone(),
        "--from".into(),
        plan.from.to_string(),
        "--to".into(),
        plan.to.to_string(),
        "--seed".into(),
        plan.seed.to_string(),
        "--work".into(),
        plan.work.display().to_string(),
        "--base".into(),
        plan.base.display().to_string(),
        "--max-voxels".into(),
        plan.max_voxels.to_string(),
    ];
    let mut cmd = if mem_mb > 0 {
        // The shell sets the limit and becomes the worker (no unsafe pre_exec here).
        let mut c = Command::new("sh");
        c.arg("-c")
            .arg(format!("ulimit -v {} && exec \"$0\" \"$@\"", mem_mb * 1024))
            .arg(exe)
            .args(&args);
        c
    } else {
        let mut c = Command::new(exe);
        c.args(&args);
        c
    };
    // Its last words are the allocator's or the runtime's message, not a backtrace.
    let mut child = cmd
        .env("RUST_BACKTRACE", "0")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .with_context(|| format!("starting a worker ({})", exe.display()))?;
    let (tx, rx) = channel();
    let stdout = child.stdout.take().context("worker stdout")?;
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines() {
            match line {
                Ok(l) => {
                    if tx.send(Msg::Line(l)).is_err() {
                        return;
                    }
                }
                Err(_) => break,
            }
        }
        let _ = tx.send(Msg::Eof);
    });
    let mut err = child.stderr.take().context("worker stderr")?;
    let stderr = std::thread::spawn(move || {
        let mut tail = VecDeque::new();
        for line in BufReader::new(&mut err).lines() {
            let Ok(line) = line else { break };
            tail.push_back(clean(&line));
            if tail.len() > 8 {
                tail.pop_front();
            }
        }
        tail
    });
    Ok(Running {
        child,
        lines: rx,
        stderr: Some(stderr),
    })
}

/// The worker's last lines on standard error; call once it has exited (or been killed).
fn last_words(r: &mut Running) -> String {
    r.stderr
        .take()
        .and_then(|h| h.join().ok())
        .map(|t| t.into_iter().collect::<Vec<_>>().join(" | "))
        .unwrap_or_default()
}

fn describe(status: ExitStatus) -> String {
    #[cfg(unix)]
    {
        use std::os::unix::process::ExitStatusExt as _;
        if let Some(sig) = status.signal() {
            let name = match sig {
                6 => "SIGABRT",
                9 => "SIGKILL",
                11 => "SIGSEGV",
                7 => "SIGBUS",
                _ => "signal",
            };
            return format!("{name} ({sig})");
        }
    }
    status.to_string()
}

/// Runs cases `from..to` of `group` (index `index`) in workers, restarting after each abort or
/// hang.
fn run_range(
    exe: &Path,
    index: usize,
    group: &FileGroup,
    (from, to): (u64, u64),
    work: PathBuf,
    opts: &Options,
) -> Result<GroupStats> {
    let mut s = GroupStats::default();
    let hang = Duration::from_millis(opts.hang_ms);
    let mut next = from;
    while next < to {
        let plan = Plan {
            group: group.name.to_string(),
            from: next,
            to,
            seed: opts.seed,
            work: work.clone(),
            base: opts.base.clone(),
            max_voxels: opts.max_voxels,
        };
        let mut w = spawn(exe, &plan, opts.mem_mb)?;
        let mut current: Option<(u64, Instant)> = None;
        // The last line read (start-up before the first).
        let mut last = Instant::now();
        let seed_of = |k: u64| file_case_seed(opts.seed, index, k);
        loop {
            let wait = match current {
                Some((_, t0)) => hang.saturating_sub(t0.elapsed()),
                // Between cases, and at start-up (loading the corpus): a minute more.
                None => (hang + Duration::from_secs(60)).saturating_sub(last.elapsed()),
            };
            match w.lines.recv_timeout(wait) {
                Ok(Msg::Line(line)) => {
                    last = Instant::now();
                    let f: Vec<&str> = line.splitn(5, '\t').collect();
                    let k = f.get(1).and_then(|x| x.parse::<u64>().ok());
                    match (f.first().copied(), k) {
                        (Some("@@S"), Some(k)) => current = Some((k, Instant::now())),
                        (Some("@@F"), Some(k)) => {
                            let kind = f.get(2).copied().unwrap_or("");
                            let detail = f.get(3).copied().unwrap_or("");
                            let kind: &'static str = match kind {
                                "panic" => {
                                    s.panics += 1;
                                    "panic"
                                }
                                "wrong" => {
                                    s.wrong += 1;
                                    "wrong"
                                }
                                "unreadable" => {
                                    s.unreadable += 1;
                                    "unreadable"
                                }
                                _ => {
                                    s.disagree += 1;
                                    "disagree"
                                }
                            };
                            s.note(kind, seed_of(k), detail, opts.show);
                        }
                        (Some("@@R"), Some(k)) => {
                            s.cases += 1;
                            s.accepted += u64::from(f.get(2) == Some(&"1"));
                            s.heavy += u64::from(f.get(3) == Some(&"1"));
                            let ms: f64 = f.get(4).and_then(|x| x.parse().ok()).unwrap_or(0.0);
                            if ms > s.slowest.0 {
                                s.slowest = (ms, seed_of(k));
                            }
                            next = k + 1;
                            current = None;
                        }
                        _ => {}
                    }
                }
                Ok(Msg::Eof) => {
                    let status = w.child.wait()?;
                    match current {
                        Some((k, _)) => {
                            s.cases += 1;
                            s.aborts += 1;
                            let words = last_words(&mut w);
                            s.note(
                                "abort",
                                seed_of(k),
                                &format!("the worker died: {}; {words}", describe(status)),
                                opts.show,
                            );
                            next = k + 1;
                        }
                        None if next < to => bail!(
                            "a {} worker ended without running case {next}: {}; {}",
                            group.name,
                            describe(status),
                            last_words(&mut w)
                        ),
                        None => {}
                    }
                    break;
                }
                Err(RecvTimeoutError::Timeout | RecvTimeoutError::Disconnected) => {
                    // Ours to end: the worker this supervisor started.
                    let _ = w.child.kill();
                    let _ = w.child.wait();
                    match current {
                        Some((k, _)) => {
                            s.cases += 1;
                            s.hangs += 1;
                            s.note(
                                "hang",
                                seed_of(k),
                                &format!("no answer within {} ms; killed", opts.hang_ms),
                                opts.show,
                            );
                            next = k + 1;
                        }
                        None => bail!(
                            "a {} worker was silent for a minute between cases: {}",
                            group.name,
                            last_words(&mut w)
                        ),
                    }
                    break;
                }
            }
        }
    }
    Ok(s)
}

/// Runs `cases` cases of file group `index` in `opts.jobs` parallel workers.
///
/// # Errors
/// A worker that cannot be started or dies outside a case.
pub fn run_group(exe: &Path, index: usize, cases: u64, opts: &Options) -> Result<GroupStats> {
    let list = groups();
    let group = &list[index];
    let jobs = (opts.jobs.max(1) as u64).min(cases.max(1));
    let chunk = cases.div_ceil(jobs);
    let results: Vec<Result<GroupStats>> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..jobs)
            .map(|j| {
                let range = (j * chunk, ((j + 1) * chunk).min(cases));
                let work = opts
                    .work
                    .join(format!("{}-{j}", group.name.replace("::", "-")));
                scope.spawn(move || run_range(exe, index, group, range, work, opts))
            })
            .collect();
        handles
            .into_iter()
            .map(|h| {
                h.join()
                    .unwrap_or_else(|_| bail!("a supervisor thread panicked"))
            })
            .collect()
    });
    let mut total = GroupStats::default();
    for r in results {
        total.merge(&r?, opts.show);
    }
    Ok(total)
}
