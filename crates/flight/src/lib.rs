//! # trust-flight — the closed loop: one flight of one planner through one world, written as a run log
//!
//! The simulator's middle stage (paper Sec. IV): it takes a [`World`] built by `trust-world`,
//! assembles the planner the scenario names ([`trust_planner::build`]), flies it and writes the
//! run log of `trust-runlog`. The world and the planner meet here: [`scenario`] reads a
//! scenario file with its `[planner]` section as `trust-planner`'s spec and checks both halves. Use [`fly`] for one flight; studies and experiments
//! (`trust-experiments`) call it once per trial and planner. To drive the loop yourself (another
//! observer, a flight paused and inspected), use [`closed_loop::step`] with a [`FlightState`].
//!
//! Every `physics_dt_s` the true obstacles move ([`trust_world::traffic::Traffic`]) and the vehicle
//! integrates its dynamics toward the committed plan ([`trust_vehicle::Vehicle`]); at the sensor
//! rate the obstacles are measured with noise and dropouts into the trackers
//! ([`trust_world::sensing::Sensing`]); at the replanning rate the manager plans from the measured
//! vehicle state and the trackers' forecasts — never from the true obstacles. When its plan takes
//! effect, and whether a busy planner skips replanning ticks, is the [`Clock`]'s: a fixed latency
//! (reproducible), or real time (the cycle's measured wall time, optionally scaled, is charged;
//! `docs/decisions/0004-real-time-clock-model.md`). After every physics step the true vehicle
//! sphere is checked against the true static geometry and the true obstacles; the flight ends when
//! it collides, arrives within the goal tolerance, when the planner's verdict that the goal cannot
//! be reached has held for [`UNREACHABLE_SETTLE_S`], or when it runs out of time.
//!
//! The run log ([`trust_runlog`]) holds a `state` record at the log rate and at the last instant
//! (so a collision or arrival between two log ticks is in the log), a `cycle` record per planning
//! cycle, and the `outcome`, whose figures are computed from the logged states exactly as the
//! contract defines them.
//!
//! ```no_run
//! use std::path::{Path, PathBuf};
//! use trust_flight::scenario::{load_checked, resolve_planner};
//! use trust_flight::{RunOptions, fly};
//! use trust_world::World;
//!
//! let scenario = load_checked(Path::new("scenarios/quickstart.toml"))?;
//! let world = World::build(&scenario)?;
//! let options = RunOptions { log_path: Some(PathBuf::from("out/run.jsonl")), ..RunOptions::default() };
//! let flight = fly(&world, &resolve_planner(&scenario), &options, |_| {})?;
//! println!("{:?}", flight.summary.outcome.status);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(missing_docs)]

use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};
use trust_core::{PolyTraj, Vec3};
use trust_manager::{Event, Hit, StepReport};
use trust_planner::{AnyManager, FrontendSpec, ResolvedPlanner};
use trust_plot::quantile_sorted;
use trust_predict::{Forecast, ObstacleShape};
use trust_route::GlobalRoute;
use trust_runlog::{
    Bounds, BranchSamples, CycleRecord, Dropped, ForecastRecord, ForecastShape, Header, LimitsInfo,
    LogWriter, ObstacleInfo, ObstacleKind, Outcome, Record, SCHEMA, StateRecord, Status,
    VehicleInfo,
};
use trust_vehicle::{ControlledQuadrotor, PerfectTracking, Reference, Vehicle, VehicleState};
use trust_world::World;
use trust_world::scenario::VehicleModel;
use trust_world::sensing::Sensing;
use trust_world::traffic::{MovingShape, Traffic};

pub mod closed_loop;
mod error;
pub mod map_sensing;
pub mod scenario;
pub use closed_loop::{
    Clearances, Clock, Contact, CycleEvent, Ending, FlightObserver, FlightState, LoopParams,
    UNREACHABLE_SETTLE_S, obstacle_walls,
};
pub use error::FlightError;

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
    /// Median and 99th percentile of the cycle's own time (ms): its wall time less the time it
    /// waited for the manager's worker (fixed latency; the loop runs faster than real time, so
    /// the worker has had less than a period), or the time charged (real time).
    pub cycle_ms_median: f64,
    /// See `cycle_ms_median`.
    pub cycle_ms_p99: f64,
    /// The longest cycle's wall time (ms).
    #[serde(default)]
    pub cycle_ms_max: f64,
    /// Cycles that exceeded the manager's cycle budget (`cycle_budget_ms`): their wall time, or in
    /// the real-time mode the time charged (wall time times `cpu_scale`).
    #[serde(default)]
    pub over_budget_count: usize,
    /// Cycles that made the planner skip replanning ticks (real-time latency mode only).
    #[serde(default)]
    pub overrun_count: usize,
    /// Replanning ticks skipped in all (real-time latency mode only).
    #[serde(default)]
    pub skipped_tick_count: u64,
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
        static_shapes: world
            .static_shape_specs()
            .into_iter()
            .map(Into::into)
            .collect(),
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

/// The logged figures of a flight, accumulated state by state (the contract's definitions):
/// what the `outcome` record reports about the states. [`fly`] and the ROS 2 world
/// (`trust_ros2::dds_world`) keep one.
#[derive(Debug, Clone)]
pub struct Tally {
    /// Least static clearance so far (m; infinite before the first state or without static
    /// obstacles).
    pub min_static: f64,
    /// Least clearance to a moving obstacle so far (m; infinite likewise).
    pub min_dynamic: f64,
    /// Greatest speed so far (m/s).
    pub max_speed: f64,
    /// Greatest acceleration norm so far (m/s²).
    pub max_accel: f64,
    /// Length of the polyline through the states (m).
    pub path_length: f64,
    last_p: Option<Vec3>,
}

impl Default for Tally {
    fn default() -> Self {
        Tally::new()
    }
}

impl Tally {
    /// No state yet.
    pub fn new() -> Self {
        Tally {
            min_static: f64::INFINITY,
            min_dynamic: f64::INFINITY,
            max_speed: 0.0,
            max_accel: 0.0,
            path_length: 0.0,
            last_p: None,
        }
    }

    /// Adds the state `p`, `v`, `a` with its static and moving clearances (m).
    pub fn add(&mut self, p: &Vec3, v: &Vec3, a: &Vec3, static_c: f64, dynamic_c: f64) {
        self.min_static = self.min_static.min(static_c);
        self.min_dynamic = self.min_dynamic.min(dynamic_c);
        self.max_speed = self.max_speed.max(v.norm());
        self.max_accel = self.max_accel.max(a.norm());
        if let Some(q) = self.last_p {
            self.path_length += (p - q).norm();
        }
        self.last_p = Some(*p);
    }

    /// The outcome's static clearance: [`NO_OBSTACLE_CLEARANCE_M`] when none was met.
    pub fn min_clearance_static_m(&self) -> f64 {
        finite_or_stand_in(self.min_static)
    }

    /// The outcome's moving clearance: [`NO_OBSTACLE_CLEARANCE_M`] when none was met.
    pub fn min_clearance_dynamic_m(&self) -> f64 {
        finite_or_stand_in(self.min_dynamic)
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
    let mut manager = trust_planner::build(planner, &scenario::planner_context(world))?;
    // The scenes are built on this map: the manager's worker may read it between cycles.
    manager.share_map(world.planner_map_shared());
    sensing.update(0.0, traffic.positions())?;
    Ok(Setup {
        traffic,
        sensing,
        manager,
    })
}

/// Flies `planner` through `world` once (see the module docs): [`closed_loop::step`] until the
/// flight ends, with the run log, the cycle statistics and the forecast history as observers.
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
    let params = LoopParams::new(world, planner);
    // In real time the planner's wall-clock budgets back its work budgets, on the emulated
    // computer's clock: `cpu_scale` times slower, so its budgets are `cpu_scale` times shorter
    // on this one.
    let real_time = matches!(params.clock, Clock::RealTime { .. });
    let planner = &match params.clock {
        Clock::RealTime { cpu_scale } => real_time_planner(planner, cpu_scale),
        Clock::Fixed { .. } => planner.clone(),
    };
    let Setup {
        traffic,
        sensing,
        manager,
    } = set_up(world, planner)?;
    let hover = Reference::hover(world.start());
    // The controller keeps the commanded acceleration within the vehicle's limit unless the
    // scenario's gains say otherwise.
    let mut gains = scenario.vehicle.gains;
    gains.max_accel_m_s2 = gains.max_accel_m_s2.or(Some(scenario.vehicle.limits.a_max));
    let vehicle: Box<dyn Vehicle> = match scenario.vehicle.model {
        VehicleModel::Quadrotor => Box::new(ControlledQuadrotor::starting_on(
            scenario.vehicle.quadrotor,
            gains,
            0.0,
            &hover,
        )?),
        VehicleModel::Perfect => Box::new(PerfectTracking::new(0.0, &hover)?),
    };
    let mut state = FlightState {
        traffic,
        sensing,
        manager,
        vehicle,
        hover,
        active: None,
        pending: None,
        step: 0,
        t: 0.0,
        busy_until: 0.0,
        worker_since: None,
        unreachable_since: None,
        map_sensing: match map_sensing::MapSensing::new(world)? {
            Some(m) => Some(m.with_commit_margin(scenario::tracking_margin_m(world, planner))?),
            None => None,
        },
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
    let growth_s = planner.manager.forecast_growth();
    let mut observers = (
        Logger {
            writer,
            record: FlightRecord {
                states: Vec::new(),
                cycles: Vec::new(),
                static_clearance: Vec::new(),
                dynamic_clearance: Vec::new(),
                plans: Vec::new(),
            },
            tally: Tally::new(),
            zero_timing: options.zero_timing,
            log_branches: options.log_branches,
            real_time,
            growth_s,
            next_plan_snapshot: 0.0,
        },
        (
            CycleStats::new(params.cycle_budget_ms, real_time),
            GivenForecasts {
                given: ForecastHistory::new(),
                remember_s: 2.0 * planner.manager.horizon_s,
                growth_s,
            },
        ),
    );

    // t = 0.
    {
        let v = state.vehicle.state();
        let c = Clearances::at(world, &state.traffic, params.vehicle_radius_m, &v.p);
        observers.state(0.0, v, state.traffic.positions(), &c)?;
    }
    let walls = obstacle_walls(world);
    let mut next_progress = options.progress_every_s.unwrap_or(f64::INFINITY);
    let ending = loop {
        if let Some(ending) = closed_loop::step(&params, world, &walls, &mut state, &mut observers)?
        {
            break ending;
        }
        if state.t >= next_progress {
            progress(state.t);
            next_progress += options.progress_every_s.unwrap_or(f64::INFINITY);
        }
    };

    let (
        Logger {
            writer,
            record,
            tally,
            ..
        },
        (stats, history),
    ) = observers;
    let t = state.t;
    let (status, with, reason) = match &ending {
        Ending::Arrived => (Status::Arrived, None, None),
        Ending::Collided(contact) => (Status::Collided, Some(contact.to_string()), None),
        Ending::TimedOut => (Status::TimedOut, None, None),
        Ending::Unreachable { cause } => (Status::Unreachable, None, Some(cause.to_string())),
        Ending::Invalid { reason } => (Status::Invalid, None, Some(reason.clone())),
    };
    let forecast_warning_s = match ending {
        Ending::Collided(Contact::Obstacle(id)) => {
            state.traffic.positions().get(id).map(|centre| {
                forecast_warning(
                    &history.given,
                    id,
                    centre,
                    t,
                    params.vehicle_radius_m,
                    world.planner_map().bounds(),
                )
            })
        }
        _ => None,
    };
    let outcome = Outcome {
        status,
        t,
        flight_time_s: t,
        path_length_m: tally.path_length,
        min_clearance_static_m: tally.min_clearance_static_m(),
        min_clearance_dynamic_m: tally.min_clearance_dynamic_m(),
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
    let mut walls_ms = stats.walls_ms;
    walls_ms.sort_by(f64::total_cmp);
    let wall_s = wall_start.elapsed().as_secs_f64();
    let summary = RunSummary {
        scenario: scenario.name.clone(),
        planner: planner.label.clone(),
        seed: scenario.seed,
        cycle_count: record.cycles.len(),
        cycle_ms_median: quantile_sorted(&walls_ms, 0.5).unwrap_or(0.0),
        cycle_ms_p99: quantile_sorted(&walls_ms, 0.99).unwrap_or(0.0),
        cycle_ms_max: walls_ms.last().copied().unwrap_or(0.0),
        over_budget_count: stats.over_budget,
        overrun_count: stats.overruns,
        skipped_tick_count: stats.skipped_ticks,
        solve_ms_per_trajectory: stats.solve_ms / stats.trajectories.max(1) as f64,
        cpu_ms_per_trajectory: stats.cpu_ms / stats.trajectories.max(1) as f64,
        trajectory_count: stats.trajectories,
        fallback_count: stats.fallbacks,
        unsafe_fallback_count: stats.unsafe_fallbacks,
        switch_count: stats.switches,
        reanchor_count: stats.reanchors,
        wall_s,
        real_time_factor: outcome.t / wall_s.max(1e-9),
        log_path: options.log_path.clone(),
        outcome,
    };
    Ok(Flight { summary, record })
}

/// The run log being written and the in-memory record of the flight (an observer).
struct Logger {
    writer: Option<LogWriter>,
    record: FlightRecord,
    tally: Tally,
    zero_timing: bool,
    log_branches: bool,
    real_time: bool,
    growth_s: f64,
    next_plan_snapshot: f64,
}

impl FlightObserver for Logger {
    fn state(
        &mut self,
        t: f64,
        s: &VehicleState,
        positions: &[Vec3],
        c: &Clearances,
    ) -> Result<(), FlightError> {
        let rec = StateRecord {
            t,
            p: v3(&s.p),
            v: v3(&s.v),
            a: v3(&s.a),
            obstacles: positions.iter().map(v3).collect(),
        };
        self.tally.add(&s.p, &s.v, &s.a, c.static_m, c.dynamic_m);
        if let Some(w) = self.writer.as_mut() {
            w.write(&Record::State(rec.clone()))?;
        }
        self.record.states.push(rec);
        self.record.static_clearance.push(c.static_m);
        self.record.dynamic_clearance.push(c.dynamic_m);
        Ok(())
    }

    fn cycle(&mut self, cycle: &CycleEvent<'_>) -> Result<(), FlightError> {
        if let Some(plan) = cycle.manager.plan()
            && cycle.t >= self.next_plan_snapshot
        {
            self.record.plans.push(plan.clone());
            self.next_plan_snapshot = cycle.t + 1.0;
        }
        let mut rec = cycle_record(
            cycle.report,
            cycle.manager.route(),
            cycle.effective_t,
            self.zero_timing,
        );
        rec.map_ms = cycle
            .map_ms
            .map(|ms| if self.zero_timing { 0.0 } else { ms });
        if self.real_time {
            rec.charged_ms = Some(cycle.charged_s * 1e3);
            rec.overrun_ticks = (cycle.overrun_ticks > 0).then_some(cycle.overrun_ticks);
        }
        if self.log_branches {
            rec.branch_samples = Some(branch_samples(cycle.manager));
            rec.forecasts = Some(forecast_records(cycle.ids, cycle.forecasts, self.growth_s));
        }
        if let Some(w) = self.writer.as_mut() {
            w.write(&Record::Cycle(rec.clone()))?;
        }
        self.record.cycles.push(rec);
        Ok(())
    }
}

/// `planner` as flown in real time on a computer `cpu_scale` times slower than this one: its
/// wall-clock budgets on (not reproducible) and divided by `cpu_scale`, so that they hold on the
/// emulated computer's clock.
pub fn real_time_planner(planner: &ResolvedPlanner, cpu_scale: f64) -> ResolvedPlanner {
    let mut p = planner.clone();
    p.reproducible = false;
    p.manager.enforce_budget = true;
    p.manager.real_time_scale = Some(cpu_scale);
    p.manager.cycle_budget_ms /= cpu_scale;
    match &mut p.frontend {
        FrontendSpec::DevPrm(x) => x.budget_ms /= cpu_scale,
        FrontendSpec::VPrm(x) => x.budget_ms /= cpu_scale,
        FrontendSpec::SparseAStar(x) => x.budget_ms /= cpu_scale,
        FrontendSpec::StraightLine(_) => {}
    }
    p
}

/// The cycles' statistics for the summary (an observer).
#[derive(Debug, Clone, Default)]
struct CycleStats {
    budget_ms: f64,
    /// Cycle times are the charged time (real time) rather than the wall time less the wait
    /// for the worker.
    real_time: bool,
    /// Each cycle's own time (ms, see [`RunSummary::cycle_ms_median`]).
    walls_ms: Vec<f64>,
    solve_ms: f64,
    cpu_ms: f64,
    trajectories: usize,
    fallbacks: usize,
    unsafe_fallbacks: usize,
    switches: usize,
    reanchors: usize,
    over_budget: usize,
    overruns: usize,
    skipped_ticks: u64,
}

impl CycleStats {
    fn new(budget_ms: f64, real_time: bool) -> Self {
        CycleStats {
            budget_ms,
            real_time,
            ..CycleStats::default()
        }
    }
}

impl FlightObserver for CycleStats {
    fn cycle(&mut self, cycle: &CycleEvent<'_>) -> Result<(), FlightError> {
        let report = cycle.report;
        let timing = &report.timing;
        let spent_ms = if self.real_time {
            cycle.charged_s * 1e3
        } else {
            timing.wall_ms - timing.waited_ms
        };
        self.walls_ms.push(spent_ms);
        self.over_budget += usize::from(spent_ms > self.budget_ms);
        self.overruns += usize::from(cycle.overrun_ticks > 0);
        self.skipped_ticks += cycle.overrun_ticks;
        self.solve_ms += timing.backend_ms;
        self.cpu_ms += timing.frontend_ms + timing.backend_ms + timing.checker_ms;
        self.trajectories += timing.solve_count;
        if let Some(f) = &report.fallback {
            self.fallbacks += 1;
            self.unsafe_fallbacks += usize::from(!f.collision_free);
        }
        self.switches += usize::from(report.switched());
        self.reanchors += report
            .events
            .iter()
            .filter(|e| matches!(e, Event::Reanchored { .. }))
            .count();
        Ok(())
    }
}

/// The forecasts the planner planned against (growth stopped as its manager stops it) over the
/// last two horizons, by obstacle id, newest last (an observer): a collision's outcome says how
/// long they had the obstacle where it hit.
struct GivenForecasts {
    given: ForecastHistory,
    remember_s: f64,
    growth_s: f64,
}

impl FlightObserver for GivenForecasts {
    fn cycle(&mut self, cycle: &CycleEvent<'_>) -> Result<(), FlightError> {
        let t = cycle.t;
        self.given.push_back((
            t,
            cycle
                .ids
                .iter()
                .copied()
                .zip(
                    cycle
                        .forecasts
                        .iter()
                        .map(|f| f.with_growth_for(self.growth_s)),
                )
                .collect(),
        ));
        while self
            .given
            .front()
            .is_some_and(|(tk, _)| *tk < t - self.remember_s)
        {
            self.given.pop_front();
        }
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
        .any(|e| {
            matches!(
                e,
                Event::Rerouted { .. } | Event::RouteFailed { .. } | Event::GoalUnreachable { .. }
            )
        })
        // A slice of a search still under way.
        || report.timing.route_ms > 0.0;
    // A worker job was merged, a route slice taken back: its wall time is positive.
    let merged = report.timing.worker_ms > 0.0;
    let route_away = report.timing.route_worker_ms > 0.0;
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
        fallback_along: report.fallback.as_ref().map(|f| f.along.to_string()),
        dropped: dropped(report),
        route: route
            .filter(|_| rerouted)
            .map(|r| r.points().iter().map(v3).collect()),
        route_ms: planned.then(|| time(report.timing.route_ms)),
        branch_samples: None,
        forecasts: None,
        charged_ms: None,
        overrun_ticks: None,
        worker_ms: merged.then(|| time(report.timing.worker_ms)),
        waited_ms: (merged || route_away).then(|| time(report.timing.waited_ms)),
        route_worker_ms: route_away.then(|| time(report.timing.route_worker_ms)),
        map_ms: None,
        aim: Some(report.aim),
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
            crate::scenario::Scenario::from_toml_str(text, std::path::Path::new("r.toml")).unwrap();
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
