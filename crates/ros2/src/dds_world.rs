//! The simulator as the ROS 2 world of a separate `trust-node` (`trust-sim dds-world`): the
//! scenario's true obstacles move and the vehicle model flies the `trajectory` the node
//! publishes (positions and yaw), in real time; the world publishes its ROS time on `/clock`
//! (`rosgraph_msgs/Clock`, every physics step: the system time by default, so that a node on
//! either clock works, or simulated from `clock_start_s`, for a node with `use_sim_time`), and
//! stamped with it the vehicle's `odom` (position, attitude, velocity), the `goal` and the
//! obstacles (`obstacles`, their true centres and sizes), and
//! writes the flight's run log (`trust_runlog`, contract `run-log-v1`): a `state` record every
//! physics step, a `cycle` record per `events` message of the node, the `outcome`.
//!
//! With `[sensing.static]` other than `"known"` the world also ray-casts the scenario's sensor
//! (depth camera or LiDAR, `trust_flight::map_sensing`'s, its noise from the same seed stream)
//! from the vehicle at the sensor's rate and publishes each scan on `cloud` as a
//! `sensor_msgs/PointCloud2` in `body_frame` ([`scan_cloud`]), stamped as the odometry of the same
//! step; a node with `[cloud]` then flies the scenario on the map it senses.
//!
//! Not yet as `trust-sim run`: no sensor noise or dropouts (the node's tracker gets the true
//! centres), no `[clock]` model (the node's real cycle times apply), the `cycle` records carry
//! only what `trust_msgs/PlannerEvent` has (`main` is `null`, `branches` 0).

use std::path::Path;
use std::time::{Duration as StdDuration, Instant};

use trust_core::Vec3;
use trust_flight::{Clearances, Tally};
use trust_flightstack::frame::wrap_angle;
use trust_runlog::{CycleRecord, LogWriter, Outcome, Record, StateRecord, Status};
use trust_sensing::{DepthCamera, Lidar, Pose, RaySensor, ReturnKind, Scan, Truth};
use trust_vehicle::{ControlledQuadrotor, PerfectTracking, Reference, Vehicle, VehicleState};
use trust_world::World;
use trust_world::map_sensing::StaticSensor;
use trust_world::scenario::VehicleModel;
use trust_world::traffic::MovingShape;

use crate::cloud::{CloudLayout, encode_points};
use crate::convert::unit_quaternion;
use crate::dds::{self, input_qos, plan_qos, system_time, topics};
use crate::error::Ros2Error;
use crate::heading::yaw_of;
use crate::msg::builtin_interfaces::Time;
use crate::msg::geometry_msgs::{Point, PoseStamped, Quaternion, Vector3};
use crate::msg::nav_msgs::Odometry;
use crate::msg::rosgraph_msgs::Clock;
use crate::msg::sensor_msgs::PointCloud2;
use crate::msg::trajectory_msgs::MultiDOFJointTrajectory;
use crate::msg::trust_msgs::{MovingObstacle, MovingObstacleArray, PlannerEvent};

/// The fastest the world's vehicle turns towards the trajectory's yaw (rad/s): PX4's default
/// `MPC_YAWRAUTO_MAX` (45°/s). A flight stack limits the yaw rate so; our SE(3) controller holds
/// a yaw with no rate feed-forward, and a step of the reference yaw (the node's yaw steps where
/// the speed crosses its threshold) would ask it for a large yaw torque at once.
pub const YAW_RATE_LIMIT_RAD_S: f64 = std::f64::consts::FRAC_PI_4;

/// How the world runs.
#[derive(Debug, Clone, PartialEq)]
pub struct DdsWorldOptions {
    /// The world frame of every message (the node's `world_frame`).
    pub world_frame: String,
    /// Physics and log step (s); the contract asks for ≤ 0.02.
    pub dt_s: f64,
    /// Obstacle observations are published every this many seconds.
    pub obstacles_period_s: f64,
    /// Give up when no trajectory arrives within this long (s) before take-off.
    pub wait_for_plan_s: f64,
    /// The world's ROS time, published on `/clock` every step and the stamp of every message
    /// it writes: `Some(start)`: simulated, `start + t` at `t` s of simulated time since [`fly`]
    /// started (the node needs `use_sim_time`); `None` (the default): the system time when it
    /// writes, so that a node on either clock works (the world runs in real time; when it lags
    /// behind, its stamps still say when its messages left).
    pub clock_start_s: Option<f64>,
    /// The vehicle's body frame: the frame of the sensor's clouds.
    pub body_frame: String,
}

impl Default for DdsWorldOptions {
    fn default() -> Self {
        DdsWorldOptions {
            world_frame: "map".into(),
            dt_s: 0.02,
            obstacles_period_s: 0.1,
            wait_for_plan_s: 60.0,
            clock_start_s: None,
            body_frame: "base_link".into(),
        }
    }
}

fn sim_err(what: &str, e: impl std::fmt::Display) -> Ros2Error {
    Ros2Error::invalid(what, e, "a working simulated world")
}

fn v3(v: &Vec3) -> [f64; 3] {
    [v.x, v.y, v.z]
}

/// The moving obstacles at `positions` as a `trust_msgs/MovingObstacleArray` (ids = the
/// scenario's order).
///
/// # Errors
/// [`Ros2Error::Invalid`] for a box obstacle (`trust_msgs` has spheres and cylinders).
pub fn obstacle_message(
    world: &World,
    positions: &[Vec3],
    stamp: Time,
    frame: &str,
) -> Result<MovingObstacleArray, Ros2Error> {
    let obstacles = world
        .obstacles()
        .iter()
        .zip(positions)
        .enumerate()
        .map(|(id, (o, p))| {
            let (shape, size) = match o.shape {
                MovingShape::Sphere { radius } => (
                    MovingObstacle::SHAPE_SPHERE,
                    Vector3 {
                        x: 2.0 * radius,
                        y: 2.0 * radius,
                        z: 2.0 * radius,
                    },
                ),
                MovingShape::Cylinder {
                    radius,
                    half_height,
                } => (
                    MovingObstacle::SHAPE_CYLINDER,
                    Vector3 {
                        x: 2.0 * radius,
                        y: 2.0 * radius,
                        z: 2.0 * half_height,
                    },
                ),
                MovingShape::Box { .. } => {
                    return Err(Ros2Error::invalid(
                        format!("obstacles[{id}].shape"),
                        "box",
                        "a sphere or a cylinder (trust_msgs/MovingObstacle)",
                    ));
                }
            };
            Ok(MovingObstacle {
                id: id as u32,
                shape,
                size,
                position: (*p).into(),
                ..MovingObstacle::default()
            })
        })
        .collect::<Result<_, _>>()?;
    Ok(MovingObstacleArray {
        header: stamp.into_header(frame),
        obstacles,
    })
}

/// The reference of `traj` at ROS time `now` (s): linear between its samples, with the jerk
/// of the accelerations' slope (the controller's body-rate feed-forward: without it the
/// quadrotor lags and overshoots the planned speed) and the yaw of the rotations (the shorter
/// way round), its last sample held (at rest) after its end, its first before its start.
pub fn reference_at(traj: &MultiDOFJointTrajectory, now: f64) -> Option<Reference> {
    let t0 = traj.header.stamp.as_seconds();
    let yaw_at = |k: usize| {
        let q = traj.points[k].transforms.first()?.rotation;
        // A zero rotation (not ours) flies heading 0.
        Some(unit_quaternion("rotation", &q).map_or(0.0, |q| yaw_of(&q)))
    };
    let sample = |k: usize| {
        let p = &traj.points[k];
        Some((
            t0 + p.time_from_start.as_seconds(),
            Vec3::from(p.transforms.first()?.translation),
            Vec3::from(p.velocities.first()?.linear),
            Vec3::from(p.accelerations.first()?.linear),
        ))
    };
    let n = traj.points.len();
    if n == 0 {
        return None;
    }
    let k = traj
        .points
        .partition_point(|p| t0 + p.time_from_start.as_seconds() <= now);
    let (p, v, a, j, yaw) = if k == 0 {
        let (_, p, v, a) = sample(0)?;
        (p, v, a, Vec3::zeros(), yaw_at(0)?)
    } else if k == n {
        let (_, p, _, _) = sample(n - 1)?;
        let rest = Vec3::zeros();
        (p, rest, rest, rest, yaw_at(n - 1)?)
    } else {
        let (ta, pa, va, aa) = sample(k - 1)?;
        let (tb, pb, vb, ab) = sample(k)?;
        let h = tb - ta;
        let (s, j) = if h > 0.0 {
            ((now - ta) / h, (ab - aa) / h)
        } else {
            (0.0, Vec3::zeros())
        };
        let (ya, yb) = (yaw_at(k - 1)?, yaw_at(k)?);
        let yaw = wrap_angle(ya + wrap_angle(yb - ya) * s);
        (pa.lerp(&pb, s), va.lerp(&vb, s), aa.lerp(&ab, s), j, yaw)
    };
    Some(Reference { p, v, a, j, yaw })
}

/// A scan as the cloud a sensor driver on the vehicle would publish, in the body frame of the
/// vehicle at `position` with `attitude`, one point per ray in the scan's order (`FLOAT32`
/// x, y, z, PCL's 16-byte point, one row): a hit at its range; a ray without a return at twice
/// the sensor's range `range_m`, beyond the node's `max_range_m` when that is the sensor's range,
/// so the node clears space along it up to that range and marks nothing (a depth driver would
/// send NaN and lose that evidence); an invalid ray as NaN.
///
/// # Errors
/// [`Ros2Error::Invalid`] for a cloud too large for `PointCloud2`'s `u32` sizes.
pub fn scan_cloud(
    scan: &Scan,
    position: &Vec3,
    attitude: &nalgebra::UnitQuaternion<f64>,
    range_m: f64,
    header: crate::msg::std_msgs::Header,
) -> Result<PointCloud2, Ros2Error> {
    let to_body = attitude.inverse();
    let points: Vec<Vec3> = scan
        .rays
        .iter()
        .map(|r| {
            let range = match r.kind {
                ReturnKind::Hit => r.range,
                ReturnKind::NoReturn => 2.0 * range_m,
                ReturnKind::Invalid => return Vec3::repeat(f64::NAN),
            };
            to_body * (scan.origin + r.direction * range - position)
        })
        .collect();
    encode_points(header, &points, &CloudLayout::default())
}

/// The scenario's static sensor, ray-cast from the vehicle every period (module docs).
struct CloudSource {
    sensor: Box<dyn RaySensor>,
    rng: rand_chacha::ChaCha8Rng,
    scan: Scan,
    period_s: f64,
    next_t: f64,
    range_m: f64,
}

impl CloudSource {
    /// The sensor of `world`'s `[sensing.static]`; `None` for `"known"`.
    fn new(world: &World) -> Result<Option<Self>, Ros2Error> {
        use rand::SeedableRng;
        let Some((sensor, _)) = world.scenario().sensing.static_map.sensor() else {
            return Ok(None);
        };
        let (boxed, range_m): (Box<dyn RaySensor>, f64) = match sensor {
            StaticSensor::Depth(p) => (Box::new(DepthCamera::new(p)?), p.max_depth_m),
            StaticSensor::Lidar(p) => (Box::new(Lidar::new(p)?), p.max_range_m),
        };
        Ok(Some(CloudSource {
            period_s: 1.0 / sensor.rate_hz(),
            sensor: boxed,
            rng: rand_chacha::ChaCha8Rng::seed_from_u64(trust_world::mix_seed(
                world.scenario().seed,
                trust_flight::map_sensing::NOISE_STREAM,
            )),
            scan: Scan::default(),
            next_t: 0.0,
            range_m,
        }))
    }

    /// The cloud at simulated time `t` if a scan is due (`dt`: the step), else `None`.
    fn due(
        &mut self,
        t: f64,
        dt: f64,
        vehicle: &VehicleState,
        world: &World,
        header: crate::msg::std_msgs::Header,
    ) -> Result<Option<PointCloud2>, Ros2Error> {
        if t + 0.5 * dt < self.next_t {
            return Ok(None);
        }
        while self.next_t <= t + 0.5 * dt {
            self.next_t += self.period_s;
        }
        let pose = Pose::new(vehicle.p, vehicle.attitude);
        self.sensor.scan(
            &pose,
            &Truth::static_only(world.truth_map()),
            &mut self.rng,
            &mut self.scan,
        )?;
        scan_cloud(
            &self.scan,
            &vehicle.p,
            &vehicle.attitude,
            self.range_m,
            header,
        )
        .map(Some)
    }
}

/// The world's DDS side: its node, the node's inputs it writes, what it reads back.
struct Ports {
    /// Kept alive while its publishers and subscriptions are used.
    _node: ros2_client::Node,
    frame: String,
    goal: Vec3,
    clock: ros2_client::Publisher<Clock>,
    odom: ros2_client::Publisher<Odometry>,
    goal_pub: ros2_client::Publisher<PoseStamped>,
    obstacles: ros2_client::Publisher<MovingObstacleArray>,
    /// With a sensed static map: the sensor's clouds and their frame.
    cloud: Option<(ros2_client::Publisher<PointCloud2>, String)>,
    trajectory: ros2_client::Subscription<MultiDOFJointTrajectory>,
    events: ros2_client::Subscription<PlannerEvent>,
}

impl Ports {
    fn new(
        domain_id: u16,
        frame: &str,
        goal: Vec3,
        cloud_frame: Option<&str>,
    ) -> Result<Self, Ros2Error> {
        let context = ros2_client::Context::with_options(
            ros2_client::ContextOptions::new().domain_id(domain_id),
        )
        .map_err(|e| Ros2Error::dds("create DDS participant", e))?;
        let mut node = context
            .new_node(
                ros2_client::NodeName::new("/", "trust_sim_world")
                    .map_err(|e| Ros2Error::dds("node name", e))?,
                ros2_client::NodeOptions::new().enable_rosout(false),
            )
            .map_err(|e| Ros2Error::dds("create node", e))?;
        Ok(Ports {
            clock: dds::publisher(&mut node, topics::CLOCK, dds::clock_writer_qos())?,
            odom: dds::publisher(&mut node, topics::ODOM, input_qos())?,
            goal_pub: dds::publisher(&mut node, topics::GOAL, plan_qos())?,
            obstacles: dds::publisher(&mut node, topics::OBSTACLES, input_qos())?,
            cloud: match cloud_frame {
                Some(f) => Some((
                    dds::publisher(&mut node, topics::CLOUD, dds::cloud_qos())?,
                    f.to_owned(),
                )),
                None => None,
            },
            trajectory: dds::subscription(&mut node, topics::TRAJECTORY, plan_qos())?,
            events: dds::subscription(
                &mut node,
                topics::EVENTS,
                plan_qos().history(ros2_client::qos::History::KeepLast { depth: 100 }),
            )?,
            _node: node,
            frame: frame.to_owned(),
            goal,
        })
    }

    /// The node's inputs at ROS time `now`: `/clock`, the vehicle's `odom` (twist in the world
    /// frame), and with `slow` (every `obstacles_period_s`) the obstacles at `positions` and
    /// the goal. Writes before discovery matches a reader may fail; the next ones are sent.
    fn publish_inputs(
        &self,
        world: &World,
        now: Time,
        vehicle: &VehicleState,
        positions: &[Vec3],
        slow: bool,
    ) -> Result<(), Ros2Error> {
        let frame = self.frame.as_str();
        let _ = self.clock.publish(Clock { clock: now });
        let mut odom = Odometry {
            header: now.into_header(frame),
            child_frame_id: frame.to_owned(), // the twist is in the world frame
            ..Odometry::default()
        };
        odom.pose.pose.position = vehicle.p.into();
        let q = vehicle.attitude.quaternion();
        odom.pose.pose.orientation = Quaternion {
            x: q.i,
            y: q.j,
            z: q.k,
            w: q.w,
        };
        odom.twist.twist.linear = vehicle.v.into();
        let _ = self.odom.publish(odom);
        if slow {
            let _ = self
                .obstacles
                .publish(obstacle_message(world, positions, now, frame)?);
            let _ = self.goal_pub.publish(PoseStamped {
                header: now.into_header(frame),
                pose: crate::msg::geometry_msgs::Pose {
                    position: Point::from(self.goal),
                    ..Default::default()
                },
            });
        }
        Ok(())
    }

    /// The sensor's cloud at simulated time `t`, if one is due, stamped `now` (as the
    /// odometry of the step).
    fn publish_cloud(
        &self,
        source: Option<&mut CloudSource>,
        (t, dt): (f64, f64),
        now: Time,
        vehicle: &VehicleState,
        world: &World,
    ) -> Result<(), Ros2Error> {
        let (Some(source), Some((publisher, frame))) = (source, &self.cloud) else {
            return Ok(());
        };
        if let Some(cloud) = source.due(t, dt, vehicle, world, now.into_header(frame))? {
            let _ = publisher.publish(cloud);
        }
        Ok(())
    }

    /// The latest trajectory received since the last call, if any.
    fn latest_trajectory(&self) -> Option<MultiDOFJointTrajectory> {
        let mut latest = None;
        while let Ok(Some((m, _))) = self.trajectory.take() {
            latest = Some(m);
        }
        latest
    }
}

/// The world's ROS time ([`DdsWorldOptions::clock_start_s`]).
#[derive(Debug, Clone, Copy, PartialEq)]
enum SimClock {
    /// The system time when a message is written.
    System,
    /// `start_s + t` at simulated time `t` (s since [`fly`] started).
    Simulated { start_s: f64 },
}

impl SimClock {
    /// Simulated from `start_s`, or the system clock.
    fn new(start_s: Option<f64>) -> Result<Self, Ros2Error> {
        let Some(start_s) = start_s else {
            return Ok(SimClock::System);
        };
        // A day of simulated time must stay within `int32` seconds.
        if !(start_s.is_finite() && start_s >= 0.0 && start_s < f64::from(i32::MAX) - 86_400.0) {
            return Err(Ros2Error::invalid(
                "clock_start_s",
                start_s,
                "a finite time >= 0 s, a day short of the int32 seconds range",
            ));
        }
        Ok(SimClock::Simulated { start_s })
    }

    /// The ROS time at simulated time `t`.
    fn at(&self, t: f64) -> Result<Time, Ros2Error> {
        match self {
            SimClock::System => Ok(system_time()),
            SimClock::Simulated { start_s } => Time::from_seconds(start_s + t),
        }
    }
}

/// Flies `world` against a `trust-node` on `domain_id` (module docs) and writes the run log to
/// `log_path`; returns the outcome.
///
/// # Errors
/// [`Ros2Error`] when DDS, the world, the vehicle model or the log fail, or when no trajectory
/// arrives within `wait_for_plan_s`; [`Ros2Error::Invalid`] for an invalid `clock_start_s`.
pub fn fly(
    world: &World,
    domain_id: u16,
    log_path: &Path,
    options: &DdsWorldOptions,
) -> Result<Outcome, Ros2Error> {
    let scenario = world.scenario();
    let dt = options.dt_s;
    let mut traffic = world.traffic()?;
    let hover = Reference::hover(world.start());
    let mut gains = scenario.vehicle.gains;
    gains.max_accel_m_s2 = gains.max_accel_m_s2.or(Some(scenario.vehicle.limits.a_max));
    let mut vehicle: Box<dyn Vehicle> = match scenario.vehicle.model {
        VehicleModel::Quadrotor => Box::new(
            ControlledQuadrotor::starting_on(scenario.vehicle.quadrotor, gains, 0.0, &hover)
                .map_err(|e| sim_err("vehicle", e))?,
        ),
        VehicleModel::Perfect => {
            Box::new(PerfectTracking::new(0.0, &hover).map_err(|e| sim_err("vehicle", e))?)
        }
    };
    let clock = SimClock::new(options.clock_start_s)?;
    let mut sensor = CloudSource::new(world)?;
    let ports = Ports::new(
        domain_id,
        &options.world_frame,
        world.goal(),
        sensor.as_ref().map(|_| options.body_frame.as_str()),
    )?;

    // Before take-off: hover at the start until the node's first plan; the simulated time runs
    // with the wall clock.
    let waited = Instant::now();
    let mut plan: Option<MultiDOFJointTrajectory> = None;
    let mut next_slow = 0.0;
    while plan.is_none() {
        let t = waited.elapsed().as_secs_f64();
        if t > options.wait_for_plan_s {
            return Err(Ros2Error::dds(
                format!("no trajectory on domain {domain_id}"),
                format!("within {} s", options.wait_for_plan_s),
            ));
        }
        let slow = t >= next_slow;
        if slow {
            next_slow = t + options.obstacles_period_s;
        }
        let now = clock.at(t)?;
        ports.publish_inputs(world, now, vehicle.state(), traffic.positions(), slow)?;
        ports.publish_cloud(sensor.as_mut(), (t, dt), now, vehicle.state(), world)?;
        std::thread::sleep(StdDuration::from_secs_f64(dt));
        plan = ports.latest_trajectory();
    }
    // Cycles before take-off are not the flight's.
    while let Ok(Some(_)) = ports.events.take() {}

    let mut log = LogWriter::create(log_path).map_err(|e| sim_err("run log", e))?;
    log.write(&Record::Header(trust_flight::header(
        world,
        "trust-node",
        None,
    )))
    .map_err(|e| sim_err("run log", e))?;

    let radius = world.vehicle_radius_m();
    let tolerance = scenario.mission.goal_tolerance_m;
    let max_steps = (scenario.time_limit_s / dt).round() as u64;
    // Flight time t is simulated time takeoff + t, ROS time t0_ros + t.
    let takeoff = waited.elapsed().as_secs_f64();
    let t0_ros = clock.at(takeoff)?.as_seconds();
    let wall0 = Instant::now();
    let mut tally = Tally::default();
    let mut cycles = 0usize;
    let mut step = 0u64;
    let mut next_obstacles = 0.0;
    let mut yaw = vehicle.state().attitude.euler_angles().2;
    let state_record = |t: f64, vehicle: &dyn Vehicle, positions: &[Vec3]| {
        let s = vehicle.state();
        StateRecord {
            t,
            p: v3(&s.p),
            v: v3(&s.v),
            a: v3(&s.a),
            obstacles: positions.iter().map(v3).collect(),
        }
    };
    {
        let s = vehicle.state();
        let c = Clearances::at(world, &traffic, radius, &s.p);
        tally.add(&s.p, &s.v, &s.a, c.static_m, c.dynamic_m);
        log.write(&Record::State(state_record(
            0.0,
            &*vehicle,
            traffic.positions(),
        )))
        .map_err(|e| sim_err("run log", e))?;
    }
    let (status, with) = loop {
        let t = step as f64 * dt;
        // Inputs of the node at t.
        let slow = t + 1e-9 >= next_obstacles;
        if slow {
            next_obstacles += options.obstacles_period_s;
        }
        let now = clock.at(takeoff + t)?;
        ports.publish_inputs(world, now, vehicle.state(), traffic.positions(), slow)?;
        ports.publish_cloud(
            sensor.as_mut(),
            (takeoff + t, dt),
            now,
            vehicle.state(),
            world,
        )?;
        if let Some(m) = ports.latest_trajectory() {
            plan = Some(m);
        }
        while let Ok(Some((e, _))) = ports.events.take() {
            let te = e.header.stamp.as_seconds() - t0_ros;
            if te < 0.0 || te > t + 1e-9 {
                continue; // outside the logged flight
            }
            cycles += 1;
            log.write(&Record::Cycle(cycle_record(te, &e)))
                .map_err(|e| sim_err("run log", e))?;
        }
        // Physics from t to t + dt, the plan sampled on the ROS clock; the yaw turns towards
        // the plan's at most YAW_RATE_LIMIT_RAD_S.
        let current = plan.clone();
        let target = current
            .as_ref()
            .and_then(|p| reference_at(p, t0_ros + t))
            .map_or(yaw, |r| r.yaw);
        let turn = YAW_RATE_LIMIT_RAD_S * dt;
        yaw = wrap_angle(yaw + wrap_angle(target - yaw).clamp(-turn, turn));
        let step_yaw = yaw;
        let reference = move |tau: f64| {
            let r = current
                .as_ref()
                .and_then(|p| reference_at(p, t0_ros + tau))
                .unwrap_or(hover);
            Reference { yaw: step_yaw, ..r }
        };
        vehicle
            .step(dt, &reference)
            .map_err(|e| sim_err("vehicle", e))?;
        traffic.step(dt)?;
        step += 1;
        let t = step as f64 * dt;
        let s = vehicle.state();
        let c = Clearances::at(world, &traffic, radius, &s.p);
        tally.add(&s.p, &s.v, &s.a, c.static_m, c.dynamic_m);
        log.write(&Record::State(state_record(
            t,
            &*vehicle,
            traffic.positions(),
        )))
        .map_err(|e| sim_err("run log", e))?;
        if let Some(contact) = c.contact() {
            break (Status::Collided, Some(contact.to_string()));
        }
        if (s.p - world.goal()).norm() <= tolerance {
            break (Status::Arrived, None);
        }
        if step >= max_steps {
            break (Status::TimedOut, None);
        }
        // Real time: the next step starts at wall0 + t.
        let due = wall0 + StdDuration::from_secs_f64(t);
        if let Some(wait) = due.checked_duration_since(Instant::now()) {
            std::thread::sleep(wait);
        }
    };
    let t = step as f64 * dt;
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
        reason: None,
        cycle_count: cycles,
        forecast_warning_s: None,
    };
    log.write(&Record::Outcome(outcome.clone()))
        .map_err(|e| sim_err("run log", e))?;
    log.finish().map_err(|e| sim_err("run log", e))?;
    Ok(outcome)
}

/// A `cycle` record at flight time `t` from the node's event.
fn cycle_record(t: f64, e: &PlannerEvent) -> CycleRecord {
    let wall_ms = if e.cycle_time_ms.is_finite() {
        e.cycle_time_ms.max(0.0)
    } else {
        0.0
    };
    CycleRecord::bare(t, wall_ms, None, 0, e.events.clone())
}

#[cfg(test)]
mod tests {
    use approx::assert_relative_eq;

    use super::*;
    use crate::msg::builtin_interfaces::Duration;
    use crate::msg::geometry_msgs::{Transform, Twist};
    use crate::msg::trajectory_msgs::MultiDOFJointTrajectoryPoint;

    fn point(t: f64, x: f64, vx: f64) -> MultiDOFJointTrajectoryPoint {
        MultiDOFJointTrajectoryPoint {
            transforms: vec![Transform {
                translation: Vector3 { x, y: 1.0, z: 2.0 },
                ..Transform::default()
            }],
            velocities: vec![Twist {
                linear: Vector3 {
                    x: vx,
                    y: 0.0,
                    z: 0.0,
                },
                ..Twist::default()
            }],
            accelerations: vec![Twist::default()],
            time_from_start: Duration::from_seconds(t).expect("duration"),
        }
    }

    #[test]
    fn a_scan_becomes_a_body_frame_cloud_the_node_decodes_back_into_the_world() {
        use trust_sensing::RayMeasurement;
        let p = Vec3::new(2.0, 10.0, 3.0);
        let q = nalgebra::UnitQuaternion::from_euler_angles(0.0, 0.0, std::f64::consts::FRAC_PI_2);
        let ray = |d: Vec3, range, kind| RayMeasurement {
            direction: d.normalize(),
            range,
            kind,
        };
        let scan = Scan {
            origin: p,
            rays: vec![
                ray(Vec3::new(1.0, 0.0, 0.0), 4.0, ReturnKind::Hit),
                ray(Vec3::new(0.0, 1.0, 1.0), 10.0, ReturnKind::NoReturn),
                ray(Vec3::new(0.0, 0.0, 1.0), 0.0, ReturnKind::Invalid),
            ],
        };
        let header = Time { sec: 5, nanosec: 0 }.into_header("base_link");
        let cloud = scan_cloud(&scan, &p, &q, 10.0, header).expect("encodes");
        assert_eq!((cloud.width, cloud.height, cloud.is_dense), (3, 1, false));
        let decoded = crate::cloud::decode_points(&cloud).expect("decodes");
        assert_eq!(decoded.skipped_count, 1, "the invalid ray is NaN");
        let world: Vec<Vec3> = decoded.points.iter().map(|b| q * b + p).collect();
        // FLOAT32 on the wire: within a few µm.
        assert_relative_eq!(world[0], Vec3::new(6.0, 10.0, 3.0), epsilon = 1e-5);
        let far = Vec3::new(0.0, 1.0, 1.0).normalize() * 20.0 + p;
        assert_relative_eq!(world[1], far, epsilon = 1e-5);
    }

    #[test]
    fn the_reference_interpolates_the_samples_and_rests_at_the_end() {
        let traj = MultiDOFJointTrajectory {
            header: Time {
                sec: 100,
                nanosec: 0,
            }
            .into_header("map"),
            joint_names: vec!["base_link".into()],
            points: vec![
                point(0.0, 0.0, 1.0),
                point(0.5, 0.5, 1.0),
                point(1.0, 1.0, 0.0),
            ],
        };
        let r = reference_at(&traj, 100.25).expect("a reference");
        assert_relative_eq!(r.p.x, 0.25, epsilon = 1e-9);
        assert_relative_eq!(r.p.y, 1.0, epsilon = 1e-9);
        assert_relative_eq!(r.v.x, 1.0, epsilon = 1e-9);
        let before = reference_at(&traj, 99.0).expect("a reference");
        assert_relative_eq!(before.p.x, 0.0, epsilon = 1e-9);
        let after = reference_at(&traj, 105.0).expect("a reference");
        assert_relative_eq!(after.p.x, 1.0, epsilon = 1e-9);
        assert_relative_eq!(after.v.norm(), 0.0, epsilon = 1e-12);
        assert!(reference_at(&MultiDOFJointTrajectory::default(), 0.0).is_none());
    }

    /// Two samples 0.5 s apart at x = 0, the first at ROS time 100 s.
    fn two_samples_at_rest() -> MultiDOFJointTrajectory {
        MultiDOFJointTrajectory {
            header: Time {
                sec: 100,
                nanosec: 0,
            }
            .into_header("map"),
            joint_names: vec!["base_link".into()],
            points: vec![point(0.0, 0.0, 0.0), point(0.5, 0.0, 0.0)],
        }
    }

    #[test]
    fn the_reference_carries_the_jerk_of_the_sampled_accelerations() {
        let mut traj = two_samples_at_rest();
        traj.points[1].accelerations[0].linear.x = 2.0;
        let r = reference_at(&traj, 100.25).expect("a reference");
        assert_relative_eq!(r.a.x, 1.0, epsilon = 1e-9);
        assert_relative_eq!(r.j.x, 4.0, epsilon = 1e-9);
        let after = reference_at(&traj, 101.0).expect("a reference");
        assert_relative_eq!(after.j.norm(), 0.0, epsilon = 1e-12);
    }

    #[test]
    fn the_reference_turns_the_shorter_way_between_the_samples_yaws() {
        let mut traj = two_samples_at_rest();
        // From 170° to -170°: through 180°, not through 0°.
        traj.points[0].transforms[0].rotation = Quaternion::from_yaw(170f64.to_radians());
        traj.points[1].transforms[0].rotation = Quaternion::from_yaw(-170f64.to_radians());
        let mid = reference_at(&traj, 100.25).expect("a reference");
        assert_relative_eq!(mid.yaw.abs(), std::f64::consts::PI, epsilon = 1e-9);
        let quarter = reference_at(&traj, 100.125).expect("a reference");
        assert_relative_eq!(quarter.yaw, 175f64.to_radians(), epsilon = 1e-9);
        assert_relative_eq!(
            reference_at(&traj, 99.0).expect("before").yaw,
            170f64.to_radians(),
            epsilon = 1e-9
        );
        assert_relative_eq!(
            reference_at(&traj, 101.0).expect("after").yaw,
            -170f64.to_radians(),
            epsilon = 1e-9
        );
    }

    #[test]
    fn the_clock_starts_where_asked_and_refuses_what_int32_cannot_hold() {
        let c = SimClock::new(Some(1000.0)).expect("valid");
        assert_eq!(
            c.at(2.5).expect("in range"),
            Time {
                sec: 1002,
                nanosec: 500_000_000
            }
        );
        let now = system_time().as_seconds();
        let system = SimClock::new(None).expect("system");
        assert!((system.at(1e6).expect("now").as_seconds() - now).abs() < 5.0);
        for bad in [f64::NAN, -1.0, 3e9] {
            assert!(SimClock::new(Some(bad)).is_err(), "{bad}");
        }
    }
}
