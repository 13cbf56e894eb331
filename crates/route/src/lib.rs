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
//!   [`trust_geometry::StaticMap`] (analytic shapes and/or voxel ESDF), for a vehicle radius:
//!   in one call ([`RoutePlanner::plan`]) or a slice of work at a time
//!   ([`RoutePlanner::start_search`] → [`RouteSearch::advance`] → [`RouteProgress`]), which
//!   ends in a route, a proved verdict that the goal cannot be reached ([`Unreachable`], with
//!   its [`UnreachableCause`] and a route to the reachable point nearest the goal), or a typed
//!   failure without a verdict.
//! * [`GlobalRoute`] is the polyline with its arc length and the queries a mission manager needs:
//!   [`GlobalRoute::local_goal`], [`GlobalRoute::progress`] (for a progress monitor),
//!   [`GlobalRoute::remaining_length`], [`GlobalRoute::first_sharp_turn`] (a corner to aim at
//!   before the local goal), [`GlobalRoute::first_blocked`] /
//!   [`GlobalRoute::is_blocked`] (for a re-route when the map changes).
//!
//! Use it before the first planning cycle and again when the vehicle stalls or the route is
//! found blocked. It depends only on `trust-geometry`; invalid input is a typed [`RouteError`]
//! naming the field (points beyond ±1e6 m, the scale policy of `trust_geometry::scale`,
//! included), never a panic or a hang.
//!
//! # Algorithm and why
//!
//! 1. **Straight line first.** If the segment start → goal is clear at the inflated clearance `c`
//!    ([`StaticMap::segment_clear`](trust_geometry::StaticMap::segment_clear)), that is the
//!    route; no grid is built. Open worlds cost three units of work.
//! 2. **Weighted A\* on a 26-connected grid** over the map bounds, with the exact 3-D octile
//!    distance as heuristic (admissible, and exact in free space) times a weight of 1.2
//!    ([`DEFAULT_HEURISTIC_WEIGHT`]: the grid path is at most 1.2 × the shortest; plain A\*
//!    expands the wide plateaus of equal-cost octile paths, 70 times more cells on an E4
//!    world). Occupancy is **lazy**: a cell centre's signed distance is computed the first time
//!    a search touches it and cached (`f32`, rounded down), so the cost is proportional to the
//!    cells visited, not to the map volume. A cell is free if its centre is at least `c` from
//!    the obstacles; an edge between two free neighbours with distances `a`, `b` and length `L`
//!    is accepted without a query when `(a + b − K·L)/2 ≥ c` (`K` = 1 for analytic shapes,
//!    whose distance is exact, `2√3` for a voxel ESDF, the interpolant's slope bound), else by
//!    one exact `segment_clear` at `c`. Every edge of the route is therefore clear at `c`, and
//!    **a slot of width `2c + h` or more stays open** (`h` the cell size; between parallel
//!    faces in any orientation: the band of centres at least `c` from both faces is `h` wide,
//!    so it holds a 26-connected chain of centres whose edges lie in the band).
//!    The search runs **coarse to fine** ([`RouteParams::coarse_factor`]): first on cells 4 times
//!    larger, then on the fine grid when the coarse one finds nothing — or, for a fine grid of
//!    at most [`RouteParams::refine_max_cells`] cells (a room), always, keeping the shorter
//!    route: the coarse grid closes slots narrower than `2c + 4h`.
//! 3. **Shortcut.** From each kept vertex the route jumps to the farthest following vertex that
//!    a straight segment reaches with clearance `c` (checked with `segment_clear`), which
//!    removes the grid's 45° staircase; a shortcut is only taken when clear at `c`, so it never
//!    brings the route closer than the inflation.
//! 4. **Cheap reachability, interleaved.** While the A\* runs from the start, a flood runs from
//!    the goal's cell on the fine grid, one expansion each in turn. It is a best-first flood
//!    toward the start (it heads for the start when the goal is open, and visits its whole
//!    component when not); it stops as soon as it touches a cell the start side has expanded.
//!    A goal sealed in a box of a few metres is thus found out after the box's few thousand
//!    cells, not after the world's millions. The coarse grid's exhaustion is no verdict (it
//!    closes passages); the fine grid's is, on either side.
//! 5. **A verdict is a proof.** The grid can miss a passage narrower than `2c + h` that keeps
//!    `c`, so an exhausted side is checked once more with a relaxed flood, an
//!    over-approximation of the free space: every cell whose centre is at least `c − h·√3/2`
//!    from the obstacles, face neighbours joined when the centre of their shared face is at
//!    least `c − h/√2` from them. A path keeping `c` passes through such cells' cubes from face
//!    to face (the distance is 1-Lipschitz; on an ESDF, to within its interpolation error), so
//!    when the relaxed flood is exhausted too, no path keeps `c`, at any resolution: the goal
//!    is [`RouteProgress::Unreachable`]. When it is not, the answer is
//!    [`RouteError::Unresolved`] (no route, no verdict: a passage between `2c − h·√3` and
//!    `2c + h` wide may exist). The cause then comes from an exact flood at the radius alone:
//!    [`UnreachableCause::TooNarrow`] when it joins the sides (the vehicle fits without its
//!    margin), else [`UnreachableCause::SealedOff`]. A goal outside the bounds or closer to an
//!    obstacle than the radius is a verdict from the start
//!    ([`UnreachableCause::GoalOutsideBounds`], [`UnreachableCause::GoalInsideObstacle`]); the
//!    search still runs, toward the nearest free point (the goal clamped into the bounds, or
//!    out of the obstacle along the distance gradient), for the verdict's nearest route.
//!    On a grid coarsened to fit `max_cells`, `h` is the coarsened cell: verdicts stay proofs,
//!    only more passages are left unresolved.
//!
//! Alternatives considered. *JPS* prunes symmetric paths on uniform-cost grids but needs the
//! occupancy of whole rows for its jumps: eagerly evaluating an E4 grid (250 × 75 × 20 m, ~4 M
//! cells) costs seconds of distance queries, while lazy A* touches only what it expands. *Theta\**
//! and lazy Theta\* give any-angle paths directly but pay a line-of-sight query per expansion
//! (Theta\*: per neighbour); with analytic shapes each query is a BVH walk plus GJK, orders of
//! magnitude dearer than a cached value, and the post-hoc shortcut recovers nearly all of the
//! any-angle gain on the building-sized obstacles the route is for. The route only has to point
//! the local planner the right way round obstacles; it need not be optimal.
//!
//! # Work, slicing and determinism
//!
//! [`RouteSearch::advance`] does at most its budget of **units of work**: one unit is one
//! signed-distance evaluation, one `segment_clear` query or one cell expansion (see
//! [`RouteSearch`]). Every query is charged before it runs and the search state is explicit
//! cursors, so the answer and the work total do not depend on how the work is sliced, and no
//! clock is read (ties in the open lists break by cost, then cell index; no hash map is
//! iterated). Measured (`cargo run --release -p trust-route --example route_timing`, shared
//! 2-core machine, indicative): a unit costs 0.9–3.3 µs on analytic shapes (E4-like world,
//! rooms) and 1.2–1.8 µs on the same E4 world as a 0.2 m point-cloud ESDF; a slice of 2 500
//! units is about 2–8 ms. Cases: E4 forest 9.6 k units, 10 ms; E4 with a 30 m wall 63 k, 116 ms
//! (ESDF: 103 k, 180 ms); goal sealed in a closed 4 m box 35 m away, SealedOff after 16 k units
//! (60 × 20 × 10 m room) or 3.5 k (E4; ESDF 5.2 k), 6–14 ms; a full wall with one 0.76 m slot
//! (radius 0.2 m), 469 k units, 1.6 s.
//!
//! # Grid size, caps and memory (scale-free)
//!
//! The cell size is `h₀ = max(c / cells_per_clearance, esdf_voxel / 2)`, so it follows the
//! vehicle: an 8 × 6 × 3 m room with a 0.1 m radius gets `c = 0.15 m` and 0.075 m cells
//! (~340 k cells); a 250 × 75 × 20 m world with a 0.3 m radius gets `c = 0.45 m`, `h₀ = 0.225 m`,
//! coarsened to ≈ 0.46 m to stay under `max_cells = 4 M`. Coarsening stops at
//! `max_coarsening · h₀` (past it the coarse grid alone is searched, and its exhaustion is then
//! the verdict grid's; [`RouteError::TooManyCells`] when it does not fit either). The outer
//! cell centres lie within `h/2` of the bounds. Memory is 5 bytes per cell (distance, flags)
//! plus 12 per cell for a grid the A\* runs on (cost, parent), zero-initialised so that the
//! OS pages in only the touched part. The search stops with [`RouteError::ExpansionCap`]
//! past `max_expansions` expansions of one A\*.
//!
//! Ends: a start or goal at least `c` from the obstacles joins the nearest free cell it sees
//! at `c`; one inside the inflation joins the nearest free cell it sees at its own clearance
//! (`min(sd, c)`, less 1e-7 m), so no segment comes closer to the obstacles than the end
//! itself; one inside an obstacle (negative distance) takes the nearest free cell. Cells are
//! sought within `snap_radius_factor · c` ([`RouteError::NoFreeCell`] for the start
//! otherwise). Such a start keeps its first segment at its own clearance
//! ([`GlobalRoute::start_inside_clearance`]); such a goal is left out and the route ends at
//! the free cell ([`GlobalRoute::goal_gap_m`]).
//!
//! # Use from a mission manager
//!
//! ```
//! use trust_geometry::{AaBox, Aabb, StaticMap, Vec3};
//! use trust_route::{RouteParams, RoutePlanner, RouteProgress};
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
//! // Or a slice of work per planning cycle, flying meanwhile:
//! let planner = RoutePlanner::new(RouteParams::default())?;
//! let mut search = planner.start_search(&map, &start, &goal, 0.3)?;
//! let answer = loop {
//!     match search.advance(&map, 2_500) {
//!         RouteProgress::Pending => continue, // next cycle
//!         done => break done,
//!     }
//! };
//! assert!(matches!(answer, RouteProgress::Found(_)));
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

pub use error::{Endpoint, Readable, RouteError, UnreachableCause};
pub use params::{DEFAULT_HEURISTIC_WEIGHT, RouteParams};
pub use planner::RoutePlanner;
pub use route::{Blocked, GlobalRoute, Projection, RoutePoint};
pub use search::{RouteProgress, RouteSearch, Unreachable};
