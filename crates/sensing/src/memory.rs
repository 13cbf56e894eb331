//! What the vehicle has seen, kept for the whole flight, and the map a global route is searched
//! on when the static map is sensed.
//!
//! The [`LocalMap`] is a rolling window (20 × 20 × 4.8 m by default in flights): a wall the
//! vehicle flew along is forgotten once it leaves the window, and a route searched on the window
//! alone leads back through it. [`MapMemory`] keeps a coarse copy of every observation over the
//! world's bounds (one byte per cell: unknown, seen free, seen occupied; occupied is kept once
//! seen), folded from the window often enough that nothing leaves it unrecorded.
//!
//! [`MapMemory::route_map`] builds the map a route is searched on: the window's exact distance
//! field, the remembered obstacles outside it, and, as obstacles, the unknown cells near the
//! vehicle that its sensor cannot see from where it is ([`ViewBand`]): those above and below the
//! sensor's vertical field of view within its reach. Unknown space elsewhere stays free (the
//! optimistic policy: the route may cross it, what the vehicle commits to may not). Without that
//! band, a route toward a wall taller than the view dives under (or over) it where the camera
//! never looks, the vehicle can never commit to it, and it stalls in front of the wall; with it
//! the route leaves the vehicle through space the sensor will see before it gets there
//! (a forward camera climbs at most at its half vertical field of view).

use trust_geometry::{AaBox, Aabb, Shape, StaticMap, Vec3};

use crate::error::{SensingError, check_range};
use crate::map::LocalMap;
use crate::occupancy::VoxelState;

/// Most cells of a [`MapMemory`] (32 M, one byte each): a larger world gets coarser cells.
pub const MAX_MEMORY_CELLS: usize = 1 << 25;

/// The default cell edge of a [`MapMemory`] (m): 0.5 m, five voxels of the window, the scale of
/// the route's coarse layer; only used outside the window, where the route only needs to know
/// which way round a remembered obstacle lies.
pub const DEFAULT_MEMORY_CELL_M: f64 = 0.5;

const UNKNOWN: u8 = 0;
const FREE: u8 = 1;
const OCCUPIED: u8 = 2;

/// The directions a sensor sees from the vehicle, for [`MapMemory::route_map`]: the elevations
/// (from the horizontal plane, radians, `min < max`) it covers by turning about the vertical
/// axis, and the distance it sees to (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewBand {
    /// The lowest elevation seen (rad, in `[-π/2, π/2]`): `−vfov/2` for a level camera.
    pub min_elevation_rad: f64,
    /// The highest elevation seen (rad, in `[-π/2, π/2]`).
    pub max_elevation_rad: f64,
    /// How far the band holds (m, > 0): unknown cells beyond it stay free.
    pub reach_m: f64,
}

impl ViewBand {
    /// Checks the fields (typed error naming the field).
    ///
    /// # Errors
    /// [`SensingError::OutOfRange`] for an elevation outside `[-π/2, π/2]`, `min >= max` or a
    /// reach that is not positive and finite.
    pub fn validate(&self) -> Result<(), SensingError> {
        let half_pi = std::f64::consts::FRAC_PI_2;
        check_range(
            "view_band.min_elevation_rad",
            self.min_elevation_rad,
            -half_pi,
            half_pi,
            false,
            "in [-π/2, π/2]",
        )?;
        check_range(
            "view_band.max_elevation_rad",
            self.max_elevation_rad,
            self.min_elevation_rad,
            half_pi,
            true,
            "in (min_elevation_rad, π/2]",
        )?;
        check_range(
            "view_band.reach_m",
            self.reach_m,
            0.0,
            1.0e4,
            true,
            "in (0, 1e4]",
        )?;
        Ok(())
    }

    /// Whether the direction `d` (from the vehicle) lies within the band's elevations.
    pub fn sees(&self, d: &Vec3) -> bool {
        let elevation = d.z.atan2(d.xy().norm());
        (self.min_elevation_rad..=self.max_elevation_rad).contains(&elevation)
    }
}

/// A coarse record over the world's bounds of what the vehicle has observed (module docs).
#[derive(Debug, Clone)]
pub struct MapMemory {
    origin: Vec3,
    cell_m: f64,
    dims: [usize; 3],
    cells: Vec<u8>,
    /// The occupied cells' indices, in the order they were first seen occupied.
    occupied: Vec<usize>,
}

impl MapMemory {
    /// An all-unknown memory over `bounds` with cells of `cell_m` (grown, if the bounds would
    /// need more than [`MAX_MEMORY_CELLS`], until they fit).
    ///
    /// # Errors
    /// [`SensingError::OutOfRange`] for a cell size outside `[1e-3, 100]` m.
    pub fn new(bounds: &Aabb, cell_m: f64) -> Result<Self, SensingError> {
        check_range("memory.cell_m", cell_m, 1e-3, 100.0, false, "in [1e-3, 100]")?;
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
            origin: bounds.min,
            cell_m: cell,
            dims,
            cells: vec![UNKNOWN; dims.iter().product()],
            occupied: Vec::new(),
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

    /// The cell index along axis `i` of coordinate `x`, if inside.
    fn axis_index(&self, i: usize, x: f64) -> Option<usize> {
        let f = ((x - self.origin[i]) / self.cell_m).floor();
        (f >= 0.0 && f < self.dims[i] as f64).then_some(f as usize)
    }

    fn index(&self, c: [usize; 3]) -> usize {
        c[0] + self.dims[0] * (c[1] + self.dims[1] * c[2])
    }

    fn coords(&self, i: usize) -> [usize; 3] {
        let d = self.dims;
        [i % d[0], (i / d[0]) % d[1], i / (d[0] * d[1])]
    }

    fn center(&self, c: [usize; 3]) -> Vec3 {
        Vec3::from_fn(|i, _| self.origin[i] + (c[i] as f64 + 0.5) * self.cell_m)
    }

    fn cell_box(&self, c: [usize; 3]) -> Aabb {
        let min = Vec3::from_fn(|i, _| self.origin[i] + c[i] as f64 * self.cell_m);
        Aabb {
            min,
            max: min + Vec3::repeat(self.cell_m),
        }
    }

    /// Records the observed voxels of `map`'s window: a cell with an occupied voxel is occupied
    /// from then on, a cell with an observed voxel is no longer unknown. Returns the cells that
    /// changed. Cost: one pass over the window (about 2 ms for 200 × 200 × 48 voxels), so call
    /// it every few scans, often enough that nothing crosses the window between two calls.
    pub fn fold(&mut self, map: &LocalMap) -> usize {
        let res = map.params().resolution_m;
        let w = map.window();
        // The cell of each voxel coordinate of the window, per axis (None outside the bounds).
        let axis: [Vec<Option<usize>>; 3] = std::array::from_fn(|i| {
            let n = ((w.max[i] - w.min[i]) / res).round() as usize;
            (0..n)
                .map(|j| self.axis_index(i, w.min[i] + (j as f64 + 0.5) * res))
                .collect()
        });
        let low: [i64; 3] = std::array::from_fn(|i| (w.min[i] / res).round() as i64);
        let mut changed = 0;
        map.for_each_known(|k, occupied| {
            let c = [0, 1, 2].map(|i| {
                axis[i]
                    .get((k[i] - low[i]) as usize)
                    .copied()
                    .flatten()
            });
            let (Some(x), Some(y), Some(z)) = (c[0], c[1], c[2]) else {
                return;
            };
            let i = x + self.dims[0] * (y + self.dims[1] * z);
            let new = if occupied { OCCUPIED } else { FREE };
            if new > self.cells[i] {
                self.cells[i] = new;
                changed += 1;
                if new == OCCUPIED {
                    self.occupied.push(i);
                }
            }
        });
        changed
    }

    /// The state of the cell containing `p` ([`VoxelState::Unknown`] outside the bounds or for a
    /// non-finite `p`).
    pub fn state(&self, p: &Vec3) -> VoxelState {
        let c = [0, 1, 2].map(|i| self.axis_index(i, p[i]));
        match (c[0], c[1], c[2]) {
            (Some(x), Some(y), Some(z)) => match self.cells[self.index([x, y, z])] {
                OCCUPIED => VoxelState::Occupied,
                FREE => VoxelState::Free,
                _ => VoxelState::Unknown,
            },
            _ => VoxelState::Unknown,
        }
    }

    /// The map a route from `from` to `goal` is searched on (module docs): `near` (the
    /// window's map, whose distance field is exact inside `window`) plus, as boxes, every
    /// remembered occupied cell not wholly inside `window`, and every unknown cell within
    /// `view.reach_m` of `from` whose centre lies outside the view band, except within `keep_m`
    /// of `from` or `goal` (the vehicle's own place and the goal stay open; the route search
    /// leaves a start inside the clearance along the distance gradient). Runs of cells along x
    /// are merged into one box.
    ///
    /// # Errors
    /// [`SensingError`] for an invalid band, a non-finite `from`/`goal`/`keep_m`, or a box the
    /// geometry rejects.
    pub fn route_map(
        &self,
        near: &StaticMap,
        window: &Aabb,
        from: &Vec3,
        goal: &Vec3,
        view: &ViewBand,
        keep_m: f64,
    ) -> Result<StaticMap, SensingError> {
        view.validate()?;
        for (field, p) in [("route_map.from", from), ("route_map.goal", goal)] {
            for i in 0..3 {
                crate::error::check_finite(&format!("{field}[{i}]"), p[i])?;
            }
        }
        check_range("route_map.keep_m", keep_m, 0.0, 1.0e4, false, "in [0, 1e4]")?;
        // The blocked cells: remembered obstacles beyond the window, unseen cells off the band.
        let mut blocked: Vec<usize> = self
            .occupied
            .iter()
            .copied()
            .filter(|&i| {
                let b = self.cell_box(self.coords(i));
                !(window.contains(&b.min) && window.contains(&b.max))
            })
            .collect();
        let reach = view.reach_m;
        let range: [(usize, usize); 3] = std::array::from_fn(|i| {
            let a = ((from[i] - reach - self.origin[i]) / self.cell_m).floor();
            let b = ((from[i] + reach - self.origin[i]) / self.cell_m).ceil();
            let n = self.dims[i] as f64;
            (a.clamp(0.0, n) as usize, b.clamp(0.0, n) as usize)
        });
        for z in range[2].0..range[2].1 {
            for y in range[1].0..range[1].1 {
                for x in range[0].0..range[0].1 {
                    let i = self.index([x, y, z]);
                    if self.cells[i] != UNKNOWN {
                        continue;
                    }
                    let p = self.center([x, y, z]);
                    let d = p - from;
                    let dist = d.norm();
                    if dist <= reach
                        && dist > keep_m
                        && (p - goal).norm() > keep_m
                        && !view.sees(&d)
                    {
                        blocked.push(i);
                    }
                }
            }
        }
        // Runs along x (consecutive indices on one row) become one box each.
        blocked.sort_unstable();
        let mut boxes: Vec<Shape> = Vec::new();
        let mut k = 0;
        while k < blocked.len() {
            let first = blocked[k];
            let mut last = first;
            while k + 1 < blocked.len()
                && blocked[k + 1] == last + 1
                && blocked[k + 1] % self.dims[0] != 0
            {
                k += 1;
                last = blocked[k];
            }
            k += 1;
            let (a, b) = (self.cell_box(self.coords(first)), self.cell_box(self.coords(last)));
            boxes.push(AaBox::new(a.min, b.max)?.into());
        }
        Ok(near.clone().with_shapes(boxes)?)
    }

    /// Occupied cells (for reports and tests).
    pub fn occupied_count(&self) -> usize {
        self.cells.iter().filter(|&&c| c == OCCUPIED).count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::LocalMapParams;

    fn bounds() -> Aabb {
        Aabb::new(Vec3::zeros(), Vec3::new(40.0, 20.0, 10.0)).unwrap()
    }

    fn band() -> ViewBand {
        ViewBand {
            min_elevation_rad: -0.45,
            max_elevation_rad: 0.45,
            reach_m: 8.0,
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
        let mut bad = band();
        bad.max_elevation_rad = bad.min_elevation_rad;
        let m = MapMemory::new(&bounds(), 0.5).unwrap();
        let near = StaticMap::new(bounds()).unwrap();
        let p = Vec3::new(5.0, 5.0, 5.0);
        let err = m.route_map(&near, &bounds(), &p, &p, &bad, 1.0).unwrap_err();
        assert!(err.to_string().contains("max_elevation_rad"), "{err}");
        let nan = Vec3::new(f64::NAN, 0.0, 0.0);
        assert!(m.route_map(&near, &bounds(), &nan, &p, &band(), 1.0).is_err());
    }

    #[test]
    fn an_obstacle_seen_is_remembered_after_the_window_moves_on() {
        let mut map = LocalMap::new(LocalMapParams::default(), &Vec3::new(5.0, 5.0, 5.0)).unwrap();
        map.assume_free(&Vec3::new(5.0, 5.0, 5.0), 0.5);
        let mut memory = MapMemory::new(&bounds(), 0.5).unwrap();
        assert_eq!(memory.fold(&map), 8, "the ball of 0.5 m touches 8 cells");
        assert_eq!(memory.state(&Vec3::new(5.1, 5.1, 5.1)), VoxelState::Free);
        assert_eq!(memory.state(&Vec3::new(9.0, 5.0, 5.0)), VoxelState::Unknown);
        assert_eq!(memory.fold(&map), 0, "nothing new");
        map.recentre(&Vec3::new(30.0, 5.0, 5.0)).unwrap();
        assert_eq!(map.state(&Vec3::new(5.1, 5.1, 5.1)), VoxelState::Unknown);
        memory.fold(&map);
        assert_eq!(memory.state(&Vec3::new(5.1, 5.1, 5.1)), VoxelState::Free);
        assert_eq!(memory.state(&Vec3::new(f64::NAN, 5.1, 5.1)), VoxelState::Unknown);
    }

    /// The vehicle's own unseen column: the cells straight above and below within reach are
    /// obstacles for the route, those level with it (in the band) and beyond the reach are not.
    #[test]
    fn the_route_map_blocks_what_the_sensor_cannot_see_from_here() {
        let memory = MapMemory::new(&bounds(), 0.5).unwrap();
        let near = StaticMap::new(bounds()).unwrap();
        let from = Vec3::new(10.0, 10.0, 5.0);
        let goal = Vec3::new(35.0, 10.0, 5.0);
        let map = memory
            .route_map(&near, &Aabb::new(from, from).unwrap(), &from, &goal, &band(), 1.0)
            .unwrap();
        assert!(!map.is_free(&Vec3::new(10.2, 10.2, 8.2), 0.0), "above");
        assert!(!map.is_free(&Vec3::new(11.2, 10.2, 2.2), 0.0), "below, steeply");
        assert!(map.is_free(&Vec3::new(15.0, 10.0, 5.5), 0.3), "ahead, in the band");
        assert!(map.is_free(&Vec3::new(10.0, 10.0, 5.4), 0.0), "its own place");
        assert!(map.is_free(&Vec3::new(25.0, 10.0, 9.5), 0.0), "beyond the reach");
        // Seen space is not blocked even outside the band.
        let mut memory = memory;
        let mut local = LocalMap::new(LocalMapParams::default(), &from).unwrap();
        local.assume_free(&Vec3::new(10.0, 10.0, 7.5), 0.6);
        memory.fold(&local);
        let map = memory
            .route_map(&near, &Aabb::new(from, from).unwrap(), &from, &goal, &band(), 1.0)
            .unwrap();
        assert!(map.is_free(&Vec3::new(10.0, 10.0, 7.5), 0.0), "seen above");
    }

    /// A remembered obstacle outside the window is a box of the route map; one inside the
    /// window is left to the window's exact field.
    #[test]
    fn remembered_obstacles_outside_the_window_are_boxes() {
        let mut memory = MapMemory::new(&bounds(), 0.5).unwrap();
        let i = memory.index([20, 20, 10]);
        for j in [0, i] {
            memory.cells[j] = OCCUPIED; // the origin corner's cell, one inside the window
            memory.occupied.push(j);
        }
        let near = StaticMap::new(bounds()).unwrap();
        let window = Aabb::new(Vec3::new(8.0, 8.0, 3.0), Vec3::new(12.0, 12.0, 7.0)).unwrap();
        let from = Vec3::new(30.0, 10.0, 5.0);
        let far = ViewBand {
            reach_m: 0.1,
            ..band()
        };
        let map = memory
            .route_map(&near, &window, &from, &from, &far, 0.0)
            .unwrap();
        assert_eq!(map.shapes().len(), 1);
        assert!(!map.is_free(&Vec3::new(0.25, 0.25, 0.25), 0.0));
        assert!(map.is_free(&Vec3::new(10.25, 10.25, 5.25), 0.0));
        assert_eq!(memory.occupied_count(), 2);
    }
}
