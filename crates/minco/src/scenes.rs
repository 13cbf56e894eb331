//! Deterministic scenes for experiment E2 (design.md §5; paper Sec. IV-B, Table Sim-A-2 and Figs.
//! Sim-A-2-1 / Sim-A-2-2): a 50 × 20 × 10 m map crossed from `(1, 10, 5)` to `(49, 10, 5)` at the
//! paper's limits (`v_max = 10 m/s`, `a_max = 15 m/s²`).
//!
//! - [`e2_static`]: five static obstacles (three columns, two balls) on and beside the straight
//!   line, no moving obstacles; the guide path weaves between them.
//! - [`e2_dynamic`]: an empty static map and five moving obstacles (balls and columns) that
//!   cross the straight line one after the other and then drift into the goal region, so that a
//!   trajectory forced to stop on the goal meets them ("the moving obstacles gradually block the
//!   trajectories and the terminal states", Fig. Sim-A-2-2). The guide is the straight line.
//!
//! The exact obstacle layout of the paper is not published; these are ours, built to exercise
//! the same situations.

use trust_core::{Aabb, Forecast, GuidePath, Limits, ObstacleShape, Scene, State, StaticMap, Vec3};
use trust_geometry::{Cylinder, Shape, Sphere};

/// One E2 case: map, forecasts, start, goal, limits and a guide path.
#[derive(Debug, Clone)]
pub struct E2Case {
    /// `"static"` or `"dynamic"`.
    pub name: &'static str,
    /// Static obstacles and bounds `[0, 50] × [0, 20] × [0, 10]`.
    pub map: StaticMap,
    /// Moving obstacles, forecast at `t0`.
    pub forecasts: Vec<Forecast>,
    /// Time of the forecasts and of the start (s).
    pub t0: f64,
    /// Start state (at rest).
    pub start: State,
    /// Goal.
    pub goal: Vec3,
    /// The paper's limits (Sec. IV): 10 m/s, 15 m/s².
    pub limits: Limits,
    /// Vertices of the guide path, start first, goal last.
    pub guide_points: Vec<Vec3>,
}

impl E2Case {
    /// The scene the backends see.
    pub fn scene(&self) -> Scene<'_> {
        Scene {
            map: &self.map,
            forecasts: &self.forecasts,
            t0: self.t0,
        }
    }

    /// The guide path.
    pub fn guide(&self) -> GuidePath {
        GuidePath {
            points: self.guide_points.clone(),
        }
    }
}

const START: Vec3 = Vec3::new(1.0, 10.0, 5.0);
const GOAL: Vec3 = Vec3::new(49.0, 10.0, 5.0);

fn bounds() -> Aabb {
    Aabb {
        min: Vec3::zeros(),
        max: Vec3::new(50.0, 20.0, 10.0),
    }
}

fn column(x: f64, y: f64, radius: f64) -> Shape {
    Shape::Cylinder(Cylinder {
        center: Vec3::new(x, y, 5.0),
        radius,
        half_height: 5.0,
    })
}

fn ball(x: f64, y: f64, z: f64, radius: f64) -> Shape {
    Shape::Sphere(Sphere {
        center: Vec3::new(x, y, z),
        radius,
    })
}

/// The static case: columns at `x = 12, 24, 32`, balls at `x = 18, 40`, on or near the straight
/// line; the guide passes each with at least 0.8 m of clearance.
pub fn e2_static() -> E2Case {
    let shapes = vec![
        column(12.0, 10.5, 1.2),
        ball(18.0, 8.0, 5.0, 1.2),
        column(24.0, 11.5, 1.2),
        column(32.0, 8.8, 1.2),
        ball(40.0, 10.5, 5.5, 1.5),
    ];
    let map = StaticMap::from_shapes(bounds(), shapes).expect("E2 static shapes are valid");
    E2Case {
        name: "static",
        map,
        forecasts: Vec::new(),
        t0: 0.0,
        start: State::at_rest(0.0, START),
        goal: GOAL,
        limits: Limits::default(),
        guide_points: vec![
            START,
            Vec3::new(12.0, 8.2, 5.0),
            Vec3::new(18.0, 10.2, 5.0),
            Vec3::new(24.0, 9.2, 5.0),
            Vec3::new(32.0, 11.0, 5.0),
            Vec3::new(40.0, 8.0, 5.0),
            GOAL,
        ],
    }
}

/// A forecast at `t0 = 0` with `r_safe = 0.2 m` and `μ_o = 0.05 m/s`.
fn moving(shape: ObstacleShape, p0: Vec3, v0: Vec3, r_o: f64) -> Forecast {
    Forecast::new(shape, p0, v0, 0.0, r_o, 0.2, 0.05).expect("E2 forecasts are valid")
}

/// The dynamic case: no static obstacles; five moving obstacles. Times are for a vehicle that
/// averages about 7–8 m/s along the straight line:
/// - a ball crossing `x = 15` (downward in y) at about 2 s;
/// - a column crossing `x = 28` (upward in y) at about 3.5 s;
/// - a ball flying head-on along the line from the goal side;
/// - a ball that drifts onto the goal at about 6 s and a column that reaches it at about 6.7 s
///   (they block the terminal state).
pub fn e2_dynamic() -> E2Case {
    let map = StaticMap::empty(bounds()).expect("E2 bounds have a volume");
    let column = ObstacleShape::Cylinder { half_height: 5.0 };
    let forecasts = vec![
        moving(
            ObstacleShape::Sphere,
            Vec3::new(15.0, 16.0, 5.0),
            Vec3::new(0.0, -3.0, 0.0),
            0.8,
        ),
        moving(
            column,
            Vec3::new(28.0, 3.0, 5.0),
            Vec3::new(0.0, 2.0, 0.0),
            0.8,
        ),
        moving(
            ObstacleShape::Sphere,
            Vec3::new(45.0, 10.5, 5.0),
            Vec3::new(-2.0, 0.0, 0.0),
            0.8,
        ),
        moving(
            ObstacleShape::Sphere,
            Vec3::new(49.0, 16.0, 5.0),
            Vec3::new(0.0, -1.0, 0.0),
            1.0,
        ),
        moving(
            column,
            Vec3::new(46.0, 2.0, 5.0),
            Vec3::new(0.0, 1.2, 0.0),
            0.8,
        ),
    ];
    E2Case {
        name: "dynamic",
        map,
        forecasts,
        t0: 0.0,
        start: State::at_rest(0.0, START),
        goal: GOAL,
        limits: Limits::default(),
        guide_points: vec![START, GOAL],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn static_guide_is_clear_and_inside() {
        let case = e2_static();
        let scene = case.scene();
        for w in case.guide_points.windows(2) {
            assert!(
                case.map.segment_clear(&w[0], &w[1], 0.5),
                "{:?} -> {:?}",
                w[0],
                w[1]
            );
            assert!(scene.check_in_bounds("p", &w[0]).is_ok());
        }
        // The straight line is blocked: the guide matters.
        assert!(!case.map.segment_clear(&START, &GOAL, 0.0));
    }

    #[test]
    fn dynamic_obstacles_block_the_straight_line_and_the_goal() {
        let case = e2_dynamic();
        let scene = case.scene();
        // The goal is blocked around 6-7 s.
        let blocked_goal =
            (0..=40).any(|k| scene.dynamic_clearance(&GOAL, 5.0 + 0.05 * k as f64) < 0.0);
        assert!(blocked_goal);
        // A straight constant-speed flight of 6.5 s collides.
        let collides = (0..=650).any(|k| {
            let t = 0.01 * k as f64;
            scene.dynamic_clearance(&(START + (GOAL - START) * (t / 6.5)), t) < 0.0
        });
        assert!(collides);
        assert!(scene.static_clearance(&START).is_infinite());
    }

    #[test]
    fn cases_are_deterministic() {
        let (a, b) = (e2_dynamic(), e2_dynamic());
        assert_eq!(a.forecasts, b.forecasts);
        assert_eq!(e2_static().guide_points, e2_static().guide_points);
    }
}
