//! Scenario section `[sensing.static]`: whether the planner is given the static map or senses it
//! (issue 34).
//!
//! * `"known"` (the default): the planner gets the static map as the scenario describes it
//!   (`World::planner_map`); every flight is as before.
//! * `{ depth = { … } }` or `{ lidar = { … } }`: the vehicle carries a depth camera or a LiDAR
//!   (`trust_sensing::DepthCamera`, `trust_sensing::Lidar`), ray-cast against the true static
//!   map from its pose at the sensor's rate, and the planner plans in the online map it builds
//!   (`trust_sensing::LocalMap`). Every field of the inner table is optional and overrides the
//!   sensor's default (`DepthCameraParams::default`: a D435 at 160 × 120, 30 fps;
//!   `LidarParams::default`: a VLP-16); an optional `map = { … }` overrides the local map's
//!   (`LocalMapParams::default`: 0.1 m voxels, an 11.2 × 11.2 × 4.8 m window).
//!
//! ```toml
//! [sensing]
//! static = { depth = { rate_hz = 15.0, map = { resolution_m = 0.15 } } }
//! ```
//!
//! Invalid values are problems of `trust-sim validate` naming the field
//! (`sensing.static.depth.rate_hz`), the value and the accepted range.

use serde::{Deserialize, Serialize};
use trust_sensing::{DepthCameraParams, LidarParams, LocalMapParams, SensingError};

use crate::problem::{Problem, Problems, fmt_num};

/// `[sensing.static]`: the planner's view of the static world.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StaticSensing {
    /// The planner is given the static map (the paper's setting).
    #[default]
    Known,
    /// A depth camera senses it.
    Depth(DepthSpec),
    /// A spinning LiDAR senses it.
    Lidar(LidarSpec),
}

/// Overrides of the local map's parameters (`trust_sensing::LocalMapParams`); absent fields
/// keep its defaults.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct MapSpec {
    /// Voxel edge (m).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub resolution_m: Option<f64>,
    /// Voxels of the rolling window along x, y, z. Default: the sensor's range, at most
    /// [`WINDOW_HALF_WIDTH_M`], on each side horizontally; `LocalMapParams`' 48 voxels
    /// vertically.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dims: Option<[usize; 3]>,
    /// Truncation of the distance field (m).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_distance_m: Option<f64>,
    /// Fast-Planner's ray-casting shortcut (`LocalMapParams::stop_at_visited`). Default false,
    /// as the library's: tracing each ray from its end back to the first voxel another ray of
    /// the frame cleared costs a fraction of the exact update (`cargo bench -p trust-sensing
    /// --bench map_update`), but a hovering camera's frame then leaves holes of metres in the
    /// free space it saw (a ray stops at the first voxel a neighbour cleared far out, and the
    /// near voxels only it crossed stay unknown), and a plan is committed only through known
    /// free space: a vehicle stopped in front of a wall never commits to the way along it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stop_at_visited: Option<bool>,
}

/// Most half-width of the default window (m): 10 m, the depth camera's range (the D435's,
/// `docs/sensing.md`). The committed part of a plan must lie in the window, so a window
/// narrower than what the sensor sees slows the vehicle down for nothing.
pub const WINDOW_HALF_WIDTH_M: f64 = 10.0;

impl MapSpec {
    /// `LocalMapParams::default()` with these overrides, for a sensor of range `range_m`.
    pub fn params(&self, range_m: f64) -> LocalMapParams {
        let d = LocalMapParams::default();
        let resolution_m = self.resolution_m.unwrap_or(d.resolution_m);
        let half = range_m.clamp(0.0, WINDOW_HALF_WIDTH_M);
        // Out-of-range values are the validation's; here only keep the count finite.
        let across = if resolution_m > 0.0 && resolution_m.is_finite() {
            ((2.0 * half / resolution_m).ceil() as usize).clamp(2, 2048)
        } else {
            d.dims[0]
        };
        LocalMapParams {
            resolution_m,
            dims: self.dims.unwrap_or([across, across, d.dims[2]]),
            max_distance_m: self.max_distance_m.unwrap_or(d.max_distance_m),
            stop_at_visited: self.stop_at_visited.unwrap_or(false),
            ..d
        }
    }
}

/// `{ depth = { … } }`: overrides of `trust_sensing::DepthCameraParams` (field docs there).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
#[allow(missing_docs)]
pub struct DepthSpec {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub width: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub height: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hfov_rad: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub vfov_rad: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub min_depth_m: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_depth_m: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rate_hz: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub noise_k_per_m: Option<f64>,
    /// The local map's overrides.
    pub map: MapSpec,
}

impl DepthSpec {
    /// `DepthCameraParams::default()` with these overrides.
    pub fn params(&self) -> DepthCameraParams {
        let d = DepthCameraParams::default();
        DepthCameraParams {
            width: self.width.unwrap_or(d.width),
            height: self.height.unwrap_or(d.height),
            hfov_rad: self.hfov_rad.unwrap_or(d.hfov_rad),
            vfov_rad: self.vfov_rad.unwrap_or(d.vfov_rad),
            min_depth_m: self.min_depth_m.unwrap_or(d.min_depth_m),
            max_depth_m: self.max_depth_m.unwrap_or(d.max_depth_m),
            rate_hz: self.rate_hz.unwrap_or(d.rate_hz),
            noise_k_per_m: self.noise_k_per_m.unwrap_or(d.noise_k_per_m),
        }
    }
}

/// `{ lidar = { … } }`: overrides of `trust_sensing::LidarParams` (field docs there).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
#[allow(missing_docs)]
pub struct LidarSpec {
    #[serde(skip_serializing_if = "Option::is_none")]
    pub channels: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub min_elevation_rad: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_elevation_rad: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub columns: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub min_range_m: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_range_m: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rate_hz: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub noise_sigma_m: Option<f64>,
    /// The local map's overrides.
    pub map: MapSpec,
}

impl LidarSpec {
    /// `LidarParams::default()` with these overrides.
    pub fn params(&self) -> LidarParams {
        let d = LidarParams::default();
        LidarParams {
            channels: self.channels.unwrap_or(d.channels),
            min_elevation_rad: self.min_elevation_rad.unwrap_or(d.min_elevation_rad),
            max_elevation_rad: self.max_elevation_rad.unwrap_or(d.max_elevation_rad),
            columns: self.columns.unwrap_or(d.columns),
            min_range_m: self.min_range_m.unwrap_or(d.min_range_m),
            max_range_m: self.max_range_m.unwrap_or(d.max_range_m),
            rate_hz: self.rate_hz.unwrap_or(d.rate_hz),
            noise_sigma_m: self.noise_sigma_m.unwrap_or(d.noise_sigma_m),
        }
    }
}

/// The sensor a `[sensing.static]` section names, with its parameters resolved.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum StaticSensor {
    /// A depth camera.
    Depth(DepthCameraParams),
    /// A LiDAR.
    Lidar(LidarParams),
}

impl StaticSensor {
    /// Frames per second.
    pub fn rate_hz(&self) -> f64 {
        match self {
            StaticSensor::Depth(p) => p.rate_hz,
            StaticSensor::Lidar(p) => p.rate_hz,
        }
    }
}

impl StaticSensor {
    /// How far from the sensor (m) a ball of radius `clearance` on its forward axis can still
    /// reach outside the sensor's view: beyond the returned distance the ball lies within the
    /// field of view (vertically and horizontally) and beyond the minimum range. A depth camera:
    /// `max(min_depth, clearance / tan(fov/2))` over both fields of view (0.54 m for the D435's
    /// 58° vertical field and a 0.3 m radius); a LiDAR: `max(min_range, clearance /
    /// tan(e))` with `e` the smaller of its lowest and highest elevation's magnitudes (a
    /// pattern that does not look both up and down reaches [`MAX_BLIND_REACH_M`]). At most
    /// [`MAX_BLIND_REACH_M`]; a negative or NaN clearance counts as 0.
    pub fn blind_reach_m(&self, clearance: f64) -> f64 {
        let c = if clearance.is_nan() {
            0.0
        } else {
            clearance.max(0.0)
        };
        let beyond = |half_angle: f64| {
            if half_angle > 0.0 && half_angle.is_finite() {
                c / half_angle.min(std::f64::consts::FRAC_PI_2 - 1e-9).tan()
            } else {
                f64::INFINITY
            }
        };
        let reach = match self {
            StaticSensor::Depth(p) => p
                .min_depth_m
                .max(beyond(0.5 * p.vfov_rad))
                .max(beyond(0.5 * p.hfov_rad)),
            StaticSensor::Lidar(p) => {
                let e = (-p.min_elevation_rad).min(p.max_elevation_rad);
                p.min_range_m.max(beyond(e))
            }
        };
        if reach.is_nan() {
            MAX_BLIND_REACH_M
        } else {
            reach.min(MAX_BLIND_REACH_M)
        }
    }
}

/// Most [`StaticSensor::blind_reach_m`] (m): 3 m, beyond which a sensor that cannot see
/// around the vehicle is not one to fly on.
pub const MAX_BLIND_REACH_M: f64 = 3.0;

impl StaticSensing {
    /// Whether the planner is given the map (`"known"`).
    pub fn is_known(&self) -> bool {
        matches!(self, StaticSensing::Known)
    }

    /// The sensor and the local map's parameters; `None` for `"known"`.
    pub fn sensor(&self) -> Option<(StaticSensor, LocalMapParams)> {
        match self {
            StaticSensing::Known => None,
            StaticSensing::Depth(s) => {
                let p = s.params();
                Some((StaticSensor::Depth(p), s.map.params(p.max_depth_m)))
            }
            StaticSensing::Lidar(s) => {
                let p = s.params();
                Some((StaticSensor::Lidar(p), s.map.params(p.max_range_m)))
            }
        }
    }

    /// Every problem with the section; field paths start with `field` (`sensing.static`).
    pub(crate) fn check(&self, field: &str, p: &mut Problems) {
        let Some((sensor, map)) = self.sensor() else {
            return;
        };
        let (kind, result) = match sensor {
            StaticSensor::Depth(d) => ("depth", d.validate()),
            StaticSensor::Lidar(l) => ("lidar", l.validate()),
        };
        let prefix = format!("{field}.{kind}");
        if let Err(e) = result {
            p.list.push(sensing_problem(e, &prefix));
        }
        if let Err(e) = map.validate() {
            p.list.push(sensing_problem(e, &prefix));
        }
    }
}

/// A parameter error of `trust-sensing` (fields `camera.…`, `lidar.…`, `map.…`) as a problem
/// under `prefix`: `camera.rate_hz` becomes `<prefix>.rate_hz`, `map.dims.x`
/// `<prefix>.map.dims.x`.
fn sensing_problem(e: SensingError, prefix: &str) -> Problem {
    let path = |field: &str| {
        let rest = match field.split_once('.') {
            Some(("map", _)) => field,
            Some((_, rest)) => rest,
            None => field,
        };
        format!("{prefix}.{rest}")
    };
    match e {
        SensingError::NonFinite { field, value } => {
            Problem::new(path(&field), fmt_num(value), "a finite number")
        }
        SensingError::OutOfRange {
            field,
            value,
            expected,
        } => Problem::new(path(&field), fmt_num(value), expected),
        SensingError::Count {
            field,
            value,
            expected,
        } => Problem::new(path(&field), value, expected),
        other => Problem::new(prefix.to_string(), other, "valid sensor parameters"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Deserialize)]
    #[serde(deny_unknown_fields)]
    struct Wrap {
        #[serde(rename = "static")]
        s: StaticSensing,
    }

    fn parse(text: &str) -> Result<StaticSensing, toml::de::Error> {
        toml::from_str::<Wrap>(text).map(|w| w.s)
    }

    fn problems(s: &StaticSensing) -> Vec<Problem> {
        let mut p = Problems::default();
        s.check("sensing.static", &mut p);
        p.list
    }

    #[test]
    fn known_depth_and_lidar_parse_with_defaults_and_overrides() {
        assert_eq!(parse("static = \"known\"").unwrap(), StaticSensing::Known);
        let d = parse("static = { depth = {} }").unwrap();
        let (sensor, map) = d.sensor().unwrap();
        assert_eq!(sensor, StaticSensor::Depth(DepthCameraParams::default()));
        assert_eq!(map.dims, [200, 200, 48]);
        assert_eq!(map.resolution_m, LocalMapParams::default().resolution_m);
        let d =
            parse("static = { depth = { rate_hz = 15.0, map = { resolution_m = 0.2 } } }").unwrap();
        let (sensor, map) = d.sensor().unwrap();
        assert_eq!(sensor.rate_hz(), 15.0);
        assert_eq!(map.resolution_m, 0.2);
        let l = parse("static = { lidar = { channels = 32 } }").unwrap();
        match l.sensor().unwrap().0 {
            StaticSensor::Lidar(p) => assert_eq!(p.channels, 32),
            other => panic!("{other:?}"),
        }
        assert!(problems(&d).is_empty());
        assert!(problems(&l).is_empty());
    }

    #[test]
    fn the_blind_reach_follows_the_field_of_view() {
        let (d435, _) = parse("static = { depth = {} }").unwrap().sensor().unwrap();
        // 58° vertical: 0.3 / tan 29° ≈ 0.541 m.
        assert!((d435.blind_reach_m(0.3) - 0.3 / 29f64.to_radians().tan()).abs() < 1e-9);
        assert!((d435.blind_reach_m(f64::NAN) - d435_min_depth()).abs() < 1e-9);
        let (vlp, _) = parse("static = { lidar = {} }").unwrap().sensor().unwrap();
        // ±15°: 0.3 / tan 15° ≈ 1.12 m.
        assert!((vlp.blind_reach_m(0.3) - 0.3 / 15f64.to_radians().tan()).abs() < 1e-6);
        let (up_only, _) = parse("static = { lidar = { min_elevation_rad = 0.1 } }")
            .unwrap()
            .sensor()
            .unwrap();
        assert_eq!(up_only.blind_reach_m(0.3), MAX_BLIND_REACH_M);
    }

    fn d435_min_depth() -> f64 {
        DepthCameraParams::default().min_depth_m
    }

    #[test]
    fn unknown_names_and_fields_are_parse_errors() {
        assert!(parse("static = \"unknown\"").is_err());
        assert!(parse("static = { sonar = {} }").is_err());
        assert!(parse("static = { depth = { fps = 30 } }").is_err());
        assert!(parse("static = { depth = { rate_hz = \"fast\" } }").is_err());
    }

    #[test]
    fn bad_values_are_problems_naming_field_value_and_range() {
        let d = parse("static = { depth = { rate_hz = -1.0 } }").unwrap();
        let p = problems(&d);
        assert_eq!(p.len(), 1);
        assert_eq!(p[0].field, "sensing.static.depth.rate_hz");
        assert!(p[0].expected.contains("Hz"), "{:?}", p[0]);
        let d = parse("static = { lidar = { channels = 0 } }").unwrap();
        assert_eq!(problems(&d)[0].field, "sensing.static.lidar.channels");
        let d = parse("static = { depth = { map = { dims = [1, 100, 40] } } }").unwrap();
        assert_eq!(problems(&d)[0].field, "sensing.static.depth.map.dims.x");
        let d = parse("static = { depth = { max_depth_m = 0.1 } }").unwrap();
        assert_eq!(problems(&d)[0].field, "sensing.static.depth.max_depth_m");
    }
}
