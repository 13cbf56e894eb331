//! What the crate's tests and benches share (doc-hidden, not an API): the quickstart node and
//! the messages they send it.

use std::path::PathBuf;

use ros2_client::{Context, ContextOptions};
use trust_core::Vec3;

use crate::dds::{DdsNode, DdsOptions, system_time};
use crate::error::Ros2Error;
use crate::msg::builtin_interfaces::Time;
use crate::msg::geometry_msgs::{Point, PoseStamped};
use crate::msg::nav_msgs::Odometry;
use crate::{NodeCore, NodeParams, NodeSetup};

/// `scenarios/quickstart.toml` of the repository.
pub fn quickstart() -> PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/quickstart.toml")
}

/// A node core planning quickstart with the default parameters, node time 0 at `origin`.
///
/// # Errors
/// As [`NodeSetup::from_scenario`] and [`NodeCore::new`].
pub fn quickstart_core(origin: Time) -> Result<NodeCore, Ros2Error> {
    let setup = NodeSetup::from_scenario(&quickstart())?;
    NodeCore::new(setup, NodeParams::default(), origin)
}

/// The quickstart node of `trust-node` on DDS domain `domain` with the default options: its
/// core (node time 0 at the current whole second of the system clock) and its DDS side.
///
/// # Errors
/// As [`quickstart_core`] and [`DdsNode::new`].
pub fn quickstart_dds_node(domain: u16) -> Result<(NodeCore, DdsNode), Ros2Error> {
    quickstart_dds_node_with(domain, NodeParams::default())
}

/// As [`quickstart_dds_node`] with `params` (its DDS options from them).
///
/// # Errors
/// As [`quickstart_dds_node`].
pub fn quickstart_dds_node_with(
    domain: u16,
    params: NodeParams,
) -> Result<(NodeCore, DdsNode), Ros2Error> {
    let origin = Time {
        sec: system_time().sec,
        nanosec: 0,
    };
    let options = DdsOptions::for_params(&params);
    let core = NodeCore::new(NodeSetup::from_scenario(&quickstart())?, params, origin)?;
    let context = Context::with_options(ContextOptions::new().domain_id(domain))
        .map_err(|e| Ros2Error::dds("create DDS participant", e))?;
    let node = DdsNode::new(&context, &options)?;
    Ok((core, node))
}

/// An odometry at `stamp` in `map`: position `p`, velocity `v` in `child_frame_id`,
/// identity orientation.
pub fn odometry(stamp: Time, child_frame_id: &str, p: Vec3, v: Vec3) -> Odometry {
    let mut m = Odometry {
        header: stamp.into_header("map"),
        child_frame_id: child_frame_id.into(),
        ..Odometry::default()
    };
    m.pose.pose.position = p.into();
    m.twist.twist.linear = v.into();
    m
}

/// A goal at `p` in `map`, stamped `stamp`.
pub fn goal(stamp: Time, p: Vec3) -> PoseStamped {
    let mut m = PoseStamped {
        header: stamp.into_header("map"),
        ..PoseStamped::default()
    };
    m.pose.position = Point::from(p);
    m
}
