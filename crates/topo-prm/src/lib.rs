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
//! (`cargo run --release -p trust-topo-prm --example prm_efficiency -- --obstacles 10 --trials 50`);
//! the criterion benches are in `benches/topo.rs`. Its headline counts distinct *valid* paths (clear
//! of every PDC, judged by one `uvd+pdc` checker for both planners; see the example's docs, which
//! also define the `raw` and spatio-temporal `st` variants). One run, 50 scenes per `K`, seed 1, on
//! the shared, loaded 2-core development machine (times vary by up to ±30 % between runs, ratios by
//! about ±5 %). V-PRM returns exactly the paths it returned before the speed-ups below.
//!
//! | K | V-PRM valid distinct / ms / per ms | DEV-PRM valid distinct / ms / per ms | ratio | raw ratio | st ratio |
//! |---|---|---|---|---|---|
//! | 2 | 0.92 / 0.91 / 1.013 | 1.16 / 0.20 / 5.932 | 5.86 | 4.90 | 5.02 |
//! | 5 | 0.70 / 1.88 / 0.372 | 1.56 / 0.51 / 3.042 | 8.18 | 3.82 | 5.55 |
//! | 10 | 0.52 / 2.05 / 0.253 | 2.12 / 0.95 / 2.237 | 8.83 | 2.39 | 4.23 |
//! | 15 | 0.44 / 2.14 / 0.206 | 2.62 / 1.54 / 1.706 | 8.29 | 1.52 | 3.75 |
//! | 20 | 0.34 / 2.15 / 0.158 | 2.74 / 2.05 / 1.334 | 8.43 | 0.98 | 3.04 |
//!
//! (Paper, K = 10: DEV-PRM 0.338, V-PRM 0.186 paths/ms, ratio 1.82.) DEV-PRM's lead comes from
//! paths that avoid where the obstacles will be (V-PRM's mostly do not, hence its low valid counts)
//! and from a roadmap that stops when it stalls ([`DevPrmParams::stall_samples`]: about 250–700
//! samples instead of V-PRM's fixed 2000). Both planners share the UVD test of the roadmap, which
//! [`gjk`] separation makes about 1.5–2× faster without changing any answer.
//!
//! Every frontend validates its query ([`check_query`]): bad numbers give
//! [`trust_core::PlanError::InvalidInput`], a start or goal outside the map
//! [`trust_core::PlanError::OutOfBounds`], inside a static obstacle
//! [`trust_core::PlanError::InCollision`]. All randomness comes from the `rng` argument; with a sample
//! budget that binds before the time budget the same seed gives the same paths. Time budgets use the
//! monotonic clock.
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
//!
//! # Changelog
//!
//! - `ggs::ggs_radius` is gone: the GGS radius is `trust_core::guidance_radius` (clamped at 0,
//!   shared with UTF-MINCO); `straight::straight_end` is a re-export of
//!   `trust_core::straight_end` (shared with the manager's straight guide).
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
pub use vprm::{Vprm, VprmParams};
