//! The thin DDS layer: one ros2-client node with the subscriptions and publishers of
//! `docs/ros2.md`, and a loop ([`DdsNode::run`]) that drains the subscriptions into a
//! [`NodeCore`], runs a cycle every `cycle_period_s` and a setpoint every
//! `1/setpoint_rate_hz` of ROS time (the system clock, or `/clock` with
//! [`DdsOptions::use_sim_time`]), and publishes what the core returns. Everything else is in
//! the core.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration as StdDuration, SystemTime, UNIX_EPOCH};

use ros2_client::qos::{Durability, History, WhenFull};
use ros2_client::{Context, MessageTypeName, Name, Node, NodeName, NodeOptions, QosProfile};
use ros2_client::{Publisher, Subscription};
use serde::{Deserialize, Serialize};
use trust_flightstack::px4::TrajectorySetpoint;

use crate::error::Ros2Error;
use crate::msg::RosMessage;
use crate::msg::builtin_interfaces::Time;
use crate::msg::geometry_msgs::PoseStamped;
use crate::msg::nav_msgs::{Odometry, Path};
use crate::msg::rosgraph_msgs::Clock;
use crate::msg::sensor_msgs::PointCloud2;
use crate::msg::tf2_msgs::TFMessage;
use crate::msg::trajectory_msgs::MultiDOFJointTrajectory;
use crate::msg::trust_msgs::{MovingObstacleArray, PlannerEvent};
use crate::msg::visualization_msgs::MarkerArray;
use crate::node_core::NodeCore;

/// Topic names, relative to the node's namespace (`/` by default, so `odom` is `/odom`, the
/// DDS topic `rt/odom`).
pub mod topics {
    /// In: `nav_msgs/Odometry`.
    pub const ODOM: &str = "odom";
    /// In: `geometry_msgs/PoseStamped`.
    pub const GOAL: &str = "goal";
    /// In: `trust_msgs/MovingObstacleArray`.
    pub const OBSTACLES: &str = "obstacles";
    /// Out: `trajectory_msgs/MultiDOFJointTrajectory`, the plan.
    pub const TRAJECTORY: &str = "trajectory";
    /// Out: `nav_msgs/Path`.
    pub const PATH: &str = "path";
    /// Out: `trajectory_msgs/MultiDOFJointTrajectory` with one point (or PX4's setpoint).
    pub const SETPOINT: &str = "setpoint";
    /// Out, with `--px4`: `px4_msgs/TrajectorySetpoint`, absolute (PX4's uXRCE-DDS topic).
    pub const PX4_SETPOINT: &str = "/fmu/in/trajectory_setpoint";
    /// Out: `visualization_msgs/MarkerArray`.
    pub const MARKERS: &str = "markers";
    /// Out: `trust_msgs/PlannerEvent`.
    pub const EVENTS: &str = "events";
    /// Out: `tf2_msgs/TFMessage`, the world-to-body transform of each odometry (absolute, as
    /// tf2's broadcasters).
    pub const TF: &str = "/tf";
    /// In with `use_sim_time` (out of `trust-sim dds-world`): `rosgraph_msgs/Clock`, absolute.
    pub const CLOCK: &str = "/clock";
    /// In with `[cloud]` (its `topic`; this is the default): `sensor_msgs/PointCloud2`.
    pub const CLOUD: &str = "cloud";
}

/// `px4_msgs/msg/TrajectorySetpoint` as a ROS message: the flight stack's struct
/// ([`TrajectorySetpoint`], PX4 `trust_flightstack::px4::PX4_RELEASE`), same wire layout.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct Px4TrajectorySetpoint(pub TrajectorySetpoint);
crate::msg::ros_message!(Px4TrajectorySetpoint, "px4_msgs", "TrajectorySetpoint");

/// Plans and paths: reliable, volatile, keep last 1 (a late subscriber waits for the next
/// cycle; only the newest plan matters).
pub fn plan_qos() -> QosProfile {
    QosProfile::publisher_default()
        .reliability_reliable(WhenFull::Fail)
        .durability(Durability::Volatile)
        .history(History::KeepLast { depth: 1 })
}

/// Setpoints: best-effort, volatile, keep last 1 (a lost one is replaced 20 ms later; PX4's
/// `/fmu/in` topics are best-effort).
pub fn setpoint_qos() -> QosProfile {
    QosProfile::subscription_default()
        .durability(Durability::Volatile)
        .history(History::KeepLast { depth: 1 })
}

/// Inputs: best-effort, volatile, keep last 10 (matches reliable and best-effort writers, so
/// both a sensor-data odometry and RViz's reliable goal are received).
pub fn input_qos() -> QosProfile {
    QosProfile::subscription_default()
        .durability(Durability::Volatile)
        .history(History::KeepLast { depth: 10 })
}

/// Point clouds: best effort, volatile, keep last 5 (rclcpp's `SensorDataQoS`; a reliable
/// writer matches too).
pub fn cloud_qos() -> QosProfile {
    QosProfile::subscription_default()
        .durability(Durability::Volatile)
        .history(History::KeepLast { depth: 5 })
}

/// `/tf`: reliable, volatile, keep last 100, as tf2's `TransformBroadcaster` (RViz's and
/// Foxglove's listeners match it).
pub fn tf_qos() -> QosProfile {
    plan_qos().history(History::KeepLast { depth: 100 })
}

/// `/clock`: the writer (`trust-sim dds-world`) reliable, volatile, keep last 1, so that both
/// reliable readers and rclcpp's best-effort clock subscription match; the node's reader is
/// best effort, keep last 1 (rclcpp's `ClockQoS`), matching either kind of writer.
pub fn clock_writer_qos() -> QosProfile {
    plan_qos()
}

/// `/clock`'s reader (see [`clock_writer_qos`]).
pub fn clock_reader_qos() -> QosProfile {
    QosProfile::subscription_default()
        .durability(Durability::Volatile)
        .history(History::KeepLast { depth: 1 })
}

/// How the node joins the DDS domain.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DdsOptions {
    /// The node's namespace (`/`).
    pub namespace: String,
    /// The node's name (`trust_planner`).
    pub node_name: String,
    /// Publish PX4's `TrajectorySetpoint` on [`topics::PX4_SETPOINT`] instead of `setpoint`.
    pub px4: bool,
    /// Publish each accepted odometry on [`topics::TF`] (`NodeParams::publish_tf`).
    pub publish_tf: bool,
    /// ROS time from [`topics::CLOCK`] instead of the system clock
    /// (`NodeParams::use_sim_time`).
    pub use_sim_time: bool,
    /// Subscribe to point clouds on this topic (`NodeParams::cloud`'s `topic`); `None`: no
    /// cloud input.
    pub cloud_topic: Option<String>,
}

impl Default for DdsOptions {
    fn default() -> Self {
        DdsOptions {
            namespace: "/".into(),
            node_name: "trust_planner".into(),
            px4: false,
            publish_tf: true,
            use_sim_time: false,
            cloud_topic: None,
        }
    }
}

impl DdsOptions {
    /// The defaults with `params`'s `publish_tf`, `use_sim_time` and cloud topic.
    pub fn for_params(params: &crate::NodeParams) -> Self {
        DdsOptions {
            publish_tf: params.publish_tf,
            use_sim_time: params.use_sim_time,
            cloud_topic: params.cloud.as_ref().map(|c| c.topic.clone()),
            ..DdsOptions::default()
        }
    }
}

/// The absolute ROS name of topic `name` in `namespace`: an absolute `name` (`/fmu/in/x`) stays
/// as it is, a relative one is put under the namespace (`odom` in `/` is `/odom`, in `/uav1`
/// `/uav1/odom`).
///
/// ros2-client 0.12 makes the DDS topic of a relative name in the root namespace `rt//odom`
/// (namespace `/`, then a `/` separator), which no other ROS 2 implementation reads as
/// `/odom`; resolving every name here keeps the DDS names `rt/odom`, `rt/uav1/odom`. Found by
/// the Cyclone DDS interop test (`tests/cyclone_interop.rs`).
pub fn resolve_name(namespace: &str, name: &str) -> String {
    if name.starts_with('/') {
        name.to_owned()
    } else {
        format!("{}/{name}", namespace.trim_end_matches('/'))
    }
}

/// A topic of message type `M` named `name` (relative to the node's namespace, see
/// [`resolve_name`]).
///
/// # Errors
/// [`Ros2Error::Dds`] for an invalid name or a failed creation.
pub fn topic<M: RosMessage>(
    node: &Node,
    name: &str,
    qos: &QosProfile,
) -> Result<ros2_client::dds::rustdds::Topic, Ros2Error> {
    let full = resolve_name(node.namespace(), name);
    let n = Name::parse(&full).map_err(|e| Ros2Error::dds(format!("topic name {full}"), e))?;
    node.create_topic(&n, MessageTypeName::new(M::PACKAGE, M::NAME), qos)
        .map_err(|e| Ros2Error::dds(format!("create topic {name}"), e))
}

/// A publisher of `M` on `name`.
///
/// # Errors
/// As [`topic`].
pub fn publisher<M: RosMessage>(
    node: &mut Node,
    name: &str,
    qos: QosProfile,
) -> Result<Publisher<M>, Ros2Error> {
    let t = topic::<M>(node, name, &qos)?;
    node.create_publisher(&t, Some(qos))
        .map_err(|e| Ros2Error::dds(format!("create publisher {name}"), e))
}

/// A subscription to `M` on `name`.
///
/// # Errors
/// As [`topic`].
pub fn subscription<M: RosMessage + 'static>(
    node: &mut Node,
    name: &str,
    qos: QosProfile,
) -> Result<Subscription<M>, Ros2Error> {
    let t = topic::<M>(node, name, &qos)?;
    node.create_subscription(&t, Some(qos))
        .map_err(|e| Ros2Error::dds(format!("create subscription {name}"), e))
}

/// Takes every sample `sub` holds and hands it to `accept`; errors (a sample that does not
/// decode, a message `accept` rejects) go to `warn` under `topic`.
fn drain<M: RosMessage + 'static>(
    sub: &Subscription<M>,
    topic: &str,
    warn: &mut dyn FnMut(&str, &Ros2Error),
    mut accept: impl FnMut(M) -> Result<(), Ros2Error>,
) {
    loop {
        match sub.take() {
            Ok(Some((m, _))) => {
                if let Err(e) = accept(m) {
                    warn(topic, &e);
                }
            }
            Ok(None) => break,
            Err(e) => {
                warn(topic, &Ros2Error::dds(format!("take from {topic}"), e));
                break;
            }
        }
    }
}

/// Where setpoints go.
enum SetpointOut {
    Trajectory(Publisher<MultiDOFJointTrajectory>),
    Px4(Publisher<Px4TrajectorySetpoint>),
}

/// The node's DDS side (module docs).
pub struct DdsNode {
    node: Node,
    odom: Subscription<Odometry>,
    goal: Subscription<PoseStamped>,
    obstacles: Subscription<MovingObstacleArray>,
    /// With `[cloud]`: the point clouds and their topic.
    cloud: Option<(Subscription<PointCloud2>, String)>,
    trajectory: Publisher<MultiDOFJointTrajectory>,
    path: Publisher<Path>,
    setpoint: SetpointOut,
    markers: Publisher<MarkerArray>,
    events: Publisher<PlannerEvent>,
    tf: Option<Publisher<TFMessage>>,
    /// `/clock` with `use_sim_time`, and the latest time it gave.
    clock: Option<(Subscription<Clock>, Option<Time>)>,
}

impl std::fmt::Debug for DdsNode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DdsNode")
            .field("node", &self.node.fully_qualified_name())
            .finish_non_exhaustive()
    }
}

/// The system clock as a ROS time.
pub fn system_time() -> Time {
    let d = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .unwrap_or_default();
    Time {
        sec: i32::try_from(d.as_secs()).unwrap_or(i32::MAX),
        nanosec: d.subsec_nanos(),
    }
}

impl DdsNode {
    /// Creates the node in `context` with its subscriptions and publishers, and starts its
    /// ros2-client spinner (ROS graph discovery) on a thread of its own.
    ///
    /// # Errors
    /// [`Ros2Error::Dds`] naming what could not be created.
    pub fn new(context: &Context, options: &DdsOptions) -> Result<Self, Ros2Error> {
        let name = NodeName::new(&options.namespace, &options.node_name)
            .map_err(|e| Ros2Error::dds("node name", e))?;
        let mut node = context
            .new_node(name, NodeOptions::new().enable_rosout(false))
            .map_err(|e| Ros2Error::dds("create node", e))?;
        let odom = subscription(&mut node, topics::ODOM, input_qos())?;
        let goal = subscription(&mut node, topics::GOAL, input_qos())?;
        let obstacles = subscription(&mut node, topics::OBSTACLES, input_qos())?;
        let cloud = match &options.cloud_topic {
            Some(name) => Some((subscription(&mut node, name, cloud_qos())?, name.clone())),
            None => None,
        };
        let trajectory = publisher(&mut node, topics::TRAJECTORY, plan_qos())?;
        let path = publisher(&mut node, topics::PATH, plan_qos())?;
        let setpoint = if options.px4 {
            SetpointOut::Px4(publisher(&mut node, topics::PX4_SETPOINT, setpoint_qos())?)
        } else {
            SetpointOut::Trajectory(publisher(&mut node, topics::SETPOINT, setpoint_qos())?)
        };
        let markers = publisher(&mut node, topics::MARKERS, plan_qos())?;
        let events = publisher(
            &mut node,
            topics::EVENTS,
            plan_qos().history(History::KeepLast { depth: 10 }),
        )?;
        let tf = if options.publish_tf {
            Some(publisher(&mut node, topics::TF, tf_qos())?)
        } else {
            None
        };
        let clock = if options.use_sim_time {
            Some((
                subscription(&mut node, topics::CLOCK, clock_reader_qos())?,
                None,
            ))
        } else {
            None
        };
        let spinner = node
            .spinner()
            .map_err(|e| Ros2Error::dds("create spinner", e))?;
        std::thread::Builder::new()
            .name("ros2-spinner".into())
            .spawn(move || futures::executor::block_on(spinner.spin()))
            .map_err(|e| Ros2Error::dds("start spinner thread", e))?;
        Ok(DdsNode {
            node,
            odom,
            goal,
            obstacles,
            cloud,
            trajectory,
            path,
            setpoint,
            markers,
            events,
            tf,
            clock,
        })
    }

    /// The ROS time now: the system clock, or with `use_sim_time` the latest `/clock` received
    /// (`None` before the first, as ROS's time is zero until then: nothing runs).
    pub fn now(&mut self) -> Option<Time> {
        let Some((sub, latest)) = &mut self.clock else {
            return Some(system_time());
        };
        while let Ok(Some((m, _))) = sub.take() {
            *latest = Some(m.clock);
        }
        *latest
    }

    /// With `use_sim_time`, waits for the first `/clock` (polling every 10 ms) until `stop` is
    /// set; otherwise the system time at once.
    pub fn wait_for_time(&mut self, stop: &AtomicBool) -> Option<Time> {
        loop {
            if let Some(t) = self.now() {
                return Some(t);
            }
            if stop.load(Ordering::Relaxed) {
                return None;
            }
            std::thread::sleep(StdDuration::from_millis(10));
        }
    }

    /// Hands every message received so far to `core`; a rejected message, or one that does
    /// not decode, goes to `warn`. Publishes `/tf` once after new odometry was accepted.
    pub fn receive(&mut self, core: &mut NodeCore, warn: &mut dyn FnMut(&str, &Ros2Error)) {
        let odom_count = core.counters().odom_count;
        drain(&self.odom, topics::ODOM, warn, |m| core.on_odometry(&m));
        if core.counters().odom_count > odom_count
            && let (Some(tf), Some(m)) = (&self.tf, core.transform())
            && let Err(e) = tf.publish(m)
        {
            warn(topics::TF, &Ros2Error::dds("publish tf", e));
        }
        if let Some((sub, name)) = &self.cloud {
            // After the odometry: a cloud is placed by the odometry at its stamp. Only the
            // newest waiting cloud is folded in; older ones are dropped and counted (a node
            // behind its sensor catches up instead of mapping the past).
            let mut newest = None;
            let mut dropped = 0;
            drain(sub, name, warn, |m| {
                dropped += u64::from(newest.replace(m).is_some());
                Ok(())
            });
            core.drop_clouds(dropped);
            if let Some(m) = newest
                && let Err(e) = core.on_cloud(&m)
            {
                warn(name, &e);
            }
        }
        drain(&self.goal, topics::GOAL, warn, |m| core.on_goal(&m));
        drain(&self.obstacles, topics::OBSTACLES, warn, |m| {
            core.on_obstacles(&m)
        });
    }

    /// Runs one cycle of `core` at `now` and publishes its messages (the trajectory first);
    /// returns the planning cycle's own wall time (ms, the manager's step, as in `events`), or
    /// `None` when no cycle ran (no odometry or goal yet).
    ///
    /// # Errors
    /// The cycle's error (nothing published), or [`Ros2Error::Dds`] if a write fails.
    pub fn cycle(&mut self, core: &mut NodeCore, now: Time) -> Result<Option<f64>, Ros2Error> {
        let Some(out) = core.cycle(now)? else {
            return Ok(None);
        };
        let planning_ms = out.event.cycle_time_ms;
        if let Some(t) = out.trajectory {
            self.trajectory
                .publish(t)
                .map_err(|e| Ros2Error::dds("publish trajectory", e))?;
        }
        if let Some(p) = out.path {
            self.path
                .publish(p)
                .map_err(|e| Ros2Error::dds("publish path", e))?;
        }
        self.markers
            .publish(out.markers)
            .map_err(|e| Ros2Error::dds("publish markers", e))?;
        self.events
            .publish(out.event)
            .map_err(|e| Ros2Error::dds("publish events", e))?;
        Ok(Some(planning_ms))
    }

    /// Publishes the setpoint of `core` at `now` (nothing without a plan).
    ///
    /// # Errors
    /// The conversion's error, or [`Ros2Error::Dds`] if the write fails.
    pub fn setpoint(&mut self, core: &mut NodeCore, now: Time) -> Result<(), Ros2Error> {
        match &self.setpoint {
            SetpointOut::Trajectory(p) => {
                if let Some(s) = core.setpoint(now)? {
                    p.publish(s)
                        .map_err(|e| Ros2Error::dds("publish setpoint", e))?;
                }
            }
            SetpointOut::Px4(p) => {
                if let Some(s) = core.px4_setpoint(now)? {
                    p.publish(Px4TrajectorySetpoint(s))
                        .map_err(|e| Ros2Error::dds("publish setpoint", e))?;
                }
            }
        }
        Ok(())
    }

    /// Runs the node until `stop` is set: receives continuously (polling every 1 ms), runs a
    /// cycle every `cycle_period_s` and a setpoint every `1/setpoint_rate_hz` of ROS time
    /// ([`DdsNode::now`]: with `use_sim_time` nothing runs before the first `/clock`, and the
    /// timers restart when the clock goes back). Errors of a cycle or a setpoint go to `warn`
    /// and the loop goes on.
    pub fn run(
        &mut self,
        core: &mut NodeCore,
        stop: &AtomicBool,
        warn: &mut dyn FnMut(&str, &Ros2Error),
    ) {
        let mut cycle_timer = Timer::new(core.params().cycle_period_s);
        let mut setpoint_timer = Timer::new(1.0 / core.params().setpoint_rate_hz);
        while !stop.load(Ordering::Relaxed) {
            self.receive(core, warn);
            if let Some(now) = self.now() {
                let s = now.as_seconds();
                if cycle_timer.due(s)
                    && let Err(e) = self.cycle(core, now)
                {
                    warn("cycle", &e);
                }
                if setpoint_timer.due(s)
                    && let Err(e) = self.setpoint(core, now)
                {
                    warn(topics::SETPOINT, &e);
                }
            }
            std::thread::sleep(StdDuration::from_millis(1));
        }
    }
}

/// A periodic timer on ROS time (s).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Timer {
    period_s: f64,
    /// The next tick; `None` before the first (which is due at once).
    next_s: Option<f64>,
    /// The latest time seen.
    last_s: f64,
}

impl Timer {
    fn new(period_s: f64) -> Self {
        Timer {
            period_s,
            next_s: None,
            last_s: f64::NEG_INFINITY,
        }
    }

    /// Whether a tick is due at time `now_s`; if so, the next one is scheduled a period later
    /// (after an overrun, a period from now: missed ticks are skipped, not run back to back).
    /// A clock that went back (a simulator restarted) restarts the timer.
    fn due(&mut self, now_s: f64) -> bool {
        if now_s < self.last_s {
            self.next_s = None;
        }
        self.last_s = now_s;
        let next = self.next_s.unwrap_or(now_s);
        if now_s < next {
            return false;
        }
        let mut following = next + self.period_s;
        if following < now_s {
            following = now_s + self.period_s;
        }
        self.next_s = Some(following);
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The DDS topic of `name` for a node in `namespace`, as ros2-client writes it.
    fn dds_topic(namespace: &str, name: &str) -> String {
        let node = NodeName::new(namespace, "n").expect("node name");
        Name::parse(&resolve_name(namespace, name))
            .expect("valid name")
            .to_dds_name("rt", &node, "")
    }

    #[test]
    fn timers_tick_on_ros_time_skip_overruns_and_restart_when_it_goes_back() {
        // Binary fractions: the sums are exact.
        let mut t = Timer::new(0.25);
        let ticks: Vec<f64> = [0.0, 0.125, 0.25, 0.375, 0.5, 1.375, 1.5, 1.625]
            .into_iter()
            .filter(|&s| t.due(1000.0 + s))
            .collect();
        // The overrun to 1.375 skips 0.75..1.25; the next tick is 1.625.
        assert_eq!(ticks, vec![0.0, 0.25, 0.5, 1.375, 1.625]);
        // The clock restarts at 0: a tick at once, then every period.
        assert!(t.due(0.0));
        assert!(!t.due(0.125));
        assert!(t.due(0.25));
    }

    #[test]
    fn relative_names_in_the_root_namespace_are_rt_slash_name_not_rt_double_slash() {
        assert_eq!(dds_topic("/", topics::ODOM), "rt/odom");
        assert_eq!(dds_topic("/uav1", topics::ODOM), "rt/uav1/odom");
        assert_eq!(
            dds_topic("/", topics::PX4_SETPOINT),
            "rt/fmu/in/trajectory_setpoint"
        );
        assert_eq!(
            dds_topic("/uav1", topics::PX4_SETPOINT),
            "rt/fmu/in/trajectory_setpoint"
        );
        assert_eq!(dds_topic("/uav1", topics::TF), "rt/tf");
        assert_eq!(dds_topic("/uav1", topics::CLOCK), "rt/clock");
    }
}
