//! The node's online map from point clouds (`[cloud]` in the parameter file): each
//! `sensor_msgs/PointCloud2` on the `cloud` topic becomes a scan (rays from the sensor's origin
//! to its points) folded into the same rolling-window map as the simulator's unknown-map mode
//! (`trust_flight::map_sensing::OnlineMap`: log-odds voxels, the take-off ball and the body's
//! ball known free, the export to the planner, FASTER's known-free commit check). The planner
//! then plans in the exported map and commits only to observed free space, as `trust-sim run`
//! with `[sensing.static]` other than `"known"`. Without `[cloud]` the node plans in the
//! scenario's map, as before.
//!
//! **Frames.** A cloud stamped in `world_frame` has its points in the world; one in
//! `body_frame` is moved into the world by the vehicle's pose at the cloud's stamp; one in
//! `sensor_frame` (when set) by that pose and the sensor's mount on the body
//! (`sensor_translation_m`, `sensor_rpy_rad`). Any other frame is rejected (counted, logged):
//! the node reads no TF. The rays start at the sensor's origin, the mount's translation from the
//! vehicle at the stamp (the vehicle's position without a mount).
//!
//! **The pose at a stamp** comes from the odometry kept over the last [`POSE_HISTORY_S`]:
//! between two odometry messages the position is interpolated linearly and the orientation by
//! slerp; after the latest, the position is extrapolated at its velocity for at most
//! `odom_timeout_s`, the orientation held. A cloud older than the odometry kept, or newer than
//! that, is rejected (a cloud usually lags the odometry by its processing time, well within a
//! second).
//!
//! **Ranges.** A point farther than `max_range_m` from the sensor is a ray without a return
//! clipped at that range (free space up to it, nothing occupied: OctoMap's `maxrange` of
//! `insertPointCloud`); a point within 1 µm of the sensor is skipped. NaN or infinite points
//! carry no direction and are skipped ([`crate::cloud`]).

use std::collections::VecDeque;
use std::sync::Arc;

use nalgebra::{Isometry3, Translation3, UnitQuaternion};
use serde::{Deserialize, Serialize};
use trust_core::{Aabb, StaticMap, Vec3};
use trust_flight::map_sensing::OnlineMap;
use trust_manager::CommitCheck;
use trust_sensing::{DepthCameraParams, LocalMap, RayMeasurement, ReturnKind, Scan};
use trust_world::map_sensing::{MAX_BLIND_REACH_M, MapSpec, StaticSensor, WINDOW_HALF_WIDTH_M};

use crate::error::Ros2Error;

/// How long odometry is kept to place a cloud (s): 1 s.
pub const POSE_HISTORY_S: f64 = 1.0;

/// Farthest `max_range_m` (m): 1000 m (a `LocalMap` takes rays up to 1e4 m).
pub const MAX_RANGE_LIMIT_M: f64 = 1000.0;

/// `[cloud]`: the point-cloud input and the online map (module docs). Every field is optional.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct CloudParams {
    /// The topic (relative to the node's namespace, or absolute). Default `cloud`.
    pub topic: String,
    /// The local map's overrides, as `[sensing.static]`'s `map = { … }` in a scenario
    /// (`trust_world::map_sensing::MapSpec`: `resolution_m`, `dims`, `max_distance_m`,
    /// `stop_at_visited`); the default window reaches `max_range_m` (at most 10 m) on each side
    /// horizontally.
    pub map: MapSpec,
    /// Points farther than this from the sensor clear space up to it and mark nothing (m), in
    /// `(0, 1000]`. Default 10 m: the D435's depth range, the simulator's default camera
    /// (`trust_world::map_sensing::WINDOW_HALF_WIDTH_M`).
    pub max_range_m: f64,
    /// How far from the sensor the vehicle's ball can lie outside its view (m), in `[0, 3]`:
    /// with the vehicle's radius and a voxel diagonal, the radius of the ball round the first
    /// odometry that starts known free. Default: the simulator's for its default camera (a D435
    /// at 87° × 58°, minimum depth 0.3 m: `StaticSensor::blind_reach_m` for the vehicle's
    /// radius, 0.54 m for 0.3 m).
    pub blind_reach_m: Option<f64>,
    /// A sensor frame accepted besides `world_frame` and `body_frame` (e.g.
    /// `camera_depth_optical_frame`), mounted on the body as below. Default none.
    pub sensor_frame: Option<String>,
    /// The sensor's origin in the body frame (m). Default 0.
    pub sensor_translation_m: [f64; 3],
    /// The sensor frame's orientation in the body frame: roll, pitch, yaw (rad, about the
    /// body's fixed x, y, z axes in that order: `UnitQuaternion::from_euler_angles`). Default 0;
    /// an optical frame (z forward, x right, y down) on a FLU body is `[-π/2, 0, -π/2]`.
    pub sensor_rpy_rad: [f64; 3],
}

impl Default for CloudParams {
    fn default() -> Self {
        CloudParams {
            topic: "cloud".into(),
            map: MapSpec::default(),
            max_range_m: WINDOW_HALF_WIDTH_M,
            blind_reach_m: None,
            sensor_frame: None,
            sensor_translation_m: [0.0; 3],
            sensor_rpy_rad: [0.0; 3],
        }
    }
}

impl CloudParams {
    /// Checks every field, naming the first invalid one (`cloud.…`).
    ///
    /// # Errors
    /// [`Ros2Error::Invalid`] with the field, the value and the range.
    pub fn validate(&self) -> Result<(), Ros2Error> {
        if self.topic.is_empty() {
            return Err(Ros2Error::invalid("cloud.topic", "\"\"", "a topic name"));
        }
        if !(self.max_range_m.is_finite()
            && self.max_range_m > 0.0
            && self.max_range_m <= MAX_RANGE_LIMIT_M)
        {
            return Err(Ros2Error::invalid(
                "cloud.max_range_m",
                self.max_range_m,
                format!("a range in (0, {MAX_RANGE_LIMIT_M}] m"),
            ));
        }
        if let Some(b) = self.blind_reach_m
            && !(b.is_finite() && (0.0..=MAX_BLIND_REACH_M).contains(&b))
        {
            return Err(Ros2Error::invalid(
                "cloud.blind_reach_m",
                b,
                format!("a distance in [0, {MAX_BLIND_REACH_M}] m"),
            ));
        }
        if self.sensor_frame.as_deref() == Some("") {
            return Err(Ros2Error::invalid(
                "cloud.sensor_frame",
                "\"\"",
                "a frame id",
            ));
        }
        for (field, v) in [
            ("cloud.sensor_translation_m", self.sensor_translation_m),
            ("cloud.sensor_rpy_rad", self.sensor_rpy_rad),
        ] {
            if !v.iter().all(|c| c.is_finite() && c.abs() <= 100.0) {
                return Err(Ros2Error::invalid(
                    field,
                    format!("{v:?}"),
                    "finite components of magnitude at most 100",
                ));
            }
        }
        self.map
            .params(self.max_range_m)
            .validate()
            .map_err(|e| Ros2Error::invalid("cloud.map", e, "valid local map parameters"))
    }

    /// The sensor's pose in the body frame.
    pub fn mount(&self) -> Isometry3<f64> {
        let [x, y, z] = self.sensor_translation_m;
        let [r, p, yaw] = self.sensor_rpy_rad;
        Isometry3::from_parts(
            Translation3::new(x, y, z),
            UnitQuaternion::from_euler_angles(r, p, yaw),
        )
    }
}

/// One odometry pose kept to place clouds.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Kept {
    t: f64,
    p: Vec3,
    q: UnitQuaternion<f64>,
    v: Vec3,
}

/// The vehicle's poses over the last [`POSE_HISTORY_S`] (module docs).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PoseHistory {
    poses: VecDeque<Kept>,
}

impl PoseHistory {
    /// Keeps the pose `(p, q)` with world velocity `v` at node time `t`. An odometry older
    /// than the latest kept starts the history anew (a clock that went back).
    pub fn push(&mut self, t: f64, p: Vec3, q: UnitQuaternion<f64>, v: Vec3) {
        if self.poses.back().is_some_and(|k| t < k.t) {
            self.poses.clear();
        }
        if self.poses.back().is_some_and(|k| t == k.t) {
            self.poses.pop_back();
        }
        self.poses.push_back(Kept { t, p, q, v });
        while self.poses.front().is_some_and(|k| k.t < t - POSE_HISTORY_S) {
            self.poses.pop_front();
        }
    }

    /// The vehicle's pose at node time `t` (module docs), extrapolating at most `ahead_s`
    /// past the latest odometry.
    ///
    /// # Errors
    /// [`Ros2Error::Invalid`] naming `cloud.header.stamp` before any odometry, before the
    /// oldest kept or more than `ahead_s` after the latest.
    pub fn at(&self, t: f64, ahead_s: f64) -> Result<Isometry3<f64>, Ros2Error> {
        let (Some(first), Some(last)) = (self.poses.front(), self.poses.back()) else {
            return Err(Ros2Error::invalid(
                "cloud.header.stamp",
                format!("node time {t} s"),
                "a cloud after the first odometry (its pose places the points)",
            ));
        };
        let pose = |p: Vec3, q| Isometry3::from_parts(Translation3::from(p), q);
        if t > last.t {
            let ahead = t - last.t;
            if ahead > ahead_s {
                return Err(Ros2Error::invalid(
                    "cloud.header.stamp",
                    format!("{ahead} s after the latest odometry"),
                    format!("at most odom_timeout_s = {ahead_s} s after it"),
                ));
            }
            return Ok(pose(last.p + last.v * ahead, last.q));
        }
        if t < first.t {
            return Err(Ros2Error::invalid(
                "cloud.header.stamp",
                format!("{} s before the latest odometry", last.t - t),
                format!("a stamp within the odometry kept ({} s)", last.t - first.t),
            ));
        }
        let i = self.poses.partition_point(|k| k.t <= t).max(1) - 1;
        let a = self.poses[i];
        let Some(b) = self.poses.get(i + 1) else {
            return Ok(pose(a.p, a.q));
        };
        let s = ((t - a.t) / (b.t - a.t)).clamp(0.0, 1.0);
        let q =
            a.q.try_slerp(&b.q, s, 1e-9)
                .unwrap_or(if s < 0.5 { a.q } else { b.q });
        Ok(pose(a.p + (b.p - a.p) * s, q))
    }
}

/// The scan of `points` (in a frame whose pose in the world is `to_world`) seen from
/// `origin` (world): one ray per point, a hit at its range, or beyond `max_range_m` a ray
/// without a return of that range; points within 1 µm of the origin are left out. Returns the
/// scan and how many points were left out.
pub fn cloud_scan(
    points: &[Vec3],
    to_world: &Isometry3<f64>,
    origin: Vec3,
    max_range_m: f64,
) -> (Scan, usize) {
    let mut skipped = 0;
    let rays = points
        .iter()
        .filter_map(|p| {
            let d = to_world.transform_point(&(*p).into()).coords - origin;
            let r = d.norm();
            if !(r.is_finite() && r > 1e-6) {
                skipped += 1;
                return None;
            }
            Some(if r > max_range_m {
                RayMeasurement {
                    direction: d / r,
                    range: max_range_m,
                    kind: ReturnKind::NoReturn,
                }
            } else {
                RayMeasurement {
                    direction: d / r,
                    range: r,
                    kind: ReturnKind::Hit,
                }
            })
        })
        .collect();
    (Scan { origin, rays }, skipped)
}

/// A cycle's map and commit check ([`CloudMap::for_cycle`]).
pub type CycleMap = (Arc<StaticMap>, Arc<dyn CommitCheck>);

/// The node's point-cloud state: the parameters, the poses, and the online map from the first
/// odometry on.
pub struct CloudMap {
    params: CloudParams,
    mount: Isometry3<f64>,
    poses: PoseHistory,
    online: Option<OnlineMap>,
    bounds: Aabb,
    radius_m: f64,
    blind_reach_m: f64,
}

impl std::fmt::Debug for CloudMap {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CloudMap")
            .field("params", &self.params)
            .field("poses", &self.poses)
            .field("started", &self.online.is_some())
            .finish_non_exhaustive()
    }
}

/// Where a cloud's points are, by its frame.
enum CloudFrame {
    World,
    Body,
    Sensor,
}

impl CloudMap {
    /// The state for `params` (checked) in a world of `bounds`, for a vehicle of radius
    /// `radius_m`.
    ///
    /// # Errors
    /// As [`CloudParams::validate`].
    pub fn new(params: CloudParams, bounds: Aabb, radius_m: f64) -> Result<Self, Ros2Error> {
        params.validate()?;
        let blind_reach_m = params.blind_reach_m.unwrap_or_else(|| {
            StaticSensor::Depth(DepthCameraParams::default()).blind_reach_m(radius_m)
        });
        Ok(CloudMap {
            mount: params.mount(),
            params,
            poses: PoseHistory::default(),
            online: None,
            bounds,
            radius_m,
            blind_reach_m,
        })
    }

    /// The parameters.
    pub fn params(&self) -> &CloudParams {
        &self.params
    }

    /// The online map, once the first odometry started it.
    pub fn map(&self) -> Option<&LocalMap> {
        self.online.as_ref().map(OnlineMap::map)
    }

    /// Keeps an accepted odometry's pose; the first starts the map round it.
    ///
    /// # Errors
    /// [`Ros2Error::Sensing`] if the map cannot start there (a position out of scale).
    pub fn observe_odometry(
        &mut self,
        t: f64,
        p: Vec3,
        q: UnitQuaternion<f64>,
        v: Vec3,
    ) -> Result<(), Ros2Error> {
        if self.online.is_none() {
            self.online = Some(OnlineMap::new(
                self.params.map.params(self.params.max_range_m),
                &p,
                self.bounds,
                self.radius_m,
                self.blind_reach_m,
            )?);
        }
        self.poses.push(t, p, q, v);
        Ok(())
    }

    /// Folds the points of a cloud in `frame` at node time `t` into the map (module docs);
    /// returns how many points were inserted and how many were left out at the origin.
    ///
    /// # Errors
    /// [`Ros2Error::Invalid`] naming `cloud.header.frame_id` for a frame not accepted,
    /// `cloud.header.stamp` for a stamp outside the odometry ([`PoseHistory::at`]);
    /// [`Ros2Error::Sensing`] if the map rejects the scan.
    pub fn insert(
        &mut self,
        frame: &str,
        frames: (&str, &str),
        t: f64,
        ahead_s: f64,
        points: &[Vec3],
    ) -> Result<(usize, usize), Ros2Error> {
        let (world_frame, body_frame) = frames;
        let kind = if frame == world_frame {
            CloudFrame::World
        } else if frame == body_frame {
            CloudFrame::Body
        } else if self.params.sensor_frame.as_deref() == Some(frame) {
            CloudFrame::Sensor
        } else {
            let mut accepted = vec![world_frame, body_frame];
            accepted.extend(self.params.sensor_frame.as_deref());
            return Err(Ros2Error::invalid(
                "cloud.header.frame_id",
                format!("{frame:?}"),
                format!("one of {accepted:?} (the node reads no TF)"),
            ));
        };
        let body = self.poses.at(t, ahead_s)?;
        let sensor = body * self.mount;
        let to_world = match kind {
            CloudFrame::World => Isometry3::identity(),
            CloudFrame::Body => body,
            CloudFrame::Sensor => sensor,
        };
        let origin = sensor.translation.vector;
        let (scan, skipped) = cloud_scan(points, &to_world, origin, self.params.max_range_m);
        let online = self
            .online
            .as_mut()
            .ok_or_else(|| Ros2Error::invalid("cloud", "a cloud", "odometry first"))?;
        online.insert(&scan, &body.translation.vector)?;
        Ok((scan.rays.len(), skipped))
    }

    /// The planner's map and the commit check for a cycle; `None` before the first odometry.
    ///
    /// # Errors
    /// [`Ros2Error::Sensing`] if the map cannot be exported.
    pub fn for_cycle(&mut self) -> Result<Option<CycleMap>, Ros2Error> {
        let Some(online) = self.online.as_mut() else {
            return Ok(None);
        };
        Ok(Some((online.planner_map()?, online.commit_check())))
    }
}

#[cfg(test)]
mod tests {
    use approx::assert_relative_eq;
    use std::f64::consts::FRAC_PI_2;

    use super::*;

    #[test]
    fn poses_are_interpolated_extrapolated_and_bounded() {
        let mut h = PoseHistory::default();
        assert!(h.at(0.0, 0.5).is_err(), "no odometry yet");
        let q0 = UnitQuaternion::from_euler_angles(0.0, 0.0, 0.0);
        let q1 = UnitQuaternion::from_euler_angles(0.0, 0.0, FRAC_PI_2);
        h.push(0.0, Vec3::new(0.0, 0.0, 1.0), q0, Vec3::new(1.0, 0.0, 0.0));
        h.push(0.5, Vec3::new(0.5, 0.0, 1.0), q1, Vec3::new(1.0, 0.0, 0.0));
        let mid = h.at(0.25, 0.5).expect("between");
        assert_relative_eq!(mid.translation.vector, Vec3::new(0.25, 0.0, 1.0));
        assert_relative_eq!(
            mid.rotation.euler_angles().2,
            FRAC_PI_2 / 2.0,
            epsilon = 1e-12
        );
        let ahead = h.at(0.75, 0.5).expect("extrapolated");
        assert_relative_eq!(ahead.translation.vector, Vec3::new(0.75, 0.0, 1.0));
        assert_eq!(ahead.rotation, q1);
        assert!(h.at(1.1, 0.5).is_err(), "too far ahead");
        assert!(h.at(-0.1, 0.5).is_err(), "before the history");
        // Pushed past POSE_HISTORY_S, the oldest goes.
        h.push(1.2, Vec3::zeros(), q0, Vec3::zeros());
        assert!(h.at(0.1, 0.5).is_err(), "0 s is gone");
        assert!(h.at(0.5, 0.5).is_ok(), "0.5 s is kept");
        // A clock that went back starts anew.
        h.push(0.1, Vec3::zeros(), q0, Vec3::zeros());
        assert!(h.at(0.5, 0.5).is_ok() && h.at(0.05, 0.5).is_err());
    }

    #[test]
    fn far_points_clear_to_the_range_and_near_ones_are_left_out() {
        let (scan, skipped) = cloud_scan(
            &[
                Vec3::new(3.0, 0.0, 0.0),
                Vec3::new(0.0, 30.0, 0.0),
                Vec3::zeros(),
            ],
            &Isometry3::identity(),
            Vec3::zeros(),
            10.0,
        );
        assert_eq!(skipped, 1);
        assert_eq!(scan.rays.len(), 2);
        assert_eq!(scan.rays[0].kind, ReturnKind::Hit);
        assert_relative_eq!(scan.rays[0].range, 3.0);
        assert_eq!(scan.rays[1].kind, ReturnKind::NoReturn);
        assert_relative_eq!(scan.rays[1].range, 10.0);
        assert_relative_eq!(scan.rays[1].direction, Vec3::new(0.0, 1.0, 0.0));
    }

    #[test]
    fn bad_parameters_are_named() {
        let bad = |p: CloudParams| p.validate().expect_err("invalid").to_string();
        let d = CloudParams::default();
        assert!(
            bad(CloudParams {
                max_range_m: 0.0,
                ..d.clone()
            })
            .contains("cloud.max_range_m")
        );
        assert!(
            bad(CloudParams {
                blind_reach_m: Some(5.0),
                ..d.clone()
            })
            .contains("cloud.blind_reach_m")
        );
        assert!(
            bad(CloudParams {
                sensor_rpy_rad: [f64::NAN, 0.0, 0.0],
                ..d.clone()
            })
            .contains("cloud.sensor_rpy_rad")
        );
        let mut m = d.clone();
        m.map.resolution_m = Some(-1.0);
        assert!(bad(m).contains("cloud.map"));
        d.validate().expect("the defaults are valid");
    }
}
