//! # trust-world — everything a scenario file describes, built once per trial
//!
//! The first stage of the simulator's data path (scenario file → world → closed loop → run log →
//! experiments; paper Sec. IV): [`scenario`] parses and checks the TOML file, [`World::build`]
//! generates the layout and the planner's map from the seeds, [`traffic`] moves the true obstacles
//! (scripted ones along [`script`]) and [`sensing`] turns them into the forecasts the planner
//! sees. The planner is not the world's: the scenario's `[planner]` section is a type parameter
//! of [`Scenario`] the world never looks inside, read and assembled by `trust-planner` where the
//! closed loop composes the two (`trust_flight::scenario`). Errors are [`WorldError`]s naming
//! the file, field and value.
//!
//! Use it to load a scenario and build its world: [`World::build`] validates the scenario, generates
//! the layout from the world seed ([`Seeds::world`]) and builds the planner's map. Everything that
//! varies between planners of one trial is created from the world afterwards: [`World::traffic`],
//! [`World::sensing`]. A world is immutable and `Send + Sync`: build it
//! once per trial and share it read-only (`Arc<World>`); E4's voxel map takes about 5 s and 0.9 GB.
//!
//! # Truth and the planner's view
//!
//! * [`World::static_shapes`] are the true static obstacles (also the run-log header's
//!   `static_shapes`). With `source = "inline"` or `"file"` point clouds, the points are truth too
//!   ([`World::static_points`], [`World::static_points_file`]).
//! * [`World::true_static_clearance`] is the simulator's collision test: shapes analytically
//!   (a BVH of the true shapes), points through a k-d tree.
//! * [`World::planner_map`] is what the planner sees: the shapes analytically without a point
//!   cloud; only a voxel ESDF of the sampled cloud with `source = "shapes"` ([`sample_shapes`]
//!   documents the sampling); the shapes plus an ESDF of the points for inline and file clouds.
//!   [`World::static_map_error_m`] bounds how much it may overestimate a true distance, and the
//!   planner's clearances include it.
//!
//! The generators (`e1`, `e2-static`, `e2-dynamic`, `e3`, `e4`) reproduce the paper's stated
//! settings; their distributions and why: `docs/decisions/0020-world-generators.md`; the point-cloud
//! view: `0005-point-cloud-esdf.md`. `dynamic-forest` is MIT-ACL's benchmark
//! (`trust_scenes::dynamic_forest`, `docs/dynamic-forest.md`).
//!
//! # Validation
//!
//! [`check`] runs every check [`World::build`] and a flight's set-up run on the world's part:
//! the file's checks with the scale policy ([`scenario::scale`]), the layout, and the traffic,
//! sensor and vehicle model of the flight (`trust_flight::scenario::check` adds the planner's
//! section and its assembly: `trust-sim validate`). Files the scenario names are read under [`files`]' caps and path policy.
//!
//! ```no_run
//! use std::path::Path;
//! use trust_world::{Scenario, World, load_checked};
//!
//! // The `[planner]` section read as a plain table (the simulator reads it typed).
//! let scenario: Scenario = load_checked(Path::new("scenarios/quickstart.toml"))?;
//! let world = World::build(&scenario)?;
//! println!("{} static shapes", world.static_shapes().len());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![warn(missing_docs)]

pub mod error;
pub mod files;
pub(crate) mod generate;
mod kdtree;
pub mod map_sensing;
pub mod problem;
mod sampling;
pub mod scenario;
pub mod script;
pub mod seeds;
pub mod sensing;
pub mod traffic;

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use serde::{Deserialize, Serialize};
use trust_core::{Aabb, Limits, StaticMap, Vec3};
use trust_geometry::Shape;

pub use kdtree::PointTree;
pub use sampling::sample_shapes;
pub use seeds::{Seeds, mix_seed};

pub use crate::error::WorldError;
pub use crate::scenario::Scenario;
use crate::scenario::{PointCloudSpec, StaticShape};
use crate::sensing::Sensing;
use crate::traffic::{MovingObstacle, Traffic};

/// What building a world took (for reports; wall-clock times never influence the world).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct BuildStats {
    /// True static shapes.
    pub shape_count: usize,
    /// Moving obstacles.
    pub obstacle_count: usize,
    /// Points of the planner's cloud (sampled, inline or from the file); 0 without a cloud.
    pub cloud_point_count: usize,
    /// Voxels of the planner's ESDF per axis, if it has one.
    pub esdf_dims: Option<[usize; 3]>,
    /// Bytes the ESDF keeps (8 per voxel).
    pub esdf_bytes: usize,
    /// Voxels occupied by the cloud.
    pub esdf_occupied_count: usize,
    /// Validation and layout generation (ms).
    pub layout_ms: f64,
    /// Sampling or reading the cloud (ms).
    pub cloud_ms: f64,
    /// Building the planner's map, including the ESDF (ms).
    pub map_ms: f64,
    /// Everything (ms).
    pub total_ms: f64,
}

/// The world of one trial (module docs).
#[derive(Debug, Clone)]
pub struct World {
    /// The scenario without its `[planner]` section (the flight's, not the world's).
    scenario: Scenario<()>,
    bounds: Aabb,
    shapes: Vec<Shape>,
    truth_map: StaticMap,
    truth_points: Option<PointTree>,
    static_points_file: Option<PathBuf>,
    planner_map: Arc<StaticMap>,
    static_map_error_m: f64,
    obstacles: Vec<MovingObstacle>,
    seeds: Seeds,
    stats: BuildStats,
}

impl World {
    /// Validates `scenario` and builds its world from `scenario.seed`.
    ///
    /// # Errors
    /// [`WorldError::Invalid`] with every problem of the scenario; [`WorldError::Read`] /
    /// [`WorldError::PointsFile`] for the points file; [`WorldError::Geometry`] if a map cannot be
    /// built (only for inputs validation lets through by mistake).
    pub fn build<P: Clone>(scenario: &Scenario<P>) -> Result<World, WorldError> {
        let t0 = Instant::now();
        let origin = scenario.origin();
        let Prepared {
            bounds,
            layout,
            cloud_points,
        } = prepare(scenario).map_err(|problems| WorldError::Invalid {
            path: origin,
            problems,
        })?;
        let seeds = scenario.seeds();
        let layout_ms = ms_since(t0);

        let t1 = Instant::now();
        let (cloud, truth_points, static_points_file) = match &scenario.static_map.point_cloud {
            None => (None, None, None),
            Some(PointCloudSpec::Shapes {
                esdf_voxel_m,
                spacing_m,
            }) => {
                let spacing = spacing_m.unwrap_or(*esdf_voxel_m);
                (
                    Some((
                        sample_shapes(&layout.shapes, &bounds, spacing),
                        *esdf_voxel_m,
                        Some(spacing),
                    )),
                    None,
                    None,
                )
            }
            Some(PointCloudSpec::Inline {
                esdf_voxel_m,
                points,
            }) => {
                let pts: Vec<Vec3> = points.iter().map(|p| Vec3::from(*p)).collect();
                (
                    Some((pts.clone(), *esdf_voxel_m, None)),
                    Some(PointTree::new(pts)),
                    None,
                )
            }
            Some(PointCloudSpec::File { esdf_voxel_m, path }) => {
                // Read once, by the checks in `prepare`.
                let pts = cloud_points.ok_or_else(|| {
                    WorldError::input("static.point_cloud.path", path.display(), "a points file")
                })?;
                (
                    Some((pts.clone(), *esdf_voxel_m, None)),
                    Some(PointTree::new(pts)),
                    Some(scenario.resolve_path(path)),
                )
            }
        };
        let cloud_ms = ms_since(t1);

        let t2 = Instant::now();
        let truth_map = StaticMap::from_shapes(bounds, layout.shapes.clone())?;
        let (planner_map, static_map_error_m, cloud_point_count) = match cloud {
            None => (truth_map.clone(), 0.0, 0),
            Some((points, voxel, spacing)) => {
                let base = if matches!(
                    scenario.static_map.point_cloud,
                    Some(PointCloudSpec::Shapes { .. })
                ) {
                    StaticMap::new(bounds)?
                } else {
                    truth_map.clone()
                };
                let n = points.len();
                let _ = spacing;
                (
                    base.with_point_cloud(&points, voxel)?,
                    static_map_error_for(scenario),
                    n,
                )
            }
        };
        let map_ms = ms_since(t2);
        let esdf = planner_map.esdf();
        let stats = BuildStats {
            shape_count: layout.shapes.len(),
            obstacle_count: layout.obstacles.len(),
            cloud_point_count,
            esdf_dims: esdf.map(|e| e.dims()),
            esdf_bytes: esdf.map_or(0, |e| std::mem::size_of_val(e.distances())),
            esdf_occupied_count: esdf.map_or(0, |e| e.occupied_count()),
            layout_ms,
            cloud_ms,
            map_ms,
            total_ms: ms_since(t0),
        };
        Ok(World {
            scenario: scenario.with_planner(()),
            bounds,
            shapes: layout.shapes,
            truth_map,
            truth_points,
            static_points_file,
            planner_map: Arc::new(planner_map),
            static_map_error_m,
            obstacles: layout.obstacles,
            seeds,
            stats,
        })
    }

    /// This world with `scenario` in place of the one it was built from, when the two agree on
    /// everything the world is made of (seed, world, static map, obstacles, mission and vehicle
    /// radius) and differ only in how the trial is flown (planner, vehicle model and limits,
    /// sensing, traffic faults, clocks, time limit); otherwise a world built from `scenario`.
    /// Studies fly several planners and variants over one world without rebuilding its ESDF.
    ///
    /// # Errors
    /// As [`World::build`] when a rebuild is needed.
    pub fn with_scenario<P: Clone>(mut self, scenario: &Scenario<P>) -> Result<World, WorldError> {
        let (a, b) = (&self.scenario, scenario);
        let same_world = a.seed == b.seed
            && a.world == b.world
            && a.static_map == b.static_map
            && a.obstacles == b.obstacles
            && a.random_obstacles == b.random_obstacles
            && a.mission == b.mission
            && a.vehicle.radius_m == b.vehicle.radius_m
            && a.path == b.path;
        if !same_world {
            return World::build(scenario);
        }
        let problems = scenario.validate();
        if !problems.is_empty() {
            return Err(WorldError::Invalid {
                path: scenario.origin(),
                problems,
            });
        }
        self.scenario = scenario.with_planner(());
        Ok(self)
    }

    /// The scenario it was built from, without its `[planner]` section (a flight is given its
    /// planner separately: `trust_flight::fly`).
    pub fn scenario(&self) -> &Scenario<()> {
        &self.scenario
    }

    /// The map bounds (where the vehicle may fly).
    pub fn bounds(&self) -> &Aabb {
        &self.bounds
    }

    /// The true static shapes: generated first, then `static.shapes`.
    pub fn static_shapes(&self) -> &[Shape] {
        &self.shapes
    }

    /// The true static shapes in the scenario's and the run-log contract's form (vertical
    /// cylinders as `center = [x, y]`, `z_min`, `z_max`).
    pub fn static_shape_specs(&self) -> Vec<StaticShape> {
        self.shapes
            .iter()
            .map(scenario::sections::static_shape)
            .collect()
    }

    /// The true static points of an inline or file cloud (tree order, not file order).
    pub fn static_points(&self) -> Option<&[Vec3]> {
        self.truth_points.as_ref().map(PointTree::points)
    }

    /// The points file of a file-sourced cloud (the run log's `static_points_file`; copy it next
    /// to the log, whose path is relative to the log's folder).
    pub fn static_points_file(&self) -> Option<&Path> {
        self.static_points_file.as_deref()
    }

    /// Distance from `p` to the nearest true static obstacle surface: the shapes' signed
    /// distance (negative inside), and the Euclidean distance to the nearest true cloud point.
    /// `f64::INFINITY` with no static obstacle. Subtract the vehicle radius for the run log's
    /// clearance.
    pub fn true_static_clearance(&self, p: &Vec3) -> f64 {
        let shapes = if self.shapes.is_empty() {
            f64::INFINITY
        } else {
            self.truth_map.signed_distance(p)
        };
        let points = self
            .truth_points
            .as_ref()
            .and_then(|t| t.nearest(p))
            .map_or(f64::INFINITY, |(d, _)| d);
        shapes.min(points)
    }

    /// The true static shapes as a map (what the vehicle's sensors ray-cast against,
    /// [`map_sensing`]); the true cloud points are not in it ([`World::static_points`]).
    pub fn truth_map(&self) -> &StaticMap {
        &self.truth_map
    }

    /// The planner's static map (module docs).
    pub fn planner_map(&self) -> &StaticMap {
        &self.planner_map
    }

    /// The planner's static map, shared (the manager's `share_map` takes it: its worker reads
    /// the map between cycles).
    pub fn planner_map_shared(&self) -> Arc<StaticMap> {
        Arc::clone(&self.planner_map)
    }

    /// How much the planner's map may overestimate the distance to a true static obstacle (m):
    /// 0 for analytic shapes; for an ESDF, [`esdf_error_bound`] (0.35 m at 0.2 m voxels).
    pub fn static_map_error_m(&self) -> f64 {
        self.static_map_error_m
    }

    /// The true moving obstacles at `t = 0`.
    pub fn obstacles(&self) -> &[MovingObstacle] {
        &self.obstacles
    }

    /// The trial's seeds.
    pub fn seeds(&self) -> Seeds {
        self.seeds
    }

    /// What the build took.
    pub fn stats(&self) -> &BuildStats {
        &self.stats
    }

    /// Start position.
    pub fn start(&self) -> Vec3 {
        Vec3::from(self.scenario.mission.start)
    }

    /// Goal position.
    pub fn goal(&self) -> Vec3 {
        Vec3::from(self.scenario.mission.goal)
    }

    /// The vehicle's radius (m).
    pub fn vehicle_radius_m(&self) -> f64 {
        self.scenario.vehicle.radius_m
    }

    /// The vehicle's limits.
    pub fn limits(&self) -> Limits {
        self.scenario.vehicle.limits
    }

    /// Fresh true traffic for a flight: the initial obstacles, the scenario's fault level and
    /// the traffic seed.
    ///
    /// # Errors
    /// As [`Traffic::new`] (not for a validated scenario).
    pub fn traffic(&self) -> Result<Traffic, WorldError> {
        Traffic::new(
            &self.obstacles,
            self.scenario.traffic.fault_level,
            self.seeds.traffic,
        )
    }

    /// A fresh sensor for a flight (the scenario's `[sensing]`, the sensing seed), warmed up on
    /// the `warmup_s` before take-off ([`Sensing::warm_up`]).
    ///
    /// # Errors
    /// As [`Sensing::new`] (not for a validated scenario).
    pub fn sensing(&self) -> Result<Sensing, WorldError> {
        let shapes: Vec<_> = self.obstacles.iter().map(|o| o.shape).collect();
        let mut s = Sensing::new(
            &self.scenario.sensing,
            &shapes,
            self.vehicle_radius_m(),
            self.seeds.sensing,
        )?
        .with_walls(self.obstacles.iter().map(|o| Some(o.region)).collect())?;
        let positions: Vec<Vec3> = self.obstacles.iter().map(|o| o.position).collect();
        let velocities: Vec<Vec3> = self.obstacles.iter().map(|o| o.velocity).collect();
        s.warm_up(&positions, &velocities)?;
        Ok(s)
    }
}

/// What [`World::build`] starts from: the checked scenario's bounds, its generated layout and the
/// cloud points read from its file (if any).
struct Prepared {
    bounds: Aabb,
    layout: generate::Layout,
    cloud_points: Option<Vec<Vec3>>,
}

/// The planner map's error bound of `scenario`'s static map ([`esdf_error_bound`] of its cloud,
/// 0 without one): what [`World::static_map_error_m`] will be, known before the map is built
/// (the planner's assembly is checked with it before a world exists).
pub fn static_map_error_for<P>(scenario: &Scenario<P>) -> f64 {
    match &scenario.static_map.point_cloud {
        None => 0.0,
        Some(PointCloudSpec::Shapes {
            esdf_voxel_m,
            spacing_m,
        }) => esdf_error_bound(*esdf_voxel_m, Some(spacing_m.unwrap_or(*esdf_voxel_m))),
        Some(
            PointCloudSpec::Inline { esdf_voxel_m, .. } | PointCloudSpec::File { esdf_voxel_m, .. },
        ) => esdf_error_bound(*esdf_voxel_m, None),
    }
}

/// What a flight sets up before its first step (`trust_flight::set_up` and the vehicle), run
/// on the generated layout so that validation rejects what the flight would: the true traffic,
/// the warmed-up sensor and its first round and the vehicle model at rest on the start (the
/// planner's assembly is checked where the planner is known, `trust_flight::scenario::check`).
/// Their errors are reported on the section the file wrote (`obstacles`, `sensing`, `vehicle`);
/// the scale policy keeps every derived parameter in range, so these are a backstop, not the
/// usual message.
fn preflight<P>(scenario: &Scenario<P>, layout: &generate::Layout, p: &mut problem::Problems) {
    let seeds = scenario.seeds();
    let mut problem = |section: &str, what: &str, e: &dyn std::fmt::Display| {
        p.push(
            section,
            "(the file's values)",
            format!("values {what} accepts; it reports: {e}"),
        );
    };
    let traffic = match Traffic::new(
        &layout.obstacles,
        scenario.traffic.fault_level,
        seeds.traffic,
    ) {
        Ok(t) => Some(t),
        Err(e) => {
            problem("obstacles", "the obstacle traffic", &e);
            None
        }
    };
    let shapes: Vec<_> = layout.obstacles.iter().map(|o| o.shape).collect();
    let positions: Vec<Vec3> = layout.obstacles.iter().map(|o| o.position).collect();
    let velocities: Vec<Vec3> = layout.obstacles.iter().map(|o| o.velocity).collect();
    let sensed = Sensing::new(
        &scenario.sensing,
        &shapes,
        scenario.vehicle.radius_m,
        seeds.sensing,
    )
    .and_then(|s| s.with_walls(layout.obstacles.iter().map(|o| Some(o.region)).collect()))
    .and_then(|mut s| {
        s.warm_up(&positions, &velocities)?;
        if let Some(t) = &traffic {
            s.update(0.0, t.positions())?;
        }
        Ok(s)
    });
    if let Err(e) = sensed {
        problem("sensing", "the sensor and tracker", &e);
    }
    let hover = trust_vehicle::Reference::hover(Vec3::from(scenario.mission.start));
    let vehicle = match scenario.vehicle.model {
        scenario::VehicleModel::Quadrotor => {
            let mut gains = scenario.vehicle.gains;
            gains.max_accel_m_s2 = gains.max_accel_m_s2.or(Some(scenario.vehicle.limits.a_max));
            trust_vehicle::ControlledQuadrotor::starting_on(
                scenario.vehicle.quadrotor,
                gains,
                0.0,
                &hover,
            )
            .map(|_| ())
        }
        scenario::VehicleModel::Perfect => {
            trust_vehicle::PerfectTracking::new(0.0, &hover).map(|_| ())
        }
    };
    if let Err(e) = vehicle {
        problem(
            "vehicle",
            "the vehicle model (with vehicle.limits.a_max)",
            &e,
        );
    }
}

/// Every check of a scenario: the file's ([`Scenario::validate`]), and, when the geometry is
/// valid, start and goal against the generated layout, and then what a flight sets up before
/// its first step ([`preflight`]). The layout is generated once and the points file read once;
/// `Err` holds every problem, in file order, layout problems last.
fn prepare<P>(scenario: &Scenario<P>) -> Result<Prepared, Vec<scenario::Problem>> {
    let file = scenario.check_file();
    let mut problems = file.problems;
    let mut layout = None;
    if file.geometry_ok
        && let Some(bounds) = &file.bounds
    {
        match generate::generate(scenario, bounds, scenario.seeds().world) {
            Ok(l) => {
                generate::check_layout(scenario, &mut problems, &l, file.cloud_points.as_deref());
                if problems.list.is_empty() {
                    preflight(scenario, &l, &mut problems);
                }
                layout = Some(l);
            }
            Err(p) => problems.list.extend(p),
        }
    }
    match (problems.list.is_empty(), file.bounds, layout) {
        (true, Some(bounds), Some(layout)) => Ok(Prepared {
            bounds,
            layout,
            cloud_points: file.cloud_points,
        }),
        (true, _, _) => Err(vec![scenario::Problem::new(
            "world.bounds",
            "(missing)",
            "bounds or a generator",
        )]),
        (false, _, _) => Err(problems.list),
    }
}

/// Every problem of `scenario`, as [`World::build`] finds them, without building the maps:
/// [`Scenario::validate`]'s (with the scale policy, [`scenario::scale`]), start and goal against
/// the generated layout, and what a flight sets up before its first step (traffic, sensing, the
/// vehicle model). Empty: [`World::build`] will not reject the scenario (its maps are within the
/// caps checked here: ESDF voxels, cloud points); `trust_flight::scenario::check` adds the
/// planner's section — `trust-sim validate`.
pub fn check<P>(scenario: &Scenario<P>) -> Vec<scenario::Problem> {
    prepare(scenario).err().unwrap_or_default()
}

/// Reads, parses and checks a scenario file ([`Scenario::parse_file`], then [`check`]) without
/// building the maps; its `[planner]` section is read as `P` and not checked.
///
/// # Errors
/// [`WorldError::Read`], [`WorldError::Parse`], or [`WorldError::Invalid`] with every problem.
pub fn load_checked<P: serde::de::DeserializeOwned + Default + Clone>(
    path: &Path,
) -> Result<Scenario<P>, WorldError> {
    let s = Scenario::parse_file(path)?;
    let problems = check(&s);
    WorldError::unless_problems(s, path, problems)
}

/// Bound (m) on how much the planner's trilinear ESDF of voxel size `voxel_m` may overestimate
/// the distance from a point to the true static obstacles it was built from: true points
/// (`spacing_m = None`) or shapes sampled by [`sample_shapes`] at `spacing_m`.
///
/// `voxel·√3` for points and for shapes sampled at the voxel size (the default), and
/// `spacing·√3/2 + voxel·√3` for another spacing. Proof sketch: let `q` be the true obstacle
/// point nearest to `p`. The voxel containing `q` (points; or, for shapes, the voxel of the
/// lattice point nearest to `q`, which is within `spacing·√3/2` of the shape and therefore
/// sampled) is occupied, and its centre lies within `voxel·√3/2` of `q` (plus `spacing·√3/2`
/// unless the lattice is the voxel centres), so the distance `D` from `p` to the nearest occupied
/// voxel centre exceeds the true distance by at most that. Each ESDF value is `D` at a voxel
/// centre (exact EDT); `D` is 1-Lipschitz, and the trilinear weights `w_k` of the cell corners
/// `c_k` satisfy `Σ w_k |p − c_k| ≤ voxel·√3/2`, so the interpolant exceeds `D(p)` by at most
/// another `voxel·√3/2`. Measured on a 0.2 m map of pillars, walls, blocks and a sphere
/// (`tests/world.rs`), the worst overestimate over 19 000 free points is 0.03 m against this
/// bound's 0.35 m: the sampling inflates shapes by half a voxel diagonal, which usually cancels
/// the interpolation error.
pub fn esdf_error_bound(voxel_m: f64, spacing_m: Option<f64>) -> f64 {
    let diagonal = 3f64.sqrt();
    match spacing_m {
        Some(s) if s != voxel_m => s * diagonal / 2.0 + voxel_m * diagonal,
        _ => voxel_m * diagonal,
    }
}

fn ms_since(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}
