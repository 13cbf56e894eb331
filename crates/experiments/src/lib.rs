//! # trust-experiments — studies and experiments over closed-loop flights
//!
//! The last stage of the simulator's data path (paper Sec. IV-D and the ablations beyond it): runs
//! write records, this crate turns records into tables and figures. [`study`] flies a set of
//! planners and variants over seeds (`trust-sim ablate`, E4), in shards that merge by concatenating
//! their `runs.csv`, and writes `summary.json` and `report.md`; [`e3`] reproduces Table Sim-B-1
//! (the branches of one planning cycle); [`flight_plots`] draws the figures of one flight from its
//! run log. Errors are [`ExperimentError`]s naming the file, field and value.
#![warn(missing_docs)]

pub mod e3;
mod error;
pub mod flight_plots;
pub mod study;

pub use error::ExperimentError;
