//! `rosgraph_msgs`: [`Clock`], the simulated time on `/clock`.

use serde::{Deserialize, Serialize};

use crate::msg::builtin_interfaces::Time;

/// `rosgraph_msgs/msg/Clock`: the current time of a simulated clock. Nodes with `use_sim_time`
/// take their ROS time from the latest one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct Clock {
    /// `builtin_interfaces/Time clock`.
    pub clock: Time,
}
ros_message!(Clock, "rosgraph_msgs", "Clock");
