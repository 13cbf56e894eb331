//! # trust-flight — the closed loop: one flight of one planner through one world, written as a run log
//!
//! The simulator's middle stage (paper Sec. IV-D): it takes a [`World`] built by `trust-world`,
//! assembles the planner the scenario names ([`trust_world::planner::build`]), flies it and writes
//! the run log of `trust-runlog`. Use [`fly`] for one flight; studies and experiments
//! (`trust-experiments`) call it once per trial and planner.
//!
//!
//! Every `physics_dt_s` the true obstacles move ([`trust_world::traffic::Traffic`]) and the vehicle
//! integrates its dynamics toward the committed plan ([`trust_vehicle::Vehicle`]); at the sensor
//! rate the obstacles are measured with noise and dropouts into the trackers
//! ([`trust_world::sensing::Sensing`]); at the replanning rate the manager plans from the measured
//! vehicle state and the trackers' forecasts — never from the true obstacles — and the new plan
//! takes effect after the latency (fixed, or the cycle's measured wall time). After every physics
//! step the true vehicle sphere is checked against the true static geometry and the true
//! obstacles; the flight ends when it collides, arrives within the goal tolerance, or runs out of
//! time.
//!
//! The run log ([`trust_runlog`]) holds a `state` record at the log rate and at the last instant
//! (so a collision or arrival between two log ticks is in the log), a `cycle` record per planning
//! cycle, and the `outcome`, whose figures are computed from the logged states exactly as the
//! contract defines them.
//!
//! # Changelog
//!
//! - Issue 19: cycle records carry the route the manager planned (`route`, `route_ms`) and a
//!   fallback's shortfall (`fallback_shortfall_m`). The forecasts the manager gets carry their
//!   obstacle's region when it is not the world (`trust_predict::Forecast::walls`: the traffic
//!   turns the obstacle back at its walls), and the logged forecasts the growth stop
//!   (`ForecastRecord::growth_s`).
//! - Moved out of `trust-sim` (issue 17): `trust_sim::run::{fly, header, RunOptions, RunSummary,
//!   Flight, FlightRecord}` are at this crate's root.
//! - `trust_sim::error::SimError` is split by stage; this crate's errors are [`FlightError`]s
//!   (wrapping `trust_world::WorldError` for setup, vehicle, planner and run-log errors).
//! - Added [`set_up`] / [`Setup`]: the traffic, sensing and planner at `t = 0`, shared by [`fly`]
//!   and E3.
//! - Added (issue 20): [`RunOptions::log_branches`] writes the kept branches and the forecasts
//!   into the `cycle` records ([`BRANCH_SAMPLE_STEP_S`]).
//! - [`RunSummary::cycle_ms_median`] and `cycle_ms_p99` use `trust_plot::quantile_sorted` (the same
//!   type-7 quantile as before; still 0 without cycles).
#![warn(missing_docs)]

use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};
use trust_core::{PolyTraj, Scene, Vec3};
use trust_manager::{Event, Hit, StepReport};
use trust_plot::quantile_sorted;
use trust_route::GlobalRoute;

use trust_world::World;
use trust_world::planner::{self, AnyManager, ResolvedPlanner};
use trust_world::scenario::{Latency, VehicleModel};
use trust_world::sensing::Sensing;
use trust_world::traffic::{MovingShape, Traffic};

mod error;
pub use error::FlightError;
use trust_predict::{Forecast, ObstacleShape};
use trust_runlog::{
    Bounds, BranchSamples, CycleRecord, Dropped, ForecastRecord, ForecastShape, Header, LimitsInfo,
    LogWriter, ObstacleInfo, ObstacleKind, Outcome, Record, SCHEMA, StateRecord, Status,
    VehicleInfo,
};
use trust_vehicle::{ControlledQuadrotor, PerfectTracking, Reference, Vehicle};

/// Stand-in for "no obstacle of this kind" in the outcome's clearances (JSON has no infinity).
pub const NO_OBSTACLE_CLEARANCE_M: f64 = 1e9;

/// How to run a flight.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RunOptions {
    /// Write the run log here (`None`: keep nothing on disk; the summary is still returned).
    pub log_path: Option<PathBuf>,
    /// Write zeros instead of measured times in the log's `cycle` records, so that two runs with
    /// the same seed give byte-identical logs (the timing fields are the only machine-dependent
    /// part of a log with a fixed latency).
    pub zero_timing: bool,
    /// Report progress (simulated seconds) to this callback every simulated second.
    pub progress_every_s: Option<f64>,
    /// Write the kept branches (sampled every [`BRANCH_SAMPLE_STEP_S`]) and the cycle's forecasts
    /// into every `cycle` record (`branch_samples`, `forecasts`). The scenario's `[log] branches`
    /// and `trust-sim run --log-branches` decide; off by default.
    pub log_branches: bool,
}

/// Time between two logged samples of a branch (s): 5 per second, enough to draw a trajectory
/// that turns at most a few times per second, and about 4 numbers × 5 per second of horizon per
/// branch in the log.
pub const BRANCH_SAMPLE_STEP_S: f64 = 0.2;

/// What one flight did: the outcome and statistics of its planning cycles.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunSummary {
    /// Scenario name.
    pub scenario: String,
    /// Planner label.
    pub planner: String,
    /// Trial seed.
    pub seed: u64,
    /// The outcome record.
    pub outcome: Outcome,
    /// Planning cycles.
    pub cycle_count: usize,
    /// Median and 99th percentile of the cycle wall time (ms).
    pub cycle_ms_median: f64,
    /// See `cycle_ms_median`.
    pub cycle_ms_p99: f64,
    /// Mean solve time per optimized trajectory (ms).
    pub solve_ms_per_trajectory: f64,
    /// Mean CPU time per optimized trajectory, frontend and checks included (ms): the paper's
    /// "CPU time per trajectory".
    pub cpu_ms_per_trajectory: f64,
    /// Trajectories optimized in the whole flight.
    pub trajectory_count: usize,
    /// Cycles that ended in a braking fallback.
    pub fallback_count: usize,
    /// Fallbacks that were not collision-free under the forecasts.
    pub unsafe_fallback_count: usize,
    /// Main-branch switches.
    pub switch_count: usize,
    /// Re-anchorings on the measured state.
    pub reanchor_count: usize,
    /// Wall-clock time of the whole flight, simulation included (s).
    pub wall_s: f64,
    /// Simulated seconds per wall-clock second.
    pub real_time_factor: f64,
    /// The run log, if written.
    pub log_path: Option<PathBuf>,
}

/// Everything kept in memory about a flight for plots and reports.
#[derive(Debug, Clone, PartialEq)]
pub struct FlightRecord {
    /// The logged states.
    pub states: Vec<StateRecord>,
    /// The cycle records.
    pub cycles: Vec<CycleRecord>,
    /// Static clearance at each logged state (m).
    pub static_clearance: Vec<f64>,
    /// Dynamic clearance at each logged state (m).
    pub dynamic_clearance: Vec<f64>,
    /// The committed plan at a few instants (every second), for plots.
    pub plans: Vec<PolyTraj>,
}

/// The result of [`fly`].
#[derive(Debug, Clone, PartialEq)]
pub struct Flight {
    /// The summary.
    pub summary: RunSummary,
    /// The in-memory record.
    pub record: FlightRecord,
}

fn v3(v: &Vec3) -> [f64; 3] {
    [v.x, v.y, v.z]
}

/// The run-log header for a flight of `planner_label` through `world`; `points_file` is the
/// header's `static_points_file` (relative to the log's folder).
pub fn header(world: &World, planner_label: &str, points_file: Option<String>) -> Header {
    let s = world.scenario();
    let b = world.bounds();
    Header {
        schema: SCHEMA.to_string(),
        scenario: s.name.clone(),
        seed: s.seed,
        planner: planner_label.to_string(),
        bounds: Bounds {
            min: v3(&b.min),
            max: v3(&b.max),
        },
        vehicle: VehicleInfo {
            radius: world.vehicle_radius_m(),
            model: Some(
                match s.vehicle.model {
                    VehicleModel::Quadrotor => "se3-quadrotor",
                    VehicleModel::Perfect => "perfect-tracking",
                }
                .to_string(),
            ),
        },
        limits: LimitsInfo {
            v_max: world.limits().v_max,
            a_max: world.limits().a_max,
        },
        start: v3(&world.start()),
        goal: v3(&world.goal()),
        goal_tolerance: s.mission.goal_tolerance_m,
        static_shapes: world.static_shape_specs(),
        static_points_file: points_file,
        obstacles: world
            .obstacles()
            .iter()
            .enumerate()
            .map(|(id, o)| match o.shape {
                MovingShape::Sphere { radius } => ObstacleInfo {
                    id,
                    shape: ObstacleKind::Sphere,
                    radius,
                    half_height: None,
                    half_extents: None,
                },
                MovingShape::Cylinder {
                    radius,
                    half_height,
                } => ObstacleInfo {
                    id,
                    shape: ObstacleKind::Cylinder,
                    radius,
                    half_height: Some(half_height),
                    half_extents: None,
                },
                MovingShape::Box { half_extents } => ObstacleInfo {
                    id,
                    shape: ObstacleKind::Box,
                    radius: o.shape.radius(),
                    half_height: None,
                    half_extents: Some(half_extents),
                },
            })
            .collect(),
        sim: serde_json::to_value(&s.sim).ok(),
    }
}

/// The logged figures of a flight, accumulated state by state (the contract's definitions).
#[derive(Debug, Clone)]
struct Tally {
    min_static: f64,
    min_dynamic: f64,
    max_speed: f64,
    max_accel: f64,
    path_length: f64,
    last_p: Option<Vec3>,
}

impl Tally {
    fn new() -> Self {
        Tally {
            min_static: f64::INFINITY,
            min_dynamic: f64::INFINITY,
            max_speed: 0.0,
            max_accel: 0.0,
            path_length: 0.0,
            last_p: None,
        }
    }

    fn add(&mut self, p: &Vec3, v: &Vec3, a: &Vec3, static_c: f64, dynamic_c: f64) {
        self.min_static = self.min_static.min(static_c);
        self.min_dynamic = self.min_dynamic.min(dynamic_c);
        self.max_speed = self.max_speed.max(v.norm());
        self.max_accel = self.max_accel.max(a.norm());
        if let Some(q) = self.last_p {
            self.path_length += (p - q).norm();
        }
        self.last_p = Some(*p);
    }
}

fn finite_or_stand_in(x: f64) -> f64 {
    if x.is_finite() {
        x
    } else {
        NO_OBSTACLE_CLEARANCE_M
    }
}

/// The parts of a flight at `t = 0`, before the first planning cycle: the traffic, the sensing
/// (already updated with the traffic's positions at `t = 0`) and the planner built for `world`.
/// [`fly`] starts from it, and so does E3's single cold cycle.
pub struct Setup {
    /// The moving obstacles at `t = 0`.
    pub traffic: Traffic,
    /// The sensing, updated at `t = 0`.
    pub sensing: Sensing,
    /// The planner, built for `world`.
    pub manager: AnyManager,
}

/// Sets up a flight of `planner` through `world` (see [`Setup`]).
///
/// # Errors
/// [`FlightError`] for traffic, sensing or a planner that cannot be set up for `world`.
pub fn set_up(world: &World, planner: &ResolvedPlanner) -> Result<Setup, FlightError> {
    let traffic = world.traffic()?;
    let mut sensing = world.sensing()?;
    let manager = planner::build(planner, &world.planner_context())?;
    sensing.update(0.0, traffic.positions())?;
    Ok(Setup {
        traffic,
        sensing,
        manager,
    })
}

/// Flies `planner` through `world` once (see the module docs).
///
/// # Errors
/// [`FlightError`] for a world or planner that cannot be set up, or a log that cannot be written.
/// A planner that rejects its input mid-flight is not an error: the outcome is `invalid` with
/// the reason.
pub fn fly(
    world: &World,
    planner: &ResolvedPlanner,
    options: &RunOptions,
    mut progress: impl FnMut(f64),
) -> Result<Flight, FlightError> {
    let wall_start = Instant::now();
    let scenario = world.scenario();
    let sim = &scenario.sim;
    let dt = sim.physics_dt_s;
    let steps_per = |rate_hz: f64| ((1.0 / rate_hz) / dt).round().max(1.0) as u64;
    let replan_steps = steps_per(sim.replan_rate_hz);
    let log_steps = steps_per(sim.log_rate_hz);
    let max_steps = (scenario.time_limit_s / dt).ceil() as u64;
    let radius = world.vehicle_radius_m();
    let (start, goal) = (world.start(), world.goal());
    let tolerance = scenario.mission.goal_tolerance_m;

    let Setup {
        mut traffic,
        mut sensing,
        mut manager,
    } = set_up(world, planner)?;
    let hover = Reference::hover(start);
    // The controller keeps the commanded acceleration within the vehicle's limit unless the
    // scenario's gains say otherwise.
    let mut gains = scenario.vehicle.gains;
    gains.max_accel_m_s2 = gains.max_accel_m_s2.or(Some(scenario.vehicle.limits.a_max));
    let mut vehicle: Box<dyn Vehicle> = match scenario.vehicle.model {
        VehicleModel::Quadrotor => Box::new(ControlledQuadrotor::starting_on(
            scenario.vehicle.quadrotor,
            gains,
            0.0,
            &hover,
        )?),
        VehicleModel::Perfect => Box::new(PerfectTracking::new(0.0, &hover)?),
    };
    let fixed_latency = match sim.latency {
        Latency::Fixed { seconds } => Some(seconds.unwrap_or(planner.manager.latency())),
        Latency::Measured {} => None,
    };

    let writer = match &options.log_path {
        Some(path) => {
            let points_file = match world.static_points_file() {
                Some(src) => {
                    let dir = path.parent().unwrap_or(Path::new("."));
                    let name = "static_points.xyz";
                    std::fs::copy(src, dir.join(name)).map_err(|source| FlightError::Write {
                        path: dir.join(name),
                        source,
                    })?;
                    Some(name.to_string())
                }
                None => None,
            };
            let mut w = LogWriter::create(path)?;
            w.write(&Record::Header(header(world, &planner.label, points_file)))?;
            Some(w)
        }
        None => None,
    };

    let mut log = Logger {
        writer,
        record: FlightRecord {
            states: Vec::new(),
            cycles: Vec::new(),
            static_clearance: Vec::new(),
            dynamic_clearance: Vec::new(),
            plans: Vec::new(),
        },
        tally: Tally::new(),
    };

    let clearances = |p: &Vec3, traffic: &trust_world::traffic::Traffic| {
        let static_c = world.true_static_clearance(p) - radius;
        let (d, id) = traffic.clearance(p);
        (static_c, d - radius, id)
    };

    // t = 0.
    {
        let (sc, dc, _) = clearances(&vehicle.state().p, &traffic);
        log.state(0.0, vehicle.as_ref(), traffic.positions(), sc, dc)?;
    }

    let mut active: Option<PolyTraj> = None;
    let mut pending: Option<(f64, PolyTraj)> = None;
    let mut cycle_walls = Vec::new();
    let (mut solve_ms, mut cpu_ms, mut trajectories) = (0.0, 0.0, 0usize);
    let (mut fallbacks, mut unsafe_fallbacks, mut switches, mut reanchors) = (0, 0, 0, 0);
    let mut ended: Option<(Status, Option<String>, Option<String>)> = None;
    let mut next_progress = options.progress_every_s.unwrap_or(f64::INFINITY);
    let mut next_plan_snapshot = 0.0;
    // The forecasts the planner planned against (growth stopped as its manager stops it) over
    // the last two horizons, by obstacle id, newest last: a collision's outcome says how long
    // they had the obstacle where it hit.
    let mut given = ForecastHistory::new();
    let remember_s = 2.0 * planner.manager.horizon_s;
    let growth_s = planner.manager.forecast_growth();
    let regions = obstacle_walls(world);
    let mut step = 0u64;
    let mut t = 0.0;
    while ended.is_none() {
        // Plan.
        if step.is_multiple_of(replan_steps) {
            // Each forecast knows the box its obstacle stays inside when that is not the map
            // (a scenario's obstacle region, where the traffic turns it back).
            let ids = sensing.tracked_ids();
            let forecasts: Vec<Forecast> = sensing
                .forecasts(t)?
                .into_iter()
                .zip(&ids)
                .map(|(f, &id)| match regions.get(id).copied().flatten() {
                    Some(region) => f.with_walls(region),
                    None => f,
                })
                .collect();
            given.push_back((
                t,
                ids.iter()
                    .copied()
                    .zip(forecasts.iter().map(|f| f.with_growth_for(growth_s)))
                    .collect(),
            ));
            while given.front().is_some_and(|(tk, _)| *tk < t - remember_s) {
                given.pop_front();
            }
            let scene = Scene::new(world.planner_map(), &forecasts, t)?;
            let measured = vehicle.state().kinematic();
            let cycle_start = Instant::now();
            match manager.step(t, &measured, &goal, &scene) {
                Ok(report) => {
                    let wall = cycle_start.elapsed().as_secs_f64();
                    let latency = fixed_latency.unwrap_or(wall);
                    let effective = t + (latency / dt).ceil() * dt;
                    if let Some(plan) = manager.plan() {
                        pending = Some((effective, plan.clone()));
                        if t >= next_plan_snapshot {
                            log.record.plans.push(plan.clone());
                            next_plan_snapshot = t + 1.0;
                        }
                    }
                    cycle_walls.push(report.timing.wall_ms);
                    solve_ms += report.timing.backend_ms;
                    cpu_ms += report.timing.frontend_ms
                        + report.timing.backend_ms
                        + report.timing.checker_ms;
                    trajectories += report.timing.solve_count;
                    if let Some(f) = &report.fallback {
                        fallbacks += 1;
                        if !f.collision_free {
                            unsafe_fallbacks += 1;
                        }
                    }
                    switches += usize::from(report.switched());
                    reanchors += report
                        .events
                        .iter()
                        .filter(|e| matches!(e, trust_manager::Event::Reanchored { .. }))
                        .count();
                    let mut record =
                        cycle_record(&report, manager.route(), effective, options.zero_timing);
                    if options.log_branches {
                        record.branch_samples = Some(branch_samples(&manager));
                        record.forecasts = Some(forecast_records(&ids, &forecasts, growth_s));
                    }
                    log.cycle(record)?;
                }
                Err(e) => {
                    ended = Some((Status::Invalid, None, Some(e.to_string())));
                    break;
                }
            }
        }
        if let Some((te, _)) = &pending
            && t + 0.5 * dt >= *te
        {
            active = pending.take().map(|(_, p)| p);
        }

        // Physics.
        let reference = |tau: f64| match &active {
            Some(plan) => Reference::from_traj(plan, tau, 0.0),
            None => hover,
        };
        vehicle.step(dt, &reference)?;
        traffic.step(dt)?;
        step += 1;
        t = step as f64 * dt;

        // Checks.
        let p = vehicle.state().p;
        let (sc, dc, id) = clearances(&p, &traffic);
        if sc < 0.0 || dc < 0.0 {
            let with = if sc <= dc {
                "static".to_string()
            } else {
                format!("obstacle:{}", id.unwrap_or(0))
            };
            ended = Some((Status::Collided, Some(with), None));
        } else if (p - goal).norm() <= tolerance {
            ended = Some((Status::Arrived, None, None));
        } else if step >= max_steps {
            ended = Some((Status::TimedOut, None, None));
        }
        if ended.is_some() || step.is_multiple_of(log_steps) {
            log.state(t, vehicle.as_ref(), traffic.positions(), sc, dc)?;
        }
        sensing.update(t, traffic.positions())?;
        if t >= next_progress {
            progress(t);
            next_progress += options.progress_every_s.unwrap_or(f64::INFINITY);
        }
    }

    let Logger {
        writer,
        record,
        tally,
    } = log;
    let (status, with, reason) = ended.unwrap_or((Status::Invalid, None, None));
    let forecast_warning_s = with
        .as_deref()
        .and_then(|w| w.strip_prefix("obstacle:"))
        .and_then(|id| id.parse::<usize>().ok())
        .and_then(|id| {
            let centre = traffic.positions().get(id).copied()?;
            Some(forecast_warning(
                &given,
                id,
                &centre,
                t,
                radius,
                world.planner_map().bounds(),
            ))
        });
    let outcome = Outcome {
        status,
        t,
        flight_time_s: t,
        path_length_m: tally.path_length,
        min_clearance_static_m: finite_or_stand_in(tally.min_static),
        min_clearance_dynamic_m: finite_or_stand_in(tally.min_dynamic),
        max_speed: tally.max_speed,
        max_accel: tally.max_accel,
        with,
        reason,
        cycle_count: record.cycles.len(),
        forecast_warning_s,
    };
    if let Some(mut w) = writer {
        w.write(&Record::Outcome(outcome.clone()))?;
        w.finish()?;
    }
    let mut walls = cycle_walls;
    walls.sort_by(f64::total_cmp);
    let wall_s = wall_start.elapsed().as_secs_f64();
    let summary = RunSummary {
        scenario: scenario.name.clone(),
        planner: planner.label.clone(),
        seed: scenario.seed,
        cycle_count: record.cycles.len(),
        cycle_ms_median: quantile_sorted(&walls, 0.5).unwrap_or(0.0),
        cycle_ms_p99: quantile_sorted(&walls, 0.99).unwrap_or(0.0),
        solve_ms_per_trajectory: solve_ms / trajectories.max(1) as f64,
        cpu_ms_per_trajectory: cpu_ms / trajectories.max(1) as f64,
        trajectory_count: trajectories,
        fallback_count: fallbacks,
        unsafe_fallback_count: unsafe_fallbacks,
        switch_count: switches,
        reanchor_count: reanchors,
        wall_s,
        real_time_factor: outcome.t / wall_s.max(1e-9),
        log_path: options.log_path.clone(),
        outcome,
    };
    Ok(Flight { summary, record })
}

/// The run log being written and the in-memory record of the flight.
struct Logger {
    writer: Option<LogWriter>,
    record: FlightRecord,
    tally: Tally,
}

impl Logger {
    fn state(
        &mut self,
        t: f64,
        vehicle: &dyn Vehicle,
        positions: &[Vec3],
        static_c: f64,
        dynamic_c: f64,
    ) -> Result<(), FlightError> {
        let s = vehicle.state();
        let rec = StateRecord {
            t,
            p: v3(&s.p),
            v: v3(&s.v),
            a: v3(&s.a),
            obstacles: positions.iter().map(v3).collect(),
        };
        self.tally.add(&s.p, &s.v, &s.a, static_c, dynamic_c);
        if let Some(w) = self.writer.as_mut() {
            w.write(&Record::State(rec.clone()))?;
        }
        self.record.states.push(rec);
        self.record.static_clearance.push(static_c);
        self.record.dynamic_clearance.push(dynamic_c);
        Ok(())
    }

    fn cycle(&mut self, rec: CycleRecord) -> Result<(), FlightError> {
        if let Some(w) = self.writer.as_mut() {
            w.write(&Record::Cycle(rec.clone()))?;
        }
        self.record.cycles.push(rec);
        Ok(())
    }
}

fn cycle_record(
    report: &StepReport,
    route: Option<&GlobalRoute>,
    effective_t: f64,
    zero_timing: bool,
) -> CycleRecord {
    let time = |x: f64| if zero_timing { 0.0 } else { x };
    let rerouted = report
        .events
        .iter()
        .any(|e| matches!(e, Event::Rerouted { .. }));
    let planned = report
        .events
        .iter()
        .any(|e| matches!(e, Event::Rerouted { .. } | Event::RouteFailed { .. }));
    CycleRecord {
        t: report.t,
        wall_ms: time(report.timing.wall_ms),
        main: report.main,
        branches: report.branches.len(),
        events: report.event_tags().iter().map(|s| s.to_string()).collect(),
        frontend_ms: time(report.timing.frontend_ms),
        backend_ms: time(report.timing.backend_ms),
        checker_ms: time(report.timing.checker_ms),
        solve_count: report.timing.solve_count,
        effective_t,
        branch_j: report.branches.iter().map(|b| b.j).collect(),
        fallback_collision_free: report.fallback.as_ref().map(|f| f.collision_free),
        fallback_shortfall_m: report
            .fallback
            .as_ref()
            .filter(|f| !f.collision_free)
            .map(|f| f.shortfall_m),
        fallback_along: report.fallback.as_ref().map(|f| f.along.clone()),
        dropped: dropped(report),
        route: route
            .filter(|_| rerouted)
            .map(|r| r.points().iter().map(v3).collect()),
        route_ms: planned.then(|| time(report.timing.route_ms)),
        branch_samples: None,
        forecasts: None,
    }
}

/// The manager's kept branches after a cycle, main branch first, then the others in ranking
/// order, each sampled every [`BRANCH_SAMPLE_STEP_S`] from its start to its end (both included).
fn branch_samples(manager: &AnyManager) -> Vec<BranchSamples> {
    let main = manager.main();
    let ordered = manager
        .branches()
        .iter()
        .filter(|b| Some(b.id) == main)
        .chain(manager.branches().iter().filter(|b| Some(b.id) != main));
    ordered
        .map(|b| {
            let traj = b.traj();
            let (t0, t1) = (traj.t_start(), traj.t_end());
            let n = ((t1 - t0) / BRANCH_SAMPLE_STEP_S).ceil().max(1.0) as usize;
            let samples = (0..=n)
                .map(|k| {
                    let t = if k == n {
                        t1
                    } else {
                        t0 + k as f64 * BRANCH_SAMPLE_STEP_S
                    };
                    let p = traj.position(t);
                    [t, p.x, p.y, p.z]
                })
                .collect();
            BranchSamples { id: b.id, samples }
        })
        .collect()
}

/// By obstacle, the box it is known to stay inside when that is not the map: the region of a
/// moving obstacle that the traffic turns back at its walls ([`Forecast::walls`]). `None` for
/// an obstacle whose region is the world and for scripted ones (a script does not reflect).
fn obstacle_walls(world: &World) -> Vec<Option<trust_predict::Aabb>> {
    world
        .obstacles()
        .iter()
        .map(|o| (!o.motion.is_scripted() && o.region != *world.bounds()).then_some(o.region))
        .collect()
}

/// Forecasts by cycle: (cycle time, forecasts by obstacle id), oldest first.
type ForecastHistory = std::collections::VecDeque<(f64, Vec<(usize, Forecast)>)>;

/// How long before `t_contact` the forecasts of obstacle `id` in `given` (time, forecasts by
/// id; oldest first) have all had its true centre `centre` at contact within their uncertainty
/// (`inflation − vehicle radius`), counting their wall images ([`Outcome::forecast_warning_s`]).
fn forecast_warning(
    given: &ForecastHistory,
    id: usize,
    centre: &Vec3,
    t_contact: f64,
    vehicle_radius: f64,
    walls: &trust_predict::Aabb,
) -> f64 {
    let holds = |f: &Forecast| {
        let within = |g: &Forecast| {
            (centre - g.center(t_contact)).norm() <= g.inflation(t_contact) - vehicle_radius
        };
        within(f)
            || trust_predict::wall_images(f, f.walls.as_ref().unwrap_or(walls), f.t0, t_contact)
                .iter()
                .any(within)
    };
    let mut since = t_contact;
    for (tk, forecasts) in given.iter().rev() {
        match forecasts.iter().find(|(i, _)| *i == id) {
            Some((_, f)) if holds(f) => since = *tk,
            _ => break,
        }
    }
    t_contact - since
}

/// The cycle's forecasts as logged: as sensed, with the growth stop the manager applies to them
/// before planning (`growth_s`, absent when they grow for ever) and the region whose walls the
/// manager mirrors them at (`walls`, absent at the world's bounds).
fn forecast_records(ids: &[usize], forecasts: &[Forecast], growth_s: f64) -> Vec<ForecastRecord> {
    ids.iter()
        .zip(forecasts)
        .map(|(&id, f)| ForecastRecord {
            id,
            p0: v3(&f.p0),
            v0: v3(&f.v0),
            t0: f.t0,
            r0: f.radius(f.t0),
            mu: f.mu,
            shape: match f.shape {
                ObstacleShape::Sphere => ForecastShape::Sphere,
                ObstacleShape::Cylinder { .. } => ForecastShape::Cylinder {
                    half_height: f.vertical_half_extent(f.t0),
                },
            },
            growth_s: growth_s.is_finite().then_some(growth_s),
            walls: f.walls.as_ref().map(|w| [v3(&w.min), v3(&w.max)]),
        })
        .collect()
}

/// Counts the cycle's safety drops by cause.
fn dropped(report: &StepReport) -> Dropped {
    let mut out = Dropped::default();
    for event in &report.events {
        if let Event::DroppedCollision {
            violation,
            braking_tail,
            ..
        } = event
        {
            out.braking_tail += usize::from(*braking_tail);
            match violation.map(|v| v.with) {
                Some(Hit::Static) => out.static_map += 1,
                Some(Hit::Obstacle(_)) => out.moving += 1,
                Some(Hit::Bounds) => out.bounds += 1,
                None => out.limits += 1,
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use trust_predict::Aabb;

    /// A ball (radius 0.2 m, `r_safe` 0.3 m for a 0.1 m vehicle, growth 0.5 m/s) forecast at
    /// every 0.1 s from `t0 = 0` on, walking +x at 1 m/s from x = 1 (forecast velocity `v`).
    fn given(v: f64, until: f64) -> ForecastHistory {
        (0..=(until * 10.0).round() as usize)
            .map(|k| {
                let t = k as f64 * 0.1;
                let f = Forecast::new(
                    ObstacleShape::Sphere,
                    Vec3::new(1.0 + t, 5.0, 5.0),
                    Vec3::new(v, 0.0, 0.0),
                    t,
                    0.2,
                    0.3,
                    0.5,
                )
                .unwrap();
                (t, vec![(3, f)])
            })
            .collect()
    }

    fn walls() -> Aabb {
        Aabb::new(Vec3::zeros(), Vec3::new(100.0, 10.0, 10.0)).unwrap()
    }

    #[test]
    fn forecasts_know_the_region_their_obstacle_turns_back_in() {
        let text = "name = \"regions\"\n[world]\nbounds = { min = [0, 0, 0], max = [60, 20, 10] }\n\
            [mission]\nstart = [2, 10, 5]\ngoal = [58, 10, 5]\n\
            [[random_obstacles]]\ncount = 2\nspeed_m_s = [0.5, 1.0]\nregion = { min = [8, 0, 0], max = [52, 20, 10] }\n\
            [[random_obstacles]]\ncount = 1\nspeed_m_s = [0.5, 1.0]\n\
            [[obstacles]]\nshape = \"sphere\"\nradius_m = 0.5\nposition = [30, 5, 5]\nvelocity = [0, 1, 0]\n";
        let s =
            trust_world::scenario::Scenario::from_toml_str(text, std::path::Path::new("r.toml"))
                .unwrap();
        let world = World::build(&s).unwrap();
        let walls = obstacle_walls(&world);
        let region = Aabb::new(Vec3::new(8.0, 0.0, 0.0), Vec3::new(52.0, 20.0, 10.0)).unwrap();
        assert_eq!(walls.len(), 4);
        assert_eq!(walls.iter().filter(|w| **w == Some(region)).count(), 2);
        assert_eq!(walls.iter().filter(|w| w.is_none()).count(), 2);
    }

    #[test]
    fn logged_forecasts_carry_their_region_and_growth_stop() {
        let f = given(1.0, 0.0)[0].1[0].1;
        let region = Aabb::new(Vec3::new(2.0, 0.0, 0.0), Vec3::new(8.0, 6.0, 3.0)).unwrap();
        let records = forecast_records(&[4, 7], &[f.with_walls(region), f], 1.0);
        assert_eq!(records[0].id, 4);
        assert_eq!(records[0].walls, Some([[2.0, 0.0, 0.0], [8.0, 6.0, 3.0]]));
        assert_eq!(records[0].growth_s, Some(1.0));
        assert_eq!(records[1].walls, None);
        let grows = forecast_records(&[4], &[f], f64::INFINITY);
        assert_eq!(grows[0].growth_s, None);
    }

    /// The warning for obstacle `id` truly at `(x, 5, 5)` at contact time 2 s, far from walls.
    fn warning(given: &ForecastHistory, id: usize, x: f64) -> f64 {
        forecast_warning(given, id, &Vec3::new(x, 5.0, 5.0), 2.0, 0.1, &walls())
    }

    #[test]
    fn a_forecast_that_held_gives_the_whole_history_as_warning() {
        // The ball walks as forecast: at contact (t = 2, x = 3) every forecast had it.
        let w = warning(&given(1.0, 2.0), 3, 3.0);
        assert!((w - 2.0).abs() < 1e-9, "{w}");
    }

    #[test]
    fn an_obstacle_outside_its_last_forecast_gives_no_warning() {
        // Forecast standing still, true ball 2 m away from the last forecast's centre.
        let w = warning(&given(0.0, 2.0), 3, 5.0);
        assert_eq!(w, 0.0);
        // Another obstacle's id: no forecast of it, no warning.
        let w = warning(&given(1.0, 2.0), 4, 3.0);
        assert_eq!(w, 0.0);
    }

    #[test]
    fn the_warning_counts_only_the_forecasts_that_had_it() {
        // Forecasts standing still: the one issued at t_k misses the ball at contact by
        // 2 − t_k against an uncertainty 0.2 + 0.5·(2 − t_k), so only those from t_k = 1.6 on
        // have it.
        let w = warning(&given(0.0, 2.0), 3, 3.0);
        assert!((w - 0.4).abs() < 1e-9, "{w}");
    }

    #[test]
    fn a_forecast_reflected_at_a_wall_counts_by_its_image() {
        // The last forecast (t = 1.5, at x = 2.5) says the ball keeps walking +x; the true ball
        // turns at the wall x = 4 (its centre at 3.8) and is 2.5 s later where only the mirror
        // image of the forecast is.
        let walls = Aabb::new(Vec3::zeros(), Vec3::new(4.0, 10.0, 10.0)).unwrap();
        let mut g = given(1.0, 1.5);
        g.retain(|(t, _)| *t >= 1.5);
        let t_c = 4.0;
        let straight = 2.5 + (t_c - 1.5);
        let reflected = 2.0 * (4.0 - 0.2) - straight;
        let w = forecast_warning(&g, 3, &Vec3::new(reflected, 5.0, 5.0), t_c, 0.1, &walls);
        assert!((w - 2.5).abs() < 1e-9, "{w}");
        // Without the walls in the way, the same point is far outside the forecast.
        let open = Aabb::new(Vec3::zeros(), Vec3::new(100.0, 10.0, 10.0)).unwrap();
        let w = forecast_warning(&g, 3, &Vec3::new(reflected, 5.0, 5.0), t_c, 0.1, &open);
        assert_eq!(w, 0.0);
    }
}
