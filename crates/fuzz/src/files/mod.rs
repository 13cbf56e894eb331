//! The file groups (issue 32, item 6): structure-aware mutations of the files the tools read —
//! scenarios, the CSV tracks and points files they name, and run logs — through the library entry
//! points of `trust-sim validate`, `run` (its set-up), `audit`, `replay` and `export`.
//!
//! | group | mutates | entry points | oracles beyond no panic / abort / hang and readable messages |
//! |---|---|---|---|
//! | `files::scenario` | corpus scenarios: numbers at the scale policy's edges, types swapped, keys and tables deleted, duplicated or spliced from other files, features added at their edges, special paths, bytes | `load_checked`, [`scenario::run_set_up`] | validate ⇔ run sets up, same message when both refuse |
//! | `files::track` | the pedestrians' CSV tracks, row by row and byte by byte, and the `file` names | idem | idem |
//! | `files::points` | a scenario's points file and its `path` | idem | idem |
//! | `files::log` | corpus logs flown at start-up: JSON edits, lines, counts, points file and its name, bytes | audit (±`--cycles`), `RunLog::read`, replay, export | the readers agree |
//! | `files::tamper` | one tamper per log | audit | flagged as [`log`]'s table says |
//!
//! **Isolation.** Each group runs in worker processes — this binary re-executed with
//! `--worker GROUP` — under an address-space limit (`--mem-mb`, set by `sh -c 'ulimit -v'`, so no
//! unsafe code): an allocation the limit refuses aborts the worker, not the run. A worker writes
//! `@@S k` before case `k` and `@@R k …` after it; the supervisor ([`worker::run_group`]) names the
//! case that aborted (with the worker's last words on standard error) or hung (no `@@R` within
//! `--hang-ms`: the worker is killed), counts it, and starts a new worker after it. Every case
//! is reproducible alone: `trust-fuzz --only GROUP --replay SEED [--keep DIR]`.

pub mod corpus;
mod log;
pub mod mutate;
pub mod readable;
mod scenario;
pub mod worker;

use std::path::Path;

use corpus::{CaseDir, Corpus, ScenarioBase};
use mutate::Rng;

/// What a case found beyond an ordinary answer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Flag {
    /// An oracle violated (a tamper not flagged as required).
    Wrong,
    /// A message a person cannot read ([`readable::problem`]).
    Unreadable,
    /// Two entry points that must agree do not (validate and run; the log readers).
    Disagree,
}

impl Flag {
    /// The name on the worker's protocol and in reports.
    pub fn name(self) -> &'static str {
        match self {
            Flag::Wrong => "wrong",
            Flag::Unreadable => "unreadable",
            Flag::Disagree => "disagree",
        }
    }
}

/// What one case did.
#[derive(Debug, Default)]
pub struct Verdict {
    /// The entry points accepted the file (validated; a log the audit passes).
    pub accepted: bool,
    /// Validated, but its map is beyond the build budget: not set up.
    pub heavy: bool,
    /// Oracle violations, with what happened.
    pub flags: Vec<(Flag, String)>,
    /// What the case did to the file (for `--replay`).
    pub note: String,
}

impl Verdict {
    /// Records a violation.
    pub fn flag(&mut self, flag: Flag, detail: String) {
        self.flags.push((flag, detail));
    }

    /// Runs the readability oracle on `message` (a reader of `input`).
    pub fn readable(&mut self, message: &str, input: &str) {
        if let Some(p) = readable::problem(message, input) {
            let head: String = message.chars().take(300).collect();
            self.flag(Flag::Unreadable, format!("{p}: {head}"));
        }
    }
}

/// What every case of a worker shares.
pub struct Ctx {
    /// The files mutated.
    pub corpus: Corpus,
    /// Validated scenarios with more ESDF voxels than this are not set up (heavy).
    pub max_voxels: f64,
}

impl Ctx {
    /// Loads the corpus: the repository's scenarios and tracks, and the logs flown into `base`
    /// ([`prepare`]).
    ///
    /// # Errors
    /// A corpus file that cannot be read.
    pub fn load(base: &Path, max_voxels: f64) -> anyhow::Result<Ctx> {
        let root = corpus::repo_root();
        let mut logs = Vec::new();
        if base.is_dir() {
            let mut dirs: Vec<_> = std::fs::read_dir(base)?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.join("run.jsonl").is_file())
                .collect();
            dirs.sort();
            for d in dirs {
                let text = std::fs::read_to_string(d.join("run.jsonl"))?;
                logs.push(corpus::BaseLog {
                    name: d
                        .file_name()
                        .unwrap_or_default()
                        .to_string_lossy()
                        .into_owned(),
                    lines: text.lines().map(str::to_string).collect(),
                    points: std::fs::read(d.join("static_points.xyz")).ok(),
                });
            }
        }
        Ok(Ctx {
            corpus: Corpus {
                scenarios: corpus::load_scenarios(&root)?,
                tracks: corpus::load_tracks(&root)?,
                points: corpus::points_file(),
                logs,
            },
            max_voxels,
        })
    }

    /// A corpus scenario, drawn by weight.
    pub fn pick_scenario(&self, rng: &mut Rng) -> &ScenarioBase {
        let total: u32 = self.corpus.scenarios.iter().map(|s| s.weight).sum();
        let mut r = mutate::pick(rng, total.max(1) as usize) as u32;
        for s in &self.corpus.scenarios {
            if r < s.weight {
                return s;
            }
            r -= s.weight;
        }
        &self.corpus.scenarios[0]
    }
}

/// Flies the corpus logs into `base` and checks that each passes the audit untouched.
///
/// # Errors
/// A corpus scenario that does not fly, or a log the audit does not pass.
pub fn prepare(base: &Path) -> anyhow::Result<()> {
    let scenarios = corpus::load_scenarios(&corpus::repo_root())?;
    let logs = corpus::generate_logs(&scenarios, base)?;
    log::check_bases(&logs, base)
}

/// One file group.
pub struct FileGroup {
    /// `files::…`, selected by `--only`.
    pub name: &'static str,
    /// Relative share of the cases (with the API groups' weights).
    pub weight: u32,
    /// Whether its cases read the corpus logs ([`prepare`] first).
    pub needs_logs: bool,
    /// One case.
    pub run: fn(&Ctx, &mut Rng, &CaseDir) -> Verdict,
}

/// The harness's own check, selected only by name (`--only files::selftest`, weight 0): a case
/// draws one of four: an ordinary answer, a panic, an allocation beyond any memory limit (an
/// abort), or a sleep past the hang limit.
fn selftest(_: &Ctx, rng: &mut Rng, _: &CaseDir) -> Verdict {
    use rand::Rng as _;
    match rng.random_range(0..4) {
        1 => panic!("selftest panic"),
        2 => {
            // 1 TiB, which no limit allows (black_box: the optimizer would drop it).
            let v: Vec<u8> = std::hint::black_box(Vec::with_capacity(1 << 40));
            Verdict {
                accepted: std::hint::black_box(v.capacity()) > 0,
                ..Verdict::default()
            }
        }
        3 => {
            std::thread::sleep(std::time::Duration::from_secs(3600));
            Verdict::default()
        }
        _ => Verdict {
            accepted: true,
            ..Verdict::default()
        },
    }
}

/// Every file group, in report order.
pub fn groups() -> Vec<FileGroup> {
    vec![
        FileGroup {
            name: "files::scenario",
            weight: 240,
            needs_logs: false,
            run: scenario::scenario_case,
        },
        FileGroup {
            name: "files::track",
            weight: 80,
            needs_logs: false,
            run: scenario::track_case,
        },
        FileGroup {
            name: "files::points",
            weight: 50,
            needs_logs: false,
            run: scenario::points_case,
        },
        FileGroup {
            name: "files::log",
            weight: 120,
            needs_logs: true,
            run: log::log_case,
        },
        FileGroup {
            name: "files::tamper",
            weight: 110,
            needs_logs: true,
            run: log::tamper_case,
        },
        FileGroup {
            name: "files::selftest",
            weight: 0,
            needs_logs: false,
            run: selftest,
        },
    ]
}
