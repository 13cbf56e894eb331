//! # trust-route — a global route on the known static map for TRUST-Planner
//!
//! The paper's local planner (Sec. III: DEV-PRM, the GGS, the MINCO back end and the terminal cost
//! H_s) aims at one goal point within its planning horizon. Aiming at the final goal in a straight
//! line fails in front of a wall wider than the sampling box or inside a cul-de-sac; this crate
//! supplies the point to aim at instead: where a collision-free route on the known static map leaves
//! the planning horizon ([`GlobalRoute::local_goal`]). The paper has no such route; it is this
//! project's addition (issue 19).
//!
//! * [`RoutePlanner`] with [`RouteParams`] plans a [`GlobalRoute`] from a start to a goal on a
//!   [`trust_geometry::StaticMap`] (analytic shapes and/or voxel ESDF), for a vehicle radius: in one
//!   call ([`RoutePlanner::plan`]) or a slice of work at a time ([`RoutePlanner::start_search`] →
//!   [`RouteSearch::advance`] → [`RouteProgress`]), which ends in a route, a proved verdict that the
//!   goal cannot be reached ([`Unreachable`], with its [`UnreachableCause`] and a route to the
//!   reachable point nearest the goal), or a typed failure without a verdict.
//! * [`GlobalRoute`] is the polyline with the queries a mission manager needs:
//!   [`GlobalRoute::local_goal`], [`GlobalRoute::progress`], [`GlobalRoute::remaining_length`],
//!   [`GlobalRoute::first_sharp_turn`], [`GlobalRoute::first_blocked`] / [`GlobalRoute::is_blocked`].
//!
//! How: the straight line if it is clear; else weighted A\* ([`DEFAULT_HEURISTIC_WEIGHT`]) on a
//! 26-connected grid whose occupancy is computed lazily, coarse to fine
//! ([`RouteParams::coarse_factor`], [`RouteParams::refine_max_cells`]); then a shortcut. Every edge
//! is clear at the inflated clearance `c`, a slot `2c + h` wide stays open, and unreachability is
//! proved by relaxed floods (an over-approximation of the free space) beside the A\*, first on a
//! layer twice as coarse, then on the fine one. [`RouteSearch::advance`] does at most its
//! budget of units of work (a distance query, a line-of-sight query or an expansion); the answer does
//! not depend on the slicing and no clock is read. The reasoning, the proofs, the measured costs and
//! the rejected alternatives (JPS, Theta\*): `docs/decisions/0003-route-searched-in-slices.md` and
//! `0019-route-grid-and-verdicts.md`; timings: `cargo run --release -p trust-route --example
//! route_timing`.
//!
//! Use it before the first planning cycle and again when the vehicle stalls or the route is found
//! blocked (the manager's `Router` does). It depends only on `trust-geometry`; invalid input is a typed
//! [`RouteError`] naming the field, never a panic or a hang.
//!
//! ```
//! use trust_geometry::{AaBox, Aabb, StaticMap, Vec3};
//! use trust_route::{RouteParams, RoutePlanner, RouteProgress};
//!
//! let bounds = Aabb::new(Vec3::zeros(), Vec3::new(60.0, 40.0, 10.0))?;
//! let wall = AaBox::new(Vec3::new(20.0, 5.0, 0.0), Vec3::new(21.0, 35.0, 10.0))?;
//! let map = StaticMap::from_shapes(bounds, vec![wall.into()])?;
//! let (start, goal) = (Vec3::new(2.0, 20.0, 3.0), Vec3::new(58.0, 20.0, 3.0));
//! let planner = RoutePlanner::new(RouteParams::default())?;
//! let mut search = planner.start_search(&map, &start, &goal, 0.3)?;
//! let route = loop {
//!     match search.advance(&map, 2_500) {
//!         RouteProgress::Pending => continue, // next planning cycle
//!         RouteProgress::Found(route) => break route,
//!         other => panic!("{other:?}"),
//!     }
//! };
//! let s = route.project_after(&start, 0.0)?.s; // progress that never goes back
//! let aim = route.local_goal_from(s, 10.0)?; // horizon = v_max · horizon_s
//! assert!((aim.point - route.point_at(s)).norm() <= 10.0 + 1e-9);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(missing_docs)]

mod error;
mod grid;
mod params;
mod planner;
mod route;
pub mod scenes;
mod search;

/// The public vector type: `nalgebra::Vector3<f64>` (as in `trust-geometry`).
pub type Vec3 = nalgebra::Vector3<f64>;

pub use error::{Endpoint, Readable, RouteError, RouteErrorKind, UnreachableCause};
pub use params::{DEFAULT_HEURISTIC_WEIGHT, RouteParams};
pub use planner::RoutePlanner;
pub use route::{Blocked, GlobalRoute, Projection, RoutePoint};
pub use search::{RouteProgress, RouteSearch, Unreachable};
