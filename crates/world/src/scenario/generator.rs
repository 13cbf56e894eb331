//! World generators of the paper's experiments (scenario key `world.generator`, tagged by
//! `kind`). The parameters live here; the generation itself is [`crate`]'s, which
//! documents every distribution.

use serde::{Deserialize, Serialize};
use trust_core::{Aabb, Vec3};

use crate::problem::Problems;
use crate::scenario::bounds::BoundsSpec;
use crate::traffic::{ManeuverParams, Motion};

/// Which generator, with its parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum GeneratorSpec {
    /// `{ kind = "e1", obstacle_count = 10 }`: experiment E1 (paper Sec. IV-A, Fig.
    /// Sim-A-1-1(c)), a 20 × 20 × 10 m box with random moving obstacles.
    E1(E1Params),
    /// `{ kind = "e2-static" }`: the static case of experiment E2 (paper Sec. IV-B, Table
    /// Sim-A-2), `trust_scenes::e2::e2_static`.
    E2Static(E2Params),
    /// `{ kind = "e2-dynamic" }`: the dynamic case of E2, `trust_scenes::e2::e2_dynamic`.
    E2Dynamic(E2Params),
    /// `{ kind = "e3" }`: experiment E3 (paper Sec. IV-C, Table Sim-B-1), the setting of Fig.
    /// Sim-A-1-1(a): goal 65 m ahead, moving obstacles near the start.
    E3(E3Params),
    /// `{ kind = "e4" }`: experiment E4 (paper Sec. IV-D, Fig. baseline-test-3), 250 × 75 × 20 m
    /// of dense static obstacles seen as a point cloud and 100 moving obstacles.
    E4(E4Params),
    /// `{ kind = "dynamic-forest", obstacle_count = 50 }`: MIT-ACL's dynamic-forest benchmark
    /// (`trust_scenes::dynamic_forest`): 65 % cubes on trefoil knots, the rest pillars and bars,
    /// between `(0, 0, 2)` and `(105, 0, 2)`; not an experiment of the paper.
    DynamicForest(DynamicForestParams),
}

impl GeneratorSpec {
    /// The scenario name of this kind.
    pub fn kind_name(&self) -> &'static str {
        match self {
            GeneratorSpec::E1(_) => "e1",
            GeneratorSpec::E2Static(_) => "e2-static",
            GeneratorSpec::E2Dynamic(_) => "e2-dynamic",
            GeneratorSpec::E3(_) => "e3",
            GeneratorSpec::E4(_) => "e4",
            GeneratorSpec::DynamicForest(_) => "dynamic-forest",
        }
    }

    /// The bounds the generator is designed for, used when `world.bounds` is absent:
    /// E1 `[0, 0, 0]..[20, 20, 10]` (paper: 20 × 20 × 10 m), E2 `[0, 0, 0]..[50, 20, 10]`
    /// (paper: 50 × 20 × 10 m), E3 `[-5, -10, 0]..[70, 10, 15]` (ours: Fig. Sim-A-1-1(a)'s goal
    /// `[65, 0, 7.5]` seen from a start at the origin needs 65 m along x; 20 m across as in E1,
    /// 15 m high so that the goal height 7.5 m is mid-height), E4 `[0, 0, 0]..[250, 75, 20]`
    /// (paper: 250 × 75 × 20 m), dynamic forest `[-5, -15, 0.5]..[110, 15, 6]` (ours: 5 m
    /// behind the start and beyond the goal along x; ±15 m across, 6 m beyond the farthest
    /// reach of any obstacle so the forest can be flown around as in the peers' ±200 m map;
    /// z = SANDO's altitude limits 0.5–6 m, `config/sando.yaml`).
    pub fn default_bounds(&self) -> Aabb {
        let (min, max) = match self {
            GeneratorSpec::E1(_) => ([0.0, 0.0, 0.0], [20.0, 20.0, 10.0]),
            GeneratorSpec::E2Static(_) | GeneratorSpec::E2Dynamic(_) => {
                ([0.0, 0.0, 0.0], [50.0, 20.0, 10.0])
            }
            GeneratorSpec::E3(_) => ([-5.0, -10.0, 0.0], [70.0, 10.0, 15.0]),
            GeneratorSpec::E4(_) => ([0.0, 0.0, 0.0], [250.0, 75.0, 20.0]),
            GeneratorSpec::DynamicForest(_) => ([-5.0, -15.0, 0.5], [110.0, 15.0, 6.0]),
        };
        Aabb {
            min: Vec3::from(min),
            max: Vec3::from(max),
        }
    }

    pub(crate) fn check(&self, field: &str, p: &mut Problems) {
        match self {
            GeneratorSpec::E1(e) => check_motion(&format!("{field}.motion"), &e.motion, p),
            GeneratorSpec::E2Static(_) | GeneratorSpec::E2Dynamic(_) => {}
            GeneratorSpec::E3(e) => {
                if let Some(r) = &e.region
                    && !r.is_valid()
                {
                    p.push(
                        format!("{field}.region"),
                        crate::problem::fmt_bounds(&r.min, &r.max),
                        "finite bounds with min < max on every axis",
                    );
                }
                check_motion(&format!("{field}.motion"), &e.motion, p);
            }
            GeneratorSpec::E4(e) => e.check(field, p),
            GeneratorSpec::DynamicForest(_) => {}
        }
    }
}

pub(crate) fn check_motion(field: &str, m: &Motion, p: &mut Problems) {
    match m {
        Motion::RandomManeuvers(m) => m.check(field, p),
        Motion::Samples(_) | Motion::Fourier(_) => p.push(
            format!("{field}.kind"),
            if matches!(m, Motion::Samples(_)) {
                "\"samples\""
            } else {
                "\"fourier\""
            },
            "\"constant-velocity\" or \"random-maneuvers\": a scripted motion belongs to one \
             explicit [[obstacles]] entry, not to a generated group",
        ),
        Motion::ConstantVelocity {} => {}
    }
}

/// Parameters of the dynamic-forest generator (`trust_scenes::dynamic_forest` documents the
/// draws). The benchmark's tiers are easy / medium / hard = 50 / 100 / 200 obstacles.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DynamicForestParams {
    /// Number of obstacles `N`, moving and static. Default 50 (the easy tier).
    pub obstacle_count: usize,
}

impl Default for DynamicForestParams {
    fn default() -> Self {
        DynamicForestParams { obstacle_count: 50 }
    }
}

/// Parameters of the E2 generators: none (the scenes are fixed; the empty table rejects unknown
/// fields).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct E2Params {}

/// Parameters of the E1 generator. The obstacle distributions are E1's random scenes
/// (`trust_scenes::e1`, see
/// [`crate::scenario::RandomObstacles`]'s defaults).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct E1Params {
    /// `k`, the number of moving obstacles. Default 10 (the paper's headline comparison).
    pub obstacle_count: usize,
    /// Their motion. Default constant velocity (E1 is a frontend experiment on one snapshot).
    pub motion: Motion,
}

impl Default for E1Params {
    fn default() -> Self {
        E1Params {
            obstacle_count: 10,
            motion: Motion::default(),
        }
    }
}

/// Parameters of the E3 generator: random moving obstacles with E1's distributions in a region
/// near the start.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct E3Params {
    /// Number of moving obstacles. Default 10 (ours: as E1's headline `k`).
    pub obstacle_count: usize,
    /// Where they start and stay. Default: x from 5 to 45 m (the first 40 m horizon of a
    /// 10 m/s flight from the origin, [`GeneratorSpec::default_bounds`]), the full width and
    /// height of the world bounds.
    pub region: Option<BoundsSpec>,
    /// Their motion. Default random maneuvers with [`ManeuverParams::default`] (within the
    /// default forecasts' `μ`).
    pub motion: Motion,
}

impl Default for E3Params {
    fn default() -> Self {
        E3Params {
            obstacle_count: 10,
            region: None,
            motion: Motion::RandomManeuvers(ManeuverParams::default()),
        }
    }
}

/// Parameters of the E4 generator. The paper states only "250 × 75 × 20 m, densely filled with
/// static point clouds, as well as 100 randomly generated dynamic obstacles"; the shapes, sizes,
/// counts and speeds below are ours (see [`crate`] for how they are placed and why).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct E4Params {
    /// Number of pillars (full-height vertical cylinders, like trunks or columns). Default 320.
    pub pillar_count: usize,
    /// Pillar radius range (m). Default 0.5–1.5.
    pub pillar_radius_m: [f64; 2],
    /// Number of walls (thin boxes standing on the ground, along x or y). Default 40.
    pub wall_count: usize,
    /// Wall length range (m). Default 4–12.
    pub wall_length_m: [f64; 2],
    /// Wall thickness range (m). Default 0.4–0.8.
    pub wall_thickness_m: [f64; 2],
    /// Wall height range (m). Default 6–20.
    pub wall_height_m: [f64; 2],
    /// Number of blocks (boxes standing on the ground, like small buildings). Default 40.
    pub block_count: usize,
    /// Block side range (m), drawn separately for x and y. Default 2–6.
    pub block_size_m: [f64; 2],
    /// Block height range (m). Default 3–15.
    pub block_height_m: [f64; 2],
    /// Smallest horizontal gap between the footprints of two static obstacles (m), so that
    /// there are passages everywhere. Default 2.5 m (about eight vehicle radii; the backend's
    /// static clearance at 0.2 m voxels is 0.3 + 0.1 + 0.35 = 0.75 m on each side, so a 1 m wide
    /// corridor remains — see `trust_planner::assemble` and `World::static_map_error_m`).
    pub min_gap_m: f64,
    /// No static footprint comes within this horizontal distance of the start or the goal (m).
    /// Default 10 m.
    pub endpoint_clear_m: f64,
    /// Number of moving obstacles. Default 100 (paper).
    pub moving_count: usize,
    /// Probability that a moving obstacle is a cylinder (else a sphere). Default 0.5.
    pub moving_cylinder_fraction: f64,
    /// Moving sphere radius range (m). Default 0.4–1.0.
    pub moving_sphere_radius_m: [f64; 2],
    /// Moving cylinder radius range (m). Default 0.3–0.8.
    pub moving_cylinder_radius_m: [f64; 2],
    /// Moving cylinder half-height range (m). Default 1.0–2.5 (2–5 m tall).
    pub moving_cylinder_half_height_m: [f64; 2],
    /// Moving obstacle speed range (m/s). Default 0.5–2.5 (E1's 0.5–3 m/s, slightly slower
    /// in the clutter).
    pub moving_speed_m_s: [f64; 2],
    /// Largest climb angle of a moving sphere's velocity (degrees). Default 20 (mostly level
    /// traffic in a 20 m high world).
    pub moving_max_climb_deg: f64,
    /// The moving obstacles stay this far (m, along x) from the world's x ends, so the start
    /// and goal regions stay clear of them at all times. Default 10 m.
    pub moving_end_margin_m: f64,
    /// Their motion. Default random maneuvers with [`ManeuverParams::default`] (within the
    /// default forecasts' `μ`).
    pub moving_motion: Motion,
}

impl Default for E4Params {
    fn default() -> Self {
        E4Params {
            pillar_count: 320,
            pillar_radius_m: [0.5, 1.5],
            wall_count: 40,
            wall_length_m: [4.0, 12.0],
            wall_thickness_m: [0.4, 0.8],
            wall_height_m: [6.0, 20.0],
            block_count: 40,
            block_size_m: [2.0, 6.0],
            block_height_m: [3.0, 15.0],
            min_gap_m: 2.5,
            endpoint_clear_m: 10.0,
            moving_count: 100,
            moving_cylinder_fraction: 0.5,
            moving_sphere_radius_m: [0.4, 1.0],
            moving_cylinder_radius_m: [0.3, 0.8],
            moving_cylinder_half_height_m: [1.0, 2.5],
            moving_speed_m_s: [0.5, 2.5],
            moving_max_climb_deg: 20.0,
            moving_end_margin_m: 10.0,
            moving_motion: Motion::RandomManeuvers(ManeuverParams::default()),
        }
    }
}

impl E4Params {
    fn check(&self, field: &str, p: &mut Problems) {
        let f = |name: &str| format!("{field}.{name}");
        p.range(&f("pillar_radius_m"), self.pillar_radius_m, true);
        p.range(&f("wall_length_m"), self.wall_length_m, true);
        p.range(&f("wall_thickness_m"), self.wall_thickness_m, true);
        p.range(&f("wall_height_m"), self.wall_height_m, true);
        p.range(&f("block_size_m"), self.block_size_m, true);
        p.range(&f("block_height_m"), self.block_height_m, true);
        p.non_negative(&f("min_gap_m"), self.min_gap_m);
        p.non_negative(&f("endpoint_clear_m"), self.endpoint_clear_m);
        p.probability(
            &f("moving_cylinder_fraction"),
            self.moving_cylinder_fraction,
        );
        p.range(
            &f("moving_sphere_radius_m"),
            self.moving_sphere_radius_m,
            true,
        );
        p.range(
            &f("moving_cylinder_radius_m"),
            self.moving_cylinder_radius_m,
            true,
        );
        p.range(
            &f("moving_cylinder_half_height_m"),
            self.moving_cylinder_half_height_m,
            true,
        );
        p.range(&f("moving_speed_m_s"), self.moving_speed_m_s, false);
        if !(0.0..=90.0).contains(&self.moving_max_climb_deg) {
            p.push(
                f("moving_max_climb_deg"),
                self.moving_max_climb_deg,
                "an angle in [0, 90] degrees",
            );
        }
        p.non_negative(&f("moving_end_margin_m"), self.moving_end_margin_m);
        check_motion(&f("moving_motion"), &self.moving_motion, p);
    }
}
