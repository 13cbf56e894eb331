//! The simulator as the ROS 2 world of a separate `trust-node` (`trust-sim dds-world`): the
//! scenario's true obstacles move and the vehicle model flies the `trajectory` the node
//! publishes, in real time on the system clock (the node's clock); the world publishes the
//! vehicle's `odom`, the `goal` and the obstacles (`obstacles`, their true centres and sizes)
//! and writes the flight's run log (`trust_runlog`, contract `run-log-v1`): a `state` record
//! every physics step, a `cycle` record per `events` message of the node, the `outcome`.
//!
//! Not yet as `trust-sim run`: no sensor noise or dropouts (the node's tracker gets the true
//! centres), no `[clock]` model (the node's real cycle times apply), the `cycle` records carry
//! only what `trust_msgs/PlannerEvent` has (`main` is `null`, `branches` 0).

use std::path::Path;
use std::time::{Duration as StdDuration, Instant};

use trust_core::Vec3;
use trust_flight::Clearances;
use trust_runlog::{CycleRecord, Dropped, LogWriter, Outcome, Record, StateRecord, Status};
use trust_vehicle::{ControlledQuadrotor, PerfectTracking, Reference, Vehicle};
use trust_world::World;
use trust_world::scenario::VehicleModel;
use trust_world::traffic::MovingShape;

use crate::dds::{self, input_qos, plan_qos, system_time, topics};
use crate::error::Ros2Error;
use crate::msg::builtin_interfaces::Time;
use crate::msg::geometry_msgs::{Point, PoseStamped, Vector3};
use crate::msg::nav_msgs::Odometry;
use crate::msg::trajectory_msgs::MultiDOFJointTrajectory;
use crate::msg::trust_msgs::{MovingObstacle, MovingObstacleArray, PlannerEvent};

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
}

impl Default for DdsWorldOptions {
    fn default() -> Self {
        DdsWorldOptions {
            world_frame: "map".into(),
            dt_s: 0.02,
            obstacles_period_s: 0.1,
            wait_for_plan_s: 60.0,
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

/// The reference of `traj` at ROS time `now` (s): linear between its samples, its last sample
/// held (at rest) after its end, its first before its start.
pub fn reference_at(traj: &MultiDOFJointTrajectory, now: f64) -> Option<Reference> {
    let t0 = traj.header.stamp.as_seconds();
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
    let (p, v, a) = if k == 0 {
        let (_, p, v, a) = sample(0)?;
        (p, v, a)
    } else if k == n {
        let (_, p, _, _) = sample(n - 1)?;
        (p, Vec3::zeros(), Vec3::zeros())
    } else {
        let (ta, pa, va, aa) = sample(k - 1)?;
        let (tb, pb, vb, ab) = sample(k)?;
        let s = if tb > ta { (now - ta) / (tb - ta) } else { 0.0 };
        (pa.lerp(&pb, s), va.lerp(&vb, s), aa.lerp(&ab, s))
    };
    Some(Reference {
        p,
        v,
        a,
        j: Vec3::zeros(),
        yaw: 0.0,
    })
}

/// Flies `world` against a `trust-node` on `domain_id` (module docs) and writes the run log to
/// `log_path`; returns the outcome.
///
/// # Errors
/// [`Ros2Error`] when DDS, the world, the vehicle model or the log fail, or when no trajectory
/// arrives within `wait_for_plan_s`.
pub fn fly(
    world: &World,
    domain_id: u16,
    log_path: &Path,
    options: &DdsWorldOptions,
) -> Result<Outcome, Ros2Error> {
    let scenario = world.scenario();
    let frame = options.world_frame.as_str();
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

    let context =
        ros2_client::Context::with_options(ros2_client::ContextOptions::new().domain_id(domain_id))
            .map_err(|e| Ros2Error::dds("create DDS participant", e))?;
    let mut node = context
        .new_node(
            ros2_client::NodeName::new("/", "trust_sim_world")
                .map_err(|e| Ros2Error::dds("node name", e))?,
            ros2_client::NodeOptions::new().enable_rosout(false),
        )
        .map_err(|e| Ros2Error::dds("create node", e))?;
    let odom_pub = dds::publisher::<Odometry>(&mut node, topics::ODOM, input_qos())?;
    let goal_pub = dds::publisher::<PoseStamped>(&mut node, topics::GOAL, plan_qos())?;
    let obstacles_pub =
        dds::publisher::<MovingObstacleArray>(&mut node, topics::OBSTACLES, input_qos())?;
    let traj_sub =
        dds::subscription::<MultiDOFJointTrajectory>(&mut node, topics::TRAJECTORY, plan_qos())?;
    let events_sub = dds::subscription::<PlannerEvent>(
        &mut node,
        topics::EVENTS,
        plan_qos().history(ros2_client::qos::History::KeepLast { depth: 100 }),
    )?;

    let odom_at = |p: Vec3, v: Vec3| {
        let mut m = Odometry {
            header: system_time().into_header(frame),
            child_frame_id: frame.to_owned(), // the twist is in the world frame
            ..Odometry::default()
        };
        m.pose.pose.position = p.into();
        m.twist.twist.linear = v.into();
        m
    };
    let goal = PoseStamped {
        header: system_time().into_header(frame),
        pose: crate::msg::geometry_msgs::Pose {
            position: Point::from(world.goal()),
            ..Default::default()
        },
    };

    // Before take-off: hover at the start until the node's first plan.
    let waited = Instant::now();
    let mut plan: Option<MultiDOFJointTrajectory> = None;
    while plan.is_none() {
        if waited.elapsed().as_secs_f64() > options.wait_for_plan_s {
            return Err(Ros2Error::dds(
                format!("no trajectory on domain {domain_id}"),
                format!("within {} s", options.wait_for_plan_s),
            ));
        }
        let _ = odom_pub.publish(odom_at(world.start(), Vec3::zeros()));
        let _ = goal_pub.publish(PoseStamped {
            header: system_time().into_header(frame),
            ..goal.clone()
        });
        let _ = obstacles_pub.publish(obstacle_message(
            world,
            traffic.positions(),
            system_time(),
            frame,
        )?);
        std::thread::sleep(StdDuration::from_millis(100));
        while let Ok(Some((m, _))) = traj_sub.take() {
            plan = Some(m);
        }
    }
    // Cycles before take-off are not the flight's.
    while let Ok(Some(_)) = events_sub.take() {}

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
    let t0_ros = system_time().as_seconds();
    let wall0 = Instant::now();
    let mut tally = Tally::default();
    let mut cycles = 0usize;
    let mut step = 0u64;
    let mut next_obstacles = 0.0;
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
        let c = Clearances::at(world, &traffic, radius, &vehicle.state().p);
        tally.add(vehicle.state(), &c);
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
        let _ = odom_pub.publish(odom_at(vehicle.state().p, vehicle.state().v));
        if t + 1e-9 >= next_obstacles {
            let _ = obstacles_pub.publish(obstacle_message(
                world,
                traffic.positions(),
                system_time(),
                frame,
            )?);
            let _ = goal_pub.publish(PoseStamped {
                header: system_time().into_header(frame),
                ..goal.clone()
            });
            next_obstacles += options.obstacles_period_s;
        }
        while let Ok(Some((m, _))) = traj_sub.take() {
            plan = Some(m);
        }
        while let Ok(Some((e, _))) = events_sub.take() {
            let te = e.header.stamp.as_seconds() - t0_ros;
            if te < 0.0 || te > t + 1e-9 {
                continue; // outside the logged flight
            }
            cycles += 1;
            log.write(&Record::Cycle(cycle_record(te, &e)))
                .map_err(|e| sim_err("run log", e))?;
        }
        // Physics from t to t + dt, the plan sampled on the ROS clock.
        let current = plan.clone();
        let reference = move |tau: f64| {
            current
                .as_ref()
                .and_then(|p| reference_at(p, t0_ros + tau))
                .unwrap_or(hover)
        };
        vehicle
            .step(dt, &reference)
            .map_err(|e| sim_err("vehicle", e))?;
        traffic.step(dt)?;
        step += 1;
        let t = step as f64 * dt;
        let s = vehicle.state();
        let c = Clearances::at(world, &traffic, radius, &s.p);
        tally.add(s, &c);
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
        min_clearance_static_m: tally.min_static.min(1e9),
        min_clearance_dynamic_m: tally.min_dynamic.min(1e9),
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
    CycleRecord {
        t,
        wall_ms: if e.cycle_time_ms.is_finite() {
            e.cycle_time_ms.max(0.0)
        } else {
            0.0
        },
        main: None,
        branches: 0,
        events: e.events.clone(),
        frontend_ms: 0.0,
        backend_ms: 0.0,
        checker_ms: 0.0,
        solve_count: 0,
        effective_t: t,
        branch_j: Vec::new(),
        fallback_collision_free: None,
        fallback_shortfall_m: None,
        fallback_along: None,
        dropped: Dropped::default(),
        route: None,
        route_ms: None,
        branch_samples: None,
        forecasts: None,
        charged_ms: None,
        overrun_ticks: None,
        worker_ms: None,
        waited_ms: None,
        map_ms: None,
    }
}

/// The outcome's figures over the logged states (as the contract defines them).
#[derive(Debug)]
struct Tally {
    last: Option<Vec3>,
    path_length: f64,
    min_static: f64,
    min_dynamic: f64,
    max_speed: f64,
    max_accel: f64,
}

impl Default for Tally {
    fn default() -> Self {
        Tally {
            last: None,
            path_length: 0.0,
            min_static: f64::INFINITY,
            min_dynamic: f64::INFINITY,
            max_speed: 0.0,
            max_accel: 0.0,
        }
    }
}

impl Tally {
    fn add(&mut self, s: &trust_vehicle::VehicleState, c: &Clearances) {
        if let Some(last) = self.last {
            self.path_length += (s.p - last).norm();
        }
        self.last = Some(s.p);
        self.min_static = self.min_static.min(c.static_m);
        self.min_dynamic = self.min_dynamic.min(c.dynamic_m);
        self.max_speed = self.max_speed.max(s.v.norm());
        self.max_accel = self.max_accel.max(s.a.norm());
    }
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
}
