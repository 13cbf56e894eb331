//! # trust-manager — multi-branch spatio-temporal trajectory manager (not built yet)
//!
//! This crate will hold Algorithm 1 of the paper (Sec. III-A, "Incremental Planning of TRUST-Planner"):
//! a priority queue of up to N homotopy-distinct trajectory branches, marched, replanned and explored
//! every cycle. It is generic over the three traits of `trust-core` and is filled by the manager issue;
//! today it exports nothing, so that nothing pretends to work.
#![warn(missing_docs)]
