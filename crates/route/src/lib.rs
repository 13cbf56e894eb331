//! A global route on the known static map for TRUST-Planner.
//!
//! The paper's local planner (Sec. III: DEV-PRM, the GGS, the MINCO back end and the terminal cost
//! H_s) aims at one goal point within its planning horizon. Aiming at the final goal in a straight
//! line fails in front of a wall wider than the sampling box or inside a cul-de-sac; this crate
//! supplies the point to aim at instead: the place where a collision-free route on the known
//! static map leaves the planning horizon ([`GlobalRoute::local_goal`]). The paper has no such
//! route; it is this project's addition (issue 19).
//!
//! * [`RoutePlanner`] with [`RouteParams`] plans a [`GlobalRoute`] from a start to a goal on a
//!   [`trust_geometry::StaticMap`] (analytic shapes and/or voxel ESDF), for a vehicle radius.
//! * [`GlobalRoute`] is the polyline with its arc length and the queries a mission manager needs:
//!   [`GlobalRoute::local_goal`], [`GlobalRoute::progress`] (for a progress monitor),
//!   [`GlobalRoute::remaining_length`], [`GlobalRoute::first_sharp_turn`] (a corner to aim at
//!   before the local goal), [`GlobalRoute::first_blocked`] /
//!   [`GlobalRoute::is_blocked`] (for a re-route when the map changes).
//!
//! Use it once before the first planning cycle and again when the vehicle stalls or the route is
//! found blocked. It depends only on `trust-geometry`; every failure is a typed [`RouteError`]
//! naming the cap or the field, never a panic or a hang.
//!
//! # Algorithm and why
//!
//! 1. **Straight line first.** If the segment start → goal is clear at the inflated clearance `c`
//!    ([`StaticMap::segment_clear`](trust_geometry::StaticMap::segment_clear)), that is the
//!    route; no grid is built. Open worlds cost one line-of-sight query.
//! 2. **Weighted A\* on a 26-connected grid** over the map bounds, with the exact 3-D octile
//!    distance as heuristic (admissible, and exact in free space) times a weight of 1.2
//!    ([`DEFAULT_HEURISTIC_WEIGHT`]: the grid path is at most 1.2 × the shortest; plain A\*
//!    expands the wide plateaus of equal-cost octile paths, 70 times more cells on an E4 world). Occupancy is **lazy**: a cell's signed distance is computed
//!    the first time the search touches it and cached in one byte, so the cost is proportional to
//!    the cells the search visits, not to the map volume. A cell is free if its centre is at
//!    least `c + h·√3/2` from the obstacles (`h` the cell size): since the map's signed distance
//!    is 1-Lipschitz (exactly so for the analytic shapes, and to within the ESDF's interpolation
//!    error for voxels), every point of an edge between two free neighbours — within `h·√3/2`
//!    of one end — is then at least `c` from the obstacles. The route is collision-free at `c`
//!    without a line-of-sight query per edge.
//!    The search runs **coarse to fine** ([`RouteParams::coarse_factor`]): first on cells 4 times
//!    larger (a coarse free cell is farther from the obstacles, so its route is as safe), then on
//!    the fine grid when the coarse one finds nothing — or, for a fine grid of at most
//!    [`RouteParams::refine_max_cells`] cells (a room), always, keeping the shorter route: the
//!    coarse grid closes passages narrower than about `2(c + 4h·√3/2)`.
//! 3. **Shortcut.** From each kept vertex the route jumps to the farthest following vertex that
//!    a straight segment reaches with clearance `c` (checked with `segment_clear`), which
//!    removes the grid's 45° staircase; a shortcut is only taken when clear at `c`, so it never
//!    brings the route closer than the inflation.
//!
//! Alternatives considered. *JPS* prunes symmetric paths on uniform-cost grids but needs the
//! occupancy of whole rows for its jumps: eagerly evaluating an E4 grid (250 × 75 × 20 m, ~4 M
//! cells) costs seconds of distance queries, while lazy A* touches only what it expands. *Theta\**
//! and lazy Theta\* give any-angle paths directly but pay a line-of-sight query per expansion
//! (Theta\*: per neighbour); with analytic shapes each query is a BVH walk plus GJK, orders of
//! magnitude dearer than a cached byte, and the post-hoc shortcut recovers nearly all of the
//! any-angle gain on the building-sized obstacles the route is for. The route only has to point
//! the local planner the right way round obstacles; it need not be optimal.
//!
//! # Grid size, caps and memory (scale-free)
//!
//! The cell size is `h₀ = max(c / cells_per_clearance, esdf_voxel / 2)`, so it follows the
//! vehicle: an 8 × 6 × 3 m room with a 0.1 m radius gets `c = 0.15 m` and 0.075 m cells
//! (~340 k cells); a 250 × 75 × 20 m world with a 0.3 m radius gets `c = 0.45 m`, `h₀ = 0.225 m`,
//! coarsened to ≈ 0.36 m to stay under `max_cells = 4 M`. Coarsening stops at
//! `max_coarsening · h₀` ([`RouteError::TooManyCells`] past it). Memory is 13 bytes per cell
//! (cost, parent, state), zero-initialised so that the OS pages in only the touched part. The
//! search stops with [`RouteError::ExpansionCap`] past `max_expansions` and with
//! [`RouteError::Deadline`] past an optional deadline ([`RoutePlanner::plan_until`]).
//!
//! Cost (`cargo bench -p trust-route`, medians on a shared 2-core machine): an E4-like world
//! with 400 obstacles, 246 m start to goal, 25 ms; the same with a 30 m full-height wall across
//! the line, 238 ms; an 8 × 6 × 3 m room with thin pillars and a wall, radius 0.1 m, 165 ms.
//!
//! Ends: a start or goal inside the inflated obstacles joins the nearest free cell within
//! `snap_radius_factor · c` ([`RouteError::NoFreeCell`] otherwise); such a start makes the first
//! segment exempt from the clearance ([`GlobalRoute::start_inside_clearance`]), such a goal is
//! left out and the route ends at the free cell ([`GlobalRoute::goal_gap_m`]). An exhausted
//! search is [`RouteError::Unreachable`].
//!
//! # Use from a mission manager
//!
//! ```
//! use trust_geometry::{AaBox, Aabb, StaticMap, Vec3};
//! use trust_route::{RouteParams, RoutePlanner};
//!
//! let bounds = Aabb::new(Vec3::zeros(), Vec3::new(60.0, 40.0, 10.0))?;
//! let wall = AaBox::new(Vec3::new(20.0, 5.0, 0.0), Vec3::new(21.0, 35.0, 10.0))?;
//! let map = StaticMap::from_shapes(bounds, vec![wall.into()])?;
//! let (start, goal) = (Vec3::new(2.0, 20.0, 3.0), Vec3::new(58.0, 20.0, 3.0));
//! // Before the first cycle (and again after a stall or a blocked route):
//! let route = RoutePlanner::new(RouteParams::default())?.plan(&map, &start, &goal, 0.3)?;
//! // Every cycle: progress that never goes back, and the point to aim at.
//! let mut s = 0.0;
//! let position = start;
//! s = route.project_after(&position, s)?.s;
//! let aim = route.local_goal_from(s, 10.0)?; // horizon = v_max · horizon_s, say
//! assert!((aim.point - route.point_at(s)).norm() <= 10.0 + 1e-9);
//! // When the map changes: re-route if what lies ahead is blocked.
//! assert!(!route.is_blocked(&map, route.clearance_m() * 0.99, s)?);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Determinism: no clock is read unless a deadline is given, ties in the open list break by
//! cost then cell index, and no hash map is iterated: same input, same route.
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

pub use error::{Endpoint, Readable, RouteError, UnreachableCause};
pub use params::{DEFAULT_HEURISTIC_WEIGHT, RouteParams};
pub use planner::RoutePlanner;
pub use route::{Blocked, GlobalRoute, Projection, RoutePoint};
pub use search::{RouteProgress, RouteSearch, Unreachable};
