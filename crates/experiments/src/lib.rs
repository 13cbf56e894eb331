//! # trust-experiments — studies and experiments over closed-loop flights
//!
//! The last stage of the simulator's data path (paper Sec. IV-D and the ablations beyond it): runs
//! write records, this crate turns records into tables and figures. [`study`] flies a set of
//! planners and variants over seeds (`trust-sim ablate`, E4), in shards that merge by concatenating
//! their `runs.csv`, and writes `summary.json` and `report.md`; [`e3`] reproduces Table Sim-B-1
//! (the branches of one planning cycle); [`e1`] and [`e2`] type the JSON printed by the E1 and E2
//! examples and write their reports; [`flight_plots`] draws the figures of one flight from its
//! run log. Errors are [`ExperimentError`]s naming the file, field and value.
//!
//! # Changelog
//!
//! - Issue 19: [`suite`] (`trust-sim suite`): every scenario file of a folder with K seeds, one
//!   table per class; the study's `Variant::Route`, and a study flies without the route otherwise;
//!   the flight plots draw the route.
//! - Moved out of `trust-sim` (issue 17): `trust_sim::{study, e3, flight_plots}` are
//!   `trust_experiments::{study, e3, flight_plots}`.
//! - `trust_sim::error::SimError` is split by stage; this crate's errors are [`ExperimentError`]s
//!   (wrapping `trust_world::WorldError`, `trust_flight::FlightError`, plotting and run-log errors).
//! - `study::RunRow::TIMING_COLUMNS` is removed: [`study::RunRow::timing_columns`] is a slice of
//!   [`study::RunRow::COLUMNS`], so the list is written once.
//! - [`study::stats::median`] is the 0.5-quantile of `trust_plot::quantile_sorted`: for an even
//!   count `a + 0.5 (b − a)` instead of `0.5 (a + b)` (the same value up to the last bits; it only
//!   summarizes timings).
//! - New [`e1`] and [`e2`] (issue 17): the E1/E2 reports that `xtask` assembled by JSON path lookups
//!   are typed here (`E1Row`, `E2Results`, with errors naming the field); same `report.md` bytes.
#![warn(missing_docs)]

pub mod e1;
pub mod e2;
pub mod e3;
mod error;
pub mod flight_plots;
pub mod study;
pub mod suite;

pub use error::ExperimentError;
