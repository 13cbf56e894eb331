//! What the roadmap "sees": the static map plus an optional set of swept obstacles, each a
//! predictive directional cone ([`Pdc`], the one implementation in `trust_predict`).
//!
//! V-PRM uses the static map (and, optionally, the moving obstacles frozen where they are now: cones
//! over a window of length zero); DEV-PRM adds the predictive directional cones of all forecasts
//! (paper Sec. III-B). Segment tests reject cones by bounding box before any exact test, and
//! [`Obstacles::restricted_to`] keeps only the cones near a region so that a whole search pays for
//! the relevant obstacles only.

use std::cell::Cell;

use trust_core::{Aabb, Forecast, MapWork, PlanError, StaticMap, Vec3};
use trust_predict::Pdc;

/// The predictive directional cones of `forecasts` over `[t_start, t_start + horizon_s]` (a negative
/// horizon counts as zero: the obstacles as they are at `t_start`).
///
/// # Errors
/// [`PlanError::InvalidInput`] naming the forecast if one is invalid or `t_start` is not finite.
pub fn forecast_cones(
    forecasts: &[Forecast],
    t_start: f64,
    horizon_s: f64,
) -> Result<Vec<Pdc>, PlanError> {
    let t_end = t_start + horizon_s.max(0.0);
    forecasts
        .iter()
        .enumerate()
        .map(|(i, f)| {
            Pdc::over_window(f, t_start, t_end)
                .map_err(|e| PlanError::invalid(format!("scene.forecasts[{i}]"), f, e.to_string()))
        })
        .collect()
}

/// The elementary operations of an [`Obstacles`]' queries so far: the static map's
/// ([`MapWork`]) and the cones'. A search's deterministic work budget is charged from these
/// ([`QueryWork::units`]), so that a budget stands for about the same time whether the map is
/// empty, a few shapes or a dense point-cloud ESDF.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct QueryWork {
    /// The static map's operations.
    pub map: MapWork,
    /// Cones whose box was compared with a query's (segment or point).
    pub cone_boxes: u64,
    /// Cones tested exactly (their box met the query's).
    pub cone_tests: u64,
}

impl QueryWork {
    /// Estimated cost of one map query's fixed part (call, checks, broad phase), in work units.
    ///
    /// One unit is one nanosecond of the 2-core development machine under load: the weights
    /// are a non-negative least-squares fit (relative error) of the time of 680 DEV-PRM searches
    /// of 15 scenes — E1, E3, E4, the suite, point-cloud ESDFs, shapes, crowds — with their
    /// counts (`TRUST_PRM_WORK_TRACE`, `examples/prm_work_fit.rs`). Measured over predicted
    /// time: 0.80–1.68 at the 10th–90th percentile, medians 0.85–1.55 by scene.
    pub const QUERY_UNITS: u64 = 126;
    /// Estimated cost of one ESDF sample (trilinear interpolation), in work units.
    pub const ESDF_SAMPLE_UNITS: u64 = 84;
    /// Estimated cost of one exact shape test, in work units.
    pub const SHAPE_TEST_UNITS: u64 = 17;
    /// Estimated cost of one cone box comparison, in work units.
    pub const CONE_BOX_UNITS: u64 = 17;
    /// Estimated cost of one exact cone test, in work units.
    pub const CONE_TEST_UNITS: u64 = 106;

    /// The work in units (a weighted sum of the counts; see the constants).
    pub fn units(&self) -> u64 {
        [
            (self.map.queries, Self::QUERY_UNITS),
            (self.map.esdf_samples, Self::ESDF_SAMPLE_UNITS),
            (self.map.shape_tests, Self::SHAPE_TEST_UNITS),
            (self.cone_boxes, Self::CONE_BOX_UNITS),
            (self.cone_tests, Self::CONE_TEST_UNITS),
        ]
        .iter()
        .fold(0u64, |sum, &(n, w)| sum.saturating_add(n.saturating_mul(w)))
    }
}

/// The obstacle set of one search: static map ∪ cones. Its queries count their elementary
/// operations ([`Obstacles::work`]).
#[derive(Debug, Clone)]
pub struct Obstacles<'a> {
    map: &'a StaticMap,
    cones: Vec<Pdc>,
    work: Cell<QueryWork>,
}

impl<'a> Obstacles<'a> {
    /// Only the static map.
    pub fn new(map: &'a StaticMap) -> Self {
        Obstacles::with_cones(map, Vec::new())
    }

    /// The static map and the given cones.
    pub fn with_cones(map: &'a StaticMap, cones: Vec<Pdc>) -> Self {
        Obstacles {
            map,
            cones,
            work: Cell::default(),
        }
    }

    /// The static map and the predictive directional cones of `forecasts` over
    /// `[t_start, t_start + horizon_s]` ([`forecast_cones`]).
    ///
    /// # Errors
    /// As [`forecast_cones`].
    pub fn with_forecast_cones(
        map: &'a StaticMap,
        forecasts: &[Forecast],
        t_start: f64,
        horizon_s: f64,
    ) -> Result<Self, PlanError> {
        Ok(Obstacles::with_cones(
            map,
            forecast_cones(forecasts, t_start, horizon_s)?,
        ))
    }

    /// The static map.
    pub fn map(&self) -> &'a StaticMap {
        self.map
    }

    /// The cones.
    pub fn cones(&self) -> &[Pdc] {
        &self.cones
    }

    /// The operations of the queries so far (a copy starts from the original's count;
    /// [`Obstacles::restricted_to`] from zero).
    pub fn work(&self) -> QueryWork {
        self.work.get()
    }

    fn charge(&self, f: impl FnOnce(&mut QueryWork)) {
        let mut w = self.work.get();
        f(&mut w);
        self.work.set(w);
    }

    /// Cone `i`'s line-of-sight test of `[a, b]` (`seg_box` its box), counted.
    pub(crate) fn cone_segment_clear(
        &self,
        i: usize,
        a: &Vec3,
        b: &Vec3,
        clearance: f64,
        seg_box: &Aabb,
    ) -> bool {
        let cone = &self.cones[i];
        let exact = cone.aabb().intersects(&seg_box.inflated(clearance));
        self.charge(|w| {
            w.cone_boxes += 1;
            w.cone_tests += u64::from(exact);
        });
        cone.segment_clear_in_box(a, b, clearance, seg_box)
    }

    /// The static map's line-of-sight test of `[a, b]`, counted.
    pub(crate) fn map_segment_clear(&self, a: &Vec3, b: &Vec3, clearance: f64) -> bool {
        let mut w = self.work.get();
        let clear = self.map.segment_clear_counted(a, b, clearance, &mut w.map);
        self.work.set(w);
        clear
    }

    /// Drops every cone for which `drop` returns true (e.g. cones that contain the start); returns how
    /// many were dropped.
    pub fn drop_cones(&mut self, mut drop: impl FnMut(&Pdc) -> bool) -> usize {
        let before = self.cones.len();
        self.cones.retain(|c| !drop(c));
        before - self.cones.len()
    }

    /// A copy that keeps only the cones whose boxes meet `region` (the static map is kept whole).
    pub fn restricted_to(&self, region: &Aabb) -> Obstacles<'a> {
        Obstacles::with_cones(
            self.map,
            self.cones
                .iter()
                .filter(|c| c.aabb().intersects(region))
                .copied()
                .collect(),
        )
    }

    /// True if nothing (no cone box, no static shape box, no voxel map) meets `region`: every segment
    /// inside it is then clear.
    #[cfg(test)]
    pub(crate) fn region_is_empty(&self, region: &Aabb, scratch: &mut Vec<usize>) -> bool {
        if self.cones.iter().any(|c| c.aabb().intersects(region)) {
            return false;
        }
        if self.map.esdf().is_some_and(|e| e.occupied_count() > 0) {
            return false;
        }
        self.map.shapes_near(region, scratch);
        scratch.is_empty()
    }

    /// Line of sight: every point of `[a, b]` keeps at least `threshold` from every obstacle.
    pub fn segment_clear(&self, a: &Vec3, b: &Vec3, threshold: f64) -> bool {
        if threshold.is_nan() || !a.iter().chain(b.iter()).all(|c| c.is_finite()) {
            return false;
        }
        let c = threshold.max(0.0);
        let seg_box = Aabb::from_segment(a, b);
        (0..self.cones.len()).all(|i| self.cone_segment_clear(i, a, b, c, &seg_box))
            && self.map_segment_clear(a, b, c)
    }

    /// True if `p` keeps at least `clearance` from every obstacle.
    pub fn is_free(&self, p: &Vec3, clearance: f64) -> bool {
        let cones_clear = self.cones.iter().all(|c| {
            let exact = c.aabb().inflated(clearance.max(0.0)).contains(p);
            self.charge(|w| {
                w.cone_boxes += 1;
                w.cone_tests += u64::from(exact);
            });
            c.point_clear(p, clearance)
        });
        cones_clear && {
            let mut w = self.work.get();
            let free = self.map.is_free_counted(p, clearance, &mut w.map);
            self.work.set(w);
            free
        }
    }

    /// Signed distance to the nearest obstacle (`+∞` when there is none).
    pub fn clearance(&self, p: &Vec3) -> f64 {
        self.distance_and_gradient(p).0
    }

    /// Signed distance to the nearest obstacle and its gradient (zero gradient when there is none).
    pub fn distance_and_gradient(&self, p: &Vec3) -> (f64, Vec3) {
        let mut w = self.work.get();
        let mut best = self.map.distance_and_gradient_counted(p, &mut w.map);
        for c in &self.cones {
            w.cone_boxes += 1;
            // A cone is no closer than its box: skip it when the box is not closer than the best.
            if c.aabb().distance_to_point(p) >= best.0 {
                continue;
            }
            w.cone_tests += 1;
            let (d, g) = c.distance_and_gradient(p);
            if d < best.0 {
                best = (d, g);
            }
        }
        self.work.set(w);
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use trust_geometry::{Shape, Sphere};

    fn map() -> StaticMap {
        let bounds =
            Aabb::new(Vec3::new(-10.0, -10.0, -10.0), Vec3::new(10.0, 10.0, 10.0)).unwrap();
        StaticMap::from_shapes(
            bounds,
            vec![Shape::from(
                Sphere::new(Vec3::new(0.0, 5.0, 0.0), 1.0).unwrap(),
            )],
        )
        .unwrap()
    }

    #[test]
    fn sees_map_and_cones() {
        let m = map();
        let ball = Forecast::sphere(Vec3::zeros(), Vec3::x(), 0.0, 1.0, 0.0, 0.0).unwrap();
        let obs = Obstacles::with_forecast_cones(&m, &[ball], 0.0, 1.0).unwrap();
        let (a, b) = (Vec3::new(-5.0, -3.0, 0.0), Vec3::new(5.0, -3.0, 0.0));
        assert!(obs.segment_clear(&a, &b, 0.1));
        assert!(!obs.segment_clear(&Vec3::new(-5.0, 0.0, 0.0), &Vec3::new(5.0, 0.0, 0.0), 0.0));
        assert!(!obs.segment_clear(&Vec3::new(-5.0, 5.0, 0.0), &Vec3::new(5.0, 5.0, 0.0), 0.0));
        assert!(!obs.is_free(&Vec3::new(0.5, 0.0, 0.0), 0.0));
        assert!((obs.clearance(&Vec3::new(0.5, 2.5, 0.0)) - 1.5).abs() < 1e-9);
        let mut scratch = Vec::new();
        let far = Aabb::new(Vec3::new(5.0, -9.0, -1.0), Vec3::new(6.0, -8.0, 1.0)).unwrap();
        assert!(obs.region_is_empty(&far, &mut scratch));
        assert!(obs.restricted_to(&far).cones().is_empty());
        let near = Aabb::new(Vec3::new(-1.0, 4.0, -1.0), Vec3::new(1.0, 6.0, 1.0)).unwrap();
        assert!(!obs.region_is_empty(&near, &mut scratch));
    }

    #[test]
    fn empty_world_is_all_clear() {
        let bounds = Aabb::new(Vec3::zeros(), Vec3::repeat(1.0)).unwrap();
        let m = StaticMap::new(bounds).unwrap();
        let obs = Obstacles::new(&m);
        assert!(obs.segment_clear(&Vec3::zeros(), &Vec3::repeat(1.0), 0.3));
        assert_eq!(obs.clearance(&Vec3::zeros()), f64::INFINITY);
    }
}
