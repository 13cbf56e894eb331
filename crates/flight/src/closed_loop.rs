//! The closed loop as a step: [`LoopParams`] (fixed for a flight), [`FlightState`] (everything
//! a flight changes) and [`step`], which advances the flight by one physics step and reports to a
//! [`FlightObserver`] (rapier's `PhysicsPipeline::step` is the model: every piece of state it
//! touches is an argument, the observers are `&mut dyn` with a no-op `()`).
//!
//! The clock model is in one place, [`Clock`]:
//!
//! * [`Clock::Fixed`] — a cycle's plan takes effect a fixed latency after the cycle's start and
//!   the next cycle starts at the next replanning tick, however long the cycle took. The log is
//!   a function of the seed alone (byte-identical with zeroed timing fields).
//! * [`Clock::RealTime`] — the planner is busy from a cycle's start for the cycle's measured wall
//!   time times `cpu_scale`; its plan takes effect when it finishes (not before the instant it was
//!   planned from, the manager's latency), the next cycle starts at the first replanning tick
//!   after that, and the ticks in between are skipped: the cycle's `overrun_ticks`.

use trust_core::{PolyTraj, Scene, Vec3};
use trust_manager::{CycleTiming, StepReport, UnreachableCause};
use trust_planner::{AnyManager, ResolvedPlanner};
use trust_predict::Forecast;
use trust_vehicle::{Reference, Vehicle, VehicleState};
use trust_world::World;
use trust_world::scenario::Latency;
use trust_world::sensing::Sensing;
use trust_world::traffic::Traffic;

use crate::FlightError;
use crate::map_sensing::MapSensing;
use std::sync::Arc;

/// When a cycle's plan takes effect and when the next cycle may start (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Clock {
    /// A fixed latency (s) after the cycle's start; cycles start at every replanning tick.
    Fixed {
        /// The latency (s).
        latency_s: f64,
    },
    /// The cycle's measured wall time times `cpu_scale`; a busy planner skips ticks.
    RealTime {
        /// The factor on the measured time (3: an onboard computer three times slower).
        cpu_scale: f64,
    },
}

impl Clock {
    /// The clock a scenario's `sim.latency` names; `manager_latency_s` is the manager's own
    /// (`ManagerParams::latency`), the fixed latency when the scenario gives none.
    pub fn from_latency(latency: Latency, manager_latency_s: f64) -> Self {
        match latency {
            Latency::Fixed { seconds } => Clock::Fixed {
                latency_s: seconds.unwrap_or(manager_latency_s),
            },
            Latency::Measured { cpu_scale } => Clock::RealTime {
                cpu_scale: cpu_scale.unwrap_or(1.0),
            },
        }
    }

    /// The time (s) the planner is charged for a cycle whose wall time was `wall_ms`.
    pub fn charged_s(&self, wall_ms: f64) -> f64 {
        match *self {
            Clock::Fixed { latency_s } => latency_s,
            Clock::RealTime { cpu_scale } => wall_ms.max(0.0) * 1e-3 * cpu_scale,
        }
    }
}

/// The time (s) the planner is charged for a cycle at `t` with `timing`
/// ([`Clock::charged_s`]). In real time, the time the cycle waited for the manager's worker is
/// not charged (a flight in real time would not have waited for a job done by then) but the
/// worker's lateness is: the job started at `worker_since` and ran `worker_ms` (scaled by
/// `cpu_scale`, on a core of its own), so its results were ready no earlier than that. A route
/// slice done between cycles is not waited for: the manager takes its answer only once it is
/// due ([`trust_manager::ManagerParams::real_time_scale`]).
pub fn charged_for(clock: Clock, timing: &CycleTiming, worker_since: Option<f64>, t: f64) -> f64 {
    match clock {
        Clock::Fixed { .. } => clock.charged_s(timing.wall_ms),
        Clock::RealTime { cpu_scale } => {
            let own = clock.charged_s(timing.wall_ms - timing.waited_ms);
            let late = worker_since
                .filter(|_| timing.worker_ms > 0.0)
                .map_or(0.0, |since| {
                    (since + timing.worker_ms * 1e-3 * cpu_scale - t).max(0.0)
                });
            own + late
        }
    }
}

/// What a flight keeps fixed: the clocks, the goal and when it ends.
#[derive(Debug, Clone, PartialEq)]
pub struct LoopParams {
    /// Physics (and control) step (s).
    pub dt_s: f64,
    /// Physics steps per replanning period.
    pub replan_steps: u64,
    /// Physics steps per logged state.
    pub log_steps: u64,
    /// The flight times out after this many physics steps.
    pub max_steps: u64,
    /// The mission's goal.
    pub goal: Vec3,
    /// Arrival: the vehicle centre within this distance of the goal (m).
    pub goal_tolerance_m: f64,
    /// The vehicle's radius (m), for the clearances.
    pub vehicle_radius_m: f64,
    /// The clock model.
    pub clock: Clock,
    /// The latency the manager plans for (s): a plan starts this long after its cycle, and
    /// never takes effect before that.
    pub manager_latency_s: f64,
    /// The manager's cycle budget (ms): a cycle longer than this is counted as over budget.
    pub cycle_budget_ms: f64,
    /// How long the manager's verdict that the goal cannot be reached must hold before the
    /// flight ends as `unreachable` (s).
    pub unreachable_settle_s: f64,
}

/// Default [`LoopParams::unreachable_settle_s`]: 2 s, a few re-checks of the verdict (the
/// manager re-checks at least every planning horizon) and time to brake to the held stop.
pub const UNREACHABLE_SETTLE_S: f64 = 2.0;

impl LoopParams {
    /// The loop of a flight of `planner` through `world`.
    pub fn new(world: &World, planner: &ResolvedPlanner) -> Self {
        let scenario = world.scenario();
        let sim = &scenario.sim;
        let dt = sim.physics_dt_s;
        let steps_per = |rate_hz: f64| ((1.0 / rate_hz) / dt).round().max(1.0) as u64;
        let manager_latency_s = planner.manager.latency();
        LoopParams {
            dt_s: dt,
            replan_steps: steps_per(sim.replan_rate_hz),
            log_steps: steps_per(sim.log_rate_hz),
            max_steps: (scenario.time_limit_s / dt).ceil() as u64,
            goal: world.goal(),
            goal_tolerance_m: scenario.mission.goal_tolerance_m,
            vehicle_radius_m: world.vehicle_radius_m(),
            clock: Clock::from_latency(sim.latency, manager_latency_s),
            manager_latency_s,
            cycle_budget_ms: planner.manager.cycle_budget_ms,
            unreachable_settle_s: UNREACHABLE_SETTLE_S,
        }
    }

    /// The replanning period (s).
    pub fn replan_period_s(&self) -> f64 {
        self.replan_steps as f64 * self.dt_s
    }
}

/// Everything a flight changes, step by step.
pub struct FlightState {
    /// The true moving obstacles.
    pub traffic: Traffic,
    /// The sensing and its trackers.
    pub sensing: Sensing,
    /// The planner.
    pub manager: AnyManager,
    /// The true vehicle.
    pub vehicle: Box<dyn Vehicle>,
    /// What the vehicle tracks before the first plan takes effect.
    pub hover: Reference,
    /// The plan the vehicle tracks.
    pub active: Option<PolyTraj>,
    /// The latest plan and when it takes effect (s).
    pub pending: Option<(f64, PolyTraj)>,
    /// Physics steps done.
    pub step: u64,
    /// Simulated time (s): `step · dt`.
    pub t: f64,
    /// The planner is busy until this time (s) ([`Clock::RealTime`]).
    pub busy_until: f64,
    /// When the planner's worker started its job, if the last cycle started one (s; the job's
    /// lateness is charged to the cycle that merges it, [`Clock::RealTime`]).
    pub worker_since: Option<f64>,
    /// Since when the manager has held that the goal cannot be reached (s), and why.
    pub unreachable_since: Option<(f64, UnreachableCause)>,
    /// The sensed static map, when the scenario's `[sensing.static]` is not `"known"`
    /// ([`crate::map_sensing`]); `None`: the planner is given the map.
    pub map_sensing: Option<MapSensing>,
}

/// What the vehicle touched; its `Display` is the run log's spelling (`static`,
/// `obstacle:<id>`).
pub use trust_runlog::Contact;

/// How a flight ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Ending {
    /// Within the goal tolerance.
    Arrived,
    /// A clearance below zero.
    Collided(Contact),
    /// The time limit passed.
    TimedOut,
    /// The manager held that the goal cannot be reached for the settling time.
    Unreachable {
        /// The manager's cause (its `Display` is the outcome's `reason`).
        cause: UnreachableCause,
    },
    /// The planner rejected its input.
    Invalid {
        /// The planner's error.
        reason: String,
    },
}

/// The vehicle's clearances at one instant (m, from the vehicle's surface).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Clearances {
    /// To the true static geometry.
    pub static_m: f64,
    /// To the nearest true moving obstacle (`+∞` without any).
    pub dynamic_m: f64,
    /// That obstacle's id.
    pub nearest: Option<usize>,
}

impl Clearances {
    /// The clearances of a vehicle at `p` in `world` among `traffic`.
    pub fn at(world: &World, traffic: &Traffic, radius: f64, p: &Vec3) -> Self {
        let (d, nearest) = traffic.clearance(p);
        Clearances {
            static_m: world.true_static_clearance(p) - radius,
            dynamic_m: d - radius,
            nearest,
        }
    }

    /// What the vehicle touches, if anything (the nearer surface when both).
    pub fn contact(&self) -> Option<Contact> {
        if self.static_m >= 0.0 && self.dynamic_m >= 0.0 {
            None
        } else if self.static_m <= self.dynamic_m {
            Some(Contact::Static)
        } else {
            // A negative dynamic clearance comes from an obstacle, so `nearest` is set.
            self.nearest
                .map(Contact::Obstacle)
                .or(Some(Contact::Static))
        }
    }
}

/// One planning cycle as the loop saw it.
pub struct CycleEvent<'a> {
    /// The cycle's start (s).
    pub t: f64,
    /// The manager's report.
    pub report: &'a StepReport,
    /// The manager after the cycle.
    pub manager: &'a AnyManager,
    /// The tracked obstacles' ids, in the order of `forecasts`.
    pub ids: &'a [usize],
    /// The forecasts the manager planned against (as sensed, with their regions).
    pub forecasts: &'a [Forecast],
    /// When the cycle's plan takes effect (s).
    pub effective_t: f64,
    /// The time the planner was charged (s; [`Clock::charged_s`]).
    pub charged_s: f64,
    /// Replanning ticks skipped because the planner was still busy with this cycle.
    pub overrun_ticks: u64,
    /// The online map's time since the previous cycle (ms; [`crate::map_sensing`]), `None`
    /// with a known map.
    pub map_ms: Option<f64>,
}

/// Hooks into the loop (`()` does nothing). Errors end the flight with that error.
pub trait FlightObserver {
    /// A true state worth logging: every log tick, and the last instant.
    fn state(
        &mut self,
        _t: f64,
        _vehicle: &VehicleState,
        _obstacles: &[Vec3],
        _clearances: &Clearances,
    ) -> Result<(), FlightError> {
        Ok(())
    }

    /// A planning cycle that returned a report.
    fn cycle(&mut self, _cycle: &CycleEvent<'_>) -> Result<(), FlightError> {
        Ok(())
    }
}

impl FlightObserver for () {}

impl<A: FlightObserver, B: FlightObserver> FlightObserver for (A, B) {
    fn state(
        &mut self,
        t: f64,
        vehicle: &VehicleState,
        obstacles: &[Vec3],
        clearances: &Clearances,
    ) -> Result<(), FlightError> {
        self.0.state(t, vehicle, obstacles, clearances)?;
        self.1.state(t, vehicle, obstacles, clearances)
    }

    fn cycle(&mut self, cycle: &CycleEvent<'_>) -> Result<(), FlightError> {
        self.0.cycle(cycle)?;
        self.1.cycle(cycle)
    }
}

/// By obstacle, the box it is known to stay inside when that is not the map: the region of a
/// moving obstacle that the traffic turns back at its walls ([`Forecast::walls`]). `None` for
/// an obstacle whose region is the world and for scripted ones (a script does not reflect).
pub fn obstacle_walls(world: &World) -> Vec<Option<trust_predict::Aabb>> {
    world
        .obstacles()
        .iter()
        .map(|o| (!o.motion.is_scripted() && o.region != *world.bounds()).then_some(o.region))
        .collect()
}

/// Advances the flight by one physics step: a planning cycle first when the step is on a
/// replanning tick and the planner is free, then the vehicle and the obstacles move, the
/// vehicle is checked against the true geometry and the sensors measure. `walls` is
/// [`obstacle_walls`] of `world`. Returns how the flight ended, if it did.
///
/// # Errors
/// [`FlightError`] from the sensing, the vehicle model or an observer. A planner that rejects
/// its input is not an error: the flight ends [`Ending::Invalid`].
pub fn step(
    params: &LoopParams,
    world: &World,
    walls: &[Option<trust_predict::Aabb>],
    state: &mut FlightState,
    observer: &mut dyn FlightObserver,
) -> Result<Option<Ending>, FlightError> {
    let dt = params.dt_s;
    let t = state.t;
    if let Some(m) = state.map_sensing.as_mut() {
        m.sense(t, dt, state.vehicle.state(), world)?;
    }
    if state.step.is_multiple_of(params.replan_steps)
        && t + 0.5 * dt >= state.busy_until
        && let Some(ending) = plan(params, world, walls, state, observer)?
    {
        return Ok(Some(ending));
    }
    if let Some((te, _)) = &state.pending
        && t + 0.5 * dt >= *te
    {
        state.active = state.pending.take().map(|(_, p)| p);
    }

    // Physics. With a sensed map the vehicle turns to look where it goes; else yaw 0.
    let yaw = state.map_sensing.as_mut().map_or(0.0, |m| m.turn(dt));
    let hover = Reference { yaw, ..state.hover };
    let active = &state.active;
    let reference = |tau: f64| match active {
        Some(plan) => Reference::from_traj(plan, tau, yaw),
        None => hover,
    };
    state.vehicle.step(dt, &reference)?;
    state.traffic.step(dt)?;
    state.step += 1;
    state.t = state.step as f64 * dt;
    let t = state.t;

    // Checks.
    let vehicle = state.vehicle.state();
    let clearances = Clearances::at(world, &state.traffic, params.vehicle_radius_m, &vehicle.p);
    let ending = if let Some(contact) = clearances.contact() {
        Some(Ending::Collided(contact))
    } else if (vehicle.p - params.goal).norm() <= params.goal_tolerance_m {
        Some(Ending::Arrived)
    } else if let Some((since, cause)) = state.unreachable_since
        && t - since >= params.unreachable_settle_s - 0.5 * dt
    {
        Some(Ending::Unreachable { cause })
    } else if state.step >= params.max_steps {
        Some(Ending::TimedOut)
    } else {
        None
    };
    if ending.is_some() || state.step.is_multiple_of(params.log_steps) {
        observer.state(t, vehicle, state.traffic.positions(), &clearances)?;
    }
    state.sensing.update(t, state.traffic.positions())?;
    Ok(ending)
}

/// One planning cycle at `state.t` (see [`step`]).
fn plan(
    params: &LoopParams,
    world: &World,
    walls: &[Option<trust_predict::Aabb>],
    state: &mut FlightState,
    observer: &mut dyn FlightObserver,
) -> Result<Option<Ending>, FlightError> {
    let t = state.t;
    let dt = params.dt_s;
    // Each forecast knows the box its obstacle stays inside when that is not the map (a
    // scenario's obstacle region, where the traffic turns it back).
    let ids = state.sensing.tracked_ids();
    let forecasts: Vec<Forecast> = state
        .sensing
        .forecasts(t)?
        .into_iter()
        .zip(&ids)
        .map(|(f, &id)| match walls.get(id).copied().flatten() {
            Some(region) => f.with_walls(region),
            None => f,
        })
        .collect();
    // A sensed map: the cycle plans in it, and commits only to what it observed free.
    let sensed = match state.map_sensing.as_mut() {
        Some(m) => {
            let map = m.planner_map()?;
            state.manager.share_map(Arc::clone(&map));
            state.manager.set_commit_check(Some(m.commit_check()));
            Some(map)
        }
        None => None,
    };
    let map = sensed.as_deref().unwrap_or(world.planner_map());
    let scene = Scene::new(map, &forecasts, t)?;
    let measured = state.vehicle.state().kinematic();
    let stepped = state.manager.step(t, &measured, &params.goal, &scene);
    let map_ms = match state.map_sensing.as_mut() {
        Some(m) => {
            state.manager.set_commit_check(None);
            let p = state.vehicle.state().p;
            let refused = stepped.as_ref().is_ok_and(|r| {
                r.events
                    .iter()
                    .any(|e| matches!(e, trust_manager::Event::NotKnownFree { .. }))
            });
            m.aim(t, &p, &params.goal, &state.manager, refused);
            Some(m.take_map_ms())
        }
        None => None,
    };
    let report = match stepped {
        Ok(report) => report,
        Err(e) => {
            return Ok(Some(Ending::Invalid {
                reason: e.to_string(),
            }));
        }
    };
    let charged_s = charged_for(params.clock, &report.timing, state.worker_since.take(), t);
    state.worker_since = report.worker_started.then_some(t + charged_s);
    // A plan starts `manager_latency_s` after its cycle (where it leaves the committed plan):
    // it takes effect then, or when the planner is done with it if that is later.
    let delay = charged_s.max(params.manager_latency_s);
    let effective_t = t + (delay / dt).ceil() * dt;
    let overrun_ticks = match params.clock {
        Clock::Fixed { .. } => 0,
        Clock::RealTime { .. } => {
            state.busy_until = t + charged_s;
            let periods = (charged_s / params.replan_period_s() - 1e-9)
                .ceil()
                .max(1.0);
            periods as u64 - 1
        }
    };
    if let Some(plan) = state.manager.plan() {
        state.pending = Some((effective_t, plan.clone()));
    }
    match report.goal_unreachable() {
        Some(verdict) => {
            if state.unreachable_since.is_none() {
                state.unreachable_since = Some((t, verdict.cause));
            }
        }
        None => state.unreachable_since = None,
    }
    observer.cycle(&CycleEvent {
        t,
        report: &report,
        manager: &state.manager,
        ids: &ids,
        forecasts: &forecasts,
        effective_t,
        charged_s,
        overrun_ticks,
        map_ms,
    })?;
    Ok(None)
}
