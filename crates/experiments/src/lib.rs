//! # trust-experiments — studies and experiments over closed-loop flights
//!
//! The last stage of the simulator's data path (paper Sec. IV-D and the ablations beyond it): runs
//! write records, this crate turns records into tables and figures. [`study`] flies a set of
//! planners and variants over seeds (`trust-sim ablate`, E4), in shards that merge by concatenating
//! their `runs.csv`, and writes `summary.json` and `report.md`; [`suite`] flies every scenario file
//! of a folder with K seeds and writes one table per class (`trust-sim suite`); [`e3`] reproduces
//! Table Sim-B-1 (the branches of one planning cycle); [`e1`] and [`e2`] type the JSON printed by the
//! E1 and E2 examples and write their reports; [`flight_plots`] draws the figures of one flight from
//! its run log; [`forest`] flies MIT-ACL's dynamic-forest benchmark and scores it with the
//! peers' metrics (`trust-sim forest`). Errors are [`ExperimentError`]s naming the file, field and value.
//!
//! Use it to run or summarize a comparison (the `trust-sim` binary and `cargo xtask ablate` are thin
//! wrappers), or to read a study's outputs: [`study::read_runs_csv`] and the serde types of
//! `summary.json` ([`study::report::StudySummary`]). Summaries, reports and plots are functions of the
//! rows alone, which is why a merged sharded study equals a single run.
//!
//! ```
//! use trust_experiments::study::stats::wilson;
//!
//! // 4 arrivals in 4 trials: the 95 % Wilson interval is [51 %, 100 %].
//! let success = wilson(4, 4);
//! assert_eq!(success.rate, 1.0);
//! assert!((success.ci95_low - 0.51).abs() < 0.01 && success.ci95_high == 1.0);
//! ```
#![warn(missing_docs)]

pub mod e1;
pub mod e2;
pub mod e3;
mod error;
pub mod flight_plots;
pub mod forest;
pub mod study;
pub mod suite;

pub use error::ExperimentError;
