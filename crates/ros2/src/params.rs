//! The node's own parameters ([`NodeParams`], a TOML file, `deny_unknown_fields`) and what it
//! takes from a scenario file ([`NodeSetup`]: the planner's `[planner]` section, the vehicle,
//! the map's bounds and static shapes, the obstacle filter's `[sensing]` settings).

use std::path::Path;
use std::sync::Arc;

use serde::{Deserialize, Serialize};
use trust_core::StaticMap;
use trust_planner::{AnyManager, PlannerContext, PlannerSpec};
use trust_predict::EkfParams;
use trust_world::{Scenario, World};

use crate::error::Ros2Error;
use crate::heading::YawMode;
use crate::sensing::CloudParams;

/// `[node]` parameters (all optional; defaults below).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct NodeParams {
    /// The world frame every input must be in and every output is in: ENU, z up (REP 103).
    /// Default `map`.
    pub world_frame: String,
    /// The vehicle's body frame (FLU), the odometry's `child_frame_id` and the trajectory's
    /// joint name. Default `base_link`.
    pub body_frame: String,
    /// Planning cycle period (s), `> 0`. Default 0.1 s: the simulator's replanning period.
    pub cycle_period_s: f64,
    /// Sampling step of `trajectory` and `path` (s), `> 0`. Default 0.05 s.
    pub trajectory_dt_s: f64,
    /// Rate of `setpoint` (Hz), in `[2, 1000]`. Default 50 Hz (PX4 needs > 2 Hz in offboard).
    pub setpoint_rate_hz: f64,
    /// Odometry older than this at a cycle (s) is stale: the cycle is skipped and counted.
    /// Default 0.5 s.
    pub odom_timeout_s: f64,
    /// An obstacle track not observed for this long (s) is dropped. Default 1.0 s.
    pub obstacle_timeout_s: f64,
    /// The yaw policy of the published trajectory and setpoints ([`crate::heading`]); default
    /// `face_velocity` above 0.3 m/s, holding the last yaw (at first the vehicle's) below.
    pub yaw: YawMode,
    /// Publish the latest odometry on `/tf` as the transform `world_frame` → `body_frame`.
    /// Default `true`; set `false` where the vehicle's localization broadcasts that transform
    /// already (two publishers of one transform make it jump).
    pub publish_tf: bool,
    /// Take ROS time from `/clock` (`rosgraph_msgs/Clock`, a simulator's clock) instead of the
    /// system clock, as ROS's `use_sim_time` parameter: stamps, cycles and setpoints follow it.
    /// Default `false`; `trust-node --use-sim-time` sets it.
    pub use_sim_time: bool,
    /// `[cloud]`: subscribe to a `sensor_msgs/PointCloud2` and plan in the online map built
    /// from it, committing only to observed free space ([`crate::sensing`]). Default none: the
    /// planner plans in the scenario's map.
    pub cloud: Option<CloudParams>,
}

impl Default for NodeParams {
    fn default() -> Self {
        NodeParams {
            world_frame: "map".into(),
            body_frame: "base_link".into(),
            cycle_period_s: 0.1,
            trajectory_dt_s: 0.05,
            setpoint_rate_hz: 50.0,
            odom_timeout_s: 0.5,
            obstacle_timeout_s: 1.0,
            yaw: YawMode::default(),
            publish_tf: true,
            use_sim_time: false,
            cloud: None,
        }
    }
}

impl NodeParams {
    /// Reads a parameter file (TOML, the fields of [`NodeParams`] at top level).
    ///
    /// # Errors
    /// [`Ros2Error::Io`] if it cannot be read or parsed (toml's line and column), or
    /// [`Ros2Error::Invalid`] naming the first invalid field.
    pub fn load(path: &Path) -> Result<Self, Ros2Error> {
        let io = |cause: String| Ros2Error::Io {
            path: path.display().to_string(),
            cause,
        };
        let text = std::fs::read_to_string(path).map_err(|e| io(e.to_string()))?;
        let params: NodeParams = toml::from_str(&text).map_err(|e| io(e.to_string()))?;
        params.validate()?;
        Ok(params)
    }

    /// Checks every field, naming the first invalid one.
    ///
    /// # Errors
    /// [`Ros2Error::Invalid`] with the field, the value and the range.
    pub fn validate(&self) -> Result<(), Ros2Error> {
        for (field, value) in [
            ("world_frame", &self.world_frame),
            ("body_frame", &self.body_frame),
        ] {
            if value.is_empty() {
                return Err(Ros2Error::invalid(field, "\"\"", "a frame id"));
            }
        }
        let positive = |field: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(Ros2Error::invalid(field, v, "a finite number > 0"))
            }
        };
        positive("cycle_period_s", self.cycle_period_s)?;
        positive("trajectory_dt_s", self.trajectory_dt_s)?;
        positive("odom_timeout_s", self.odom_timeout_s)?;
        positive("obstacle_timeout_s", self.obstacle_timeout_s)?;
        if !(self.setpoint_rate_hz.is_finite() && (2.0..=1000.0).contains(&self.setpoint_rate_hz)) {
            return Err(Ros2Error::invalid(
                "setpoint_rate_hz",
                self.setpoint_rate_hz,
                "a rate in [2, 1000] Hz",
            ));
        }
        self.yaw.validate()?;
        match &self.cloud {
            Some(c) => c.validate(),
            None => Ok(()),
        }
    }
}

/// What the node takes from a scenario file: the planner as flown in the simulator, built for
/// the file's vehicle and map, and the obstacle filter's settings.
#[derive(Debug)]
pub struct NodeSetup {
    /// The manager of the file's `[planner]` section ([`trust_planner::build`]).
    pub manager: AnyManager,
    /// The static map the planner sees (bounds and static shapes, or the point-cloud ESDF).
    pub map: Arc<StaticMap>,
    /// The vehicle's radius (m).
    pub vehicle_radius_m: f64,
    /// Margin added to the vehicle radius in every forecast's `r_safe` (m),
    /// `[sensing] r_safe_margin_m`.
    pub r_safe_margin_m: f64,
    /// The obstacle filter's parameters, `[sensing.ekf]`.
    pub ekf: EkfParams,
}

impl NodeSetup {
    /// Reads a scenario file (the world's checks and the `[planner]` section's own, as
    /// `trust-sim validate`), builds its map and its planner for its vehicle
    /// ([`trust_planner::build`], the planner seed of the file's trial); the file's moving
    /// obstacles, mission and clocks are ignored (the node gets those over ROS, and its latency
    /// is its cycle's).
    ///
    /// # Errors
    /// [`Ros2Error::World`] with every problem of the file, [`Ros2Error::Invalid`] for the
    /// first problem of its `[planner]` section, [`Ros2Error::Planner`] if the planner cannot be
    /// assembled for the vehicle.
    pub fn from_scenario(path: &Path) -> Result<Self, Ros2Error> {
        let scenario: Scenario<PlannerSpec> = trust_world::load_checked(path)?;
        if let Some(p) = scenario.planner.problems().into_iter().next() {
            return Err(Ros2Error::invalid(p.field, p.value, p.expected));
        }
        let world = World::build(&scenario)?;
        let ctx = PlannerContext {
            limits: world.limits(),
            vehicle_radius_m: world.vehicle_radius_m(),
            static_map_error_m: world.static_map_error_m(),
            seed: world.seeds().planner,
        };
        let mut manager = trust_planner::build(&scenario.planner.resolve(), &ctx)?;
        let map = world.planner_map_shared();
        manager.share_map(Arc::clone(&map));
        Ok(NodeSetup {
            manager,
            map,
            vehicle_radius_m: world.vehicle_radius_m(),
            r_safe_margin_m: scenario.sensing.r_safe_margin_m,
            ekf: scenario.sensing.ekf.clone(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `text` loaded from a file of its own (tests run in parallel threads).
    fn parse(text: &str) -> Result<NodeParams, Ros2Error> {
        static FILES: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
        let k = FILES.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let dir = std::env::temp_dir().join(format!("trust-node-params-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        let path = dir.join(format!("{k}.toml"));
        std::fs::write(&path, text).expect("write");
        let r = NodeParams::load(&path);
        let _ = std::fs::remove_file(&path);
        r
    }

    #[test]
    fn yaw_tf_and_sim_time_read_from_the_parameter_file() {
        let p = parse(
            "publish_tf = false\nuse_sim_time = true\n[yaw]\nkind = \"fixed\"\nyaw_rad = 1.5\n",
        )
        .expect("valid");
        assert_eq!(p.yaw, YawMode::Fixed { yaw_rad: 1.5 });
        assert!(!p.publish_tf && p.use_sim_time);
        let p = parse("[yaw]\nkind = \"face_velocity\"\nmin_speed_m_s = 0.5\n").expect("valid");
        assert_eq!(p.yaw, YawMode::FaceVelocity { min_speed_m_s: 0.5 });
        assert_eq!(parse("").expect("defaults"), NodeParams::default());
        assert_eq!(
            NodeParams::default().yaw,
            YawMode::FaceVelocity { min_speed_m_s: 0.3 }
        );
    }

    #[test]
    fn a_bad_yaw_is_named() {
        let e =
            parse("[yaw]\nkind = \"face_velocity\"\nmin_speed_m_s = -1\n").expect_err("negative");
        assert!(e.to_string().contains("yaw.min_speed_m_s"), "{e}");
        let e = parse("[yaw]\nkind = \"fixed\"\nyaw = 1\n").expect_err("unknown field");
        assert!(e.to_string().contains("yaw"), "{e}");
        assert!(parse("[yaw]\nkind = \"spin\"\n").is_err());
    }
}
