//! `trust_msgs`, our package (`crates/ros2/msg/trust_msgs`, buildable with `colcon`):
//! [`MovingObstacle`], [`MovingObstacleArray`] and [`PlannerEvent`].

use serde::{Deserialize, Serialize};

use crate::msg::Covariance;
use crate::msg::geometry_msgs::{Point, Vector3};
use crate::msg::std_msgs::Header;

/// `trust_msgs/msg/MovingObstacle`: one observed moving obstacle.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct MovingObstacle {
    /// `uint32 id`: stable across messages; one track per id.
    pub id: u32,
    /// `uint8 shape`: [`MovingObstacle::SHAPE_SPHERE`] or [`MovingObstacle::SHAPE_CYLINDER`].
    pub shape: u8,
    /// `geometry_msgs/Vector3 size`: full extents as a marker's `scale` (sphere: `x` =
    /// diameter; vertical cylinder: `x` = diameter, `z` = height), m.
    pub size: Vector3,
    /// `geometry_msgs/Point position`: the centre, in `header.frame_id` (m).
    pub position: Point,
    /// `geometry_msgs/Vector3 velocity` (m/s): the sender's estimate (informational; the node
    /// tracks velocity with its own filter).
    pub velocity: Vector3,
    /// `float64[36] covariance`: row-major, of `(x, y, z, vx, vy, vz)` (informational).
    pub covariance: Covariance,
}
ros_message!(MovingObstacle, "trust_msgs", "MovingObstacle");

impl MovingObstacle {
    /// `shape`: a ball.
    pub const SHAPE_SPHERE: u8 = 0;
    /// `shape`: a vertical (z) cylinder.
    pub const SHAPE_CYLINDER: u8 = 1;
}

/// `trust_msgs/msg/MovingObstacleArray`: the obstacles observed at `header.stamp`.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct MovingObstacleArray {
    /// `std_msgs/Header header`.
    pub header: Header,
    /// `MovingObstacle[] obstacles`.
    pub obstacles: Vec<MovingObstacle>,
}
ros_message!(MovingObstacleArray, "trust_msgs", "MovingObstacleArray");

/// `trust_msgs/msg/PlannerEvent`: what one planning cycle did.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct PlannerEvent {
    /// `std_msgs/Header header`: the cycle's time.
    pub header: Header,
    /// `uint64 cycle_count`: cycles run so far, this one included.
    pub cycle_count: u64,
    /// `float64 cycle_time_ms`: wall time of the cycle (ms).
    pub cycle_time_ms: f64,
    /// `bool has_plan`: whether a plan is committed after the cycle.
    pub has_plan: bool,
    /// `bool fallback`: whether the plan is a fallback manoeuvre.
    pub fallback: bool,
    /// `string[] events`: the manager's events, one JSON object each.
    pub events: Vec<String>,
}
ros_message!(PlannerEvent, "trust_msgs", "PlannerEvent");
