//! What a sensor returns: one measurement per ray, in the world frame.

use serde::{Deserialize, Serialize};
use trust_geometry::Vec3;

/// What came back along one ray.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ReturnKind {
    /// A surface at the measured range: the end voxel is occupied evidence, the voxels before it
    /// free evidence.
    Hit,
    /// Nothing within the sensor's maximum range along this ray (`range` is that maximum):
    /// free-space evidence up to it.
    NoReturn,
    /// No measurement (a surface closer than the minimum range, or a dropout): no evidence at
    /// all; `range` is 0.
    Invalid,
}

/// One ray of a scan.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RayMeasurement {
    /// Unit direction of the ray in the world frame.
    pub direction: Vec3,
    /// Measured range along `direction`, metres (see [`ReturnKind`] for its meaning per kind).
    pub range: f64,
    /// What came back.
    pub kind: ReturnKind,
}

/// One frame of a ray sensor: the sensor origin and its rays (in the sensor's own order: row
/// by row for a camera, column by column for a LiDAR), all in the world frame.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Scan {
    /// Sensor origin in the world frame.
    pub origin: Vec3,
    /// The rays.
    pub rays: Vec<RayMeasurement>,
}

impl Scan {
    /// The surface points measured (rays of kind [`ReturnKind::Hit`]), in the world frame.
    pub fn points(&self) -> impl Iterator<Item = Vec3> + '_ {
        self.rays
            .iter()
            .filter(|r| r.kind == ReturnKind::Hit)
            .map(|r| self.origin + r.direction * r.range)
    }

    /// Number of rays of the given kind.
    pub fn count(&self, kind: ReturnKind) -> usize {
        self.rays.iter().filter(|r| r.kind == kind).count()
    }
}
