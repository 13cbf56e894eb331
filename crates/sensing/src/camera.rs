//! A simulated pinhole depth camera.

use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use trust_geometry::Vec3;

use crate::error::{SensingError, check_count, check_range};
use crate::pose::Pose;
use crate::scan::{ReturnKind, Scan};
use crate::sensor::{Noise, RayPattern, RaySensor, scan_pattern};
use crate::truth::Truth;

/// Parameters of a [`DepthCamera`]. Defaults: [`DepthCameraParams::d435_160x120`]; the sources
/// of every number are in `docs/sensing.md`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DepthCameraParams {
    /// Pixels per row, `1..=4096`.
    pub width: usize,
    /// Rows, `1..=4096`.
    pub height: usize,
    /// Horizontal field of view, radians, in `(0, 3]` (a pinhole sees less than π).
    pub hfov_rad: f64,
    /// Vertical field of view, radians, in `(0, 3]`.
    pub vfov_rad: f64,
    /// Smallest depth measured, metres (closer surfaces give [`ReturnKind::Invalid`]).
    pub min_depth_m: f64,
    /// Largest depth measured, metres (farther surfaces give [`ReturnKind::NoReturn`]).
    pub max_depth_m: f64,
    /// Frames per second.
    pub rate_hz: f64,
    /// Depth noise `σ(z) = k z²` (stereo / structured light: the disparity error grows the depth
    /// error with the square of the depth), `k` in 1/m; 0 turns the noise off.
    pub noise_k_per_m: f64,
}

impl Default for DepthCameraParams {
    fn default() -> Self {
        Self::d435_160x120()
    }
}

impl DepthCameraParams {
    /// Intel RealSense D435 at its native 848 × 480 depth resolution: 87° × 58° field of view,
    /// 0.3–10 m, 30 fps, `σ = 0.0036 z²` (Intel's depth RMS error formula at 848 px; see
    /// `docs/sensing.md`).
    pub fn d435() -> Self {
        Self {
            width: 848,
            height: 480,
            hfov_rad: 87f64.to_radians(),
            vfov_rad: 58f64.to_radians(),
            min_depth_m: 0.3,
            max_depth_m: 10.0,
            rate_hz: 30.0,
            noise_k_per_m: 0.0036,
        }
    }

    /// The D435 binned to the benchmark's 160 × 120 frame (same field of view, range, rate and
    /// noise): the default for planning.
    pub fn d435_160x120() -> Self {
        Self {
            width: 160,
            height: 120,
            ..Self::d435()
        }
    }

    /// Checks every field (named `camera.<field>` in the error).
    pub fn validate(&self) -> Result<(), SensingError> {
        check_count("camera.width", self.width, 1, 4096, "in 1..=4096")?;
        check_count("camera.height", self.height, 1, 4096, "in 1..=4096")?;
        check_range(
            "camera.hfov_rad",
            self.hfov_rad,
            0.0,
            3.0,
            true,
            "in (0, 3] rad",
        )?;
        check_range(
            "camera.vfov_rad",
            self.vfov_rad,
            0.0,
            3.0,
            true,
            "in (0, 3] rad",
        )?;
        check_range(
            "camera.min_depth_m",
            self.min_depth_m,
            0.0,
            1e4,
            false,
            "in [0, 1e4] m",
        )?;
        check_range(
            "camera.max_depth_m",
            self.max_depth_m,
            self.min_depth_m,
            1e4,
            true,
            "in (min_depth_m, 1e4] m",
        )?;
        check_range(
            "camera.rate_hz",
            self.rate_hz,
            0.0,
            1e4,
            true,
            "in (0, 1e4] Hz",
        )?;
        check_range(
            "camera.noise_k_per_m",
            self.noise_k_per_m,
            0.0,
            1.0,
            false,
            "in [0, 1] 1/m",
        )?;
        Ok(())
    }
}

/// A pinhole depth camera looking along the sensor's +x axis (rows go down, columns right; see
/// [`Pose`]). It reports depth along the optical axis; a [`Scan`] holds the range along each
/// pixel's ray (depth × `|d| / d_x`), row by row, and [`DepthCamera::depth_image`] turns it back
/// into depths.
#[derive(Debug, Clone)]
pub struct DepthCamera {
    params: DepthCameraParams,
    pattern: RayPattern,
}

impl DepthCamera {
    /// A camera with validated `params`; the pixel rays are computed once here.
    pub fn new(params: DepthCameraParams) -> Result<Self, SensingError> {
        params.validate()?;
        let (w, h) = (params.width, params.height);
        let tx = (0.5 * params.hfov_rad).tan();
        let ty = (0.5 * params.vfov_rad).tan();
        let mut dirs = Vec::with_capacity(w * h);
        let mut range_per_unit = Vec::with_capacity(w * h);
        for v in 0..h {
            // Row centre, from the top (+z) down.
            let b = ty * (1.0 - 2.0 * (v as f64 + 0.5) / h as f64);
            for u in 0..w {
                // Column centre, from the left (+y) to the right.
                let a = tx * (1.0 - 2.0 * (u as f64 + 0.5) / w as f64);
                let d = Vec3::new(1.0, a, b);
                let n = d.norm();
                dirs.push(d / n);
                range_per_unit.push(n);
            }
        }
        Ok(Self {
            params,
            pattern: RayPattern {
                dirs,
                range_per_unit,
                min: params.min_depth_m,
                max: params.max_depth_m,
            },
        })
    }

    /// The parameters.
    pub fn params(&self) -> &DepthCameraParams {
        &self.params
    }

    /// Unit direction of pixel `(u, v)` (column, row) in the sensor frame, or `None` outside the
    /// image.
    pub fn pixel_direction(&self, u: usize, v: usize) -> Option<Vec3> {
        (u < self.params.width && v < self.params.height)
            .then(|| self.pattern.dirs[v * self.params.width + u])
    }

    /// Unit pixel directions in the sensor frame and the range per unit of depth of each (row
    /// by row), for the projective map update.
    pub(crate) fn pixel_rays(&self) -> (&[Vec3], &[f64]) {
        (&self.pattern.dirs, &self.pattern.range_per_unit)
    }

    /// Depth per pixel (row by row) of a scan this camera took: metres along the optical axis,
    /// 0 where there is no measurement (the RealSense convention for "no data"): rays of kind
    /// [`ReturnKind::NoReturn`] or [`ReturnKind::Invalid`]. Rays beyond the image are ignored.
    pub fn depth_image(&self, scan: &Scan) -> Vec<f64> {
        scan.rays
            .iter()
            .zip(&self.pattern.range_per_unit)
            .map(|(r, n)| match r.kind {
                ReturnKind::Hit => r.range / n,
                _ => 0.0,
            })
            .collect()
    }
}

impl RaySensor for DepthCamera {
    fn name(&self) -> &str {
        "depth camera"
    }

    fn scan(
        &self,
        pose: &Pose,
        truth: &Truth<'_>,
        rng: &mut ChaCha8Rng,
        out: &mut Scan,
    ) -> Result<(), SensingError> {
        let noise = Noise {
            sigma0: 0.0,
            k: self.params.noise_k_per_m,
        };
        scan_pattern(&self.pattern, noise, pose, truth, rng, out)
    }

    fn rate_hz(&self) -> f64 {
        self.params.rate_hz
    }
}
