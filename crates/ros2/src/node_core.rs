//! [`NodeCore`]: the node without DDS. Messages go in ([`NodeCore::on_odometry`],
//! [`NodeCore::on_goal`], [`NodeCore::on_obstacles`], with `[cloud]` [`NodeCore::on_cloud`]);
//! a cycle at a clock value the caller gives
//! ([`NodeCore::cycle`]) runs the planner and returns the messages to publish; setpoints are
//! sampled from the committed plan at any clock value ([`NodeCore::setpoint`],
//! [`NodeCore::px4_setpoint`]). No clock is read inside and nothing is sent, so every step is
//! reproducible and testable alone (the style's rule for step functions).
//!
//! A bad message (another frame, a NaN pose, a zero quaternion, out-of-order obstacles) is an
//! [`Ros2Error`] naming the field; the message is ignored and counted
//! ([`NodeCounters::rejected_count`]), the node's state is unchanged.

use std::sync::Arc;

use trust_core::{Forecast, Scene, State, StaticMap, Vec3};
use trust_flightstack::frame::FrameTransform;
use trust_flightstack::px4::{self, TrajectorySetpoint};
use trust_planner::AnyManager;

use crate::convert::{
    Clock, goal_position, markers, odometry_state, odometry_transform, path_message,
    trajectory_message, trajectory_point, unit_quaternion,
};
use crate::error::Ros2Error;
use crate::heading::{Heading, yaw_of};
use crate::msg::builtin_interfaces::Time;
use crate::msg::geometry_msgs::PoseStamped;
use crate::msg::nav_msgs::{Odometry, Path};
use crate::msg::sensor_msgs::PointCloud2;
use crate::msg::tf2_msgs::{TFMessage, TransformStamped};
use crate::msg::trajectory_msgs::MultiDOFJointTrajectory;
use crate::msg::trust_msgs::{MovingObstacleArray, PlannerEvent};
use crate::msg::visualization_msgs::MarkerArray;
use crate::params::{NodeParams, NodeSetup};
use crate::sensing::CloudMap;
use crate::tracker::{Tracker, observation};

/// What the node counted since it started.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct NodeCounters {
    /// Odometry messages accepted.
    pub odom_count: u64,
    /// Goals accepted.
    pub goal_count: u64,
    /// Obstacle messages accepted.
    pub obstacles_count: u64,
    /// Messages rejected (and ignored) because a field was invalid.
    pub rejected_count: u64,
    /// Planning cycles run.
    pub cycle_count: u64,
    /// Cycles skipped: no odometry or no goal yet.
    pub idle_count: u64,
    /// Cycles skipped because the odometry was older than `odom_timeout_s`.
    pub stale_count: u64,
    /// Point clouds accepted into the online map (`[cloud]`).
    pub cloud_count: u64,
    /// Point clouds rejected (another frame, a stamp outside the odometry, a malformed
    /// cloud); each is also in `rejected_count`.
    pub cloud_rejected_count: u64,
    /// Points of accepted clouds inserted as rays.
    pub cloud_point_count: u64,
    /// Points of accepted clouds skipped: NaN or infinite, or at the sensor's origin.
    pub cloud_skipped_point_count: u64,
    /// Clouds dropped unread because a newer one was waiting ([`NodeCore::drop_clouds`]).
    pub cloud_dropped_count: u64,
}

/// The messages of one planning cycle.
#[derive(Debug, Clone, PartialEq)]
pub struct CycleOutput {
    /// `trajectory`: the committed plan from now on, sampled every `trajectory_dt_s` (`None`
    /// when the manager has no plan).
    pub trajectory: Option<MultiDOFJointTrajectory>,
    /// `path`: the same samples as poses.
    pub path: Option<Path>,
    /// `markers`: the kept branches and the forecasts.
    pub markers: MarkerArray,
    /// `events`: what the cycle did.
    pub event: PlannerEvent,
}

/// The ROS-free node (module docs).
#[derive(Debug)]
pub struct NodeCore {
    params: NodeParams,
    clock: Clock,
    manager: AnyManager,
    map: Arc<StaticMap>,
    tracker: Tracker,
    odom: Option<State>,
    goal: Option<Vec3>,
    forecasts: Vec<Forecast>,
    heading: Heading,
    /// The latest accepted odometry as the world-to-body transform.
    odom_transform: Option<TransformStamped>,
    /// With `[cloud]`: the online map the planner plans in.
    cloud: Option<CloudMap>,
    counters: NodeCounters,
}

impl NodeCore {
    /// A node planning with `setup` (from a scenario file, [`NodeSetup::from_scenario`]) and
    /// `params`, whose node time 0 is the ROS time `origin` (the DDS layer passes its start
    /// time, whole seconds).
    ///
    /// # Errors
    /// [`Ros2Error::Invalid`] for invalid `params` or a non-finite vehicle radius.
    pub fn new(setup: NodeSetup, params: NodeParams, origin: Time) -> Result<Self, Ros2Error> {
        params.validate()?;
        let r = setup.vehicle_radius_m + setup.r_safe_margin_m;
        if !(r.is_finite() && r >= 0.0) {
            return Err(Ros2Error::invalid(
                "vehicle.radius_m + sensing.r_safe_margin_m",
                r,
                "a finite number >= 0",
            ));
        }
        let tracker = Tracker::new(setup.ekf, r, params.obstacle_timeout_s);
        let cloud = match &params.cloud {
            Some(c) => Some(CloudMap::new(
                c.clone(),
                *setup.map.bounds(),
                setup.vehicle_radius_m,
            )?),
            None => None,
        };
        Ok(NodeCore {
            clock: Clock {
                origin_s: origin.as_seconds(),
            },
            manager: setup.manager,
            map: setup.map,
            tracker,
            odom: None,
            goal: None,
            forecasts: Vec::new(),
            heading: Heading::new(params.yaw)?,
            odom_transform: None,
            cloud,
            counters: NodeCounters::default(),
            params,
        })
    }

    /// The parameters.
    pub fn params(&self) -> &NodeParams {
        &self.params
    }

    /// The clock mapping node time to ROS time.
    pub fn clock(&self) -> &Clock {
        &self.clock
    }

    /// The planner (its committed plan is [`trust_manager::Manager::plan`]).
    pub fn manager(&self) -> &AnyManager {
        &self.manager
    }

    /// The counters.
    pub fn counters(&self) -> NodeCounters {
        self.counters
    }

    /// The goal, once one was accepted.
    pub fn goal(&self) -> Option<Vec3> {
        self.goal
    }

    /// The online map built from the point clouds (`[cloud]`), once the first odometry
    /// started it; `None` without `[cloud]`.
    pub fn online_map(&self) -> Option<&trust_sensing::LocalMap> {
        self.cloud.as_ref()?.map()
    }

    /// Counts a rejected message and passes its error on.
    fn rejected<T>(&mut self, r: Result<T, Ros2Error>) -> Result<T, Ros2Error> {
        if r.is_err() {
            self.counters.rejected_count += 1;
        }
        r
    }

    /// Takes an odometry message as the vehicle's latest state ([`odometry_state`]).
    ///
    /// # Errors
    /// As [`odometry_state`]; the message is ignored and counted.
    pub fn on_odometry(&mut self, msg: &Odometry) -> Result<(), Ros2Error> {
        let r = odometry_state(msg, &self.params.world_frame, &self.clock).and_then(|state| {
            let q = unit_quaternion("odom.pose.pose.orientation", &msg.pose.pose.orientation)?;
            Ok((state, q, odometry_transform(msg, &self.params.body_frame)?))
        });
        let (state, q, transform) = self.rejected(r)?;
        if let Some(cloud) = &mut self.cloud {
            let r = cloud.observe_odometry(state.t, state.p, q, state.v);
            self.rejected(r)?;
        }
        self.odom = Some(state);
        self.heading.observe_vehicle(yaw_of(&q));
        self.odom_transform = Some(transform);
        self.counters.odom_count += 1;
        Ok(())
    }

    /// `/tf`: the latest accepted odometry as the transform from the world frame to
    /// `body_frame`, stamped with the odometry's stamp; `None` before the first odometry.
    pub fn transform(&self) -> Option<TFMessage> {
        Some(TFMessage {
            transforms: vec![self.odom_transform.clone()?],
        })
    }

    /// Takes a goal ([`goal_position`]); it replaces the previous one.
    ///
    /// # Errors
    /// As [`goal_position`]; the message is ignored and counted.
    pub fn on_goal(&mut self, msg: &PoseStamped) -> Result<(), Ros2Error> {
        let r = goal_position(msg, &self.params.world_frame);
        self.goal = Some(self.rejected(r)?);
        self.counters.goal_count += 1;
        Ok(())
    }

    /// Feeds the obstacles observed at the message's stamp to their tracks
    /// ([`crate::tracker`]).
    ///
    /// # Errors
    /// [`Ros2Error::Invalid`] naming the field (frame, an obstacle's position, shape or size,
    /// a stamp before a track's last observation); the whole message is ignored and counted.
    pub fn on_obstacles(&mut self, msg: &MovingObstacleArray) -> Result<(), Ros2Error> {
        let r = self.observe(msg);
        self.rejected(r)?;
        self.counters.obstacles_count += 1;
        Ok(())
    }

    fn observe(&mut self, msg: &MovingObstacleArray) -> Result<(), Ros2Error> {
        if msg.header.frame_id != self.params.world_frame {
            return Err(Ros2Error::invalid(
                "obstacles.header.frame_id",
                format!("{:?}", msg.header.frame_id),
                format!("the node's world frame {:?}", self.params.world_frame),
            ));
        }
        let t = self.clock.node_time(&msg.header.stamp);
        let observations = msg
            .obstacles
            .iter()
            .enumerate()
            .map(|(i, o)| observation(&format!("obstacles.obstacles[{i}]"), o))
            .collect::<Result<Vec<_>, _>>()?;
        self.tracker.observe(t, &observations)
    }

    /// Folds a point cloud into the online map ([`crate::sensing`]: its points decoded by
    /// [`crate::cloud::decode_points`], placed by its frame and the odometry at its stamp).
    ///
    /// # Errors
    /// [`Ros2Error::Invalid`] naming the field: the node has no `[cloud]` section, a frame
    /// other than the world, body or sensor frame, a stamp outside the odometry kept, a
    /// malformed cloud; [`Ros2Error::Sensing`] if the map rejects the scan. The cloud is
    /// ignored and counted (`rejected_count`, `cloud_rejected_count`).
    pub fn on_cloud(&mut self, msg: &PointCloud2) -> Result<(), Ros2Error> {
        let r = self.insert_cloud(msg);
        if r.is_err() {
            self.counters.cloud_rejected_count += 1;
        }
        let (inserted, skipped) = self.rejected(r)?;
        self.counters.cloud_count += 1;
        self.counters.cloud_point_count += inserted as u64;
        self.counters.cloud_skipped_point_count += skipped as u64;
        Ok(())
    }

    /// Counts `n` clouds dropped unread (the DDS layer folds only the newest waiting one).
    pub fn drop_clouds(&mut self, n: u64) {
        self.counters.cloud_dropped_count += n;
    }

    fn insert_cloud(&mut self, msg: &PointCloud2) -> Result<(usize, usize), Ros2Error> {
        let Some(cloud) = &mut self.cloud else {
            return Err(Ros2Error::invalid(
                "cloud",
                "a point cloud",
                "a [cloud] section in the node's parameters",
            ));
        };
        let t = self.clock.node_time(&msg.header.stamp);
        let decoded = crate::cloud::decode_points(msg)?;
        let (inserted, at_origin) = cloud.insert(
            &msg.header.frame_id,
            (&self.params.world_frame, &self.params.body_frame),
            t,
            self.params.odom_timeout_s,
            &decoded.points,
        )?;
        Ok((inserted, decoded.skipped_count + at_origin))
    }

    /// One planning cycle at ROS time `now`: the latest odometry, extrapolated at its velocity
    /// to `now`, is the measured state; the tracks' forecasts at `now` and the map are the
    /// scene; `Manager::step` plans toward the goal. `Ok(None)` (nothing to publish) without a
    /// goal or odometry yet.
    ///
    /// # Errors
    /// [`Ros2Error::Invalid`] naming `odom.header.stamp` when the odometry is older than
    /// `odom_timeout_s` (the cycle is skipped and counted); [`Ros2Error::Plan`] if the planner
    /// rejects its input; conversion errors naming the field.
    pub fn cycle(&mut self, now: Time) -> Result<Option<CycleOutput>, Ros2Error> {
        let t = self.clock.node_time(&now);
        let (Some(odom), Some(goal)) = (self.odom, self.goal) else {
            self.counters.idle_count += 1;
            return Ok(None);
        };
        let age = t - odom.t;
        if age > self.params.odom_timeout_s {
            self.counters.stale_count += 1;
            return Err(Ros2Error::invalid(
                "odom.header.stamp",
                format!("{age} s old"),
                format!(
                    "odometry at most odom_timeout_s = {} s old",
                    self.params.odom_timeout_s
                ),
            ));
        }
        let measured = State {
            t,
            p: odom.p + odom.v * age.max(0.0),
            v: odom.v,
            a: odom.a,
        };
        self.forecasts = self.tracker.forecasts(t)?;
        // With `[cloud]`: plan in the online map, commit only to observed free space (as
        // `trust_flight`'s unknown-map mode).
        let sensed = match &mut self.cloud {
            Some(cloud) => cloud.for_cycle()?,
            None => None,
        };
        let map = match &sensed {
            Some((map, check)) => {
                self.manager.share_map(Arc::clone(map));
                self.manager.set_commit_check(Some(Arc::clone(check)));
                Arc::clone(map)
            }
            None => Arc::clone(&self.map),
        };
        drop(sensed);
        let scene = Scene::new(&map, &self.forecasts, t)?;
        let stepped = self.manager.step(t, &measured, &goal, &scene);
        if self.cloud.is_some() {
            // The check holds the map: drop it before the next cloud, or that copies the map.
            self.manager.set_commit_check(None);
        }
        let report = stepped?;
        self.counters.cycle_count += 1;
        let p = &self.params;
        let (trajectory, path) = match self.manager.plan() {
            Some(plan) => {
                // The plan ahead is sampled with copies of the yaw stream; the stream itself
                // advances to the present only.
                let ahead = self.heading.ahead()?;
                let trajectory = trajectory_message(
                    plan,
                    t,
                    p.trajectory_dt_s,
                    &self.clock,
                    (&p.world_frame, &p.body_frame),
                    &mut ahead.clone(),
                )?;
                let path = path_message(
                    plan,
                    t,
                    p.trajectory_dt_s,
                    &self.clock,
                    &p.world_frame,
                    &mut ahead.clone(),
                )?;
                let now = plan.state(t.clamp(plan.t_start(), plan.t_end()));
                self.heading.next(&now.v, &now.a)?;
                (Some(trajectory), Some(path))
            }
            None => (None, None),
        };
        let main = self.manager.main();
        let branches: Vec<_> = self
            .manager
            .branches()
            .iter()
            .map(|b| (b.traj(), Some(b.id) == main))
            .collect();
        let markers = MarkerArray {
            markers: markers(
                &branches,
                &self.forecasts,
                t,
                p.trajectory_dt_s,
                &self.clock,
                &p.world_frame,
            )?,
        };
        let event = PlannerEvent {
            header: self.clock.header(t, &p.world_frame)?,
            cycle_count: self.counters.cycle_count,
            cycle_time_ms: report.timing.wall_ms,
            has_plan: self.manager.plan().is_some(),
            fallback: report.fallback.is_some(),
            events: report
                .events
                .iter()
                .map(|e| {
                    serde_json::to_string(e).unwrap_or_else(|e| format!("{{\"error\":\"{e}\"}}"))
                })
                .collect(),
        };
        Ok(Some(CycleOutput {
            trajectory,
            path,
            markers,
            event,
        }))
    }

    /// The node time of ROS time `now`, clamped into the committed plan's span (a vehicle
    /// before the plan starts holds its start, after it ends its end); `None` without a plan.
    fn plan_time(&self, now: &Time) -> Option<f64> {
        let plan = self.manager.plan()?;
        Some(
            self.clock
                .node_time(now)
                .clamp(plan.t_start(), plan.t_end()),
        )
    }

    /// The setpoint at ROS time `now`: a one-point `MultiDOFJointTrajectory` stamped `now`
    /// (`time_from_start` 0) of the committed plan at `now` (its end after it ends), its yaw
    /// the yaw stream's next ([`crate::heading`]); `None` without a plan.
    ///
    /// # Errors
    /// Conversion errors naming the field (a non-finite sample, a stamp out of range).
    pub fn setpoint(&mut self, now: Time) -> Result<Option<MultiDOFJointTrajectory>, Ros2Error> {
        let (Some(plan), Some(t)) = (self.manager.plan(), self.plan_time(&now)) else {
            return Ok(None);
        };
        Ok(Some(MultiDOFJointTrajectory {
            header: now.into_header(&self.params.world_frame),
            joint_names: vec![self.params.body_frame.clone()],
            points: vec![trajectory_point(plan, t, t, &mut self.heading)?],
        }))
    }

    /// The PX4 setpoint at ROS time `now` ([`trust_flightstack::px4::setpoint_at`]: NED, the
    /// yaw stream's yaw as `π/2 − yaw` and its rate negated, NaN with `uncontrolled`), stamped
    /// with `now` in µs; `None` without a plan.
    ///
    /// # Errors
    /// [`Ros2Error::FlightStack`] naming the field that does not fit PX4's `f32`.
    pub fn px4_setpoint(&mut self, now: Time) -> Result<Option<TrajectorySetpoint>, Ros2Error> {
        let (Some(t), Some(plan)) = (self.plan_time(&now), self.manager.plan()) else {
            return Ok(None);
        };
        let us = (now.as_seconds() * 1e6).max(0.0) as u64;
        Ok(Some(px4::setpoint_at(
            plan,
            t,
            us,
            &FrameTransform::identity(),
            self.heading.tracker()?,
        )?))
    }
}

#[cfg(test)]
mod tests {
    use approx::assert_relative_eq;

    use std::f64::consts::{FRAC_PI_2, PI, TAU};

    use super::*;
    use crate::heading::YawMode;
    use crate::msg::geometry_msgs::{Point, Quaternion, Vector3};
    use crate::msg::trust_msgs::MovingObstacle;
    use crate::msg::visualization_msgs::Marker;

    const ORIGIN: Time = Time {
        sec: 1_700_000_000,
        nanosec: 0,
    };

    fn at(t: f64) -> Time {
        Time::from_seconds(ORIGIN.as_seconds() + t).expect("in range")
    }

    fn core() -> NodeCore {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../scenarios/quickstart.toml");
        let setup = NodeSetup::from_scenario(&path).expect("quickstart builds");
        NodeCore::new(setup, NodeParams::default(), ORIGIN).expect("valid")
    }

    fn odom(t: f64, p: [f64; 3]) -> Odometry {
        let mut m = Odometry::default();
        m.header.stamp = at(t);
        m.header.frame_id = "map".into();
        m.child_frame_id = "base_link".into();
        m.pose.pose.position = Point {
            x: p[0],
            y: p[1],
            z: p[2],
        };
        m
    }

    fn goal(p: [f64; 3]) -> PoseStamped {
        let mut m = PoseStamped::default();
        m.header.stamp = ORIGIN;
        m.header.frame_id = "map".into();
        m.pose.position = Point {
            x: p[0],
            y: p[1],
            z: p[2],
        };
        m
    }

    /// The cycles at 0 and 0.1 s with the vehicle at rest at `m`'s pose: at rest the manager
    /// holds its place in the first cycle while the first route is searched on its thread; the
    /// second flies toward the goal. Returns the second cycle's output.
    fn past_the_route_wait(core: &mut NodeCore, m: &Odometry) -> CycleOutput {
        core.cycle(at(0.0)).expect("cycle").expect("ran");
        let mut later = m.clone();
        later.header.stamp = at(0.1);
        core.on_odometry(&later).expect("valid");
        core.cycle(at(0.1)).expect("cycle").expect("ran")
    }

    fn field_of(e: &Ros2Error) -> &str {
        match e {
            Ros2Error::Invalid { field, .. } => field,
            other => panic!("expected Invalid, got {other}"),
        }
    }

    #[test]
    fn odometry_and_goal_give_a_trajectory_sampling_the_managers_plan() {
        let mut core = core();
        let m = odom(0.0, [2.0, 10.0, 3.0]);
        core.on_odometry(&m).expect("valid");
        core.on_goal(&goal([38.0, 10.0, 3.0])).expect("valid");
        let out = past_the_route_wait(&mut core, &m);
        let traj = out.trajectory.expect("a plan");
        let plan = core.manager().plan().expect("committed plan").clone();
        assert_eq!(traj.header.frame_id, "map");
        assert_eq!(traj.joint_names, vec!["base_link".to_string()]);
        assert!(traj.points.len() > 10, "{} samples", traj.points.len());
        let start = core.clock().node_time(&traj.header.stamp);
        for (k, point) in traj.points.iter().enumerate() {
            let t = start + point.time_from_start.as_seconds();
            let p = plan.position(t);
            let v = plan.velocity(t);
            let tr = point.transforms[0].translation;
            assert_relative_eq!(tr.x, p.x, epsilon = 1e-6);
            assert_relative_eq!(tr.y, p.y, epsilon = 1e-6);
            assert_relative_eq!(tr.z, p.z, epsilon = 1e-6);
            assert_relative_eq!(point.velocities[0].linear.x, v.x, epsilon = 1e-6);
            if k > 0 && k + 1 < traj.points.len() {
                assert_relative_eq!(
                    point.time_from_start.as_seconds(),
                    k as f64 * 0.05,
                    epsilon = 1e-6
                );
            }
        }
        let last = traj.points.last().expect("points");
        assert_relative_eq!(
            start + last.time_from_start.as_seconds(),
            plan.t_end(),
            epsilon = 1e-6
        );
        let path = out.path.expect("a path");
        assert_eq!(path.poses.len(), traj.points.len());
        assert_eq!(out.event.cycle_count, 2);
        assert!(out.event.has_plan);
        assert!(
            out.markers.markers.iter().any(|m| m.ns == "branches"),
            "the branches are drawn"
        );
        // The setpoint is the plan at the clock value given.
        let sp = core.setpoint(at(0.3)).expect("valid").expect("a plan");
        let p = plan.position(0.3_f64.clamp(plan.t_start(), plan.t_end()));
        assert_relative_eq!(
            sp.points[0].transforms[0].translation.x,
            p.x,
            epsilon = 1e-6
        );
        assert_eq!(sp.header.stamp, at(0.3));
        // PX4: NED, so north (our y) first, down = -z.
        let px4 = core.px4_setpoint(at(0.3)).expect("valid").expect("a plan");
        assert_relative_eq!(f64::from(px4.position[0]), p.y, epsilon = 1e-4);
        assert_relative_eq!(f64::from(px4.position[1]), p.x, epsilon = 1e-4);
        assert_relative_eq!(f64::from(px4.position[2]), -p.z, epsilon = 1e-4);
    }

    /// The yaw of a rotation about z alone, decoded on its own: `2 atan2(z, w)`.
    fn yaw_of_rotation(q: &Quaternion) -> f64 {
        assert_eq!((q.x, q.y), (0.0, 0.0), "a rotation about z alone: {q:?}");
        assert_relative_eq!(q.z * q.z + q.w * q.w, 1.0, epsilon = 1e-12);
        2.0 * q.z.atan2(q.w)
    }

    /// `a` wrapped to `[−π, π)`.
    fn wrapped(a: f64) -> f64 {
        (a + PI).rem_euclid(TAU) - PI
    }

    /// The heading of the plan's horizontal velocity at node time `t` (ENU, from east).
    fn heading(plan: &trust_core::PolyTraj, t: f64) -> f64 {
        let v = plan.velocity(t);
        v.y.atan2(v.x)
    }

    #[test]
    fn the_yaw_faces_the_velocity_holds_when_slow_and_px4_gets_it_in_ned() {
        let mut core = core();
        // The vehicle faces north; the goal lies east-north-east, past the cylinder at (12, 8):
        // the plan curves.
        let mut m = odom(0.0, [2.0, 4.0, 3.0]);
        m.pose.pose.orientation = Quaternion::from_yaw(FRAC_PI_2);
        core.on_odometry(&m).expect("valid");
        core.on_goal(&goal([20.0, 9.0, 3.0])).expect("valid");
        let out = past_the_route_wait(&mut core, &m);
        let plan = core.manager().plan().expect("a plan").clone();
        // The plan starts at rest: its first sample holds the vehicle's heading.
        let traj = out.trajectory.expect("a trajectory");
        let first = &traj.points[0];
        assert_eq!(yaw_of_rotation(&first.transforms[0].rotation), FRAC_PI_2);
        assert_eq!(first.velocities[0].angular.z, 0.0);

        // The setpoint stream, every 20 ms to beyond the plan's end, against the plan's own
        // velocity: facing it when faster than 0.3 m/s with its heading's rate (a central
        // difference), else the last yaw; PX4's yaw from north clockwise (the NED velocity
        // (north, east) = (v_y, v_x)), its rate negated.
        let (mut fast, mut turning, mut slow) = (0, 0, 0);
        let mut last_yaw = FRAC_PI_2;
        let steps = ((plan.t_end() + 0.5) / 0.02) as usize;
        for k in 0..=steps {
            let t = k as f64 * 0.02;
            let sp = core.setpoint(at(t)).expect("valid").expect("a plan");
            let px4 = core.px4_setpoint(at(t)).expect("valid").expect("a plan");
            let point = &sp.points[0];
            let yaw = yaw_of_rotation(&point.transforms[0].rotation);
            let rate = point.velocities[0].angular.z;
            let (px4_yaw, px4_rate) = (f64::from(px4.yaw), f64::from(px4.yawspeed));
            assert!(yaw.is_finite() && rate.is_finite() && px4_yaw.is_finite());
            // ψ_ned = π/2 − ψ_enu, in [−π, π].
            assert!((-PI..=PI).contains(&px4_yaw), "{px4_yaw}");
            assert!(wrapped(px4_yaw - (FRAC_PI_2 - yaw)).abs() < 2e-6, "t {t}");
            assert!(
                (px4_rate + rate).abs() <= 1e-5 * rate.abs().max(1.0),
                "t {t}"
            );
            let tc = t.clamp(plan.t_start(), plan.t_end());
            let v = plan.velocity(tc);
            let speed = (v.x * v.x + v.y * v.y).sqrt();
            if speed > 0.3 {
                fast += 1;
                // (The stamps are whole nanoseconds: the node's time is t within 1e-9 s.)
                assert!(wrapped(yaw - heading(&plan, tc)).abs() < 1e-6, "t {t}");
                let north_east = v.x.atan2(v.y);
                assert!(wrapped(px4_yaw - north_east).abs() < 2e-6, "t {t}");
                let h = 1e-5;
                if tc - h > plan.t_start() && tc + h < plan.t_end() {
                    let fd = wrapped(heading(&plan, tc + h) - heading(&plan, tc - h)) / (2.0 * h);
                    assert!(
                        (rate - fd).abs() <= 1e-4 * fd.abs().max(1.0),
                        "t {t}: {rate} vs {fd}"
                    );
                    turning += usize::from(rate.abs() > 0.01);
                }
            } else {
                slow += 1;
                assert_eq!((yaw, rate), (last_yaw, 0.0), "t {t}");
            }
            last_yaw = yaw;
        }
        assert!(fast > 20 && slow > 0, "{fast} fast, {slow} slow setpoints");
        assert!(
            turning > 20,
            "the plan curves: some yaw rate ({turning} setpoints)"
        );
    }

    #[test]
    fn uncontrolled_yaw_is_nan_for_px4_and_the_vehicles_heading_in_ros_messages() {
        let setup = NodeSetup::from_scenario(
            &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../scenarios/quickstart.toml"),
        )
        .expect("quickstart");
        let params = NodeParams {
            yaw: YawMode::Uncontrolled,
            ..NodeParams::default()
        };
        let mut core = NodeCore::new(setup, params, ORIGIN).expect("valid");
        let mut m = odom(0.0, [2.0, 10.0, 3.0]);
        m.pose.pose.orientation = Quaternion::from_yaw(-0.4);
        core.on_odometry(&m).expect("valid");
        core.on_goal(&goal([38.0, 10.0, 3.0])).expect("valid");
        core.cycle(at(0.0)).expect("cycle").expect("ran");
        let px4 = core.px4_setpoint(at(0.5)).expect("valid").expect("a plan");
        assert!(px4.yaw.is_nan() && px4.yawspeed.is_nan());
        assert!(px4.position.iter().all(|x| x.is_finite()));
        let sp = core.setpoint(at(0.5)).expect("valid").expect("a plan");
        assert_relative_eq!(
            yaw_of_rotation(&sp.points[0].transforms[0].rotation),
            -0.4,
            epsilon = 1e-12
        );
        assert_eq!(sp.points[0].velocities[0].angular.z, 0.0);
    }

    #[test]
    fn the_latest_odometry_is_the_tf_transform_to_the_body_frame() {
        let mut core = core();
        assert!(core.transform().is_none());
        let mut m = odom(0.25, [2.0, 10.0, 3.0]);
        // The twist in the world frame: the child frame of /tf is still the body frame.
        m.child_frame_id = "map".into();
        // Not normalized: /tf carries the unit quaternion.
        let q = Quaternion::from_yaw(0.7);
        m.pose.pose.orientation = Quaternion {
            x: 0.0,
            y: 0.0,
            z: 2.0 * q.z,
            w: 2.0 * q.w,
        };
        core.on_odometry(&m).expect("valid");
        let tf = core.transform().expect("after an odometry");
        assert_eq!(tf.transforms.len(), 1);
        let t = &tf.transforms[0];
        assert_eq!(t.header, m.header);
        assert_eq!(t.child_frame_id, "base_link");
        assert_eq!(
            Vec3::from(t.transform.translation),
            Vec3::new(2.0, 10.0, 3.0)
        );
        assert_relative_eq!(t.transform.rotation.z, q.z, epsilon = 1e-15);
        assert_relative_eq!(t.transform.rotation.w, q.w, epsilon = 1e-15);
        // A rejected odometry leaves it as it was.
        let mut bad = odom(0.5, [f64::NAN, 0.0, 0.0]);
        bad.child_frame_id = "map".into();
        assert!(core.on_odometry(&bad).is_err());
        assert_eq!(core.transform().expect("kept"), tf);
    }

    #[test]
    fn without_a_goal_or_odometry_nothing_is_published() {
        let mut core = core();
        assert!(core.cycle(at(0.0)).expect("no error").is_none());
        core.on_odometry(&odom(0.0, [2.0, 10.0, 3.0]))
            .expect("valid");
        assert!(core.cycle(at(0.1)).expect("no error").is_none());
        assert!(core.setpoint(at(0.1)).expect("no error").is_none());
        assert_eq!(core.counters().idle_count, 2);
        assert_eq!(core.counters().cycle_count, 0);
    }

    #[test]
    fn a_nan_pose_is_a_typed_error_counted_and_ignored() {
        let mut core = core();
        let e = core
            .on_odometry(&odom(0.0, [f64::NAN, 10.0, 3.0]))
            .expect_err("NaN");
        assert_eq!(field_of(&e), "odom.pose.pose.position");
        assert_eq!(core.counters().rejected_count, 1);
        assert_eq!(core.counters().odom_count, 0);
        core.on_goal(&goal([38.0, 10.0, 3.0])).expect("valid");
        assert!(
            core.cycle(at(0.0)).expect("no error").is_none(),
            "no odometry yet"
        );
        let mut g = goal([1.0, 2.0, 3.0]);
        g.pose.position.z = f64::INFINITY;
        let e = core.on_goal(&g).expect_err("infinite");
        assert_eq!(field_of(&e), "goal.pose.position");
        assert_eq!(
            core.goal(),
            Some(Vec3::new(38.0, 10.0, 3.0)),
            "the old goal stays"
        );
    }

    #[test]
    fn a_zero_quaternion_or_another_frame_is_rejected() {
        let mut core = core();
        let mut m = odom(0.0, [2.0, 10.0, 3.0]);
        m.pose.pose.orientation = Quaternion {
            x: 0.0,
            y: 0.0,
            z: 0.0,
            w: 0.0,
        };
        let e = core.on_odometry(&m).expect_err("zero quaternion");
        assert_eq!(field_of(&e), "odom.pose.pose.orientation");
        let mut m = odom(0.0, [2.0, 10.0, 3.0]);
        m.header.frame_id = "odom".into();
        let e = core.on_odometry(&m).expect_err("frame");
        assert_eq!(field_of(&e), "odom.header.frame_id");
        assert!(e.to_string().contains("\"map\""), "{e}");
        assert_eq!(core.counters().rejected_count, 2);
    }

    #[test]
    fn body_frame_velocity_is_rotated_into_the_world() {
        let mut core = core();
        let mut m = odom(0.0, [2.0, 10.0, 3.0]);
        // Yaw 90°: the body's x axis points north (world y).
        m.pose.pose.orientation = Quaternion::from_yaw(std::f64::consts::FRAC_PI_2);
        m.twist.twist.linear = Vector3 {
            x: 1.0,
            y: 0.0,
            z: 0.0,
        };
        core.on_odometry(&m).expect("valid");
        let s = core.odom.expect("accepted");
        assert_relative_eq!(s.v.x, 0.0, epsilon = 1e-12);
        assert_relative_eq!(s.v.y, 1.0, epsilon = 1e-12);
    }

    #[test]
    fn stale_odometry_skips_the_cycle_with_a_typed_error() {
        let mut core = core();
        core.on_odometry(&odom(0.0, [2.0, 10.0, 3.0]))
            .expect("valid");
        core.on_goal(&goal([38.0, 10.0, 3.0])).expect("valid");
        let e = core.cycle(at(2.0)).expect_err("2 s old");
        assert_eq!(field_of(&e), "odom.header.stamp");
        assert_eq!(core.counters().stale_count, 1);
    }

    fn obstacle(id: u32, shape: u8, p: [f64; 3]) -> MovingObstacle {
        MovingObstacle {
            id,
            shape,
            size: Vector3 {
                x: 1.0,
                y: 1.0,
                z: 2.0,
            },
            position: Point {
                x: p[0],
                y: p[1],
                z: p[2],
            },
            ..MovingObstacle::default()
        }
    }

    #[test]
    fn obstacles_become_forecasts_and_bad_ones_are_rejected_whole() {
        let mut core = core();
        let mut msg = MovingObstacleArray::default();
        msg.header.frame_id = "map".into();
        for k in 0..5 {
            msg.header.stamp = at(-0.5 + 0.1 * f64::from(k));
            msg.obstacles = vec![
                obstacle(7, MovingObstacle::SHAPE_SPHERE, [20.0, 10.0, 3.0]),
                obstacle(9, MovingObstacle::SHAPE_CYLINDER, [30.0, 4.0, 3.0]),
            ];
            core.on_obstacles(&msg).expect("valid");
        }
        assert_eq!(core.tracker.len(), 2);
        // A bad shape: the whole message is ignored.
        msg.header.stamp = at(0.0);
        msg.obstacles[1].shape = 7;
        let e = core.on_obstacles(&msg).expect_err("shape 7");
        assert_eq!(field_of(&e), "obstacles.obstacles[1].shape");
        // Out of order.
        msg.header.stamp = at(-1.0);
        msg.obstacles[1].shape = MovingObstacle::SHAPE_SPHERE;
        let e = core.on_obstacles(&msg).expect_err("older");
        assert_eq!(field_of(&e), "obstacles.header.stamp");
        assert_eq!(core.counters().rejected_count, 2);
        assert_eq!(core.counters().obstacles_count, 5);

        core.on_odometry(&odom(0.0, [2.0, 10.0, 3.0]))
            .expect("valid");
        core.on_goal(&goal([38.0, 10.0, 3.0])).expect("valid");
        let out = core.cycle(at(0.0)).expect("cycle").expect("ran");
        let drawn: Vec<i32> = out
            .markers
            .markers
            .iter()
            .filter(|m| m.ns == "forecasts")
            .map(|m| m.kind)
            .collect();
        assert_eq!(drawn, vec![Marker::SPHERE, Marker::CYLINDER]);
        // Tracks not seen for obstacle_timeout_s are dropped.
        core.on_odometry(&odom(2.0, [2.0, 10.0, 3.0]))
            .expect("valid");
        core.cycle(at(2.0)).expect("cycle").expect("ran");
        assert!(core.tracker.is_empty());
    }

    fn cloud_core(cloud: crate::sensing::CloudParams) -> NodeCore {
        let setup = NodeSetup::from_scenario(
            &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("../../scenarios/quickstart.toml"),
        )
        .expect("quickstart");
        let params = NodeParams {
            cloud: Some(cloud),
            ..NodeParams::default()
        };
        NodeCore::new(setup, params, ORIGIN).expect("valid")
    }

    fn cloud(t: f64, frame: &str, points: &[Vec3]) -> PointCloud2 {
        crate::cloud::encode_points(
            at(t).into_header(frame),
            points,
            &crate::cloud::CloudLayout::default(),
        )
        .expect("valid layout")
    }

    #[test]
    fn a_body_frame_cloud_is_placed_by_the_odometry_at_its_stamp() {
        use trust_sensing::VoxelState;
        let mut core = cloud_core(crate::sensing::CloudParams::default());
        assert!(core.online_map().is_none(), "no odometry yet");
        let e = core
            .on_cloud(&cloud(0.0, "base_link", &[Vec3::new(4.0, 0.0, 0.0)]))
            .expect_err("before any odometry");
        assert_eq!(field_of(&e), "cloud.header.stamp");
        // Facing north (yaw 90°), 1 m/s forward: from (2.05, 10.05) at 0 s to (2.05, 10.25)
        // at 0.2 s. (Voxel centres: 0.1 m voxels.)
        for (t, y) in [(0.0, 10.05), (0.2, 10.25)] {
            let mut m = odom(t, [2.05, y, 3.05]);
            m.pose.pose.orientation = Quaternion::from_yaw(FRAC_PI_2);
            m.twist.twist.linear = Vector3 {
                x: 1.0,
                y: 0.0,
                z: 0.0,
            };
            core.on_odometry(&m).expect("valid");
        }
        // At 0.1 s the vehicle is at (2.05, 10.15, 3.05): body x is world +y, body y world −x.
        let nan = Vec3::new(f64::NAN, 0.0, 0.0);
        core.on_cloud(&cloud(
            0.1,
            "base_link",
            &[Vec3::new(4.0, 0.0, 0.0), Vec3::new(4.0, 1.0, 0.0), nan],
        ))
        .expect("valid");
        let map = core.online_map().expect("started");
        for p in [Vec3::new(2.05, 14.15, 3.05), Vec3::new(1.05, 14.15, 3.05)] {
            assert_eq!(map.state(&p), VoxelState::Occupied, "{p:?}");
        }
        for y in [11.55, 12.55, 13.55] {
            assert_eq!(
                map.state(&Vec3::new(2.05, y, 3.05)),
                VoxelState::Free,
                "y {y}"
            );
        }
        assert_eq!(
            map.state(&Vec3::new(4.05, 12.05, 3.05)),
            VoxelState::Unknown
        );
        let c = core.counters();
        assert_eq!(
            (
                c.cloud_count,
                c.cloud_point_count,
                c.cloud_skipped_point_count
            ),
            (1, 2, 1)
        );
        assert_eq!((c.rejected_count, c.cloud_rejected_count), (1, 1));

        // Another frame: rejected, counted, the map unchanged.
        let e = core
            .on_cloud(&cloud(0.1, "camera", &[Vec3::new(0.0, 0.0, 6.0)]))
            .expect_err("unknown frame");
        assert_eq!(field_of(&e), "cloud.header.frame_id");
        assert!(e.to_string().contains("base_link"), "{e}");
        // Too far past the odometry (odom_timeout_s 0.5 s).
        let e = core
            .on_cloud(&cloud(0.9, "map", &[Vec3::new(2.05, 16.05, 3.05)]))
            .expect_err("stale");
        assert_eq!(field_of(&e), "cloud.header.stamp");
        let c = core.counters();
        assert_eq!((c.cloud_count, c.cloud_rejected_count), (1, 3));
    }

    #[test]
    fn a_sensor_frame_cloud_goes_through_the_mount_and_a_node_without_cloud_refuses_one() {
        use trust_sensing::VoxelState;
        // An optical frame (z forward, x right, y down) 0.1 m ahead of the body.
        let params = crate::sensing::CloudParams {
            sensor_frame: Some("camera".into()),
            sensor_translation_m: [0.1, 0.0, 0.0],
            sensor_rpy_rad: [-FRAC_PI_2, 0.0, -FRAC_PI_2],
            ..crate::sensing::CloudParams::default()
        };
        let mut core = cloud_core(params);
        let mut m = odom(0.0, [2.05, 10.05, 3.05]);
        m.pose.pose.orientation = Quaternion::from_yaw(FRAC_PI_2);
        core.on_odometry(&m).expect("valid");
        // 4 m ahead of the camera and 1 m to its right: the body's (4.1, −1, 0), facing north.
        core.on_cloud(&cloud(0.0, "camera", &[Vec3::new(1.0, 0.0, 4.0)]))
            .expect("valid");
        let map = core.online_map().expect("started");
        assert_eq!(
            map.state(&Vec3::new(3.05, 14.15, 3.05)),
            VoxelState::Occupied
        );
        // The ray starts at the camera, 0.1 m north of the vehicle.
        assert_eq!(map.state(&Vec3::new(2.55, 12.15, 3.05)), VoxelState::Free);

        let mut plain = core_without_cloud();
        let e = plain
            .on_cloud(&cloud(0.0, "map", &[Vec3::new(1.0, 0.0, 4.0)]))
            .expect_err("no [cloud]");
        assert_eq!(field_of(&e), "cloud");
        assert_eq!(plain.counters().cloud_rejected_count, 1);
        assert!(plain.online_map().is_none());
    }

    fn core_without_cloud() -> NodeCore {
        core()
    }

    #[test]
    fn with_a_cloud_the_planner_plans_in_the_sensed_map_not_the_scenarios() {
        let mut core = cloud_core(crate::sensing::CloudParams::default());
        let m = odom(0.0, [2.0, 10.0, 3.0]);
        core.on_odometry(&m).expect("valid");
        core.on_goal(&goal([38.0, 10.0, 3.0])).expect("valid");
        // A wall across the way at x = 6.05, y in [8, 12], z in [1, 5], seen in the map frame.
        let wall: Vec<Vec3> = (0..41)
            .flat_map(|i| (0..41).map(move |k| (i, k)))
            .map(|(i, k)| Vec3::new(6.05, 8.0 + 0.1 * f64::from(i), 1.0 + 0.1 * f64::from(k)))
            .collect();
        core.on_cloud(&cloud(0.0, "map", &wall)).expect("valid");
        assert_eq!(core.counters().cloud_point_count, wall.len() as u64);
        past_the_route_wait(&mut core, &m);
        let main = core.manager().main().expect("a main branch");
        let branch = core
            .manager()
            .branches()
            .iter()
            .find(|b| b.id == main)
            .expect("main");
        let traj = branch.traj();
        // The main branch goes round the sensed wall (vehicle radius 0.5 m), which the
        // scenario's map does not have.
        let mut t = traj.t_start();
        while t <= traj.t_end() {
            let p = traj.position(t);
            if (5.0..7.0).contains(&p.x) {
                assert!(
                    !(7.4..12.6).contains(&p.y) || !(0.4..5.6).contains(&p.z),
                    "through the wall at t {t}: {p:?}"
                );
            }
            t += 0.02;
        }
        // Without the cloud the same cycle flies straight through x = 6.
        let mut plain = core_without_cloud();
        plain.on_odometry(&m).expect("valid");
        plain.on_goal(&goal([38.0, 10.0, 3.0])).expect("valid");
        past_the_route_wait(&mut plain, &m);
        let plan = plain.manager().plan().expect("a plan");
        let crossing = (0..1000)
            .map(|k| {
                plan.position(plan.t_start() + (plan.t_end() - plan.t_start()) * k as f64 / 1000.0)
            })
            .find(|p| p.x > 6.0)
            .expect("it passes x = 6");
        assert!((crossing.y - 10.0).abs() < 1.0, "{crossing:?}");
    }
}
