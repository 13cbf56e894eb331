//! [`RouteSearch`]: the resumable, work-bounded search behind [`crate::RoutePlanner`].
//!
//! The search is a state machine over explicit cursors (the cell being expanded and the next of
//! its 26 neighbours, the next snap candidate, the next shortcut test). Every costly query is
//! charged to a [`Meter`] *before* it runs; when the budget is spent the query is not run and
//! the cursor stays where it is, so the next [`RouteSearch::advance`] retries exactly that step.
//! Cached signed distances make a retry free of charge. Hence the sequence of queries, and the
//! result, do not depend on how the work is sliced.

use std::collections::{BinaryHeap, VecDeque};

use trust_geometry::StaticMap;

use crate::Vec3;
use crate::error::{Endpoint, RouteError, UnreachableCause};
use crate::grid::{
    Balls, CLOSED, FLOOD_G, FLOOD_R, FLOOD_S, FLOOD_X, Grid, Layer, Meter, NEIGHBOUR_STEPS, Open,
    Paused, SEEN, SIGHT_UNIT_M, octile,
};
use crate::params::RouteParams;
use crate::route::GlobalRoute;

/// Most cells examined per side of the snap cube (the cube holds `(2k + 1)³` cells).
const MAX_SNAP_HALF_WIDTH: i64 = 24;
/// How much less than the end's own distance the segment to a snapped cell may keep, in metres
/// (rounding of the distance queries).
const SNAP_TOLERANCE_M: f64 = 1e-7;
/// Most gradient steps taken to leave an obstacle that buries the goal.
const MAX_ESCAPE_STEPS: usize = 16;

/// What [`RouteSearch::advance`] reports.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum RouteProgress {
    /// The budget ran out before an answer; call [`RouteSearch::advance`] again.
    Pending,
    /// A route from the start to the goal (see [`GlobalRoute`] for what it guarantees).
    Found(GlobalRoute),
    /// A verdict: the goal cannot be reached, why, and the best the vehicle can do instead.
    Unreachable(Unreachable),
    /// The search stopped without a verdict: a cap ([`RouteError::ExpansionCap`],
    /// [`RouteError::TooManyCells`]), no free cell near the start
    /// ([`RouteError::NoFreeCell`]), or no grid to search on ([`RouteError::InvalidParam`] for
    /// a zero inflated clearance on a map without an ESDF).
    Failed(RouteError),
}

/// The verdict that the goal cannot be reached ([`RouteProgress::Unreachable`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Unreachable {
    /// Why.
    pub cause: UnreachableCause,
    /// A route from the start to the reachable point nearest the goal that the start-side
    /// search found before the verdict (its expanded cell nearest the goal, or the free point
    /// next to a buried or outside goal when the search reached it), shortcut like any route;
    /// [`GlobalRoute::goal_gap_m`] is its distance to the goal. `None` when the search expanded
    /// no cell, or when no free point was found near a goal buried in an obstacle.
    pub nearest: Option<GlobalRoute>,
    /// Units of work the search did in all ([`RouteSearch::work_done`]).
    pub work_done: usize,
}

/// A resumable route search started by [`crate::RoutePlanner::start_search`].
///
/// It owns all its state and does not borrow the map: pass the same map to every
/// [`RouteSearch::advance`] (another map gives an unspecified, though memory-safe and
/// panic-free, answer).
///
/// **Unit of work.** One unit is one of: a signed-distance evaluation of the map (a grid cell's
/// centre, the start or goal, a gradient step out of an obstacle), a
/// [`StaticMap::segment_clear`] query (an edge the cell distances cannot prove clear; a snap's
/// line of sight or a shortcut test costs one unit plus one per 2 m of its length, and the
/// straight line from start to goal is tested in 2 m pieces of one unit each), or one cell
/// expansion (popping a cell
/// of the A* or of a flood and looking at its neighbours, the neighbours' queries charged
/// separately). Cached values are free. A unit's time depends on the map (see the crate docs
/// for measured costs).
///
/// **Determinism.** The queries run in a fixed order that does not depend on the budgets: the
/// same map, ends and radius give the same sequence of queries and the same answer whether the
/// search runs in one [`RouteSearch::advance`] or in a thousand, and the same work total.
#[derive(Debug, Clone)]
pub struct RouteSearch {
    params: RouteParams,
    radius: f64,
    clearance: f64,
    start: Vec3,
    goal: Vec3,
    /// The goal clamped into the map bounds.
    target: Vec3,
    goal_in_bounds: bool,
    work: usize,
    done: Option<RouteProgress>,
    sd_start: Option<f64>,
    sd_target: Option<f64>,
    straight_clear: Option<bool>,
    /// Pieces of the straight line of sight found clear so far.
    straight_pieces: usize,
    /// Units paid toward the query that paused the last slice ([`Meter::charge_sight`]).
    prepaid: usize,
    built: bool,
    layers: Vec<Layer>,
    /// The layer the verdicts are proved on (the finest grid that fits `max_cells`).
    fine: usize,
    /// The coarse layer searched first, if any (cleared when its ends do not snap).
    coarse: Option<usize>,
    /// The layer the relaxed floods try a proof on first ([`VERDICT_COARSENING`] times the
    /// fine cell), if any; when its floods meet, they start again on the fine layer.
    verdict_layer: Option<usize>,
    start_snap: Vec<SnapState>,
    target_snap: Vec<SnapState>,
    /// Gradient steps out of the obstacle burying the goal: the point reached and the count.
    escape: Option<(Vec3, usize, bool)>,
    escape_snap: Option<SnapState>,
    astar: Option<Astar>,
    /// Expansions of finished A* searches.
    expanded_before: usize,
    /// The nearest cell to the goal of a finished A* search: distance, grid, path.
    nearest_before: Option<(f64, Grid, Vec<usize>)>,
    /// The relaxed floods at the clearance from the goal's side and from the start's: the
    /// first one exhausted proves the goal unreachable.
    goal_flood: Option<Flood>,
    start_flood: Option<Flood>,
    sides: Sides,
    /// The goal flood's first cell when no cell at the clearance joins the goal: the snap at
    /// the radius.
    goal_seed: SnapState,
    /// Whose turn it is, and the work at which it passes on.
    turn: Turn,
    turn_end: usize,
    /// The A* on the fine grid ran dry (the floods go on alone).
    astar_exhausted: bool,
    /// The floods met on the coarser verdict layer: a proof on the fine one is unlikely (walls
    /// thinner than that layer resolves), so the fine goal-side flood gets shorter turns
    /// ([`UNLIKELY_TURN_UNITS`]) and the A* most of the work.
    unlikely: bool,
    /// The exact flood at the radius once a side is proved sealed (the verdict's cause).
    cause_flood: Option<Flood>,
    /// Which of [`RouteSearch::cause_of`]'s floods runs.
    cause_stage: u8,
    /// Parts of a unit bought and not yet spent ([`Meter::charge_parts`]).
    credit: u32,
    finishing: Option<Finishing>,
    coarse_route: Option<GlobalRoute>,
    refining: bool,
    reached_target: bool,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Sides {
    NotStarted,
    /// Both floods run on layer `layer`: `goal` and `start` are their first cells.
    Running {
        layer: usize,
        start: usize,
        goal: usize,
    },
    /// The floods met (or the A* reached the goal): no proof to come from them.
    Joined,
    /// The flood from `side` ran dry without meeting the other side: no path keeps the
    /// clearance. `from` is its first cell (`None`: no cell near the goal at all), `to` the
    /// other side's, both on layer `layer`.
    Proved {
        layer: usize,
        side: Endpoint,
        from: Option<usize>,
        to: Option<usize>,
    },
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Turn {
    Astar,
    Goal,
    Start,
}

#[derive(Debug, Clone)]
enum SnapState {
    NotStarted,
    Running(SnapCursor),
    Done(Option<usize>),
}

/// Candidate cells around an end, nearest first, and the next one to try.
#[derive(Debug, Clone)]
struct SnapCursor {
    cands: Vec<usize>,
    next: usize,
    level: f64,
    /// Line of sight required from the end to the cell, at this clearance (`None`: the end is
    /// inside an obstacle, the nearest free cell is taken).
    sight: Option<f64>,
}

impl SnapCursor {
    fn new(grid: &Grid, p: &Vec3, bound: f64, level: f64, sight: Option<f64>) -> Self {
        let c = grid.nearest_cell(p);
        let k = ((bound / grid.h).ceil() as i64 + 1).clamp(1, MAX_SNAP_HALF_WIDTH);
        let mut cands = Vec::new();
        for dz in -k..=k {
            for dy in -k..=k {
                for dx in -k..=k {
                    let q = [c[0] + dx, c[1] + dy, c[2] + dz];
                    if let Some(i) = grid.index(q) {
                        let d = (grid.center(q) - p).norm();
                        if d <= bound {
                            cands.push((d, i));
                        }
                    }
                }
            }
        }
        cands.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        Self {
            cands: cands.into_iter().map(|(_, i)| i).collect(),
            next: 0,
            level,
            sight,
        }
    }

    fn run(
        &mut self,
        layer: &mut Layer,
        map: &StaticMap,
        p: &Vec3,
        m: &mut Meter,
    ) -> Result<Option<usize>, Paused> {
        while let Some(&i) = self.cands.get(self.next) {
            if layer.sd(map, i, m)? >= self.level {
                match self.sight {
                    None => return Ok(Some(i)),
                    Some(s) => {
                        let center = layer.grid.center_of(i);
                        m.charge_sight((center - p).norm())?;
                        if map.segment_clear(p, &center, s) {
                            return Ok(Some(i));
                        }
                    }
                }
            }
            self.next += 1;
        }
        Ok(None)
    }
}

/// Weighted A* from the start cell `s` to the target cell `t` on one layer.
#[derive(Debug, Clone)]
struct Astar {
    layer: usize,
    s: usize,
    t: Option<usize>,
    g: Vec<f64>,
    parent: Vec<u32>,
    open: BinaryHeap<Open>,
    /// The cell being expanded, its cost and the next neighbour to look at.
    cur: Option<(usize, f64, usize)>,
    expanded: usize,
    /// The expanded cell nearest the goal: distance and cell.
    best: Option<(f64, usize)>,
}

enum AstarStep {
    Expanded,
    Reached,
    Exhausted,
    Cap,
}

impl Astar {
    fn new(layer_ix: usize, layer: &mut Layer, s: usize, t: Option<usize>, weight: f64) -> Self {
        let n = layer.grid.len();
        let mut open = BinaryHeap::new();
        layer.flags[s] |= SEEN;
        let h = t.map_or(0.0, |t| {
            weight * octile(layer.grid.coords(s), layer.grid.coords(t), layer.grid.h)
        });
        open.push(Open {
            f: h,
            g: 0.0,
            cell: s as u32,
        });
        Self {
            layer: layer_ix,
            s,
            t,
            g: vec![0.0; n],
            parent: vec![0; n],
            open,
            cur: None,
            expanded: 0,
            best: None,
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn step(
        &mut self,
        layer: &mut Layer,
        map: &StaticMap,
        m: &mut Meter,
        level: f64,
        weight: f64,
        max_expansions: usize,
        goal: &Vec3,
    ) -> Result<AstarStep, Paused> {
        let steps = &*NEIGHBOUR_STEPS;
        let h = layer.grid.h;
        loop {
            if let Some((i, gi, k)) = self.cur {
                let Some(&(d, len)) = steps.get(k) else {
                    self.cur = None;
                    return Ok(AstarStep::Expanded);
                };
                let c = layer.grid.coords(i);
                if let Some(j) = layer.grid.index([c[0] + d[0], c[1] + d[1], c[2] + d[2]])
                    && layer.flags[j] & CLOSED == 0
                    && layer.sd(map, j, m)? >= level
                    && layer.edge_clear(map, i, j, level, m)?
                {
                    let gj = gi + len * h;
                    if layer.flags[j] & SEEN == 0 || gj < self.g[j] {
                        layer.flags[j] |= SEEN;
                        self.g[j] = gj;
                        self.parent[j] = i as u32 + 1;
                        let hj = self.t.map_or(0.0, |t| {
                            weight * octile(layer.grid.coords(j), layer.grid.coords(t), h)
                        });
                        self.open.push(Open {
                            f: gj + hj,
                            g: gj,
                            cell: j as u32,
                        });
                    }
                }
                self.cur = Some((i, gi, k + 1));
                continue;
            }
            let top = loop {
                match self.open.peek() {
                    None => return Ok(AstarStep::Exhausted),
                    Some(o)
                        if layer.flags[o.cell as usize] & CLOSED != 0
                            || o.g > self.g[o.cell as usize] =>
                    {
                        self.open.pop();
                    }
                    Some(o) => break *o,
                }
            };
            let i = top.cell as usize;
            if Some(i) == self.t {
                return Ok(AstarStep::Reached);
            }
            m.charge()?;
            self.open.pop();
            layer.flags[i] |= CLOSED;
            self.expanded += 1;
            if self.expanded > max_expansions {
                return Ok(AstarStep::Cap);
            }
            let d = (layer.grid.center_of(i) - goal).norm();
            if self.best.is_none_or(|(bd, _)| d < bd) {
                self.best = Some((d, i));
            }
            self.cur = Some((i, top.g, 0));
        }
    }

    /// The cells from the start to `end` (which the search reached).
    fn path(&self, end: usize) -> Vec<usize> {
        let mut path = vec![end];
        let mut cur = end;
        while cur != self.s {
            cur = (self.parent[cur] - 1) as usize;
            path.push(cur);
        }
        path.reverse();
        path
    }
}

/// A breadth-first flood over the cells at least `level` from the obstacles, from one cell
/// toward another: it visits the whole component when the other cell is not in it, and stops
/// when it reaches that cell (or meets the other side's search).
#[derive(Debug, Clone)]
struct Flood {
    flag: u16,
    level: f64,
    /// Edges must be clear at `level` (a route); `false`: face neighbours within
    /// [`Flood::slack`] of `level` whose shared face may hold a point at `level` join (a relaxed
    /// flood, an over-approximation of the free space for a proof).
    exact: bool,
    /// For a relaxed flood: the distance from the bounds to the outer cell centres per axis.
    margins: [f64; 3],
    target: usize,
    open: Queue,
    cur: Option<(usize, usize)>,
}

/// A flood's cells to expand.
#[derive(Debug, Clone)]
enum Queue {
    /// First in, first out: for the proofs, whose order does not matter; O(1) where a heap
    /// over a large frontier misses the caches.
    Fifo(VecDeque<u32>),
    /// Nearest to the target first: for a flood expected to leak toward the other side (the
    /// cause's), which then heads there instead of filling the world.
    Greedy(BinaryHeap<Open>),
}

impl Queue {
    fn push(&mut self, cell: usize, grid: &Grid, target: usize) {
        match self {
            Self::Fifo(q) => q.push_back(cell as u32),
            Self::Greedy(h) => h.push(Open {
                f: octile(grid.coords(cell), grid.coords(target), 1.0),
                g: 0.0,
                cell: cell as u32,
            }),
        }
    }

    fn front(&self) -> Option<usize> {
        match self {
            Self::Fifo(q) => q.front().map(|&c| c as usize),
            Self::Greedy(h) => h.peek().map(|o| o.cell as usize),
        }
    }

    fn pop(&mut self) {
        match self {
            Self::Fifo(q) => {
                q.pop_front();
            }
            Self::Greedy(h) => {
                h.pop();
            }
        }
    }
}

enum FloodStep {
    Expanded,
    Reached,
    Met,
    Exhausted,
}

impl Flood {
    fn new(
        layer: &mut Layer,
        from: usize,
        target: usize,
        flag: u16,
        level: f64,
        exact: bool,
        greedy: bool,
    ) -> Self {
        layer.flags[from] |= flag;
        let mut open = if greedy {
            Queue::Greedy(BinaryHeap::new())
        } else {
            Queue::Fifo(VecDeque::new())
        };
        open.push(from, &layer.grid, target);
        Self {
            flag,
            level,
            exact,
            margins: [0.0; 3],
            target,
            open,
            cur: None,
        }
    }

    /// How far below `level` cell `i`'s centre may be: 0 for an exact flood; for a relaxed one
    /// the largest distance from a point of the bounds in the cell's Voronoi cube to its
    /// centre: `h·√3/2`, more for the outer cells (the bounds lie up to `h` beyond them).
    fn slack(&self, grid: &Grid, i: usize) -> f64 {
        if self.exact {
            return 0.0;
        }
        let c = grid.coords(i);
        (0..3)
            .map(|a| {
                let outer = c[a] == 0 || c[a] as usize + 1 == grid.dims[a];
                let w = if outer {
                    self.margins[a].max(0.5 * grid.h)
                } else {
                    0.5 * grid.h
                };
                w * w
            })
            .sum::<f64>()
            .sqrt()
    }

    /// One expansion (charged [`FLOOD_EXPANSION_PARTS`]; the cells' distances come from the
    /// balls' bounds where they settle them, [`Layer::at_least`]). `met(i)`: cell `i` is known
    /// to be reachable from the other side.
    fn step(
        &mut self,
        layer: &mut Layer,
        map: &StaticMap,
        m: &mut Meter,
        balls: &Balls,
        met: impl Fn(&Layer, usize) -> bool,
    ) -> Result<FloodStep, Paused> {
        let steps: &[([i64; 3], f64)] = if self.exact {
            &*NEIGHBOUR_STEPS
        } else {
            &FACE_STEPS
        };
        loop {
            if let Some((i, k)) = self.cur {
                let Some(&(d, _)) = steps.get(k) else {
                    self.cur = None;
                    return Ok(FloodStep::Expanded);
                };
                let c = layer.grid.coords(i);
                if let Some(j) = layer.grid.index([c[0] + d[0], c[1] + d[1], c[2] + d[2]])
                    && layer.flags[j] & self.flag == 0
                    && layer.at_least(map, j, self.level - self.slack(&layer.grid, j), balls, m)?
                    && (if self.exact {
                        layer.edge_clear_bounded(map, i, j, self.level, balls, m)?
                    } else {
                        // A path crossing between the two cubes crosses their shared face.
                        layer.face_open(map, i, j, self.level, balls, m)?
                    })
                {
                    layer.flags[j] |= self.flag;
                    self.open.push(j, &layer.grid, self.target);
                }
                self.cur = Some((i, k + 1));
                continue;
            }
            let Some(i) = self.open.front() else {
                return Ok(FloodStep::Exhausted);
            };
            if i == self.target {
                return Ok(FloodStep::Reached);
            }
            if met(layer, i) {
                return Ok(FloodStep::Met);
            }
            m.charge_parts(if self.exact {
                FLOOD_EXPANSION_PARTS * 2
            } else {
                FLOOD_EXPANSION_PARTS
            })?;
            self.open.pop();
            self.cur = Some((i, 0));
        }
    }
}

/// The six face neighbours of a cell (the relaxed floods' steps).
const FACE_STEPS: [([i64; 3], f64); 6] = [
    ([-1, 0, 0], 1.0),
    ([1, 0, 0], 1.0),
    ([0, -1, 0], 1.0),
    ([0, 1, 0], 1.0),
    ([0, 0, -1], 1.0),
    ([0, 0, 1], 1.0),
];

/// Parts of a unit ([`crate::grid::PARTS_PER_UNIT`]) charged per expansion of a relaxed flood
/// (six neighbours whose bounds are mostly known); an exact flood's (26 neighbours and their
/// edges) is charged twice that. Measured with `cargo run --release -p trust-route --example
/// route_timing` (decision 0019).
const FLOOD_EXPANSION_PARTS: u32 = 16;

/// Units of work a search keeps the turn for before the next one's ([`RouteSearch`]: the A*,
/// the goal-side and the start-side relaxed floods take turns).
const TURN_UNITS: usize = 32;

/// A flood's turn once a proof has become unlikely ([`RouteSearch`]'s `unlikely`): the A*
/// then gets four fifths of the work.
const UNLIKELY_TURN_UNITS: usize = 8;

/// How much coarser than the fine grid the layer is on which the relaxed floods try a proof
/// first: 8 times fewer cells. The over-approximation stays sound at any cell size; a coarser
/// one only leaks through thinner walls (walls thinner than about `(2.7·h − 2c)` between
/// cells of size `h`), and then the floods start again on the fine grid.
const VERDICT_COARSENING: f64 = 2.0;

/// A relaxed flood at clearance `c` from cell `from` toward cell `to`, flagging `flag`.
fn relaxed_flood(
    layer: &mut Layer,
    map: &StaticMap,
    from: usize,
    to: usize,
    flag: u16,
    c: f64,
    greedy: bool,
) -> Flood {
    let grid = layer.grid;
    let margins: [f64; 3] = std::array::from_fn(|a| grid.origin[a] - map.bounds().min[a]);
    Flood {
        margins,
        ..Flood::new(layer, from, to, flag, c, false, greedy)
    }
}

/// What to do with a route once its shortcut is done.
#[derive(Debug, Clone, Copy, PartialEq)]
enum After {
    /// The coarse search's route: refine it or answer with it.
    Coarse,
    /// The fine search's route: the answer.
    Fine,
    /// The refining fine search's route: the shorter of it and the coarse one.
    Refined,
    /// The route to the nearest point, for a verdict.
    Nearest(UnreachableCause),
}

/// The greedy line-of-sight shortcut, resumable: from each kept point, jump to the farthest
/// following point reachable by a straight segment clear at the clearance (stopping at the first
/// that is not), or to the next point if none is.
#[derive(Debug, Clone)]
struct Finishing {
    after: After,
    points: Vec<Vec3>,
    out: Vec<Vec3>,
    anchor: usize,
    j: usize,
    cell_m: f64,
    expanded: usize,
    goal_included: bool,
}

impl Finishing {
    fn run(&mut self, map: &StaticMap, clearance: f64, m: &mut Meter) -> Result<(), Paused> {
        let last = self.points.len().saturating_sub(1);
        while self.anchor < last {
            if self.j < last {
                m.charge_sight((self.points[self.j + 1] - self.points[self.anchor]).norm())?;
                if map.segment_clear(
                    &self.points[self.anchor],
                    &self.points[self.j + 1],
                    clearance,
                ) {
                    self.j += 1;
                    continue;
                }
            }
            self.out.push(self.points[self.j]);
            self.anchor = self.j;
            self.j = self.anchor + 1;
        }
        Ok(())
    }
}

/// Drops consecutive duplicates and interior points collinear with their neighbours.
pub(crate) fn simplify(points: Vec<Vec3>) -> Vec<Vec3> {
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

impl RouteSearch {
    /// A search from `start` to `goal` (both checked finite and in scale; `start` in bounds);
    /// nothing is evaluated until [`RouteSearch::advance`].
    pub(crate) fn new(
        params: RouteParams,
        map: &StaticMap,
        start: Vec3,
        goal: Vec3,
        radius: f64,
    ) -> Self {
        let clearance = params.clearance_for(radius);
        Self {
            target: map.bounds().clamp(&goal),
            goal_in_bounds: map.contains(&goal),
            params,
            radius,
            clearance,
            start,
            goal,
            work: 0,
            done: None,
            sd_start: None,
            sd_target: None,
            straight_clear: None,
            straight_pieces: 0,
            prepaid: 0,
            built: false,
            layers: Vec::new(),
            fine: 0,
            coarse: None,
            start_snap: Vec::new(),
            target_snap: Vec::new(),
            escape: None,
            escape_snap: None,
            astar: None,
            expanded_before: 0,
            nearest_before: None,
            goal_flood: None,
            start_flood: None,
            sides: Sides::NotStarted,
            goal_seed: SnapState::NotStarted,
            turn: Turn::Astar,
            turn_end: 0,
            astar_exhausted: false,
            unlikely: false,
            cause_flood: None,
            cause_stage: 0,
            verdict_layer: None,
            credit: 0,
            finishing: None,
            coarse_route: None,
            refining: false,
            reached_target: false,
        }
    }

    /// Does at most `budget` units of work (see [`RouteSearch`] for the unit), then returns
    /// [`RouteProgress::Pending`] or the answer. Once answered, every later call returns the
    /// same answer at no cost.
    pub fn advance(&mut self, map: &StaticMap, budget: usize) -> RouteProgress {
        if let Some(done) = &self.done {
            return done.clone();
        }
        let mut m = Meter {
            work: self.work,
            limit: self.work.saturating_add(budget),
            prepaid: self.prepaid,
            credit: self.credit,
        };
        let r = self.drive(map, &mut m);
        self.work = m.work;
        self.prepaid = m.prepaid;
        self.credit = m.credit;
        match r {
            Ok(mut answer) => {
                if let RouteProgress::Unreachable(u) = &mut answer {
                    u.work_done = self.work;
                }
                self.done = Some(answer.clone());
                answer
            }
            Err(Paused) => RouteProgress::Pending,
        }
    }

    /// Units of work done so far.
    pub fn work_done(&self) -> usize {
        self.work
    }

    /// Cells expanded so far by the start-side searches.
    pub fn expanded_count(&self) -> usize {
        self.expanded_before + self.astar.as_ref().map_or(0, |a| a.expanded)
    }

    /// True once the search holds its answer.
    pub fn is_done(&self) -> bool {
        self.done.is_some()
    }

    /// The inflated clearance the route keeps, in metres.
    pub fn clearance_m(&self) -> f64 {
        self.clearance
    }

    /// True if the search's route ended at the free point next to a goal buried in an obstacle
    /// (the [`Unreachable::nearest`] of a [`UnreachableCause::GoalInsideObstacle`] then reaches
    /// as near the goal as the map allows).
    pub(crate) fn reached_target(&self) -> bool {
        self.reached_target
    }

    /// The snap bound for an end at signed distance `sd` on a grid of cells `h`.
    fn snap_bound(&self, sd: f64, level: f64, h: f64) -> f64 {
        let snap = self.params.snap_radius_factor * self.clearance;
        if sd >= level { snap.max(4.0 * h) } else { snap }
    }

    fn snap_cursor(&self, grid: &Grid, p: &Vec3, sd: f64, level: f64) -> SnapCursor {
        let sight = if sd >= level {
            Some(level)
        } else if sd > 0.0 {
            Some((sd.min(level) - SNAP_TOLERANCE_M).max(0.0))
        } else {
            None
        };
        SnapCursor::new(grid, p, self.snap_bound(sd, level, grid.h), level, sight)
    }

    /// Runs the snap of `which` end on layer `ix` at the inflated clearance.
    fn snap(
        &mut self,
        map: &StaticMap,
        m: &mut Meter,
        ix: usize,
        which: Endpoint,
    ) -> Result<Option<usize>, Paused> {
        let (p, sd) = match which {
            Endpoint::Start => (self.start, self.sd_start.unwrap_or(f64::NEG_INFINITY)),
            Endpoint::Goal => (self.target, self.sd_target.unwrap_or(f64::NEG_INFINITY)),
        };
        let state = match which {
            Endpoint::Start => &self.start_snap[ix],
            Endpoint::Goal => &self.target_snap[ix],
        };
        let mut cursor = match state {
            SnapState::Done(r) => return Ok(*r),
            SnapState::Running(c) => c.clone(),
            SnapState::NotStarted => {
                self.snap_cursor(&self.layers[ix].grid, &p, sd, self.clearance)
            }
        };
        let r = cursor.run(&mut self.layers[ix], map, &p, m);
        let slot = match which {
            Endpoint::Start => &mut self.start_snap[ix],
            Endpoint::Goal => &mut self.target_snap[ix],
        };
        *slot = match r {
            Ok(cell) => SnapState::Done(cell),
            Err(Paused) => SnapState::Running(cursor),
        };
        r
    }

    /// The goal-side cause known from the ends alone.
    fn goal_cause(&self, sd_target: f64) -> Option<UnreachableCause> {
        if !self.goal_in_bounds {
            Some(UnreachableCause::GoalOutsideBounds)
        } else if sd_target < self.radius {
            Some(UnreachableCause::GoalInsideObstacle {
                signed_distance_m: sd_target,
            })
        } else {
            None
        }
    }

    /// Builds the grids; `Err` with the answer when there is none to search on.
    fn build(&mut self, map: &StaticMap) -> Result<(), RouteError> {
        let p = &self.params;
        let c = self.clearance;
        let esdf_half = map.esdf().map_or(0.0, |e| 0.5 * e.resolution());
        let h0 = (c / p.cells_per_clearance).max(esdf_half);
        if h0 <= 0.0 {
            // A zero radius and margin on a map without an ESDF: no length to derive a grid from.
            return Err(RouteError::InvalidParam {
                field: "radius_m".to_owned(),
                value: self.radius,
                expected: "a positive inflated clearance (radius or margin > 0) for a grid search"
                    .to_owned(),
            });
        }
        let fine = Grid::new(map.bounds(), h0, p.max_cells, h0 * p.max_coarsening);
        let coarse = (p.coarse_factor > 1.0).then(|| {
            let h = h0 * p.coarse_factor;
            Grid::new(map.bounds(), h, p.max_cells, h * p.max_coarsening)
        });
        match (fine, coarse) {
            (Ok(f), Some(Ok(cg))) => {
                // Refinement after a coarse route only on an unrefined fine grid small enough.
                self.layers = vec![Layer::new(f, map), Layer::new(cg, map)];
                self.coarse = Some(1);
            }
            (Ok(f), _) => self.layers = vec![Layer::new(f, map)],
            (Err(_), Some(Ok(cg))) => self.layers = vec![Layer::new(cg, map)],
            (Err(e), _) => return Err(e),
        }
        self.fine = 0;
        // Cells larger than the clearance leak through walls thinner than 0.7·c: no layer
        // coarser than that (E4's fine grid, coarsened to fit, is already about c).
        let vh = self.layers[0].grid.h * VERDICT_COARSENING;
        if vh <= c * (1.0 + 1e-9)
            && let Ok(vg) = Grid::new(map.bounds(), vh, p.max_cells, vh)
        {
            self.layers.push(Layer::new(vg, map));
            self.verdict_layer = Some(self.layers.len() - 1);
        }
        self.start_snap = vec![SnapState::NotStarted; self.layers.len()];
        self.target_snap = vec![SnapState::NotStarted; self.layers.len()];
        self.built = true;
        Ok(())
    }

    fn h0(&self, map: &StaticMap) -> f64 {
        let esdf_half = map.esdf().map_or(0.0, |e| 0.5 * e.resolution());
        (self.clearance / self.params.cells_per_clearance).max(esdf_half)
    }

    /// True if a coarse route is to be refined on the fine grid.
    fn refine_allowed(&self, map: &StaticMap) -> bool {
        let p = &self.params;
        let g = &self.layers[self.fine].grid;
        self.coarse.is_some()
            && g.h == self.h0(map)
            && g.cells() <= p.refine_max_cells.min(p.max_cells)
    }

    /// The whole search as a function of its memoised state: returns the answer, or `Paused`.
    fn drive(&mut self, map: &StaticMap, m: &mut Meter) -> Result<RouteProgress, Paused> {
        let c = self.clearance;
        let sd_start = match self.sd_start {
            Some(v) => v,
            None => {
                m.charge()?;
                *self.sd_start.insert(map.signed_distance(&self.start))
            }
        };
        let sd_target = match self.sd_target {
            Some(v) => v,
            None => {
                m.charge()?;
                *self.sd_target.insert(map.signed_distance(&self.target))
            }
        };
        let cause = self.goal_cause(sd_target);
        if cause.is_none() && sd_start >= c && sd_target >= c {
            let clear = match self.straight_clear {
                Some(v) => v,
                None => {
                    // In pieces of `SIGHT_UNIT_M`, one unit each, so that a long line of sight
                    // (a 600 m trip across a city) is spread over the slices like the rest.
                    let d = self.goal - self.start;
                    let pieces = ((d.norm() / SIGHT_UNIT_M).ceil() as usize).clamp(1, 1 << 20);
                    let mut clear = true;
                    while self.straight_pieces < pieces {
                        m.charge()?;
                        let k = self.straight_pieces as f64;
                        let a = self.start + d * (k / pieces as f64);
                        let b = self.start + d * ((k + 1.0) / pieces as f64);
                        if !map.segment_clear(&a, &b, c) {
                            clear = false;
                            break;
                        }
                        self.straight_pieces += 1;
                    }
                    *self.straight_clear.insert(clear)
                }
            };
            if clear {
                let points = simplify(vec![self.start, self.goal]);
                return Ok(RouteProgress::Found(GlobalRoute::new(
                    points, c, None, 0, false, 0.0,
                )));
            }
        }
        if !self.built
            && let Err(e) = self.build(map)
        {
            return Ok(RouteProgress::Failed(e));
        }
        let fine = self.fine;
        let Some(start_cell) = self.snap(map, m, fine, Endpoint::Start)? else {
            let h = self.layers[fine].grid.h;
            return Ok(RouteProgress::Failed(RouteError::NoFreeCell {
                which: Endpoint::Start,
                point: self.start,
                bound_m: self.snap_bound(sd_start, c, h),
                clearance_m: c,
            }));
        };
        let mut target_cell = self.snap(map, m, fine, Endpoint::Goal)?;
        if target_cell.is_none() && cause.is_some() {
            target_cell = self.escape(map, m)?;
            if target_cell.is_none() {
                return Ok(RouteProgress::Unreachable(Unreachable {
                    cause: cause.unwrap_or(UnreachableCause::SealedOff),
                    nearest: None,
                    work_done: 0,
                }));
            }
        }
        if let Some(ix) = self.coarse {
            let s = self.snap(map, m, ix, Endpoint::Start)?;
            let t = if target_cell.is_some() {
                self.snap(map, m, ix, Endpoint::Goal)?
            } else {
                None
            };
            if s.is_none() || t.is_none() {
                self.coarse = None;
            }
        }
        if self.sides == Sides::NotStarted {
            let goal = match target_cell {
                Some(t) => Some(t),
                None => self.goal_seed(map, m)?,
            };
            self.sides = match goal {
                Some(g) => match self.verdict_layer {
                    Some(v) => {
                        // The cells holding the fine ends' centres (which keep the clearance)
                        // are in the relaxed free space of the coarser layer.
                        let (fg, vg) = (self.layers[fine].grid, self.layers[v].grid);
                        let at = |i: usize| vg.index(vg.nearest_cell(&fg.center_of(i)));
                        match (at(start_cell), at(g)) {
                            (Some(vs), Some(vgoal)) => self.start_floods(map, v, vs, vgoal),
                            _ => self.start_floods(map, fine, start_cell, g),
                        }
                    }
                    None => self.start_floods(map, fine, start_cell, g),
                },
                None => Sides::Proved {
                    layer: fine,
                    side: Endpoint::Goal,
                    from: None,
                    to: Some(start_cell),
                },
            };
            self.turn_end = m.work + TURN_UNITS;
        }
        loop {
            if let Some(f) = &mut self.finishing {
                f.run(map, c, m)?;
                let f = self.finishing.take().expect("finishing");
                if let Some(answer) = self.finished(map, f, cause) {
                    return Ok(answer);
                }
                continue;
            }
            if let Sides::Proved {
                layer,
                side,
                from,
                to,
            } = self.sides
            {
                let verdict = match cause {
                    Some(cause) => cause,
                    None => {
                        // The same ends on the fine layer, for the cause's later stages.
                        let goal = match target_cell {
                            Some(t) => Some(t),
                            None => self.goal_seed(map, m)?,
                        };
                        let fine_ends = match (side, goal) {
                            (Endpoint::Start, g) => (start_cell, g),
                            (Endpoint::Goal, Some(g)) => (g, Some(start_cell)),
                            (Endpoint::Goal, None) => (start_cell, None),
                        };
                        self.cause_of(map, m, layer, side, (from, to), fine_ends)?
                    }
                };
                self.sides = Sides::Joined;
                if let Some(answer) = self.verdict(verdict) {
                    return Ok(answer);
                }
                continue;
            }
            let running = matches!(self.sides, Sides::Running { .. });
            if self.astar_exhausted && !running {
                // The start's side ran dry on the grid, the relaxed floods met: a passage the
                // grid cannot resolve may keep the clearance.
                if let Some(cause) = cause {
                    if let Some(answer) = self.verdict(cause) {
                        return Ok(answer);
                    }
                    continue;
                }
                return Ok(RouteProgress::Failed(RouteError::Unresolved {
                    clearance_m: c,
                    cell_m: self.layers[fine].grid.h,
                }));
            }
            if !running {
                self.turn = Turn::Astar;
            } else if (self.turn == Turn::Astar && self.astar_exhausted)
                || (self.turn == Turn::Start && self.start_flood.is_none())
            {
                // The A* ran dry, or the start side's flood is not (or no longer) running.
                self.pass_turn(m.work);
            }
            if let (
                Sides::Running {
                    layer: ix,
                    start,
                    goal,
                },
                Turn::Goal | Turn::Start,
            ) = (self.sides, self.turn)
            {
                let balls = self.balls(ix);
                let coarse = self.coarse.filter(|_| !self.refining);
                // The flood's layer, and the A*'s layers (fine, coarse) to read from.
                let (mut layer, mut fine_l, mut coarse_l) = (None, None, None);
                for (k, l) in self.layers.iter_mut().enumerate() {
                    if k == ix {
                        layer = Some(l);
                    } else if k == fine {
                        fine_l = Some(&*l);
                    } else if Some(k) == coarse {
                        coarse_l = Some(&*l);
                    }
                }
                let layer = layer.expect("the flood's layer");
                let (side, step) = if self.turn == Turn::Goal {
                    let flood = self.goal_flood.as_mut().expect("goal flood");
                    let step = flood.step(layer, map, m, &balls, |layer, i| {
                        // The start side's cells, and the A*'s (reached from the start at the
                        // clearance) on its layers: no proof to come from this side.
                        let closed = if ix == fine {
                            CLOSED | FLOOD_S
                        } else {
                            FLOOD_S
                        };
                        if layer.flags[i] & closed != 0 {
                            return true;
                        }
                        let p = layer.grid.center_of(i);
                        [fine_l, coarse_l].into_iter().flatten().any(|al| {
                            let q = al.grid.nearest_cell(&p);
                            al.grid.index(q).is_some_and(|j| al.flags[j] & CLOSED != 0)
                        })
                    })?;
                    ((Endpoint::Goal, goal, start), step)
                } else {
                    let flood = self.start_flood.as_mut().expect("start flood");
                    let step = flood.step(layer, map, m, &balls, |layer, i| {
                        layer.flags[i] & FLOOD_G != 0
                    })?;
                    ((Endpoint::Start, start, goal), step)
                };
                match step {
                    FloodStep::Expanded => {
                        if m.work >= self.turn_end {
                            self.pass_turn(m.work);
                        }
                    }
                    // The coarser layer could not separate the sides: try the fine one.
                    FloodStep::Reached | FloodStep::Met if ix != fine => {
                        let g = match target_cell {
                            Some(t) => Some(t),
                            None => self.goal_seed(map, m)?,
                        };
                        self.unlikely = true;
                        self.sides = match g {
                            Some(g) => self.start_floods(map, fine, start_cell, g),
                            None => Sides::Joined,
                        };
                    }
                    FloodStep::Reached | FloodStep::Met => self.sides = Sides::Joined,
                    FloodStep::Exhausted => {
                        let (side, from, to) = side;
                        self.sides = Sides::Proved {
                            layer: ix,
                            side,
                            from: Some(from),
                            to: Some(to),
                        };
                    }
                }
                continue;
            }
            if self.astar.is_none() {
                let (ix, s, t) = match self.coarse {
                    Some(ix) if !self.refining => (
                        ix,
                        self.snap(map, m, ix, Endpoint::Start)?.unwrap_or(0),
                        self.snap(map, m, ix, Endpoint::Goal)?,
                    ),
                    _ => (fine, start_cell, target_cell),
                };
                let w = self.params.heuristic_weight;
                self.astar = Some(Astar::new(ix, &mut self.layers[ix], s, t, w));
            }
            let astar = self.astar.as_mut().expect("astar");
            let ix = astar.layer;
            let step = astar.step(
                &mut self.layers[ix],
                map,
                m,
                c,
                self.params.heuristic_weight,
                self.params.max_expansions,
                &self.goal,
            )?;
            match step {
                AstarStep::Expanded => {
                    if running && m.work >= self.turn_end {
                        self.pass_turn(m.work);
                    }
                }
                AstarStep::Reached => {
                    let astar = self.astar.take().expect("astar");
                    let t = astar.t.expect("reached target");
                    let after = if Some(ix) == self.coarse && !self.refining {
                        After::Coarse
                    } else if self.refining {
                        After::Refined
                    } else {
                        After::Fine
                    };
                    if running {
                        self.sides = Sides::Joined;
                    }
                    self.reached_target = cause.is_some();
                    let grid = self.layers[ix].grid;
                    let expanded = astar.expanded;
                    self.finishing = Some(self.finishing_for(
                        after,
                        &grid,
                        &astar.path(t),
                        expanded,
                        cause.is_none() && sd_target >= c,
                    ));
                }
                AstarStep::Exhausted if Some(ix) == self.coarse && !self.refining => {
                    // The coarse grid closes passages: its exhaustion is no verdict.
                    let astar = self.astar.take().expect("astar");
                    self.keep_nearest(&astar);
                    self.coarse = None;
                }
                AstarStep::Exhausted | AstarStep::Cap if self.refining => {
                    let astar = self.astar.take().expect("astar");
                    self.expanded_before += astar.expanded;
                    let coarse = self.coarse_route.take().expect("coarse route");
                    return Ok(self.wrap(coarse, cause));
                }
                AstarStep::Exhausted => {
                    if let Some(cause) = cause {
                        if let Some(answer) = self.verdict(cause) {
                            return Ok(answer);
                        }
                        continue;
                    }
                    // The floods decide: a proof, or no verdict when they meet. The start side's
                    // flood on the fine layer starts now.
                    self.astar_exhausted = true;
                    if let Sides::Running { layer, start, goal } = self.sides
                        && self.start_flood.is_none()
                    {
                        let l = &mut self.layers[layer];
                        self.start_flood =
                            Some(relaxed_flood(l, map, start, goal, FLOOD_S, c, false));
                    }
                }
                AstarStep::Cap => {
                    return Ok(RouteProgress::Failed(RouteError::ExpansionCap {
                        cap: self.params.max_expansions,
                    }));
                }
            }
        }
    }

    /// Leaves an obstacle that buries the goal along the distance gradient, then takes the
    /// nearest free cell of the fine grid.
    fn escape(&mut self, map: &StaticMap, m: &mut Meter) -> Result<Option<usize>, Paused> {
        let c = self.clearance;
        let fine = self.fine;
        let h = self.layers[fine].grid.h;
        loop {
            let (p, n, out) = self.escape.unwrap_or((self.target, 0, false));
            if out || n >= MAX_ESCAPE_STEPS {
                break;
            }
            m.charge()?;
            let (d, g) = map.distance_and_gradient(&p);
            let next = if d >= c || g.norm() == 0.0 || !d.is_finite() {
                (p, n + 1, true)
            } else {
                let q = map.bounds().clamp(&(p + g.normalize() * (c + h - d)));
                (q, n + 1, false)
            };
            self.escape = Some(next);
        }
        let (p, _, _) = self.escape.unwrap_or((self.target, 0, true));
        let mut cursor = match self.escape_snap.take() {
            Some(SnapState::Done(r)) => {
                self.escape_snap = Some(SnapState::Done(r));
                return Ok(r);
            }
            Some(SnapState::Running(c)) => c,
            _ => SnapCursor::new(&self.layers[fine].grid, &p, 4.0 * h, c, None),
        };
        let r = cursor.run(&mut self.layers[fine], map, &p, m);
        self.escape_snap = Some(match r {
            Ok(cell) => SnapState::Done(cell),
            Err(Paused) => SnapState::Running(cursor),
        });
        r
    }

    /// Keeps the nearest cell to the goal of a finished A* if it beats the one kept.
    fn keep_nearest(&mut self, astar: &Astar) {
        self.expanded_before += astar.expanded;
        if let Some((d, cell)) = astar.best
            && self
                .nearest_before
                .as_ref()
                .is_none_or(|(bd, _, _)| d < *bd)
        {
            let grid = self.layers[astar.layer].grid;
            self.nearest_before = Some((d, grid, astar.path(cell)));
        }
    }

    fn finishing_for(
        &self,
        after: After,
        grid: &Grid,
        cells: &[usize],
        expanded: usize,
        goal_included: bool,
    ) -> Finishing {
        let mut points = Vec::with_capacity(cells.len() + 2);
        points.push(self.start);
        points.extend(cells.iter().map(|&i| grid.center_of(i)));
        if goal_included {
            points.push(self.goal);
        }
        let points = simplify(points);
        let (out, anchor, j) = if self.params.shortcut {
            (vec![points[0]], 0, 1)
        } else {
            (points.clone(), points.len(), points.len())
        };
        Finishing {
            after,
            points,
            out,
            anchor,
            j,
            cell_m: grid.h,
            expanded,
            goal_included,
        }
    }

    /// The route of a finished shortcut, and the answer if it is one.
    fn finished(
        &mut self,
        map: &StaticMap,
        f: Finishing,
        cause: Option<UnreachableCause>,
    ) -> Option<RouteProgress> {
        let points = simplify(f.out);
        let end = points.last().copied().unwrap_or(self.start);
        let gap = if f.goal_included {
            0.0
        } else {
            (end - self.goal).norm()
        };
        let inside = self.sd_start.is_none_or(|d| d < self.clearance);
        let route = GlobalRoute::new(
            points,
            self.clearance,
            Some(f.cell_m),
            f.expanded,
            inside,
            gap,
        );
        match f.after {
            After::Coarse if self.refine_allowed(map) => {
                self.coarse_route = Some(route);
                self.refining = true;
                None
            }
            After::Coarse | After::Fine => {
                let mut route = route;
                route.add_expanded(self.expanded_before);
                Some(self.wrap(route, cause))
            }
            After::Refined => {
                let coarse = self.coarse_route.take().expect("coarse route");
                let (mut keep, other) = if route.length() < coarse.length() {
                    (route, coarse)
                } else {
                    (coarse, route)
                };
                keep.add_expanded(other.expanded_count() + self.expanded_before);
                Some(self.wrap(keep, cause))
            }
            After::Nearest(cause) => Some(RouteProgress::Unreachable(Unreachable {
                cause,
                nearest: Some(route),
                work_done: 0,
            })),
        }
    }

    fn wrap(&self, route: GlobalRoute, cause: Option<UnreachableCause>) -> RouteProgress {
        match cause {
            None => RouteProgress::Found(route),
            Some(cause) => RouteProgress::Unreachable(Unreachable {
                cause,
                nearest: Some(route),
                work_done: 0,
            }),
        }
    }

    /// Starts the route to the nearest cell for a verdict (`None`: the caller's loop runs its
    /// shortcut), or the answer at once when the search expanded nothing.
    fn verdict(&mut self, cause: UnreachableCause) -> Option<RouteProgress> {
        if let Some(astar) = self.astar.take() {
            self.keep_nearest(&astar);
        }
        match self.nearest_before.take() {
            Some((_, grid, cells)) => {
                self.finishing = Some(self.finishing_for(
                    After::Nearest(cause),
                    &grid,
                    &cells,
                    self.expanded_before,
                    false,
                ));
                None
            }
            None => Some(RouteProgress::Unreachable(Unreachable {
                cause,
                nearest: None,
                work_done: 0,
            })),
        }
    }

    /// The levels the floods test cells at ([`Balls`]): down to the relaxed floods'
    /// `c − h·√3/2` (or the radius, if lower), up to the clearance.
    fn balls(&self, layer: usize) -> Balls {
        let h = self.layers[layer].grid.h;
        let c = self.clearance;
        Balls {
            low: c.min(self.radius) - h * 3.0_f64.sqrt() / 2.0,
            high: c,
        }
    }

    /// Starts the relaxed floods at the clearance on layer `ix`, from cells `start` and `goal`
    /// of that layer. On the coarser verdict layer both run beside the A* (a cheap screen);
    /// on the fine layer only the goal side's does, the start side's once the A* (which
    /// explores the start's side at the clearance) has run dry: in the common case, a goal
    /// that can be reached, a fine start-side flood would only slow the A* down.
    fn start_floods(&mut self, map: &StaticMap, ix: usize, start: usize, goal: usize) -> Sides {
        let c = self.clearance;
        let both = self.astar_exhausted;
        let layer = &mut self.layers[ix];
        self.goal_flood = Some(relaxed_flood(layer, map, goal, start, FLOOD_G, c, false));
        self.start_flood = both.then(|| relaxed_flood(layer, map, start, goal, FLOOD_S, c, false));
        Sides::Running {
            layer: ix,
            start,
            goal,
        }
    }

    /// Passes the turn to the next search: the A* (unless it ran dry), the goal-side flood,
    /// the start-side flood (if it runs).
    fn pass_turn(&mut self, work: usize) {
        let start = self.start_flood.is_some();
        self.turn = match self.turn {
            Turn::Astar => Turn::Goal,
            Turn::Goal if start => Turn::Start,
            Turn::Goal | Turn::Start if self.astar_exhausted => Turn::Goal,
            Turn::Goal | Turn::Start => Turn::Astar,
        };
        let short = self.unlikely && self.turn != Turn::Astar && !self.astar_exhausted;
        self.turn_end = work
            + if short {
                UNLIKELY_TURN_UNITS
            } else {
                TURN_UNITS
            };
    }

    /// The goal flood's first cell when no cell at the clearance joins the goal: the nearest
    /// cell at the radius (the old snap rules), `None` if there is none.
    fn goal_seed(&mut self, map: &StaticMap, m: &mut Meter) -> Result<Option<usize>, Paused> {
        let fine = self.fine;
        let mut cur = match std::mem::replace(&mut self.goal_seed, SnapState::NotStarted) {
            SnapState::Done(r) => {
                self.goal_seed = SnapState::Done(r);
                return Ok(r);
            }
            SnapState::Running(cur) => cur,
            SnapState::NotStarted => {
                let grid = self.layers[fine].grid;
                let sd = self.sd_target.unwrap_or(f64::NEG_INFINITY);
                self.snap_cursor(&grid, &self.target, sd, self.radius)
            }
        };
        let r = cur.run(&mut self.layers[fine], map, &self.target, m);
        self.goal_seed = match r {
            Ok(cell) => SnapState::Done(cell),
            Err(Paused) => SnapState::Running(cur),
        };
        r
    }

    /// The cause of a proved verdict: the relaxed flood at the clearance from `side` ran dry
    /// on layer `ix`, which proves that no path keeps `c`. The relaxed flood takes every cell
    /// whose centre is at least `c − h·√3/2` from the obstacles (less at the outer cells, whose
    /// cubes reach the bounds) and joins two face neighbours when the centre of their shared
    /// face is at least `c − h/√2` from them: every point at least `c` from the obstacles lies
    /// in such a cell's Voronoi cube, and a path through free space passes from cube to cube
    /// through shared faces (1-Lipschitz distance: a face point at `c` puts the face centre
    /// within `h/√2` of it), so an exhausted relaxed flood proves that no path keeps `c`, at any
    /// resolution (up to the rounding of the distance queries). Bounds stamped by balls only
    /// ever admit a cell or face the query would have admitted. The cause then comes from the
    /// same relaxed flood at the radius (on the proof's layer, then on the fine one):
    /// `SealedOff` if it runs dry (proved: no path keeps the radius); else from an exact flood
    /// at the radius on the fine layer: `TooNarrow` if it joins the sides (a path keeping the
    /// radius exists), `SealedOff` if not (none that the fine grid resolves).
    fn cause_of(
        &mut self,
        map: &StaticMap,
        m: &mut Meter,
        ix: usize,
        side: Endpoint,
        (from, to): (Option<usize>, Option<usize>),
        (ffrom, fto): (usize, Option<usize>),
    ) -> Result<UnreachableCause, Paused> {
        let (c, r) = (self.clearance, self.radius);
        let (Some(from), Some(to)) = (from, to) else {
            return Ok(UnreachableCause::SealedOff);
        };
        if r >= c {
            return Ok(UnreachableCause::SealedOff);
        }
        let fine = self.fine;
        let Some(fto) = fto else {
            return Ok(UnreachableCause::SealedOff);
        };
        loop {
            // Stages: the relaxed flood at the radius on the proof's layer, then on the fine
            // layer (if another), then the exact flood at the radius on the fine layer.
            let stage = self.cause_stage;
            let (lx, exact) = match stage {
                0 => (ix, false),
                1 if ix != fine => (fine, false),
                1 => {
                    self.cause_stage = 2;
                    continue;
                }
                _ => (fine, true),
            };
            let (a, b) = if lx == ix { (from, to) } else { (ffrom, fto) };
            let balls = self.balls(lx);
            let layer = &mut self.layers[lx];
            let flood = self.cause_flood.get_or_insert_with(|| {
                if exact {
                    Flood::new(layer, a, b, FLOOD_X, r, true, true)
                } else {
                    relaxed_flood(layer, map, a, b, FLOOD_R, r, true)
                }
            });
            // Cells known to be joined to the other side: its flood's (a relaxed flood at
            // the clearance joins no fewer cells than one at the radius), and on the fine
            // layer the A*'s, joined to the start by edges that keep the clearance.
            let other = match (side, exact) {
                (Endpoint::Goal, false) => FLOOD_S,
                (Endpoint::Start, false) => FLOOD_G,
                (_, true) => 0,
            } | if lx == fine && side == Endpoint::Goal {
                CLOSED
            } else {
                0
            };
            let joined = loop {
                match flood.step(layer, map, m, &balls, |l, i| l.flags[i] & other != 0)? {
                    FloodStep::Expanded => {}
                    FloodStep::Reached | FloodStep::Met => break true,
                    FloodStep::Exhausted => break false,
                }
            };
            self.cause_flood = None;
            if !joined {
                return Ok(UnreachableCause::SealedOff);
            }
            if exact {
                return Ok(UnreachableCause::TooNarrow { clearance_m: c });
            }
            self.cause_stage = stage + 1;
        }
    }
}
