//! The obstacle distribution of experiment E1's random scenes (paper Sec. IV-A): the paper gives
//! the box (20 × 20 × 10 m) and random dynamic obstacles but no distributions, so these are ours.
//! DEV-PRM's E1 scenes (`trust_topo_prm::scenes::SceneParams::default`) and the world's random
//! obstacle groups (`trust_world::scenario::RandomObstacles::default`) both start from them.

/// Obstacle speed range (m/s).
pub const SPEED_M_S: (f64, f64) = (0.5, 3.0);

/// Obstacle size `r_o` range (m): sphere radius, cylinder radius.
pub const RADIUS_M: (f64, f64) = (0.5, 1.5);

/// Fraction of obstacles that are full-height vertical cylinders (the rest are spheres).
pub const CYLINDER_FRACTION: f64 = 0.5;

/// Clearance (m) of the start and the goal from every obstacle at the query time.
pub const ENDPOINT_CLEARANCE_M: f64 = 1.0;
