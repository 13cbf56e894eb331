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
        let units = 1 + (len_m / SIGHT_UNIT_M).clamp(0.0, 1.0e9) as usize;
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
}

/// Metres of a line-of-sight query charged as one more unit ([`Meter::charge_sight`]).
pub(crate) const SIGHT_UNIT_M: f64 = 2.0;

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

    pub(crate) fn len(&self) -> usize {
        self.dims[0] * self.dims[1] * self.dims[2]
    }

    pub(crate) fn index(&self, c: [i64; 3]) -> Option<usize> {
        if (0..3).all(|a| c[a] >= 0 && (c[a] as usize) < self.dims[a]) {
            Some(c[0] as usize + self.dims[0] * (c[1] as usize + self.dims[1] * c[2] as usize))
        } else {
            None
        }
    }

    pub(crate) fn coords(&self, i: usize) -> [i64; 3] {
        let x = i % self.dims[0];
        let y = (i / self.dims[0]) % self.dims[1];
        let z = i / (self.dims[0] * self.dims[1]);
        [x as i64, y as i64, z as i64]
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
pub(crate) const EVALUATED: u8 = 1;
/// Per-cell flag: expanded by the A* from the start (closed set).
pub(crate) const CLOSED: u8 = 2;
/// Per-cell flag: the A* from the start holds a tentative cost for it.
pub(crate) const SEEN: u8 = 4;
/// Per-cell flag: reached by the flood from the goal at the inflated clearance.
pub(crate) const FLOOD_C: u8 = 8;
/// Per-cell flag: reached by the relaxed flood at the vehicle radius (the verdict's cause).
pub(crate) const FLOOD_R: u8 = 16;
/// Per-cell flag: reached by the relaxed flood at the inflated clearance (the verdict's proof).
pub(crate) const FLOOD_CR: u8 = 32;

/// The 26 neighbour offsets of a cell and their lengths in cells (1, √2 or √3).
pub(crate) fn neighbour_steps() -> [([i64; 3], f64); 26] {
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
/// time a search touches it (one unit of work) and kept, rounded down to `f32`. Every array is
/// zero-initialised, so the OS pages in only the part the searches touch.
#[derive(Debug, Clone)]
pub(crate) struct Layer {
    pub(crate) grid: Grid,
    /// Lower bound on the centre's signed distance (valid under [`EVALUATED`]).
    sd: Vec<f32>,
    /// [`EVALUATED`], [`CLOSED`], [`SEEN`], [`FLOOD_C`], [`FLOOD_R`].
    pub(crate) flags: Vec<u8>,
    /// Slope bound of the map's signed distance ([`ESDF_LIPSCHITZ`] or 1).
    pub(crate) lipschitz: f64,
}

impl Layer {
    pub(crate) fn new(grid: Grid, map: &StaticMap) -> Self {
        let n = grid.len();
        Self {
            grid,
            sd: vec![0.0; n],
            flags: vec![0; n],
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
            let mut f = d as f32;
            if f64::from(f) > d {
                f = f.next_down();
            }
            self.sd[i] = f;
            self.flags[i] |= EVALUATED;
        }
        Ok(f64::from(self.sd[i]))
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
    fn the_meter_refuses_the_unit_past_its_limit() {
        let mut m = Meter {
            work: 0,
            limit: 2,
            prepaid: 0,
        };
        assert!(m.charge().is_ok() && m.charge().is_ok());
        assert_eq!(m.charge(), Err(Paused));
        assert_eq!(m.work, 2);
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
        };
        for i in (0..layer.grid.len()).step_by(97) {
            let d = layer.sd(&map, i, &mut m).unwrap();
            assert!(d <= map.signed_distance(&layer.grid.center_of(i)));
        }
    }
}
