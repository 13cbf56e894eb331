//! Random dynamic scenes for experiment E1 (paper Sec. IV-A, Fig. Sim-A-1-1(c)), shared by the example,
//! the tests and the benches.
//!
//! A box (20 × 20 × 10 m by default) without static obstacles, `k` moving obstacles — spheres and
//! full-height vertical cylinders with random size, speed and uncertainty growth — and a start and a
//! goal on opposite sides (x = margin and x = size − margin) that are free at the query time.

use rand::Rng as _;
use serde::{Deserialize, Serialize};

use trust_core::{
    Aabb, Forecast, Limits, ObstacleShape, PathQuery, PlanError, Rng, State, StaticMap, Vec3,
    check_finite_vec, check_non_negative, check_positive,
};

/// How random scenes are drawn. Defaults follow the E1 setting of the paper (20 × 20 × 10 m, random
/// dynamic obstacles); the paper gives no obstacle distributions, so those are ours.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SceneParams {
    /// Size of the box `[0, size]` (m). Paper: 20 × 20 × 10.
    /// Accepted: each component in `[1e-9, 1e6]` m, more than twice `margin`.
    pub size: Vec3,
    /// Obstacle speed range (m/s). Ours: 0.5–3.
    /// Accepted: `0 ≤ lo ≤ hi ≤ 1e4` m/s.
    pub speed: (f64, f64),
    /// Obstacle size `r_o` range (m). Ours: 0.5–1.5.
    /// Accepted: `0 < lo ≤ hi ≤ 1e6` m.
    pub radius: (f64, f64),
    /// Uncertainty growth `mu` range (m/s). Ours: 0.1–0.3.
    /// Accepted: `0 ≤ lo ≤ hi ≤ 1e4` m/s.
    pub mu: (f64, f64),
    /// Safety margin `r_safe` of every forecast (m). Ours: 0.
    /// Accepted: `[0, 1e6]` m.
    pub r_safe: f64,
    /// Probability that an obstacle is a full-height vertical cylinder (else a sphere). Ours: 0.5.
    /// Accepted: `[0, 1]`.
    pub cylinder_fraction: f64,
    /// Distance of start and goal from the box faces (m). Ours: 1.
    /// Accepted: `≥ 0` and less than half the smallest `size` component.
    pub margin: f64,
    /// Start and goal keep at least this distance from every obstacle at the query time (m). Ours: 1.
    /// Accepted: `[0, 1e6]` m.
    pub endpoint_clearance: f64,
    /// Planning horizon `T_h` of the query (s). Ours: 2 (the 18 m crossing at 10 m/s takes ~2 s).
    /// Accepted: `[1e-9, 1e7]` s.
    pub horizon_s: f64,
    /// Vehicle limits of the query. Paper Sec. IV: 10 m/s, 15 m/s².
    pub limits: Limits,
}

impl Default for SceneParams {
    fn default() -> Self {
        SceneParams {
            size: Vec3::new(20.0, 20.0, 10.0),
            speed: trust_scenes::e1::SPEED_M_S,
            radius: trust_scenes::e1::RADIUS_M,
            mu: (0.1, 0.3),
            r_safe: 0.0,
            cylinder_fraction: trust_scenes::e1::CYLINDER_FRACTION,
            margin: 1.0,
            endpoint_clearance: trust_scenes::e1::ENDPOINT_CLEARANCE_M,
            horizon_s: 2.0,
            limits: Limits::default(),
        }
    }
}

fn check_range(field: &str, (lo, hi): (f64, f64), positive: bool) -> Result<(), PlanError> {
    let ok =
        lo.is_finite() && hi.is_finite() && lo <= hi && if positive { lo > 0.0 } else { lo >= 0.0 };
    if ok {
        Ok(())
    } else {
        Err(PlanError::invalid(
            field,
            (lo, hi),
            if positive {
                "finite (lo, hi) with 0 < lo <= hi"
            } else {
                "finite (lo, hi) with 0 <= lo <= hi"
            },
        ))
    }
}

impl SceneParams {
    /// Checks every field.
    pub fn validate(&self) -> Result<(), PlanError> {
        use trust_core::scale::{self, Quantity};
        check_finite_vec("scene.size", &self.size)?;
        for i in 0..3 {
            check_positive("scene.size", self.size[i])?;
        }
        scale::check_vec("scene.size", &self.size, Quantity::PositiveLength)?;
        check_range("scene.speed", self.speed, false)?;
        crate::ranges::quantity("scene.speed.1", self.speed.1, Quantity::Rate)?;
        check_range("scene.radius", self.radius, true)?;
        crate::ranges::quantity("scene.radius.1", self.radius.1, Quantity::Length)?;
        check_range("scene.mu", self.mu, false)?;
        crate::ranges::quantity("scene.mu.1", self.mu.1, Quantity::Rate)?;
        crate::ranges::quantity("scene.r_safe", self.r_safe, Quantity::Length)?;
        crate::ranges::quantity(
            "scene.endpoint_clearance",
            self.endpoint_clearance,
            Quantity::Length,
        )?;
        crate::ranges::quantity(
            "scene.horizon_s",
            self.horizon_s,
            Quantity::PositiveDuration,
        )?;
        if !(0.0..=1.0).contains(&self.cylinder_fraction) {
            return Err(PlanError::invalid(
                "scene.cylinder_fraction",
                self.cylinder_fraction,
                "a probability in [0, 1]",
            ));
        }
        check_non_negative("scene.margin", self.margin)?;
        check_non_negative("scene.endpoint_clearance", self.endpoint_clearance)?;
        if 2.0 * self.margin >= self.size.x.min(self.size.y).min(self.size.z) {
            return Err(PlanError::invalid(
                "scene.margin",
                self.margin,
                format!(
                    "less than half the smallest component of scene.size = {:?}",
                    [self.size.x, self.size.y, self.size.z]
                ),
            ));
        }
        check_positive("scene.horizon_s", self.horizon_s)?;
        self.limits.validate()
    }
}

/// A random dynamic scene with its query.
#[derive(Debug, Clone)]
pub struct RandomScene {
    /// The static map: bounds only.
    pub map: StaticMap,
    /// The moving obstacles, forecast at `t = 0`.
    pub forecasts: Vec<Forecast>,
    /// Start (at rest, `t = 0`) and goal.
    pub query: PathQuery,
}

/// Attempts per obstacle to find a placement that keeps start and goal free.
const PLACEMENT_ATTEMPTS: usize = 1000;

/// Draws a scene with `k` moving obstacles from `params` (all randomness from `rng`). Errors on invalid
/// params, or if an obstacle cannot be placed away from start and goal in 1000 attempts.
pub fn random_dynamic_scene(
    k: usize,
    params: &SceneParams,
    rng: &mut Rng,
) -> Result<RandomScene, PlanError> {
    params.validate()?;
    let size = params.size;
    let map = StaticMap::new(Aabb::new(Vec3::zeros(), size)?)?;
    let m = params.margin;
    let uniform = |lo: f64, hi: f64, rng: &mut Rng| {
        if hi > lo {
            rng.random_range(lo..hi)
        } else {
            lo
        }
    };
    let start = Vec3::new(m, uniform(m, size.y - m, rng), uniform(m, size.z - m, rng));
    let goal = Vec3::new(
        size.x - m,
        uniform(m, size.y - m, rng),
        uniform(m, size.z - m, rng),
    );
    let mut forecasts = Vec::with_capacity(k);
    for i in 0..k {
        let mut placed = None;
        for _ in 0..PLACEMENT_ATTEMPTS {
            let cylinder = rng.random_bool(params.cylinder_fraction);
            let r_o = uniform(params.radius.0, params.radius.1, rng);
            let speed = uniform(params.speed.0, params.speed.1, rng);
            let mu = uniform(params.mu.0, params.mu.1, rng);
            let yaw = uniform(0.0, std::f64::consts::TAU, rng);
            let (shape, p0, v0) = if cylinder {
                let p0 = Vec3::new(
                    uniform(0.0, size.x, rng),
                    uniform(0.0, size.y, rng),
                    0.5 * size.z,
                );
                let v0 = Vec3::new(yaw.cos(), yaw.sin(), 0.0) * speed;
                (
                    ObstacleShape::Cylinder {
                        half_height: 0.5 * size.z,
                    },
                    p0,
                    v0,
                )
            } else {
                let p0 = Vec3::new(
                    uniform(0.0, size.x, rng),
                    uniform(0.0, size.y, rng),
                    uniform(0.0, size.z, rng),
                );
                let z = uniform(-1.0, 1.0, rng);
                let ring = (1.0 - z * z).sqrt();
                let v0 = Vec3::new(ring * yaw.cos(), ring * yaw.sin(), z) * speed;
                (ObstacleShape::Sphere, p0, v0)
            };
            let f = Forecast::new(shape, p0, v0, 0.0, r_o, params.r_safe, mu)?;
            let clear = |p: &Vec3| f.signed_distance(p, 0.0) >= params.endpoint_clearance;
            if clear(&start) && clear(&goal) {
                placed = Some(f);
                break;
            }
        }
        let Some(f) = placed else {
            return Err(PlanError::invalid(
                format!("scene obstacle {i}"),
                PLACEMENT_ATTEMPTS,
                "a placement that keeps start and goal free (reduce scene.radius, scene.r_safe or \
                 scene.endpoint_clearance, or enlarge scene.size)",
            ));
        };
        forecasts.push(f);
    }
    Ok(RandomScene {
        map,
        forecasts,
        query: PathQuery {
            start: State::at_rest(0.0, start),
            goal,
            limits: params.limits,
            horizon_s: params.horizon_s,
            exploration: 1.0,
        },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn scenes_are_valid_and_reproducible() {
        let p = SceneParams::default();
        let a = random_dynamic_scene(10, &p, &mut Rng::seed_from_u64(7)).unwrap();
        let b = random_dynamic_scene(10, &p, &mut Rng::seed_from_u64(7)).unwrap();
        assert_eq!(a.forecasts, b.forecasts);
        assert_eq!(a.query, b.query);
        assert_eq!(a.forecasts.len(), 10);
        for f in &a.forecasts {
            assert!(f.validate().is_ok());
            assert!(f.signed_distance(&a.query.start.p, 0.0) >= 1.0);
            let speed = f.v0.norm();
            assert!((0.5..=3.0).contains(&speed), "{speed}");
        }
        assert!(a.query.validate().is_ok());
        assert!(a.map.contains(&a.query.start.p) && a.map.contains(&a.query.goal));
        assert!(
            random_dynamic_scene(0, &p, &mut Rng::seed_from_u64(1))
                .unwrap()
                .forecasts
                .is_empty()
        );
    }

    #[test]
    fn bad_params_are_rejected() {
        let p = SceneParams {
            radius: (2.0, 1.0),
            ..SceneParams::default()
        };
        let e = random_dynamic_scene(1, &p, &mut Rng::seed_from_u64(1))
            .unwrap_err()
            .to_string();
        assert!(e.contains("scene.radius"), "{e}");
        let p = SceneParams {
            cylinder_fraction: 1.5,
            ..SceneParams::default()
        };
        assert!(p.validate().is_err());
    }
}
