//! # trust-ros2 — TRUST-Planner as a ROS 2 node, without a ROS install
//!
//! The planner as flown in the simulator (a scenario file's `[planner]` section, built by
//! `trust_planner::build` for the file's vehicle and map), behind ROS 2 topics: it subscribes
//! to `odom` (`nav_msgs/Odometry`), `goal` (`geometry_msgs/PoseStamped`) and `obstacles`
//! (`trust_msgs/MovingObstacleArray`), runs a planning cycle (Algorithm 1,
//! `trust_manager::Manager::step`) every `cycle_period_s`, and publishes `trajectory`
//! (`trajectory_msgs/MultiDOFJointTrajectory`), `path`, `setpoint` (or PX4's
//! `TrajectorySetpoint` on `/fmu/in/trajectory_setpoint`), `markers`, `events` and `/tf` (the
//! odometry as `map → base_link`), with a yaw per [`heading`]; with `use_sim_time` its ROS time
//! is `/clock`'s. With `[cloud]` in its parameters it also subscribes to a point cloud
//! (`sensor_msgs/PointCloud2`, decoded by [`cloud`]) and plans in the online map built from
//! it, committing only to observed free space, as the simulator's unknown-map mode
//! ([`sensing`]). Topics, frames, QoS and parameters: `docs/ros2.md`.
//!
//! Use it to fly the planner on a ROS 2 vehicle or in a ROS 2 simulator. DDS comes from
//! `ros2-client` (pure Rust over RustDDS): the binary `trust-node` builds with cargo alone and
//! talks to ROS 2 nodes on the same domain over the default RMW's wire protocol
//! (`docs/decisions/0023-ros2-client.md`). The message types are serde structs laid out as
//! the `.msg` files ([`msg`]); `trust_msgs` ships as a ROS package in
//! `crates/ros2/msg/trust_msgs` for ROS users to build.
//!
//! The node is split in two: [`NodeCore`] (messages in, messages out, at a clock value it is
//! given; no DDS, unit-tested) and the thin [`dds`] layer. Obstacle observations feed the same
//! EKF forecasts as the simulator's sensing ([`tracker`]).
//!
//! ```no_run
//! use trust_ros2::msg::builtin_interfaces::Time;
//! use trust_ros2::msg::geometry_msgs::{Point, PoseStamped};
//! use trust_ros2::msg::nav_msgs::Odometry;
//! use trust_ros2::{NodeCore, NodeParams, NodeSetup};
//!
//! let setup = NodeSetup::from_scenario("scenarios/quickstart.toml".as_ref())?;
//! let origin = Time { sec: 1_700_000_000, nanosec: 0 };
//! let mut core = NodeCore::new(setup, NodeParams::default(), origin)?;
//! let mut odom = Odometry::default();
//! odom.header.stamp = origin;
//! odom.header.frame_id = "map".into();
//! odom.pose.pose.position = Point { x: 2.0, y: 10.0, z: 3.0 };
//! core.on_odometry(&odom)?;
//! let mut goal = PoseStamped::default();
//! goal.header.frame_id = "map".into();
//! goal.pose.position = Point { x: 38.0, y: 10.0, z: 3.0 };
//! core.on_goal(&goal)?;
//! let out = core.cycle(origin)?.expect("odometry and a goal: a cycle ran");
//! assert!(out.trajectory.is_some());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(missing_docs)]

pub mod cdr;
pub mod cloud;
pub mod convert;
pub mod dds;
pub mod dds_world;
pub mod error;
pub mod heading;
pub mod msg;
pub mod node_core;
pub mod params;
pub mod sensing;
#[doc(hidden)]
pub mod test_support;
pub mod tracker;

pub use error::Ros2Error;
pub use node_core::{CycleOutput, NodeCore, NodeCounters};
pub use params::{NodeParams, NodeSetup};
