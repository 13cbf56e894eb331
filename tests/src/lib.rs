//! # trust-tests — workspace-level tests
//!
//! Holds the tests that span crates: the tidy rules of `ARCHITECTURE.md` (dependency direction, crate
//! docs, lint inheritance) in `tests/tidy.rs`, and end-to-end tests of the planner as later crates land.
//! It has no library code of its own; this file exists so the crate has a documented root.
#![warn(missing_docs)]
