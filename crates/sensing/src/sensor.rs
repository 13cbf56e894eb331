//! The ray-sensor trait and the scan loop every sensor shares.

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use trust_geometry::Vec3;

use crate::error::SensingError;
use crate::pose::Pose;
use crate::scan::{RayMeasurement, ReturnKind, Scan};
use crate::truth::Truth;

/// A simulated sensor that measures ranges along a fixed pattern of rays.
///
/// `scan` ray-casts every ray of one frame from `pose` against `truth` and writes the result into
/// `out` (its buffer is reused). Noise comes only from `rng`: the same pose, world and generator
/// state give the same scan. Errors only on an invalid pose (non-finite, out of scale, not a unit
/// quaternion).
pub trait RaySensor: Send + Sync {
    /// A short name for reports.
    fn name(&self) -> &str;
    /// One frame from `pose` against `truth`.
    fn scan(
        &self,
        pose: &Pose,
        truth: &Truth<'_>,
        rng: &mut ChaCha8Rng,
        out: &mut Scan,
    ) -> Result<(), SensingError>;
    /// Frames per second.
    fn rate_hz(&self) -> f64;
}

/// The fixed geometry of a sensor's rays, in the sensor frame.
#[derive(Debug, Clone)]
pub(crate) struct RayPattern {
    /// Unit directions.
    pub dirs: Vec<Vec3>,
    /// Range per unit of the sensor's reported distance along each ray (1 for a LiDAR, which
    /// reports range; `|d|/d_x ≥ 1` for a depth camera, which reports depth along its axis).
    pub range_per_unit: Vec<f64>,
    /// Minimum and maximum reported distance (depth or range).
    pub min: f64,
    /// See `min`.
    pub max: f64,
}

/// The noise of a reported distance `z`: `σ(z) = sigma0 + k z²`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Noise {
    pub sigma0: f64,
    pub k: f64,
}

impl Noise {
    fn is_off(&self) -> bool {
        self.sigma0 == 0.0 && self.k == 0.0
    }
}

/// Casts every ray of `pattern` from `pose` against `truth`, adding noise to each reported
/// distance (one standard normal draw per ray, in ray order, whether or not it hits, so that
/// the noise of a ray does not depend on the others; no draws when the noise is off).
pub(crate) fn scan_pattern(
    pattern: &RayPattern,
    noise: Noise,
    pose: &Pose,
    truth: &Truth<'_>,
    rng: &mut ChaCha8Rng,
    out: &mut Scan,
) -> Result<(), SensingError> {
    pose.validate()?;
    let rot = pose.attitude.to_rotation_matrix();
    out.origin = pose.position;
    out.rays.clear();
    out.rays.reserve(pattern.dirs.len());
    for (d, &per_unit) in pattern.dirs.iter().zip(&pattern.range_per_unit) {
        let direction = rot * d;
        let max_t = pattern.max * per_unit;
        let hit = truth.cast(&pose.position, &direction, max_t);
        let n: f64 = if noise.is_off() {
            0.0
        } else {
            rng.sample(StandardNormal)
        };
        let (range, kind) = match hit {
            Some(t) => {
                let z = t / per_unit;
                let measured = z + n * (noise.sigma0 + noise.k * z * z);
                if measured < pattern.min || !measured.is_finite() {
                    (0.0, ReturnKind::Invalid)
                } else if measured > pattern.max {
                    (max_t, ReturnKind::NoReturn)
                } else {
                    (measured * per_unit, ReturnKind::Hit)
                }
            }
            None => (max_t, ReturnKind::NoReturn),
        };
        out.rays.push(RayMeasurement {
            direction,
            range,
            kind,
        });
    }
    Ok(())
}
