//! # trust-sim — closed-loop simulator and experiment harness (not built yet)
//!
//! This crate will assemble the paper's baselines 1–3 and TRUST-Planner from the `trust-core` traits,
//! fly them in closed loop among maneuvering obstacles (paper Sec. IV-D), and write the reports of the
//! experiments. It is filled by the simulator and ablation issues; today it exports nothing, so that
//! nothing pretends to work.
#![warn(missing_docs)]

pub mod e3;
pub mod error;
pub mod flight_plots;
pub mod planner;
pub mod run;
pub mod scenario;
pub mod sensing;
pub mod study;
pub mod traffic;
pub mod world;
