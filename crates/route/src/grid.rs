//! The search grids: cell geometry ([`Grid`]), the lazily evaluated per-cell signed distances and
//! the edge test ([`Layer`]), and the work meter every costly query is charged to ([`Meter`]).

use std::cmp::Ordering;

use trust_geometry::{Aabb, StaticMap};

use crate::Vec3;
use crate::error::RouteError;

/// Bound on how fast the map's signed distance can fall along a line, in metres per metre, on a
/// map with a voxel ESDF: `2√3`, the slope bound of the trilinear interpolant stated by
/// `trust_geometry` (`StaticMap::segment_clear`). Analytic shapes are exact distance functions,
/// hence 1-Lipschitz.
pub(crate) const ESDF_LIPSCHITZ: f64 = 2.0 * 1.732_050_807_568_877_3;

/// The search ran out of its work budget; the step that was about to run is retried by the next
/// [`crate::RouteSearch::advance`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Paused;

/// Counts units of work and refuses one past the current call's limit.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Meter {
    /// Units done since the search started.
    pub(crate) work: usize,
    /// Units this call may reach.
    pub(crate) limit: usize,
    /// Units already paid toward the query that paused the previous slice (kept by the search).
    pub(crate) prepaid: usize,
    /// Parts of a unit bought and not yet spent ([`Meter::charge_parts`], kept by the search).
    pub(crate) credit: u32,
}

impl Meter {
    /// Takes one unit, or reports the budget spent (the caller then does not run the query).
    pub(crate) fn charge(&mut self) -> Result<(), Paused> {
        if self.work >= self.limit {
            Err(Paused)
        } else {
            self.work += 1;
            Ok(())
        }
    }

    /// Takes the units of a line-of-sight query over `len_m` metres: one, plus one per
    /// [`SIGHT_UNIT_M`] (a long segment meets more shapes and ESDF samples). A query dearer
    /// than what is left of the slice is paid over several slices ([`Meter::prepaid`]) and runs
    /// once paid, so no slice exceeds its budget and the total does not depend on the slicing.
    pub(crate) fn charge_sight(&mut self, len_m: f64) -> Result<(), Paused> {
        self.charge_units(1 + (len_m / SIGHT_UNIT_M).clamp(0.0, 1.0e9) as usize)
    }

    /// Takes `units` for one step that runs only once all are paid: paid over several slices
    /// if need be ([`Meter::prepaid`]), so no slice exceeds its budget and the total does not
    /// depend on the slicing. The retried step must reach this call again with nothing changed.
    pub(crate) fn charge_units(&mut self, units: usize) -> Result<(), Paused> {
        while self.prepaid < units {
            if self.work >= self.limit {
                return Err(Paused);
            }
            let take = (units - self.prepaid).min(self.limit - self.work);
            self.work += take;
            self.prepaid += take;
        }
        self.prepaid = 0;
        Ok(())
    }

    /// Takes `parts` [`PARTS_PER_UNIT`]ths of a unit for a cheap step (a flood expansion, a ball
    /// of bounds stamped into the grid): whole units are bought before the step runs and the
    /// change is kept in [`Meter::credit`] (saved by the search), so the total stays an integer
    /// count of units that does not depend on the slicing.
    pub(crate) fn charge_parts(&mut self, parts: u32) -> Result<(), Paused> {
        while self.credit < parts {
            self.charge()?;
            self.credit += PARTS_PER_UNIT;
        }
        self.credit -= parts;
        Ok(())
    }
}

/// Parts of a unit of work that [`Meter::charge_parts`] counts in.
pub(crate) const PARTS_PER_UNIT: u32 = 64;

/// Metres of a line-of-sight query charged as one more unit ([`Meter::charge_sight`]).
pub(crate) const SIGHT_UNIT_M: f64 = 2.0;

/// Cells per side of a storage brick ([`Grid::index`]).
const BRICK: usize = 4;

/// The grid the search runs on: cell centres `origin + h · (i, j, k)`, all inside the bounds.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Grid {
    pub(crate) origin: Vec3,
    pub(crate) h: f64,
    pub(crate) dims: [usize; 3],
}

impl Grid {
    /// The finest grid of cell size at least `h0` with at most `max_cells` cells, centred in
    /// `bounds` with its outer centres at most `h/2` inside them; [`RouteError::TooManyCells`] if that needs cells larger than `max_h`.
    pub(crate) fn new(
        bounds: &Aabb,
        h0: f64,
        max_cells: usize,
        max_h: f64,
    ) -> Result<Self, RouteError> {
        let ext = bounds.extent();
        let count = |h: f64| -> [usize; 3] {
            // Enough cells that the outer centres lie within h/2 of the bounds (every point of
            // the bounds within h·√3/2 of a centre); capped far above any admissible count so
            // the product stays in u128.
            let n = |e: f64| (e / h).ceil().clamp(1.0, 1.0e12) as usize;
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

    /// Bricks per axis ([`BRICK`] cells a side, the last ones padded).
    fn bricks(&self) -> [usize; 3] {
        self.dims.map(|d| d.div_ceil(BRICK))
    }

    /// Length of the per-cell arrays: the cells in bricks of `BRICK³` (the padding cells at
    /// the far faces are never indexed).
    pub(crate) fn len(&self) -> usize {
        self.bricks().iter().product::<usize>() * BRICK * BRICK * BRICK
    }

    /// The number of cells.
    pub(crate) fn cells(&self) -> usize {
        self.dims[0] * self.dims[1] * self.dims[2]
    }

    /// The index of every cell (not the padding).
    #[cfg(test)]
    pub(crate) fn indices(&self) -> impl Iterator<Item = usize> + '_ {
        let [nx, ny, nz] = self.dims.map(|d| d as i64);
        (0..nz).flat_map(move |z| {
            (0..ny).flat_map(move |y| (0..nx).filter_map(move |x| self.index([x, y, z])))
        })
    }

    /// Cells are stored brick by brick (`BRICK³` cells each, x fastest within a brick and
    /// across bricks): a cell's face neighbours mostly share its brick, so a flood or an A*
    /// touches a few cache lines per expansion where a row-major layout touched one per
    /// neighbour in y and z.
    pub(crate) fn index(&self, c: [i64; 3]) -> Option<usize> {
        if (0..3).all(|a| c[a] >= 0 && (c[a] as usize) < self.dims[a]) {
            let [x, y, z] = c.map(|v| v as usize);
            let nb = self.bricks();
            let brick = x / BRICK + nb[0] * (y / BRICK + nb[1] * (z / BRICK));
            let local = x % BRICK + BRICK * (y % BRICK + BRICK * (z % BRICK));
            Some(brick * BRICK * BRICK * BRICK + local)
        } else {
            None
        }
    }

    pub(crate) fn coords(&self, i: usize) -> [i64; 3] {
        let nb = self.bricks();
        let (brick, local) = (i / (BRICK * BRICK * BRICK), i % (BRICK * BRICK * BRICK));
        let b = [
            brick % nb[0],
            (brick / nb[0]) % nb[1],
            brick / (nb[0] * nb[1]),
        ];
        let l = [
            local % BRICK,
            (local / BRICK) % BRICK,
            local / (BRICK * BRICK),
        ];
        [0, 1, 2].map(|a| (b[a] * BRICK + l[a]) as i64)
    }

    pub(crate) fn center(&self, c: [i64; 3]) -> Vec3 {
        self.origin + Vec3::new(c[0] as f64, c[1] as f64, c[2] as f64) * self.h
    }

    pub(crate) fn center_of(&self, i: usize) -> Vec3 {
        self.center(self.coords(i))
    }

    /// The cell whose centre is nearest to `p` (clamped into the grid).
    pub(crate) fn nearest_cell(&self, p: &Vec3) -> [i64; 3] {
        let mut c = [0_i64; 3];
        for a in 0..3 {
            let f = ((p[a] - self.origin[a]) / self.h).round();
            c[a] = f.clamp(0.0, (self.dims[a] - 1) as f64) as i64;
        }
        c
    }
}

/// Exact cost of a 26-connected grid path between cells `a` and `b` in free space (the 3-D
/// octile distance), in metres.
pub(crate) fn octile(a: [i64; 3], b: [i64; 3], h: f64) -> f64 {
    let mut d = [
        (a[0] - b[0]).unsigned_abs() as f64,
        (a[1] - b[1]).unsigned_abs() as f64,
        (a[2] - b[2]).unsigned_abs() as f64,
    ];
    d.sort_by(|x, y| y.total_cmp(x));
    let (d1, d2, d3) = (d[0], d[1], d[2]);
    h * (3.0_f64.sqrt() * d3 + 2.0_f64.sqrt() * (d2 - d3) + (d1 - d2))
}

/// A heap entry: smallest `f` first, then largest `g` (deeper first), then smallest index.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Open {
    pub(crate) f: f64,
    pub(crate) g: f64,
    pub(crate) cell: u32,
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

/// Per-cell flag: the signed distance of the centre is in [`Layer::sd`].
pub(crate) const EVALUATED: u16 = 1;
/// Per-cell flag: expanded by the A* from the start (closed set).
pub(crate) const CLOSED: u16 = 2;
/// Per-cell flag: the A* from the start holds a tentative cost for it.
pub(crate) const SEEN: u16 = 4;
/// Per-cell flag: reached by the relaxed flood at the inflated clearance from the goal.
pub(crate) const FLOOD_G: u16 = 8;
/// Per-cell flag: reached by the exact flood at the vehicle radius (the verdict's cause).
pub(crate) const FLOOD_R: u16 = 16;
/// Per-cell flag: reached by the relaxed flood at the inflated clearance from the start.
pub(crate) const FLOOD_S: u16 = 32;
/// Per-cell flag: [`Layer`]'s stored value is a lower bound on the centre's signed distance
/// stamped by a free ball ([`Layer::query_stamped`]), not (yet) its evaluated value.
pub(crate) const BOUND: u16 = 64;
/// Per-cell flag: an upper bound on the centre's signed distance is stored (a blocked ball).
pub(crate) const UBOUND: u16 = 128;
/// Per-cell flag: reached by the exact flood at the vehicle radius (the verdict's cause when
/// the relaxed one at the radius joins the sides).
pub(crate) const FLOOD_X: u16 = 256;

/// Largest radius of a ball of bounds, in cells (a ball stamps at most `(2k + 1)³` cells).
pub(crate) const MAX_BALL_CELLS: i64 = 10;
/// Cells of a ball's bounding cube stamped per unit of work ([`Layer::query_stamped`]); measured
/// with `cargo run --release -p trust-route --example route_timing` (see decision 0019).
pub(crate) const STAMPED_CELLS_PER_UNIT: u32 = 1024;

/// The 26 neighbour offsets of a cell and their lengths in cells (1, √2 or √3), computed once.
pub(crate) static NEIGHBOUR_STEPS: std::sync::LazyLock<[([i64; 3], f64); 26]> =
    std::sync::LazyLock::new(neighbour_steps);

/// The 26 neighbour offsets of a cell and their lengths in cells (1, √2 or √3).
fn neighbour_steps() -> [([i64; 3], f64); 26] {
    let mut out = [([0; 3], 0.0); 26];
    let mut n = 0;
    for z in -1..=1_i64 {
        for y in -1..=1_i64 {
            for x in -1..=1_i64 {
                if [x, y, z] != [0, 0, 0] {
                    let k = [x, y, z].iter().filter(|&&v| v != 0).count() as f64;
                    out[n] = ([x, y, z], k.sqrt());
                    n += 1;
                }
            }
        }
    }
    out
}

/// A grid with its lazily evaluated cells: each centre's signed distance is computed the first
/// time a search touches it (one unit of work) and kept, rounded down to `f32`. The floods also
/// keep bounds proved by other cells' distances ("balls", [`Layer::query_stamped`]). Every
/// array is zero-initialised, so the OS pages in only the part the searches touch.
#[derive(Debug, Clone)]
pub(crate) struct Layer {
    pub(crate) grid: Grid,
    /// Lower bound on the centre's signed distance: its value under [`EVALUATED`], a bound
    /// stamped by a ball under [`BOUND`].
    sd: Vec<f32>,
    /// Upper bound on the centre's signed distance (valid under [`UBOUND`]).
    ub: Vec<f32>,
    /// [`EVALUATED`], [`CLOSED`], [`SEEN`], [`FLOOD_G`], [`FLOOD_R`], [`FLOOD_S`], [`BOUND`],
    /// [`UBOUND`].
    pub(crate) flags: Vec<u16>,
    /// Slope bound of the map's signed distance ([`ESDF_LIPSCHITZ`] or 1), valid for the
    /// whole map (its shapes and its ESDF alike).
    pub(crate) lipschitz: f64,
    /// The cells (and their distances) whose balls are still to be stamped ([`Layer::flush`]):
    /// at most the two ends of one edge.
    pending: Vec<(usize, f64)>,
}

/// The levels the floods test cells at, which bound the balls worth stamping: lower bounds are
/// stamped while they are at least `low` (the lowest level tested), upper bounds while they are
/// below `high` (the highest).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Balls {
    pub(crate) low: f64,
    pub(crate) high: f64,
}

/// `x` rounded down to `f32` (a lower bound stays one).
fn f32_down(x: f64) -> f32 {
    let mut f = x as f32;
    if f64::from(f) > x {
        f = f.next_down();
    }
    f
}

/// `x` rounded up to `f32` (an upper bound stays one).
fn f32_up(x: f64) -> f32 {
    let mut f = x as f32;
    if f64::from(f) < x {
        f = f.next_up();
    }
    f
}

impl Layer {
    pub(crate) fn new(grid: Grid, map: &StaticMap) -> Self {
        let n = grid.len();
        Self {
            grid,
            sd: vec![0.0; n],
            ub: vec![0.0; n],
            flags: vec![0; n],
            pending: Vec::with_capacity(2),
            lipschitz: if map.esdf().is_some() {
                ESDF_LIPSCHITZ
            } else {
                1.0
            },
        }
    }

    /// The signed distance of cell `i`'s centre (a lower bound within one `f32` rounding),
    /// charging one unit the first time.
    pub(crate) fn sd(&mut self, map: &StaticMap, i: usize, m: &mut Meter) -> Result<f64, Paused> {
        if self.flags[i] & EVALUATED == 0 {
            m.charge()?;
            let d = map.signed_distance(&self.grid.center_of(i));
            self.sd[i] = f32_down(d);
            self.flags[i] |= EVALUATED;
        }
        Ok(f64::from(self.sd[i]))
    }

    /// The best lower bound known on cell `i`'s signed distance without a query.
    fn lower_bound(&self, i: usize) -> Option<f64> {
        (self.flags[i] & (EVALUATED | BOUND) != 0).then(|| f64::from(self.sd[i]))
    }

    /// [`Layer::edge_clear`] for the floods: the bounds the balls proved settle most edges;
    /// else both ends are evaluated, and then one exact [`StaticMap::segment_clear`] if needed.
    pub(crate) fn edge_clear_bounded(
        &mut self,
        map: &StaticMap,
        i: usize,
        j: usize,
        level: f64,
        balls: &Balls,
        m: &mut Meter,
    ) -> Result<bool, Paused> {
        self.flush(balls, m)?;
        let (p, q) = (self.grid.center_of(i), self.grid.center_of(j));
        let len = (q - p).norm();
        if let (Some(a), Some(b)) = (self.lower_bound(i), self.lower_bound(j))
            && 0.5 * (a + b - self.lipschitz * len) >= level
        {
            return Ok(true);
        }
        // Both ends' queries are paid for at once, before either runs: a pause between them
        // would let the next slice's flush stamp the first one's ball and settle the edge by
        // bounds, where an unsliced search queries the second end.
        let unknown = [i, j].map(|c| self.flags[c] & EVALUATED == 0);
        m.charge_units(unknown.iter().filter(|&&u| u).count())?;
        for (c, u) in [i, j].into_iter().zip(unknown) {
            if u {
                self.evaluate_deferred(map, c);
            }
        }
        let (a, b) = (f64::from(self.sd[i]), f64::from(self.sd[j]));
        if 0.5 * (a + b - self.lipschitz * len) >= level {
            return Ok(true);
        }
        m.charge()?;
        Ok(map.segment_clear(&p, &q, level))
    }

    /// For a relaxed flood: may the face shared by neighbour cells `i` and `j` hold a point at
    /// least `level` from the obstacles? Its centre is then at least `level − h/√2` from them
    /// (every point of the face lies within `h/√2` of its centre); the centre lies `h/2` from
    /// both cell centres, so their bounds settle most faces, else one query of the centre.
    pub(crate) fn face_open(
        &mut self,
        map: &StaticMap,
        i: usize,
        j: usize,
        level: f64,
        balls: &Balls,
        m: &mut Meter,
    ) -> Result<bool, Paused> {
        self.flush(balls, m)?;
        let h = self.grid.h;
        let need = level - h / 2.0_f64.sqrt();
        let known = self.lower_bound(i).into_iter().chain(self.lower_bound(j));
        if known.fold(f64::NEG_INFINITY, f64::max) - self.lipschitz * 0.5 * h >= need {
            return Ok(true);
        }
        m.charge()?;
        let mid = 0.5 * (self.grid.center_of(i) + self.grid.center_of(j));
        Ok(map.signed_distance(&mid) >= need)
    }

    /// True if cell `i`'s centre is at least `level` from the obstacles, using the bounds the
    /// balls proved when they settle it and else one query ([`Layer::query_stamped`]).
    pub(crate) fn at_least(
        &mut self,
        map: &StaticMap,
        i: usize,
        level: f64,
        balls: &Balls,
        m: &mut Meter,
    ) -> Result<bool, Paused> {
        self.flush(balls, m)?;
        let f = self.flags[i];
        if f & (EVALUATED | BOUND) != 0 && f64::from(self.sd[i]) >= level {
            return Ok(true);
        }
        if f & EVALUATED != 0 {
            return Ok(false);
        }
        if f & UBOUND != 0 && f64::from(self.ub[i]) < level {
            return Ok(false);
        }
        Ok(self.query_stamped(map, i, m)? >= level)
    }

    /// Evaluates cell `i`'s signed distance `D` (one unit) and stamps the bounds it proves on
    /// the cells around: with the map's slope bound `K`, every centre `q` within `ρ` of the
    /// centre `p` has `D − K·ρ ≤ sd(q) ≤ D + K·ρ`. Lower bounds are stamped out to where they
    /// fall to [`Balls::low`] (a free ball: those cells are free at every level the floods
    /// test), upper bounds out to where they reach [`Balls::high`] (a blocked ball), each at
    /// most [`MAX_BALL_CELLS`] cells; the stamping is charged by the cells it visits.
    pub(crate) fn query_stamped(
        &mut self,
        map: &StaticMap,
        i: usize,
        m: &mut Meter,
    ) -> Result<f64, Paused> {
        if self.flags[i] & EVALUATED != 0 {
            return Ok(f64::from(self.sd[i]));
        }
        m.charge()?;
        Ok(self.evaluate_deferred(map, i))
    }

    /// Evaluates cell `i` (already paid for) and defers its ball. The ball's size is known only
    /// now: it is paid for and stamped at the start of the next operation that reads bounds
    /// ([`Layer::flush`]), before anything else that operation does, so a pause never falls
    /// between a query and a decision that reads the bounds, and the grid's bounds and the
    /// work total do not depend on the slicing.
    fn evaluate_deferred(&mut self, map: &StaticMap, i: usize) -> f64 {
        let d = map.signed_distance(&self.grid.center_of(i));
        self.sd[i] = f32_down(d);
        self.flags[i] = (self.flags[i] & !BOUND) | EVALUATED;
        self.pending.push((i, d));
        d
    }

    /// Stamps the balls of the last queries ([`Layer::query_stamped`]) still to be paid for.
    /// Every operation that reads bounds calls it first, and nothing else before it.
    pub(crate) fn flush(&mut self, balls: &Balls, m: &mut Meter) -> Result<(), Paused> {
        while let Some(&(i, d)) = self.pending.first() {
            let (h, k) = (self.grid.h, self.lipschitz);
            let (low, up) = (d - balls.low, balls.high - d);
            let reach = low.max(up) / (k * h);
            if reach.is_nan() || reach < 1.0 {
                self.pending.remove(0);
                continue;
            }
            let r = (reach.floor() as i64).min(MAX_BALL_CELLS);
            let cube = (2 * r + 1).pow(3) as u32;
            m.charge_parts(cube.div_ceil(STAMPED_CELLS_PER_UNIT / PARTS_PER_UNIT))?;
            self.pending.remove(0);
            self.stamp(i, d, r, balls);
        }
        Ok(())
    }

    /// Stamps the bounds that cell `i`'s distance `d` proves on the cells within `r` cells.
    fn stamp(&mut self, i: usize, d: f64, r: i64, balls: &Balls) {
        let (h, k) = (self.grid.h, self.lipschitz);
        let c = self.grid.coords(i);
        for dz in -r..=r {
            for dy in -r..=r {
                for dx in -r..=r {
                    let Some(j) = self.grid.index([c[0] + dx, c[1] + dy, c[2] + dz]) else {
                        continue;
                    };
                    let f = self.flags[j];
                    if f & EVALUATED != 0 {
                        continue;
                    }
                    let rho = h * ((dx * dx + dy * dy + dz * dz) as f64).sqrt();
                    let lb = d - k * rho;
                    if lb >= balls.low && (f & BOUND == 0 || f64::from(self.sd[j]) < lb) {
                        self.sd[j] = f32_down(lb);
                        self.flags[j] |= BOUND;
                    }
                    let ub = d + k * rho;
                    if ub < balls.high && (f & UBOUND == 0 || f64::from(self.ub[j]) > ub) {
                        self.ub[j] = f32_up(ub);
                        self.flags[j] |= UBOUND;
                    }
                }
            }
        }
    }

    /// True if the straight edge between the centres of cells `i` and `j` (both at least `level`
    /// from the obstacles) keeps `level` everywhere. Accepted without a query when the two
    /// distances alone prove it: along an edge of length `L` between centres with distances
    /// `a` and `b`, the distance is at least `(a + b − K·L) / 2` for a `K`-Lipschitz field;
    /// otherwise one exact [`StaticMap::segment_clear`] (one unit).
    pub(crate) fn edge_clear(
        &mut self,
        map: &StaticMap,
        i: usize,
        j: usize,
        level: f64,
        m: &mut Meter,
    ) -> Result<bool, Paused> {
        let (a, b) = (self.sd(map, i, m)?, self.sd(map, j, m)?);
        let (p, q) = (self.grid.center_of(i), self.grid.center_of(j));
        let len = (q - p).norm();
        if 0.5 * (a + b - self.lipschitz * len) >= level {
            return Ok(true);
        }
        m.charge()?;
        Ok(map.segment_clear(&p, &q, level))
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
        assert!(g.cells() <= 1000);
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
    fn the_meter_refuses_the_unit_past_its_limit() {
        let mut m = Meter {
            work: 0,
            limit: 2,
            prepaid: 0,
            credit: 0,
        };
        assert!(m.charge().is_ok() && m.charge().is_ok());
        assert_eq!(m.charge(), Err(Paused));
        assert_eq!(m.work, 2);
    }

    fn random_map(seed: u64, count: usize) -> StaticMap {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let b = Aabb::new(Vec3::zeros(), Vec3::new(6.0, 5.0, 4.0)).unwrap();
        let shapes = (0..count)
            .map(|_| {
                let lo = Vec3::new(
                    rng.random_range(0.0..5.5),
                    rng.random_range(0.0..4.5),
                    rng.random_range(0.0..3.5),
                );
                let size = Vec3::new(
                    rng.random_range(0.05..2.0),
                    rng.random_range(0.05..2.0),
                    rng.random_range(0.05..2.0),
                );
                trust_geometry::AaBox::new(lo, lo + size).unwrap().into()
            })
            .collect();
        StaticMap::from_shapes(b, shapes).unwrap()
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(24))]
        /// Free and blocked balls are sound: every cell a ball settles is settled as a query at
        /// its own centre would settle it (brute force over every cell of the grid), at every
        /// level the floods test, whatever order the cells are visited in.
        #[test]
        fn balls_settle_cells_as_their_own_queries_would(
            seed in 0_u64..1_000_000,
            count in 0_usize..8,
            h in 0.05_f64..0.3,
            low in -0.2_f64..0.5,
            span in 0.0_f64..0.6,
            stride in 1_usize..40,
        ) {
            let map = random_map(seed, count);
            let grid = Grid::new(map.bounds(), h, 200_000, 10.0).unwrap();
            let mut layer = Layer::new(grid, &map);
            let balls = Balls { low, high: low + span };
            let mut m = Meter { work: 0, limit: usize::MAX, prepaid: 0, credit: 0 };
            let cells: Vec<usize> = grid.indices().collect();
            let n = cells.len();
            let levels = [low, low + 0.5 * span, low + span];
            for (step, i) in (0..n).map(|k| cells[(k * stride * 7919) % n]).enumerate() {
                let level = levels[step % 3];
                let truth = map.signed_distance(&grid.center_of(i));
                let said = layer.at_least(&map, i, level, &balls, &mut m).unwrap();
                // Within the f32 rounding of the stored bounds.
                if said {
                    proptest::prop_assert!(truth >= level - 1e-5, "cell {i}: {truth} < {level}");
                } else {
                    proptest::prop_assert!(truth < level + 1e-5, "cell {i}: {truth} >= {level}");
                }
            }
        }
    }

    #[test]
    fn bricks_index_every_cell_once_and_round_trip() {
        let b = Aabb::new(Vec3::zeros(), Vec3::new(1.3, 0.7, 0.9)).unwrap();
        let g = Grid::new(&b, 0.1, 1_000_000, 0.1).unwrap();
        let mut seen = vec![false; g.len()];
        for i in g.indices() {
            assert!(!seen[i], "cell {i} twice");
            seen[i] = true;
            assert_eq!(g.index(g.coords(i)), Some(i));
        }
        assert_eq!(seen.iter().filter(|&&v| v).count(), g.cells());
        assert_eq!(g.index([g.dims[0] as i64, 0, 0]), None);
    }

    #[test]
    fn a_free_ball_settles_an_empty_room_with_few_queries() {
        let b = Aabb::new(Vec3::zeros(), Vec3::new(8.0, 8.0, 8.0)).unwrap();
        let pillar =
            trust_geometry::AaBox::new(Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.2, 0.2, 8.0)).unwrap();
        let map = StaticMap::from_shapes(b, vec![pillar.into()]).unwrap();
        let grid = Grid::new(&b, 0.2, 1_000_000, 0.2).unwrap();
        let mut layer = Layer::new(grid, &map);
        let balls = Balls {
            low: 0.2,
            high: 0.4,
        };
        let mut m = Meter {
            work: 0,
            limit: usize::MAX,
            prepaid: 0,
            credit: 0,
        };
        let mut queries = 0;
        for i in grid.indices() {
            let before = layer.flags[i] & (EVALUATED | BOUND);
            let free = layer.at_least(&map, i, 0.4, &balls, &mut m).unwrap();
            queries += usize::from(before == 0);
            assert_eq!(free, map.signed_distance(&grid.center_of(i)) >= 0.4);
        }
        assert!(queries * 20 < grid.cells(), "{queries} of {}", grid.cells());
    }

    #[test]
    fn cached_distances_are_lower_bounds() {
        let b = Aabb::new(Vec3::zeros(), Vec3::new(4.0, 4.0, 4.0)).unwrap();
        let wall =
            trust_geometry::AaBox::new(Vec3::new(1.0, 0.0, 0.0), Vec3::new(1.3, 4.0, 4.0)).unwrap();
        let map = StaticMap::from_shapes(b, vec![wall.into()]).unwrap();
        let mut layer = Layer::new(Grid::new(&b, 0.1, 1_000_000, 0.1).unwrap(), &map);
        let mut m = Meter {
            work: 0,
            limit: usize::MAX,
            prepaid: 0,
            credit: 0,
        };
        let grid = layer.grid;
        for i in grid.indices().step_by(97) {
            let d = layer.sd(&map, i, &mut m).unwrap();
            assert!(d <= map.signed_distance(&layer.grid.center_of(i)));
        }
    }
}
