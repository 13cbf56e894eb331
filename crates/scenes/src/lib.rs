//! # trust-scenes — the paper's experiment scenes, below the planners and the world
//!
//! The fixed scenes of experiment E2 (paper Sec. IV-B, Table Sim-A-2: [`e2::e2_static`],
//! [`e2::e2_dynamic`] and random scenes of the same kinds) and the obstacle distribution of E1's
//! random scenes (Sec. IV-A, [`e1`]), and MIT-ACL's dynamic forest ([`dynamic_forest`], a
//! benchmark of other planners: cubes on trefoil knots among pillars and bars). They are data, not planning: the optimizer's tests, benches
//! and examples fly them (`trust_minco::scenes` re-exports [`e2`]), DEV-PRM's E1 scenes start from
//! [`e1`], and the world's `e2-static` / `e2-dynamic` generators and random obstacle groups build
//! scenario worlds from them — without the world depending on a planner crate.
//!
//! Use it for a scene of the paper's experiments without the planner that was measured on it.
//!
//! ```
//! let case = trust_scenes::e2::e2_dynamic();
//! assert_eq!(case.forecasts.len(), 5);
//! assert!(case.map.shapes().is_empty());
//! ```
#![warn(missing_docs)]

pub mod dynamic_forest;
pub mod e1;
pub mod e2;
