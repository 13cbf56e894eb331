//! The sections of a scenario file (see the [`crate::scenario`] module docs for the format).

use std::path::PathBuf;

use serde::{Deserialize, Serialize};
use trust_core::{Aabb, Limits, Vec3};
use trust_geometry::{AaBox, Cylinder, Shape, Sphere};

use super::bounds::BoundsSpec;
use crate::problem::Problem;
use crate::scenario::generator::GeneratorSpec;
use crate::traffic::{Motion, MovingObstacle, MovingShape};
use trust_vehicle::{QuadrotorParams, Se3Gains};

/// Section `[world]`: the bounds and an optional generator.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WorldSection {
    /// The map bounds, where the vehicle may fly. Optional with a generator (each has natural
    /// bounds, [`GeneratorSpec::default_bounds`]); required without one.
    pub bounds: Option<BoundsSpec>,
    /// A generator that fills static shapes and/or moving obstacles, seeded by the scenario's
    /// `seed`. Explicit `[[static.shapes]]`, `[[obstacles]]` and `[[random_obstacles]]` are
    /// added to what it generates.
    pub generator: Option<GeneratorSpec>,
}

/// A static obstacle of `[[static.shapes]]`, tagged by `kind` —
/// `{ kind = "sphere", center = [x, y, z], radius = r }`,
/// `{ kind = "cylinder", center = [x, y], radius = r, z_min = a, z_max = b }` (vertical, as in the
/// run-log contract), `{ kind = "box", min = [x, y, z], max = [x, y, z] }` (axis-aligned). The
/// world's own type: the run log's [`trust_runlog::StaticShape`] has the same variants, tagged
/// externally, and converts both ways (`From`), for writing a log's header and reading one.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum StaticShape {
    /// A ball.
    Sphere {
        /// Centre.
        center: [f64; 3],
        /// Radius.
        radius: f64,
    },
    /// A vertical cylinder: axis through `center` (x, y) from `z_min` to `z_max`.
    Cylinder {
        /// Axis position (x, y).
        center: [f64; 2],
        /// Radius.
        radius: f64,
        /// Bottom.
        z_min: f64,
        /// Top.
        z_max: f64,
    },
    /// An axis-aligned box.
    Box {
        /// Lower corner.
        min: [f64; 3],
        /// Upper corner.
        max: [f64; 3],
    },
}

impl From<StaticShape> for trust_runlog::StaticShape {
    fn from(s: StaticShape) -> Self {
        match s {
            StaticShape::Sphere { center, radius } => Self::Sphere { center, radius },
            StaticShape::Cylinder {
                center,
                radius,
                z_min,
                z_max,
            } => Self::Cylinder {
                center,
                radius,
                z_min,
                z_max,
            },
            StaticShape::Box { min, max } => Self::Box { min, max },
        }
    }
}

impl From<trust_runlog::StaticShape> for StaticShape {
    fn from(s: trust_runlog::StaticShape) -> Self {
        match s {
            trust_runlog::StaticShape::Sphere { center, radius } => Self::Sphere { center, radius },
            trust_runlog::StaticShape::Cylinder {
                center,
                radius,
                z_min,
                z_max,
            } => Self::Cylinder {
                center,
                radius,
                z_min,
                z_max,
            },
            trust_runlog::StaticShape::Box { min, max } => Self::Box { min, max },
        }
    }
}

/// The geometry shape of a static obstacle, without checks (the scenario's validation checks it).
pub(crate) fn geometry_shape(s: &StaticShape) -> Shape {
    match *s {
        StaticShape::Sphere { center, radius } => Shape::Sphere(Sphere {
            center: Vec3::from(center),
            radius,
        }),
        StaticShape::Cylinder {
            center,
            radius,
            z_min,
            z_max,
        } => Shape::Cylinder(Cylinder {
            center: Vec3::new(center[0], center[1], 0.5 * (z_min + z_max)),
            radius,
            half_height: 0.5 * (z_max - z_min),
        }),
        StaticShape::Box { min, max } => Shape::AaBox(AaBox {
            min: Vec3::from(min),
            max: Vec3::from(max),
        }),
    }
}

/// The scenario (and run-log) form of a geometry shape.
pub(crate) fn static_shape(s: &Shape) -> StaticShape {
    match s {
        Shape::Sphere(s) => StaticShape::Sphere {
            center: s.center.into(),
            radius: s.radius,
        },
        Shape::Cylinder(c) => StaticShape::Cylinder {
            center: [c.center.x, c.center.y],
            radius: c.radius,
            z_min: c.center.z - c.half_height,
            z_max: c.center.z + c.half_height,
        },
        Shape::AaBox(b) => StaticShape::Box {
            min: b.min.into(),
            max: b.max.into(),
        },
    }
}

/// Section `[static]`: static obstacles known in advance (paper Sec. IV-D: the static map is
/// given).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StaticSection {
    /// Analytic shapes (`[[static.shapes]]`), added to a generator's.
    #[serde(default)]
    pub shapes: Vec<StaticShape>,
    /// What the planner sees as a point cloud (`[static.point_cloud]`); absent: the planner sees
    /// the shapes analytically.
    pub point_cloud: Option<PointCloudSpec>,
}

/// `[static.point_cloud]`, tagged by `source`. The planner's map is a voxel ESDF of the cloud
/// (`trust_geometry::StaticMap::with_point_cloud`) over the world bounds.
///
/// * `source = "shapes"`: the cloud is sampled from all static shapes (generated and explicit),
///   which stay the truth; the planner sees only the cloud ([`crate`] describes the
///   sampling).
/// * `source = "inline"` / `"file"`: the points are the truth (a point closer than the vehicle
///   radius is a collision) and the planner sees them as an ESDF, plus any shapes analytically.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "source", rename_all = "kebab-case", deny_unknown_fields)]
pub enum PointCloudSpec {
    /// Sampled from the static shapes.
    Shapes {
        /// ESDF voxel size (m), `> 0`; the grid must stay within `trust_geometry::MAX_VOXELS`.
        esdf_voxel_m: f64,
        /// Lattice spacing of the samples (m), `> 0`. Default: `esdf_voxel_m`.
        spacing_m: Option<f64>,
    },
    /// Points listed in the file.
    Inline {
        /// ESDF voxel size (m).
        esdf_voxel_m: f64,
        /// The points `[[x, y, z], ...]`, at least one.
        points: Vec<[f64; 3]>,
    },
    /// Points read from a text file of `x y z` lines (blank lines and `#` comments allowed).
    File {
        /// ESDF voxel size (m).
        esdf_voxel_m: f64,
        /// The file, relative to the scenario file's folder (or absolute).
        path: PathBuf,
    },
}

impl PointCloudSpec {
    /// The ESDF voxel size (m).
    pub fn esdf_voxel_m(&self) -> f64 {
        match self {
            PointCloudSpec::Shapes { esdf_voxel_m, .. }
            | PointCloudSpec::Inline { esdf_voxel_m, .. }
            | PointCloudSpec::File { esdf_voxel_m, .. } => *esdf_voxel_m,
        }
    }
}

/// Shape kind of an explicit moving obstacle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MovingShapeKind {
    /// A ball of radius `radius_m`.
    Sphere,
    /// A vertical cylinder of radius `radius_m` and half-height `half_height_m`, centred at
    /// mid-height.
    Cylinder,
    /// An axis-aligned box of half extents `half_extents` about its centre (forecast as its
    /// circumscribing vertical cylinder, [`crate::traffic`]).
    Box,
}

/// One explicit moving obstacle (`[[obstacles]]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObstacleSpec {
    /// `"sphere"`, `"cylinder"` or `"box"`.
    pub shape: MovingShapeKind,
    /// Radius (m), `> 0`; required for spheres and cylinders, not allowed for boxes.
    pub radius_m: Option<f64>,
    /// Half-height (m) of a cylinder, `> 0`; required for cylinders, not allowed otherwise.
    pub half_height_m: Option<f64>,
    /// Half extents `[hx, hy, hz]` (m) of a box, each `> 0`; required for boxes, not allowed
    /// otherwise.
    pub half_extents: Option<[f64; 3]>,
    /// Centre at `t = 0` (m); required, except for a scripted motion (`samples`, `fourier`), whose
    /// script gives it (and then not allowed).
    pub position: Option<[f64; 3]>,
    /// Velocity at `t = 0` (m/s). Default at rest; not allowed with a scripted motion.
    pub velocity: Option<[f64; 3]>,
    /// Motion model. Default `{ kind = "constant-velocity" }`; `samples` and `fourier` script the
    /// motion (`trust_world::script`).
    #[serde(default)]
    pub motion: Motion,
    /// The box it stays inside (reflecting at its walls). Default: the world bounds.
    pub region: Option<BoundsSpec>,
}

impl ObstacleSpec {
    /// The true shape (a missing size reads as 0, which validation rejects).
    pub fn moving_shape(&self) -> MovingShape {
        let radius = self.radius_m.unwrap_or(0.0);
        match self.shape {
            MovingShapeKind::Sphere => MovingShape::Sphere { radius },
            MovingShapeKind::Cylinder => MovingShape::Cylinder {
                radius,
                half_height: self.half_height_m.unwrap_or(0.0),
            },
            MovingShapeKind::Box => MovingShape::Box {
                half_extents: self.half_extents.unwrap_or([0.0; 3]),
            },
        }
    }
}

impl ObstacleSpec {
    /// The obstacle as the traffic takes it, in `region`, with `field` (`obstacles[i]`) naming
    /// it: a samples file is read (`resolve` maps its path, usually
    /// [`crate::scenario::Scenario::resolve_path`]) and a scripted obstacle starts where its
    /// script is at `t = 0`, with the script's velocity (the first sample when the samples are
    /// invalid: validation names them). A missing position reads as the origin (validation
    /// rejects it).
    ///
    /// # Errors
    /// A [`Problem`] naming `FIELD.motion.file` when the samples file cannot be read or a line
    /// does not parse (with its line number).
    pub(crate) fn moving_obstacle(
        &self,
        field: &str,
        region: Aabb,
        resolve: impl Fn(&std::path::Path) -> PathBuf,
    ) -> Result<MovingObstacle, Problem> {
        let motion = match &self.motion {
            Motion::Samples(spec) => Motion::Samples(spec.load(&resolve).map_err(|e| {
                Problem::new(
                    format!("{field}.motion.file"),
                    format!(
                        "{:?}",
                        spec.file.clone().unwrap_or_default().display().to_string()
                    ),
                    format!("a readable CSV file of `t,x,y,z` lines ({e})"),
                )
            })?),
            m => m.clone(),
        };
        let (mut position, mut velocity) = (
            Vec3::from(self.position.unwrap_or_default()),
            Vec3::from(self.velocity.unwrap_or_default()),
        );
        if motion.is_scripted() {
            match motion.script(&format!("{field}.motion")) {
                Ok(Some(script)) => (position, velocity) = script.evaluate(0.0),
                _ => {
                    if let Motion::Samples(s) = &motion
                        && let Some(first) = s.samples.first()
                    {
                        position = Vec3::new(first[1], first[2], first[3]);
                    }
                    velocity = Vec3::zeros();
                }
            }
        }
        Ok(MovingObstacle {
            shape: self.moving_shape(),
            position,
            velocity,
            motion,
            region,
        })
    }
}

/// A group of random moving obstacles (`[[random_obstacles]]`), drawn from the scenario's seed.
///
/// Each obstacle is a cylinder with probability `cylinder_fraction`, else a sphere; sizes and
/// speed are uniform in their ranges; the centre is uniform over the positions that keep the
/// whole obstacle inside `region`; the direction of motion is uniform in yaw, horizontal for
/// cylinders and, for spheres, uniform on the part of the unit sphere within `max_climb_deg` of
/// the horizontal. Placements that come within `vehicle.radius_m + endpoint_clearance_m` of the
/// start or the goal, or (with `avoid_static`) overlap a static shape, are redrawn (up to 1000
/// times per obstacle). Defaults are those of experiment E1's random scenes
/// (`trust_scenes::e1`: radii 0.5–1.5 m, speeds 0.5–3 m/s, half
/// cylinders, full-height cylinders, directions uniform on the sphere, 1 m endpoint clearance).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RandomObstacles {
    /// Number of obstacles.
    pub count: usize,
    /// Probability that an obstacle is a cylinder, in `[0, 1]`.
    pub cylinder_fraction: f64,
    /// Sphere radius range (m).
    pub sphere_radius_m: [f64; 2],
    /// Cylinder radius range (m).
    pub cylinder_radius_m: [f64; 2],
    /// Cylinder half-height range (m); `None`: full height of the region (as in E1).
    pub cylinder_half_height_m: Option<[f64; 2]>,
    /// Speed range (m/s).
    pub speed_m_s: [f64; 2],
    /// Largest climb angle of a sphere's initial velocity (degrees, `[0, 90]`).
    pub max_climb_deg: f64,
    /// Where the obstacles start and stay (reflecting at its walls). Default: the world bounds.
    pub region: Option<BoundsSpec>,
    /// Extra clearance (m) of start and goal from every obstacle at `t = 0`, beyond the vehicle
    /// radius.
    pub endpoint_clearance_m: f64,
    /// Do not start inside (or touching) a static shape.
    pub avoid_static: bool,
    /// Motion model of every obstacle; with `random-maneuvers` and no `speed_m_s`, the group's
    /// speed range is used.
    pub motion: Motion,
}

impl Default for RandomObstacles {
    fn default() -> Self {
        use trust_scenes::e1;
        RandomObstacles {
            count: 10,
            cylinder_fraction: e1::CYLINDER_FRACTION,
            sphere_radius_m: [e1::RADIUS_M.0, e1::RADIUS_M.1],
            cylinder_radius_m: [e1::RADIUS_M.0, e1::RADIUS_M.1],
            cylinder_half_height_m: None,
            speed_m_s: [e1::SPEED_M_S.0, e1::SPEED_M_S.1],
            max_climb_deg: 90.0,
            region: None,
            endpoint_clearance_m: e1::ENDPOINT_CLEARANCE_M,
            avoid_static: true,
            motion: Motion::default(),
        }
    }
}

/// Section `[mission]`: a start and a goal, given or drawn from the trial seed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, try_from = "RawMission")]
pub struct Mission {
    /// Start position (m); the vehicle starts at rest at `t = 0`. Drawn from the seed with
    /// `random` (then optional in the file).
    pub start: [f64; 3],
    /// Goal position (m). Drawn from the seed with `random` (then optional in the file).
    pub goal: [f64; 3],
    /// Arrival radius around the goal (m), `> 0`. Default 0.5 m (the run-log contract's example).
    #[serde(default = "default_goal_tolerance")]
    pub goal_tolerance_m: f64,
    /// "Random flight": draw the start and the goal from the trial seed ([`RandomEndpoints`]);
    /// every seed flies another mission in the same scene.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub random: Option<RandomEndpoints>,
}

/// `[mission] random = { ... }`: the start and the goal drawn uniformly in `region` from the
/// trial seed (a stream of its own, so the world, the traffic and the noise of a seed do not
/// change), each at least `vehicle.radius_m + clearance_m` from every explicit static shape
/// (`[[static.shapes]]`), and at least `min_distance_m` apart. Up to 200 starts with 200 goals
/// each, and at most [`endpoint_draw_count`] points in all (draws × static shapes within the
/// scale policy); if no pair fits, the farthest clear pair is kept and validation names
/// `mission.random.min_distance_m`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RandomEndpoints {
    /// Where to draw (`{min, max}`); default: the world bounds.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub region: Option<BoundsSpec>,
    /// Least distance between the start and the goal (m). Default 0.
    #[serde(default)]
    pub min_distance_m: f64,
    /// Clearance beyond the vehicle radius from the explicit static shapes (m). Default 0.
    #[serde(default)]
    pub clearance_m: f64,
}

/// The file's `[mission]` before the draw: start and goal are required without `random`.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMission {
    start: Option<[f64; 3]>,
    goal: Option<[f64; 3]>,
    #[serde(default = "default_goal_tolerance")]
    goal_tolerance_m: f64,
    #[serde(default)]
    random: Option<RandomEndpoints>,
}

impl TryFrom<RawMission> for Mission {
    type Error = String;

    fn try_from(raw: RawMission) -> Result<Self, String> {
        let (start, goal) = match (raw.start, raw.goal, &raw.random) {
            (Some(s), Some(g), _) => (s, g),
            // Drawn from the seed once the scenario is read (Scenario::with_seed).
            (s, g, Some(_)) => (s.unwrap_or([0.0; 3]), g.unwrap_or([0.0; 3])),
            (None, _, None) => return Err("missing field `start` (give it, or `random`)".into()),
            (_, None, None) => return Err("missing field `goal` (give it, or `random`)".into()),
        };
        Ok(Mission {
            start,
            goal,
            goal_tolerance_m: raw.goal_tolerance_m,
            random: raw.random,
        })
    }
}

impl RandomEndpoints {
    /// Draws `(start, goal)` for trial seed `seed` in `bounds` (the world bounds, used without a
    /// `region`), clear of `shapes` by `radius + clearance_m`.
    pub fn draw(
        &self,
        seed: u64,
        bounds: &Aabb,
        shapes: &[Shape],
        radius: f64,
    ) -> ([f64; 3], [f64; 3]) {
        use rand::{Rng as _, SeedableRng};
        let region = self.region.as_ref().map_or(*bounds, BoundsSpec::aabb);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(crate::seeds::mix_seed(seed, 5));
        let need = radius + self.clearance_m;
        let clear = |p: &Vec3| {
            shapes
                .iter()
                .map(|s| s.signed_distance(p))
                .fold(f64::INFINITY, f64::min)
        };
        fn uniform(rng: &mut rand_chacha::ChaCha8Rng, lo: f64, hi: f64) -> f64 {
            if hi > lo {
                rng.random_range(lo..hi)
            } else {
                lo
            }
        }
        let draw_point = |rng: &mut rand_chacha::ChaCha8Rng| {
            Vec3::new(
                uniform(rng, region.min.x, region.max.x),
                uniform(rng, region.min.y, region.max.y),
                uniform(rng, region.min.z, region.max.z),
            )
        };
        // Pairs: a clear start, then up to GOAL_DRAWS clear goals far enough from it; a start
        // near the middle of a small region may have no goal far enough, so the start is drawn
        // again (drawing the start alone first failed for 1 seed in 20 in the suite's rooms).
        // Without a valid pair, the farthest clear pair seen (validation then names the field).
        // At most `endpoint_draw_count(shapes)` points in all, so that draws × shapes stays
        // within the scale policy's MAX_ENDPOINT_WORK.
        let mut left = endpoint_draw_count(shapes.len());
        let mut best: Option<(f64, Vec3, Vec3)> = None;
        'starts: for _ in 0..START_DRAWS {
            if left == 0 {
                break;
            }
            left -= 1;
            let start = draw_point(&mut rng);
            if clear(&start) < need {
                continue;
            }
            for _ in 0..GOAL_DRAWS {
                if left == 0 {
                    break 'starts;
                }
                left -= 1;
                let goal = draw_point(&mut rng);
                if clear(&goal) < need {
                    continue;
                }
                let d = (goal - start).norm();
                if d >= self.min_distance_m {
                    return (start.into(), goal.into());
                }
                if best.is_none_or(|(b, _, _)| d > b) {
                    best = Some((d, start, goal));
                }
            }
        }
        let (start, goal) = best.map_or((region.min, region.max), |(_, a, b)| (a, b));
        (start.into(), goal.into())
    }

    /// Whether [`RandomEndpoints::draw`] can draw in this region (its own or `bounds`): finite,
    /// `min <= max`, within the scale policy's coordinates. Otherwise the scenario keeps the
    /// file's start and goal and validation names the region.
    pub fn drawable(&self, bounds: &Aabb) -> bool {
        let region = self.region.as_ref().map_or(*bounds, BoundsSpec::aabb);
        (0..3).all(|k| {
            let (lo, hi) = (region.min[k], region.max[k]);
            lo.is_finite()
                && hi.is_finite()
                && lo <= hi
                && lo.abs() <= super::scale::MAX_COORD_M
                && hi.abs() <= super::scale::MAX_COORD_M
        })
    }
}

/// Start draws of [`RandomEndpoints::draw`].
const START_DRAWS: usize = 200;
/// Goal draws per start.
const GOAL_DRAWS: usize = 200;

/// How many points [`RandomEndpoints::draw`] draws at most with `shape_count` static shapes:
/// `200 + 200 · 200`, fewer when the draws times the shapes would exceed
/// [`super::scale::MAX_ENDPOINT_WORK`] (at least 2).
pub fn endpoint_draw_count(shape_count: usize) -> usize {
    (super::scale::MAX_ENDPOINT_WORK / shape_count.max(1)).clamp(2, START_DRAWS * (1 + GOAL_DRAWS))
}

fn default_goal_tolerance() -> f64 {
    0.5
}

/// Which vehicle model flies the plan.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum VehicleModel {
    /// `trust_vehicle::ControlledQuadrotor` (rigid body + SE(3) controller).
    #[default]
    Quadrotor,
    /// `trust_vehicle::PerfectTracking` (the state is the reference).
    Perfect,
}

/// Section `[vehicle]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct VehicleSection {
    /// Radius of the sphere that must stay clear of obstacles (m), `> 0`. Default 0.3 m (the
    /// run-log contract's example; the default quadrotor's 0.15 m arms plus 5-inch propellers
    /// and a margin).
    pub radius_m: f64,
    /// Planner limits. Default the paper's (Sec. IV): `v_max = 10 m/s`, `a_max = 15 m/s²`.
    pub limits: Limits,
    /// `"quadrotor"` (default) or `"perfect"`.
    pub model: VehicleModel,
    /// Rigid-body parameters of the quadrotor model.
    pub quadrotor: QuadrotorParams,
    /// Gains of its SE(3) controller.
    pub gains: Se3Gains,
}

impl Default for VehicleSection {
    fn default() -> Self {
        VehicleSection {
            radius_m: 0.3,
            limits: Limits::default(),
            model: VehicleModel::Quadrotor,
            quadrotor: QuadrotorParams::default(),
            gains: Se3Gains::default(),
        }
    }
}

/// When a new plan takes effect after the state it was planned from (`sim.latency`, tagged by
/// `kind`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Latency {
    /// A fixed delay: `{ kind = "fixed", seconds = 0.05 }`; without `seconds`, the manager's
    /// latency (`ManagerParams::latency()`: its `latency_s`, else its cycle budget).
    Fixed {
        /// The delay (s), `≥ 0`.
        seconds: Option<f64>,
    },
    /// Real time: `{ kind = "measured" }` (alias `"real-time"`), machine-dependent. The planner
    /// is busy from a cycle's start for the cycle's measured wall time times `cpu_scale`; its
    /// plan takes effect when it finishes, the next cycle starts at the first replanning tick
    /// after that, and the ticks in between are skipped (logged as the cycle's
    /// `overrun_ticks`). The planner's wall-clock budgets are on in this mode.
    #[serde(alias = "real-time")]
    Measured {
        /// The measured time is multiplied by this factor, to emulate a slower onboard computer
        /// (3: a computer three times slower than this one). Range `(0, 100]`; default 1.
        cpu_scale: Option<f64>,
    },
}

/// Largest [`Latency::Measured`] `cpu_scale` accepted.
pub const MAX_CPU_SCALE: f64 = 100.0;

impl Latency {
    /// The real-time mode at `cpu_scale` ([`Latency::Measured`]).
    pub fn real_time(cpu_scale: f64) -> Self {
        Latency::Measured {
            cpu_scale: Some(cpu_scale),
        }
    }

    /// Whether this is the real-time mode ([`Latency::Measured`]).
    pub fn is_real_time(&self) -> bool {
        matches!(self, Latency::Measured { .. })
    }
}

impl Default for Latency {
    fn default() -> Self {
        Latency::Fixed { seconds: None }
    }
}

/// Section `[sim]`: the closed loop's clocks.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SimSection {
    /// Physics (and control) step (s). Default 0.002 s: the 500 Hz the vehicle model was
    /// validated at (`trust_world::vehicle`).
    pub physics_dt_s: f64,
    /// Replanning rate (Hz); its period must be a multiple of `physics_dt_s`. Default 10 Hz
    /// (design.md §4).
    pub replan_rate_hz: f64,
    /// State-record rate of the run log (Hz), `≥ 50` (run-log contract); its period must be a
    /// multiple of `physics_dt_s`. Default 50 Hz.
    pub log_rate_hz: f64,
    /// Latency model. Default fixed at the manager's latency.
    pub latency: Latency,
}

impl Default for SimSection {
    fn default() -> Self {
        SimSection {
            physics_dt_s: 0.002,
            replan_rate_hz: 10.0,
            log_rate_hz: 50.0,
            latency: Latency::default(),
        }
    }
}
