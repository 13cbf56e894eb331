//! Standard maps for benchmarks, examples and tests of the route planner: an E4-size world
//! (250 × 75 × 20 m of blocks, walls and pillars, optionally a 30 m wall across the straight line)
//! and a Crazyflie-scale room (8 × 6 × 3 m with four 5 cm pillars and a wall across most of the
//! middle); the tail cases (a goal sealed in a closed box 35 m from the start, in a room and in
//! an E4 world; a full wall with one slot); a point cloud of a map's shapes, for the same world
//! as a voxel ESDF. Deterministic for a seed.

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
    let bounds = Aabb::new(Vec3::zeros(), Vec3::new(250.0, 75.0, 20.0))?;
    StaticMap::from_shapes(bounds, e4_shapes(seed, wall)?)
}

/// The shapes of [`e4_like`].
fn e4_shapes(seed: u64, wall: bool) -> Result<Vec<Shape>, GeometryError> {
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
    Ok(shapes)
}

/// The six 0.3 m walls of a closed box of outer half-size `half` around `centre`.
///
/// # Errors
/// None for a positive `half` above 0.3 m; the box constructor's error is passed on.
pub fn closed_box(centre: Vec3, half: f64) -> Result<Vec<Shape>, GeometryError> {
    box_with_hole(centre, half, 0.3, 0.0)
}

/// The walls (`t` thick) of a box of outer half-size `half` around `centre`, with a square hole
/// of side `hole` in the middle of its +x wall (none when `hole` is 0): the +x wall is then four
/// pieces around the hole.
///
/// # Errors
/// None for `half > t > 0` and `hole < 2 (half - t)`; the box constructor's error is passed on.
pub fn box_with_hole(
    centre: Vec3,
    half: f64,
    t: f64,
    hole: f64,
) -> Result<Vec<Shape>, GeometryError> {
    let (lo, hi) = (centre - Vec3::repeat(half), centre + Vec3::repeat(half));
    let mut out = Vec::new();
    for a in 0..3 {
        for far in [false, true] {
            let (mut min, mut max) = (lo, hi);
            if far {
                min[a] = hi[a] - t;
            } else {
                max[a] = lo[a] + t;
            }
            if a == 0 && far && hole > 0.0 {
                let (y0, y1) = (centre.y - hole / 2.0, centre.y + hole / 2.0);
                let (z0, z1) = (centre.z - hole / 2.0, centre.z + hole / 2.0);
                for (ylo, yhi, zlo, zhi) in [
                    (min.y, y0, min.z, max.z),
                    (y1, max.y, min.z, max.z),
                    (y0, y1, min.z, z0),
                    (y0, y1, z1, max.z),
                ] {
                    let (p, q) = (Vec3::new(min.x, ylo, zlo), Vec3::new(max.x, yhi, zhi));
                    out.push(AaBox::new(p, q)?.into());
                }
                continue;
            }
            out.push(AaBox::new(min, max)?.into());
        }
    }
    Ok(out)
}

/// A 60 × 20 × 10 m room with the goal sealed in a closed 4 m box 35 m from the start:
/// the map, the start and the goal.
///
/// # Errors
/// None in practice; the map constructor's error is passed on.
pub fn sealed_goal_room() -> Result<(StaticMap, Vec3, Vec3), GeometryError> {
    let (start, goal) = (Vec3::new(5.0, 10.0, 5.0), Vec3::new(40.0, 10.0, 5.0));
    let bounds = Aabb::new(Vec3::zeros(), Vec3::new(60.0, 20.0, 10.0))?;
    Ok((
        StaticMap::from_shapes(bounds, closed_box(goal, 2.0)?)?,
        start,
        goal,
    ))
}

/// The [`e4_like`] world (no wall) with the goal sealed in a closed 4 m box 35 m from the E4
/// start: the map, the start and the goal.
///
/// # Errors
/// None in practice; the map constructor's error is passed on.
pub fn sealed_goal_e4(seed: u64) -> Result<(StaticMap, Vec3, Vec3), GeometryError> {
    let start = Vec3::from(E4_START_GOAL[0]);
    let goal = start + Vec3::new(35.0, 0.0, 0.0);
    let mut shapes = e4_shapes(seed, false)?;
    shapes.extend(closed_box(goal, 2.0)?);
    let bounds = Aabb::new(Vec3::zeros(), Vec3::new(250.0, 75.0, 20.0))?;
    Ok((StaticMap::from_shapes(bounds, shapes)?, start, goal))
}

/// A 60 × 20 × 10 m room cut at x = 30 m by a 1 m full wall with one vertical slot of `width`
/// (from y = 10 m): the map, the start and the goal on either side.
///
/// # Errors
/// An error for a non-positive `width`; the map constructor's error is passed on.
pub fn slot_wall(width: f64) -> Result<(StaticMap, Vec3, Vec3), GeometryError> {
    let bounds = Aabb::new(Vec3::zeros(), Vec3::new(60.0, 20.0, 10.0))?;
    let shapes: Vec<Shape> = vec![
        AaBox::new(Vec3::new(29.5, -1.0, -1.0), Vec3::new(30.5, 10.0, 11.0))?.into(),
        AaBox::new(
            Vec3::new(29.5, 10.0 + width, -1.0),
            Vec3::new(30.5, 21.0, 11.0),
        )?
        .into(),
    ];
    Ok((
        StaticMap::from_shapes(bounds, shapes)?,
        Vec3::new(2.0, 5.0, 3.0),
        Vec3::new(58.0, 5.0, 3.0),
    ))
}

/// The points of a lattice of spacing `spacing` (offset by half a spacing) inside `map`'s
/// bounds that lie inside one of its shapes: a point cloud of the map, for the same world as a
/// voxel ESDF (`StaticMap::with_point_cloud`).
pub fn shape_cloud(map: &StaticMap, spacing: f64) -> Vec<Vec3> {
    let b = map.bounds();
    let mut out = Vec::new();
    for shape in map.shapes() {
        let a = shape.aabb();
        let lo = Vec3::from_fn(|i, _| a.min[i].max(b.min[i]));
        let hi = Vec3::from_fn(|i, _| a.max[i].min(b.max[i]));
        let n = |i: usize| ((hi[i] - lo[i]) / spacing).floor().max(0.0) as usize + 1;
        for k in 0..n(2) {
            for j in 0..n(1) {
                for i in 0..n(0) {
                    let p =
                        lo + Vec3::new(i as f64 + 0.5, j as f64 + 0.5, k as f64 + 0.5) * spacing;
                    if b.contains(&p) && shape.signed_distance(&p) <= 0.0 {
                        out.push(p);
                    }
                }
            }
        }
    }
    out
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
