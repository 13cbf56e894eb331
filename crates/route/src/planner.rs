//! [`RoutePlanner`]: a bounded A* over a lazily evaluated, inflated occupancy grid, followed by a
//! line-of-sight shortcut.

use std::cmp::Ordering;
use std::collections::BinaryHeap;
use std::time::Instant;

use trust_geometry::{Aabb, StaticMap};

use crate::Vec3;
use crate::error::{Endpoint, RouteError, check_point, check_range};
use crate::params::RouteParams;
use crate::route::GlobalRoute;

/// Largest vehicle radius accepted, in metres.
const MAX_RADIUS_M: f64 = 1.0e3;
/// Expansions between two looks at the deadline.
const DEADLINE_STRIDE: usize = 256;
/// Most cells examined per side of the snap cube (the cube holds `(2k + 1)³` cells).
const MAX_SNAP_HALF_WIDTH: i64 = 24;

/// Plans a [`GlobalRoute`] on a [`StaticMap`]; see the crate docs for the algorithm.
///
/// Planning is a pure function of the map, the end points, the radius and the parameters (the
/// optional deadline aside): same input, same route.
#[derive(Debug, Clone)]
pub struct RoutePlanner {
    params: RouteParams,
}

/// The grid the search runs on: cell centres `origin + h · (i, j, k)`, all inside the bounds.
#[derive(Debug, Clone, Copy)]
struct Grid {
    origin: Vec3,
    h: f64,
    dims: [usize; 3],
}

impl Grid {
    /// The coarsest grid of cell size at least `h` with at most `max_cells` cells, centred in
    /// `bounds`.
    fn new(bounds: &Aabb, h0: f64, max_cells: usize, max_h: f64) -> Result<Self, RouteError> {
        let ext = bounds.extent();
        let count = |h: f64| -> [usize; 3] {
            // Capped far above any admissible count so the product stays in u128.
            let n = |e: f64| (e / h).floor().clamp(1.0, 1.0e12) as usize;
            [n(ext.x), n(ext.y), n(ext.z)]
        };
        let cells = |d: [usize; 3]| d.iter().map(|&n| n as u128).product::<u128>();
        let mut h = h0;
        let mut dims = count(h);
        if cells(dims) > max_cells as u128 {
            // The continuous estimate, then a few 1 % steps for the floors.
            h = h.max((ext.x * ext.y * ext.z / max_cells as f64).cbrt());
            dims = count(h);
            let mut steps = 0;
            while cells(dims) > max_cells as u128 && steps < 64 {
                h *= 1.01;
                dims = count(h);
                steps += 1;
            }
            if h > max_h || cells(dims) > max_cells as u128 {
                let coarsest = count(max_h);
                return Err(RouteError::TooManyCells {
                    cells: cells(coarsest),
                    cap: max_cells,
                    cell_m: max_h,
                });
            }
        }
        let origin = Vec3::from_fn(|a, _| {
            let e = ext[a];
            let used = (dims[a] - 1) as f64 * h;
            bounds.min[a] + 0.5 * (e - used).max(0.0)
        });
        Ok(Self { origin, h, dims })
    }

    fn len(&self) -> usize {
        self.dims[0] * self.dims[1] * self.dims[2]
    }

    fn index(&self, c: [i64; 3]) -> Option<usize> {
        if (0..3).all(|a| c[a] >= 0 && (c[a] as usize) < self.dims[a]) {
            Some(c[0] as usize + self.dims[0] * (c[1] as usize + self.dims[1] * c[2] as usize))
        } else {
            None
        }
    }

    fn coords(&self, i: usize) -> [i64; 3] {
        let x = i % self.dims[0];
        let y = (i / self.dims[0]) % self.dims[1];
        let z = i / (self.dims[0] * self.dims[1]);
        [x as i64, y as i64, z as i64]
    }

    fn center(&self, c: [i64; 3]) -> Vec3 {
        self.origin + Vec3::new(c[0] as f64, c[1] as f64, c[2] as f64) * self.h
    }

    /// The cell whose centre is nearest to `p` (clamped into the grid).
    fn nearest_cell(&self, p: &Vec3) -> [i64; 3] {
        let mut c = [0_i64; 3];
        for a in 0..3 {
            let f = ((p[a] - self.origin[a]) / self.h).round();
            c[a] = f.clamp(0.0, (self.dims[a] - 1) as f64) as i64;
        }
        c
    }
}

/// Occupancy cache states in the low two bits (0: not evaluated yet; a cell's signed distance is
/// computed when first seen).
const FREE: u8 = 1;
const BLOCKED: u8 = 2;
/// Flag: the cell has been expanded (closed set).
const CLOSED: u8 = 4;
/// Flag: the cell has a tentative cost in `g`.
const SEEN: u8 = 8;

/// A* search state over a [`Grid`]; every array is zero-initialised (lazily paged by the OS).
struct Search<'a> {
    map: &'a StaticMap,
    grid: Grid,
    /// Signed distance a cell centre needs to be free: the clearance plus `h·√3/2`.
    node_clearance: f64,
    state: Vec<u8>,
    g: Vec<f64>,
    parent: Vec<u32>,
}

/// The two ends of a route query and what [`RoutePlanner::plan_until`] found about them.
#[derive(Debug, Clone, Copy)]
struct Ends {
    start: Vec3,
    goal: Vec3,
    start_free: bool,
    goal_free: bool,
    clearance: f64,
}

/// A heap entry: smallest `f` first, then largest `g` (deeper first), then smallest index.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Open {
    f: f64,
    g: f64,
    cell: u32,
}

impl Eq for Open {}

impl Ord for Open {
    fn cmp(&self, other: &Self) -> Ordering {
        other
            .f
            .total_cmp(&self.f)
            .then(self.g.total_cmp(&other.g))
            .then(other.cell.cmp(&self.cell))
    }
}

impl PartialOrd for Open {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// Exact cost of a 26-connected grid path between cells `a` and `b` in free space (the 3-D
/// octile distance), in metres.
fn octile(a: [i64; 3], b: [i64; 3], h: f64) -> f64 {
    let mut d = [
        (a[0] - b[0]).unsigned_abs() as f64,
        (a[1] - b[1]).unsigned_abs() as f64,
        (a[2] - b[2]).unsigned_abs() as f64,
    ];
    d.sort_by(|x, y| y.total_cmp(x));
    let (d1, d2, d3) = (d[0], d[1], d[2]);
    h * (3.0_f64.sqrt() * d3 + 2.0_f64.sqrt() * (d2 - d3) + (d1 - d2))
}

impl<'a> Search<'a> {
    fn is_free(&mut self, i: usize) -> bool {
        match self.state[i] & 3 {
            FREE => true,
            BLOCKED => false,
            _ => {
                let p = self.grid.center(self.grid.coords(i));
                let free = self.map.signed_distance(&p) >= self.node_clearance;
                self.state[i] |= if free { FREE } else { BLOCKED };
                free
            }
        }
    }

    /// Free cells within `bound` of `p`, nearest first (ties by index), each accepted by `ok`.
    fn nearest_free(
        &mut self,
        p: &Vec3,
        bound: f64,
        mut ok: impl FnMut(&Vec3) -> bool,
    ) -> Option<usize> {
        let c = self.grid.nearest_cell(p);
        let k = ((bound / self.grid.h).ceil() as i64 + 1).clamp(1, MAX_SNAP_HALF_WIDTH);
        let mut cands = Vec::new();
        for dz in -k..=k {
            for dy in -k..=k {
                for dx in -k..=k {
                    let q = [c[0] + dx, c[1] + dy, c[2] + dz];
                    if let Some(i) = self.grid.index(q) {
                        let d = (self.grid.center(q) - p).norm();
                        if d <= bound {
                            cands.push((d, i));
                        }
                    }
                }
            }
        }
        cands.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        cands.into_iter().map(|(_, i)| i).find(|&i| {
            let centre = self.grid.center(self.grid.coords(i));
            self.is_free(i) && ok(&centre)
        })
    }

    /// A* from cell `s` to cell `t`; the cell path from `s` to `t`.
    fn astar(
        &mut self,
        s: usize,
        t: usize,
        max_expansions: usize,
        deadline: Option<Instant>,
        clearance: f64,
        weight: f64,
    ) -> Result<(Vec<usize>, usize), RouteError> {
        let h = self.grid.h;
        let tc = self.grid.coords(t);
        let steps: Vec<([i64; 3], f64)> = (-1..=1_i64)
            .flat_map(|z| (-1..=1_i64).flat_map(move |y| (-1..=1_i64).map(move |x| [x, y, z])))
            .filter(|d| *d != [0, 0, 0])
            .map(|d| {
                let n = d.iter().filter(|&&v| v != 0).count() as f64;
                (d, h * n.sqrt())
            })
            .collect();
        let mut open = BinaryHeap::new();
        self.g[s] = 0.0;
        self.state[s] |= SEEN;
        open.push(Open {
            f: weight * octile(self.grid.coords(s), tc, h),
            g: 0.0,
            cell: s as u32,
        });
        let mut expanded = 0_usize;
        while let Some(Open { g, cell, .. }) = open.pop() {
            let i = cell as usize;
            if self.state[i] & CLOSED != 0 || g > self.g[i] {
                continue;
            }
            if i == t {
                let mut path = vec![t];
                let mut cur = t;
                while cur != s {
                    cur = (self.parent[cur] - 1) as usize;
                    path.push(cur);
                }
                path.reverse();
                return Ok((path, expanded));
            }
            self.state[i] |= CLOSED;
            expanded += 1;
            if expanded > max_expansions {
                return Err(RouteError::ExpansionCap {
                    cap: max_expansions,
                });
            }
            if expanded.is_multiple_of(DEADLINE_STRIDE)
                && deadline.is_some_and(|d| Instant::now() >= d)
            {
                return Err(RouteError::Deadline { expanded });
            }
            let c = self.grid.coords(i);
            for &(d, cost) in &steps {
                let Some(j) = self.grid.index([c[0] + d[0], c[1] + d[1], c[2] + d[2]]) else {
                    continue;
                };
                if self.state[j] & CLOSED != 0 || !self.is_free(j) {
                    continue;
                }
                let gj = g + cost;
                if self.state[j] & SEEN == 0 || gj < self.g[j] {
                    self.state[j] |= SEEN;
                    self.g[j] = gj;
                    self.parent[j] = cell + 1;
                    open.push(Open {
                        f: gj + weight * octile(self.grid.coords(j), tc, h),
                        g: gj,
                        cell: j as u32,
                    });
                }
            }
        }
        Err(RouteError::Unreachable {
            expanded,
            clearance_m: clearance,
        })
    }
}

/// Greedy line-of-sight shortcut: from each kept point, jump to the farthest following point
/// reachable by a straight segment clear at `clearance` (stopping at the first that is not), or to
/// the next point if none is.
fn shortcut(map: &StaticMap, points: &[Vec3], clearance: f64) -> Vec<Vec3> {
    let mut out = Vec::with_capacity(points.len());
    let Some(first) = points.first() else {
        return out;
    };
    out.push(*first);
    let last = points.len() - 1;
    let mut anchor = 0;
    while anchor < last {
        let mut j = anchor + 1;
        while j < last && map.segment_clear(&points[anchor], &points[j + 1], clearance) {
            j += 1;
        }
        out.push(points[j]);
        anchor = j;
    }
    out
}

/// Drops consecutive duplicates and interior points collinear with their neighbours.
fn simplify(points: Vec<Vec3>) -> Vec<Vec3> {
    let mut out: Vec<Vec3> = Vec::with_capacity(points.len());
    for p in points {
        if out
            .last()
            .is_some_and(|q| (p - q).norm() <= 1e-12 * (1.0 + p.amax()))
        {
            continue;
        }
        if out.len() >= 2 {
            let a = out[out.len() - 2];
            let b = out[out.len() - 1];
            let (u, v) = (b - a, p - b);
            if u.cross(&v).norm() <= 1e-9 * u.norm() * v.norm() && u.dot(&v) > 0.0 {
                out.pop();
            }
        }
        out.push(p);
    }
    out
}

impl RoutePlanner {
    /// A planner with validated parameters.
    pub fn new(params: RouteParams) -> Result<Self, RouteError> {
        params.validate()?;
        Ok(Self { params })
    }

    /// The parameters.
    pub fn params(&self) -> &RouteParams {
        &self.params
    }

    /// Plans a route from `start` to `goal` for a vehicle of radius `radius_m` (see
    /// [`RoutePlanner::plan_until`]), with no deadline: deterministic.
    pub fn plan(
        &self,
        map: &StaticMap,
        start: &Vec3,
        goal: &Vec3,
        radius_m: f64,
    ) -> Result<GlobalRoute, RouteError> {
        self.plan_until(map, start, goal, radius_m, None)
    }

    /// Plans a route from `start` to `goal` for a vehicle of radius `radius_m`, giving up with
    /// [`RouteError::Deadline`] once `deadline` has passed (checked every 256 expansions).
    ///
    /// * Both ends must be finite and inside the map bounds.
    /// * If the straight segment is clear at the inflated clearance `c`
    ///   ([`RouteParams::clearance_for`]), the route is that segment (no grid is built); a start
    ///   equal to the goal gives a one-point route of length 0.
    /// * Otherwise A* runs on the grid described in the crate docs. An end at least `c` from
    ///   every obstacle is joined to the nearest free cell it sees with clearance `c`; an end
    ///   inside the inflated obstacles is joined to the nearest free cell within the snap radius
    ///   regardless ([`GlobalRoute::start_inside_clearance`]); a goal so joined is not part of
    ///   the route, which ends at that cell ([`GlobalRoute::goal_gap_m`]).
    /// * Errors: [`RouteError::InvalidParam`] for a radius outside `[0, 1000]` m,
    ///   [`RouteError::NonFinitePoint`], [`RouteError::OutsideBounds`],
    ///   [`RouteError::TooManyCells`], [`RouteError::NoFreeCell`],
    ///   [`RouteError::ExpansionCap`], [`RouteError::Deadline`], [`RouteError::Unreachable`].
    pub fn plan_until(
        &self,
        map: &StaticMap,
        start: &Vec3,
        goal: &Vec3,
        radius_m: f64,
        deadline: Option<Instant>,
    ) -> Result<GlobalRoute, RouteError> {
        let radius = check_range("radius_m", radius_m, 0.0, MAX_RADIUS_M)?;
        let start = check_point("start", start)?;
        let goal = check_point("goal", goal)?;
        for (which, p) in [(Endpoint::Start, start), (Endpoint::Goal, goal)] {
            if !map.contains(&p) {
                return Err(RouteError::OutsideBounds { which, point: p });
            }
        }
        let p = &self.params;
        let clearance = p.clearance_for(radius);
        let start_free = map.is_free(&start, clearance);
        let goal_free = map.is_free(&goal, clearance);
        if start_free && goal_free && map.segment_clear(&start, &goal, clearance) {
            return Ok(GlobalRoute::new(
                simplify(vec![start, goal]),
                clearance,
                None,
                0,
                false,
                0.0,
            ));
        }

        // The grid (cell size rule: see RouteParams).
        let esdf_half = map.esdf().map_or(0.0, |e| 0.5 * e.resolution());
        let h0 = (clearance / p.cells_per_clearance).max(esdf_half);
        if h0 <= 0.0 {
            // A zero radius and margin on a map without an ESDF: no length to derive a grid from.
            return Err(RouteError::InvalidParam {
                field: "radius_m".to_owned(),
                value: radius_m,
                expected: "a positive inflated clearance (radius or margin > 0) for a grid search"
                    .to_owned(),
            });
        }
        let ends = Ends {
            start,
            goal,
            start_free,
            goal_free,
            clearance,
        };
        // Coarse to fine: a coarse grid's free cells are farther from the obstacles (the node
        // clearance grows with the cell), so a coarse route is as safe as a fine one; when the
        // coarse grid finds none (a passage too narrow for it) the fine grid searches, and when
        // the fine grid is small it searches anyway for a shorter route through the passages
        // the coarse one closed (`refine_max_cells`).
        let mut expanded_before = 0;
        if p.coarse_factor > 1.0 {
            // The coarse grid coarsens to fit the cell cap like the fine one: a world too large
            // for the fine grid at its coarsest (a 320 × 320 × 45 m city with a 0.25 m vehicle)
            // is still routed, on the coarse grid.
            let coarse = h0 * p.coarse_factor;
            match self.grid_route(map, &ends, coarse, coarse * p.max_coarsening, deadline) {
                Ok(route) => return Ok(self.refined(map, &ends, h0, route, deadline)),
                Err(RouteError::Unreachable { expanded, .. }) => expanded_before = expanded,
                Err(RouteError::NoFreeCell { .. } | RouteError::TooManyCells { .. }) => {}
                Err(e) => return Err(e),
            }
        }
        let mut route = self.grid_route(map, &ends, h0, h0 * p.max_coarsening, deadline)?;
        route.add_expanded(expanded_before);
        Ok(route)
    }

    /// `coarse`, or the route on the fine grid of cells `h0` when that grid has at most
    /// `refine_max_cells` cells and its route is shorter. The coarse route is kept whenever
    /// the fine search fails (a cap, the deadline): it is valid, only longer.
    fn refined(
        &self,
        map: &StaticMap,
        ends: &Ends,
        h0: f64,
        coarse: GlobalRoute,
        deadline: Option<Instant>,
    ) -> GlobalRoute {
        let p = &self.params;
        let cap = p.refine_max_cells.min(p.max_cells);
        if Grid::new(map.bounds(), h0, cap, h0).is_err() {
            return coarse;
        }
        match self.grid_route(map, ends, h0, h0, deadline) {
            Ok(mut fine) if fine.length() < coarse.length() => {
                fine.add_expanded(coarse.expanded_count());
                fine
            }
            Ok(fine) => {
                let mut coarse = coarse;
                coarse.add_expanded(fine.expanded_count());
                coarse
            }
            Err(_) => coarse,
        }
    }

    /// A* on a grid of cells of size `h` (coarsened up to `h_max` to fit `max_cells`) between
    /// the ends, then the shortcut.
    fn grid_route(
        &self,
        map: &StaticMap,
        ends: &Ends,
        h0: f64,
        h_max: f64,
        deadline: Option<Instant>,
    ) -> Result<GlobalRoute, RouteError> {
        let p = &self.params;
        let Ends {
            start,
            goal,
            start_free,
            goal_free,
            clearance,
        } = *ends;
        let grid = Grid::new(map.bounds(), h0, p.max_cells, h_max)?;
        let n = grid.len();
        let mut search = Search {
            map,
            grid,
            node_clearance: clearance + grid.h * 3.0_f64.sqrt() / 2.0,
            state: vec![0; n],
            g: vec![0.0; n],
            parent: vec![0; n],
        };
        let snap = p.snap_radius_factor * clearance;
        // Free ends may join a farther cell they see; ends inside the inflation take the nearest.
        let reach = |free: bool| {
            if free { snap.max(4.0 * grid.h) } else { snap }
        };
        let end_cell = |search: &mut Search<'_>, which, q: Vec3, free: bool| {
            search
                .nearest_free(&q, reach(free), |c| {
                    !free || map.segment_clear(&q, c, clearance)
                })
                .ok_or(RouteError::NoFreeCell {
                    which,
                    point: q,
                    bound_m: reach(free),
                    clearance_m: clearance,
                })
        };
        let s = end_cell(&mut search, Endpoint::Start, start, start_free)?;
        let t = end_cell(&mut search, Endpoint::Goal, goal, goal_free)?;
        let (cells, expanded) = search.astar(
            s,
            t,
            p.max_expansions,
            deadline,
            clearance,
            p.heuristic_weight,
        )?;

        let mut points = Vec::with_capacity(cells.len() + 2);
        points.push(start);
        points.extend(cells.iter().map(|&i| grid.center(grid.coords(i))));
        if goal_free {
            points.push(goal);
        }
        let points = simplify(points);
        let points = if p.shortcut {
            simplify(shortcut(map, &points, clearance))
        } else {
            points
        };
        let goal_gap = (points.last().copied().unwrap_or(start) - goal).norm();
        Ok(GlobalRoute::new(
            points,
            clearance,
            Some(grid.h),
            expanded,
            !start_free,
            if goal_free { 0.0 } else { goal_gap },
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn octile_is_exact_on_axes_and_diagonals() {
        assert!((octile([0, 0, 0], [3, 0, 0], 0.5) - 1.5).abs() < 1e-12);
        assert!((octile([0, 0, 0], [2, 2, 0], 1.0) - 2.0 * 2.0_f64.sqrt()).abs() < 1e-12);
        assert!((octile([0, 0, 0], [2, 2, 2], 1.0) - 2.0 * 3.0_f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn grid_coarsens_to_fit_the_cap_and_errors_past_the_coarsening_bound() {
        let b = Aabb::new(Vec3::zeros(), Vec3::new(100.0, 100.0, 10.0)).unwrap();
        let g = Grid::new(&b, 0.1, 1000, 100.0).unwrap();
        assert!(g.len() <= 1000);
        assert!(g.h > 0.1);
        let e = Grid::new(&b, 0.1, 1000, 0.2).unwrap_err();
        assert!(
            matches!(e, RouteError::TooManyCells { cap: 1000, .. }),
            "{e}"
        );
    }

    #[test]
    fn grid_cell_centres_lie_inside_the_bounds() {
        let b = Aabb::new(Vec3::new(-1.0, 2.0, 0.0), Vec3::new(7.3, 8.1, 3.05)).unwrap();
        let g = Grid::new(&b, 0.3, 1_000_000, 0.3).unwrap();
        let lo = g.center([0, 0, 0]);
        let hi = g.center([
            g.dims[0] as i64 - 1,
            g.dims[1] as i64 - 1,
            g.dims[2] as i64 - 1,
        ]);
        assert!(b.contains(&lo) && b.contains(&hi), "{lo} {hi}");
    }

    #[test]
    fn simplify_drops_duplicates_and_collinear_points() {
        let pts = vec![
            Vec3::zeros(),
            Vec3::zeros(),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(2.0, 1.0, 0.0),
        ];
        assert_eq!(simplify(pts).len(), 3);
    }
}
