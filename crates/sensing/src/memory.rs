//! What the vehicle has seen, kept for the whole flight, and the map a global route is searched
//! on when the static map is sensed.
//!
//! The [`LocalMap`] is a rolling window (20 × 20 × 4.8 m by default in flights): a surface the
//! camera sees above or below it is never stored, and a wall the vehicle flew along is
//! forgotten once it leaves the window, so a route searched on the window alone leads over it
//! or back through it. [`MapMemory`] keeps a coarse record over the world's bounds, one byte
//! per cell: unknown, seen (some voxel of it observed), occupied (kept once seen). Surfaces come
//! from every scan's returns ([`MapMemory::record`], wherever they lie), seen space from the
//! window every few scans ([`MapMemory::fold`]).
//!
//! [`MapMemory::route_map`] builds the map a route is searched on: the window's map, the
//! remembered surfaces beyond the window, and **the unseen cells round the vehicle** (within a
//! reach, beyond its own place), as merged boxes. The route then leaves the vehicle through
//! space the sensor has seen: not under a wall the camera cannot look below, not through the
//! holes a grazing view leaves in a wall, not straight up where a forward camera never looks.
//! Beyond the reach unknown space stays free (the optimistic policy: the route may cross it,
//! what the vehicle commits to may not). Cells are coarse (0.5 m) so that a voxel the rays
//! happened to miss does not close the way.

use std::collections::HashMap;

use trust_geometry::{AaBox, Aabb, Shape, StaticMap, Vec3};

use crate::error::{SensingError, check_range};
use crate::map::LocalMap;
use crate::scan::Scan;

/// Most cells of a [`MapMemory`] (32 M, one byte each): a larger world gets coarser cells.
pub const MAX_MEMORY_CELLS: usize = 1 << 25;

/// The default cell edge of a [`MapMemory`] (m): 0.5 m, five voxels of the window; the memory
/// only shapes the route beyond the window, where it needs to know which way round a
/// remembered obstacle lies, not the width of a door.
pub const DEFAULT_MEMORY_CELL_M: f64 = 0.5;

/// The unseen cells a route may not cross ([`MapMemory::blocked_boxes`]): those whose centres
/// lie farther than `keep_m` and within `reach_m` of `from`, and farther than `keep_m` from
/// `goal`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Unseen {
    /// Where the route starts (the vehicle).
    pub from: Vec3,
    /// Where it goes.
    pub goal: Vec3,
    /// The vehicle's own place and the goal's (m).
    pub keep_m: f64,
    /// How far round `from` unseen cells are blocked (m).
    pub reach_m: f64,
}

impl Unseen {
    /// No unseen cell blocked (a reach of 0).
    pub fn none() -> Self {
        Self {
            from: Vec3::zeros(),
            goal: Vec3::zeros(),
            keep_m: 0.0,
            reach_m: 0.0,
        }
    }
}

/// A coarse record over the world's bounds of the surfaces the vehicle has seen (module docs).
#[derive(Debug, Clone)]
pub struct MapMemory {
    bounds: Aabb,
    cell_m: f64,
    dims: [usize; 3],
    cells: Vec<u8>,
    /// The occupied cells' indices, in the order they were first seen.
    list: Vec<usize>,
}

const UNKNOWN: u8 = 0;
const SEEN: u8 = 1;
const OCCUPIED: u8 = 2;

impl MapMemory {
    /// An empty memory over `bounds` with cells of `cell_m` (grown, if the bounds would need
    /// more than [`MAX_MEMORY_CELLS`], until they fit).
    ///
    /// # Errors
    /// [`SensingError::OutOfRange`] for a cell size outside `[1e-3, 100]` m.
    pub fn new(bounds: &Aabb, cell_m: f64) -> Result<Self, SensingError> {
        check_range(
            "memory.cell_m",
            cell_m,
            1e-3,
            100.0,
            false,
            "in [1e-3, 100]",
        )?;
        let extent = bounds.max - bounds.min;
        let dims_for = |h: f64| -> [usize; 3] {
            std::array::from_fn(|i| ((extent[i] / h).ceil() as usize).max(1))
        };
        let mut cell = cell_m;
        while dims_for(cell).iter().product::<usize>() > MAX_MEMORY_CELLS {
            cell *= 1.25;
        }
        let dims = dims_for(cell);
        Ok(Self {
            bounds: *bounds,
            cell_m: cell,
            dims,
            cells: vec![UNKNOWN; dims.iter().product()],
            list: Vec::new(),
        })
    }

    /// The cell edge (m).
    pub fn cell_m(&self) -> f64 {
        self.cell_m
    }

    /// Cells per axis.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// Occupied cells.
    pub fn occupied_count(&self) -> usize {
        self.list.len()
    }

    /// The index of the cell containing `p`, if inside the bounds (and finite).
    fn index_of(&self, p: &Vec3) -> Option<usize> {
        let mut c = [0usize; 3];
        for (i, ci) in c.iter_mut().enumerate() {
            let f = ((p[i] - self.bounds.min[i]) / self.cell_m).floor();
            if !(f >= 0.0 && f < self.dims[i] as f64) {
                return None;
            }
            *ci = f as usize;
        }
        Some(c[0] + self.dims[0] * (c[1] + self.dims[1] * c[2]))
    }

    fn coords(&self, i: usize) -> [usize; 3] {
        let d = self.dims;
        [i % d[0], (i / d[0]) % d[1], i / (d[0] * d[1])]
    }

    fn mark(&mut self, i: usize, state: u8) -> bool {
        if self.cells[i] >= state {
            return false;
        }
        self.cells[i] = state;
        if state == OCCUPIED {
            self.list.push(i);
        }
        true
    }

    /// Records the surface points of `scan` (its hits, wherever they lie: above or below the
    /// window too). Returns the cells newly occupied. Cost: one cell lookup per hit.
    pub fn record(&mut self, scan: &Scan) -> usize {
        let mut changed = 0;
        for p in scan.points() {
            if let Some(i) = self.index_of(&p) {
                changed += usize::from(self.mark(i, OCCUPIED));
            }
        }
        changed
    }

    /// Records the observed voxels of `map`'s window: a cell with an occupied voxel is occupied,
    /// one with an observed voxel is seen. Returns the cells that changed. Cost: one pass over
    /// the window (a few milliseconds for the flights' 200 × 200 × 48 voxels): call it every few
    /// scans.
    pub fn fold(&mut self, map: &LocalMap) -> usize {
        let res = map.params().resolution_m;
        let w = map.window();
        // The cell index of each voxel coordinate of the window, per axis.
        let axis: [Vec<Option<usize>>; 3] = std::array::from_fn(|i| {
            let n = ((w.max[i] - w.min[i]) / res).round() as usize;
            (0..n)
                .map(|j| {
                    let f = ((w.min[i] + (j as f64 + 0.5) * res - self.bounds.min[i])
                        / self.cell_m)
                        .floor();
                    (f >= 0.0 && f < self.dims[i] as f64).then_some(f as usize)
                })
                .collect()
        });
        let low: [i64; 3] = std::array::from_fn(|i| (w.min[i] / res).round() as i64);
        let mut changed = 0;
        map.for_each_known(|k, occupied| {
            let c = [0, 1, 2].map(|i| axis[i].get((k[i] - low[i]) as usize).copied().flatten());
            if let (Some(x), Some(y), Some(z)) = (c[0], c[1], c[2]) {
                let i = x + self.dims[0] * (y + self.dims[1] * z);
                changed += usize::from(self.mark(i, if occupied { OCCUPIED } else { SEEN }));
            }
        });
        changed
    }

    /// True if the cell containing `p` holds a surface seen (false outside the bounds).
    pub fn is_occupied(&self, p: &Vec3) -> bool {
        self.index_of(p).is_some_and(|i| self.cells[i] == OCCUPIED)
    }

    /// True if no voxel of the cell containing `p` has been observed (true outside the bounds).
    pub fn is_unseen(&self, p: &Vec3) -> bool {
        self.index_of(p).is_none_or(|i| self.cells[i] == UNKNOWN)
    }

    /// The cells a route from `from` toward `goal` may not cross, as merged boxes (runs along
    /// x, then equal runs on consecutive rows along y, then equal rectangles on consecutive
    /// layers along z: a wall becomes one box, not thousands): the remembered surfaces not
    /// wholly inside `window` whose voxels the window has observed (`knows`: its own field holds
    /// those exactly; a window that moved away and back has forgotten them), and the unseen cells
    /// whose centres lie farther than `keep_m` and within `reach_m` of `from` and farther than
    /// `keep_m` from `goal`.
    pub fn blocked_boxes(
        &self,
        window: &Aabb,
        knows: &dyn Fn(&Aabb) -> bool,
        unseen: &Unseen,
    ) -> Vec<AaBox> {
        let Unseen {
            from,
            goal,
            keep_m,
            reach_m,
        } = *unseen;
        let h = self.cell_m;
        let lo = |c: [usize; 3]| Vec3::from_fn(|i, _| self.bounds.min[i] + c[i] as f64 * h);
        let inside = |c: [usize; 3]| {
            let a = lo(c);
            let b = a + Vec3::repeat(h);
            window.contains(&a) && window.contains(&b) && knows(&Aabb { min: a, max: b })
        };
        let mut cells: Vec<usize> = self
            .list
            .iter()
            .copied()
            .filter(|&i| !inside(self.coords(i)))
            .collect();
        if from.iter().all(|v| v.is_finite()) && reach_m.is_finite() {
            let range: [(usize, usize); 3] = std::array::from_fn(|i| {
                let n = self.dims[i] as f64;
                let a = ((from[i] - reach_m - self.bounds.min[i]) / h).floor();
                let b = ((from[i] + reach_m - self.bounds.min[i]) / h).ceil();
                (a.clamp(0.0, n) as usize, b.clamp(0.0, n) as usize)
            });
            for z in range[2].0..range[2].1 {
                for y in range[1].0..range[1].1 {
                    for x in range[0].0..range[0].1 {
                        let i = x + self.dims[0] * (y + self.dims[1] * z);
                        if self.cells[i] != UNKNOWN {
                            continue;
                        }
                        let p = lo([x, y, z]) + Vec3::repeat(0.5 * h);
                        let d = (p - from).norm();
                        if d > keep_m && d <= reach_m && (p - goal).norm() > keep_m {
                            cells.push(i);
                        }
                    }
                }
            }
        }
        cells.sort_unstable();
        cells.dedup();
        // Runs along x: (y, z) -> [(x0, x1)].
        let mut runs: Vec<(usize, usize, usize, usize)> = Vec::new(); // (z, x0, x1, y)
        let mut k = 0;
        while k < cells.len() {
            let first = self.coords(cells[k]);
            let mut last = first[0];
            while k + 1 < cells.len() && cells[k + 1] == cells[k] + 1 && last + 1 < self.dims[0] {
                k += 1;
                last += 1;
            }
            k += 1;
            runs.push((first[2], first[0], last, first[1]));
        }
        // Along y: equal (z, x0, x1) on consecutive y.
        runs.sort_unstable();
        let mut rects: Vec<(usize, usize, usize, usize, usize)> = Vec::new(); // (x0, x1, y0, y1, z)
        for (z, x0, x1, y) in runs {
            match rects.last_mut() {
                Some(r) if r.4 == z && r.0 == x0 && r.1 == x1 && r.3 + 1 == y => r.3 = y,
                _ => rects.push((x0, x1, y, y, z)),
            }
        }
        // Along z: equal rectangles on consecutive layers.
        let mut open: HashMap<(usize, usize, usize, usize), (usize, usize)> = HashMap::new();
        let mut out: Vec<(usize, usize, usize, usize, usize, usize)> = Vec::new();
        rects.sort_unstable_by_key(|r| (r.4, r.0, r.1, r.2, r.3));
        for (x0, x1, y0, y1, z) in rects {
            let key = (x0, x1, y0, y1);
            match open.get_mut(&key) {
                Some(span) if span.1 + 1 == z => span.1 = z,
                Some(span) => {
                    out.push((x0, x1, y0, y1, span.0, span.1));
                    *span = (z, z);
                }
                None => {
                    open.insert(key, (z, z));
                }
            }
        }
        out.extend(
            open.into_iter()
                .map(|((x0, x1, y0, y1), (z0, z1))| (x0, x1, y0, y1, z0, z1)),
        );
        out.sort_unstable();
        out.into_iter()
            .filter_map(|(x0, x1, y0, y1, z0, z1)| {
                AaBox::new(lo([x0, y0, z0]), lo([x1 + 1, y1 + 1, z1 + 1])).ok()
            })
            .collect()
    }

    /// The map a route from `from` toward `goal` is searched on (module docs): `near` (the
    /// window's map) plus [`MapMemory::blocked_boxes`].
    ///
    /// # Errors
    /// [`SensingError::Geometry`] if a box is rejected (not for a memory built by `new`).
    pub fn route_map(
        &self,
        near: StaticMap,
        window: &Aabb,
        knows: &dyn Fn(&Aabb) -> bool,
        unseen: &Unseen,
    ) -> Result<StaticMap, SensingError> {
        let boxes = self.blocked_boxes(window, knows, unseen);
        Ok(near.with_shapes(boxes.into_iter().map(Shape::from))?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::LocalMapParams;
    use crate::scan::{RayMeasurement, ReturnKind};

    fn bounds() -> Aabb {
        Aabb::new(Vec3::zeros(), Vec3::new(40.0, 20.0, 10.0)).unwrap()
    }

    fn hits(points: &[Vec3]) -> Scan {
        Scan {
            origin: Vec3::new(1.0, 1.0, 1.0),
            rays: points
                .iter()
                .map(|p| RayMeasurement {
                    direction: (p - Vec3::new(1.0, 1.0, 1.0)).normalize(),
                    range: (p - Vec3::new(1.0, 1.0, 1.0)).norm(),
                    kind: ReturnKind::Hit,
                })
                .collect(),
        }
    }

    #[test]
    fn a_huge_world_gets_coarser_cells_and_bad_input_is_typed() {
        let huge = Aabb::new(Vec3::zeros(), Vec3::new(1e4, 1e4, 100.0)).unwrap();
        let m = MapMemory::new(&huge, 0.5).unwrap();
        assert!(m.dims().iter().product::<usize>() <= MAX_MEMORY_CELLS);
        assert!(m.cell_m() > 0.5);
        assert!(MapMemory::new(&bounds(), f64::NAN).is_err());
        assert!(MapMemory::new(&bounds(), 0.0).is_err());
        assert!(!m.is_occupied(&Vec3::new(f64::NAN, 1.0, 1.0)));
        assert!(!m.is_occupied(&Vec3::new(-1.0, 1.0, 1.0)));
    }

    #[test]
    fn surfaces_are_remembered_wherever_the_window_is() {
        let mut memory = MapMemory::new(&bounds(), 0.5).unwrap();
        let scan = hits(&[
            Vec3::new(5.1, 5.1, 9.1),
            Vec3::new(5.2, 5.2, 9.2),
            Vec3::new(50.0, 1.0, 1.0),
        ]);
        assert_eq!(
            memory.record(&scan),
            1,
            "two hits in one cell, one outside the bounds"
        );
        assert!(memory.is_occupied(&Vec3::new(5.4, 5.4, 9.4)));
        assert!(!memory.is_occupied(&Vec3::new(5.6, 5.4, 9.4)));
        assert_eq!(memory.record(&scan), 0, "nothing new");
        let map = LocalMap::new(LocalMapParams::default(), &Vec3::new(5.0, 5.0, 5.0)).unwrap();
        assert_eq!(memory.fold(&map), 0, "an empty window adds nothing");
    }

    /// Unseen cells round the vehicle block the route, except its own place and the goal's;
    /// seen ones and those beyond the reach do not.
    #[test]
    fn unseen_cells_near_the_vehicle_are_blocked() {
        let mut memory = MapMemory::new(&bounds(), 0.5).unwrap();
        let from = Vec3::new(10.0, 10.0, 5.0);
        let goal = Vec3::new(12.2, 10.2, 5.2);
        let mut local = LocalMap::new(LocalMapParams::default(), &from).unwrap();
        local.assume_free(&Vec3::new(10.2, 10.2, 7.2), 0.3);
        memory.fold(&local);
        assert!(!memory.is_unseen(&Vec3::new(10.2, 10.2, 7.2)));
        assert!(memory.is_unseen(&Vec3::new(10.2, 10.2, 8.2)));
        let near = StaticMap::new(bounds()).unwrap();
        let window = Aabb::new(from, from).unwrap();
        let map = memory
            .route_map(
                near,
                &window,
                &|_| true,
                &Unseen {
                    from,
                    goal,
                    keep_m: 1.0,
                    reach_m: 4.0,
                },
            )
            .unwrap();
        assert!(
            !map.is_free(&Vec3::new(10.2, 10.2, 8.2), 0.0),
            "unseen, near"
        );
        assert!(map.is_free(&Vec3::new(10.2, 10.2, 7.2), 0.0), "seen");
        assert!(
            map.is_free(&Vec3::new(10.2, 10.2, 5.2), 0.0),
            "its own place"
        );
        assert!(map.is_free(&goal, 0.0), "the goal's place");
        assert!(
            map.is_free(&Vec3::new(16.2, 10.2, 5.2), 0.0),
            "beyond the reach"
        );
        assert!(map.shapes().len() < 200, "merged: {}", map.shapes().len());
    }

    /// A wall of cells becomes one box; cells wholly inside the window are left to it.
    #[test]
    fn a_remembered_wall_is_one_box_outside_the_window() {
        let mut memory = MapMemory::new(&bounds(), 0.5).unwrap();
        let mut points = Vec::new();
        for y in 0..20 {
            for z in 0..12 {
                for x in 0..2 {
                    points.push(Vec3::new(
                        20.1 + 0.5 * x as f64,
                        2.1 + 0.5 * y as f64,
                        0.1 + 0.5 * z as f64,
                    ));
                }
            }
        }
        memory.record(&hits(&points));
        assert_eq!(memory.occupied_count(), 480);
        let far = Aabb::new(Vec3::new(0.0, 0.0, 0.0), Vec3::new(5.0, 5.0, 5.0)).unwrap();
        let boxes = memory.blocked_boxes(&far, &|_| true, &Unseen::none());
        assert_eq!(boxes.len(), 1, "{boxes:?}");
        assert!((boxes[0].min - Vec3::new(20.0, 2.0, 0.0)).norm() < 1e-9);
        assert!((boxes[0].max - Vec3::new(21.0, 12.0, 6.0)).norm() < 1e-9);
        // A window holding part of the wall: the cells wholly inside it are not boxes.
        let window = Aabb::new(Vec3::new(15.0, 0.0, 0.0), Vec3::new(25.0, 7.0, 10.0)).unwrap();
        let boxes = memory.blocked_boxes(&window, &|_| true, &Unseen::none());
        let covered: f64 = boxes.iter().map(|b| (b.max - b.min).product()).sum();
        assert!((covered - 1.0 * 5.0 * 6.0).abs() < 1e-9, "{boxes:?}");
        // A window that moved away and back has forgotten the wall: all of it is a box again.
        let forgot = memory.blocked_boxes(&window, &|_| false, &Unseen::none());
        assert_eq!(forgot.len(), 1, "{forgot:?}");
        let near = StaticMap::new(bounds()).unwrap();
        let map = memory
            .route_map(near, &window, &|_| true, &Unseen::none())
            .unwrap();
        assert!(!map.is_free(&Vec3::new(20.5, 10.0, 3.0), 0.0));
        assert!(
            map.is_free(&Vec3::new(20.5, 5.0, 3.0), 0.0),
            "inside the window"
        );
    }
}
