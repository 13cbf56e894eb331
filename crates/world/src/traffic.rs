//! The true moving obstacles: what the planner never sees directly (paper Sec. IV: "the planner
//! can not access to the precise future motion of dynamic obstacles").
//!
//! [`Traffic`] moves every obstacle from its initial state ([`MovingObstacle`]) under its
//! [`Motion`] model, reflecting it at the walls of its region so that it always stays fully
//! inside, and answers the collision question of the closed loop: [`Traffic::clearance`], the
//! distance from the vehicle centre to the nearest true obstacle surface.
//!
//! # Random maneuvers
//!
//! [`Motion::RandomManeuvers`] is a piecewise-constant control process. Maneuver instants form a
//! Poisson process with mean interval [`ManeuverParams::mean_interval_s`] (exponential gaps). At
//! each instant the obstacle draws, uniformly,
//!
//! * a turn rate `ω ∈ [−ω_cap, ω_cap]` about the vertical axis, held until the next instant;
//! * a target speed in [`ManeuverParams::speed_m_s`], approached at a tangential acceleration of
//!   `a/√2` and then held,
//!
//! where `a` is the acceleration bound and `ω_cap = min(ω_max, a / (√2 · v_top))` with `v_top`
//! the largest speed the obstacle can have. So the turn rate never exceeds `ω_max`, the speed
//! stays in its range (once inside it), and the acceleration norm
//! `√(a_tan² + (ω·|v_h|)²) ≤ a` — which bounds the deviation from constant-velocity motion over a
//! time `T` by `a·T²/2`. A forecast with uncertainty growth `μ` and horizon `T_h` covers that
//! deviation (`a·T²/2 ≤ μ·T` for `T ≤ T_h`) exactly when `a ≤ 2μ/T_h`
//! ([`ManeuverParams::covered_by`]). Vertical velocity (spheres only) is kept between reflections.
//!
//! # Scripted motion
//!
//! [`Motion::Samples`] and [`Motion::Fourier`] are deterministic truth ([`crate::script`]): the
//! centre follows the script exactly (no reflections at the region's walls; validation checks that
//! the script keeps the obstacle inside its region), the velocity is the script's derivative, and
//! the fault level does not apply.
//!
//! # Boxes
//!
//! A moving obstacle may be an axis-aligned box ([`MovingShape::Box`]): collisions are judged on
//! the box. Its forecasts ([`MovingShape::forecast_shape`]) use the vertical cylinder that
//! circumscribes it — radius `√(hx² + hy²)`, half-height `hz` — which contains the box, is
//! contained in its circumscribing sphere (radius `√(hx² + hy² + hz²)`), so it never blocks more
//! space than the sphere would, and is a shape every forecast and cone already handles (growing
//! in radius and half-height). A box does not rotate, so the cylinder stays conservative.
//!
//! # Fault level
//!
//! [`TrafficParams::fault_level`] `f ≥ 0` scales the acceleration and turn-rate bounds of every
//! maneuvering obstacle by `1 + f`. At `f = 0` the obstacles move as their scenario states (the
//! shipped scenarios choose bounds the forecast's `μ` covers); at `f > 0` they maneuver beyond it,
//! the "obstacle maneuvers beyond mu" fault of design.md §7. Constant-velocity obstacles are not
//! affected. A reflection at a region wall is an instantaneous velocity change that no `μ` covers;
//! [`Traffic::bounce_counts`] reports them.
//!
//! # Determinism
//!
//! Each obstacle draws its maneuvers from its own `ChaCha8` stream seeded from the traffic seed
//! and its index, and maneuver instants are continuous times (a step is split at them). So the
//! trajectories depend only on the seed and the sequence of step sizes — the closed loop steps at
//! the scenario's fixed physics step, whatever the planner does.

use rand::{Rng as _, SeedableRng};
use rand_distr::{Distribution, Exp};
use serde::{Deserialize, Serialize};
use trust_core::{Aabb, Rng, Vec3};
use trust_geometry::{box_sdf, cylinder_sdf, sphere_sdf};
use trust_predict::ObstacleShape;

use crate::error::WorldError;
use crate::problem::{Problems, fmt_bounds, fmt_num, fmt_vec};
use crate::script::{
    FOURIER_CHECK_SAMPLES, FourierCurve, FourierSpec, SampledPath, SamplesSpec, Script,
    check_fourier, check_inside, check_samples,
};
use crate::seeds::mix_seed;

/// True shape and size of a moving obstacle. A cylinder is vertical with its centre at
/// mid-height (run-log contract, `obstacles`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum MovingShape {
    /// A ball.
    Sphere {
        /// Radius (m), `> 0`.
        radius: f64,
    },
    /// A vertical cylinder.
    Cylinder {
        /// Radius (m), `> 0`.
        radius: f64,
        /// Half of the height (m), `> 0`.
        half_height: f64,
    },
    /// An axis-aligned box, centred at the obstacle's centre.
    Box {
        /// Half extents `[hx, hy, hz]` (m), each `> 0`.
        half_extents: [f64; 3],
    },
}

impl MovingShape {
    /// The radius of the forecast shape, a forecast's `r_o`: the sphere's or cylinder's radius;
    /// for a box, `√(hx² + hy²)`, the radius of the vertical cylinder its forecasts use (module
    /// docs).
    pub fn radius(&self) -> f64 {
        match *self {
            MovingShape::Sphere { radius } | MovingShape::Cylinder { radius, .. } => radius,
            MovingShape::Box { half_extents: h } => h[0].hypot(h[1]),
        }
    }

    /// Half extents of the bounding box about the centre.
    pub fn half_extents(&self) -> Vec3 {
        match *self {
            MovingShape::Sphere { radius } => Vec3::repeat(radius),
            MovingShape::Cylinder {
                radius,
                half_height,
            } => Vec3::new(radius, radius, half_height),
            MovingShape::Box { half_extents } => Vec3::from(half_extents),
        }
    }

    /// Signed distance from `p` to the obstacle centred at `center` (negative inside).
    pub fn signed_distance(&self, center: &Vec3, p: &Vec3) -> f64 {
        match *self {
            MovingShape::Sphere { radius } => sphere_sdf(center, radius, p).0,
            MovingShape::Cylinder {
                radius,
                half_height,
            } => cylinder_sdf(center, radius, half_height, p).0,
            MovingShape::Box { half_extents } => {
                let h = Vec3::from(half_extents);
                box_sdf(&(center - h), &(center + h), p).0
            }
        }
    }

    /// The shape a forecast of this obstacle uses (its `r_o` is [`MovingShape::radius`]): a box
    /// is forecast as its circumscribing vertical cylinder (module docs).
    pub fn forecast_shape(&self) -> ObstacleShape {
        match *self {
            MovingShape::Sphere { .. } => ObstacleShape::Sphere,
            MovingShape::Cylinder { half_height, .. } => ObstacleShape::Cylinder { half_height },
            MovingShape::Box { half_extents } => ObstacleShape::Cylinder {
                half_height: half_extents[2],
            },
        }
    }

    /// `"sphere"`, `"cylinder"` or `"box"` (the run log's `shape`).
    pub fn kind_name(&self) -> &'static str {
        match self {
            MovingShape::Sphere { .. } => "sphere",
            MovingShape::Cylinder { .. } => "cylinder",
            MovingShape::Box { .. } => "box",
        }
    }
}

/// Bounds of the random maneuvers (see the module docs for the process).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ManeuverParams {
    /// Mean time between maneuver instants (s), `> 0`. Default 2 s (ours: one maneuver per
    /// typical 2–4 s planning horizon).
    pub mean_interval_s: f64,
    /// Bound `a` on the acceleration norm (m/s²), `≥ 0`. Default 0.1 m/s² =
    /// [`ManeuverParams::covered_by`]`(0.2 m/s, 4 s)`: the default EKF's `mu_min` (0.2 m/s) over
    /// the manager's default 4 s horizon, so the default maneuvers stay within the forecasts.
    pub max_accel_m_s2: f64,
    /// Bound `ω_max` on the turn rate about the vertical (rad/s), `≥ 0`. Default 0.5 rad/s (ours;
    /// at the default acceleration bound it only binds below 0.14 m/s).
    pub max_turn_rate_rad_s: f64,
    /// Speed range `[min, max]` (m/s) of the target speeds. `None`: the initial speed is held
    /// (turns only). Random obstacle groups use their own speed range when this is `None`.
    pub speed_m_s: Option<[f64; 2]>,
}

impl Default for ManeuverParams {
    fn default() -> Self {
        ManeuverParams {
            mean_interval_s: 2.0,
            max_accel_m_s2: Self::covered_by(0.2, 4.0),
            max_turn_rate_rad_s: 0.5,
            speed_m_s: None,
        }
    }
}

impl ManeuverParams {
    /// The largest acceleration bound whose maneuvers a forecast with growth rate `mu` (m/s)
    /// covers over `horizon_s`: `2·mu/horizon_s` (the deviation `a·T²/2` stays below `mu·T` for
    /// every `T ≤ horizon_s`).
    pub fn covered_by(mu: f64, horizon_s: f64) -> f64 {
        2.0 * mu / horizon_s
    }

    pub(crate) fn check(&self, field: &str, problems: &mut Problems) {
        problems.positive(&format!("{field}.mean_interval_s"), self.mean_interval_s);
        problems.non_negative(&format!("{field}.max_accel_m_s2"), self.max_accel_m_s2);
        problems.non_negative(
            &format!("{field}.max_turn_rate_rad_s"),
            self.max_turn_rate_rad_s,
        );
        if let Some(r) = self.speed_m_s {
            problems.range(&format!("{field}.speed_m_s"), r, false);
        }
    }
}

/// How a moving obstacle moves (scenario key `motion`, tagged by `kind`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Motion {
    /// Straight lines at constant velocity between reflections: `{ kind = "constant-velocity" }`.
    ConstantVelocity {},
    /// Random maneuvers within bounds: `{ kind = "random-maneuvers", max_accel_m_s2 = 0.1, ... }`.
    RandomManeuvers(ManeuverParams),
    /// Scripted: time-stamped samples, inline or from a CSV file: `{ kind = "samples", file =
    /// "data/walker.csv", end = "hold" }` ([`crate::script`]).
    Samples(SamplesSpec),
    /// Scripted: a closed curve given by Fourier coefficients: `{ kind = "fourier", period_s =
    /// 12, center = [x, y, z], cos = [[r, 0, 0]], sin = [[0, r, 0]] }` ([`crate::script`]).
    Fourier(FourierSpec),
}

impl Motion {
    /// Whether the motion is scripted (samples or a Fourier curve): the obstacle's position and
    /// velocity come from the script.
    pub fn is_scripted(&self) -> bool {
        matches!(self, Motion::Samples(_) | Motion::Fourier(_))
    }

    /// The script ready to evaluate, for a scripted motion whose samples are loaded; `None` for
    /// the other motions.
    ///
    /// # Errors
    /// [`WorldError::Input`] naming the first bad sample or coefficient under `field`, or a
    /// samples file that was not loaded ([`SamplesSpec::load`]).
    pub fn script(&self, field: &str) -> Result<Option<Script>, WorldError> {
        match self {
            Motion::Samples(s) => {
                if s.samples.is_empty() && s.file.is_some() {
                    return Err(WorldError::input(
                        format!("{field}.file"),
                        format!("{:?} (not loaded)", s.file.clone().unwrap_or_default()),
                        "samples loaded from the file (SamplesSpec::load) before the traffic is built",
                    ));
                }
                Ok(Some(Script::Samples(SampledPath::new(
                    field, &s.samples, s.end,
                )?)))
            }
            Motion::Fourier(f) => Ok(Some(Script::Fourier(FourierCurve::new(field, f)?))),
            _ => Ok(None),
        }
    }
}

impl Default for Motion {
    fn default() -> Self {
        Motion::ConstantVelocity {}
    }
}

/// One true moving obstacle in its initial state.
#[derive(Debug, Clone, PartialEq)]
pub struct MovingObstacle {
    /// Shape and true size.
    pub shape: MovingShape,
    /// Centre at `t = 0` (m).
    pub position: Vec3,
    /// Velocity at `t = 0` (m/s).
    pub velocity: Vec3,
    /// Motion model.
    pub motion: Motion,
    /// The box the obstacle stays fully inside (it reflects at its walls): usually the world
    /// bounds.
    pub region: Aabb,
}

impl MovingObstacle {
    /// Every problem with this obstacle; field paths start with `field` (e.g. `obstacles[2]`).
    pub fn problems(&self, field: &str) -> Vec<crate::problem::Problem> {
        let mut p = Problems::default();
        self.check(field, &mut p);
        p.list
    }

    pub(crate) fn check(&self, field: &str, p: &mut Problems) {
        let mut sizes_ok = true;
        match self.shape {
            MovingShape::Sphere { radius } => {
                sizes_ok &= p.positive(&format!("{field}.radius_m"), radius);
            }
            MovingShape::Cylinder {
                radius,
                half_height,
            } => {
                sizes_ok &= p.positive(&format!("{field}.radius_m"), radius);
                sizes_ok &= p.positive(&format!("{field}.half_height_m"), half_height);
            }
            MovingShape::Box { half_extents } => {
                for (axis, h) in ["x", "y", "z"].iter().zip(half_extents) {
                    sizes_ok &= p.positive(&format!("{field}.half_extents.{axis}"), h);
                }
            }
        }
        let pos_ok = p.finite_vec(&format!("{field}.position"), self.position.as_slice());
        let vel_ok = p.finite_vec(&format!("{field}.velocity"), self.velocity.as_slice());
        let r = &self.region;
        let region_ok = r.min.iter().chain(r.max.iter()).all(|x| x.is_finite())
            && (0..3).all(|i| r.min[i] < r.max[i]);
        if !region_ok {
            p.push(
                format!("{field}.region"),
                fmt_bounds(r.min.as_slice(), r.max.as_slice()),
                "finite bounds with min < max on every axis",
            );
        }
        if sizes_ok && region_ok {
            let e = self.shape.half_extents();
            let fits = (0..3).all(|i| r.max[i] - r.min[i] >= 2.0 * e[i] - 1e-12);
            if !fits {
                p.push(
                    format!("{field}.region"),
                    fmt_bounds(r.min.as_slice(), r.max.as_slice()),
                    format!(
                        "a region at least as large as the obstacle (half extents {})",
                        fmt_vec(e.as_slice())
                    ),
                );
            } else if pos_ok && !self.motion.is_scripted() {
                let inside = (0..3).all(|i| {
                    self.position[i] >= r.min[i] + e[i] - 1e-9
                        && self.position[i] <= r.max[i] - e[i] + 1e-9
                });
                if !inside {
                    p.push(
                        format!("{field}.position"),
                        fmt_vec(self.position.as_slice()),
                        format!(
                            "a centre keeping the whole obstacle inside its region {}",
                            fmt_bounds(r.min.as_slice(), r.max.as_slice())
                        ),
                    );
                }
            }
        }
        let motion_field = format!("{field}.motion");
        let e = self.shape.half_extents();
        let inside_checkable = sizes_ok && region_ok;
        match &self.motion {
            Motion::Samples(s) => {
                if s.samples.is_empty() && s.file.is_some() {
                    p.push(
                        format!("{motion_field}.file"),
                        format!("{:?} (not loaded)", s.file.clone().unwrap_or_default()),
                        "samples loaded from the file (SamplesSpec::load)",
                    );
                } else {
                    let labels = s.labels(&motion_field);
                    check_samples(&motion_field, &s.samples, &labels, s.end, p);
                    if inside_checkable {
                        // Every finite sample, whatever else is wrong with the track.
                        let positions: Vec<(String, Vec3)> = labels
                            .into_iter()
                            .zip(&s.samples)
                            .filter(|(_, q)| q.iter().all(|x| x.is_finite()))
                            .map(|(l, q)| (l, Vec3::new(q[1], q[2], q[3])))
                            .collect();
                        check_inside(&positions, &e, r, &format!("{field}.region"), p);
                    }
                }
            }
            Motion::Fourier(f) => {
                let fields_ok = check_fourier(&motion_field, f, p);
                if fields_ok && inside_checkable {
                    let curve = FourierCurve::new(&motion_field, f).ok();
                    let first_out = curve.and_then(|c| {
                        (0..FOURIER_CHECK_SAMPLES)
                            .map(|k| {
                                let t = f.period_s * k as f64 / FOURIER_CHECK_SAMPLES as f64;
                                (t, c.evaluate(t).0)
                            })
                            .find(|(_, q)| {
                                !(0..3).all(|i| {
                                    q[i] >= r.min[i] + e[i] - 1e-9 && q[i] <= r.max[i] - e[i] + 1e-9
                                })
                            })
                    });
                    if let Some((t, q)) = first_out {
                        check_inside(
                            &[(format!("{motion_field} at t = {} s", fmt_num(t)), q)],
                            &e,
                            r,
                            &format!("{field}.region"),
                            p,
                        );
                    }
                }
            }
            _ => {}
        }
        if let Motion::RandomManeuvers(m) = &self.motion {
            m.check(&motion_field, p);
            if let (Some([lo, hi]), true) = (m.speed_m_s, vel_ok) {
                let s = self.velocity.norm();
                if lo.is_finite() && hi.is_finite() && !(lo - 1e-9..=hi + 1e-9).contains(&s) {
                    p.push(
                        format!("{field}.velocity"),
                        format!(
                            "{} (speed {})",
                            fmt_vec(self.velocity.as_slice()),
                            fmt_num(s)
                        ),
                        format!(
                            "a speed within {field}.motion.speed_m_s {}",
                            fmt_vec(&[lo, hi])
                        ),
                    );
                }
            }
        }
    }
}

/// Scenario section `[traffic]`: how the truth departs from what the forecasts cover.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TrafficParams {
    /// Fault level `f ≥ 0`: maneuvering obstacles use `1 + f` times their acceleration and
    /// turn-rate bounds (module docs). Default 0: maneuvers as stated.
    pub fault_level: f64,
}

impl Default for TrafficParams {
    fn default() -> Self {
        TrafficParams { fault_level: 0.0 }
    }
}

/// Per-obstacle state of the maneuver process.
#[derive(Debug, Clone)]
struct Agent {
    /// Lowest and highest centre positions (region shrunk by the half extents).
    lo: Vec3,
    hi: Vec3,
    /// Unit direction of motion.
    dir: Vec3,
    speed: f64,
    maneuver: Option<ManeuverState>,
    /// A scripted motion: the centre and velocity come from it.
    script: Option<Script>,
}

#[derive(Debug, Clone)]
struct ManeuverState {
    rng: Rng,
    gap: Exp<f64>,
    next_event_t: f64,
    omega_cap: f64,
    tangential_accel: f64,
    speed_range: [f64; 2],
    turn_rate: f64,
    target_speed: f64,
}

impl ManeuverState {
    fn draw(&mut self) {
        self.turn_rate = if self.omega_cap > 0.0 {
            self.rng.random_range(-self.omega_cap..=self.omega_cap)
        } else {
            0.0
        };
        let [lo, hi] = self.speed_range;
        self.target_speed = if hi > lo {
            self.rng.random_range(lo..=hi)
        } else {
            lo
        };
    }
}

/// The true moving obstacles of one flight (see the module docs).
#[derive(Debug, Clone)]
pub struct Traffic {
    t: f64,
    agents: Vec<Agent>,
    positions: Vec<Vec3>,
    velocities: Vec<Vec3>,
    shapes: Vec<MovingShape>,
    bounce_counts: Vec<usize>,
    maneuver_counts: Vec<usize>,
}

impl Traffic {
    /// The obstacles at `t = 0`, with maneuver bounds scaled by `1 + fault_level` and maneuver
    /// randomness from `seed`.
    ///
    /// # Errors
    /// [`WorldError::Input`] naming the first invalid obstacle field (`obstacles[i]. …`) or a
    /// negative/non-finite `fault_level`.
    pub fn new(
        obstacles: &[MovingObstacle],
        fault_level: f64,
        seed: u64,
    ) -> Result<Self, WorldError> {
        if !(fault_level.is_finite() && fault_level >= 0.0) {
            return Err(WorldError::input(
                "traffic.fault_level",
                fault_level,
                "a finite number >= 0",
            ));
        }
        let mut problems = Problems::default();
        for (i, o) in obstacles.iter().enumerate() {
            o.check(&format!("obstacles[{i}]"), &mut problems);
        }
        if let Some(first) = problems.list.into_iter().next() {
            return Err(WorldError::Input(first));
        }
        let scale = 1.0 + fault_level;
        let agents = obstacles
            .iter()
            .enumerate()
            .map(|(i, o)| {
                let e = o.shape.half_extents();
                let lo = o.region.min + e;
                let hi = (o.region.max - e).sup(&lo);
                let speed = o.velocity.norm();
                let dir = if speed > 0.0 {
                    o.velocity / speed
                } else {
                    Vec3::x()
                };
                let script = o.motion.script(&format!("obstacles[{i}].motion"))?;
                let maneuver = match &o.motion {
                    Motion::ConstantVelocity {} | Motion::Samples(_) | Motion::Fourier(_) => None,
                    Motion::RandomManeuvers(m) => {
                        let speed_range = m.speed_m_s.unwrap_or([speed, speed]);
                        let v_top = speed_range[1].max(speed);
                        let a = m.max_accel_m_s2 * scale;
                        let omega_max = m.max_turn_rate_rad_s * scale;
                        let omega_cap = if v_top > 0.0 {
                            omega_max.min(a / (std::f64::consts::SQRT_2 * v_top))
                        } else {
                            omega_max
                        };
                        let gap = Exp::new(1.0 / m.mean_interval_s).map_err(|_| {
                            WorldError::input(
                                format!("obstacles[{i}].motion.mean_interval_s"),
                                m.mean_interval_s,
                                "a finite number > 0",
                            )
                        })?;
                        let mut rng = Rng::seed_from_u64(mix_seed(seed, i as u64));
                        let next_event_t = gap.sample(&mut rng);
                        Some(ManeuverState {
                            rng,
                            gap,
                            next_event_t,
                            omega_cap,
                            tangential_accel: a / std::f64::consts::SQRT_2,
                            speed_range,
                            turn_rate: 0.0,
                            target_speed: speed,
                        })
                    }
                };
                Ok(Agent {
                    lo,
                    hi,
                    dir,
                    speed,
                    maneuver,
                    script,
                })
            })
            .collect::<Result<Vec<_>, WorldError>>()?;
        let initial = |k: usize| match &agents[k].script {
            Some(s) => s.evaluate(0.0),
            None => (obstacles[k].position, obstacles[k].velocity),
        };
        let (positions, velocities) = (0..obstacles.len()).map(initial).unzip();
        Ok(Traffic {
            t: 0.0,
            positions,
            velocities,
            shapes: obstacles.iter().map(|o| o.shape).collect(),
            bounce_counts: vec![0; obstacles.len()],
            maneuver_counts: vec![0; obstacles.len()],
            agents,
        })
    }

    /// Current time (s); starts at 0.
    pub fn time(&self) -> f64 {
        self.t
    }

    /// Number of obstacles.
    pub fn len(&self) -> usize {
        self.agents.len()
    }

    /// Whether there are no obstacles.
    pub fn is_empty(&self) -> bool {
        self.agents.is_empty()
    }

    /// True centres, in obstacle order (the run log's `state.obstacles`).
    pub fn positions(&self) -> &[Vec3] {
        &self.positions
    }

    /// True velocities, in obstacle order.
    pub fn velocities(&self) -> &[Vec3] {
        &self.velocities
    }

    /// True shapes and sizes, in obstacle order.
    pub fn shapes(&self) -> &[MovingShape] {
        &self.shapes
    }

    /// Reflections at a region wall so far, per obstacle.
    pub fn bounce_counts(&self) -> &[usize] {
        &self.bounce_counts
    }

    /// Maneuver instants so far, per obstacle.
    pub fn maneuver_counts(&self) -> &[usize] {
        &self.maneuver_counts
    }

    /// Distance from the vehicle centre `p` to the nearest true obstacle surface (negative
    /// inside) and that obstacle's index; `(f64::INFINITY, None)` without obstacles. Subtract the
    /// vehicle radius for the run log's clearance.
    pub fn clearance(&self, p: &Vec3) -> (f64, Option<usize>) {
        let mut best = (f64::INFINITY, None);
        for (i, (shape, c)) in self.shapes.iter().zip(&self.positions).enumerate() {
            let d = shape.signed_distance(c, p);
            if d < best.0 {
                best = (d, Some(i));
            }
        }
        best
    }

    /// Advances every obstacle by `dt` seconds.
    ///
    /// # Errors
    /// [`WorldError::Input`] if `dt` is not finite and positive (nothing changes).
    pub fn step(&mut self, dt: f64) -> Result<(), WorldError> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(WorldError::input("dt", dt, "a finite time step > 0 s"));
        }
        let t_end = self.t + dt;
        for (i, agent) in self.agents.iter_mut().enumerate() {
            if let Some(script) = &agent.script {
                (self.positions[i], self.velocities[i]) = script.evaluate(t_end);
                continue;
            }
            let mut t = self.t;
            let p = &mut self.positions[i];
            loop {
                let t_stop = match &agent.maneuver {
                    Some(m) => m.next_event_t.min(t_end),
                    None => t_end,
                };
                if t_stop > t {
                    self.bounce_counts[i] += integrate(agent, p, t_stop - t);
                    t = t_stop;
                }
                match &mut agent.maneuver {
                    Some(m) if m.next_event_t <= t_end => {
                        m.draw();
                        m.next_event_t += m.gap.sample(&mut m.rng);
                        self.maneuver_counts[i] += 1;
                    }
                    _ => break,
                }
            }
            self.velocities[i] = agent.dir * agent.speed;
        }
        self.t = t_end;
        Ok(())
    }
}

/// Integrates one agent over `h` under its current controls (trapezoidal position update) and
/// reflects it at its region; returns the number of reflections.
fn integrate(agent: &mut Agent, p: &mut Vec3, h: f64) -> usize {
    let v_old = agent.dir * agent.speed;
    if let Some(m) = &agent.maneuver {
        let dv = m.tangential_accel * h;
        agent.speed = if agent.speed < m.target_speed {
            (agent.speed + dv).min(m.target_speed)
        } else {
            (agent.speed - dv).max(m.target_speed)
        };
        let angle = m.turn_rate * h;
        if angle != 0.0 {
            let (s, c) = angle.sin_cos();
            let (x, y) = (agent.dir.x, agent.dir.y);
            agent.dir.x = c * x - s * y;
            agent.dir.y = s * x + c * y;
        }
    }
    let v_new = agent.dir * agent.speed;
    *p += (v_old + v_new) * (0.5 * h);
    let mut bounces = 0;
    for axis in 0..3 {
        let (x, flips) = fold(p[axis], agent.lo[axis], agent.hi[axis]);
        p[axis] = x;
        if flips % 2 == 1 {
            agent.dir[axis] = -agent.dir[axis];
        }
        bounces += flips;
    }
    bounces
}

/// Folds `x` into `[lo, hi]` by mirror reflections; returns the folded value and the number of
/// reflections (odd: the velocity component flips). A zero-width interval pins `x` to `lo`.
fn fold(x: f64, lo: f64, hi: f64) -> (f64, usize) {
    if (lo..=hi).contains(&x) {
        return (x, 0);
    }
    let span = hi - lo;
    if span <= 0.0 {
        return (lo, 0);
    }
    let u = x - lo;
    let k = (u / span).floor();
    let r = (u - k * span).clamp(0.0, span);
    let flips = k.abs() as usize;
    if (k as i64).rem_euclid(2) == 0 {
        (lo + r, flips)
    } else {
        (hi - r, flips)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fold_reflects_and_counts() {
        assert_eq!(fold(0.5, 0.0, 1.0), (0.5, 0));
        let (x, k) = fold(1.25, 0.0, 1.0);
        assert!((x - 0.75).abs() < 1e-12 && k == 1);
        let (x, k) = fold(-0.25, 0.0, 1.0);
        assert!((x - 0.25).abs() < 1e-12 && k == 1);
        let (x, k) = fold(2.25, 0.0, 1.0);
        assert!((x - 0.25).abs() < 1e-12 && k == 2);
        assert_eq!(fold(3.0, 2.0, 2.0), (2.0, 0));
    }
}
