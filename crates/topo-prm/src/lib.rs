//! # trust-topo-prm — topological path frontends and homotopy checkers
//!
//! The path-planning half of TRUST-Planner's hierarchy (paper Sec. III-A and III-B): frontends that
//! return several homotopy-distinct guide paths for the trajectory backend, and the checkers that
//! decide whether two paths or trajectories are in the same class.
//!
//! | item | what | paper |
//! |---|---|---|
//! | [`DevPrm`] | DEV-PRM: V-PRM + predictive directional cones + obstacle-aware samples + goal guidance surface, beam search | Sec. III-B, Algorithm 2, eq. PDC |
//! | [`Vprm`] | Fast-Planner's visibility PRM (the E1 comparison) | Sec. IV-A |
//! | [`StraightLine`] | baseline 1: straight guide truncated to the horizon | Sec. IV-D |
//! | [`SparseAStar`] | baseline 2: one shortest path by heading-limited A* | Sec. IV-D |
//! | [`Uvd`], [`uvd::equivalent`] | uniform visibility deformation for paths (optionally seeing PDCs) | Sec. III-A (its ancestor) |
//! | [`Tvd`], [`tvd::equivalent`] | temporal visibility deformation for trajectories | Sec. III-A |
//! | [`scenes::random_dynamic_scene`] | the random scenes of experiment E1 | Sec. IV-A |
//! | [`gjk::separated`] | GJK separation test of convex sets (clears whole ranges of UVD chords) | — |
//!
//! Use a frontend through [`trust_core::PathFrontend`] and a checker through
//! [`trust_core::HomotopyChecker`]; the building blocks (roadmap, searches, shortcut, selection,
//! visibility, sampling frame) are public modules so that a variant can be assembled from them. The
//! predictive directional cones themselves are `trust_predict::Pdc`, shared with every other user.
//!
//! Experiment E1 (paper Fig. Sim-A-1-1(c)) is the example `prm_efficiency`
//! (`cargo run --release -p trust-topo-prm --example prm_efficiency -- --obstacles 10 --trials 50`,
//! or `cargo xtask experiment e1`); the criterion benches are in `benches/topo.rs`. Its headline
//! counts distinct *valid* paths (clear of every PDC, judged by one `uvd+pdc` checker for both
//! planners; the example's docs define the `raw` and spatio-temporal `st` variants). Why DEV-PRM's
//! sampling box, cone horizon and stopping rule differ from Fast-Planner's, with the measured E1
//! table: `docs/decisions/0013-dev-prm-box-and-cone-horizon.md`.
//!
//! Every frontend validates its query ([`check_query`]): bad numbers give
//! [`trust_core::PlanError::InvalidInput`], a start or goal outside the map
//! [`trust_core::PlanError::OutOfBounds`], inside a static obstacle
//! [`trust_core::PlanError::InCollision`]. All randomness comes from the `rng` argument. DEV-PRM and
//! V-PRM stop on a work budget (`budget_ms · work_per_ms` units of estimated work, [`QueryWork`]),
//! so the same seed gives the same paths on any machine, and also on the monotonic clock unless
//! `wall_clock_budget` is off.
//!
//! ```
//! use rand::SeedableRng;
//! use trust_core::{PathFrontend, Rng, Scene};
//! use trust_topo_prm::{DevPrm, scenes};
//!
//! let mut rng = Rng::seed_from_u64(1);
//! let world = scenes::random_dynamic_scene(5, &scenes::SceneParams::default(), &mut rng)?;
//! let scene = Scene::new(&world.map, &world.forecasts, 0.0)?;
//! let result = DevPrm::default().search(&world.query, &scene, &mut rng)?;
//! for path in &result.paths {
//!     assert_eq!(path.start(), world.query.start.p);
//! }
//! # Ok::<(), trust_core::PlanError>(())
//! ```
#![warn(missing_docs)]

pub mod astar;
pub mod devprm;
pub mod ggs;
pub mod gjk;
mod prm;
pub mod ranges;
pub mod roadmap;
pub mod sampling;
pub mod scenes;
pub mod search;
pub mod select;
pub mod shortcut;
pub mod straight;
pub mod tvd;
pub mod uvd;
pub mod visibility;
pub mod vprm;

pub use astar::{SparseAStar, SparseAStarParams};
pub use devprm::{DevPrm, DevPrmParams};
pub use prm::{COINCIDENT_M, check_query};
pub use straight::StraightLine;
pub use tvd::{Tvd, TvdParams};
pub use uvd::{Uvd, UvdParams};
pub use visibility::QueryWork;
pub use vprm::{Vprm, VprmParams};
