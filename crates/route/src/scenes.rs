//! Standard maps for benchmarks, examples and tests of the route planner: an E4-size world
//! (250 × 75 × 20 m of blocks, walls and pillars, optionally a 30 m wall across the straight line)
//! and a Crazyflie-scale room (8 × 6 × 3 m with four 5 cm pillars and a wall across most of the
//! middle). Deterministic for a seed.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use trust_geometry::{AaBox, Aabb, Cylinder, GeometryError, Shape, StaticMap, Vec3};

/// Start and goal of [`e4_like`] (the paper's E4 mission: along the long axis at 5 m).
pub const E4_START_GOAL: [[f64; 3]; 2] = [[2.0, 37.5, 5.0], [248.0, 37.5, 5.0]];

/// An E4-like world: 40 blocks, 40 walls and 320 full-height pillars, 10 m kept free around
/// start and goal ([`E4_START_GOAL`]), plus (if `wall`) a 30 m wide full-height wall across the
/// straight line at x = 27 m.
///
/// # Errors
/// None in practice (every shape is valid); the map constructor's error is passed on.
pub fn e4_like(seed: u64, wall: bool) -> Result<StaticMap, GeometryError> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut shapes: Vec<Shape> = Vec::new();
    let x = |rng: &mut ChaCha8Rng| rng.random_range(12.0..238.0);
    let y = |rng: &mut ChaCha8Rng| rng.random_range(0.0..75.0);
    for _ in 0..40 {
        let c = Vec3::new(x(&mut rng), y(&mut rng), rng.random_range(2.0..8.0));
        let half = Vec3::new(
            rng.random_range(1.0..3.0),
            rng.random_range(1.0..3.0),
            rng.random_range(1.0..4.0),
        );
        shapes.push(AaBox::from_center_half_extents(c, half)?.into());
    }
    for _ in 0..40 {
        let c = Vec3::new(x(&mut rng), y(&mut rng), 10.0);
        let half = if rng.random_bool(0.5) {
            Vec3::new(0.3, rng.random_range(2.0..6.0), 10.0)
        } else {
            Vec3::new(rng.random_range(2.0..6.0), 0.3, 10.0)
        };
        shapes.push(AaBox::from_center_half_extents(c, half)?.into());
    }
    for _ in 0..320 {
        let c = Vec3::new(x(&mut rng), y(&mut rng), 10.0);
        shapes.push(Cylinder::new(c, rng.random_range(0.3..0.8), 10.0)?.into());
    }
    if wall {
        let c = Vec3::new(27.0, 37.5, 10.0);
        shapes.push(AaBox::from_center_half_extents(c, Vec3::new(0.5, 15.0, 10.0))?.into());
    }
    let bounds = Aabb::new(Vec3::zeros(), Vec3::new(250.0, 75.0, 20.0))?;
    StaticMap::from_shapes(bounds, shapes)
}

/// An 8 × 6 × 3 m room with four 5 cm pillars and a wall across most of the middle (x = 4 m,
/// from y = 0 to 4.5 m).
///
/// # Errors
/// None in practice; the map constructor's error is passed on.
pub fn crazyflie_room() -> Result<StaticMap, GeometryError> {
    let mut shapes: Vec<Shape> = Vec::new();
    for (x, y) in [(2.5, 2.0), (2.5, 4.0), (5.5, 2.0), (5.5, 4.0)] {
        shapes.push(Cylinder::new(Vec3::new(x, y, 1.5), 0.05, 1.5)?.into());
    }
    shapes.push(AaBox::new(Vec3::new(3.9, 0.0, 0.0), Vec3::new(4.1, 4.5, 3.0))?.into());
    let bounds = Aabb::new(Vec3::zeros(), Vec3::new(8.0, 6.0, 3.0))?;
    StaticMap::from_shapes(bounds, shapes)
}
