//! The scale policy's checks on a parsed scenario: every value the file sets against the limits
//! of [`super::scale`] (which holds the limits and knows no section type, so that the sections
//! may use them).

use trust_core::Aabb;
use trust_geometry::{MAX_VOXELS, checked_voxel_count};

use super::generator::GeneratorSpec;
use super::scale::{
    A_MAX_RANGE, MAX_CLOUD_POINTS, MAX_COORD_M, MAX_FAULT_LEVEL, MAX_NOISE_M,
    MAX_OBSTACLE_ACCEL_M_S2, MAX_OBSTACLE_COUNT, MAX_SCRIPT_TIME_S, MAX_SIZE_M, MAX_SPEED_M_S,
    MAX_STATIC_SHAPE_COUNT, MAX_TIME_LIMIT_S, MAX_VEHICLE_RADIUS_M, MAX_WARMUP_S, PHYSICS_DT_RANGE,
    V_MAX_RANGE, esdf_dims, fmt_grid,
};
use super::{PointCloudSpec, Scenario};
use crate::problem::{Problems, fmt_count, fmt_num};
use crate::traffic::Motion;

impl<P> Scenario<P> {
    /// The scale policy (module docs) on every value the file sets; `bounds` are the world
    /// bounds if valid.
    pub(crate) fn check_scale(&self, p: &mut Problems, bounds: Option<&Aabb>) {
        p.within("time_limit_s", self.time_limit_s, MAX_TIME_LIMIT_S, "s");
        self.scale_world(p);
        self.scale_static(p, bounds);
        self.scale_obstacles(p);
        self.scale_mission_and_vehicle(p);
        self.scale_sensing_and_sim(p, bounds);
    }

    fn scale_world(&self, p: &mut Problems) {
        if let Some(b) = &self.world.bounds {
            p.within_vec("world.bounds.min", &b.min, MAX_COORD_M, "m");
            p.within_vec("world.bounds.max", &b.max, MAX_COORD_M, "m");
        }
        let Some(g) = &self.world.generator else {
            return;
        };
        let f = |name: &str| format!("world.generator.{name}");
        match g {
            GeneratorSpec::E1(e) => {
                p.count(
                    &f("obstacle_count"),
                    e.obstacle_count as u128,
                    MAX_OBSTACLE_COUNT,
                    "moving obstacles",
                );
                self.scale_motion(p, &f("motion"), &e.motion);
            }
            GeneratorSpec::E2Static(_) | GeneratorSpec::E2Dynamic(_) => {}
            GeneratorSpec::E3(e) => {
                p.count(
                    &f("obstacle_count"),
                    e.obstacle_count as u128,
                    MAX_OBSTACLE_COUNT,
                    "moving obstacles",
                );
                if let Some(r) = &e.region {
                    p.within_vec(&f("region.min"), &r.min, MAX_COORD_M, "m");
                    p.within_vec(&f("region.max"), &r.max, MAX_COORD_M, "m");
                }
                self.scale_motion(p, &f("motion"), &e.motion);
            }
            GeneratorSpec::E4(e) => {
                for (name, n) in [
                    ("pillar_count", e.pillar_count),
                    ("wall_count", e.wall_count),
                    ("block_count", e.block_count),
                ] {
                    p.count(&f(name), n as u128, MAX_STATIC_SHAPE_COUNT, "static shapes");
                }
                p.count(
                    &f("moving_count"),
                    e.moving_count as u128,
                    MAX_OBSTACLE_COUNT,
                    "moving obstacles",
                );
                for (name, r) in [
                    ("pillar_radius_m", e.pillar_radius_m),
                    ("wall_length_m", e.wall_length_m),
                    ("wall_thickness_m", e.wall_thickness_m),
                    ("wall_height_m", e.wall_height_m),
                    ("block_size_m", e.block_size_m),
                    ("block_height_m", e.block_height_m),
                    ("moving_sphere_radius_m", e.moving_sphere_radius_m),
                    ("moving_cylinder_radius_m", e.moving_cylinder_radius_m),
                    (
                        "moving_cylinder_half_height_m",
                        e.moving_cylinder_half_height_m,
                    ),
                ] {
                    p.within_vec(&f(name), &r, MAX_SIZE_M, "m");
                }
                p.within_vec(
                    &f("moving_speed_m_s"),
                    &e.moving_speed_m_s,
                    MAX_SPEED_M_S,
                    "m/s",
                );
                for (name, x) in [
                    ("min_gap_m", e.min_gap_m),
                    ("endpoint_clear_m", e.endpoint_clear_m),
                    ("moving_end_margin_m", e.moving_end_margin_m),
                ] {
                    p.within(&f(name), x, MAX_SIZE_M, "m");
                }
                self.scale_motion(p, &f("moving_motion"), &e.moving_motion);
            }
            GeneratorSpec::DynamicForest(d) => {
                p.count(
                    &f("obstacle_count"),
                    d.obstacle_count as u128,
                    MAX_OBSTACLE_COUNT.min(MAX_STATIC_SHAPE_COUNT),
                    "obstacles",
                );
            }
        }
    }

    fn scale_static(&self, p: &mut Problems, bounds: Option<&Aabb>) {
        use super::StaticShape;
        let shapes = &self.static_map.shapes;
        let generated = match &self.world.generator {
            Some(GeneratorSpec::E4(e)) => {
                e.pillar_count as u128 + e.wall_count as u128 + e.block_count as u128
            }
            Some(GeneratorSpec::DynamicForest(d)) => {
                let n = d.obstacle_count;
                (n - trust_scenes::dynamic_forest::moving_count(n)) as u128
            }
            _ => 0,
        };
        let total = shapes.len() as u128 + generated;
        if total > MAX_STATIC_SHAPE_COUNT as u128 {
            p.push(
                "static.shapes",
                format!(
                    "{} shapes ({} generated)",
                    fmt_count(total),
                    fmt_count(generated)
                ),
                format!(
                    "at most {MAX_STATIC_SHAPE_COUNT} static shapes in all, explicit and \
                     generated (scale policy)"
                ),
            );
        }
        for (i, s) in shapes.iter().enumerate() {
            let f = |name: &str| format!("static.shapes[{i}].{name}");
            match *s {
                StaticShape::Sphere { center, radius } => {
                    p.within_vec(&f("center"), &center, MAX_COORD_M, "m");
                    p.within(&f("radius"), radius, MAX_SIZE_M, "m");
                }
                StaticShape::Cylinder {
                    center,
                    radius,
                    z_min,
                    z_max,
                } => {
                    p.within_vec(&f("center"), &center, MAX_COORD_M, "m");
                    p.within(&f("radius"), radius, MAX_SIZE_M, "m");
                    p.within(&f("z_min"), z_min, MAX_COORD_M, "m");
                    p.within(&f("z_max"), z_max, MAX_COORD_M, "m");
                }
                StaticShape::Box { min, max } => {
                    p.within_vec(&f("min"), &min, MAX_COORD_M, "m");
                    p.within_vec(&f("max"), &max, MAX_COORD_M, "m");
                }
            }
        }
        let Some(cloud) = &self.static_map.point_cloud else {
            return;
        };
        p.within(
            "static.point_cloud.esdf_voxel_m",
            cloud.esdf_voxel_m(),
            MAX_SIZE_M,
            "m",
        );
        match cloud {
            PointCloudSpec::Shapes {
                spacing_m: Some(s), ..
            } if s.is_finite() && *s > 0.0 => {
                p.within("static.point_cloud.spacing_m", *s, MAX_SIZE_M, "m");
                if let Some(b) = bounds {
                    let dims = esdf_dims(b, *s);
                    if checked_voxel_count(dims).is_err() {
                        p.push(
                            "static.point_cloud.spacing_m",
                            fmt_num(*s),
                            format!(
                                "a spacing giving at most {MAX_VOXELS} lattice points over \
                                 world.bounds (scale policy; this one gives {})",
                                fmt_grid(b, *s)
                            ),
                        );
                    }
                }
            }
            PointCloudSpec::Inline { points, .. }
                if p.count(
                    "static.point_cloud.points",
                    points.len() as u128,
                    MAX_CLOUD_POINTS,
                    "points",
                ) =>
            {
                for (i, q) in points.iter().enumerate() {
                    p.within_vec(
                        &format!("static.point_cloud.points[{i}]"),
                        q,
                        MAX_COORD_M,
                        "m",
                    );
                }
            }
            _ => {}
        }
    }

    fn scale_obstacles(&self, p: &mut Problems) {
        let mut total = self.obstacles.len() as u128;
        for (i, o) in self.obstacles.iter().enumerate() {
            let f = |name: &str| format!("obstacles[{i}].{name}");
            if let Some(x) = o.position {
                p.within_vec(&f("position"), &x, MAX_COORD_M, "m");
            }
            if let Some(v) = o.velocity {
                p.within_vec(&f("velocity"), &v, MAX_SPEED_M_S, "m/s");
            }
            if let Some(r) = o.radius_m {
                p.within(&f("radius_m"), r, MAX_SIZE_M, "m");
            }
            if let Some(h) = o.half_height_m {
                p.within(&f("half_height_m"), h, MAX_SIZE_M, "m");
            }
            if let Some(h) = o.half_extents {
                p.within_vec(&f("half_extents"), &h, MAX_SIZE_M, "m");
            }
            if let Some(r) = &o.region {
                p.within_vec(&f("region.min"), &r.min, MAX_COORD_M, "m");
                p.within_vec(&f("region.max"), &r.max, MAX_COORD_M, "m");
            }
            self.scale_motion(p, &f("motion"), &o.motion);
        }
        for (i, g) in self.random_obstacles.iter().enumerate() {
            let f = |name: &str| format!("random_obstacles[{i}].{name}");
            p.count(
                &f("count"),
                g.count as u128,
                MAX_OBSTACLE_COUNT,
                "moving obstacles",
            );
            total += g.count as u128;
            p.within_vec(&f("sphere_radius_m"), &g.sphere_radius_m, MAX_SIZE_M, "m");
            p.within_vec(
                &f("cylinder_radius_m"),
                &g.cylinder_radius_m,
                MAX_SIZE_M,
                "m",
            );
            if let Some(h) = g.cylinder_half_height_m {
                p.within_vec(&f("cylinder_half_height_m"), &h, MAX_SIZE_M, "m");
            }
            p.within_vec(&f("speed_m_s"), &g.speed_m_s, MAX_SPEED_M_S, "m/s");
            p.within(
                &f("endpoint_clearance_m"),
                g.endpoint_clearance_m,
                MAX_SIZE_M,
                "m",
            );
            if let Some(r) = &g.region {
                p.within_vec(&f("region.min"), &r.min, MAX_COORD_M, "m");
                p.within_vec(&f("region.max"), &r.max, MAX_COORD_M, "m");
            }
            self.scale_motion(p, &f("motion"), &g.motion);
        }
        total += match &self.world.generator {
            Some(GeneratorSpec::E1(e)) => e.obstacle_count as u128,
            Some(GeneratorSpec::E3(e)) => e.obstacle_count as u128,
            Some(GeneratorSpec::E4(e)) => e.moving_count as u128,
            Some(GeneratorSpec::DynamicForest(d)) => {
                trust_scenes::dynamic_forest::moving_count(d.obstacle_count) as u128
            }
            _ => 0,
        };
        if total > MAX_OBSTACLE_COUNT as u128 {
            p.push(
                "obstacles",
                format!("{} moving obstacles in all", fmt_count(total)),
                format!(
                    "at most {MAX_OBSTACLE_COUNT} moving obstacles in all: [[obstacles]], \
                     [[random_obstacles]] counts and the generator's (scale policy)"
                ),
            );
        }
    }

    /// A motion model's magnitudes; a script's period against the physics step.
    fn scale_motion(&self, p: &mut Problems, field: &str, m: &Motion) {
        let dt = self.sim.physics_dt_s;
        match m {
            Motion::ConstantVelocity {} => {}
            Motion::RandomManeuvers(r) => {
                if let Some(s) = r.speed_m_s {
                    p.within_vec(&format!("{field}.speed_m_s"), &s, MAX_SPEED_M_S, "m/s");
                }
                p.within(
                    &format!("{field}.max_accel_m_s2"),
                    r.max_accel_m_s2,
                    MAX_OBSTACLE_ACCEL_M_S2,
                    "m/s²",
                );
                if dt.is_finite() && r.mean_interval_s.is_finite() && r.mean_interval_s > 0.0 {
                    p.in_range(
                        &format!("{field}.mean_interval_s"),
                        r.mean_interval_s,
                        dt,
                        MAX_SCRIPT_TIME_S,
                        "s (at least sim.physics_dt_s)",
                    );
                }
            }
            Motion::Fourier(c) => {
                if dt.is_finite()
                    && dt > 0.0
                    && c.period_s.is_finite()
                    && c.period_s > 0.0
                    && c.period_s < dt
                {
                    p.push(
                        format!("{field}.period_s"),
                        fmt_num(c.period_s),
                        format!(
                            "a period of at least sim.physics_dt_s = {} s (scale policy: the \
                             simulation cannot follow a faster curve)",
                            fmt_num(dt)
                        ),
                    );
                }
                p.within(
                    &format!("{field}.phase_s"),
                    c.phase_s,
                    MAX_SCRIPT_TIME_S,
                    "s",
                );
                p.within_vec(&format!("{field}.center"), &c.center, MAX_COORD_M, "m");
            }
            Motion::Samples(_) => {}
        }
    }

    fn scale_mission_and_vehicle(&self, p: &mut Problems) {
        let m = &self.mission;
        if m.random.is_none() {
            p.within_vec("mission.start", &m.start, MAX_COORD_M, "m");
            p.within_vec("mission.goal", &m.goal, MAX_COORD_M, "m");
        }
        p.within(
            "mission.goal_tolerance_m",
            m.goal_tolerance_m,
            MAX_SIZE_M,
            "m",
        );
        if let Some(r) = &m.random {
            p.within(
                "mission.random.min_distance_m",
                r.min_distance_m,
                MAX_SIZE_M,
                "m",
            );
            p.within("mission.random.clearance_m", r.clearance_m, MAX_SIZE_M, "m");
            if let Some(region) = &r.region {
                p.within_vec("mission.random.region.min", &region.min, MAX_COORD_M, "m");
                p.within_vec("mission.random.region.max", &region.max, MAX_COORD_M, "m");
            }
        }
        let v = &self.vehicle;
        // Non-positive values are reported by the sign checks (validate.rs).
        p.within("vehicle.radius_m", v.radius_m, MAX_VEHICLE_RADIUS_M, "m");
        for (field, x, (lo, hi), unit) in [
            ("vehicle.limits.v_max", v.limits.v_max, V_MAX_RANGE, "m/s"),
            ("vehicle.limits.a_max", v.limits.a_max, A_MAX_RANGE, "m/s²"),
        ] {
            if x > 0.0 {
                p.in_range(field, x, lo, hi, unit);
            }
        }
    }

    fn scale_sensing_and_sim(&self, p: &mut Problems, bounds: Option<&Aabb>) {
        let s = &self.sensing;
        let diagonal = bounds.map_or(f64::INFINITY, |b| b.extent().norm());
        let noise_cap = MAX_NOISE_M.min(diagonal);
        if s.position_noise_m.is_finite() && s.position_noise_m > noise_cap {
            p.push(
                "sensing.position_noise_m",
                fmt_num(s.position_noise_m),
                format!(
                    "a noise of at most {} m (scale policy: at most {} m and at most the world's \
                     diagonal, {} m)",
                    fmt_num(noise_cap),
                    fmt_num(MAX_NOISE_M),
                    fmt_num(diagonal)
                ),
            );
        }
        p.within(
            "sensing.r_safe_margin_m",
            s.r_safe_margin_m,
            MAX_SIZE_M,
            "m",
        );
        p.within("sensing.warmup_s", s.warmup_s, MAX_WARMUP_S, "s");
        p.within(
            "traffic.fault_level",
            self.traffic.fault_level,
            MAX_FAULT_LEVEL,
            "",
        );
        let (lo, hi) = PHYSICS_DT_RANGE;
        if self.sim.physics_dt_s > 0.0 {
            p.in_range("sim.physics_dt_s", self.sim.physics_dt_s, lo, hi, "s");
        }
    }
}
