//! A simulated spinning multi-channel LiDAR.

use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use trust_geometry::Vec3;

use crate::error::{SensingError, check_count, check_range};
use crate::pose::Pose;
use crate::scan::Scan;
use crate::sensor::{Noise, RayPattern, RaySensor, scan_pattern};
use crate::truth::Truth;

/// Parameters of a [`Lidar`]. Defaults: [`LidarParams::vlp16`]; sources in `docs/sensing.md`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LidarParams {
    /// Laser channels (rings), `1..=256`, at elevations spread evenly over
    /// `[min_elevation_rad, max_elevation_rad]`.
    pub channels: usize,
    /// Elevation of the lowest channel, radians, in `[-π/2, π/2]`.
    pub min_elevation_rad: f64,
    /// Elevation of the highest channel, radians, `>= min_elevation_rad`.
    pub max_elevation_rad: f64,
    /// Firings per revolution (azimuth steps of `2π / columns`), `1..=65536`.
    pub columns: usize,
    /// Smallest range measured, metres.
    pub min_range_m: f64,
    /// Largest range measured, metres.
    pub max_range_m: f64,
    /// Revolutions (frames) per second.
    pub rate_hz: f64,
    /// Range noise (one standard deviation), metres, independent of the range.
    pub noise_sigma_m: f64,
}

impl Default for LidarParams {
    fn default() -> Self {
        Self::vlp16()
    }
}

impl LidarParams {
    /// Velodyne VLP-16 (Puck) at 10 Hz: 16 channels over ±15° (2° apart), 0.2° azimuth steps
    /// (1800 per revolution), 100 m range, ±3 cm accuracy taken as σ = 3 cm; the minimum range of
    /// 0.5 m is ours (see `docs/sensing.md`).
    pub fn vlp16() -> Self {
        Self {
            channels: 16,
            min_elevation_rad: (-15f64).to_radians(),
            max_elevation_rad: 15f64.to_radians(),
            columns: 1800,
            min_range_m: 0.5,
            max_range_m: 100.0,
            rate_hz: 10.0,
            noise_sigma_m: 0.03,
        }
    }

    /// Checks every field (named `lidar.<field>` in the error).
    pub fn validate(&self) -> Result<(), SensingError> {
        let half_pi = std::f64::consts::FRAC_PI_2;
        check_count("lidar.channels", self.channels, 1, 256, "in 1..=256")?;
        check_count("lidar.columns", self.columns, 1, 65536, "in 1..=65536")?;
        check_range(
            "lidar.min_elevation_rad",
            self.min_elevation_rad,
            -half_pi,
            half_pi,
            false,
            "in [-π/2, π/2] rad",
        )?;
        check_range(
            "lidar.max_elevation_rad",
            self.max_elevation_rad,
            self.min_elevation_rad,
            half_pi,
            false,
            "in [min_elevation_rad, π/2] rad",
        )?;
        check_range(
            "lidar.min_range_m",
            self.min_range_m,
            0.0,
            1e4,
            false,
            "in [0, 1e4] m",
        )?;
        check_range(
            "lidar.max_range_m",
            self.max_range_m,
            self.min_range_m,
            1e4,
            true,
            "in (min_range_m, 1e4] m",
        )?;
        check_range(
            "lidar.rate_hz",
            self.rate_hz,
            0.0,
            1e4,
            true,
            "in (0, 1e4] Hz",
        )?;
        check_range(
            "lidar.noise_sigma_m",
            self.noise_sigma_m,
            0.0,
            10.0,
            false,
            "in [0, 10] m",
        )?;
        Ok(())
    }

    /// Elevation of channel `c` (0 the lowest), radians.
    pub fn elevation(&self, c: usize) -> f64 {
        if self.channels <= 1 {
            return 0.5 * (self.min_elevation_rad + self.max_elevation_rad);
        }
        let f = c as f64 / (self.channels - 1) as f64;
        self.min_elevation_rad + f * (self.max_elevation_rad - self.min_elevation_rad)
    }
}

/// A spinning LiDAR about the sensor's +z axis. A [`Scan`] holds its rays column by column
/// (azimuth `2π j / columns` from +x towards +y), each column's channels from the lowest up:
/// ray `j * channels + c`. One frame is taken at one pose (no motion distortion).
#[derive(Debug, Clone)]
pub struct Lidar {
    params: LidarParams,
    pattern: RayPattern,
}

impl Lidar {
    /// A LiDAR with validated `params`; the ray pattern is computed once here.
    pub fn new(params: LidarParams) -> Result<Self, SensingError> {
        params.validate()?;
        let n = params.channels * params.columns;
        let mut dirs = Vec::with_capacity(n);
        for j in 0..params.columns {
            let az = std::f64::consts::TAU * j as f64 / params.columns as f64;
            for c in 0..params.channels {
                let el = params.elevation(c);
                dirs.push(Vec3::new(
                    el.cos() * az.cos(),
                    el.cos() * az.sin(),
                    el.sin(),
                ));
            }
        }
        Ok(Self {
            params,
            pattern: RayPattern {
                dirs,
                range_per_unit: vec![1.0; n],
                min: params.min_range_m,
                max: params.max_range_m,
            },
        })
    }

    /// The parameters.
    pub fn params(&self) -> &LidarParams {
        &self.params
    }
}

impl RaySensor for Lidar {
    fn name(&self) -> &str {
        "lidar"
    }

    fn scan(
        &self,
        pose: &Pose,
        truth: &Truth<'_>,
        rng: &mut ChaCha8Rng,
        out: &mut Scan,
    ) -> Result<(), SensingError> {
        let noise = Noise {
            sigma0: self.params.noise_sigma_m,
            k: 0.0,
        };
        scan_pattern(&self.pattern, noise, pose, truth, rng, out)
    }

    fn rate_hz(&self) -> f64 {
        self.params.rate_hz
    }
}
