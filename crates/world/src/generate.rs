//! The layout of a world: static shapes and initial moving obstacles, generated from the
//! scenario and its world seed (the distributions are documented in [`crate`]).

use rand::{Rng as _, SeedableRng};
use trust_core::{Aabb, Rng, Vec3};
use trust_geometry::{AaBox, Cylinder, Shape};
use trust_predict::ObstacleShape;

use crate::problem::{Problems, fmt_bounds, fmt_count, fmt_num, fmt_vec};
use crate::scenario::scale::{MAX_PLACEMENT_WORK, check_sampled_points, sampled_point_bound};
use crate::scenario::{
    DynamicForestParams, E4Params, GeneratorSpec, PointCloudSpec, Problem, RandomObstacles,
    Scenario,
};
use crate::traffic::{Motion, MovingObstacle, MovingShape};

/// Draws per obstacle before a placement is given up.
pub(crate) const PLACEMENT_ATTEMPTS: usize = 1000;

/// Static shapes and initial moving obstacles, with where each came from (for messages).
#[derive(Debug, Clone, Default)]
pub(crate) struct Layout {
    /// Generated shapes first, then `static.shapes` in file order.
    pub(crate) shapes: Vec<Shape>,
    pub(crate) generated_shape_count: usize,
    /// Generated obstacles, then `[[obstacles]]`, then each `[[random_obstacles]]` group.
    pub(crate) obstacles: Vec<MovingObstacle>,
    pub(crate) obstacle_origins: Vec<String>,
}

/// Distance tests the placements of one world may still make (the scale policy's
/// [`MAX_PLACEMENT_WORK`]): every rejection-sampling attempt spends one test per shape it is
/// compared with.
struct Work {
    left: u64,
}

impl Work {
    fn new() -> Self {
        Work {
            left: MAX_PLACEMENT_WORK,
        }
    }

    /// Spends `n` tests; `false` once the budget is gone.
    fn spend(&mut self, n: usize) -> bool {
        let n = n.max(1) as u64;
        if n > self.left {
            self.left = 0;
            false
        } else {
            self.left -= n;
            true
        }
    }
}

/// The problem of a placement that ran out of [`Work`].
fn out_of_work(field: String, count: usize, placed: usize) -> Problem {
    Problem::new(
        field,
        count,
        format!(
            "a count that can be placed within the placement budget ({} distance tests per world, \
             scale policy; {placed} were placed): fewer obstacles, more room, or fewer shapes to \
             avoid",
            fmt_count(MAX_PLACEMENT_WORK as u128)
        ),
    )
}

/// One placement by rejection, the routine of every generator: up to [`PLACEMENT_ATTEMPTS`]
/// draws, each spending `cost` tests of `work` first; `draw` returns `Ok(Some(_))` for an
/// accepted draw, `Ok(None)` for a rejected one. `Ok(None)` when every attempt was rejected.
///
/// # Errors
/// `out_of_work()` once the budget is gone; an error of `draw`.
fn place_by_rejection<T>(
    work: &mut Work,
    cost: usize,
    out_of_work: impl FnOnce() -> Problem,
    mut draw: impl FnMut() -> Result<Option<T>, Problem>,
) -> Result<Option<T>, Problem> {
    for _ in 0..PLACEMENT_ATTEMPTS {
        if !work.spend(cost) {
            return Err(out_of_work());
        }
        if let Some(t) = draw()? {
            return Ok(Some(t));
        }
    }
    Ok(None)
}

impl Layout {
    pub(crate) fn shape_origin(&self, i: usize) -> String {
        if i < self.generated_shape_count {
            format!("generated static shape {i}")
        } else {
            format!("static.shapes[{}]", i - self.generated_shape_count)
        }
    }

    pub(crate) fn obstacle_origin(&self, i: usize) -> String {
        self.obstacle_origins
            .get(i)
            .cloned()
            .unwrap_or_else(|| format!("moving obstacle {i}"))
    }
}

/// Start, goal and vehicle radius: what every generator keeps clear.
struct Endpoints {
    start: Vec3,
    goal: Vec3,
    radius: f64,
}

/// Generates the layout of `s` in `bounds` from `seed` (the world stream). Assumes the sections
/// it reads passed validation; errors are problems naming the generator or group that could not
/// be placed.
pub(crate) fn generate<P>(
    s: &Scenario<P>,
    bounds: &Aabb,
    seed: u64,
) -> Result<Layout, Vec<Problem>> {
    let mut rng = Rng::seed_from_u64(seed);
    let ends = Endpoints {
        start: Vec3::from(s.mission.start),
        goal: Vec3::from(s.mission.goal),
        radius: s.vehicle.radius_m,
    };
    let mut layout = Layout::default();
    let mut problems = Problems::default();
    let mut work = Work::new();
    let explicit: Vec<Shape> = s
        .static_map
        .shapes
        .iter()
        .map(crate::scenario::sections::geometry_shape)
        .collect();
    if let Some(g) = &s.world.generator {
        run_generator(
            g,
            bounds,
            &explicit,
            &ends,
            &mut rng,
            &mut work,
            &mut layout,
            &mut problems,
        );
    }
    layout.generated_shape_count = layout.shapes.len();
    layout.shapes.extend(explicit);
    for (i, o) in s.obstacles.iter().enumerate() {
        let field = format!("obstacles[{i}]");
        let region = o.region.map_or(*bounds, |r| r.aabb());
        match o.moving_obstacle(&field, region, |p| s.resolve_path(p)) {
            Ok(m) => layout.obstacles.push(m),
            Err(p) => {
                problems.list.push(p);
                continue;
            }
        }
        layout.obstacle_origins.push(format!("obstacles[{i}]"));
    }
    for (i, g) in s.random_obstacles.iter().enumerate() {
        let field = format!("random_obstacles[{i}]");
        let region = g.region.map_or(*bounds, |r| r.aabb());
        let statics = layout.shapes.clone();
        match random_group(g, &region, &statics, &ends, &mut rng, &mut work, &field) {
            Ok(obs) => {
                for (k, o) in obs.into_iter().enumerate() {
                    layout.obstacles.push(o);
                    layout
                        .obstacle_origins
                        .push(format!("{field} obstacle {k}"));
                }
            }
            Err(p) => problems.list.push(p),
        }
    }
    if problems.list.is_empty() {
        Ok(layout)
    } else {
        Err(problems.list)
    }
}

/// Runs generator `g`; its moving obstacles avoid the `explicit` static shapes too.
#[allow(clippy::too_many_arguments)]
fn run_generator(
    g: &GeneratorSpec,
    bounds: &Aabb,
    explicit: &[Shape],
    ends: &Endpoints,
    rng: &mut Rng,
    work: &mut Work,
    layout: &mut Layout,
    problems: &mut Problems,
) {
    match g {
        GeneratorSpec::E1(e) => {
            let group = RandomObstacles {
                count: e.obstacle_count,
                motion: e.motion.clone(),
                ..RandomObstacles::default()
            };
            push_group(&group, bounds, explicit, ends, rng, work, layout, problems);
        }
        GeneratorSpec::E2Static(_) | GeneratorSpec::E2Dynamic(_) => {
            let case = if matches!(g, GeneratorSpec::E2Static(_)) {
                trust_scenes::e2::e2_static()
            } else {
                trust_scenes::e2::e2_dynamic()
            };
            layout.shapes.extend(case.map.shapes().iter().copied());
            for (k, f) in case.forecasts.iter().enumerate() {
                let shape = match f.shape {
                    ObstacleShape::Sphere => MovingShape::Sphere { radius: f.r_o },
                    ObstacleShape::Cylinder { half_height } => MovingShape::Cylinder {
                        radius: f.r_o,
                        half_height,
                    },
                };
                layout.obstacles.push(MovingObstacle {
                    shape,
                    position: f.center(0.0),
                    velocity: f.v0,
                    motion: Motion::ConstantVelocity {},
                    region: *bounds,
                });
                layout
                    .obstacle_origins
                    .push(format!("world.generator obstacle {k}"));
            }
        }
        GeneratorSpec::E3(e) => {
            let region = e.region.map_or_else(
                || {
                    let mut r = *bounds;
                    r.min.x = bounds.min.x.max(5.0);
                    r.max.x = bounds.max.x.min(45.0);
                    r
                },
                |r| r.aabb(),
            );
            let group = RandomObstacles {
                count: e.obstacle_count,
                motion: e.motion.clone(),
                region: Some(crate::scenario::BoundsSpec::from_aabb(&region)),
                ..RandomObstacles::default()
            };
            push_group(&group, bounds, explicit, ends, rng, work, layout, problems);
        }
        GeneratorSpec::E4(e) => {
            match e4_static(e, bounds, ends, rng, work) {
                Ok(shapes) => layout.shapes.extend(shapes),
                Err(p) => problems.list.push(p),
            }
            let mut region = *bounds;
            region.min.x += e.moving_end_margin_m;
            region.max.x -= e.moving_end_margin_m;
            let group = RandomObstacles {
                count: e.moving_count,
                cylinder_fraction: e.moving_cylinder_fraction,
                sphere_radius_m: e.moving_sphere_radius_m,
                cylinder_radius_m: e.moving_cylinder_radius_m,
                cylinder_half_height_m: Some(e.moving_cylinder_half_height_m),
                speed_m_s: e.moving_speed_m_s,
                max_climb_deg: e.moving_max_climb_deg,
                region: Some(crate::scenario::BoundsSpec::from_aabb(&region)),
                endpoint_clearance_m: 1.0,
                avoid_static: true,
                motion: e.moving_motion.clone(),
            };
            let statics: Vec<Shape> = layout.shapes.iter().chain(explicit).copied().collect();
            push_group(&group, bounds, &statics, ends, rng, work, layout, problems);
        }
        GeneratorSpec::DynamicForest(d) => dynamic_forest(d, bounds, rng, layout),
    }
}

/// The dynamic forest (`trust_scenes::dynamic_forest`): its pillars and bars become static
/// boxes, its cubes box obstacles on Fourier curves (the trefoils' exact coefficients). A cube
/// may leave the world bounds (the knots reach z −1.9 to 6.9 m): its region is the world
/// bounds widened to [`ForestRanges::reach`](trust_scenes::dynamic_forest::ForestRanges::reach),
/// which only validation reads (a script does not reflect at walls). No placement is
/// rejected: the centres start 5 m from the start along x, as in the benchmark.
fn dynamic_forest(d: &DynamicForestParams, bounds: &Aabb, rng: &mut Rng, layout: &mut Layout) {
    use trust_scenes::dynamic_forest::{self as forest, FOREST_RANGES, ForestObstacle};
    let (lo, hi) = FOREST_RANGES.reach();
    let region = Aabb {
        min: bounds.min.inf(&lo),
        max: bounds.max.sup(&hi),
    };
    let half = 0.5 * forest::CUBE_SIDE_M;
    for (k, o) in forest::generate(d.obstacle_count, &FOREST_RANGES, rng)
        .into_iter()
        .enumerate()
    {
        match o {
            ForestObstacle::Moving(knot) => {
                let f = knot.fourier();
                layout.obstacles.push(MovingObstacle {
                    shape: MovingShape::Box {
                        half_extents: [half; 3],
                    },
                    position: knot.position(0.0),
                    velocity: knot.velocity(0.0),
                    motion: Motion::Fourier(crate::script::FourierSpec {
                        period_s: f.period_s,
                        center: f.center,
                        cos: f.cos.to_vec(),
                        sin: f.sin.to_vec(),
                        phase_s: f.phase_s,
                    }),
                    region,
                });
                layout
                    .obstacle_origins
                    .push(format!("world.generator obstacle {k} (moving cube)"));
            }
            ForestObstacle::Pillar { .. } | ForestObstacle::Bar { .. } => {
                if let Some((min, max)) = o.static_box() {
                    layout.shapes.push(Shape::AaBox(AaBox { min, max }));
                }
            }
        }
    }
}

/// Draws a generator's random group and appends it to the layout (or a problem).
#[allow(clippy::too_many_arguments)]
fn push_group(
    group: &RandomObstacles,
    bounds: &Aabb,
    statics: &[Shape],
    ends: &Endpoints,
    rng: &mut Rng,
    work: &mut Work,
    layout: &mut Layout,
    problems: &mut Problems,
) {
    let region = group.region.map_or(*bounds, |r| r.aabb());
    match random_group(group, &region, statics, ends, rng, work, "world.generator") {
        Ok(obs) => {
            for (k, o) in obs.into_iter().enumerate() {
                layout.obstacles.push(o);
                layout
                    .obstacle_origins
                    .push(format!("world.generator obstacle {k}"));
            }
        }
        Err(p) => problems.list.push(p),
    }
}

/// Uniform in `[lo, hi]` (the point `lo` when the range is empty).
fn uniform(rng: &mut Rng, [lo, hi]: [f64; 2]) -> f64 {
    if hi > lo {
        rng.random_range(lo..=hi)
    } else {
        lo
    }
}

/// Draws a random group (see [`RandomObstacles`] for the distributions).
fn random_group(
    g: &RandomObstacles,
    region: &Aabb,
    statics: &[Shape],
    ends: &Endpoints,
    rng: &mut Rng,
    work: &mut Work,
    field: &str,
) -> Result<Vec<MovingObstacle>, Problem> {
    if !crate::scenario::BoundsSpec::from_aabb(region).is_valid() {
        return Err(Problem::new(
            format!("{field}.region"),
            fmt_bounds(region.min.as_slice(), region.max.as_slice()),
            "finite bounds with min < max on every axis",
        ));
    }
    let motion = match &g.motion {
        Motion::RandomManeuvers(m) if m.speed_m_s.is_none() => {
            let mut m = m.clone();
            m.speed_m_s = Some(g.speed_m_s);
            Motion::RandomManeuvers(m)
        }
        other => other.clone(),
    };
    let height = region.max.z - region.min.z;
    let sin_climb = g.max_climb_deg.to_radians().sin();
    // Validation caps the count (scale policy); the capacity is capped again here.
    let mut out = Vec::with_capacity(g.count.min(crate::scenario::scale::MAX_OBSTACLE_COUNT));
    let cost = if g.avoid_static { statics.len() } else { 1 };
    for i in 0..g.count {
        let out_of_work = || out_of_work(format!("{field}.count"), g.count, i);
        let placed = place_by_rejection(work, cost, out_of_work, || {
            let cylinder = rng.random_bool(g.cylinder_fraction);
            let shape = if cylinder {
                let radius = uniform(rng, g.cylinder_radius_m);
                let half_height = match g.cylinder_half_height_m {
                    Some(h) => uniform(rng, h),
                    None => 0.5 * height,
                };
                MovingShape::Cylinder {
                    radius,
                    half_height,
                }
            } else {
                MovingShape::Sphere {
                    radius: uniform(rng, g.sphere_radius_m),
                }
            };
            let e = shape.half_extents();
            if (0..3).any(|k| region.max[k] - region.min[k] < 2.0 * e[k]) {
                return Err(Problem::new(
                    format!("{field}.region"),
                    fmt_bounds(region.min.as_slice(), region.max.as_slice()),
                    format!(
                        "a region large enough for every obstacle size (an obstacle with half \
                         extents {} does not fit)",
                        crate::problem::fmt_vec(e.as_slice())
                    ),
                ));
            }
            let mut position = Vec3::zeros();
            for k in 0..3 {
                position[k] = uniform(rng, [region.min[k] + e[k], region.max[k] - e[k]]);
            }
            let speed = uniform(rng, g.speed_m_s);
            let yaw = rng.random_range(0.0..std::f64::consts::TAU);
            let direction = if cylinder {
                Vec3::new(yaw.cos(), yaw.sin(), 0.0)
            } else {
                let z = if sin_climb > 0.0 {
                    rng.random_range(-sin_climb..=sin_climb)
                } else {
                    0.0
                };
                let ring = (1.0 - z * z).max(0.0).sqrt();
                Vec3::new(ring * yaw.cos(), ring * yaw.sin(), z)
            };
            let clear = ends.radius + g.endpoint_clearance_m;
            if shape.signed_distance(&position, &ends.start) < clear
                || shape.signed_distance(&position, &ends.goal) < clear
            {
                return Ok(None);
            }
            if g.avoid_static {
                let bound = e.norm();
                if statics
                    .iter()
                    .any(|s| s.signed_distance(&position) <= bound)
                {
                    return Ok(None);
                }
            }
            Ok(Some(MovingObstacle {
                shape,
                position,
                velocity: direction * speed,
                motion: motion.clone(),
                region: *region,
            }))
        })?;
        match placed {
            Some(o) => out.push(o),
            None => {
                return Err(Problem::new(
                    format!("{field}.count"),
                    g.count,
                    format!(
                        "a count that can be placed clear of start, goal and static shapes \
                         (obstacle {i} failed {PLACEMENT_ATTEMPTS} placements)"
                    ),
                ));
            }
        }
    }
    Ok(out)
}

/// A horizontal footprint of a static obstacle.
#[derive(Debug, Clone, Copy)]
enum Footprint {
    Circle { c: [f64; 2], r: f64 },
    Rect { min: [f64; 2], max: [f64; 2] },
}

/// Distance from a 2-D point to a rectangle (0 inside).
fn point_rect(p: [f64; 2], min: [f64; 2], max: [f64; 2]) -> f64 {
    let dx = (min[0] - p[0]).max(p[0] - max[0]).max(0.0);
    let dy = (min[1] - p[1]).max(p[1] - max[1]).max(0.0);
    dx.hypot(dy)
}

impl Footprint {
    /// Horizontal gap between two footprints (≤ 0 when they overlap).
    fn gap(&self, other: &Footprint) -> f64 {
        match (*self, *other) {
            (Footprint::Circle { c: a, r: ra }, Footprint::Circle { c: b, r: rb }) => {
                (a[0] - b[0]).hypot(a[1] - b[1]) - ra - rb
            }
            (Footprint::Circle { c, r }, Footprint::Rect { min, max })
            | (Footprint::Rect { min, max }, Footprint::Circle { c, r }) => {
                point_rect(c, min, max) - r
            }
            (Footprint::Rect { min: a0, max: a1 }, Footprint::Rect { min: b0, max: b1 }) => {
                let dx = (a0[0] - b1[0]).max(b0[0] - a1[0]).max(0.0);
                let dy = (a0[1] - b1[1]).max(b0[1] - a1[1]).max(0.0);
                dx.hypot(dy)
            }
        }
    }

    /// Distance from a 2-D point to the footprint (0 inside).
    fn distance(&self, p: [f64; 2]) -> f64 {
        match *self {
            Footprint::Circle { c, r } => ((p[0] - c[0]).hypot(p[1] - c[1]) - r).max(0.0),
            Footprint::Rect { min, max } => point_rect(p, min, max),
        }
    }

    fn inside(&self, b: &Aabb) -> bool {
        let (lo, hi) = match *self {
            Footprint::Circle { c, r } => ([c[0] - r, c[1] - r], [c[0] + r, c[1] + r]),
            Footprint::Rect { min, max } => (min, max),
        };
        lo[0] >= b.min.x && lo[1] >= b.min.y && hi[0] <= b.max.x && hi[1] <= b.max.y
    }
}

/// E4's static obstacles: blocks, then walls, then pillars, each placed uniformly at random with
/// rejection (module docs of [`crate`]).
fn e4_static(
    e: &E4Params,
    bounds: &Aabb,
    ends: &Endpoints,
    rng: &mut Rng,
    work: &mut Work,
) -> Result<Vec<Shape>, Problem> {
    let mut placed: Vec<Footprint> = Vec::new();
    let mut shapes = Vec::new();
    let z0 = bounds.min.z;
    let top = bounds.max.z;
    let xy = |rng: &mut Rng, margin: [f64; 2]| {
        [
            uniform(rng, [bounds.min.x + margin[0], bounds.max.x - margin[0]]),
            uniform(rng, [bounds.min.y + margin[1], bounds.max.y - margin[1]]),
        ]
    };
    let start = [ends.start.x, ends.start.y];
    let goal = [ends.goal.x, ends.goal.y];
    let accept = |f: Footprint, placed: &mut Vec<Footprint>| {
        let ok = f.inside(bounds)
            && f.distance(start) >= e.endpoint_clear_m
            && f.distance(goal) >= e.endpoint_clear_m
            && placed.iter().all(|o| f.gap(o) >= e.min_gap_m);
        if ok {
            placed.push(f);
        }
        ok
    };
    let kinds: [(&str, usize); 3] = [
        ("block_count", e.block_count),
        ("wall_count", e.wall_count),
        ("pillar_count", e.pillar_count),
    ];
    for (name, count) in kinds {
        for i in 0..count {
            let out_of_work = || out_of_work(format!("world.generator.{name}"), count, i);
            let cost = placed.len();
            let shape = place_by_rejection(work, cost, out_of_work, || {
                let (foot, shape) = match name {
                    "block_count" => {
                        let sx = uniform(rng, e.block_size_m);
                        let sy = uniform(rng, e.block_size_m);
                        let h = uniform(rng, e.block_height_m).min(top - z0);
                        let c = xy(rng, [0.5 * sx, 0.5 * sy]);
                        let min = [c[0] - 0.5 * sx, c[1] - 0.5 * sy];
                        let max = [c[0] + 0.5 * sx, c[1] + 0.5 * sy];
                        (
                            Footprint::Rect { min, max },
                            Shape::AaBox(AaBox {
                                min: Vec3::new(min[0], min[1], z0),
                                max: Vec3::new(max[0], max[1], z0 + h),
                            }),
                        )
                    }
                    "wall_count" => {
                        let len = uniform(rng, e.wall_length_m);
                        let thick = uniform(rng, e.wall_thickness_m);
                        let h = uniform(rng, e.wall_height_m).min(top - z0);
                        let along_x = rng.random_bool(0.5);
                        let (sx, sy) = if along_x { (len, thick) } else { (thick, len) };
                        let c = xy(rng, [0.5 * sx, 0.5 * sy]);
                        let min = [c[0] - 0.5 * sx, c[1] - 0.5 * sy];
                        let max = [c[0] + 0.5 * sx, c[1] + 0.5 * sy];
                        (
                            Footprint::Rect { min, max },
                            Shape::AaBox(AaBox {
                                min: Vec3::new(min[0], min[1], z0),
                                max: Vec3::new(max[0], max[1], z0 + h),
                            }),
                        )
                    }
                    _ => {
                        let r = uniform(rng, e.pillar_radius_m);
                        let c = xy(rng, [r, r]);
                        (
                            Footprint::Circle { c, r },
                            Shape::Cylinder(Cylinder {
                                center: Vec3::new(c[0], c[1], 0.5 * (z0 + top)),
                                radius: r,
                                half_height: 0.5 * (top - z0),
                            }),
                        )
                    }
                };
                Ok(accept(foot, &mut placed).then_some(shape))
            })?;
            if let Some(shape) = shape {
                shapes.push(shape);
            } else {
                return Err(Problem::new(
                    format!("world.generator.{name}"),
                    count,
                    format!(
                        "a count that fits in world.bounds with min_gap_m = {} and endpoint_clear_m = {} \
                         (only {i} could be placed)",
                        fmt_num(e.min_gap_m),
                        fmt_num(e.endpoint_clear_m)
                    ),
                ));
            }
        }
    }
    Ok(shapes)
}

/// Start and goal of `scenario` against its generated (true) geometry; `cloud` is the truth
/// cloud read by the file checks.
pub(crate) fn check_layout<P>(
    scenario: &Scenario<P>,
    p: &mut Problems,
    layout: &Layout,
    cloud: Option<&[Vec3]>,
) {
    let r = scenario.vehicle.radius_m;
    if let Some(PointCloudSpec::Shapes {
        esdf_voxel_m,
        spacing_m,
    }) = &scenario.static_map.point_cloud
    {
        if layout.shapes.is_empty() {
            p.push(
                "static.point_cloud.source",
                "\"shapes\"",
                "static shapes to sample (none are given or generated)",
            );
        } else if let Some(bounds) = scenario.bounds() {
            // Counted before sampling (scale policy), on the field that sets the spacing.
            let spacing = spacing_m.unwrap_or(*esdf_voxel_m);
            let field = if spacing_m.is_some() {
                "static.point_cloud.spacing_m"
            } else {
                "static.point_cloud.esdf_voxel_m"
            };
            let bound = sampled_point_bound(&layout.shapes, &bounds, spacing);
            check_sampled_points(p, field, spacing, bound);
        }
    }
    // Only the start: a goal inside a static obstacle is a mission that cannot be flown, which
    // the planner says (`goal_unreachable`) and the flight ends on (status `unreachable`).
    {
        let (name, q) = ("mission.start", &scenario.mission.start);
        let x = Vec3::from(*q);
        for (i, s) in layout.shapes.iter().enumerate() {
            let d = s.signed_distance(&x);
            if d < r {
                p.push(
                    name,
                    fmt_vec(q),
                    format!(
                        "a point at least vehicle.radius_m = {} m from every static obstacle \
                         ({} is at {d:.3} m)",
                        fmt_num(r),
                        layout.shape_origin(i)
                    ),
                );
            }
        }
        if let Some(points) = cloud {
            let (d, i) = points
                .iter()
                .enumerate()
                .map(|(i, c)| ((c - x).norm(), i))
                .fold((f64::INFINITY, 0), |a, b| if b.0 < a.0 { b } else { a });
            if d < r {
                p.push(
                    name,
                    fmt_vec(q),
                    format!(
                        "a point at least vehicle.radius_m = {} m from every static cloud \
                         point (point {i} at {} is at {d:.3} m)",
                        fmt_num(r),
                        fmt_vec(points[i].as_slice())
                    ),
                );
            }
        }
    }
    let start = Vec3::from(scenario.mission.start);
    for (i, o) in layout.obstacles.iter().enumerate() {
        let d = o.shape.signed_distance(&o.position, &start);
        if d < r {
            p.push(
                "mission.start",
                fmt_vec(&scenario.mission.start),
                format!(
                    "a start at least vehicle.radius_m = {} m from every moving obstacle at \
                     t = 0 ({} is at {d:.3} m)",
                    fmt_num(r),
                    layout.obstacle_origin(i)
                ),
            );
        }
    }
}
