//! What a planner sees at one instant: the static map and the forecasts of the moving obstacles.

use trust_geometry::StaticMap;
use trust_predict::Forecast;

use crate::error::{check_finite_vec, check_scaled};
use crate::{PlanError, Vec3};
use trust_geometry::scale::Quantity;

/// The world as one planning call sees it: the static map plus forecasts of moving obstacles, all made
/// at time `t0` (s). Cheap to build (it only borrows), so build one per planning cycle.
#[derive(Debug, Clone, Copy)]
pub struct Scene<'a> {
    /// Static obstacles and map bounds.
    pub map: &'a StaticMap,
    /// Forecasts of the moving obstacles (each carries its own `t0`; usually equal to `Scene::t0`).
    pub forecasts: &'a [Forecast],
    /// Time at which the scene was observed (s).
    pub t0: f64,
}

impl<'a> Scene<'a> {
    /// A validated scene: `t0` finite and every forecast valid (finite vectors and times, positive
    /// size, non-negative margin and growth rate). The error names the forecast's index.
    pub fn new(map: &'a StaticMap, forecasts: &'a [Forecast], t0: f64) -> Result<Self, PlanError> {
        check_scaled("scene.t0", t0, Quantity::Time)?;
        for (i, f) in forecasts.iter().enumerate() {
            check_finite_vec(&format!("scene.forecasts[{i}].p0"), &f.p0)?;
            check_finite_vec(&format!("scene.forecasts[{i}].v0"), &f.v0)?;
            check_scaled(&format!("scene.forecasts[{i}].t0"), f.t0, Quantity::Time)?;
            f.validate().map_err(|e| {
                PlanError::invalid(format!("scene.forecasts[{i}]"), f, e.to_string())
            })?;
        }
        Ok(Scene { map, forecasts, t0 })
    }

    /// Signed distance from `p` to the static map (`+∞` for an empty map).
    pub fn static_clearance(&self, p: &Vec3) -> f64 {
        self.map.signed_distance(p)
    }

    /// Smallest signed distance from `p` to the moving obstacles as forecast at absolute time `t`
    /// (`+∞` without forecasts).
    pub fn dynamic_clearance(&self, p: &Vec3, t: f64) -> f64 {
        self.forecasts
            .iter()
            .map(|f| f.signed_distance(p, t))
            .fold(f64::INFINITY, f64::min)
    }

    /// Smallest signed distance from `p` to anything at absolute time `t`.
    pub fn clearance(&self, p: &Vec3, t: f64) -> f64 {
        self.static_clearance(p).min(self.dynamic_clearance(p, t))
    }

    /// `Ok` if `p` is inside the map bounds, else [`PlanError::OutOfBounds`] naming `field`.
    pub fn check_in_bounds(&self, field: &str, p: &Vec3) -> Result<(), PlanError> {
        let b = self.map.bounds();
        if b.contains(p) {
            Ok(())
        } else {
            Err(PlanError::OutOfBounds {
                field: field.to_string(),
                point: [p.x, p.y, p.z],
                min: [b.min.x, b.min.y, b.min.z],
                max: [b.max.x, b.max.y, b.max.z],
            })
        }
    }

    /// `Ok` if `p` keeps at least `needed` metres from the static map, else [`PlanError::InCollision`].
    pub fn check_static_free(&self, field: &str, p: &Vec3, needed: f64) -> Result<(), PlanError> {
        let clearance = self.static_clearance(p);
        if clearance >= needed {
            Ok(())
        } else {
            Err(PlanError::InCollision {
                field: field.to_string(),
                point: [p.x, p.y, p.z],
                clearance,
                needed,
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use trust_geometry::{Aabb, Shape, Sphere};
    use trust_predict::ObstacleShape;

    fn map() -> StaticMap {
        let bounds = Aabb::new(Vec3::zeros(), Vec3::new(10.0, 10.0, 5.0)).unwrap();
        let pillar = Shape::Sphere(Sphere::new(Vec3::new(5.0, 5.0, 2.0), 1.0).unwrap());
        StaticMap::from_shapes(bounds, vec![pillar]).unwrap()
    }

    fn ball(p0: Vec3, v0: Vec3) -> Forecast {
        Forecast::new(ObstacleShape::Sphere, p0, v0, 0.0, 0.5, 0.0, 0.0).unwrap()
    }

    #[test]
    fn clearance_combines_static_and_moving_obstacles() {
        let map = map();
        let forecasts = [ball(Vec3::new(1.0, 1.0, 1.0), Vec3::new(1.0, 0.0, 0.0))];
        let scene = Scene::new(&map, &forecasts, 0.0).unwrap();
        let p = Vec3::new(3.0, 1.0, 1.0);
        // At t = 2 the ball is centred on p.
        assert!((scene.dynamic_clearance(&p, 2.0) + 0.5).abs() < 1e-12);
        assert!(scene.clearance(&p, 2.0) < 0.0);
        assert!(scene.clearance(&p, 0.0) > 0.0);
        let inside_pillar = Vec3::new(5.0, 5.0, 2.0);
        assert!(
            scene
                .check_static_free("start", &inside_pillar, 0.0)
                .is_err()
        );
        assert!(
            scene
                .check_in_bounds("goal", &Vec3::new(11.0, 0.0, 0.0))
                .is_err()
        );
        assert!(
            scene
                .check_in_bounds("goal", &Vec3::new(9.0, 9.0, 4.0))
                .is_ok()
        );
    }

    #[test]
    fn empty_scene_has_infinite_dynamic_clearance() {
        let map = map();
        let scene = Scene::new(&map, &[], 0.0).unwrap();
        assert_eq!(scene.dynamic_clearance(&Vec3::zeros(), 1.0), f64::INFINITY);
    }

    #[test]
    fn invalid_forecasts_are_named() {
        let map = map();
        let mut bad = ball(Vec3::zeros(), Vec3::zeros());
        bad.r_o = -1.0;
        let forecasts = [ball(Vec3::zeros(), Vec3::zeros()), bad];
        let e = Scene::new(&map, &forecasts, 0.0).unwrap_err().to_string();
        assert!(e.contains("scene.forecasts[1]"), "{e}");
        let mut nan = ball(Vec3::zeros(), Vec3::zeros());
        nan.v0.x = f64::NAN;
        let e = Scene::new(&map, &[nan], 0.0).unwrap_err().to_string();
        assert!(e.contains("scene.forecasts[0].v0"), "{e}");
        assert!(Scene::new(&map, &[], f64::NAN).is_err());
    }
}
