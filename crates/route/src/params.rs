//! [`RouteParams`]: how the route planner inflates the map, sizes its grid and bounds its search.

use serde::{Deserialize, Serialize};

use crate::error::{RouteError, check_range};

/// Parameters of [`crate::RoutePlanner`]. Every length is derived from the vehicle radius passed
/// to [`crate::RoutePlanner::plan`] (and the map's resolution), so the defaults serve an 8 × 6 ×
/// 3 m room with a 0.1 m vehicle and a 250 × 75 × 20 m world with a 0.3 m vehicle alike.
///
/// Derived quantities, with `r` the vehicle radius:
///
/// * inflated clearance `c = r · (1 + margin_radius_factor) + margin_m` — every route segment
///   keeps at least `c` from the static obstacles;
/// * preferred cell size `h₀ = max(c / cells_per_clearance, esdf_voxel / 2)` (no finer than half
///   an ESDF voxel: finer cells add no information), coarsened to fit `max_cells` but never
///   beyond `max_coarsening · h₀` ([`RouteError::TooManyCells`] past it);
/// * snap radius `snap_radius_factor · c` for a start or goal inside the inflated obstacles.
///
/// The defaults are this crate's design choices (no paper value exists: the paper has no global
/// route); the doc comment of each field gives its reason and valid range.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RouteParams {
    /// Safety margin as a fraction of the vehicle radius, added to the radius. Range `[0, 10]`;
    /// default 0.5 (a route half a radius wider than contact leaves the local planner room to
    /// bend around it without touching).
    pub margin_radius_factor: f64,
    /// Absolute safety margin in metres, added on top (e.g. a tracking-error bound). Range
    /// `[0, 100]`; default 0.
    pub margin_m: f64,
    /// Cells per inflated clearance: `h₀ = c / cells_per_clearance`. Range `[0.5, 8]`; default 2
    /// (gaps as narrow as `2c + h` stay open while the grid stays coarse: see the crate docs).
    pub cells_per_clearance: f64,
    /// Cap on the number of grid cells (memory: 23 bytes per cell, touched lazily). Range
    /// `[1, 100_000_000]`; default 4 000 000 (92 MB at most; an E4 world at 0.45 m cells).
    pub max_cells: usize,
    /// How much coarser than `h₀` the grid may become to fit `max_cells`. Range `[1, 16]`;
    /// default 4.
    pub max_coarsening: f64,
    /// Cap on A* expansions before [`RouteError::ExpansionCap`]. Range `[1, 100_000_000]`;
    /// default 2 000 000.
    pub max_expansions: usize,
    /// Weight `w` on the A* heuristic (weighted A*: `f = g + w·h`). The grid path is at most `w`
    /// times the shortest grid path (before the shortcut, which only shortens it). Range
    /// `[1, 10]`; default: see [`DEFAULT_HEURISTIC_WEIGHT`].
    pub heuristic_weight: f64,
    /// A start or goal inside the inflated obstacles snaps to the nearest free cell within
    /// `snap_radius_factor · c`. Range `[0, 100]`; default 4.
    pub snap_radius_factor: f64,
    /// Coarse to fine: the search first runs on cells `coarse_factor` times larger than `h₀`
    /// and only falls back to `h₀` when that grid finds no route (a slot narrower than `2c`
    /// plus its cell). Range `[1, 64]`, `1` searches the fine grid only; default 4: a coarse
    /// route is as safe (its edges are checked at `c` like the fine ones) and the search
    /// touches 4³ = 64 times fewer cells — on the suite's shaft climb (a 40 × 40 m slab with one
    /// 4 × 4 m shaft, the search fills the whole space below the slab) the first cycle took 3.3 s,
    /// now 18 ms, 15 ms of it the route (`route_ms` of `trust-sim run scenarios/suite/shaft_climb.toml`).
    pub coarse_factor: f64,
    /// After a coarse route is found, a fine grid (at `h₀`) of at most this many cells is
    /// searched too, and the shorter of the two routes is kept. The coarse grid may close passages
    /// narrower than `2c + coarse_factor·h₀` (then `2(c + coarse_factor·h₀·√3/2)`, 1.8 m for a
    /// 0.22 m vehicle): in a
    /// 12 × 10 × 3 m store with 2.4 m aisles the coarse route went round the shelves, 11.7 m for
    /// 9.3 m, and the flight took 3.4 × d/v_max. Small grids are cheap to search (every room of
    /// the suite, the variants and two holdout sets: ≤ 2 ms), large ones are not (a 40 × 40 m
    /// shaft: 0.6 s instead of 8 ms), hence the cap. Range `[0, 100 000 000]` (`max_cells` applies too), 0 never refines;
    /// default 1 000 000 (23 MB at most; the slowest fine search measured under it, a
    /// Crazyflie-scale U-trap, 99 ms).
    pub refine_max_cells: usize,
    /// Replace the grid path by the greedy line-of-sight shortcut (each kept segment checked with
    /// `StaticMap::segment_clear` at the inflated clearance). Default true.
    pub shortcut: bool,
}

/// Default [`RouteParams::heuristic_weight`]: 1.2. On the E4-like bench world (250 × 75 × 20 m,
/// 400 obstacles, 0.45 m cells; `examples/route_timing.rs`) plain A* (`w = 1`) expands 332 k
/// cells because the octile metric has wide plateaus of equal-cost paths, `w = 1.2` expands
/// 4.6 k for a route 0.4 % longer (with a 30 m wall across: 416 k → 62 k cells, 1.1 % longer);
/// larger weights save little more and lengthen the route by 1–3 %.
pub const DEFAULT_HEURISTIC_WEIGHT: f64 = 1.2;

impl Default for RouteParams {
    fn default() -> Self {
        Self {
            margin_radius_factor: 0.5,
            margin_m: 0.0,
            cells_per_clearance: 2.0,
            max_cells: 4_000_000,
            max_coarsening: 4.0,
            max_expansions: 2_000_000,
            heuristic_weight: DEFAULT_HEURISTIC_WEIGHT,
            snap_radius_factor: 4.0,
            coarse_factor: 4.0,
            refine_max_cells: 1_000_000,
            shortcut: true,
        }
    }
}

/// Largest value accepted for the two counts.
const MAX_COUNT: usize = 100_000_000;

impl RouteParams {
    /// Checks every field against its documented range; the error names the field
    /// (`route.<field>`) and the value.
    pub fn validate(&self) -> Result<(), RouteError> {
        check_range(
            "route.margin_radius_factor",
            self.margin_radius_factor,
            0.0,
            10.0,
        )?;
        check_range("route.margin_m", self.margin_m, 0.0, 100.0)?;
        check_range(
            "route.cells_per_clearance",
            self.cells_per_clearance,
            0.5,
            8.0,
        )?;
        check_range("route.max_coarsening", self.max_coarsening, 1.0, 16.0)?;
        check_range("route.heuristic_weight", self.heuristic_weight, 1.0, 10.0)?;
        check_range("route.coarse_factor", self.coarse_factor, 1.0, 64.0)?;
        check_range(
            "route.snap_radius_factor",
            self.snap_radius_factor,
            0.0,
            100.0,
        )?;
        for (field, v) in [
            ("route.max_cells", self.max_cells),
            ("route.max_expansions", self.max_expansions),
        ] {
            if !(1..=MAX_COUNT).contains(&v) {
                return Err(RouteError::InvalidParam {
                    field: field.to_owned(),
                    value: v as f64,
                    expected: format!("an integer in [1, {MAX_COUNT}]"),
                });
            }
        }
        if self.refine_max_cells > MAX_COUNT {
            return Err(RouteError::InvalidParam {
                field: "route.refine_max_cells".to_owned(),
                value: self.refine_max_cells as f64,
                expected: format!("an integer in [0, {MAX_COUNT}]"),
            });
        }
        Ok(())
    }

    /// The inflated clearance `r · (1 + margin_radius_factor) + margin_m` for a vehicle of radius
    /// `radius_m`.
    pub fn clearance_for(&self, radius_m: f64) -> f64 {
        radius_m * (1.0 + self.margin_radius_factor) + self.margin_m
    }
}
