//! Scenario files: everything one simulated flight needs, in TOML.
//!
//! A scenario names the world (bounds, static obstacles, moving obstacles — explicit or from a
//! generator), the mission, the vehicle, the planner, the sensing, how the truth departs from the
//! forecasts, the closed loop's clocks, a time limit and a seed. Every table rejects unknown
//! fields; every section except `[mission]` has defaults, so a minimal file is short:
//!
//! ```toml
//! name = "minimal"
//! [world]
//! bounds = { min = [0, 0, 0], max = [20, 20, 10] }
//! [mission]
//! start = [1, 10, 5]
//! goal = [19, 10, 5]
//! ```
//!
//! # Format (annotated)
//!
//! ```toml
//! name = "quickstart"            # for reports and the run log
//! description = "…"              # optional, free text
//! seed = 1                       # the trial seed: world, maneuvers, sensor noise, planner
//! time_limit_s = 20.0            # default 60
//!
//! [world]
//! bounds = { min = [0, 0, 0], max = [40, 20, 10] }   # optional with a generator
//! # generator = { kind = "e4", pillar_count = 150 } # e1 | e2-static | e2-dynamic | e3 | e4 | dynamic-forest
//!
//! [[static.shapes]]              # vertical cylinder, as in the run-log contract
//! kind = "cylinder"
//! center = [12, 8]
//! radius = 1.0
//! z_min = 0.0
//! z_max = 10.0
//! [[static.shapes]]
//! kind = "box"
//! min = [20, 12, 0]
//! max = [23, 16, 6]
//! [[static.shapes]]
//! kind = "sphere"
//! center = [30, 6, 4]
//! radius = 1.2
//!
//! [static.point_cloud]           # optional: the planner sees a cloud, not the shapes
//! source = "shapes"              # shapes | inline (points = [[x,y,z], …]) | file (path = "…")
//! esdf_voxel_m = 0.2
//!
//! [[obstacles]]                  # an explicit moving obstacle
//! shape = "cylinder"             # sphere | cylinder | box
//! radius_m = 0.5                 # spheres and cylinders
//! half_height_m = 1.5            # cylinders only
//! position = [25, 15, 5]
//! velocity = [0, -1.5, 0]
//! motion = { kind = "random-maneuvers", max_accel_m_s2 = 0.1, speed_m_s = [1, 2] }
//!
//! [[obstacles]]                  # scripted (crate::script): no position/velocity, the script
//! shape = "box"                  # gives them; an axis-aligned box (forecast as the vertical
//! half_extents = [0.4, 0.4, 0.4] # cylinder around it, crate::traffic)
//! motion = { kind = "fourier", period_s = 12, center = [20, 10, 4], cos = [[3, 0, 0]], sin = [[0, 3, 0]] }
//! # motion = { kind = "samples", file = "data/walker.csv", end = "hold" }   # t,x,y,z lines
//! # motion = { kind = "samples", samples = [[0, 1, 2, 1], [2, 3, 2, 1]], end = "loop" }
//!
//! [[random_obstacles]]           # a group drawn from the seed
//! count = 4
//! speed_m_s = [0.5, 2.0]
//! region = { min = [8, 0, 0], max = [34, 20, 10] }
//! motion = { kind = "random-maneuvers" }
//!
//! [mission]
//! start = [2, 10, 3]
//! goal = [38, 10, 3]
//! goal_tolerance_m = 0.5
//! # "random flight": start and goal drawn from the seed instead (sections::RandomEndpoints)
//! # random = { region = { min = [1, 1, 1], max = [39, 19, 9] }, min_distance_m = 20, clearance_m = 0.3 }
//!
//! [vehicle]
//! radius_m = 0.3
//! limits = { v_max = 10.0, a_max = 15.0 }
//! model = "quadrotor"            # quadrotor | perfect; [vehicle.quadrotor], [vehicle.gains]
//!
//! [planner]                      # read by the planner's crate (trust_planner::PlannerSpec)
//! name = "trust"                 # trust | baseline1 | baseline2 | baseline3
//! reproducible = true            # no wall-clock budgets (trust_planner::assemble)
//! # frontend = { kind = "v-prm", budget_ms = 20 }   # dev-prm | v-prm | straight-line | sparse-a-star
//! # backend = { kind = "minco" }                    # utf-minco | minco
//! # checker = { kind = "uvd" }                      # tvd | uvd
//! # tracking_margin_m = 0.02                        # default 0.01 + 0.0015 a_max (trust_planner)
//! # [planner.manager]                               # single fields of the preset's ManagerParams
//! # horizon_s = 3.0
//! # [planner.route]                                 # the global route, on by default;
//! # enabled = false                                 # false: the paper's setting (aim at the goal)
//! # [planner.route.params]                          # trust_route::RouteParams
//!
//! [sensing]
//! rate_hz = 20.0
//! position_noise_m = 0.1
//! dropout_probability = 0.0
//! r_safe_margin_m = 0.1
//! # static = "known"             # or { depth = { … } } | { lidar = { … } }: sensed (map_sensing)
//! # [sensing.ekf]                # trust_predict::EkfParams
//!
//! [traffic]
//! fault_level = 0.0              # > 0: maneuvers beyond the forecasts' mu
//!
//! [sim]
//! physics_dt_s = 0.002
//! replan_rate_hz = 10.0
//! log_rate_hz = 50.0
//! latency = { kind = "fixed" }   # fixed (seconds = …, default the manager's) | measured
//!
//! [log]
//! branches = true                # cycles carry branches + forecasts; unset: on for `trust-sim
//!                                # run`, off for studies (see LogSection)
//! ```
//!
//! Tagged tables use a `kind` key (`source` for point clouds) next to the variant's own fields;
//! serde's internally tagged enums keep `deny_unknown_fields` working there, and an unknown
//! `kind` is reported with the list of accepted names.
//!
//! # Files it names, scale policy
//!
//! Track and points files are read under [`files`]' policy: only regular files, a size cap per
//! kind (4 MiB scenario, 16 MiB track, 512 MiB points file), read line by line; a relative path
//! is resolved against the scenario's folder and may not leave it with `..` (an absolute path is
//! read as written). Every value and count the file sets is checked against the scale policy of
//! [`scale`] (coordinates within ±1e5 m, obstacle speeds up to 1e3 m/s, `v_max` in
//! [0.01, 100] m/s, `a_max` in [0.1, 100] m/s², at most 10 000 moving obstacles and 10 000 static
//! shapes, 2e7 cloud points, …) before anything is read, allocated or drawn for it.
//!
//! # Errors
//!
//! [`Scenario::load`] keeps toml's message for syntax errors, wrong types, unknown fields and
//! unknown names (file name, line, column and the offending snippet: [`WorldError::Parse`]), and
//! then runs [`Scenario::validate`], which collects **every** semantic problem
//! ([`WorldError::Invalid`]), each as `field.path: value — expected …` ([`Problem`]) that the
//! file alone shows. Start and goal against the generated layout are checked where the layout is
//! generated — once per world, in [`crate::World::build`] — or by [`crate::load_checked`]
//! (`trust-sim validate`), which generates the layout without building the maps.

pub use crate::files;
mod bounds;
pub(crate) mod generator;
pub mod points;
pub mod scale;
mod scale_check;

pub(crate) mod sections;
mod validate;

use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use trust_core::Aabb;

pub use crate::problem::Problem;
pub use bounds::BoundsSpec;
pub use generator::{DynamicForestParams, E1Params, E2Params, E3Params, E4Params, GeneratorSpec};
pub use sections::{
    Latency, MAX_CPU_SCALE, Mission, MovingShapeKind, ObstacleSpec, PointCloudSpec,
    RandomEndpoints, RandomObstacles, SimSection, StaticSection, StaticShape, VehicleModel,
    VehicleSection, WorldSection, endpoint_draw_count,
};

use crate::error::WorldError;
use crate::seeds::Seeds;
use crate::sensing::SensingParams;
use crate::traffic::TrafficParams;

/// One scenario file (module docs for the format).
///
/// `P` is the `[planner]` section as the crate that assembles the planner reads it: the world
/// never looks inside (it depends on no planner crate). The simulator reads files as
/// `Scenario<trust_planner::PlannerSpec>` (`trust_flight::scenario::Scenario`), so a wrong
/// planner field is a parse error with its line like any other, and checks it with the rest
/// (`trust_flight::scenario::check`); the default, a plain TOML table, reads any `[planner]`
/// section unchecked (the world's own tests and tools). [`Scenario::validate`] and
/// [`crate::check`] check everything but that section.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario<P = toml::Table> {
    /// Name, for reports and the run log header's `scenario`.
    pub name: String,
    /// Free text: what the scenario reproduces.
    #[serde(default)]
    pub description: String,
    /// The trial seed (see [`Seeds`]). Default 0.
    #[serde(default)]
    pub seed: u64,
    /// Simulated time limit (s), `> 0`. Default 60 s.
    #[serde(default = "default_time_limit")]
    pub time_limit_s: f64,
    /// `[world]`: bounds and generator.
    #[serde(default)]
    pub world: WorldSection,
    /// `[static]`: static shapes and what the planner sees of them.
    #[serde(default, rename = "static")]
    pub static_map: StaticSection,
    /// `[[obstacles]]`: explicit moving obstacles.
    #[serde(default)]
    pub obstacles: Vec<ObstacleSpec>,
    /// `[[random_obstacles]]`: groups of random moving obstacles.
    #[serde(default)]
    pub random_obstacles: Vec<RandomObstacles>,
    /// `[mission]`: start, goal and arrival tolerance.
    pub mission: Mission,
    /// `[vehicle]`: radius, limits and model.
    #[serde(default)]
    pub vehicle: VehicleSection,
    /// `[planner]`: preset and overrides, read by the planner's crate (`P`, type docs).
    #[serde(default)]
    pub planner: P,
    /// `[sensing]`: obstacle sensor and tracker.
    #[serde(default)]
    pub sensing: SensingParams,
    /// `[traffic]`: fault level of the true maneuvers.
    #[serde(default)]
    pub traffic: TrafficParams,
    /// `[sim]`: physics, replanning and logging clocks, latency.
    #[serde(default)]
    pub sim: SimSection,
    /// `[log]`: what the run log carries beyond the contract (issue 20).
    #[serde(default)]
    pub log: LogSection,
    /// The file it was read from (relative paths in it are resolved against its folder);
    /// `None` for a scenario made in code (paths relative to the current directory). Not part
    /// of the file.
    #[serde(skip)]
    pub path: Option<PathBuf>,
}

fn default_time_limit() -> f64 {
    60.0
}

/// Section `[log]`: optional content of the run log.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LogSection {
    /// Whether every `cycle` record carries the kept branches (sampled) and the forecasts the
    /// cycle planned against (`branch_samples`, `forecasts`; `docs/run-log.md`). `None` (the
    /// default) leaves it to the command: on for `trust-sim run` (which also has
    /// `--log-branches` / `--no-log-branches`), off for studies (ablate, E4, the suite), whose
    /// logs stay small and byte-identical to those written before the fields existed.
    pub branches: Option<bool>,
}

impl LogSection {
    /// Whether to log branches, `default` being the command's choice when the file says nothing.
    pub fn branches_or(&self, default: bool) -> bool {
        self.branches.unwrap_or(default)
    }
}

impl<P: DeserializeOwned + Default + Clone> Scenario<P> {
    /// Parses scenario text; `origin` names it in errors and gives the folder relative paths are
    /// resolved against (its parent). Does not validate.
    ///
    /// # Errors
    /// [`WorldError::Parse`] with toml's message (line, column, snippet).
    pub fn from_toml_str(text: &str, origin: &Path) -> Result<Scenario<P>, WorldError> {
        let mut s: Scenario<P> = toml::from_str(text).map_err(|e| WorldError::Parse {
            path: origin.to_path_buf(),
            message: files::parser_message(e.to_string().trim_end()),
        })?;
        s.path = Some(origin.to_path_buf());
        Ok(s.with_seed(s.seed))
    }

    /// Reads and parses a scenario file without validating it: a regular file of at most
    /// [`files::MAX_SCENARIO_BYTES`] ([`files`]).
    ///
    /// # Errors
    /// [`WorldError::Read`], [`WorldError::NotAFile`], [`WorldError::TooLarge`],
    /// [`WorldError::Parse`].
    pub fn parse_file(path: &Path) -> Result<Scenario<P>, WorldError> {
        let text = files::read_text(path, files::MAX_SCENARIO_BYTES, "a scenario file")?;
        Scenario::from_toml_str(&text, path)
    }

    /// Reads, parses and checks a scenario file ([`Scenario::validate`]: everything the file
    /// alone shows; the layout checks run where the world is built, [`crate::World::build`], or
    /// in [`crate::load_checked`]).
    ///
    /// # Errors
    /// [`WorldError::Read`], [`WorldError::Parse`], or [`WorldError::Invalid`] with every problem
    /// [`Scenario::validate`] found.
    pub fn load(path: &Path) -> Result<Scenario<P>, WorldError> {
        let s = Scenario::parse_file(path)?;
        let problems = s.validate();
        WorldError::unless_problems(s, path, problems)
    }
}

impl<P: Clone> Scenario<P> {
    /// The same scenario with another trial seed (Monte Carlo trials).
    #[must_use]
    pub fn with_seed(&self, seed: u64) -> Scenario<P> {
        let mut s = Scenario {
            seed,
            ..self.clone()
        };
        // A random flight draws its start and goal from the seed, in a region within the scale
        // policy (validation reports one outside it; the draw would not be uniform there).
        if let (Some(random), Some(bounds)) = (&s.mission.random, s.bounds())
            && random.drawable(&bounds)
        {
            use trust_geometry::{AaBox, Cylinder, Shape, Sphere};
            // Clear of the static shapes and of the explicit moving obstacles where they are at
            // t = 0 (a start inside a person is invalid).
            let mut shapes: Vec<Shape> = s
                .static_map
                .shapes
                .iter()
                .map(sections::geometry_shape)
                .collect();
            for o in &s.obstacles {
                let Some(p) = o.position else { continue };
                let center = trust_core::Vec3::from(p);
                shapes.push(match o.moving_shape() {
                    crate::traffic::MovingShape::Sphere { radius } => {
                        Shape::Sphere(Sphere { center, radius })
                    }
                    crate::traffic::MovingShape::Cylinder {
                        radius,
                        half_height,
                    } => Shape::Cylinder(Cylinder {
                        center,
                        radius,
                        half_height,
                    }),
                    crate::traffic::MovingShape::Box { half_extents } => {
                        let h = trust_core::Vec3::from(half_extents);
                        Shape::AaBox(AaBox {
                            min: center - h,
                            max: center + h,
                        })
                    }
                });
            }
            let (start, goal) = random.draw(seed, &bounds, &shapes, s.vehicle.radius_m);
            s.mission.start = start;
            s.mission.goal = goal;
        }
        s
    }
}

impl<P> Scenario<P> {
    /// The seeds of this trial's random streams.
    pub fn seeds(&self) -> Seeds {
        Seeds::from_trial(self.seed)
    }

    /// The world bounds: `world.bounds`, else the generator's
    /// ([`GeneratorSpec::default_bounds`]); `None` if neither is given.
    pub fn bounds(&self) -> Option<Aabb> {
        match (&self.world.bounds, &self.world.generator) {
            (Some(b), _) => Some(b.aabb()),
            (None, Some(g)) => Some(g.default_bounds()),
            (None, None) => None,
        }
    }

    /// A path from the file, resolved against the folder of [`Scenario::path`] (validation
    /// refuses a relative path that leaves it: [`files`]).
    pub fn resolve_path(&self, path: &Path) -> PathBuf {
        files::resolve(self.path.as_deref().and_then(Path::parent), path)
    }

    /// What errors call this scenario: its file, or `<scenario NAME>`.
    pub fn origin(&self) -> PathBuf {
        self.path
            .clone()
            .unwrap_or_else(|| PathBuf::from(format!("<scenario {}>", self.name)))
    }
}

impl<P: Clone> Scenario<P> {
    /// The same scenario with its `[planner]` section replaced by `planner` (of any type): a
    /// world keeps its scenario without the planner (`Scenario<()>`, [`crate::World::scenario`]).
    pub fn with_planner<Q>(&self, planner: Q) -> Scenario<Q> {
        let Scenario {
            name,
            description,
            seed,
            time_limit_s,
            world,
            static_map,
            obstacles,
            random_obstacles,
            mission,
            vehicle,
            planner: _,
            sensing,
            traffic,
            sim,
            log,
            path,
        } = self.clone();
        Scenario {
            name,
            description,
            seed,
            time_limit_s,
            world,
            static_map,
            obstacles,
            random_obstacles,
            mission,
            vehicle,
            planner,
            sensing,
            traffic,
            sim,
            log,
            path,
        }
    }
}

impl<P: Serialize> Scenario<P> {
    /// The scenario as TOML text (round-trips through [`Scenario::from_toml_str`]).
    ///
    /// # Errors
    /// [`WorldError::Input`] if a value cannot be written as TOML (a seed above `i64::MAX`).
    pub fn to_toml_string(&self) -> Result<String, WorldError> {
        toml::to_string(self)
            .map_err(|e| WorldError::input("scenario", e, "a TOML-serializable scenario"))
    }
}

#[cfg(test)]
mod log_section_tests {
    use super::*;

    const BASE: &str = "name = \"t\"\n[world]\nbounds = { min = [0, 0, 0], max = [20, 20, 10] }\n\
                        [mission]\nstart = [1, 10, 5]\ngoal = [19, 10, 5]\n";

    #[test]
    fn the_log_section_is_optional_typed_and_closed() {
        let parse = |extra: &str| {
            Scenario::<toml::Table>::from_toml_str(&format!("{BASE}{extra}"), Path::new("t.toml"))
        };
        let none = parse("").unwrap();
        assert_eq!(none.log.branches, None);
        assert!(none.log.branches_or(true) && !none.log.branches_or(false));
        let off = parse("[log]\nbranches = false\n").unwrap();
        assert!(!off.log.branches_or(true));
        let e = parse("[log]\nbranches = \"yes\"\n")
            .unwrap_err()
            .to_string();
        assert!(e.contains("t.toml") && e.contains("branches"), "{e}");
        let e = parse("[log]\nbranch = true\n").unwrap_err().to_string();
        assert!(e.contains("unknown field `branch`"), "{e}");
    }
}
