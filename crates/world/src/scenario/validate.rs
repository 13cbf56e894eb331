//! [`Scenario::validate`]: every semantic check, collecting all problems.

use trust_core::{Aabb, Vec3};
use trust_geometry::{MAX_VOXELS, checked_voxel_count};

use super::scale::{esdf_dims, fmt_grid};
use super::{Latency, MAX_CPU_SCALE, MovingShapeKind, PointCloudSpec, Problem, Scenario};
use crate::problem::{Problems, fmt_bounds, fmt_count, fmt_num, fmt_vec};
use crate::scenario::points::read_points_file;
use trust_vehicle::VehicleError;

/// Relative tolerance of "a period is an integer multiple of the physics step".
const DIVIDE_TOLERANCE: f64 = 1e-9;

/// The run-log contract's lowest state-record rate (Hz).
const MIN_LOG_RATE_HZ: f64 = 50.0;

/// What the file-level checks found, and what they computed that the world build reuses (the
/// bounds, and the cloud points read from the file, so that a points file is read once per build).
pub(crate) struct FileCheck {
    /// Every problem, in file order.
    pub(crate) problems: Problems,
    /// The world bounds, if given and valid.
    pub(crate) bounds: Option<Aabb>,
    /// The cloud points that are truth (inline or file), if any and readable.
    pub(crate) cloud_points: Option<Vec<Vec3>>,
    /// Bounds, static map, obstacles, mission and vehicle radius are valid, so the layout can be
    /// generated and checked (`generate::check_layout`).
    pub(crate) geometry_ok: bool,
}

/// What the track files of a scenario's obstacles have read so far, against the scale policy's
/// totals ([`super::scale::MAX_TRACK_BYTES_TOTAL`], [`super::scale::MAX_TRACK_SAMPLES_TOTAL`]).
#[derive(Debug, Default)]
struct TrackTotals {
    bytes: u64,
    samples: usize,
    /// The totals were exceeded (reported once; no further file is read).
    over: bool,
}

impl TrackTotals {
    /// Whether obstacle `o` (`field`) may have its track file read: always without one; with
    /// one, while the totals, this file's size included, stay within the policy (reported on
    /// the first obstacle beyond them).
    fn admit<P>(
        &mut self,
        s: &Scenario<P>,
        o: &super::ObstacleSpec,
        field: &str,
        p: &mut Problems,
    ) -> bool {
        let crate::traffic::Motion::Samples(spec) = &o.motion else {
            return true;
        };
        if spec.file.is_none() {
            return true;
        }
        if self.over {
            return false;
        }
        let size = spec
            .file
            .as_ref()
            .and_then(|f| std::fs::metadata(s.resolve_path(f)).ok())
            .map_or(0, |m| m.len());
        if self.bytes.saturating_add(size) <= super::scale::MAX_TRACK_BYTES_TOTAL {
            self.bytes += size;
            return true;
        }
        self.exceeded(
            field,
            &format!("this file has {} bytes", fmt_count(u128::from(size))),
            p,
        );
        false
    }

    /// Counts the `n` samples obstacle `field`'s file gave.
    fn loaded(&mut self, n: usize, field: &str, p: &mut Problems) {
        self.samples += n;
        if self.samples > super::scale::MAX_TRACK_SAMPLES_TOTAL && !self.over {
            self.exceeded(
                field,
                &format!("this file has {} samples", fmt_count(n as u128)),
                p,
            );
        }
    }

    fn exceeded(&mut self, field: &str, this: &str, p: &mut Problems) {
        use super::scale::{MAX_TRACK_BYTES_TOTAL, MAX_TRACK_SAMPLES_TOTAL};
        self.over = true;
        p.push(
            format!("{field}.motion.file"),
            format!(
                "{} bytes and {} samples read so far",
                fmt_count(u128::from(self.bytes)),
                fmt_count(self.samples as u128)
            ),
            format!(
                "at most {} MiB of track files and {} samples in all obstacles' tracks (scale \
                 policy: a file counts for every obstacle naming it; {this})",
                MAX_TRACK_BYTES_TOTAL >> 20,
                fmt_count(MAX_TRACK_SAMPLES_TOTAL as u128),
            ),
        );
    }
}

impl<P> Scenario<P> {
    /// Every semantic problem of the scenario that the file alone shows, in file order (empty:
    /// valid). The checks against the generated layout (start and goal clear of generated shapes
    /// and cloud points) run where the layout is generated, in [`crate::World::build`] and
    /// [`crate::check`], so that a world is generated once.
    ///
    /// Checks: non-finite numbers; non-positive sizes, limits, rates and time limit; bounds with
    /// `min ≥ max`; start and goal outside the bounds, inside or within the vehicle radius of a
    /// static shape or cloud point, the start within the vehicle radius of a moving obstacle at
    /// `t = 0`; moving obstacles not fitting their region; rates whose periods are not integer
    /// multiples of the physics step (within 1e-9 relative); a log rate below 50 Hz; bad
    /// parameters of the vehicle model, the EKF and the generators; a missing
    /// or malformed points file; an empty inline cloud; an ESDF grid above
    /// `trust_geometry::MAX_VOXELS` voxels (computed without allocating); a dropout probability
    /// outside `[0, 1)`. Names (planner, kinds) are checked when the file is parsed.
    pub fn validate(&self) -> Vec<Problem> {
        self.check_file().problems.list
    }

    /// The checks of [`Scenario::validate`], with what they computed.
    pub(crate) fn check_file(&self) -> FileCheck {
        let mut p = Problems::default();
        if self.name.trim().is_empty() {
            p.push("name", "\"\"", "a non-empty name");
        }
        p.positive("time_limit_s", self.time_limit_s);

        let geometry_start = p.list.len();
        let bounds = self.check_world(&mut p);
        // The scale policy first: no file is read and nothing is generated beyond it.
        self.check_scale(&mut p, bounds.as_ref());
        let cloud_points = self.check_static(&mut p, bounds.as_ref());
        self.check_obstacles(&mut p, bounds.as_ref());
        self.check_mission(&mut p, bounds.as_ref());
        let radius_ok = p.positive("vehicle.radius_m", self.vehicle.radius_m);
        let geometry_ok = p.list.len() == geometry_start && radius_ok;

        self.check_vehicle(&mut p);
        self.sensing.check("sensing", &mut p);
        p.non_negative("traffic.fault_level", self.traffic.fault_level);
        self.check_sim(&mut p);
        FileCheck {
            problems: p,
            bounds,
            cloud_points,
            geometry_ok,
        }
    }

    fn check_world(&self, p: &mut Problems) -> Option<Aabb> {
        if let Some(g) = &self.world.generator {
            g.check("world.generator", p);
        }
        match (&self.world.bounds, &self.world.generator) {
            (None, None) => {
                p.push(
                    "world.bounds",
                    "(missing)",
                    "bounds { min = [x, y, z], max = [x, y, z] } when there is no world.generator",
                );
                None
            }
            (Some(b), _) if !b.is_valid() => {
                p.push(
                    "world.bounds",
                    fmt_bounds(&b.min, &b.max),
                    "finite bounds with min < max on every axis",
                );
                None
            }
            _ => self.bounds(),
        }
    }

    /// Checks `[static]`; returns the cloud points that are truth (inline or file), if readable.
    fn check_static(&self, p: &mut Problems, bounds: Option<&Aabb>) -> Option<Vec<Vec3>> {
        for (i, s) in self.static_map.shapes.iter().enumerate() {
            check_shape(p, &format!("static.shapes[{i}]"), s);
        }
        let cloud = self.static_map.point_cloud.as_ref()?;
        let voxel = cloud.esdf_voxel_m();
        if p.positive("static.point_cloud.esdf_voxel_m", voxel)
            && let Some(b) = bounds
        {
            let dims = esdf_dims(b, voxel);
            if checked_voxel_count(dims).is_err() {
                p.push(
                    "static.point_cloud.esdf_voxel_m",
                    fmt_num(voxel),
                    format!(
                        "a voxel size giving at most {MAX_VOXELS} voxels over world.bounds \
                         (this one gives {})",
                        fmt_grid(b, voxel)
                    ),
                );
            }
        }
        match cloud {
            PointCloudSpec::Shapes { spacing_m, .. } => {
                if let Some(s) = spacing_m {
                    p.positive("static.point_cloud.spacing_m", *s);
                }
                None
            }
            PointCloudSpec::Inline { points, .. } => {
                if points.is_empty() {
                    p.push(
                        "static.point_cloud.points",
                        "[]",
                        "at least one point [x, y, z]",
                    );
                    return None;
                }
                let mut ok = true;
                for (i, q) in points.iter().enumerate() {
                    ok &= p.finite_vec(&format!("static.point_cloud.points[{i}]"), q);
                }
                ok.then(|| points.iter().map(|q| Vec3::from(*q)).collect())
            }
            PointCloudSpec::File { path, .. } => {
                if let Some(why) = crate::files::relative_path_problem(path) {
                    p.push(
                        "static.point_cloud.path",
                        format!("{:?}", path.display().to_string()),
                        why,
                    );
                    return None;
                }
                let full = self.resolve_path(path);
                match read_points_file(&full) {
                    Ok(pts) if pts.is_empty() => {
                        p.push(
                            "static.point_cloud.path",
                            format!("{:?}", path.display().to_string()),
                            format!(
                                "a file with at least one `x y z` line ({} has none)",
                                full.display()
                            ),
                        );
                        None
                    }
                    Ok(pts) => Some(pts),
                    Err(e) => {
                        p.push(
                            "static.point_cloud.path",
                            format!("{:?}", path.display().to_string()),
                            format!("a readable file of `x y z` lines ({e})"),
                        );
                        None
                    }
                }
            }
        }
    }

    fn check_obstacles(&self, p: &mut Problems, bounds: Option<&Aabb>) {
        // Every track file is read whole, for each obstacle that names it: the totals are
        // capped too (scale policy), not only each file.
        let mut tracks = TrackTotals::default();
        for (i, o) in self.obstacles.iter().enumerate() {
            let field = format!("obstacles[{i}]");
            let before = p.list.len();
            let shape = match o.shape {
                MovingShapeKind::Sphere => "sphere",
                MovingShapeKind::Cylinder => "cylinder",
                MovingShapeKind::Box => "box",
            };
            let wants = |name: &str| match name {
                "radius_m" => o.shape != MovingShapeKind::Box,
                "half_height_m" => o.shape == MovingShapeKind::Cylinder,
                _ => o.shape == MovingShapeKind::Box,
            };
            for (name, given) in [
                ("radius_m", o.radius_m.map(fmt_num)),
                ("half_height_m", o.half_height_m.map(fmt_num)),
                ("half_extents", o.half_extents.map(|h| fmt_vec(&h))),
            ] {
                match (wants(name), given) {
                    (true, None) => p.push(
                        format!("{field}.{name}"),
                        "(missing)",
                        match name {
                            "radius_m" => format!("a radius > 0 for a {shape}"),
                            "half_height_m" => "a half-height > 0 for a cylinder".to_string(),
                            _ => "half extents [hx, hy, hz] > 0 for a box".to_string(),
                        },
                    ),
                    (false, Some(v)) => p.push(
                        format!("{field}.{name}"),
                        v,
                        format!("no {name} for shape = \"{shape}\""),
                    ),
                    _ => {}
                }
            }
            let scripted = o.motion.is_scripted();
            for (name, given) in [("position", o.position), ("velocity", o.velocity)] {
                match (scripted, given) {
                    (true, Some(v)) => p.push(
                        format!("{field}.{name}"),
                        fmt_vec(&v),
                        "no position or velocity with a scripted motion (samples, fourier): the \
                         script gives them",
                    ),
                    (false, None) if name == "position" => p.push(
                        format!("{field}.position"),
                        "(missing)",
                        "the centre at t = 0 [x, y, z]",
                    ),
                    _ => {}
                }
            }
            if let crate::traffic::Motion::Samples(s) = &o.motion {
                if let Some(file) = &s.file
                    && let Some(why) = crate::files::relative_path_problem(file)
                {
                    p.push(
                        format!("{field}.motion.file"),
                        format!("{:?}", file.display().to_string()),
                        why,
                    );
                    continue;
                }
                match (s.samples.is_empty(), &s.file) {
                    (false, Some(file)) => p.push(
                        format!("{field}.motion"),
                        format!("samples and file {:?}", file.display().to_string()),
                        "either inline samples or a file, not both",
                    ),
                    (true, None) => p.push(
                        format!("{field}.motion.samples"),
                        "(missing)",
                        "samples = [[t, x, y, z], ...] or file = \"track.csv\"",
                    ),
                    _ => {}
                }
            }
            // Missing sizes were reported above; their zeros would be reported again.
            let reported: Vec<String> = p.list[before..].iter().map(|q| q.field.clone()).collect();
            let region = match (&o.region, bounds) {
                (Some(r), _) => Some(r.aabb()),
                (None, Some(b)) => Some(*b),
                (None, None) => None,
            };
            if let Some(region) = region {
                if !tracks.admit(self, o, &field, p) {
                    continue;
                }
                match o.moving_obstacle(&field, region, |q| self.resolve_path(q)) {
                    Ok(m) => {
                        if let crate::traffic::Motion::Samples(s) = &m.motion {
                            tracks.loaded(s.samples.len(), &field, p);
                        }
                        let mut sub = Problems::default();
                        m.check(&field, &mut sub);
                        sub.list.retain(|q| {
                            !reported
                                .iter()
                                .any(|r| q.field == *r || q.field.starts_with(&format!("{r}.")))
                        });
                        p.list.extend(sub.list);
                    }
                    Err(problem) => p.list.push(problem),
                }
            }
        }
        for (i, g) in self.random_obstacles.iter().enumerate() {
            let f = |name: &str| format!("random_obstacles[{i}].{name}");
            p.probability(&f("cylinder_fraction"), g.cylinder_fraction);
            p.range(&f("sphere_radius_m"), g.sphere_radius_m, true);
            p.range(&f("cylinder_radius_m"), g.cylinder_radius_m, true);
            if let Some(h) = g.cylinder_half_height_m {
                p.range(&f("cylinder_half_height_m"), h, true);
            }
            p.range(&f("speed_m_s"), g.speed_m_s, false);
            if !(0.0..=90.0).contains(&g.max_climb_deg) {
                p.push(
                    f("max_climb_deg"),
                    fmt_num(g.max_climb_deg),
                    "an angle in [0, 90] degrees",
                );
            }
            if let Some(r) = &g.region
                && !r.is_valid()
            {
                p.push(
                    f("region"),
                    fmt_bounds(&r.min, &r.max),
                    "finite bounds with min < max on every axis",
                );
            }
            p.non_negative(&f("endpoint_clearance_m"), g.endpoint_clearance_m);
            super::generator::check_motion(&f("motion"), &g.motion, p);
        }
    }

    fn check_mission(&self, p: &mut Problems, bounds: Option<&Aabb>) {
        let m = &self.mission;
        for (name, q) in [("mission.start", &m.start), ("mission.goal", &m.goal)] {
            if !p.finite_vec(name, q) {
                continue;
            }
            if let Some(b) = bounds
                && !b.contains(&Vec3::from(*q))
            {
                p.push(
                    name,
                    fmt_vec(q),
                    format!(
                        "a point inside world.bounds {}",
                        fmt_bounds(b.min.as_slice(), b.max.as_slice())
                    ),
                );
            }
        }
        p.positive("mission.goal_tolerance_m", m.goal_tolerance_m);
        if let Some(r) = &m.random {
            p.non_negative("mission.random.min_distance_m", r.min_distance_m);
            p.non_negative("mission.random.clearance_m", r.clearance_m);
            if let Some(region) = &r.region {
                let ok = p.finite_vec("mission.random.region.min", &region.min)
                    & p.finite_vec("mission.random.region.max", &region.max);
                let (lo, hi) = (Vec3::from(region.min), Vec3::from(region.max));
                if ok && (0..3).any(|i| lo[i] > hi[i]) {
                    p.push(
                        "mission.random.region",
                        fmt_bounds(&region.min, &region.max),
                        "min <= max on every axis",
                    );
                } else if ok
                    && let Some(b) = bounds
                    && !(b.contains(&lo) && b.contains(&hi))
                {
                    p.push(
                        "mission.random.region",
                        fmt_bounds(&region.min, &region.max),
                        format!(
                            "a box inside world.bounds {}",
                            fmt_bounds(b.min.as_slice(), b.max.as_slice())
                        ),
                    );
                }
            }
            if let Some(b) = bounds {
                let (a, g) = (Vec3::from(m.start), Vec3::from(m.goal));
                // A region outside the scale policy is not drawn from (reported there).
                if r.drawable(b)
                    && r.min_distance_m.is_finite()
                    && (a - g).norm() < r.min_distance_m
                {
                    let draws = super::sections::endpoint_draw_count(self.static_map.shapes.len());
                    p.push(
                        "mission.random.min_distance_m",
                        fmt_num(r.min_distance_m),
                        format!(
                            "a distance the region allows: the farthest clear pair of {draws} \
                             draws in {} is {} m apart (the draw gives up after {draws} points: \
                             at most {} distance tests to the static shapes)",
                            match &r.region {
                                Some(region) => fmt_bounds(&region.min, &region.max),
                                None => fmt_bounds(b.min.as_slice(), b.max.as_slice()),
                            },
                            fmt_num((a - g).norm()),
                            super::scale::MAX_ENDPOINT_WORK
                        ),
                    );
                }
            }
        }
    }

    fn check_vehicle(&self, p: &mut Problems) {
        let v = &self.vehicle;
        p.positive("vehicle.limits.v_max", v.limits.v_max);
        p.positive("vehicle.limits.a_max", v.limits.a_max);
        if let Err(e) = v.quadrotor.validate() {
            p.list.push(vehicle_problem(e, "vehicle.quadrotor"));
        }
        if let Err(e) = v.gains.validate() {
            p.list.push(vehicle_problem(e, "vehicle.gains"));
        }
    }

    fn check_sim(&self, p: &mut Problems) {
        let s = &self.sim;
        let dt_ok = p.positive("sim.physics_dt_s", s.physics_dt_s);
        let sensing_ok = self.sensing.rate_hz.is_finite() && self.sensing.rate_hz > 0.0;
        let rates = [
            ("sim.replan_rate_hz", s.replan_rate_hz, true),
            ("sim.log_rate_hz", s.log_rate_hz, true),
            ("sensing.rate_hz", self.sensing.rate_hz, false),
        ];
        for (name, rate, report_sign) in rates {
            let ok = if report_sign {
                p.positive(name, rate)
            } else {
                sensing_ok
            };
            if !(ok && dt_ok) {
                continue;
            }
            let period = 1.0 / rate;
            let n = period / s.physics_dt_s;
            let k = n.round();
            if k < 1.0 || (n - k).abs() > DIVIDE_TOLERANCE * n {
                p.push(
                    name,
                    fmt_num(rate),
                    format!(
                        "a rate whose period (1/{} = {} s) is an integer multiple of \
                         sim.physics_dt_s ({} s); it is {} steps",
                        fmt_num(rate),
                        fmt_num(period),
                        fmt_num(s.physics_dt_s),
                        fmt_num(n)
                    ),
                );
            }
        }
        if s.log_rate_hz.is_finite() && s.log_rate_hz > 0.0 && s.log_rate_hz < MIN_LOG_RATE_HZ {
            p.push(
                "sim.log_rate_hz",
                fmt_num(s.log_rate_hz),
                format!(
                    "at least {MIN_LOG_RATE_HZ} Hz (run-log contract: state records at >= 50 Hz)"
                ),
            );
        }
        if let Latency::Measured {
            cpu_scale: Some(scale),
        } = s.latency
            && !(scale > 0.0 && scale <= MAX_CPU_SCALE)
        {
            p.push(
                "sim.latency.cpu_scale",
                fmt_num(scale),
                format!("a number in (0, {MAX_CPU_SCALE}]"),
            );
        }
        if let Latency::Fixed {
            seconds: Some(seconds),
        } = s.latency
        {
            p.non_negative("sim.latency.seconds", seconds);
        }
    }
}

fn check_shape(p: &mut Problems, field: &str, s: &super::StaticShape) {
    use super::StaticShape;
    match *s {
        StaticShape::Sphere { center, radius } => {
            p.finite_vec(&format!("{field}.center"), &center);
            p.positive(&format!("{field}.radius"), radius);
        }
        StaticShape::Cylinder {
            center,
            radius,
            z_min,
            z_max,
        } => {
            p.finite_vec(&format!("{field}.center"), &center);
            p.positive(&format!("{field}.radius"), radius);
            let a = p.finite(&format!("{field}.z_min"), z_min);
            let b = p.finite(&format!("{field}.z_max"), z_max);
            if a && b && z_min >= z_max {
                p.push(
                    format!("{field}.z_max"),
                    fmt_num(z_max),
                    format!("a top above z_min = {}", fmt_num(z_min)),
                );
            }
        }
        StaticShape::Box { min, max } => {
            let a = p.finite_vec(&format!("{field}.min"), &min);
            let b = p.finite_vec(&format!("{field}.max"), &max);
            if a && b {
                for (i, axis) in ["x", "y", "z"].iter().enumerate() {
                    if min[i] >= max[i] {
                        p.push(
                            format!("{field}.max"),
                            fmt_vec(&max),
                            format!(
                                "max.{axis} > min.{axis} = {} (a box with volume)",
                                fmt_num(min[i])
                            ),
                        );
                    }
                }
            }
        }
    }
}

fn vehicle_problem(e: VehicleError, prefix: &str) -> Problem {
    match e {
        VehicleError::NonFinite { field, value } => Problem::new(
            format!("{prefix}.{field}"),
            fmt_num(value),
            "a finite number",
        ),
        VehicleError::OutOfRange {
            field,
            value,
            expected,
        } => Problem::new(format!("{prefix}.{field}"), fmt_num(value), expected),
        // `VehicleError` is `#[non_exhaustive]`: a future variant still names the section.
        other => Problem::new(prefix, other, "valid vehicle parameters"),
    }
}
